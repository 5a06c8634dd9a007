"""Tracks table + own-ship state -> alerts table; and the alerts of a frames run.

The input tables are described in :mod:`skyradar.daa.tables`; :mod:`skyradar.daa.run_tables`
takes the own-ship state (and a simulated run's truth as tracks) from a frames run.

Alerts table (output), one row per track per frame, with the columns of :data:`ALERT_COLUMNS`
(each one's unit and meaning): the issued level (0 none, 1 preventive, 2 corrective, 3 warning),
the conflict geometry, the FLARM-like traffic indication, whether the track's height was measured
and whether the row is a lost track's prediction (``extrapolated``: it holds the track's alert but
never raises it, :mod:`skyradar.daa.lost_tracks`), the geometry it was alerted on, and the advice
of the frame, repeated on every row of the frame (empty/NaN when no track alerts; left out with
``with_advice=False``).

A track row without a position but with a range and a range rate (a one-channel radar's,
:func:`skyradar.daa.tables.range_only_rows`) is alerted on its range-only geometry
(:mod:`skyradar.daa.range_only`, ``geometry`` ``range-only``): its columns of direction, height and
horizontal geometry are NaN (``sector`` and ``layer`` -1), and no advice is given on a frame where
such a row alerts.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from skyradar.daa.advice import advice_columns
from skyradar.daa.alerting import (
    AlertConfig,
    AlertFilter,
    alerting_rows,
    filter_alert_levels,
    raw_alert_levels,
    required_track_age,
    velocity_unconverged,
)
from skyradar.daa.conflict import traffic_indication
from skyradar.daa.lost_tracks import lost_track_hold, lost_track_rows
from skyradar.daa.provenance import check_tracks_match_run
from skyradar.daa.range_miss import RANGE_FIT_WINDOW_S, range_only_fit
from skyradar.daa.range_only import K_SIGMA, range_only_levels
from skyradar.daa.run_tables import ownship_from_frames, truth_tracks
from skyradar.daa.tables import (
    OWNSHIP_COLUMNS,
    RANGE_COLUMNS,
    TRACK_COLUMNS,
    clean_tracks,
    covariances,
    interp_ownship,
    range_history,
)
from skyradar.io.ownship_states import OwnShipStates
from skyradar.io.tables import appended

__all__ = [
    "ALERT_COLUMNS",
    "TRACK_COLUMNS",
    "OWNSHIP_COLUMNS",
    "ownship_from_frames",
    "truth_tracks",
    "alerts_from_tracks",
    "AlertStream",
    "alerts_for_run",
    "alert_summary",
]


def _gate_unconverged(
    raw: dict,
    cov_v,
    config: AlertConfig,
    located: np.ndarray,
    range_miss: np.ndarray,
    track_miss: np.ndarray,
) -> None:
    """Silences (in ``raw``) the rows whose horizontal velocity is not known well enough to alert on.

    The velocity gate (:func:`~skyradar.daa.alerting.velocity_unconverged`) keeps a horizontal
    velocity taken from noisy directions of arrival from making a conflict. It does not silence a
    row whose range path (``range_miss``: the 3-D miss distance and its sigma fitted to the track's
    range and range rate, :func:`~skyradar.daa.range_miss.range_only_fit`) passes inside the
    warning volume's radius by :data:`~skyradar.daa.range_only.K_SIGMA` sigmas: the horizontal miss
    is at most the 3-D miss, and range and Doppler are measured to a pixel whatever the directions
    do, so that row's horizontal conflict holds whatever its velocity error. (A fast closure at
    2 km over clutter can keep a horizontal velocity sigma near 10 m/s from scattered directions
    while its range path gives the miss to about 10 m.) ``track_miss`` is the same path fitted over
    every row of the track up to the row, confirmed or not (:func:`_whole_track_range_miss`): a
    closure confirmed 2.5 km away has measured its range and range rate since its first detection,
    and its path is known seconds before its confirmed rows span the fit's window. Either path
    inside lifts the gate; it never silences a row the gate would let through, so the rows held
    before confirmation can only bring a warning earlier, never clear one.

    A silenced row is marked ``raw["gated"]``: its velocity says nothing about the conflict, so the
    M-of-N filter takes it as no evidence to raise (:func:`_filter_inputs`), not as a frame without
    one. Its hold level is left as its geometry gives it: the gate keeps an uncertain velocity from
    raising an alert, and an alert that converged frames raised is held as DO-365B holds it, while
    the volume widened by that uncertainty is predicted lost within the level's hold time.
    """
    raw["gated"] = np.zeros(len(raw["level"]), bool)
    if config.max_velocity_sigma_mps is not None and cov_v is not None:
        sigma_hv = np.sqrt(np.nan_to_num(cov_v[:, 0, 0] + cov_v[:, 1, 1], nan=np.inf))
        radius_m = config.levels[-1].volume.dthr_m
        inside = (range_miss[0] + K_SIGMA * range_miss[1] < radius_m) | (  # False where NaN
            track_miss[0] + K_SIGMA * track_miss[1] < radius_m
        )
        unconverged = velocity_unconverged(sigma_hv, raw["tcpa_s"], config) & located & ~inside
        raw["level"][unconverged] = 0
        raw["flarm_level"][unconverged] = 0
        raw["gated"] = unconverged


def _required_age(s: np.ndarray, v: np.ndarray, config: AlertConfig, located: np.ndarray) -> np.ndarray:
    """The age each row's track needs before the row may alert, s (rows without a position:
    ``min_track_age_s``)."""
    required_age = np.full(len(s), config.min_track_age_s)
    required_age[located] = required_track_age(s[located], v[located], config)
    return required_age


def _filter_inputs(raw: dict, rows: np.ndarray, predicted: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The M-of-N filter's evidence and hold levels of ``rows``: a prediction, a range-only row
    whose fit refused and a row the velocity gate silenced are no evidence of a conflict (-1).

    A gated row's velocity is too uncertain to say whether the track conflicts, so it neither
    raises a level nor counts as a frame without a conflict: counted as level 0, the gated rows
    of a fast closure's first seconds after confirmation would fill the filter's window with
    zeros, and its first converged rows would wait until they were half of that window. Its hold
    level is its geometry's (:func:`_gate_unconverged`): a warning raised on a closure's range path
    is not dropped while the velocity converges (an own-ship in a turn keeps it uncertain for
    seconds longer than the 5-s hysteresis)."""
    unknown = ~raw["known"][rows]
    evidence = np.where(predicted[rows] | unknown | raw["gated"][rows], -1, raw["level"][rows])
    return evidence, np.where(unknown, -1, raw["hold_level"][rows])


