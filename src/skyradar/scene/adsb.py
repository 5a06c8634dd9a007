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

Real downloads are repaired first (:mod:`skyradar.scene.adsb_clean`: epoch milliseconds, rows out
of order, duplicated timestamps, rows without a position, ``geoaltitude`` preferred to barometric
altitude) and each file's repairs are logged in one line; files may be ``.gz``, ``.bz2`` or ``.xz``
compressed, and JSON may be records, JSON lines or any orient of pandas' ``to_json``.
"""

from __future__ import annotations

import bz2
import gzip
import json
import logging
import lzma
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

import numpy as np
import pandas as pd

from skyradar.errors import InputError
from skyradar.geo import geodetic_to_ned
from skyradar.scene.adsb_clean import altitude_m, clean_rows, readsb_trace, time_seconds
from skyradar.scene.flyable import AIRCRAFT_CLASSES, FlyablePath, KinematicLimits, flyable_path
from skyradar.units import wrap_angle

__all__ = [
    "FT_M",
    "KT_MPS",
    "FPM_MPS",
    "FlightFit",
    "fit_flight",
    "read_track_table",
    "read_trajectory",
    "read_trajectories",
]

FT_M = 0.3048  # international foot, m (exact)
KT_MPS = 1852.0 / 3600.0  # knot, m/s (exact)
FPM_MPS = FT_M / 60.0  # foot per minute, m/s (exact)
# Plausibility limits for aircraft tracks from files: a GA sensor meets nothing faster than Mach 3
# (a bad ADS-B message or a unit mix-up is), nor anything below the Dead Sea or above 30 km.
MAX_SPEED_MPS = 3 * 343.0
ALT_LIMITS_M = (-500.0, 30_000.0)
_OPENSKY_VELOCITY = ("groundspeed", "track", "vertical_rate")
_SI_VELOCITY = ("vn", "ve", "vd")
_log = logging.getLogger(__name__)
_TIME_NAMES = {"timestamp", "time", "time_s"}
_OPENERS: dict[str, Callable[..., IO[Any]]] = {".gz": gzip.open, ".bz2": bz2.open, ".xz": lzma.open}
# A recorded flight, even a day of 1-Hz fixes as JSON, is tens of MB: more is not one track file.
MAX_INFLATED_BYTES = 256 << 20


def read_track_table(path: str | Path) -> pd.DataFrame:
    """Load a CSV, Parquet or JSON (records or JSON lines) file as a DataFrame, unchanged.

    Parameters
    ----------
    path : str or Path
        ``.csv``/``.txt``, ``.parquet``/``.pq``, ``.json``, or ``.jsonl``/``.ndjson`` for JSON lines;
        optionally compressed (``.gz``, ``.bz2``, ``.xz``).

    Returns
    -------
    pandas.DataFrame
        The file's rows and columns as stored: no unit conversion, no repair. ``icao24`` and
        ``callsign`` of a CSV stay text, so leading zeros survive.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as d:
    ...     f = pathlib.Path(d) / "track.csv"
    ...     _ = f.write_text("timestamp,icao24,latitude\\n0,008123,52.0\\n10,008123,52.001\\n")
    ...     table = read_track_table(f)
    >>> table.shape, table["icao24"].tolist(), table["latitude"].tolist()
    ((2, 3), ['008123', '008123'], [52.0, 52.001])
    """
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
    _check_inflated_size(path)
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


def _check_inflated_size(path: Path) -> None:
    """Refuse a compressed file that inflates beyond :data:`MAX_INFLATED_BYTES` before parsing it: a
    small archive can hold gigabytes (a decompression bomb), which would take minutes and all memory."""
    opener = _OPENERS.get(path.suffix.lower())
    if opener is None:
        return
    total = 0
    try:
        with opener(path, "rb") as fh:
            while chunk := fh.read(1 << 20):
                total += len(chunk)
                if total > MAX_INFLATED_BYTES:
                    raise InputError(
                        f"{path}: inflates to more than {MAX_INFLATED_BYTES >> 20} MiB; a track file is "
                        "far smaller (decompress and cut it first)"
                    )
    except (OSError, EOFError, lzma.LZMAError) as exc:
        raise InputError(f"{path}: cannot decompress ({type(exc).__name__}: {exc})") from exc


def _read_json(path: Path, lines: bool) -> pd.DataFrame:
    opener = _OPENERS.get(path.suffix.lower())
    if opener is None and path.suffix.lower() == ".zst":
        raise InputError(f"{path}: .zst is not supported here; decompress it first (zstd -d) or use .gz")
    with (opener or open)(path, "rt", encoding="utf-8") as fh:
        text = fh.read()
    data = [json.loads(line) for line in text.splitlines() if line.strip()] if lines else json.loads(text)
    if isinstance(data, dict) and isinstance(data.get("trace"), list) and "timestamp" in data:
        return readsb_trace(data)  # readsb / ADS-B Exchange trace_full_*.json
    if isinstance(data, dict) and isinstance(data.get("data"), list):
        if isinstance(data.get("columns"), list):  # pandas orient="split"
            return pd.DataFrame(data["data"], columns=data["columns"])
        data = data["data"]  # pandas orient="table": records under "data"
    if isinstance(data, dict) and data and all(isinstance(v, list | dict) for v in data.values()):
        frame = pd.DataFrame(data)  # orient="columns" (pandas' default; dict of dicts) or dict of lists
        inner = next(iter(data.values()))
        if isinstance(inner, dict) and not set(data) & _TIME_NAMES and set(inner) & _TIME_NAMES:
            frame = frame.T.infer_objects()  # orient="index": one object per row
        return frame
    if not isinstance(data, list) or not all(isinstance(row, dict) for row in data):
        raise InputError(f"{path}: JSON must be a list of records (objects), got {type(data).__name__}")
    return pd.DataFrame.from_records(data)


def _normalise(df: pd.DataFrame) -> tuple[pd.DataFrame, bool]:
    """Map OpenSky Impala state-vector columns onto the SI convention; (frame, whether Impala)."""
    cols = set(df.columns)
    if "latitude" in cols or not {"lat", "lon"} <= cols:
        return df, False
    out = df.rename(columns={"lat": "latitude", "lon": "longitude", "time": "timestamp"})
    if {"velocity", "heading", "vertrate"} <= cols and not {"vn", "ve", "vd"} & cols:
        speed = pd.to_numeric(out["velocity"], errors="coerce")
        heading = np.radians(pd.to_numeric(out["heading"], errors="coerce"))
        out["vn"], out["ve"] = speed * np.cos(heading), speed * np.sin(heading)
        out["vd"] = -pd.to_numeric(out["vertrate"], errors="coerce")
    return out, True


def _number(df: pd.DataFrame, name: str) -> np.ndarray:
    """A numeric column, NaN where missing or not a number."""
    return pd.to_numeric(df[name], errors="coerce").to_numpy(dtype=float)


def _local_velocity(df: pd.DataFrame, path: Path | str = "track", label: str = "") -> np.ndarray | None:
    """Velocities (n, 3) in the local NED frame, NaN where a row has none; None without columns.

    A recorded speed beyond Mach 3 (or a track angle beyond +-360 deg) is refused naming the row: a
    value like 1e308 is a corrupt field, not a fix to smooth through.
    """

    def checked(name: str, limit: float, unit: str) -> np.ndarray:
        values = _number(df, name)
        with np.errstate(invalid="ignore"):
            bad = np.flatnonzero(np.isinf(values) | (np.abs(values) > limit))  # NaN: missing
        if bad.size:
            i = int(bad[0])
            raise InputError(
                f"{path}: field '{name}' out of range at row {df.index[i]} ({values[i]:.6g} {unit} is beyond "
                f"+-{limit:.6g} {unit}){label}"
            )
        return values

    if all(c in df.columns for c in _SI_VELOCITY):
        return np.stack([checked(c, MAX_SPEED_MPS, "m/s") for c in _SI_VELOCITY], axis=-1)
    if all(c in df.columns for c in _OPENSKY_VELOCITY):
        gs = checked("groundspeed", MAX_SPEED_MPS / KT_MPS, "kt") * KT_MPS
        trk = np.radians(checked("track", 360.0, "deg"))
        vr = checked("vertical_rate", MAX_SPEED_MPS / FPM_MPS, "ft/min")
        return np.stack([gs * np.cos(trk), gs * np.sin(trk), -vr * FPM_MPS], axis=-1)
    return None


def _check_speed(path: Path, rows: np.ndarray, t: np.ndarray, pos: np.ndarray, label: str) -> None:
    """Refuse a jump between consecutive rows beyond :data:`MAX_SPEED_MPS` plus the position noise."""
    from skyradar.scene.adsb_clean import POSITION_NOISE_M

    dist, dt = np.linalg.norm(np.diff(pos, axis=0), axis=1), np.diff(t)
    fast = np.flatnonzero(dist > MAX_SPEED_MPS * dt + POSITION_NOISE_M)
    if fast.size:
        i = int(fast[0]) + 1
        raise InputError(
            f"{path}: fields 'latitude', 'longitude', altitude at row {rows[i]}: a jump of "
            f"{dist[i - 1]:.0f} m in {dt[i - 1]:g} s from row {rows[i - 1]} "
            f"(above Mach 3, {MAX_SPEED_MPS:.0f} m/s){label}"
        )


def _check_ranges(path, rows, lat, lon, alt, alt_field: str, label: str) -> None:
    for field_name, values, limit in (("latitude", lat, 90.0), ("longitude", lon, 360.0)):
        out = np.abs(values) > limit
        if out.any():
            i = int(np.nonzero(out)[0][0])
            raise InputError(
                f"{path}: field '{field_name}' out of range at row {rows[i]} ({values[i]:.6g}){label}"
            )
    low = np.flatnonzero((alt < ALT_LIMITS_M[0]) | (alt > ALT_LIMITS_M[1]))
    if low.size:
        i = int(low[0])
        raise InputError(
            f"{path}: field '{alt_field}' out of range at row {rows[i]} ({alt[i]:.6g} m is outside "
            f"[{ALT_LIMITS_M[0]:g}, {ALT_LIMITS_M[1]:g}] m){label}"
        )


def _drop_glitches(path, rows, t, lat, lon, alt, alt_field: str, label: str, notes: list[str]) -> np.ndarray:
    """Mask of the fixes to keep: implausible ones dropped within the budget, else InputError."""
    from skyradar.scene.adsb_clean import GLITCH_BUDGET, glitch_rows

    in_range = (np.abs(lat) <= 90.0) & (np.abs(lon) <= 360.0)
    in_range &= (alt >= ALT_LIMITS_M[0]) & (alt <= ALT_LIMITS_M[1])
    keep = in_range.copy()
    if in_range.sum() >= 2:
        ok = np.flatnonzero(in_range)
        pos = geodetic_to_ned(lat[ok], lon[ok], alt[ok], lat[ok[0]], lon[ok[0]], alt[ok[0]])
        keep[ok[glitch_rows(pos, t[ok], MAX_SPEED_MPS)]] = False
    dropped = int(len(t) - keep.sum())
    if dropped > GLITCH_BUDGET * len(t) or keep.sum() < 2:
        share = f"; {dropped} of {len(t)} fixes implausible (at most {GLITCH_BUDGET:.0%} drop as glitches)"
        try:  # name the first bad value
            _check_ranges(path, rows, lat, lon, alt, alt_field, label)
            _check_speed(path, rows, t, geodetic_to_ned(lat, lon, alt, lat[0], lon[0], alt[0]), label)
        except InputError as exc:
            raise InputError(f"{exc}{share}") from None
        raise InputError(f"{path}: fewer than 2 plausible fixes{label}{share}")
    if dropped:
        out = int((~in_range).sum())
        notes.append(f"dropped {dropped} glitch fix(es) ({out} out of range, {dropped - out} out of reach)")
    return keep


@dataclass(frozen=True)
class FlightFit:
    """A file's flight as built (:func:`fit_flight`), beside the fixes it was built from.

    Attributes
    ----------
    trajectory : Trajectory
        The flyable path.
    fix_time_s : ndarray, shape (n,)
        The fixes' times on the trajectory's clock, s (after the repairs of
        :mod:`skyradar.scene.adsb_clean`, before those of the path).
    fix_position_ned_m : ndarray, shape (n, 3)
        The fixes' positions in the trajectory's NED frame, m.
    fix_velocity_ned_mps : ndarray, shape (n, 3), or None
        The velocities the file reports (ground speed, track, vertical rate), m/s, used or not;
        None when the file has none.
    path : FlyablePath
        The smoother's result: which fixes it kept, the lag, the notes.
    limits : KinematicLimits
    notes : list of str
        Every repair, as the one line logged for the file says.

    Examples
    --------
    Three fixes 0.001 deg (111.3 m) apart in latitude every 10 s: nothing to repair, every fix kept.

    >>> import tempfile, pathlib
    >>> rows = "0,52,4,300\\n10,52.001,4,300\\n20,52.002,4,300\\n"
    >>> with tempfile.TemporaryDirectory() as d:
    ...     f = pathlib.Path(d) / "track.csv"
    ...     _ = f.write_text("time_s,latitude,longitude,alt_m\\n" + rows)
    ...     fit = fit_flight(f)
    >>> fit.fix_time_s.tolist(), np.round(fit.fix_position_ned_m[:, 0], 1).tolist()
    ([0.0, 10.0, 20.0], [0.0, 111.3, 222.5])
    >>> fit.path.kept.tolist(), fit.fix_velocity_ned_mps is None, fit.limits.name, fit.notes
    ([True, True, True], True, 'ga', [])
    """

    trajectory: Any
    fix_time_s: np.ndarray
    fix_position_ned_m: np.ndarray
    fix_velocity_ned_mps: np.ndarray | None
    path: FlyablePath
    limits: KinematicLimits
    notes: list[str]


def _one_trajectory(
    path: Path,
    df: pd.DataFrame,
    origin: tuple[float, float, float] | None,
    name: str,
    time_zero_s: float | None,
    label: str = "",
    impala: bool = False,
    limits: KinematicLimits = AIRCRAFT_CLASSES["ga"],
):
    """(trajectory, repair notes) of one aircraft's rows: a flyable path through its fixes."""
    from skyradar.scene.trajectories import Trajectory, origin_to_local_rotation

    df, col, t, alt, alt_field, notes = clean_rows(path, df, impala, label)
    if t.size < 2:
        raise InputError(
            f"{path}: field '{col}' has {t.size} row(s) with a time and a position{label}; "
            "a trajectory needs at least 2 points"
        )
    lat, lon = _number(df, "latitude"), _number(df, "longitude")
    keep = _drop_glitches(path, df.index.to_numpy(), t, lat, lon, alt, alt_field, label, notes)
    df, t, lat, lon, alt = df[keep], t[keep], lat[keep], lon[keep], alt[keep]
    if origin is None:
        origin = (float(lat[0]), float(lon[0]), float(alt[0]))
    else:
        lat0, lon0, alt0 = origin
        origin = (float(lat0), float(lon0), float(alt0))
    pos = geodetic_to_ned(lat, lon, alt, *origin)
    zero = float(t[0]) if time_zero_s is None else float(time_zero_s)
    t_rel = t - zero
    local = _local_velocity(df, path, label)
    vel = local_ned = ground_speed = None
    if local is not None:
        vel = np.einsum("nji,nj->ni", origin_to_local_rotation(lat, lon, origin[0], origin[1]), local)
        local_ned = vel
        derived = np.gradient(pos, t_rel, axis=0, edge_order=2 if t.size > 2 else 1)
        if _velocity_off_course(vel, derived, notes):
            vel, ground_speed = None, np.hypot(local[:, 0], local[:, 1])
    built = flyable_path(
        t_rel,
        pos,
        vel,
        limits,
        rows=df.index.to_numpy(),
        label=f"{path}{label}",
        ground_speed_mps=ground_speed,
    )
    notes.extend(built.notes)
    epoch = zero if col == "timestamp" else float("nan")
    traj = Trajectory.from_states(
        built.time_s, built.position_ned_m, built.velocity_ned_mps, origin=origin, name=name, epoch_s=epoch
    )
    fit = FlightFit(traj, t_rel, pos, local_ned, built, limits, notes)
    return traj, notes, fit


