"""Resolution advice: conflict bands on heading and vertical speed, and one preferred manoeuvre.

Bands follow DAIDALUS' instantaneous bands: for every candidate own-ship heading (same ground
speed and vertical speed) or vertical speed (same horizontal velocity), the straight-line
encounter with each intruder is checked for a loss of well clear within the lookahead; a
candidate is in a conflict band when any intruder (or, for vertical speed, the terrain) conflicts.
The preferred manoeuvre is BlueSky's Modified Voltage Potential (MVP): each conflicting intruder
pushes the own-ship velocity away from the intruder's position at closest approach by the
intrusion divided by the time to closest approach; the pushes add up over intruders. The MVP
heading and vertical speed are then moved to the nearest conflict-free candidate when they fall
inside a band.

Terrain: with the own-ship height above ground ``h`` and a minimum height ``h_min``, a vertical
speed ``vs`` (positive up) conflicts when ``h + vs * T_terrain < h_min``, i.e. it would take the
aircraft (or keep it) below the minimum at the end of the terrain lookahead. Heading bands do not
use terrain (the height above ground is all the flight-state estimate gives).
"""

from __future__ import annotations

import numpy as np

from skyradar.daa.conflict import WellClearVolume, cpa, loss_of_well_clear_interval

__all__ = [
    "heading_bands",
    "vertical_speed_bands",
    "band_intervals",
    "mvp_velocity",
    "resolution_advice",
    "advice_columns",
]


def _entry_times(
    own_vel: np.ndarray, s: np.ndarray, v_int: np.ndarray, volume, lookahead_s, dthr, zthr
) -> np.ndarray:
    """Earliest loss of well clear (s; inf if none) over intruders for each candidate own velocity (c, 3)."""
    if len(s) == 0:
        return np.full(len(own_vel), np.inf)
    rel_v = v_int[None, :, :] - own_vel[:, None, :]
    rel_s = np.broadcast_to(s[None, :, :], rel_v.shape)
    t_in, _ = loss_of_well_clear_interval(rel_s, rel_v, volume, lookahead_s, dthr, zthr)
    return np.where(np.isfinite(t_in), t_in, np.inf).min(axis=1)


def _heading_candidates(own: np.ndarray, step_deg: float) -> tuple[np.ndarray, np.ndarray]:
    headings = np.arange(0.0, 360.0, step_deg)
    gs, psi = np.hypot(own[0], own[1]), np.radians(headings)
    return headings, np.stack([gs * np.cos(psi), gs * np.sin(psi), np.full_like(psi, own[2])], axis=-1)


def _vs_candidates(
    own: np.ndarray, limits: tuple[float, float], step: float
) -> tuple[np.ndarray, np.ndarray]:
    vs = np.arange(limits[0], limits[1] + step / 2, step)
    return vs, np.stack([np.full_like(vs, own[0]), np.full_like(vs, own[1]), -vs], axis=-1)


def _terrain_conflict(vs, height_agl_m, min_height_agl_m, terrain_lookahead_s) -> np.ndarray:
    if height_agl_m is None or not np.isfinite(height_agl_m):
        return np.zeros(vs.shape, bool)
    return height_agl_m + vs * terrain_lookahead_s < min_height_agl_m


def _prepare(s, v_int, volume, dthr_m, zthr_m):
    s = np.asarray(s, float).reshape(-1, 3)
    v_int = np.asarray(v_int, float).reshape(-1, 3)
    dthr = np.broadcast_to(volume.dthr_m if dthr_m is None else np.asarray(dthr_m, float), (len(s),))
    zthr = np.broadcast_to(volume.zthr_m if zthr_m is None else np.asarray(zthr_m, float), (len(s),))
    return s, v_int, dthr, zthr