def _issued_levels(
    df: pd.DataFrame, t: np.ndarray, raw: dict, required_age: np.ndarray, config: AlertConfig, predicted
) -> np.ndarray:
    """Issued level per row of a whole run; silences (in ``raw``) too young tracks first.

    A track's rows before it is old enough (:func:`~skyradar.daa.alerting.alerting_rows`) say
    nothing about the conflict: they are not fed to its M-of-N filter, which starts at the first
    row that may alert instead of counting the silenced rows as "no conflict". Rows without a
    position (``located`` False) have no velocity covariance to gate on (the range fit's spread
    stands for it) and wait ``min_track_age_s``; those whose range fit refused (``raw["known"]``
    False) are no evidence either way, neither raising nor holding a level.
    """
    level = np.zeros(len(df), int)
    for _, idx in df.groupby("track_id", sort=False).indices.items():
        ready = alerting_rows(t[idx], required_age[idx])
        raw["level"][idx[~ready]] = 0
        raw["flarm_level"][idx[~ready]] = 0
        rows = idx[ready]
        evidence, hold = _filter_inputs(raw, rows, predicted)
        level[rows] = filter_alert_levels(t[rows], evidence, config, hold)
    return level


_NO_ADVICE = "not with --no-advice"
# The alerts table (``skyradar alert``), column -> "unit; meaning" (skyradar.io.table_columns).
ALERT_COLUMNS: dict[str, str] = {
    "time_s": "s; elapsed time of the frame since the run's start_time",
    "track_id": "-; the tracks table's track_id",
    "level": "-; issued alert level after the M-of-N filter and hold: 0 none, 1 preventive, 2 corrective, "
    "3 warning",
    "raw_level": "-; the level this frame's geometry alone gives (0 on extrapolated rows)",
    "flarm_level": "-; FLARM-style alarm level 0..3 from time_to_impact_s",
    "t_in_s": "s; predicted time to the loss of well clear (the highest level's volume, else the "
    "corrective one); NaN: none",
    "time_to_impact_s": "s; predicted time of entry into the collision volume; NaN: none",
    "tcpa_s": "s; time to the horizontal closest point of approach (range-only rows: the 3-D one of the "
    "range fit); negative: diverging",
    "hmd_m": "m; horizontal miss distance at the closest point of approach (from now if diverging; NaN on "
    "range-only rows)",
    "vmd_m": "m; vertical separation at the closest point of approach (NaN on range-only rows)",
    "miss_m": "m; 3-D miss distance from the track's range and range rate alone (range-only rows, and rows "
    "whose height is a co-altitude prior); NaN elsewhere or where the fit refuses",
    "range_m": "m; distance from the own-ship to the intruder (range-only rows: the track's range; "
    "extrapolated: the range fit's)",
    "bearing_deg": "deg; bearing of the intruder relative to the own-ship's heading, positive right (NaN "
    "on range-only rows)",
    "sector": "-; clock sector 0..11 of the bearing, 30 deg each, 0 dead ahead, counting clockwise (-1 on "
    "range-only rows)",
    "layer": "-; vertical layer from the elevation angle: -2 far below, 0 level, 2 far above (-1 on "
    "range-only rows: unknown)",
    "rel_north_m": "m; intruder north of the own-ship (NaN on range-only rows)",
    "rel_east_m": "m; intruder east of the own-ship (NaN on range-only rows)",
    "rel_alt_m": "m; intruder height above the own-ship (NaN on range-only rows)",
    "climb_rate_mps": "m/s; the intruder's climb rate, positive up (NaN on range-only rows)",
    "altitude_measured": "-; False: the track's height is a co-altitude prior, or it has none (range-only "
    "rows), no elevation of it was measured (the tracks table's flag; True for tables without it)",
    "extrapolated": "-; True: the track had no confirmed row on this frame; the row is its prediction "
    "from its last one",
    "geometry": "-; what the row is alerted on: 3-d (the track's position and velocity, well-clear "
    "cylinders) or range-only (no direction: the 3-D miss from range and range rate against the "
    "cylinders' corners sqrt(D^2 + Z^2), skyradar.daa.range_only)",
    "heading_bands_deg": "deg; headings in conflict with the traffic, flattened intervals [lo0, hi0, lo1, "
    f"hi1, ...], per frame (empty: no alert, or a range-only row alerts: no bearing, no band); optional: "
    f"{_NO_ADVICE}",
    "vs_bands_mps": "m/s; vertical speeds in conflict with the traffic, flattened intervals, per frame "
    f"(empty as heading_bands_deg); optional: {_NO_ADVICE}",
    "terrain_vs_bands_mps": "m/s; vertical speeds that come too close to the terrain, flattened "
    f"intervals, per frame; optional: {_NO_ADVICE}",
    "preferred_heading_deg": "deg; the preferred conflict-free heading, per frame (NaN: no alert, or a "
    f"range-only row alerts: no direction to advise); optional: {_NO_ADVICE}",
    "preferred_vs_mps": "m/s; the preferred conflict-free vertical speed, positive up, per frame (NaN: "
    f"no alert, or a range-only row alerts); optional: {_NO_ADVICE}",
}


