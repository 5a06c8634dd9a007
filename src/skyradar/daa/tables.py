"""The DAA input tables: their columns, and the checks every track row and own-ship state pass.

Tracks table (input), one row per track per frame, SI units, NED in the scenario frame:
``time_s, track_id, north_m, east_m, down_m, vn_mps, ve_mps, vd_mps`` and, when the tracker gives
them, the position covariance ``cov_pp_00 .. cov_pp_22`` (m^2) and velocity covariance
``cov_vv_00 .. cov_vv_22`` (m^2/s^2), row-major 3x3 in NED; missing covariance counts as zero.
Rows with NaN position or velocity (no direction of arrival) are skipped, except the range-only
rows: no position (NaN ``north_m`` or ``east_m``) but a range ``range_m`` (m) and range rate
``range_rate_mps`` (m/s), which are alerted on the range-only geometry
(:mod:`skyradar.daa.range_only`). With a ``confirmed`` column only confirmed rows are alerted on;
the range path that lifts the velocity gate also reads the rows before confirmation
(:func:`range_history`).
``AlertConfig.max_velocity_sigma_mps`` silences rows of tracks whose velocity has not converged.

Own-ship table: ``time_s, own_north_m, own_east_m, own_down_m, own_vn_mps, own_ve_mps, own_vd_mps``
and optionally ``own_yaw_rad`` (heading; else the ground track) and ``own_height_agl_m`` (terrain
advice). :func:`skyradar.daa.run_tables.ownship_from_frames` reads it from a frames run.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from skyradar.errors import InputError
from skyradar.io.navigation import NAVIGATION_SOURCES
from skyradar.io.ownship_states import OwnShipStates
from skyradar.io.tables import check_within, finite_column
from skyradar.track.track_table import OWNSHIP_COLUMNS as TRACKER_OWNSHIP_COLUMNS

__all__ = [
    "TRACK_COLUMNS",
    "OWNSHIP_COLUMNS",
    "OPTIONAL_OWNSHIP_COLUMNS",
    "STATE_LIMITS",
    "RANGE_COLUMNS",
    "clean_tracks",
    "range_history",
    "range_only_rows",
    "interp_ownship",
    "covariances",
]

TRACK_COLUMNS = ["time_s", "track_id", "north_m", "east_m", "down_m", "vn_mps", "ve_mps", "vd_mps"]
OWNSHIP_COLUMNS = list(TRACKER_OWNSHIP_COLUMNS)  # the own-ship table the tracker reads, too
OPTIONAL_OWNSHIP_COLUMNS = ["own_yaw_rad", "own_height_agl_m"]
# Bounds of a track's state by the last letter of its column: positions within 10 000 km of the origin,
# velocities within 10 km/s (ten times Mach 3, room for a fresh track's unconverged estimate).
STATE_LIMITS = {"m": (1.0e7, "m"), "s": (1.0e4, "m/s")}
RANGE_COLUMNS = ("range_m", "range_rate_mps")  # a range-only row's measurements (m, m/s)
_COV_P = [f"cov_pp_{i}{j}" for i in range(3) for j in range(3)]
_COV_V = [f"cov_vv_{i}{j}" for i in range(3) for j in range(3)]


def clean_tracks(tracks: pd.DataFrame, source: str) -> pd.DataFrame:
    """Checked, confirmed rows with a 3-D state or range-only; ``attrs['rows_skipped_no_state']``
    counts the others.

    NaN position/velocity means "no direction of arrival" and skips the row, unless the row has no
    position at all (NaN ``north_m`` or ``east_m``) and a finite ``range_m`` and ``range_rate_mps``
    (:func:`range_only_rows`); anything else that is not a finite number (a string, an infinity, a
    NaN time or id) is refused naming the row.

    Parameters
    ----------
    tracks : DataFrame
        Tracks table: ``time_s`` (s), ``track_id``, NED ``north_m, east_m, down_m`` (m) and
        ``vn_mps, ve_mps, vd_mps`` (m/s); optionally ``confirmed``, ``altitude_measured`` and the
        range columns ``range_m`` (m) and ``range_rate_mps`` (m/s).
    source : str
        Name of the table in error messages.

    Returns
    -------
    DataFrame
        The kept rows sorted by time and track, with integer ``track_id``.

    Examples
    --------
    A row without a direction is skipped and an unconfirmed row dropped:

    >>> t = pd.DataFrame({"time_s": [0.0, 0.0, 1.0], "track_id": [1.0, 2.0, 1.0],
    ...     "north_m": [1000.0, np.nan, 900.0], "east_m": 0.0, "down_m": 0.0, "vn_mps": -100.0,
    ...     "ve_mps": 0.0, "vd_mps": 0.0, "confirmed": [True, True, False]})
    >>> clean = clean_tracks(t, "tracks")
    >>> clean["track_id"].tolist(), clean["north_m"].tolist(), clean.attrs["rows_skipped_no_state"]
    ([1], [1000.0], 1)
    """
    missing = [c for c in TRACK_COLUMNS if c not in tracks]
    if missing:
        raise InputError(f"{source}: missing column(s) {missing}")
    df = tracks.reset_index(drop=True)
    cols = {c: finite_column(df, c, source, allow_nan=c not in ("time_s", "track_id")) for c in TRACK_COLUMNS}
    for name in TRACK_COLUMNS[2:]:  # 1e308 is finite, but no aircraft's position or velocity
        limit, unit = STATE_LIMITS[name[-1]]
        check_within(cols[name], limit, unit, source, name, "not an aircraft's state in the run's NED frame")
    ids = cols["track_id"]
    if (ids != np.round(ids)).any():
        bad = int(np.flatnonzero(ids != np.round(ids))[0])
        raise InputError(f"{source}: field 'track_id' is not a whole number at row {bad} ({ids[bad]!r})")
    # Track ids stay integers in the alerts, as the tracker wrote them.
    cols |= _range_columns(df, source)
    df = df.assign(**cols | {"track_id": ids.astype(np.int64)})
    for name in ("confirmed", "altitude_measured"):
        if name in df:
            df = df.assign(**{name: _flag(df[name], name, source)})
    if "confirmed" in df:
        df = df[df["confirmed"].to_numpy()]
    ok = np.isfinite(df[TRACK_COLUMNS[2:]].to_numpy(float)).all(axis=1) | range_only_rows(df)
    clean = df[ok].sort_values(["time_s", "track_id"], kind="stable").reset_index(drop=True)
    clean.attrs["rows_skipped_no_state"] = int((~ok).sum())
    return clean


def range_history(tracks: pd.DataFrame, source: str) -> pd.DataFrame:
    """Every row of every track, confirmed or not, that measured a range and a range rate.

    A track's range and range rate come from its range-Doppler detections whatever its ground test
    or its confirmation said, so the rows before it was confirmed extend its range path
    (:func:`skyradar.daa.range_miss.range_only_fit`) back to its first detections. Columns
    ``track_id`` (int), ``time_s`` (s), ``range_m`` (m) and ``range_rate_mps`` (m/s), in time
    order; empty without the range columns. Values are checked as :func:`clean_tracks` checks them.

    Examples
    --------
    >>> t = pd.DataFrame({"time_s": [0.0, 0.1, 0.1], "track_id": [1, 1, 2], "confirmed": [False, True, True],
    ...                   "range_m": [900.0, 890.0, np.nan], "range_rate_mps": [-100.0, -100.0, 5.0]})
    >>> range_history(t, "t").to_numpy().tolist()
    [[1.0, 0.0, 900.0, -100.0], [1.0, 0.1, 890.0, -100.0]]
    """
    columns = ["track_id", "time_s", *RANGE_COLUMNS]
    if not set(RANGE_COLUMNS) <= set(tracks) or len(tracks) == 0:
        return pd.DataFrame(
            {name: np.zeros(0, np.int64 if name == "track_id" else float) for name in columns}
        )
    df = tracks.reset_index(drop=True)
    cols = {name: finite_column(df, name, source) for name in ("time_s", "track_id")}
    cols |= _range_columns(df, source)
    measured = np.isfinite(cols["range_m"]) & np.isfinite(cols["range_rate_mps"])
    out = pd.DataFrame({name: cols[name][measured] for name in columns})
    out["track_id"] = out["track_id"].astype(np.int64)
    return out.sort_values(["time_s", "track_id"], kind="stable").reset_index(drop=True)


def _range_columns(df: pd.DataFrame, source: str) -> dict[str, np.ndarray]:
    """``df``'s range and range rate columns (those it has) as floats, NaN allowed; a non-number,
    an infinity or a value no aircraft's range or range rate has is refused naming the row."""
    cols = {}
    for name in RANGE_COLUMNS:
        if name in df:
            cols[name] = finite_column(df, name, source, allow_nan=True)
            limit, unit = STATE_LIMITS[name[-1]]
            check_within(cols[name], limit, unit, source, name, "not a range or range rate of an aircraft")
    return cols