def _velocity_off_course(vel: np.ndarray, derived: np.ndarray, notes: list[str]) -> bool:
    """Whether the recorded velocities do not point along the positions' course: a median angle above
    45 deg over the fixes moving faster than 5 m/s. Some published samples (the ``traffic`` package's
    calibration flights) carry a ground track some 100 deg off their positions' course; those
    velocities are not used. Real ADS-B of a circling glider at 5-12 s is off by 5-8 m/s, which the
    smoother weighs against the positions.
    """
    moving = np.linalg.norm(derived[:, :2], axis=1) > 5.0
    moving &= np.isfinite(vel).all(axis=1)
    off = wrap_angle(np.arctan2(vel[:, 1], vel[:, 0]) - np.arctan2(derived[:, 1], derived[:, 0]))
    angle_deg = float(np.degrees(np.median(np.abs(off[moving])))) if moving.sum() >= 3 else 0.0
    if not angle_deg > 45.0:
        return False
    notes.append(f"track {angle_deg:.0f} deg off the positions' course: only the ground speed used")
    return True


def _report(path: Path, notes: dict[str, list[str]]) -> None:
    """ONE line per file naming every repair (WARNING: shown on stderr without logging set up)."""
    parts = [f"{key}: {', '.join(n)}" if key else ", ".join(n) for key, n in notes.items() if n]
    if parts:
        _log.warning("%s: cleaned: %s", path, "; ".join(parts))