def _alerts_table(df, t, level, raw, s, v_int, yaw_rad, located, range_m) -> pd.DataFrame:
    ind = traffic_indication(np.where(located[:, None], s, 0.0), yaw_rad)  # no NaN cast to a sector

    def placed(values: np.ndarray) -> np.ndarray:
        return np.where(located, values, np.nan)

    geometry = ("t_in_s", "time_to_impact_s", "tcpa_s", "hmd_m", "vmd_m", "miss_m")
    return pd.DataFrame(
        {"time_s": t, "track_id": df["track_id"].to_numpy(), "level": level}
        | {"raw_level": raw["level"], "flarm_level": raw["flarm_level"]}
        | {name: raw[name] for name in geometry}
        | {
            "range_m": range_m,
            "bearing_deg": placed(np.degrees(ind["bearing_rad"])),
            "sector": np.where(located, ind["sector"], -1),
            "layer": np.where(located, ind["layer"], -1),
            "rel_north_m": s[:, 0],
            "rel_east_m": s[:, 1],
            "rel_alt_m": placed(ind["rel_alt_m"]),
            "climb_rate_mps": placed(-v_int[:, 2]),
            # False: the track's height is the co-altitude prior, rel_alt_m is not a measurement.
            "altitude_measured": _altitude_measured(df) & located,
        }
    )


def _altitude_measured(df: pd.DataFrame) -> np.ndarray:
    if "altitude_measured" not in df:  # truth tracks and tables from before the flag
        return np.ones(len(df), bool)
    return df["altitude_measured"].to_numpy(bool)  # checked by clean_tracks


