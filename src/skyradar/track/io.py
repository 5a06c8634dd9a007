"""Reading detections tables and simulated truth for the tracker, with clear errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.io.checks import MAX_TIME_S, check_frame_times
from skyradar.io.frames_model import frame_times_s
from skyradar.io.tables import check_within, finite_column, read_table
from skyradar.rx_layouts import MAX_TX

__all__ = [
    "REQUIRED_DETECTION_COLUMNS",
    "validate_detections",
    "validate_ownship",
    "read_detections",
    "truth_from_frames",
    "Truth",
]

REQUIRED_DETECTION_COLUMNS = ("time_s", "range_m", "radial_velocity_mps")
# What a detection may hold: times within 1e10 s (unix seconds fit), ranges and positions within
# 10 000 km, radial velocities within 10 km/s.
_DETECTION_LIMITS = {
    "time_s": (MAX_TIME_S, "s"),
    "range_m": (1.0e7, "m"),
    "radial_velocity_mps": (1.0e4, "m/s"),
    "north_m": (1.0e7, "m"),
    "east_m": (1.0e7, "m"),
    "down_m": (1.0e7, "m"),
    "other_north_m": (1.0e7, "m"),
    "other_east_m": (1.0e7, "m"),
    "other_down_m": (1.0e7, "m"),
}
_OWNSHIP_LIMITS = {"m": (1.0e7, "m"), "mps": (1.0e4, "m/s")}  # by the unit ending the column's name
# Directions a detection may hold, each within its bound or NaN (not known): angles in radians, and
# the components of the antenna's right axis, a unit vector.
_DIRECTION_LIMITS = {
    "azimuth_rad": (np.pi, "rad"),
    "elevation_rad": (np.pi / 2, "rad"),
    "other_azimuth_rad": (np.pi, "rad"),
    "other_elevation_rad": (np.pi / 2, "rad"),
    "right_axis_north": (1.0 + 1e-6, ""),
    "right_axis_east": (1.0 + 1e-6, ""),
    "right_axis_down": (1.0 + 1e-6, ""),
}


def validate_detections(df: pd.DataFrame, source: str = "detections") -> pd.DataFrame:
    """Check a detections table: required columns, finite values, ranges >= 0, time never going backwards.

    Examples
    --------
    >>> df = pd.DataFrame({"time_s": [0.0, 1.0], "range_m": [10.0, 11.0], "radial_velocity_mps": [1.0, 1.0]})
    >>> len(validate_detections(df))
    2
    """
    missing = [c for c in REQUIRED_DETECTION_COLUMNS if c not in df.columns]
    if missing:
        raise InputError(f"{source}: missing column(s) {missing} (have {list(df.columns)})")
    required = {col: finite_column(df, col, source) for col in REQUIRED_DETECTION_COLUMNS}
    rng = required["range_m"]
    if (rng < 0).any():  # a range is a distance: a negated column would be tracked behind the radar
        i = int(np.flatnonzero(rng < 0)[0])
        raise InputError(f"{source}: field 'range_m' is negative at row {i} ({rng[i]:g} m); a range is >= 0")
    # Every numeric field within what a radar measures (1e308 is finite, but no radar measures it).
    # The optional ones (a position, a direction) may be NaN, not known; text is refused, never read
    # as NaN: a position column of words would silently become a table without positions.
    limits = {col: (*bound, "not a radar measurement") for col, bound in _DETECTION_LIMITS.items()}
    limits |= {col: (*bound, "not a direction") for col, bound in _DIRECTION_LIMITS.items()}
    for col, (limit, unit, meaning) in limits.items():
        if col in required:
            check_within(required[col], limit, unit, source, col, meaning)
        elif col in df.columns:
            values = finite_column(df, col, source, allow_nan=True)
            check_within(values, limit, unit, source, col, meaning)
            df = df.assign(**{col: values})
    if "other_residue" in df.columns:  # a MIMO radar's runner-up residue: -1 or NaN (none) to MAX_TX - 1
        residue = np.nan_to_num(finite_column(df, "other_residue", source, allow_nan=True), nan=-1.0)
        bad = np.flatnonzero((residue != np.round(residue)) | (residue < -1) | (residue > MAX_TX - 1))
        if bad.size:
            i = int(bad[0])
            raise InputError(
                f"{source}: field 'other_residue' is {residue[i]:g} at row {i}: a residue is a whole "
                f"number from 0 to {MAX_TX - 1} (-1: none)"
            )
        df = df.assign(other_residue=residue.astype(np.int64))
    t = df["time_s"].to_numpy(float)
    back = np.flatnonzero(t[1:] < t[:-1])
    if back.size:
        i = int(back[0]) + 1
        raise InputError(f"{source}: field 'time_s' goes backwards at row {i} ({t[i - 1]} -> {t[i]})")
    return df


def validate_ownship(df: pd.DataFrame, columns: tuple[str, ...], source: str = "ownship") -> pd.DataFrame:
    """Check an own-ship table: ``columns`` present, at least one row, finite, time strictly increasing.

    Examples
    --------
    >>> own = pd.DataFrame({"time_s": [0.0, 1.0], "own_north_m": [0.0, 40.0]})
    >>> len(validate_ownship(own, ("time_s", "own_north_m")))
    2
    """
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise InputError(f"{source}: missing column(s) {missing} (have {list(df.columns)})")
    if len(df) == 0:
        raise InputError(f"{source}: no rows; the own-ship state is needed at every frame")
    for col in columns:
        values = finite_column(df, col, source)
        limit, unit = _OWNSHIP_LIMITS.get(col.rsplit("_", 1)[-1], (np.inf, ""))
        check_within(values, limit, unit, source, col, "not the own-ship's state")
    check_frame_times(df[columns[0]].to_numpy(float), source, field=columns[0], index_name="row")
    return df


def read_detections(path: str | Path) -> pd.DataFrame:
    """Read and validate a detections table (Parquet or CSV).

    Parameters
    ----------
    path : str or Path
        The table, with at least ``time_s`` (s), ``range_m`` (m) and ``radial_velocity_mps`` (m/s).

    Returns
    -------
    DataFrame
        The checked table; InputError naming ``path`` when a column is missing or a value is not a
        finite number within bounds.

    Examples
    --------
    >>> import os, tempfile
    >>> det = pd.DataFrame({"time_s": [0.0, 0.1], "range_m": [1000.0, 995.0], "radial_velocity_mps": -50.0})
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = os.path.join(tmp, "det.csv")
    ...     det.to_csv(path, index=False)
    ...     back = read_detections(path)
    ...     det.drop(columns="range_m").to_csv(path, index=False)
    ...     read_detections(path)
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: .../det.csv: missing column(s) ['range_m'] (have ...)
    >>> back.equals(det)
    True
    """
    df = read_table(path, required=REQUIRED_DETECTION_COLUMNS)
    return validate_detections(df, str(path))


def radar_config_from_attrs(df: pd.DataFrame) -> RadarConfig:
    """The RadarConfig stored in a table's attrs (``radar_config`` JSON), else the thesis prototype."""
    text = df.attrs.get("radar_config") if hasattr(df, "attrs") else None
    if text:
        try:
            return RadarConfig.from_json(text if isinstance(text, str) else str(text))
        except Exception:  # noqa: BLE001 - unreadable metadata falls back to the documented default
            pass
    return RadarConfig.prototype_2022()


