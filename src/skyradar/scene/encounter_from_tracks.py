"""An encounter made from two real trajectories: the intruder is moved in time and space to meet the own ship.

Given an own-ship track A and an intruder track B (ADS-B files, GPS logs, any
:class:`~skyradar.scene.trajectories.Trajectory`), :func:`encounter_from_tracks` keeps A as it
flew and moves B rigidly so that B's state at ``intruder_time_s`` meets A's state at ``t_cpa_s``:

1. both are expressed in the NED frame of A's position at ``t_cpa_s`` (the new scenario origin),
   B through the NED frame of its own meeting point, so that a track recorded a continent away
   arrives without curvature error;
2. B is optionally turned about the vertical by ``rotate_deg`` (clockwise, around its meeting
   point; velocities turn with it);
3. B is shifted in time by ``t_cpa_s - intruder_time_s`` and in space so that at ``t_cpa_s`` it
   sits ``horizontal_miss_m`` from A, perpendicular to the horizontal relative velocity (so that
   ``t_cpa_s`` is the time of the closest horizontal approach), on the ``side`` of A's track, and
   ``vertical_miss_m`` above A (negative: below).

For flights that are straight around the meeting the closest approach is exactly the requested
one (the tests check this in closed form); turning flights meet to first order, and
:func:`horizontal_cpa` measures what the result really does.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import pandas as pd

from skyradar.errors import InputError
from skyradar.scene.trajectories import Trajectory

# The closest approach is placed within this time of the requested one (s): far enough to cover the
# encounter, near enough that a long recorded flight's other crossings do not count.
REFINE_WINDOW_S = 30.0

__all__ = ["encounter_from_tracks", "horizontal_cpa", "trajectory_table", "encounter_scenario"]


def _yaw_rotation(angle_deg: float) -> np.ndarray:
    """NED rotation by ``angle_deg`` clockwise seen from above (north towards east)."""
    c, s = np.cos(np.radians(angle_deg)), np.sin(np.radians(angle_deg))
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _miss_direction(own_vel: np.ndarray, rel_vel: np.ndarray, side: str) -> np.ndarray:
    """Unit horizontal vector from A to B at the closest approach (perpendicular to the relative
    horizontal velocity), on the requested side of A's track."""
    heading = np.arctan2(own_vel[1], own_vel[0])
    right = np.array([-np.sin(heading), np.cos(heading)])
    speed = np.hypot(*rel_vel[:2])
    if speed < 1e-6:  # same velocity: no closest approach in time; put B abeam
        u = right
    else:
        u = np.array([-rel_vel[1], rel_vel[0]]) / speed
        u = u if np.dot(u, right) >= 0.0 else -u
    u = u if side == "right" else -u
    return np.array([u[0], u[1], 0.0])