def _range_fit(
    df: pd.DataFrame, t: np.ndarray, own_vel: np.ndarray, predicted: np.ndarray, wanted: np.ndarray
) -> np.ndarray:
    """The range-only path (:func:`~skyradar.daa.range_miss.range_only_fit`: miss, sigma, relative
    speed squared, time of closest approach; shape (4, n)) of every ``wanted`` measured row, over
    its track's measured rows. A lost track's prediction has no range measured: it carries the path
    of its track's last measured row, which straight motion keeps (the four are constants of it)."""
    fit = np.full((4, len(df)), np.nan)
    if not set(RANGE_COLUMNS) <= set(df):
        return fit
    ids = df["track_id"].to_numpy()
    need = wanted & ~predicted
    src = np.array([], float)
    if (predicted & wanted).any():
        # Rows are in time order: each prediction takes the last measured row of its track.
        source = pd.Series(np.where(predicted, np.nan, np.arange(len(df)))).groupby(ids).ffill()
        src = source.to_numpy()[predicted & wanted]
        need[src[np.isfinite(src)].astype(int)] = True
    rows = ~predicted
    r, rdot = (df[c].to_numpy(float)[rows] for c in RANGE_COLUMNS)
    fit[:, rows] = range_only_fit(ids[rows], t[rows], r, rdot, own_vel[rows], wanted=need[rows])
    if src.size:
        values = np.full((4, src.size), np.nan)
        ok = np.isfinite(src)
        values[:, ok] = fit[:, src[ok].astype(int)]
        fit[:, predicted & wanted] = values
    fit[:, ~wanted] = np.nan
    return fit


def _whole_track_range_miss(
    df: pd.DataFrame,
    t: np.ndarray,
    predicted: np.ndarray,
    ranges: pd.DataFrame | None,
    ownship: pd.DataFrame,
    source: str,
    wanted: np.ndarray,
) -> np.ndarray:
    """Miss distance and sigma (m, shape (2, n)) of each ``wanted`` measured row's range path fitted
    over every row of its track up to it, confirmed or not (``ranges``:
    :func:`~skyradar.daa.tables.range_history`); NaN on predictions and where the fit refuses."""
    out = np.full((2, len(df)), np.nan)
    if ranges is None or len(ranges) == 0 or len(df) == 0:
        return out
    ids = df["track_id"].to_numpy()
    mine = ranges[ranges["track_id"].isin(np.unique(ids[~predicted & wanted]))]
    mine = mine.drop_duplicates(["track_id", "time_s"], keep="last")  # a track has one state a time
    if len(mine) == 0:
        return out
    rt = mine["time_s"].to_numpy(float)
    index = pd.MultiIndex.from_arrays([mine["track_id"].to_numpy(), rt])
    at = index.get_indexer(pd.MultiIndex.from_arrays([ids, t]))
    found = (at >= 0) & ~predicted & wanted
    need = np.zeros(len(mine), bool)
    need[at[found]] = True
    own_v = interp_ownship(ownship, rt, source).velocity_ned_mps
    r, rdot = (mine[c].to_numpy(float) for c in RANGE_COLUMNS)
    miss, sigma, _, _ = range_only_fit(mine["track_id"].to_numpy(), rt, r, rdot, own_v, wanted=need)
    out[0, found], out[1, found] = miss[at[found]], sigma[at[found]]
    return out


def _merged_levels(
    s: np.ndarray,
    v: np.ndarray,
    t: np.ndarray,
    config: AlertConfig,
    cov_p,
    cov_v,
    fit: np.ndarray,
    located: np.ndarray,
) -> dict[str, np.ndarray]:
    """Raw levels and geometry of every row: the 3-D geometry on rows with a position
    (:func:`~skyradar.daa.alerting.raw_alert_levels`; on rows whose height is the co-altitude
    prior the range fit's path clears the levels it passes outside of and raises those it surely
    enters, whatever the track's velocity predicts), the range-only one on the others
    (:func:`~skyradar.daa.range_only.range_only_levels`)."""
    n = len(t)
    raw: dict[str, np.ndarray] = {
        name: np.zeros(n, int) for name in ("level", "hold_level", "flarm_level")
    } | {
        name: np.full(n, np.nan)
        for name in ("t_in_s", "time_to_impact_s", "tcpa_s", "hmd_m", "vmd_m", "dthr_m", "zthr_m")
    }
    raw["miss_m"] = fit[0].copy()
    raw["known"] = located.copy()
    if located.any():
        cp, cv = (None if c is None else c[located] for c in (cov_p, cov_v))
        miss = (fit[0, located], fit[1, located], fit[2, located], fit[3, located] - t[located])
        for name, values in raw_alert_levels(s[located], v[located], config, cp, cv, miss).items():
            raw[name][located] = values
    if (~located).any():
        far = ~located
        ranged = range_only_levels(fit[0, far], fit[1, far], fit[2, far], fit[3, far] - t[far], config)
        for name, values in ranged.items():
            raw[name][far] = values
    return raw