def read_trajectory(
    path: str | Path,
    origin: tuple[float, float, float] | None = None,
    name: str | None = None,
    time_zero_s: float | None = None,
    aircraft_class: str = "ga",
):
    """Read one aircraft's track from a CSV, Parquet or JSON file (plain or .gz/.bz2/.xz).

    The repairs of :mod:`skyradar.scene.adsb_clean` are applied, the path is built through the fixes
    within the aircraft class's kinematic limits (:func:`skyradar.scene.flyable.flyable_path`), and
    every repair is reported in one line.

    Parameters
    ----------
    path : str or Path
        ``.csv``, ``.parquet`` or ``.json`` (records, or any pandas ``to_json`` orient;
        ``.jsonl`` for JSON lines), optionally compressed (``.csv.gz``, ``.json.gz``...).
    origin : (lat_deg, lon_deg, alt_m), optional
        NED frame origin; defaults to the first point of the track.
    name : str, optional
        Trajectory name; defaults to the callsign, the icao24 address or the file stem.
    time_zero_s : float, optional
        Timestamp (unix s, or ``time_s`` value) that becomes ``time_s == 0``; default the
        first row's. Use one value for files recorded together to keep them in step.
    aircraft_class : str
        A key of :data:`skyradar.scene.flyable.AIRCRAFT_CLASSES` (``ga``, ``glider``, ``transport``,
        ``any``): the limits the built path keeps to.

    Returns
    -------
    Trajectory

    Examples
    --------
    >>> import tempfile, pathlib
    >>> folder = tempfile.TemporaryDirectory()
    >>> f = pathlib.Path(folder.name) / "track.csv"
    >>> _ = f.write_text("timestamp,latitude,longitude,altitude\\n0,52,4,1000\\n10,52.001,4,1000\\n")
    >>> traj = read_trajectory(f)
    >>> folder.cleanup()
    >>> round(float(traj.sample([10.0]).position_ned_m[0, 0]), 1), round(float(traj.origin[2]), 1)
    (111.3, 304.8)
    """
    path = Path(path)
    df, impala = _normalise(read_track_table(path))
    if "icao24" in df.columns and df["icao24"].nunique(dropna=True) > 1:
        ids = sorted(str(v) for v in df["icao24"].dropna().unique())
        raise InputError(
            f"{path}: field 'icao24' has {len(ids)} aircraft ({', '.join(ids[:5])}...); use read_trajectories"
        )
    name = name or _default_name(df, path)
    limits = _limits(aircraft_class)
    traj, notes, _fit = _one_trajectory(path, df, origin, name, time_zero_s, impala=impala, limits=limits)
    _report(path, {"": notes})
    return traj