def range_only_rows(tracks: pd.DataFrame) -> np.ndarray:
    """Rows without a position (NaN ``north_m`` or ``east_m``) that have a finite range and range
    rate: a one-channel radar's track, or a track whose directions are missing.

    Examples
    --------
    >>> t = pd.DataFrame({"north_m": [np.nan, np.nan, 1.0], "east_m": [np.nan, np.nan, 2.0],
    ...                   "range_m": [900.0, np.nan, 5.0], "range_rate_mps": [-50.0, -50.0, 0.0]})
    >>> range_only_rows(t).tolist()
    [True, False, False]
    """
    if not set(RANGE_COLUMNS) <= set(tracks):
        return np.zeros(len(tracks), bool)
    no_position = ~np.isfinite(tracks[["north_m", "east_m"]].to_numpy(float)).all(axis=1)
    return no_position & np.isfinite(tracks[list(RANGE_COLUMNS)].to_numpy(float)).all(axis=1)


def _flag(flag: pd.Series, name: str, source: str) -> np.ndarray:
    """A boolean column (or 0/1) as bools, else InputError naming the first bad row."""
    if flag.dtype != bool and not flag.isin([0, 1]).all():
        bad = int(np.flatnonzero(~flag.isin([0, 1]))[0])
        raise InputError(f"{source}: field '{name}' is not a boolean at row {bad} ({flag.iloc[bad]!r})")
    return flag.astype(bool).to_numpy()