def alerts_from_tracks(
    tracks: pd.DataFrame,
    ownship: pd.DataFrame,
    config: AlertConfig | None = None,
    with_advice: bool = True,
    source: str = "tracks",
) -> pd.DataFrame:
    """Alert levels, conflict geometry, traffic indication and advice for every track row.

    Parameters
    ----------
    tracks : DataFrame
        Tracks table (:mod:`skyradar.daa.tables`).
    ownship : DataFrame
        Own-ship state table, interpolated to the track times.
    config : AlertConfig, optional
    with_advice : bool
        Compute bands and the preferred manoeuvre on frames with an alert.
    source : str
        Name used in error messages.

    Returns
    -------
    DataFrame
        Alerts table (see module docstring).

    Examples
    --------
    An intruder closing head-on from 2000 m at 100 m/s enters the default 670.56 m volume after
    ``(2000 - 670.56) / 100`` s; the warning (level 3) is issued once the track is old enough and
    the level's M-of-N rule holds:

    >>> t = np.arange(4.0)
    >>> tracks = pd.DataFrame({"time_s": t, "track_id": 1, "north_m": 2000.0 - 100.0 * t,
    ...     "east_m": 0.0, "down_m": 0.0, "vn_mps": -100.0, "ve_mps": 0.0, "vd_mps": 0.0})
    >>> own = pd.DataFrame({"time_s": t, "own_north_m": 0.0, "own_east_m": 0.0, "own_down_m": 0.0,
    ...     "own_vn_mps": 0.0, "own_ve_mps": 0.0, "own_vd_mps": 0.0, "own_yaw_rad": 0.0})
    >>> alerts = alerts_from_tracks(tracks, own, with_advice=False)
    >>> round(float(alerts["t_in_s"][0]), 2), alerts["level"].tolist()
    (13.29, [0, 0, 0, 3])
    """
    config = config or AlertConfig()
    rows = _alert_rows(tracks, ownship, config, source)
    rows.level[:] = _issued_levels(rows.df, rows.t, rows.raw, rows.required_age, config, rows.predicted)
    return _alerts_out(rows, config, with_advice)


@dataclass
class _AlertRows:
    """Every row's state and raw levels, before the M-of-N filter issues its level."""

    df: pd.DataFrame  # the clean tracks rows and the lost tracks' predictions, in time order
    t: np.ndarray
    own: OwnShipStates  # the own-ship interpolated to the rows' times
    own_vel: np.ndarray
    s: np.ndarray  # relative position (intruder minus own-ship), m
    v: np.ndarray  # relative velocity, m/s
    v_int: np.ndarray  # the intruder's velocity, m/s
    located: np.ndarray
    predicted: np.ndarray
    fit: np.ndarray  # the range path of the rows it judges, (4, n)
    raw: dict
    required_age: np.ndarray
    level: np.ndarray  # the issued level, set by the filter

    def select(self, keep: np.ndarray) -> _AlertRows:
        """The rows where ``keep`` is True."""
        df = self.df[keep].reset_index(drop=True)
        df.attrs = dict(self.df.attrs)
        return _AlertRows(
            df,
            self.t[keep],
            self.own.select(keep),
            self.own_vel[keep],
            self.s[keep],
            self.v[keep],
            self.v_int[keep],
            self.located[keep],
            self.predicted[keep],
            self.fit[:, keep],
            {name: values[keep] for name, values in self.raw.items()},
            self.required_age[keep],
            self.level[keep],
        )


def _lost_track_holds(
    df: pd.DataFrame, ownship: pd.DataFrame, config: AlertConfig, source: str
) -> np.ndarray:
    """How long each row's prediction may stand in for its lost track, s
    (:func:`~skyradar.daa.lost_tracks.lost_track_hold`, from the own-ship at the row's time)."""
    if not config.closing_track_hold_s > config.lost_track_hold_s or len(df) == 0:
        return np.full(len(df), config.lost_track_hold_s)
    seen = interp_ownship(ownship, df["time_s"].to_numpy(float), source)
    return lost_track_hold(
        df[["north_m", "east_m", "down_m"]].to_numpy(float) - seen.position_ned_m,
        df[["vn_mps", "ve_mps", "vd_mps"]].to_numpy(float) - seen.velocity_ned_mps,
        config.lost_track_hold_s,
        config.closing_track_hold_s,
    )