def fit_flight(
    path: str | Path,
    aircraft_class: str = "ga",
    icao24: str | None = None,
    time_zero_s: float | None = None,
) -> FlightFit:
    """One aircraft's flight from a file, with the fixes it was built from (for figures and checks).

    Parameters
    ----------
    path : str or Path
        As :func:`read_trajectory` reads.
    aircraft_class : str
        A key of :data:`skyradar.scene.flyable.AIRCRAFT_CLASSES`.
    icao24 : str, optional
        The aircraft to take from a file holding several.
    time_zero_s : float, optional
        As :func:`read_trajectory`.

    Returns
    -------
    FlightFit
        The trajectory, the fixes it was built from and the repairs.

    Examples
    --------
    Two aircraft in one file; ``icao24`` picks one. Its own first fix is the origin and time zero:

    >>> import tempfile, pathlib
    >>> rows = "0,abc123,52,4,300\\n10,abc123,52.001,4,300\\n5,def456,52,4.01,600\\n15,def456,52,4.011,600\\n"
    >>> with tempfile.TemporaryDirectory() as d:
    ...     f = pathlib.Path(d) / "two.csv"
    ...     _ = f.write_text("time_s,icao24,latitude,longitude,alt_m\\n" + rows)
    ...     fit = fit_flight(f, icao24="def456")
    >>> fit.trajectory.name, fit.trajectory.origin, fit.fix_time_s.tolist()
    ('def456', (52.0, 4.01, 600.0), [0.0, 10.0])
    >>> round(float(fit.trajectory.sample([10.0]).position_ned_m[0, 1]), 1)  # 0.001 deg east at 52 N
    68.7
    """
    path = Path(path)
    limits = _limits(aircraft_class)
    df, impala = _normalise(read_track_table(path))
    if icao24 is not None:
        if "icao24" not in df.columns or not (df["icao24"].astype(str) == icao24).any():
            raise InputError(f"{path}: field 'icao24': {icao24!r} is not in the file")
        df = df[df["icao24"].astype(str) == icao24]
    elif "icao24" in df.columns and df["icao24"].nunique(dropna=True) > 1:
        ids = sorted(str(v) for v in df["icao24"].dropna().unique())
        raise InputError(
            f"{path}: field 'icao24' has {len(ids)} aircraft ({', '.join(ids[:5])}...); name one"
        )
    _traj, notes, fit = _one_trajectory(
        path, df, None, _default_name(df, path), time_zero_s, impala=impala, limits=limits
    )
    _report(path, {"": notes})
    return fit


