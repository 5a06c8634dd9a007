"""A frames run's own-ship and intruder states as plain tables (``skyradar export``).

The own-ship table holds, per frame, the navigation solution the chain used (``nav_*``: GNSS and
AHRS with errors) beside the simulator's truth (``own_*``), so that anyone can measure what a
navigation error did. The intruder table holds the intruder truth (``tgt_*``) in long form, one
row per frame and intruder; a store of several radar heads adds each head's own view
(``tgt_visible``, ``tgt_snr_db``... whatever differs between heads) as ``<variable>@<head>``
columns; the unsuffixed columns are the first head's.
Both carry ``time_s`` (s since the run's start) and ``utc`` (the instant, from ``start_time``).
:data:`OWNSHIP_EXPORT_COLUMNS` and :data:`INTRUDER_EXPORT_COLUMNS` give each column's unit and meaning.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr

from skyradar.io.frames_model import OWNSHIP_VARS, TARGET_VARS, frame_times_s, start_time_of

__all__ = [
    "OWNSHIP_EXPORT_COLUMNS",
    "INTRUDER_EXPORT_COLUMNS",
    "ownship_table",
    "intruder_table",
    "export_paths",
]


def _documented(variables: dict[str, tuple[str, str]], names) -> dict[str, str]:
    """Store variables as table columns: "unit; meaning; optional: when" (skyradar.io.table_columns)."""
    units = {"degree": "deg", "1": "-"}
    stored = "optional: the run stores the variable (a simulated run stores every one)"
    return {n: f"{units.get(variables[n][0], variables[n][0])}; {variables[n][1]}; {stored}" for n in names}


_CLOCK_COLUMNS = {
    "time_s": "s; elapsed time of the frame since the run's start_time",
    "utc": "-; UTC instant of the frame (start_time + time_s)",
}
# The own-ship table of ``skyradar export``: the navigation solution, then the truth, each in name order.
OWNSHIP_EXPORT_COLUMNS: dict[str, str] = _CLOCK_COLUMNS | _documented(
    OWNSHIP_VARS, sorted(OWNSHIP_VARS, key=lambda n: (not n.startswith("nav_"), n))
)
# The intruder table of ``skyradar export``, one row per frame and intruder.
INTRUDER_EXPORT_COLUMNS: dict[str, str] = (
    _CLOCK_COLUMNS
    | {"target": "-; the intruder's name", "target_index": "-; the intruder's index in the run, from 0"}
    | _documented(TARGET_VARS, TARGET_VARS)
    | {
        "<variable>@<head>": "as <variable>; <variable> as the radar head <head> sees it; optional: a run of "
        "several heads, for every tgt_ variable that differs between them (the unsuffixed column is the "
        "first head's)"
    }
)


def _clock(ds: xr.Dataset) -> dict[str, np.ndarray]:
    t = frame_times_s(ds)
    utc = start_time_of(ds) + (t * 1e9).round().astype("timedelta64[ns]")
    return {"time_s": t, "utc": pd.DatetimeIndex(utc).tz_localize("UTC")}


def ownship_table(ds: xr.Dataset) -> pd.DataFrame:
    """Per-frame own-ship navigation (``nav_*``) and truth (``own_*``) of a frames Dataset.

    Examples
    --------
    >>> ds = xr.Dataset({"own_north_m": ("time", [0.0, 9.0]), "nav_north_m": ("time", [1.0, 8.0])},
    ...                 coords={"time": [0.0, 0.1]})
    >>> ownship_table(ds).drop(columns="utc").to_dict("list")
    {'time_s': [0.0, 0.1], 'nav_north_m': [1.0, 8.0], 'own_north_m': [0.0, 9.0]}
    """
    cols = _clock(ds)
    for prefix in ("nav_", "own_"):
        for name in sorted(str(v) for v in ds.data_vars):
            if name.startswith(prefix) and ds[name].dims == ("time",):
                cols[name] = np.asarray(ds[name].values)
    return pd.DataFrame(cols)


def intruder_table(ds: xr.Dataset, head_views: dict[str, xr.Dataset] | None = None) -> pd.DataFrame:
    """Intruder truth (``tgt_*``) in long form: one row per frame and intruder.

    ``head_views`` (head name to that head's Dataset, every head) adds the variables that differ
    between heads as ``<variable>@<head>`` columns for every head.

    Examples
    --------
    >>> ds = xr.Dataset({"tgt_north_m": (("time", "target"), [[1.0, 2.0], [3.0, 4.0]])},
    ...                 coords={"time": [0.0, 0.1], "target": ["A", "B"]})
    >>> intruder_table(ds)[["time_s", "target", "tgt_north_m"]].values.tolist()
    [[0.0, 'A', 1.0], [0.0, 'B', 2.0], [0.1, 'A', 3.0], [0.1, 'B', 4.0]]
    """
    names = [str(v) for v in ds.data_vars if str(v).startswith("tgt_") and ds[v].dims == ("time", "target")]
    if not names:
        return pd.DataFrame({"time_s": pd.Series(dtype=float), "target": pd.Series(dtype=str)})
    n_t, n_tgt = ds[names[0]].shape
    clock = _clock(ds)
    cols = {"time_s": np.repeat(clock["time_s"], n_tgt), "utc": np.repeat(clock["utc"], n_tgt)}
    targets = ds["target"].values if "target" in ds.coords else np.array([f"T{i}" for i in range(n_tgt)])
    cols["target"] = np.tile(np.array([str(v) for v in targets], dtype=object), n_t)  # any string dtype
    cols["target_index"] = np.tile(np.arange(n_tgt), n_t)
    for name in names:
        cols[name] = np.asarray(ds[name].values).ravel()
    views = head_views or {}

    def differs(name: str, view: xr.Dataset) -> bool:
        return name in view and not np.array_equal(view[name].values, ds[name].values, equal_nan=True)

    # The variables some head sees otherwise (azimuth, SNR, visibility...), for every head.
    per_head = [n for n in names if any(differs(n, v) for v in views.values())]
    for head, view in views.items():
        for name in per_head:
            if name in view:
                cols[f"{name}@{head}"] = np.asarray(view[name].values).ravel()
    return pd.DataFrame(cols)


def export_paths(output: str | Path) -> tuple[Path, Path]:
    """(own-ship table, intruder table) for ``output``: a folder gets ``ownship.parquet`` and
    ``intruders.parquet``; a ``NAME.parquet`` file is the own-ship table, ``NAME.intruders.parquet``
    beside it the intruders.

    Examples
    --------
    >>> [p.as_posix() for p in export_paths("out/run1")]
    ['out/run1/ownship.parquet', 'out/run1/intruders.parquet']
    >>> [p.name for p in export_paths("run1.parquet")]
    ['run1.parquet', 'run1.intruders.parquet']
    """
    output = Path(output)
    if output.suffix.lower() == ".parquet":
        return output, output.with_name(output.name[: -len(".parquet")] + ".intruders.parquet")
    return output / "ownship.parquet", output / "intruders.parquet"