def _alert_rows(
    tracks: pd.DataFrame,
    ownship: pd.DataFrame,
    config: AlertConfig,
    source: str,
    cleaned: bool = False,
    ranges: pd.DataFrame | None = None,
    at_time_s: float | None = None,
) -> _AlertRows:
    """The state, geometry and raw levels of every row (:func:`alerts_from_tracks` up to its filter).
    ``cleaned``: ``tracks`` are :func:`~skyradar.daa.tables.clean_tracks`' rows already, and
    ``ranges`` every track's :func:`~skyradar.daa.tables.range_history` (else read from ``tracks``).
    ``at_time_s``: only the rows at that time (s) are returned, the earlier ones feeding their fits."""
    df = tracks.reset_index(drop=True) if cleaned else clean_tracks(tracks, source)
    if not cleaned and ranges is None:
        ranges = range_history(tracks, source)  # after clean_tracks named any missing column
    if cleaned:
        df.attrs["rows_skipped_no_state"] = 0
    holds = _lost_track_holds(df, ownship, config, source)
    df = lost_track_rows(df, ownship["time_s"].to_numpy(float), holds, at_time_s)
    predicted = df["extrapolated"].to_numpy(bool)
    t = df["time_s"].to_numpy(float)
    wanted = np.ones(len(df), bool) if at_time_s is None else t == at_time_s
    own = interp_ownship(ownship, t, source)
    path = _range_fit(df, t, own.velocity_ned_mps, predicted, wanted)
    track_miss = _whole_track_range_miss(df, t, predicted, ranges, ownship, source, wanted)
    if at_time_s is not None:
        attrs = dict(df.attrs)
        df, t, predicted = df[wanted].reset_index(drop=True), t[wanted], predicted[wanted]
        df.attrs = attrs
        path, track_miss, own = path[:, wanted], track_miss[:, wanted], own.select(wanted)
    own_pos, own_vel = own.position_ned_m, own.velocity_ned_mps
    v_int = df[["vn_mps", "ve_mps", "vd_mps"]].to_numpy(float)
    s, v = df[["north_m", "east_m", "down_m"]].to_numpy(float) - own_pos, v_int - own_vel
    located = np.isfinite(s).all(axis=1) & np.isfinite(v).all(axis=1)  # else a range-only row
    cov_p, cov_v = covariances(df)
    # The range path judges the levels of rows whose height is the co-altitude prior or that have
    # no position (a measured height is the 3-D track's to judge), and a 3-D prediction carries none.
    judged = (~_altitude_measured(df) | ~located) & ~(predicted & located)
    fit = np.where(judged, path, np.nan)
    raw = _merged_levels(s, v, t, config, cov_p, cov_v, fit, located)
    raw["level"][predicted] = 0  # a prediction holds a track's level, never raises it
    raw["flarm_level"][predicted] = 0
    _gate_unconverged(raw, cov_v, config, located, path[:2], track_miss)
    required_age = _required_age(s, v, config, located)
    level = np.zeros(len(df), int)
    return _AlertRows(df, t, own, own_vel, s, v, v_int, located, predicted, fit, raw, required_age, level)


def _alerts_out(rows: _AlertRows, config: AlertConfig, with_advice: bool) -> pd.DataFrame:
    """The alerts table of rows whose level is issued: geometry, indication and the frames' advice."""
    df, t, raw, s, located, fit, own = rows.df, rows.t, rows.raw, rows.s, rows.located, rows.fit, rows.own
    v_int, own_vel, level = rows.v_int, rows.own_vel, rows.level
    measured_r = df["range_m"].to_numpy(float) if "range_m" in df else np.full(len(df), np.nan)
    fitted_r = np.sqrt(fit[0] ** 2 + fit[2] * (fit[3] - t) ** 2)
    range_m = np.where(
        located, np.linalg.norm(s, axis=-1), np.where(np.isnan(measured_r), fitted_r, measured_r)
    )
    out = _alerts_table(df, t, level, raw, s, v_int, own.yaw_rad, located, range_m)
    out["extrapolated"] = rows.predicted
    out["geometry"] = np.where(located, "3-d", "range-only")
    if with_advice:
        corrective = config.levels[min(1, len(config.levels) - 1)]
        height = own.height_agl_m  # NaN where unknown: no terrain band, as without the column
        dthr, zthr = raw["dthr_m"], raw["zthr_m"]
        volume, alerting_time_s = corrective.volume, corrective.alerting_time_s
        advice_columns(out, s, v_int, own_vel, height, dthr, zthr, volume, alerting_time_s, located)
    out.attrs["rows_skipped_no_state"] = df.attrs["rows_skipped_no_state"]
    return out


