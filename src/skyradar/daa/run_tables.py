"""DAA tables from a frames run: the own-ship navigation state and, for a simulated run, truth as tracks.

Both follow :mod:`skyradar.daa.tables`.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import xarray as xr

from skyradar.daa.tables import OPTIONAL_OWNSHIP_COLUMNS, OWNSHIP_COLUMNS, STATE_LIMITS, TRACK_COLUMNS
from skyradar.errors import InputError
from skyradar.io.frames_model import frame_times_s
from skyradar.io.navigation import navigation_state
from skyradar.io.tables import check_within, finite_column

__all__ = ["has_ownship", "ownship_from_frames", "truth_tracks"]


def has_ownship(ds: xr.Dataset) -> bool:
    """Whether a frames run holds the own-ship state (a simulated run does, a recording may not).

    Examples
    --------
    >>> has_ownship(xr.Dataset())
    False
    """
    names = set(ds.variables)
    return any(all(f"{p}{c[4:]}" in names for c in OWNSHIP_COLUMNS[1:]) for p in ("nav_", "own_"))


def ownship_from_frames(ds: xr.Dataset, source: str = "frames") -> pd.DataFrame:
    """Own-ship state of a frames run as a table (:mod:`skyradar.daa.tables`): what the aircraft knows.

    The values are the run's navigation solution (``nav_*``, GNSS/AHRS with errors) read by
    :func:`skyradar.io.navigation.navigation_state`; only a store without ``nav_*`` variables
    gives its ``own_*`` truth (``attrs["navigation_source"] == "truth"``).

    Parameters
    ----------
    ds : xr.Dataset
        Frames Dataset with the own-ship NED position (m) and velocity (m/s), as ``nav_*`` or
        ``own_*`` variables.
    source : str
        Name of the run in error messages.

    Returns
    -------
    DataFrame
        ``time_s`` (s), the own-ship columns of :data:`OWNSHIP_COLUMNS` (m, m/s) and those of
        :data:`OPTIONAL_OWNSHIP_COLUMNS` the run has; InputError when a state variable is missing or
        not a finite state.

    Examples
    --------
    >>> t = np.arange(3.0)
    >>> state = {"own_north_m": 50.0 * t, "own_east_m": 0 * t, "own_down_m": -500 + 0 * t,
    ...          "own_vn_mps": 50 + 0 * t, "own_ve_mps": 0 * t, "own_vd_mps": 0 * t}
    >>> ds = xr.Dataset({k: ("time", v) for k, v in state.items()}, coords={"time": t})
    >>> own = ownship_from_frames(ds, "run.zarr")
    >>> own["own_north_m"].tolist(), own.attrs["navigation_source"]
    ([0.0, 50.0, 100.0], 'truth')
    >>> ownship_from_frames(ds.drop_vars("own_vd_mps"), "run.zarr")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: run.zarr: no own-ship state (missing variable(s) ['own_vd_mps'])
    """
    state = navigation_state(ds, source)
    missing = [c for c in OWNSHIP_COLUMNS[1:] if state is None or c not in state]
    if state is None or missing:
        raise InputError(f"{source}: no own-ship state (missing variable(s) {missing})")
    keep = ["time_s", *OWNSHIP_COLUMNS[1:], *(c for c in OPTIONAL_OWNSHIP_COLUMNS if c in state)]
    table = state[keep].copy()
    table.attrs["navigation_source"] = state.attrs["navigation_source"]
    # The own-ship's state at every frame: NaN (interpolated through silently) and 1e308 (inf in the
    # conflict geometry) are refused naming the row, as in a tracks table.
    for name in OWNSHIP_COLUMNS[1:]:
        values = finite_column(table.reset_index(drop=True), name, source)
        limit, unit = STATE_LIMITS[name[-1]]
        check_within(values, limit, unit, source, name, "not the own-ship's state")
    return table


def truth_tracks(ds: xr.Dataset, visible_only: bool = True) -> pd.DataFrame:
    """A tracks table made from the intruder truth of a simulated run (ids = target index).

    Examples
    --------
    >>> truth_tracks(xr.Dataset()).columns.tolist()[:3]
    ['time_s', 'track_id', 'north_m']
    """
    names = ["north_m", "east_m", "down_m", "vn_mps", "ve_mps", "vd_mps"]
    if "tgt_north_m" not in ds:
        return pd.DataFrame({c: pd.Series(dtype=float) for c in TRACK_COLUMNS})
    t = frame_times_s(ds)
    n_t, n_tgt = ds["tgt_north_m"].shape
    cols = {"time_s": np.repeat(t, n_tgt), "track_id": np.tile(np.arange(n_tgt), n_t)}
    for c in names:
        cols[c] = np.asarray(ds[f"tgt_{c}"].values, float).ravel()
    df = pd.DataFrame(cols)
    if visible_only and "tgt_visible" in ds:
        df = df[np.asarray(ds["tgt_visible"].values, bool).ravel()]
    return df.reset_index(drop=True)
