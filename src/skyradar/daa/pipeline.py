"""Tracks table + own-ship state -> alerts table.

Tracks table (input), one row per track per frame, SI units, NED in the scenario frame:
``time_s, track_id, north_m, east_m, down_m, vn_mps, ve_mps, vd_mps`` and, when the tracker gives
them, the position covariance ``cov_pp_00 .. cov_pp_22`` (m^2) and velocity covariance
``cov_vv_00 .. cov_vv_22`` (m^2/s^2), row-major 3x3 in NED; missing covariance counts as zero.
Rows with NaN position or velocity (no direction of arrival) are skipped; with a ``confirmed``
column only confirmed rows are used. ``AlertConfig.max_velocity_sigma_mps`` silences rows of tracks
whose velocity has not converged.

Own-ship table: ``time_s, own_north_m, own_east_m, own_down_m, own_vn_mps, own_ve_mps, own_vd_mps``
and optionally ``own_yaw_rad`` (heading; else the ground track) and ``own_height_agl_m`` (terrain
advice). :func:`ownship_from_frames` reads it from a frames run.

Alerts table (output), one row per track per frame: ``time_s, track_id, level`` (issued: 0 none,
1 preventive, 2 corrective, 3 warning), ``raw_level, flarm_level, t_in_s`` (predicted loss of well
clear), ``time_to_impact_s, tcpa_s, hmd_m, vmd_m, range_m, bearing_deg`` (relative to the heading,
positive right), ``sector`` (0..11 clockwise from dead ahead), ``layer`` (-2..2), ``rel_north_m,
rel_east_m, rel_alt_m`` (positive above), ``climb_rate_mps`` (intruder, positive up), and the advice
of that frame, repeated on every row of the frame (empty/NaN when no track alerts):
``heading_bands_deg, vs_bands_mps, terrain_vs_bands_mps`` (flattened conflict intervals
``[lo0, hi0, lo1, hi1, ...]``), ``preferred_heading_deg, preferred_vs_mps``.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import xarray as xr

from skyradar.daa.advice import resolution_advice
from skyradar.daa.alerting import AlertConfig, filter_alert_levels, raw_alert_levels
from skyradar.daa.conflict import traffic_indication
from skyradar.errors import InputError
from skyradar.io.tables import finite_column
from skyradar.track.track_table import OWNSHIP_COLUMNS as TRACKER_OWNSHIP_COLUMNS

__all__ = ["TRACK_COLUMNS", "OWNSHIP_COLUMNS", "ownship_from_frames", "truth_tracks", "alerts_from_tracks"]

TRACK_COLUMNS = ["time_s", "track_id", "north_m", "east_m", "down_m", "vn_mps", "ve_mps", "vd_mps"]
OWNSHIP_COLUMNS = list(TRACKER_OWNSHIP_COLUMNS)  # the own-ship table the tracker reads, too
_COV_P = [f"cov_pp_{i}{j}" for i in range(3) for j in range(3)]
_COV_V = [f"cov_vv_{i}{j}" for i in range(3) for j in range(3)]
_OPTIONAL_OWN = ["own_yaw_rad", "own_height_agl_m"]


def ownship_from_frames(ds: xr.Dataset, source: str = "frames") -> pd.DataFrame:
    """Own-ship truth of a frames run as a table (see module docstring)."""
    missing = [c for c in OWNSHIP_COLUMNS[1:] if c not in ds]
    if missing:
        raise InputError(f"{source}: no own-ship state (missing variable(s) {missing})")
    cols = {"time_s": np.asarray(ds["time"].values, float)}
    for name in OWNSHIP_COLUMNS[1:] + [c for c in _OPTIONAL_OWN if c in ds]:
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
    t = np.asarray(ds["time"].values, float)
    n_t, n_tgt = ds["tgt_north_m"].shape
    cols = {"time_s": np.repeat(t, n_tgt), "track_id": np.tile(np.arange(n_tgt), n_t)}
    for c in names:
        cols[c] = np.asarray(ds[f"tgt_{c}"].values, float).ravel()
    df = pd.DataFrame(cols)
    if visible_only and "tgt_visible" in ds:
        df = df[np.asarray(ds["tgt_visible"].values, bool).ravel()]
    return df.reset_index(drop=True)


def _interp_ownship(own: pd.DataFrame, times: np.ndarray, source: str) -> dict[str, np.ndarray]:
    own = own.sort_values("time_s")
    t = own["time_s"].to_numpy(float)
    if times.size and (times.min() < t[0] - 1.0 or times.max() > t[-1] + 1.0):
        raise InputError(
            f"{source}: field 'time_s' ({times.min():.2f}..{times.max():.2f} s) outside the own-ship "
            f"state ({t[0]:.2f}..{t[-1]:.2f} s)"
        )
    out = {}
    for c in OWNSHIP_COLUMNS[1:] + [c for c in _OPTIONAL_OWN if c in own]:
        values = own[c].to_numpy(float)
        values = np.unwrap(values) if c == "own_yaw_rad" else values
        out[c] = np.interp(times, t, values)
    if "own_yaw_rad" not in out:
        out["own_yaw_rad"] = np.arctan2(out["own_ve_mps"], out["own_vn_mps"])
    return out


def _covariances(df: pd.DataFrame) -> tuple[np.ndarray | None, np.ndarray | None]:
    cov_p = df[_COV_P].to_numpy(float).reshape(-1, 3, 3) if all(c in df for c in _COV_P) else None
    cov_v = df[_COV_V].to_numpy(float).reshape(-1, 3, 3) if all(c in df for c in _COV_V) else None
    return cov_p, cov_v


def _clean_tracks(tracks: pd.DataFrame, source: str) -> pd.DataFrame:
    """Checked, confirmed rows with a 3-D state; ``attrs['rows_skipped_no_state']`` counts the others.

    NaN position/velocity means "no direction of arrival" and skips the row; anything else that
    is not a finite number (a string, an infinity, a NaN time or id) is refused naming the row.
    """
    missing = [c for c in TRACK_COLUMNS if c not in tracks]
    if missing:
        raise InputError(f"{source}: missing column(s) {missing}")
    df = tracks.reset_index(drop=True)
    cols = {c: finite_column(df, c, source, allow_nan=c not in ("time_s", "track_id")) for c in TRACK_COLUMNS}
    ids = cols["track_id"]
    if (ids != np.round(ids)).any():
        bad = int(np.flatnonzero(ids != np.round(ids))[0])
        raise InputError(f"{source}: field 'track_id' is not a whole number at row {bad} ({ids[bad]!r})")
    # Track ids stay integers in the alerts, as the tracker wrote them.
    df = df.assign(**cols | {"track_id": ids.astype(np.int64)})
    if "confirmed" in df:
        flag = df["confirmed"]
        if flag.dtype != bool and not flag.isin([0, 1]).all():
            bad = int(np.flatnonzero(~flag.isin([0, 1]))[0])
            raise InputError(
                f"{source}: field 'confirmed' is not a boolean at row {bad} ({flag.iloc[bad]!r})"
            )
        df = df[flag.astype(bool).to_numpy()]
    ok = np.isfinite(df[TRACK_COLUMNS[2:]].to_numpy(float)).all(axis=1)
    clean = df[ok].sort_values(["time_s", "track_id"], kind="stable").reset_index(drop=True)
    clean.attrs["rows_skipped_no_state"] = int((~ok).sum())
    return clean


def _advice_columns(out: pd.DataFrame, s, v_int, own_vel, height, raw, config: AlertConfig) -> None:
    """Fill the per-frame advice columns for frames where any track has an issued alert."""
    n = len(out)
    names = ("heading_bands_deg", "vs_bands_mps", "terrain_vs_bands_mps")
    lists: dict[str, list] = {name: [[]] * n for name in names}  # shared empty list; replaced, never mutated
    pref = {"preferred_heading_deg": np.full(n, np.nan), "preferred_vs_mps": np.full(n, np.nan)}
    corrective = config.levels[min(1, len(config.levels) - 1)]
    times = out["time_s"].to_numpy()
    alerting = out["level"].to_numpy() > 0
    # Rows are sorted by time, so each frame is one contiguous block.
    starts = np.flatnonzero(np.r_[True, times[1:] != times[:-1]])
    stops = np.r_[starts[1:], n]
    for a, b in zip(starts, stops, strict=True):
        if not alerting[a:b].any():
            continue
        adv = resolution_advice(
            own_vel[a], s[a:b], v_int[a:b], corrective.volume, corrective.alerting_time_s,
            height_agl_m=None if height is None else float(height[a]),
            dthr_m=raw["dthr_m"][a:b], zthr_m=raw["zthr_m"][a:b],
        )  # fmt: skip
        for name in names:
            flat = [float(x) for band in adv[name] for x in band]
            lists[name][a:b] = [flat] * (b - a)
        for name in pref:
            pref[name][a:b] = adv[name]
    for name in names:
        out[name] = lists[name]
    for name, values in pref.items():
        out[name] = values


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
        Tracks table (see module docstring).
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
    """
    config = config or AlertConfig()
    df = _clean_tracks(tracks, source)
    t = df["time_s"].to_numpy(float)
    own = _interp_ownship(ownship, t, source)
    own_pos = np.stack([own["own_north_m"], own["own_east_m"], own["own_down_m"]], -1)
    own_vel = np.stack([own["own_vn_mps"], own["own_ve_mps"], own["own_vd_mps"]], -1)
    p = df[["north_m", "east_m", "down_m"]].to_numpy(float)
    v_int = df[["vn_mps", "ve_mps", "vd_mps"]].to_numpy(float)
    s, v = p - own_pos, v_int - own_vel
    cov_p, cov_v = _covariances(df)
    raw = raw_alert_levels(s, v, config, cov_p, cov_v)
    if config.max_velocity_sigma_mps is not None and cov_v is not None:
        sigma_hv = np.sqrt(np.nan_to_num(cov_v[:, 0, 0] + cov_v[:, 1, 1], nan=np.inf))
        unconverged = sigma_hv > config.max_velocity_sigma_mps
        raw["level"][unconverged] = 0
        raw["flarm_level"][unconverged] = 0
    level = np.zeros(len(df), int)
    for _, idx in df.groupby("track_id", sort=False).indices.items():
        young = t[idx] - t[idx[0]] < config.min_track_age_s
        raw["level"][idx[young]] = 0
        raw["flarm_level"][idx[young]] = 0
        level[idx] = filter_alert_levels(t[idx], raw["level"][idx], config)
    ind = traffic_indication(s, own["own_yaw_rad"])
    out = pd.DataFrame(
        {
            "time_s": t,
            "track_id": df["track_id"].to_numpy(),
            "level": level,
            "raw_level": raw["level"],
            "flarm_level": raw["flarm_level"],
            "t_in_s": raw["t_in_s"],
            "time_to_impact_s": raw["time_to_impact_s"],
            "tcpa_s": raw["tcpa_s"],
            "hmd_m": raw["hmd_m"],
            "vmd_m": raw["vmd_m"],
            "range_m": np.linalg.norm(s, axis=-1),
            "bearing_deg": np.degrees(ind["bearing_rad"]),
            "sector": ind["sector"],
            "layer": ind["layer"],
            "rel_north_m": s[:, 0],
            "rel_east_m": s[:, 1],
            "rel_alt_m": ind["rel_alt_m"],
            "climb_rate_mps": -v_int[:, 2],
        }
    )
    if with_advice:
        _advice_columns(out, s, v_int, own_vel, own.get("own_height_agl_m"), raw, config)
    out.attrs["rows_skipped_no_state"] = df.attrs["rows_skipped_no_state"]
    return out