def alerts_for_run(
    run: xr.Dataset,
    tracks: pd.DataFrame | None = None,
    config: AlertConfig | None = None,
    with_advice: bool = True,
    run_name: str = "frames",
    tracks_name: str = "tracks",
) -> pd.DataFrame:
    """Alerts of a frames run: on a tracks table made from it, else on the intruder truth it stores.

    The own-ship state comes from the run; a tracks table must come from the same run
    (:func:`skyradar.daa.provenance.check_tracks_match_run`), else InputError.

    Parameters
    ----------
    run : xr.Dataset
        Frames Dataset with the own-ship state (``nav_*`` or ``own_*``: NED position in m, velocity
        in m/s) and, without ``tracks``, the intruder truth (``tgt_*``, same units).
    tracks : DataFrame, optional
        Tracks table made from ``run`` (:mod:`skyradar.daa.tables`); None: the intruder truth.
    config : AlertConfig, optional
        Alerting settings (default :class:`AlertConfig`).
    with_advice : bool
        Compute bands and the preferred manoeuvre on frames with an alert.
    run_name, tracks_name : str
        Names of the run and the tracks table used in error messages.

    Returns
    -------
    DataFrame
        Alerts table (as :func:`alerts_from_tracks`); on the truth, ``track_id`` is the target index.

    Examples
    --------
    A hovering own-ship and one target closing head-on from 2000 m at 100 m/s, alerted on the
    truth:

    >>> t = np.arange(4.0)
    >>> zero = ("time", np.zeros(4))
    >>> own = {f"own_{c}": zero for c in ("north_m", "east_m", "down_m", "vn_mps", "ve_mps", "vd_mps")}
    >>> dims = ("time", "target")
    >>> tgt = {f"tgt_{c}": (dims, np.zeros((4, 1))) for c in ("east_m", "down_m", "ve_mps", "vd_mps")}
    >>> tgt["tgt_north_m"] = (dims, (2000.0 - 100.0 * t)[:, None])
    >>> tgt["tgt_vn_mps"] = (dims, np.full((4, 1), -100.0))
    >>> alerts = alerts_for_run(xr.Dataset(own | tgt, coords={"time": t}), with_advice=False)
    >>> alerts["track_id"].tolist(), alerts["level"].tolist()
    ([0, 0, 0, 0], [0, 0, 0, 3])
    """
    if tracks is None:
        own = ownship_from_frames(run, run_name)
        return alerts_from_tracks(truth_tracks(run), own, config, with_advice, run_name)
    own = ownship_from_frames(run, run_name)  # a corrupt own-ship state is named before it is compared
    check_tracks_match_run(tracks.attrs, tracks_name, run, run_name)
    return alerts_from_tracks(tracks, own, config, with_advice, tracks_name)


def alert_summary(alerts: pd.DataFrame) -> dict[str, Any]:
    """Counts of an alerts table: rows, tracks, warnings, first warning time, rows per level.

    Examples
    --------
    >>> alerts = pd.DataFrame({"time_s": [0.0, 1.0], "track_id": [3, 3], "level": [1, 3]})
    >>> alert_summary(alerts)["first_warning_s"], alert_summary(alerts)["rows_level_3"]
    (1.0, 1)
    """
    warn = alerts[alerts["level"] >= 3]
    result = {
        "rows": len(alerts),
        "tracks": int(alerts["track_id"].nunique()),
        "tracks_with_warning": int(warn["track_id"].nunique()),
        "first_warning_s": float(warn["time_s"].min()) if len(warn) else float("nan"),
        "max_level": int(alerts["level"].max()) if len(alerts) else 0,
        # NaN position/velocity without a range and range rate cannot be alerted on: say how many.
        "rows_skipped_no_state": int(alerts.attrs.get("rows_skipped_no_state", 0)),
        "rows_range_only": int((alerts["geometry"] == "range-only").sum()) if "geometry" in alerts else 0,
    }
    for level in (1, 2, 3):
        result[f"rows_level_{level}"] = int(np.sum(alerts["level"].to_numpy() == level))
    return result