def heading_bands(
    own_vel_mps: np.ndarray,
    s: np.ndarray,
    v_int_mps: np.ndarray,
    volume: WellClearVolume,
    lookahead_s: float,
    step_deg: float = 1.0,
    dthr_m=None,
    zthr_m=None,
) -> tuple[np.ndarray, np.ndarray]:
    """Conflict flag for every own-ship heading at the current ground speed and vertical speed.

    Parameters
    ----------
    own_vel_mps : ndarray, shape (3,)
        Own-ship velocity, NED, m/s.
    s : ndarray, shape (n, 3)
        Intruder positions relative to the own-ship, NED, m.
    v_int_mps : ndarray, shape (n, 3)
        Intruder velocities (absolute), NED, m/s.
    volume : WellClearVolume
    lookahead_s : float
    step_deg : float
    dthr_m, zthr_m : array_like, optional
        Per-intruder (widened) thresholds.

    Returns
    -------
    headings_deg : ndarray
        Candidate headings from north, degrees in [0, 360).
    conflict : ndarray of bool

    Examples
    --------
    >>> h, c = heading_bands(np.array([50.0, 0, 0]), np.array([[3000.0, 0, 0]]),
    ...                      np.array([[-50.0, 0, 0]]), WellClearVolume(500.0, 100.0), 60.0)
    >>> bool(c[0]), bool(c[90])
    (True, False)
    """
    s, v_int, dthr, zthr = _prepare(s, v_int_mps, volume, dthr_m, zthr_m)
    headings, cand = _heading_candidates(np.asarray(own_vel_mps, float), step_deg)
    return headings, np.isfinite(_entry_times(cand, s, v_int, volume, lookahead_s, dthr, zthr))


