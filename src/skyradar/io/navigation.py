"""The per-frame own-ship navigation state the processing chain uses: never the simulator's truth.

A frames run written from a scenario holds the own-ship truth (``own_*``) and, beside it, the
navigation solution an aircraft would have (``nav_*``: GNSS and AHRS with errors,
:mod:`skyradar.sim.navigation`). :func:`navigation_state` is the one reader process, track and
alert use: it returns the ``nav_*`` values under the own-ship table's column names
(:data:`STATE_COLUMNS`, named ``own_*`` because the table is "what the own-ship knows"). Stores
without ``nav_*`` variables hold only ``own_*``: they are used with a logged note and
``attrs["navigation_source"] == "truth"`` so a result can say so.

Examples
--------
>>> import xarray as xr
>>> ds = xr.Dataset({"own_north_m": ("time", [0.0]), "nav_north_m": ("time", [2.0])},
...                 coords={"time": [0.0]})
>>> state = navigation_state(ds)
>>> float(state["own_north_m"][0]), state.attrs["navigation_source"]
(2.0, 'navigation')
"""

from __future__ import annotations

import logging

import numpy as np
import pandas as pd
import xarray as xr

from skyradar.io.frames_model import frame_times_s

__all__ = ["STATE_COLUMNS", "NAVIGATION_SOURCES", "navigation_state", "navigation_source"]

_LOG = logging.getLogger(__name__)
STATE_COLUMNS = (
    "own_north_m",
    "own_east_m",
    "own_down_m",
    "own_vn_mps",
    "own_ve_mps",
    "own_vd_mps",
    "own_yaw_rad",
    "own_pitch_rad",
    "own_roll_rad",
    "own_lat_deg",
    "own_lon_deg",
    "own_alt_m",
    "own_height_agl_m",
)
NAVIGATION_SOURCES = ("navigation", "truth")


def navigation_source(ds: xr.Dataset) -> str | None:
    """``"navigation"`` (the run has ``nav_*``), ``"truth"`` (only ``own_*``: an older store) or None.

    Examples
    --------
    >>> navigation_source(xr.Dataset()) is None
    True
    """
    if any(f"nav_{c[4:]}" in ds for c in STATE_COLUMNS):
        return "navigation"
    if any(c in ds for c in STATE_COLUMNS):
        return "truth"
    return None


def navigation_state(ds: xr.Dataset, source: str = "frames") -> pd.DataFrame | None:
    """The own-ship state per frame as the aircraft knows it (``nav_*``), or None without any.

    Parameters
    ----------
    ds : xr.Dataset
        A frames Dataset (only its own-ship variables and ``time`` are read).
    source : str
        Name of the run, for the note logged when it falls back to the truth.

    Returns
    -------
    pandas.DataFrame or None
        ``time_s`` and the :data:`STATE_COLUMNS` the run has, from ``nav_*``, else from ``own_*``
        (stores without ``nav_*``); ``attrs["navigation_source"]`` says which. Units as in the
        column names: m, m/s, rad, degree; ``time_s`` in s.

    Examples
    --------
    A store with only the truth: its values are used, and the source says so.

    >>> ds = xr.Dataset({"own_yaw_rad": ("time", [0.0, np.pi / 2]), "own_alt_m": ("time", [100.0, 110.0])},
    ...                 coords={"time": [0.0, 0.5]})
    >>> state = navigation_state(ds)
    >>> list(state.columns), state["own_alt_m"].tolist(), state.attrs["navigation_source"]
    (['time_s', 'own_yaw_rad', 'own_alt_m'], [100.0, 110.0], 'truth')
    >>> navigation_state(xr.Dataset()) is None
    True
    """
    kind = navigation_source(ds)
    if kind is None:
        return None
    prefix = "nav_" if kind == "navigation" else "own_"
    if kind == "truth":
        _LOG.info("%s: no navigation (nav_*) variables; using the own-ship truth (own_*) instead", source)
    cols: dict[str, np.ndarray] = {"time_s": frame_times_s(ds)}
    for name in STATE_COLUMNS:
        var = prefix + name[4:]
        if var in ds:
            cols[name] = np.asarray(ds[var].values, float)
    state = pd.DataFrame(cols)
    state.attrs["navigation_source"] = kind
    return state