class Truth:
    """Intruder truth on a time grid: range, radial velocity (not aliased), visibility.

    Attributes
    ----------
    time_s : ndarray, shape (n_time,)
    range_m, radial_velocity_mps : ndarray, shape (n_time, n_target)
    visible : ndarray of bool, shape (n_time, n_target)
    names : list of str
    snr_db : ndarray, shape (n_time, n_target), or None
        Expected SNR (radar equation, no noise), when the run has it.

    Parameters
    ----------
    time_s : ndarray, shape (n_time,)
        Frame times, s.
    range_m : ndarray, shape (n_time, n_target)
        Target ranges, m.
    radial_velocity_mps : ndarray, shape (n_time, n_target)
        Target radial velocities, not aliased, m/s.
    visible : ndarray of bool, shape (n_time, n_target)
        Whether each target is in the beam.
    names : list of str, optional
        Target names (default ``T0, T1, ...``).
    snr_db : ndarray, shape (n_time, n_target), optional
        Expected SNR, dB.

    Examples
    --------
    >>> t = np.arange(4.0)
    >>> truth = Truth(t, np.column_stack([1000.0 - 50.0 * t, 3000.0 + 0 * t]), np.tile([-50.0, 0.0], (4, 1)),
    ...               np.ones((4, 2), bool))
    >>> truth.names, truth.range_m[-1].tolist(), truth.snr_db is None
    (['T0', 'T1'], [850.0, 3000.0], True)
    """

    def __init__(
        self,
        time_s: np.ndarray,
        range_m: np.ndarray,
        radial_velocity_mps: np.ndarray,
        visible: np.ndarray,
        names: list[str] | None = None,
        snr_db: np.ndarray | None = None,
    ) -> None:
        self.time_s = np.asarray(time_s, float)
        self.range_m = np.asarray(range_m, float)
        self.radial_velocity_mps = np.asarray(radial_velocity_mps, float)
        self.visible = np.asarray(visible, bool)
        self.snr_db = None if snr_db is None else np.asarray(snr_db, float)
        n = self.range_m.shape[1] if self.range_m.ndim == 2 else 0
        self.names = list(names) if names is not None else [f"T{i}" for i in range(n)]