def vertical_speed_bands(
    own_vel_mps: np.ndarray,
    s: np.ndarray,
    v_int_mps: np.ndarray,
    volume: WellClearVolume,
    lookahead_s: float,
    vs_limits_mps: tuple[float, float] = (-10.0, 10.0),
    step_mps: float = 0.5,
    height_agl_m: float | None = None,
    min_height_agl_m: float = 150.0,
    terrain_lookahead_s: float = 30.0,
    dthr_m=None,
    zthr_m=None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Conflict flags for every vertical speed (positive up) at the current horizontal velocity.

    Returns
    -------
    vs_mps : ndarray
        Candidate vertical speeds, m/s, positive up.
    traffic_conflict, terrain_conflict : ndarray of bool

    Examples
    --------
    >>> none = np.zeros((0, 3))
    >>> vs, traffic, terrain = vertical_speed_bands(np.array([50.0, 0, 0]), none, none,
    ...                                             WellClearVolume(500.0, 100.0), 60.0, height_agl_m=300.0)
    >>> float(vs[terrain].max())
    -5.5
    """
    s, v_int, dthr, zthr = _prepare(s, v_int_mps, volume, dthr_m, zthr_m)
    vs, cand = _vs_candidates(np.asarray(own_vel_mps, float), vs_limits_mps, step_mps)
    traffic = np.isfinite(_entry_times(cand, s, v_int, volume, lookahead_s, dthr, zthr))
    return vs, traffic, _terrain_conflict(vs, height_agl_m, min_height_agl_m, terrain_lookahead_s)


def band_intervals(
    values: np.ndarray, conflict: np.ndarray, step: float, circular: bool = False
) -> list[list[float]]:
    """Merge flagged candidates into ``[lo, hi]`` intervals (each candidate covers +-step/2).

    With ``circular`` (headings) an interval crossing 360 is returned as ``[lo, hi + 360]``.

    Examples
    --------
    >>> band_intervals(np.arange(0.0, 360.0, 90.0), np.array([True, False, False, True]), 90.0, circular=True)
    [[225.0, 405.0]]
    """
    conflict = np.asarray(conflict, bool)
    if not conflict.any():
        return []
    if conflict.all():
        return [[float(values[0] - step / 2), float(values[-1] + step / 2)]]
    idx = np.flatnonzero(conflict)
    runs = np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1)
    out = [[float(values[r[0]] - step / 2), float(values[r[-1]] + step / 2)] for r in runs]
    if circular and len(out) > 1 and conflict[0] and conflict[-1]:
        first = out.pop(0)
        out[-1][1] = first[1] + 360.0
    return out


def _mvp_horizontal(s: np.ndarray, vrel: np.ndarray, pz: np.ndarray) -> np.ndarray:
    """Horizontal MVP push (n, 2) per conflict: along the miss vector, intrusion over tcpa."""
    tcpa, _, _ = cpa(s, vrel)
    dist = np.maximum(np.hypot(s[:, 0], s[:, 1]), 1e-6)
    dcpa = s[:, :2] + vrel[:, :2] * tcpa[:, None]
    dabs = np.hypot(dcpa[:, 0], dcpa[:, 1])
    head_on = dabs <= 10.0
    # Head-on: no miss vector to push along, so push perpendicular to the line of sight.
    perp = np.stack([-s[:, 1], s[:, 0]], axis=-1) / dist[:, None] * 10.0
    dcpa = np.where(head_on[:, None], perp, dcpa)
    dabs = np.where(head_on, 10.0, dabs)
    tdiv = np.maximum(np.abs(tcpa), 0.5)
    outside = (pz < dist) & (dabs < dist)
    erratum = np.cos(np.arcsin(np.minimum(pz / dist, 1.0)) - np.arcsin(np.minimum(dabs / dist, 1.0)))
    push = np.where(outside, pz / np.where(outside, erratum, 1.0) - dabs, pz - dabs)
    return push[:, None] * dcpa / (tdiv * dabs)[:, None]


def _mvp_vertical(s, vrel, t_los, hpz, lookahead_s: float) -> np.ndarray:
    """Vertical MVP push (n,) per conflict, up positive as in BlueSky."""
    # Intrusion over the time to co-altitude, against the relative vertical rate; with no
    # relative rate, away from the intruder's side.
    d_up, v_up = -s[:, 2], -vrel[:, 2]
    moving = np.abs(v_up) > 0
    tsol = np.where(moving, np.abs(d_up) / np.where(moving, np.abs(v_up), 1.0), t_los)
    i_v = np.where(moving, hpz, hpz - np.abs(d_up))
    slow = tsol > lookahead_s
    tsol = np.maximum(np.where(slow, t_los, tsol), 0.5)
    i_v = np.where(slow, hpz, i_v)
    sign = np.where(moving, -np.sign(v_up), np.where(d_up >= 0, 1.0, -1.0))
    return i_v / tsol * sign


def mvp_velocity(
    own_vel_mps: np.ndarray,
    s: np.ndarray,
    v_int_mps: np.ndarray,
    volume: WellClearVolume,
    lookahead_s: float,
    resofac: float = 1.05,
    dthr_m=None,
    zthr_m=None,
) -> tuple[np.ndarray, np.ndarray]:
    """Own-ship velocity after the Modified Voltage Potential resolution (BlueSky's MVP).

    Only intruders with a predicted loss of well clear within ``lookahead_s`` contribute; the
    own-ship takes the whole manoeuvre (the intruder is not cooperative).

    Returns
    -------
    new_vel_mps : ndarray, shape (3,)
        Resolution velocity, NED, m/s.
    in_conflict : ndarray of bool, shape (n,)

    Examples
    --------
    >>> v, c = mvp_velocity(np.array([50.0, 0, 0]), np.array([[3000.0, 100.0, 0]]),
    ...                     np.array([[-50.0, 0, 0]]), WellClearVolume(500.0, 100.0), 60.0)
    >>> bool(c[0]), bool(v[1] < 0)
    (True, True)
    """
    s, v_int, dthr, zthr = _prepare(s, v_int_mps, volume, dthr_m, zthr_m)
    own = np.asarray(own_vel_mps, float)
    vrel = v_int - own
    t_los, _ = loss_of_well_clear_interval(s, vrel, volume, lookahead_s, dthr, zthr)
    conf = np.isfinite(t_los)
    if not conf.any():
        return own.copy(), conf
    s, vrel, t_los = s[conf], vrel[conf], t_los[conf]
    dv_h = _mvp_horizontal(s, vrel, dthr[conf] * resofac)
    dv_up = _mvp_vertical(s, vrel, t_los, zthr[conf] * resofac, lookahead_s)
    new = own.copy()
    new[:2] -= dv_h.sum(axis=0)
    new[2] += dv_up.sum()  # own vs_up -= dv_up, i.e. down += dv_up
    return new, conf


def _choose(values, entry_s, allowed, target: float, circular: bool) -> float:
    """Candidate nearest ``target`` among the conflict-free allowed ones; else the allowed one whose
    loss of well clear comes latest (recovery); else the one nearest ``target``."""
    diff = np.abs(values - target)
    if circular:
        diff = np.minimum(diff, 360.0 - diff)
    free = allowed & ~np.isfinite(entry_s)
    if free.any():
        return float(values[free][np.argmin(diff[free])])
    if allowed.any():
        latest = allowed & (entry_s == entry_s[allowed].max())
        return float(values[latest][np.argmin(diff[latest])])
    return float(values[np.argmin(diff)])


def resolution_advice(
    own_vel_mps: np.ndarray,
    s: np.ndarray,
    v_int_mps: np.ndarray,
    volume: WellClearVolume,
    lookahead_s: float,
    height_agl_m: float | None = None,
    min_height_agl_m: float = 150.0,
    step_deg: float = 1.0,
    vs_step_mps: float = 0.5,
    dthr_m=None,
    zthr_m=None,
) -> dict:
    """Bands and the preferred manoeuvre for one own-ship state against several intruders.

    Returns
    -------
    dict
        ``heading_bands_deg`` and ``vs_bands_mps`` (conflict intervals from traffic),
        ``terrain_vs_bands_mps``, ``mvp_heading_deg``, ``mvp_vs_mps`` (raw MVP),
        ``preferred_heading_deg``, ``preferred_vs_mps`` (the MVP values moved to the nearest
        conflict-free candidate; when every candidate conflicts, the one whose loss of well clear
        comes latest, never one into the terrain if any other exists),
        ``heading_saturated``, ``vs_saturated`` (every candidate conflicts), ``n_conflicts``.

    Examples
    --------
    >>> adv = resolution_advice(np.array([50.0, 0, 0]), np.array([[3000.0, 100.0, 0]]),
    ...                         np.array([[-50.0, 0, 0]]), WellClearVolume(500.0, 100.0), 60.0)
    >>> 270 < adv["preferred_heading_deg"] < 360
    True
    """
    own = np.asarray(own_vel_mps, float)
    s, v_int, dthr, zthr = _prepare(s, v_int_mps, volume, dthr_m, zthr_m)
    headings, h_cand = _heading_candidates(own, step_deg)
    h_entry = _entry_times(h_cand, s, v_int, volume, lookahead_s, dthr, zthr)
    vs, v_cand = _vs_candidates(own, (-10.0, 10.0), vs_step_mps)
    v_entry = _entry_times(v_cand, s, v_int, volume, lookahead_s, dthr, zthr)
    vs_terrain = _terrain_conflict(vs, height_agl_m, min_height_agl_m, 30.0)
    h_conf, vs_traffic = np.isfinite(h_entry), np.isfinite(v_entry)
    vs_conf = vs_traffic | vs_terrain
    new_vel, conf = mvp_velocity(own, s, v_int, volume, lookahead_s, dthr_m=dthr, zthr_m=zthr)
    mvp_heading = float(np.degrees(np.arctan2(new_vel[1], new_vel[0])) % 360.0)
    mvp_vs = float(-new_vel[2])
    pref_h = _choose(headings, h_entry, np.ones(len(headings), bool), mvp_heading, circular=True)
    pref_v = _choose(vs, v_entry, ~vs_terrain, mvp_vs, circular=False)
    return {
        "heading_saturated": bool(h_conf.all()),
        "vs_saturated": bool(vs_conf.all()),
        "heading_bands_deg": band_intervals(headings, h_conf, step_deg, circular=True),
        "vs_bands_mps": band_intervals(vs, vs_traffic, vs_step_mps),
        "terrain_vs_bands_mps": band_intervals(vs, vs_terrain, vs_step_mps),
        "mvp_heading_deg": mvp_heading,
        "mvp_vs_mps": mvp_vs,
        "preferred_heading_deg": pref_h,
        "preferred_vs_mps": pref_v,
        "n_conflicts": int(conf.sum()),
    }


def advice_columns(
    alerts,
    s,
    v_int,
    own_vel,
    height_agl_m,
    dthr_m,
    zthr_m,
    volume: WellClearVolume,
    alerting_time_s: float,
    located: np.ndarray | None = None,
) -> None:
    """Add the per-frame advice columns to an alerts table (in place), on frames with an issued alert.

    ``alerts`` is sorted by time with a ``level`` column; ``s``, ``v_int`` (intruder position
    relative to the own-ship, intruder velocity), ``own_vel``, ``dthr_m`` and ``zthr_m`` are per
    row, ``height_agl_m`` per row or None. Each frame's :func:`resolution_advice` is repeated on
    every row of the frame; frames with no alert get empty bands and NaN preferences.

    ``located`` (per row, default all True) marks the rows with a position. A row without one (a
    range-only track, :mod:`skyradar.daa.range_only`) has no bearing: it takes no part in the
    advice, and a frame where such a row alerts gets none (empty bands, NaN preferences), since a
    band or manoeuvre computed without it could lead into it.

    Parameters
    ----------
    alerts : DataFrame
        Alerts table sorted by ``time_s`` (s), with a ``level`` column; the columns are added to it.
    s : ndarray, shape (n, 3)
        Intruder position relative to the own-ship per row, NED, m.
    v_int : ndarray, shape (n, 3)
        Intruder velocity per row, NED, m/s.
    own_vel : ndarray, shape (n, 3)
        Own-ship velocity per row, NED, m/s.
    height_agl_m : ndarray, shape (n,), or None
        Own-ship height above ground per row, m (None: no terrain bands).
    dthr_m, zthr_m : ndarray, shape (n,)
        Horizontal and vertical thresholds per row (widened by the track's uncertainty), m.
    volume : WellClearVolume
        The well-clear volume of the advice (thresholds in m and s).
    alerting_time_s : float
        Lookahead of the bands, s.
    located : ndarray of bool, shape (n,), optional
        Rows with a position (default all).

    Returns
    -------
    None
        ``alerts`` gains ``heading_bands_deg`` (deg), ``vs_bands_mps``, ``terrain_vs_bands_mps``
        (m/s; each a flat list of band bounds per row), ``preferred_heading_deg`` (deg) and
        ``preferred_vs_mps`` (m/s).

    Examples
    --------
    Two intruders in the frame at 0 s, one of them alerting, and a frame at 1 s without an alert:
    both rows of the first frame carry that frame's :func:`resolution_advice`.

    >>> import pandas as pd
    >>> alerts = pd.DataFrame({"time_s": [0.0, 0.0, 1.0], "level": [3, 0, 0]})
    >>> s = np.array([[3000.0, 100.0, 0.0], [0.0, 5000.0, 0.0], [2900.0, 100.0, 0.0]])
    >>> v = np.array([[-50.0, 0.0, 0.0], [0.0, 0.0, 0.0], [-50.0, 0.0, 0.0]])
    >>> own, vol = np.tile([50.0, 0.0, 0.0], (3, 1)), WellClearVolume(500.0, 100.0)
    >>> advice_columns(alerts, s, v, own, None, np.full(3, 500.0), np.full(3, 100.0), vol, 60.0)
    >>> adv = resolution_advice(own[0], s[:2], v[:2], vol, 60.0, dthr_m=np.full(2, 500.0),
    ...                         zthr_m=np.full(2, 100.0))
    >>> adv["heading_bands_deg"], adv["preferred_heading_deg"]
    ([[344.5, 382.5]], 344.0)
    >>> alerts["heading_bands_deg"].tolist(), alerts["preferred_heading_deg"].tolist()
    ([[344.5, 382.5], [344.5, 382.5], []], [344.0, 344.0, nan])
    """
    n = len(alerts)
    names = ("heading_bands_deg", "vs_bands_mps", "terrain_vs_bands_mps")
    lists: dict[str, list] = {name: [[]] * n for name in names}  # shared empty list; replaced, never mutated
    pref = {"preferred_heading_deg": np.full(n, np.nan), "preferred_vs_mps": np.full(n, np.nan)}
    times = alerts["time_s"].to_numpy()
    alerting = alerts["level"].to_numpy() > 0
    placed = np.ones(n, bool) if located is None else np.asarray(located, bool)
    # Rows are sorted by time, so each frame is one contiguous block.
    starts = np.flatnonzero(np.r_[True, times[1:] != times[:-1]])
    stops = np.r_[starts[1:], n]
    for a, b in zip(starts, stops, strict=True):
        if not alerting[a:b].any() or (alerting[a:b] & ~placed[a:b]).any():
            continue
        rows = np.arange(a, b)[placed[a:b]]
        adv = resolution_advice(
            own_vel[a],
            s[rows],
            v_int[rows],
            volume,
            alerting_time_s,
            height_agl_m=None if height_agl_m is None else float(height_agl_m[a]),
            dthr_m=dthr_m[rows],
            zthr_m=zthr_m[rows],
        )
        for name in names:
            flat = [float(x) for band in adv[name] for x in band]
            lists[name][a:b] = [flat] * (b - a)
        for name in pref:
            pref[name][a:b] = adv[name]
    for name in names:
        alerts[name] = lists[name]
    for name, values in pref.items():
        alerts[name] = values
