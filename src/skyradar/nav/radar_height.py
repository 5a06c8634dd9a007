"""The ch5 radar height above the ground in place of the GNSS height above the terrain database.

The navigation solution's ``nav_height_agl_m`` is the GNSS altitude minus a terrain database under
the GNSS position: it carries the GNSS vertical error and any database error. A downward-looking
radar measures the height above the ground directly (:func:`skyradar.nav.flight_state.estimate_run`,
ch5). :func:`with_radar_height` puts that estimate into a frames Dataset's navigation state, so
process (ground discrimination, clutter prediction) and alert (terrain advice) use it; frames the
estimator did not trust keep the GNSS height.

Examples
--------
>>> import pandas as pd
>>> ds = xr.Dataset({"nav_height_agl_m": ("time", [1000.0] * 3)}, coords={"time": [0.0, 1.0, 2.0]})
>>> state = pd.DataFrame({"time_s": [0.0, 1.0, 2.0], "h_m": [990.0, 991.0, 992.0],
...                       "used_by_filter": [True, False, True]})
>>> with_radar_height(ds, state)["nav_height_agl_m"].values.tolist()
[990.0, 1000.0, 992.0]
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import xarray as xr

from skyradar.errors import InputError
from skyradar.io.frames_model import frame_times_s

__all__ = ["with_radar_height"]


def with_radar_height(ds: xr.Dataset, state: pd.DataFrame, source: str = "state") -> xr.Dataset:
    """``ds`` with ``nav_height_agl_m`` taken from a flight-state table where the filter used the frame.

    Parameters
    ----------
    ds : xr.Dataset
        Frames Dataset with a navigation solution (``nav_height_agl_m``).
    state : DataFrame
        :func:`skyradar.nav.flight_state.estimate_run` output: ``time_s``, ``h_m`` and, when
        present, ``used_by_filter`` (frames without it keep the GNSS height). Rows are matched to
        frames by time (within half a frame).
    source : str
        Name of the state table, for errors.

    Returns
    -------
    xr.Dataset
        A shallow copy with the new ``nav_height_agl_m`` and ``attrs["nav_height_source"]``
        (``"radar"``); the ``own_*`` truth is untouched.

    Raises
    ------
    InputError
        When ``ds`` has no ``nav_height_agl_m`` or ``state`` lacks ``time_s`` or ``h_m``.

    Examples
    --------
    Frames 0.5 s apart: each takes the nearest trusted estimate within 0.25 s (half a frame). The
    frame at 0.5 s is 0.3 s from both trusted ones and keeps its GNSS height; the frame at 1.0 s
    takes the estimate at 0.8 s, as the filter does not use the one at 1.0 s.

    >>> ds = xr.Dataset({"nav_height_agl_m": ("time", [500.0, 500.0, 500.0]),
    ...                  "own_height_agl_m": ("time", [480.0, 481.0, 482.0])},
    ...                 coords={"time": [0.0, 0.5, 1.0]})
    >>> state = pd.DataFrame({"time_s": [0.2, 0.8, 1.0], "h_m": [478.0, 479.0, 470.0],
    ...                       "used_by_filter": [True, True, False]})
    >>> out = with_radar_height(ds, state)
    >>> out["nav_height_agl_m"].values.tolist(), out.attrs["nav_height_source"]
    ([478.0, 500.0, 479.0], 'radar')
    >>> out["own_height_agl_m"].values.tolist() == ds["own_height_agl_m"].values.tolist()
    True
    """
    if "nav_height_agl_m" not in ds:
        raise InputError(f"{source}: the run has no navigation height (nav_height_agl_m) to replace")
    missing = [c for c in ("time_s", "h_m") if c not in state]
    if missing:
        raise InputError(f"{source}: missing column(s) {missing}")
    times = frame_times_s(ds)
    t = state["time_s"].to_numpy(float)
    h = state["h_m"].to_numpy(float)
    ok = np.isfinite(t) & np.isfinite(h)
    if "used_by_filter" in state:
        ok &= state["used_by_filter"].to_numpy(bool)
    half_frame = 0.5 * float(np.median(np.diff(times))) if times.size > 1 else 0.5
    height = np.asarray(ds["nav_height_agl_m"].values, float).copy()
    if ok.any():
        order = np.argsort(t[ok], kind="stable")
        t_ok, h_ok = t[ok][order], h[ok][order]
        # Nearest trusted estimate of each frame; used only within half a frame of it.
        right = np.clip(np.searchsorted(t_ok, times), 0, t_ok.size - 1)
        left = np.clip(right - 1, 0, None)
        nearest = np.where(np.abs(t_ok[left] - times) <= np.abs(t_ok[right] - times), left, right)
        near = np.abs(t_ok[nearest] - times) <= half_frame
        height[near] = h_ok[nearest[near]]
    out = ds.copy()
    out["nav_height_agl_m"] = ("time", height, dict(ds["nav_height_agl_m"].attrs))
    out.attrs = dict(ds.attrs) | {"nav_height_source": "radar"}
    return out