def truth_from_frames(path: str | Path) -> tuple[Truth, RadarConfig]:
    """Intruder truth and radar config from a simulated frames store (Zarr).

    With several radar heads, a target is visible in a frame when it is in any head's beam, and
    its range, radial velocity and SNR are those of the head that sees it strongest (the fused
    tracker refers every head's range to the aircraft's reference point, lever arms of metres
    apart); the radar config is the first head's.
    """
    from skyradar.io.frames import open_frames
    from skyradar.io.frames_heads import store_heads

    stored = store_heads(path)
    heads: list[str | None] = [None] if stored is None else list(stored)
    sets = [_head_truth(open_frames(path, head=h) if h else open_frames(path), path) for h in heads]
    best = np.argmax(
        np.stack(
            [np.where(s["tgt_visible"], np.nan_to_num(s["tgt_snr_db"], nan=-np.inf), -np.inf) for s in sets]
        ),
        axis=0,
    )
    pick = {k: np.choose(best, [s[k] for s in sets]) for k in sets[0] if k.startswith("tgt_")}
    pick["tgt_visible"] = np.any([s["tgt_visible"] for s in sets], axis=0)
    first = sets[0]
    truth = Truth(
        first["time_s"],
        pick["tgt_range_m"],
        pick["tgt_radial_velocity_mps"],
        pick["tgt_visible"],
        first["names"],
        pick["tgt_snr_db"],
    )
    return truth, first["config"]


def _head_truth(ds, path) -> dict:
    """One head's truth arrays (``tgt_snr_db`` NaN when the run has none), times, names, config."""
    from skyradar.io.frames import radar_config_of

    needed = ["tgt_range_m", "tgt_radial_velocity_mps", "tgt_visible"]
    missing = [v for v in needed if v not in ds]
    if missing:
        raise InputError(
            f"{path}: no intruder truth (missing variable(s) {missing}); evaluate needs a simulated run"
        )
    out = {v: ds[v].values for v in needed}
    out["tgt_visible"] = out["tgt_visible"].astype(bool)
    shape = out["tgt_visible"].shape
    out["tgt_snr_db"] = ds["tgt_snr_db"].values if "tgt_snr_db" in ds else np.full(shape, np.nan)
    names = [str(n) for n in ds["target"].values]
    return out | {"time_s": frame_times_s(ds), "names": names, "config": radar_config_of(ds, str(path))}
