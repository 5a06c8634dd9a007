"""DAA tables taken from a frames run: the own-ship state and, for a simulated run, the truth as tracks.

Both follow :mod:`skyradar.daa.tables`.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import xarray as xr

from skyradar.daa.tables import OPTIONAL_OWNSHIP_COLUMNS, OWNSHIP_COLUMNS, TRACK_COLUMNS
from skyradar.errors import InputError
from skyradar.io.frames_model import frame_times_s

__all__ = ["has_ownship", "ownship_from_frames", "truth_tracks"]


def has_ownship(ds: xr.Dataset) -> bool:
    """Whether a frames run holds the own-ship state (a simulated run does, a recording may not).

    Examples
    --------
    >>> has_ownship(xr.Dataset())
    False
    """
    return all(c in ds for c in OWNSHIP_COLUMNS[1:])


def ownship_from_frames(ds: xr.Dataset, source: str = "frames") -> pd.DataFrame:
    """Own-ship truth of a frames run as a table (:mod:`skyradar.daa.tables`)."""
    missing = [c for c in OWNSHIP_COLUMNS[1:] if c not in ds]
    if missing:
        raise InputError(f"{source}: no own-ship state (missing variable(s) {missing})")
    cols = {"time_s": frame_times_s(ds)}
    for name in OWNSHIP_COLUMNS[1:] + [c for c in OPTIONAL_OWNSHIP_COLUMNS if c in ds]:
        cols[name] = np.asarray(ds[name].values, float)
    return pd.DataFrame(cols)


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
