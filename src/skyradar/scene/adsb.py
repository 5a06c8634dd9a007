"""Read aircraft tracks (ADS-B history, GPS logs) from CSV, Parquet or JSON into trajectories.

Two column conventions are understood:

OpenSky / ``traffic`` convention (aviation units)
    ``timestamp`` (unix seconds or ISO 8601 datetime), ``latitude``, ``longitude`` [deg],
    ``altitude`` [ft], ``groundspeed`` [kt], ``track`` [deg from north, clockwise],
    ``vertical_rate`` [ft/min, positive up], optional ``icao24`` and ``callsign``.
SI convention
    ``time_s`` (or ``timestamp``), ``latitude``, ``longitude`` [deg], ``alt_m`` [m],
    ``vn``, ``ve``, ``vd`` [m/s, local NED at the aircraft].

OpenSky Impala state vectors (``time``, ``lat``, ``lon``, ``geoaltitude`` or ``baroaltitude``
[m], ``velocity`` [m/s], ``heading`` [deg], ``vertrate`` [m/s]) are renamed to the SI
convention first.

Altitudes are taken as heights above the WGS84 ellipsoid (the geoid undulation is common to
terrain and aircraft over a scenario's extent, see :mod:`skyradar.scene.trajectories`). When
velocity columns are absent, or a row has NaN velocity, velocities come from the positions
(``np.gradient`` in the NED frame). Times are stored relative to the file's first timestamp
unless ``time_zero_s`` is given; the unix time of zero is kept as ``Trajectory.epoch_s``.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from skyradar.errors import InputError
from skyradar.geo import geodetic_to_ned

__all__ = ["FT_M", "KT_MPS", "FPM_MPS", "read_track_table", "read_trajectory", "read_trajectories"]

FT_M = 0.3048  # international foot, m (exact)
KT_MPS = 1852.0 / 3600.0  # knot, m/s (exact)
FPM_MPS = FT_M / 60.0  # foot per minute, m/s (exact)
# Plausibility limits for aircraft tracks from files: a GA sensor meets nothing faster than Mach 3
# (a bad ADS-B message or a unit mix-up is), nor anything below the Dead Sea or above 30 km.
MAX_SPEED_MPS = 3 * 343.0
ALT_LIMITS_M = (-500.0, 30_000.0)
_OPENSKY_VELOCITY = ("groundspeed", "track", "vertical_rate")
_SI_VELOCITY = ("vn", "ve", "vd")


def read_track_table(path: str | Path) -> pd.DataFrame:
    """Load a CSV, Parquet or JSON (records or JSON lines) file as a DataFrame, unchanged."""
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: no such file")
    suffixes = [s.lower() for s in path.suffixes]
    kind = (
        suffixes[-2]
        if suffixes and suffixes[-1] in (".gz", ".bz2", ".xz", ".zst") and len(suffixes) > 1
        else None
    )
    kind = kind or (suffixes[-1] if suffixes else "")
    try:
        if kind in (".csv", ".txt"):
            # Addresses and callsigns are text: keep leading zeros ("008123").
            return pd.read_csv(path, dtype={"icao24": str, "callsign": str})
        if kind in (".parquet", ".pq"):
            return pd.read_parquet(path)
        if kind in (".json", ".jsonl", ".ndjson"):
            return _read_json(path, lines=kind != ".json")
    except InputError:
        raise
    except Exception as exc:  # noqa: BLE001 - any reader failure becomes one clear line
        raise InputError(f"{path}: cannot read as {kind[1:]} ({type(exc).__name__}: {exc})") from exc
    raise InputError(f"{path}: unknown file type '{kind or path.name}' (use .csv, .parquet or .json)")


def _read_json(path: Path, lines: bool) -> pd.DataFrame:
    text = path.read_text()
    data = [json.loads(line) for line in text.splitlines() if line.strip()] if lines else json.loads(text)
    if isinstance(data, dict) and data and all(isinstance(v, list) for v in data.values()):
        return pd.DataFrame(data)  # column orientation: {"latitude": [...], ...}
    if not isinstance(data, list) or not all(isinstance(row, dict) for row in data):
        raise InputError(f"{path}: JSON must be a list of records (objects), got {type(data).__name__}")
    return pd.DataFrame.from_records(data)


def _normalise(df: pd.DataFrame) -> pd.DataFrame:
    """Map OpenSky Impala state-vector columns onto the SI convention."""
    cols = set(df.columns)
    if "latitude" in cols or not {"lat", "lon"} <= cols:
        return df
    out = df.rename(columns={"lat": "latitude", "lon": "longitude", "time": "timestamp"})
    alt = next((c for c in ("geoaltitude", "baroaltitude") if c in cols), None)
    if alt is not None and "alt_m" not in cols:
        out["alt_m"] = out[alt]
    if {"velocity", "heading", "vertrate"} <= cols and not {"vn", "ve", "vd"} & cols:
        speed = pd.to_numeric(out["velocity"], errors="coerce")
        heading = np.radians(pd.to_numeric(out["heading"], errors="coerce"))
        out["vn"], out["ve"] = speed * np.cos(heading), speed * np.sin(heading)
        out["vd"] = -pd.to_numeric(out["vertrate"], errors="coerce")
    return out


def _time_seconds(path: Path, df: pd.DataFrame) -> tuple[str, np.ndarray]:
    """(column, seconds) from ``time_s`` or ``timestamp`` (unix seconds or ISO datetimes)."""
    col = "time_s" if "time_s" in df.columns else "timestamp"
    if col not in df.columns:
        raise InputError(
            f"{path}: missing required field 'timestamp' (or 'time_s'); columns are {list(df.columns)}"
        )
    raw = df[col]
    if pd.api.types.is_datetime64_any_dtype(raw):
        parsed = raw
    elif pd.api.types.is_numeric_dtype(raw):
        return col, raw.to_numpy(dtype=float)
    else:
        numeric = pd.to_numeric(raw, errors="coerce")
        if numeric.notna().all():
            return col, numeric.to_numpy(dtype=float)
        parsed = pd.to_datetime(raw, errors="coerce", utc=True, format="ISO8601")
        bad = parsed.isna() & raw.notna()
        if bad.any():
            row = int(np.nonzero(bad.to_numpy())[0][0])
            raise InputError(f"{path}: field '{col}' is not a time at row {row} ({raw.iloc[row]!r})")
    if parsed.dt.tz is None:
        parsed = parsed.dt.tz_localize("UTC")
    seconds = (parsed - pd.Timestamp(0, tz="UTC")).dt.total_seconds().to_numpy(dtype=float)
    return col, np.where(parsed.isna().to_numpy(), np.nan, seconds)


def _column(
    path: Path, df: pd.DataFrame, name: str, rows: np.ndarray, required: bool = True
) -> np.ndarray | None:
    if name not in df.columns:
        if required:
            raise InputError(f"{path}: missing required field '{name}'; columns are {list(df.columns)}")
        return None
    values = pd.to_numeric(df[name], errors="coerce").to_numpy(dtype=float)
    if required:
        bad = ~np.isfinite(values)
        if bad.any():
            i = int(np.nonzero(bad)[0][0])
            raise InputError(
                f"{path}: field '{name}' is NaN or not a number at row {rows[i]} ({df[name].iloc[i]!r})"
            )
    return values


def _check_times(path: Path, col: str, t: np.ndarray, raw: pd.Series, label: str) -> None:
    if t.size < 2:
        raise InputError(
            f"{path}: field '{col}' has {t.size} row(s){label}; a trajectory needs at least 2 points"
        )
    steps = np.diff(t)
    if np.any(steps <= 0):
        i = int(np.nonzero(steps <= 0)[0][0]) + 1
        what = "repeats" if steps[i - 1] == 0 else "goes backwards"
        before, after = (v.item() if hasattr(v, "item") else v for v in (raw.iloc[i - 1], raw.iloc[i]))
        raise InputError(f"{path}: field '{col}' {what} at row {raw.index[i]} ({before} -> {after}){label}")


def _local_velocity(path: Path, df: pd.DataFrame, rows: np.ndarray) -> np.ndarray | None:
    """Velocities (n, 3) in the local NED frame, NaN where a row has none; None without columns."""
    if all(c in df.columns for c in _SI_VELOCITY):
        return np.stack([_column(path, df, c, rows, required=False) for c in _SI_VELOCITY], axis=-1)
    if all(c in df.columns for c in _OPENSKY_VELOCITY):
        gs, trk, vr = (_column(path, df, c, rows, required=False) for c in _OPENSKY_VELOCITY)
        gs = gs * KT_MPS
        trk = np.radians(trk)
        return np.stack([gs * np.cos(trk), gs * np.sin(trk), -vr * FPM_MPS], axis=-1)
    return None


def _check_speed(path: Path, rows: np.ndarray, t: np.ndarray, pos: np.ndarray, label: str) -> None:
    """Refuse a jump between consecutive rows faster than :data:`MAX_SPEED_MPS` (NED chords are exact)."""
    speed = np.linalg.norm(np.diff(pos, axis=0), axis=1) / np.diff(t)
    fast = np.flatnonzero(speed > MAX_SPEED_MPS)
    if fast.size:
        i = int(fast[0]) + 1
        raise InputError(
            f"{path}: fields 'latitude', 'longitude', altitude at row {rows[i]}: a jump of "
            f"{speed[i - 1]:.0f} m/s from row {rows[i - 1]} (above Mach 3, {MAX_SPEED_MPS:.0f} m/s){label}"
        )


def _one_trajectory(
    path: Path,
    df: pd.DataFrame,
    origin: tuple[float, float, float] | None,
    name: str,
    time_zero_s: float | None,
    label: str = "",
):
    from skyradar.scene.trajectories import Trajectory, origin_to_local_rotation

    rows = df.index.to_numpy()
    col, t = _time_seconds(path, df)
    bad = ~np.isfinite(t)
    if bad.any():
        i = int(np.nonzero(bad)[0][0])
        raise InputError(f"{path}: field '{col}' is NaN at row {rows[i]}{label}")
    _check_times(path, col, t, df[col], label)
    lat = _column(path, df, "latitude", rows)
    lon = _column(path, df, "longitude", rows)
    if "alt_m" in df.columns:
        alt = _column(path, df, "alt_m", rows)
    else:
        alt = _column(path, df, "altitude", rows) * FT_M
    for field_name, values, limit in (("latitude", lat, 90.0), ("longitude", lon, 360.0)):
        out = np.abs(values) > limit
        if out.any():
            i = int(np.nonzero(out)[0][0])
            raise InputError(
                f"{path}: field '{field_name}' out of range at row {rows[i]} ({values[i]}){label}"
            )
    alt_field = "alt_m" if "alt_m" in df.columns else "altitude"
    low = np.flatnonzero((alt < ALT_LIMITS_M[0]) | (alt > ALT_LIMITS_M[1]))
    if low.size:
        i = int(low[0])
        raw = df[alt_field].iloc[i]
        raw = raw.item() if hasattr(raw, "item") else raw
        raise InputError(
            f"{path}: field '{alt_field}' out of range at row {rows[i]} ({raw!r}; "
            f"{alt[i]:.0f} m is outside [{ALT_LIMITS_M[0]:g}, {ALT_LIMITS_M[1]:g}] m){label}"
        )
    origin = (
        (float(lat[0]), float(lon[0]), float(alt[0])) if origin is None else tuple(float(v) for v in origin)
    )
    pos = geodetic_to_ned(lat, lon, alt, *origin)
    _check_speed(path, rows, t, pos, label)
    zero = float(t[0]) if time_zero_s is None else float(time_zero_s)
    t_rel = t - zero
    derived = np.gradient(pos, t_rel, axis=0, edge_order=2 if t.size > 2 else 1)
    local = _local_velocity(path, df, rows)
    if local is None:
        vel = derived
    else:
        vel = np.einsum("nji,nj->ni", origin_to_local_rotation(lat, lon, origin[0], origin[1]), local)
        missing = ~np.all(np.isfinite(vel), axis=1)
        vel[missing] = derived[missing]
    epoch = zero if col == "timestamp" else float("nan")
    return Trajectory.from_states(t_rel, pos, vel, origin=origin, name=name, epoch_s=epoch)


def read_trajectory(
    path: str | Path,
    origin: tuple[float, float, float] | None = None,
    name: str | None = None,
    time_zero_s: float | None = None,
):
    """Read one aircraft's track from a CSV, Parquet or JSON file.

    Parameters
    ----------
    path : str or Path
        ``.csv``, ``.parquet`` or ``.json`` (list of records; ``.jsonl`` for JSON lines).
    origin : (lat_deg, lon_deg, alt_m), optional
        NED frame origin; defaults to the first point of the track.
    name : str, optional
        Trajectory name; defaults to the callsign, the icao24 address or the file stem.
    time_zero_s : float, optional
        Timestamp (unix s, or ``time_s`` value) that becomes ``time_s == 0``; default the
        first row's. Use one value for files recorded together to keep them in step.

    Returns
    -------
    Trajectory

    Examples
    --------
    >>> import tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "track.csv"
    >>> _ = f.write_text("timestamp,latitude,longitude,altitude\\n0,52,4,1000\\n10,52.001,4,1000\\n")
    >>> traj = read_trajectory(f)
    >>> round(float(traj.position_ned_m[1, 0]), 1), round(float(traj.origin[2]), 1)
    (111.3, 304.8)
    """
    path = Path(path)
    df = _normalise(read_track_table(path))
    if "icao24" in df.columns and df["icao24"].nunique(dropna=True) > 1:
        ids = sorted(str(v) for v in df["icao24"].dropna().unique())
        raise InputError(
            f"{path}: field 'icao24' has {len(ids)} aircraft ({', '.join(ids[:5])}...); use read_trajectories"
        )
    return _one_trajectory(path, df, origin, name or _default_name(df, path), time_zero_s)


def read_trajectories(
    path: str | Path, origin: tuple[float, float, float] | None = None, time_zero_s: float | None = None
) -> dict:
    """Read every aircraft in a file (grouped by ``icao24``) into one shared NED frame and clock.

    The origin defaults to the first row's position and time zero to the earliest timestamp,
    so all trajectories stay in step. Without an ``icao24`` column the file is one aircraft,
    keyed by its file stem.

    Returns
    -------
    dict of str to Trajectory
    """
    path = Path(path)
    df = _normalise(read_track_table(path))
    if "icao24" not in df.columns:
        return {path.stem: _one_trajectory(path, df, origin, _default_name(df, path), time_zero_s)}
    if df["icao24"].isna().any():
        row = int(np.nonzero(df["icao24"].isna().to_numpy())[0][0])
        raise InputError(f"{path}: field 'icao24' is empty at row {row}")
    if origin is None or time_zero_s is None:
        col, t = _time_seconds(path, df)
        rows = df.index.to_numpy()
        if time_zero_s is None:
            finite = t[np.isfinite(t)]
            if finite.size == 0:
                raise InputError(f"{path}: field '{col}' has no valid time")
            time_zero_s = float(finite.min())
        if origin is None:
            lat = _column(path, df.iloc[:1], "latitude", rows[:1])
            lon = _column(path, df.iloc[:1], "longitude", rows[:1])
            alt = (
                _column(path, df.iloc[:1], "alt_m", rows[:1])
                if "alt_m" in df.columns
                else _column(path, df.iloc[:1], "altitude", rows[:1]) * FT_M
            )
            origin = (float(lat[0]), float(lon[0]), float(alt[0]))
    out = {}
    for icao, group in df.groupby("icao24", sort=False):
        key = str(icao)
        label = f" (icao24 {key})"
        out[key] = _one_trajectory(path, group, origin, _default_name(group, path, key), time_zero_s, label)
    return out


def _default_name(df: pd.DataFrame, path: Path, fallback: str | None = None) -> str:
    for col in ("callsign", "icao24"):
        if col in df.columns:
            values = df[col].dropna().astype(str).str.strip()
            values = values[values != ""]
            if len(values):
                return str(values.iloc[0])
    return fallback or path.stem