def interp_ownship(own: pd.DataFrame, times: np.ndarray, source: str) -> OwnShipStates:
    """Own-ship state at ``times`` (linear; heading unwrapped; else the ground track).

    Parameters
    ----------
    own : pandas.DataFrame
        Own-ship table (see the module docstring); ``attrs["navigation_source"]`` is kept when set.
    times : ndarray
        Times to interpolate to, s (at most 1 s outside the table's).
    source : str
        Name of the tracks, for errors.

    Returns
    -------
    OwnShipStates
        The state at ``times``: no attitude but the heading, no geodetic fix, and a NaN height above
        ground when the table has none.

    Examples
    --------
    >>> own = pd.DataFrame({"time_s": [0.0, 2.0], "own_north_m": [0.0, 100.0], "own_east_m": 0.0,
    ...     "own_down_m": -500.0, "own_vn_mps": 50.0, "own_ve_mps": 0.0, "own_vd_mps": 0.0})
    >>> at = interp_ownship(own, np.array([1.0]), "tracks")
    >>> float(at.north_m[0]), float(at.yaw_rad[0]), at.has_geo
    (50.0, 0.0, False)
    """
    kind = own.attrs.get("navigation_source")
    own = own.sort_values("time_s")
    t = own["time_s"].to_numpy(float)
    if times.size and (times.min() < t[0] - 1.0 or times.max() > t[-1] + 1.0):
        raise InputError(
            f"{source}: field 'time_s' ({times.min():.2f}..{times.max():.2f} s) outside the own-ship "
            f"state ({t[0]:.2f}..{t[-1]:.2f} s)"
        )
    out = {}
    for c in OWNSHIP_COLUMNS[1:] + [c for c in OPTIONAL_OWNSHIP_COLUMNS if c in own]:
        values = own[c].to_numpy(float)
        values = np.unwrap(values) if c == "own_yaw_rad" else values
        out[c] = np.interp(times, t, values)
    if "own_yaw_rad" not in out:
        out["own_yaw_rad"] = np.arctan2(out["own_ve_mps"], out["own_vn_mps"])
    out["time_s"] = np.asarray(times, float)
    known = isinstance(kind, str) and kind in NAVIGATION_SOURCES
    return OwnShipStates.from_columns(out, kind if known else None)


def covariances(df: pd.DataFrame) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Position and velocity covariances (n, 3, 3) of the rows, or None without the columns.

    Parameters
    ----------
    df : DataFrame
        Rows with the columns ``cov_pp_ij`` (m^2) and ``cov_vv_ij`` (m^2/s^2), ``i, j`` in 0..2.

    Returns
    -------
    cov_p, cov_v : ndarray, shape (n, 3, 3), or None
        Position (m^2) and velocity (m^2/s^2) covariances; None where the table lacks any of the
        nine columns.

    Examples
    --------
    >>> df = pd.DataFrame({f"cov_pp_{i}{j}": [4.0 * (i == j)] for i in range(3) for j in range(3)})
    >>> cov_p, cov_v = covariances(df)
    >>> cov_p.shape, cov_p[0].diagonal().tolist(), cov_v
    ((1, 3, 3), [4.0, 4.0, 4.0], None)
    """
    cov_p = df[_COV_P].to_numpy(float).reshape(-1, 3, 3) if all(c in df for c in _COV_P) else None
    cov_v = df[_COV_V].to_numpy(float).reshape(-1, 3, 3) if all(c in df for c in _COV_V) else None
    return cov_p, cov_v