def encounter_from_tracks(
    ownship: Trajectory,
    intruder: Trajectory,
    t_cpa_s: float,
    horizontal_miss_m: float,
    vertical_miss_m: float = 0.0,
    intruder_time_s: float | None = None,
    rotate_deg: float = 0.0,
    side: Literal["right", "left"] = "right",
) -> tuple[Trajectory, Trajectory]:
    """(own ship, intruder) in the NED frame of the own ship's position at ``t_cpa_s``.

    Parameters
    ----------
    ownship, intruder : Trajectory
        The two flights, in any frames and clocks.
    t_cpa_s : float
        Own-ship time of the closest approach, s (in ``ownship.time_s``).
    horizontal_miss_m : float
        Horizontal distance at the closest approach, m (>= 0).
    vertical_miss_m : float
        Intruder height above the own ship at ``t_cpa_s``, m.
    intruder_time_s : float, optional
        Intruder time that is moved to ``t_cpa_s``; default the middle of its span.
    rotate_deg : float
        Turn of the intruder's flight about the vertical, degrees clockwise.
    side : {"right", "left"}
        Side of the own ship's track on which the intruder passes.

    Examples
    --------
    >>> from skyradar.scene.flights import straight
    >>> a = straight([0, 0, -1000], 0.0, 50.0, 120.0, origin=(47.0, 11.0, 0.0))
    >>> b = straight([0, 0, -800], 90.0, 40.0, 200.0, origin=(40.0, -8.0, 0.0))
    >>> own, intr = encounter_from_tracks(a, b, 60.0, 150.0, vertical_miss_m=30.0)
    >>> t, h_m, v_m = horizontal_cpa(own, intr)
    >>> round(t, 2), round(h_m, 2), round(v_m, 2)
    (60.0, 150.0, 30.0)
    """
    t_b = 0.5 * (intruder.start_s + intruder.end_s) if intruder_time_s is None else float(intruder_time_s)
    _check_request(ownship, intruder, t_cpa_s, t_b, (horizontal_miss_m, vertical_miss_m, rotate_deg), side)
    meet = ownship.sample(t_cpa_s)
    own = ownship.reframed((float(meet.lat_deg[0]), float(meet.lon_deg[0]), float(meet.alt_m[0])))
    b_meet = intruder.sample(t_b)
    local = intruder.reframed((float(b_meet.lat_deg[0]), float(b_meet.lon_deg[0]), float(b_meet.alt_m[0])))
    rot = _yaw_rotation(rotate_deg)
    turned = Trajectory.from_states(
        local.time_s + (t_cpa_s - t_b),
        local.position_ned_m @ rot.T,
        local.velocity_ned_mps @ rot.T,
        origin=own.origin,
        name=intruder.name,
        epoch_s=intruder.epoch_s - (t_cpa_s - t_b),
    )
    a_state, b_state = own.sample(t_cpa_s), turned.sample(t_cpa_s)
    u = _miss_direction(
        a_state.velocity_ned_mps[0], b_state.velocity_ned_mps[0] - a_state.velocity_ned_mps[0], side
    )
    want = horizontal_miss_m * u + np.array([0.0, 0.0, -vertical_miss_m])  # intruder - own at the CPA
    shift = a_state.position_ned_m[0] - b_state.position_ned_m[0] + want
    return own, _refined(own, turned, shift, t_cpa_s, want)


def _check_request(ownship, intruder, t_cpa_s: float, t_b: float, numbers, side: str) -> None:
    horizontal_miss_m, vertical_miss_m, rotate_deg = numbers
    if not np.isfinite(horizontal_miss_m) or horizontal_miss_m < 0:
        raise InputError(f"horizontal miss: must be a finite distance >= 0 m, got {horizontal_miss_m!r}")
    for name, value in (("vertical miss", vertical_miss_m), ("rotation", rotate_deg)):
        if not np.isfinite(value):
            raise InputError(f"{name}: must be finite, got {value!r}")
    if side not in ("right", "left"):
        raise InputError(f"side: must be 'right' or 'left', got {side!r}")
    for traj, when, what in ((ownship, t_cpa_s, "closest-approach time"), (intruder, t_b, "intruder time")):
        if not traj.covers(when):
            raise InputError(
                f"{what}: {when:g} s is outside '{traj.name}' ({traj.start_s:g}..{traj.end_s:g} s)"
            )