class AlertStream:
    """:func:`alerts_from_tracks` one frame at a time: each call gives the alerts table's rows of a frame.

    Every stage of the alerting is causal (a track's M-of-N filter, its age, its range fit over a
    trailing window, a lost track's prediction from its last confirmed row, the frame's advice), so
    a frame's rows computed from the tracks and own-ship rows up to it are the whole run's. The
    stream keeps what the stages need, and no more, so a frame costs the same at any point of a
    run: each track's M-of-N filter (:class:`~skyradar.daa.alerting.AlertFilter`), fed one row per
    frame, its first time and whether it is old enough to alert; and the tracks and own-ship rows
    of a trailing window, of the tracks that can have a row on the frame (a confirmed row, or a
    prediction from one of their rows within its hold). The window is the longest hold
    (:attr:`~skyradar.daa.alerting.AlertConfig.longest_lost_track_hold_s`) plus the range fit's
    :data:`~skyradar.daa.range_miss.RANGE_FIT_WINDOW_S` plus a second: a lost track's prediction
    carries the range path of its last measured row, up to that hold old, fitted over the window
    before that row. A prediction spaces its rows by the
    median frame interval of the window (the batch: of the whole run).

    Parameters
    ----------
    config, with_advice, source
        As in :func:`alerts_from_tracks`.

    Examples
    --------
    >>> tracks = pd.DataFrame({"time_s": [0.0, 1.0], "track_id": 1, "north_m": [3000.0, 2900.0],
    ...     "east_m": 0.0, "down_m": 0.0, "vn_mps": -100.0, "ve_mps": 0.0, "vd_mps": 0.0})
    >>> own = pd.DataFrame({"time_s": [0.0, 1.0], "own_north_m": 0.0, "own_east_m": 0.0, "own_down_m": 0.0,
    ...     "own_vn_mps": 0.0, "own_ve_mps": 0.0, "own_vd_mps": 0.0, "own_yaw_rad": 0.0})
    >>> stream = AlertStream(with_advice=False)
    >>> rows = [stream.step(t, tracks[tracks.time_s == t], own[own.time_s == t]) for t in (0.0, 1.0)]
    >>> pd.concat(rows, ignore_index=True).equals(alerts_from_tracks(tracks, own, with_advice=False))
    True
    """

    def __init__(self, config: AlertConfig | None = None, with_advice: bool = True, source: str = "tracks"):
        self.config = config or AlertConfig()
        self.with_advice, self.source = with_advice, source
        self._window_s = RANGE_FIT_WINDOW_S + self.config.longest_lost_track_hold_s + 1.0
        self._tracks: pd.DataFrame | None = None  # the confirmed rows of the window
        self._ranges: pd.DataFrame | None = None  # every track's measured ranges in the window
        self._own: pd.DataFrame | None = None  # the own-ship rows of the window
        self._held_until_s: dict[int, float] = {}  # the last frame a track's prediction can reach
        self._filters: dict[int, AlertFilter] = {}
        self._first_s: dict[int, float] = {}
        self._ready: set[int] = set()

    def step(self, time_s: float, tracks: pd.DataFrame, ownship: pd.DataFrame) -> pd.DataFrame:
        """Alert one frame: its tracks rows ``tracks`` (all at ``time_s``, s) and own-ship row ``ownship``.

        Returns the frame's alerts rows; ``attrs["rows_skipped_no_state"]`` counts the frame's
        confirmed rows that have no state to alert on.
        """
        time_s = float(time_s)
        confirmed = (
            tracks["confirmed"].to_numpy(bool) if "confirmed" in tracks else np.ones(len(tracks), bool)
        )
        clean = clean_tracks(tracks, self.source)  # each row is checked once, as it comes
        self._own = appended(_since(self._own, time_s - self._window_s), ownship)
        self._tracks = appended(_since(self._tracks, time_s - self._window_s), clean)
        self._ranges = appended(
            _since(self._ranges, time_s - self._window_s), range_history(tracks, self.source)
        )
        own = self._own  # a new frame each step: its attrs are this frame's own-ship's
        own.attrs = dict(ownship.attrs)
        # A track can have a row on this frame while a prediction from one of its rows reaches it
        # (the latest such frame of any of its rows: a superset of the batch's).
        holds = _lost_track_holds(clean, own, self.config, self.source)
        plain_s = time_s + self.config.lost_track_hold_s
        reach = [(i, plain_s) for i in tracks["track_id"].to_numpy()[confirmed].tolist()]
        reach += zip(clean["track_id"].tolist(), (time_s + holds).tolist(), strict=True)
        for track, until in reach:
            self._held_until_s[track] = max(self._held_until_s.get(track, until), until)
        alive = [i for i, until in self._held_until_s.items() if until >= time_s - 1e-9]
        history = self._tracks[self._tracks["track_id"].isin(alive)]
        rows = _alert_rows(
            history, own, self.config, self.source, cleaned=True, ranges=self._ranges, at_time_s=time_s
        )
        self._issue(rows)
        out = _alerts_out(rows, self.config, self.with_advice)
        # The frame's own count: its confirmed rows without a state (the history's are counted on theirs).
        out.attrs = {"rows_skipped_no_state": clean.attrs["rows_skipped_no_state"]}
        return out

    def _issue(self, rows: _AlertRows) -> None:
        """The frame's issued levels (``rows.level``), each track's filter fed its row once it is old
        enough (:func:`_issued_levels`, one row at a time)."""
        ids = rows.df["track_id"].to_numpy()
        for i, track in enumerate(ids.tolist()):
            t = float(rows.t[i])
            first = self._first_s.setdefault(track, t)
            if track not in self._ready and t - first < rows.required_age[i] - 1e-9:
                rows.raw["level"][i] = 0
                rows.raw["flarm_level"][i] = 0
                continue
            self._ready.add(track)
            evidence, hold = _filter_inputs(rows.raw, np.array([i]), rows.predicted)
            track_filter = self._filters.setdefault(track, AlertFilter(self.config))
            rows.level[i] = track_filter.update(t, int(evidence[0]), int(hold[0]))


def _since(window: pd.DataFrame | None, since_s: float) -> pd.DataFrame | None:
    """``window``'s rows from ``since_s`` on (s)."""
    return None if window is None else window[window["time_s"].to_numpy(float) >= since_s]