def _shared_frame(path: Path, df: pd.DataFrame, impala: bool, origin, time_zero_s):
    """Default origin (first row with a full position) and time zero (earliest time) of a file."""
    if time_zero_s is None:
        col, t, _ = time_seconds(path, df)
        finite = t[np.isfinite(t)]
        if finite.size == 0:
            raise InputError(f"{path}: field '{col}' has no valid time")
        time_zero_s = float(finite.min())
    if origin is None:
        try:
            alt = altitude_m(df, impala)[0]
        except InputError as exc:
            raise InputError(f"{path}: {exc}; columns are {list(df.columns)}") from None
        lat, lon = (_number(df, c) for c in ("latitude", "longitude"))
        ok = np.flatnonzero(np.isfinite(lat) & np.isfinite(lon) & np.isfinite(alt))
        if ok.size == 0:
            raise InputError(f"{path}: no row has a latitude, longitude and altitude")
        origin = (float(lat[ok[0]]), float(lon[ok[0]]), float(alt[ok[0]]))
    return origin, time_zero_s


def read_trajectories(
    path: str | Path,
    origin: tuple[float, float, float] | None = None,
    time_zero_s: float | None = None,
    aircraft_class: str = "ga",
) -> dict:
    """Read every aircraft in a file (grouped by ``icao24``) into one shared NED frame and clock.

    The origin defaults to the first row's position and time zero to the earliest timestamp,
    so all trajectories stay in step. Without an ``icao24`` column the file is one aircraft,
    keyed by its file stem. Repairs are reported in one line for the file.

    Parameters
    ----------
    path : str or Path
        As :func:`read_trajectory` reads.
    origin : (lat_deg, lon_deg, alt_m), optional
        Shared NED frame origin (deg, deg, m); defaults to the first row with a full position.
    time_zero_s : float, optional
        Timestamp (unix s, or ``time_s`` value) that becomes ``time_s == 0`` for every aircraft, s;
        default the earliest in the file.
    aircraft_class : str
        A key of :data:`skyradar.scene.flyable.AIRCRAFT_CLASSES`: the limits every built path keeps to.

    Returns
    -------
    dict of str to Trajectory
        One trajectory per ``icao24``, all in the same frame and on the same clock.

    Examples
    --------
    ``def456`` starts 5 s after ``abc123`` and 0.01 deg east of it; both keep those offsets:

    >>> import tempfile, pathlib
    >>> rows = "0,abc123,52,4,300\\n10,abc123,52.001,4,300\\n5,def456,52,4.01,600\\n15,def456,52,4.011,600\\n"
    >>> with tempfile.TemporaryDirectory() as d:
    ...     f = pathlib.Path(d) / "two.csv"
    ...     _ = f.write_text("time_s,icao24,latitude,longitude,alt_m\\n" + rows)
    ...     tracks = read_trajectories(f)
    >>> sorted(tracks), tracks["def456"].origin, float(tracks["def456"].start_s)
    (['abc123', 'def456'], (52.0, 4.0, 300.0), 5.0)
    >>> np.round(tracks["abc123"].sample([10.0]).position_ned_m[0], 1).tolist()
    [111.3, 0.0, 0.0]
    >>> round(float(tracks["def456"].sample([5.0]).position_ned_m[0, 1]), 1)  # 0.01 deg east at 52 N
    686.8
    """
    path = Path(path)
    limits = _limits(aircraft_class)
    df, impala = _normalise(read_track_table(path))
    for name in ("latitude", "longitude"):
        if name not in df.columns:
            raise InputError(f"{path}: missing required field '{name}'; columns are {list(df.columns)}")
    if "icao24" not in df.columns:
        traj, notes, _fit = _one_trajectory(
            path, df, origin, _default_name(df, path), time_zero_s, impala=impala, limits=limits
        )
        _report(path, {"": notes})
        return {path.stem: traj}
    if df["icao24"].isna().any():
        row = int(np.nonzero(df["icao24"].isna().to_numpy())[0][0])
        raise InputError(f"{path}: field 'icao24' is empty at row {row}")
    origin, time_zero_s = _shared_frame(path, df, impala, origin, time_zero_s)
    out, notes = {}, {}
    for icao, group in df.groupby("icao24", sort=False):
        key = str(icao)
        name = _default_name(group, path, key)
        out[key], notes[key], _fit = _one_trajectory(
            path, group, origin, name, time_zero_s, f" (icao24 {key})", impala, limits
        )
    _report(path, notes)
    return out


def _limits(aircraft_class: str) -> KinematicLimits:
    if aircraft_class not in AIRCRAFT_CLASSES:
        raise InputError(f"aircraft class {aircraft_class!r} is not one of {sorted(AIRCRAFT_CLASSES)}")
    return AIRCRAFT_CLASSES[aircraft_class]


def _default_name(df: pd.DataFrame, path: Path, fallback: str | None = None) -> str:
    for col in ("callsign", "icao24"):
        if col in df.columns:
            values = df[col].dropna().astype(str).str.strip()
            values = values[values != ""]
            if len(values):
                return str(values.iloc[0])
    return fallback or path.stem