def _refined(own: Trajectory, turned: Trajectory, shift: np.ndarray, t_cpa_s: float, want: np.ndarray):
    """``turned`` moved by ``shift``, corrected until its closest horizontal approach within
    :data:`REFINE_WINDOW_S` of ``t_cpa_s`` happens at ``t_cpa_s`` with the wanted miss.

    A straight encounter needs no correction. Along curved flights a damped Newton step on the
    horizontal shift (finite-difference Jacobian of (CPA time, miss)) corrects it; when the flights
    manoeuvre too hard for that to converge, the best try is kept (:func:`horizontal_cpa` says
    what it does).
    """
    from dataclasses import replace

    window = (t_cpa_s - REFINE_WINDOW_S, t_cpa_s + REFINE_WINDOW_S)
    miss = float(np.hypot(want[0], want[1]))

    def residual(s: np.ndarray) -> tuple[np.ndarray, float]:
        moved = replace(turned, position_ned_m=turned.position_ned_m + s)
        t_star, h_m, v_m = horizontal_cpa(own, moved, window=window)
        return np.array([(t_star - t_cpa_s) * 10.0, h_m - miss]), v_m  # 0.1 s weighs like 1 m

    res, v_m = residual(shift)
    for _ in range(12):
        if np.all(np.abs(res) < 0.05):
            break
        jac = np.empty((2, 2))
        for k in range(2):
            step = np.zeros(3)
            step[k] = 1.0
            jac[:, k] = residual(shift + step)[0] - res
        try:
            delta = np.linalg.lstsq(jac, -res, rcond=None)[0]
        except np.linalg.LinAlgError:
            break
        for scale in (1.0, 0.5, 0.25, 0.1):  # backtrack: take the first step that improves
            trial = shift + np.append(scale * delta, 0.0)
            trial_res, trial_v = residual(trial)
            if np.linalg.norm(trial_res) < np.linalg.norm(res):
                shift, res, v_m = trial, trial_res, trial_v
                break
        else:
            break
    shift = shift + np.array([0.0, 0.0, want[2] + v_m])  # the wanted height at the CPA time
    return replace(turned, position_ned_m=turned.position_ned_m + shift)


def horizontal_cpa(
    own: Trajectory, intruder: Trajectory, step_s: float = 0.01, window: tuple[float, float] | None = None
) -> tuple[float, float, float]:
    """(time s, horizontal distance m, intruder height above own ship m) of the closest horizontal
    approach over the time both fly (within ``window``, s), sampled every ``step_s`` and refined by
    a parabola.

    Examples
    --------
    >>> from skyradar.scene.flights import straight
    >>> a = straight([0, 0, -500], 0.0, 40.0, 60.0)
    >>> b = straight([1200, -600, -520], 90.0, 20.0, 60.0)
    >>> [round(v, 3) for v in horizontal_cpa(a, b)]
    [30.0, 0.0, 20.0]
    """
    start, end = max(own.start_s, intruder.start_s), min(own.end_s, intruder.end_s)
    if window is not None:
        start, end = max(start, window[0]), min(end, window[1])
    if not end > start:
        raise InputError(f"'{own.name}' and '{intruder.name}' do not fly at the same time")
    t = np.linspace(start, end, max(int(np.ceil((end - start) / step_s)) + 1, 3))
    rel = intruder.sample(t).position_ned_m - own.sample(t).position_ned_m
    dist = np.hypot(rel[:, 0], rel[:, 1])
    k = int(np.clip(np.argmin(dist), 1, t.size - 2))
    d2 = dist[k - 1 : k + 2] ** 2  # squared distance is a parabola in time for straight flights
    denom = d2[0] - 2 * d2[1] + d2[2]
    frac = 0.5 * (d2[0] - d2[2]) / denom if denom > 0 else 0.0
    t_min = float(t[k] + np.clip(frac, -1.0, 1.0) * (t[1] - t[0]))
    r = (intruder.sample(t_min).position_ned_m - own.sample(t_min).position_ned_m)[0]
    return t_min, float(np.hypot(r[0], r[1])), float(-r[2])


def trajectory_table(traj: Trajectory) -> pd.DataFrame:
    """A trajectory as an SI track table :mod:`skyradar.scene.adsb` reads back exactly.

    Columns ``time_s, latitude, longitude, alt_m, vn, ve, vd`` (velocities in the local NED
    frame at the aircraft, as the SI convention has them).

    Examples
    --------
    >>> from skyradar.scene.flights import straight
    >>> trajectory_table(straight([0, 0, -100], 90.0, 30.0, 1.0, rate_hz=1.0)).round(3).iloc[1].tolist()
    [1.0, 0.0, 0.0, 100.0, 0.0, 30.0, -0.0]
    """
    from skyradar.scene.trajectories import origin_to_local_rotation

    s = traj.sample(traj.time_s)
    rot = origin_to_local_rotation(s.lat_deg, s.lon_deg, traj.origin[0], traj.origin[1])
    local = np.einsum("nij,nj->ni", rot, s.velocity_ned_mps)
    return pd.DataFrame(
        {
            "time_s": s.time_s,
            "latitude": s.lat_deg,
            "longitude": s.lon_deg,
            "alt_m": s.alt_m,
            "vn": local[:, 0],
            "ve": local[:, 1],
            "vd": local[:, 2],
        }
    )


def encounter_scenario(
    own: Trajectory,
    intruder: Trajectory,
    own_file: str,
    intruder_file: str,
    t_cpa_s: float,
    before_s: float = 60.0,
    after_s: float = 20.0,
    name: str = "encounter from tracks",
) -> dict:
    """The scenario (as a dict for YAML) flying ``own_file`` and ``intruder_file`` around ``t_cpa_s``.

    The window is ``before_s`` before to ``after_s`` after the closest approach, cut to the time
    both fly. The origin is the own-ship track's own (its ``origin``, where its local frame starts:
    the same frame the intruder is placed in); ``start_time`` is
    the UTC of t = 0 s when the own-ship track had absolute timestamps.

    Parameters
    ----------
    own, intruder : Trajectory
        The two tracks, on one clock.
    own_file, intruder_file : str
        The files the scenario's flights read (paths as the scenario file will hold them).
    t_cpa_s : float
        Time of the closest approach on the tracks' clock, s.
    before_s, after_s : float
        Length of the window before and after the closest approach, s.
    name : str
        The scenario's name.

    Returns
    -------
    dict
        The scenario's sections (``name``, ``origin``, ``ownship``, ``intruders``, ``start_s``,
        ``duration_s`` and, with absolute timestamps, ``start_time``), ready for YAML.

    Raises
    ------
    InputError
        When the two tracks do not fly at the same time within the window.

    Examples
    --------
    Both fly 0..120 s and pass 200 m apart at 30 s; the window is cut to 0..50 s:

    >>> from skyradar.scene.flights import straight
    >>> own = straight([-1500, 0, 0], 0.0, 50.0, 120.0, origin=(47.0, 11.0, 1000.0), name="own")
    >>> intr = straight([1500, 200, 0], 180.0, 50.0, 120.0, origin=(47.0, 11.0, 1000.0), name="B")
    >>> s = encounter_scenario(own, intr, "own.csv", "b.csv", 30.0)
    >>> s["origin"], s["start_s"], s["duration_s"]
    ({'lat_deg': 47.0, 'lon_deg': 11.0, 'alt_m': 1000.0}, 0.0, 50.0)
    >>> s["ownship"], s["intruders"][0]["name"], "start_time" in s
    ({'type': 'file', 'path': 'own.csv', 'time_zero_s': 0.0}, 'B', False)
    """
    start = max(own.start_s, intruder.start_s, t_cpa_s - before_s)
    end = min(own.end_s, intruder.end_s, t_cpa_s + after_s)
    if not end > start:
        raise InputError(
            f"'{own.name}' and '{intruder.name}' do not fly at the same time around the encounter"
        )
    scenario = {
        "name": name,
        "origin": dict(zip(("lat_deg", "lon_deg", "alt_m"), (float(v) for v in own.origin), strict=True)),
        "ownship": {"type": "file", "path": own_file, "time_zero_s": 0.0},
        "intruders": [{"name": intruder.name, "type": "file", "path": intruder_file, "time_zero_s": 0.0}],
        "start_s": round(float(start), 6),
        "duration_s": round(float(end - start), 6),
    }
    if np.isfinite(own.epoch_s):
        stamp = pd.Timestamp(own.epoch_s, unit="s", tz="UTC")
        scenario["start_time"] = stamp.strftime("%Y-%m-%dT%H:%M:%S.%fZ")
    return scenario
