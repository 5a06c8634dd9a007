"""Parametric flights in a scenario's NED frame: straight legs, circles, airfield circuits, encounters.

Every builder samples its flight densely (``rate_hz``, default 20 Hz) with exact analytic
positions and velocities, and derives attitude as a coordinated flight without wind
(:func:`skyradar.scene.trajectories.derive_attitude`). Speeds are horizontal (ground) speeds,
climb rates are positive up. Headings and bearings are degrees clockwise from north.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from skyradar.errors import InputError
from skyradar.scene.trajectories import GRAVITY_MPS2, MIN_TRACK_SPEED_MPS, Trajectory

__all__ = ["straight", "circle", "circuit", "encounter", "ENCOUNTER_KINDS"]

Origin = tuple[float, float, float]
ENCOUNTER_KINDS = ("head-on", "crossing", "overtaking", "converging")
_CIRCUIT_LEGS = ("upwind", "crosswind", "downwind", "base", "final")


def _check(name: str, value: float, low: float = 0.0, strict: bool = True) -> float:
    value = float(value)
    ok = np.isfinite(value) and (value > low if strict else value >= low)
    if not ok:
        raise InputError(f"field '{name}': must be {'>' if strict else '>='} {low:g} (got {value!r})")
    return value


def _vector(name: str, value) -> np.ndarray:
    v = np.asarray(value, dtype=float)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise InputError(
            f"field '{name}': must be 3 finite numbers (north, east, down) in metres (got {value!r})"
        )
    return v


def _times(duration_s: float, rate_hz: float, start_time_s: float) -> np.ndarray:
    duration_s = _check("duration_s", duration_s)
    rate_hz = _check("rate_hz", rate_hz)
    n = max(int(np.ceil(duration_s * rate_hz - 1e-9)) + 1, 2)
    return float(start_time_s) + np.linspace(0.0, duration_s, n)


def straight(
    start_ned_m,
    heading_deg: float,
    speed_mps: float,
    duration_s: float,
    climb_mps: float = 0.0,
    *,
    origin: Origin = (0.0, 0.0, 0.0),
    name: str = "straight",
    start_time_s: float = 0.0,
    rate_hz: float = 20.0,
) -> Trajectory:
    """Constant-velocity flight from ``start_ned_m`` (m) at ``start_time_s``.

    Examples
    --------
    >>> traj = straight([0.0, 0.0, -1000.0], 90.0, 30.0, 10.0)
    >>> np.round(traj.sample([10.0]).position_ned_m[0], 6).tolist()
    [0.0, 300.0, -1000.0]
    """
    start = _vector("start_ned_m", start_ned_m)
    speed = _check("speed_mps", speed_mps, strict=False)
    t = _times(duration_s, rate_hz, start_time_s)
    psi = np.radians(float(heading_deg))
    vel = np.array([speed * np.cos(psi), speed * np.sin(psi), -float(climb_mps)])
    pos = start + np.outer(t - t[0], vel)
    vels = np.broadcast_to(vel, pos.shape)
    attitude = None
    if speed < MIN_TRACK_SPEED_MPS:  # hovering or vertical: heading is the requested one, not the track
        attitude = np.tile([psi, np.arctan2(float(climb_mps), speed), 0.0], (t.size, 1))
    return Trajectory.from_states(t, pos, vels, attitude, origin=origin, name=name)


def circle(
    center_ned_m,
    radius_m: float,
    speed_mps: float,
    duration_s: float,
    clockwise: bool = True,
    start_bearing_deg: float = 0.0,
    climb_mps: float = 0.0,
    *,
    origin: Origin = (0.0, 0.0, 0.0),
    name: str = "circle",
    start_time_s: float = 0.0,
    rate_hz: float = 20.0,
) -> Trajectory:
    """Constant-speed circle around ``center_ned_m`` (its down coordinate is the start altitude).

    The flight starts at bearing ``start_bearing_deg`` from the centre; clockwise as seen from
    above is a right turn (positive bank of ``atan(V^2 / (g R))``).

    Examples
    --------
    >>> traj = circle([0.0, 0.0, -500.0], 1000.0, 50.0, 60.0)
    >>> bool(np.allclose(np.linalg.norm(traj.position_ned_m[:, :2], axis=1), 1000.0))
    True
    """
    center = _vector("center_ned_m", center_ned_m)
    radius = _check("radius_m", radius_m)
    speed = _check("speed_mps", speed_mps)
    t = _times(duration_s, rate_hz, start_time_s)
    sense = 1.0 if clockwise else -1.0
    bearing = np.radians(float(start_bearing_deg)) + sense * speed / radius * (t - t[0])
    climb = float(climb_mps)
    pos = np.stack(
        [
            center[0] + radius * np.cos(bearing),
            center[1] + radius * np.sin(bearing),
            center[2] - climb * (t - t[0]),
        ],
        axis=-1,
    )
    vel = np.stack(
        [-sense * speed * np.sin(bearing), sense * speed * np.cos(bearing), np.full_like(t, -climb)], axis=-1
    )
    return Trajectory.from_states(t, pos, vel, origin=origin, name=name)


def _circuit_segments(length_m: list[float], radius_m: float, turn: float) -> list[tuple[float, float]]:
    """(length, curvature) pieces of a rounded rectangle: straight, 90-degree turn, ..."""
    pieces = []
    for i, leg in enumerate(length_m):
        pieces.append((leg, 0.0))
        if i < 4:
            pieces.append((np.pi / 2.0 * radius_m, turn / radius_m))
    return pieces


def _turtle(
    pieces: list[tuple[float, float]], s: np.ndarray, heading0: float
) -> tuple[np.ndarray, np.ndarray]:
    """Horizontal position (n, 2) and heading (n,) at arc lengths ``s`` along the pieces."""
    starts = np.concatenate([[0.0], np.cumsum([p[0] for p in pieces])])
    xy0, h0 = [np.zeros(2)], [heading0]
    for length, curvature in pieces:  # position and heading at the start of each piece
        h, p = h0[-1], xy0[-1]
        if curvature == 0.0:
            xy0.append(p + length * np.array([np.cos(h), np.sin(h)]))
        else:
            h_end = h + curvature * length
            xy0.append(p + (np.array([np.sin(h_end) - np.sin(h), np.cos(h) - np.cos(h_end)]) / curvature))
        h0.append(h + curvature * length)
    k = np.clip(np.searchsorted(starts, s, side="right") - 1, 0, len(pieces) - 1)
    ds = s - starts[k]
    kappa = np.array([p[1] for p in pieces])[k]
    h_start = np.array(h0)[k]
    heading = h_start + kappa * ds
    safe = np.where(kappa == 0.0, 1.0, kappa)
    # Straight: p0 + ds * u(h). Arc: exact chord of a constant-curvature turn.
    dx = np.where(kappa == 0.0, ds * np.cos(h_start), (np.sin(heading) - np.sin(h_start)) / safe)
    dy = np.where(kappa == 0.0, ds * np.sin(h_start), (np.cos(h_start) - np.cos(heading)) / safe)
    return np.array(xy0)[k] + np.stack([dx, dy], axis=-1), heading


def _circuit_sides(speed: float, bank_deg: float, upwind_m, width_m, final_m) -> tuple[float, ...]:
    """Checked upwind, width and final lengths, and the turn radius they must leave room for."""
    bank = np.radians(_check("bank_deg", bank_deg))
    if bank >= np.radians(80.0):
        raise InputError(f"field 'bank_deg': must be < 80 (got {bank_deg})")
    radius = speed**2 / (GRAVITY_MPS2 * np.tan(bank))
    upwind, width, final = (
        _check(n, v) for n, v in (("upwind_m", upwind_m), ("width_m", width_m), ("final_m", final_m))
    )
    for field, value, need in (
        ("upwind_m", upwind, radius),
        ("final_m", final, radius),
        ("width_m", width, 2 * radius),
    ):
        if value < need:
            raise InputError(
                f"field '{field}': must be >= {need:.0f} m for {np.degrees(bank):.0f} deg turns "
                f"at {speed:g} m/s (got {value:g})"
            )
    return upwind, width, final, radius


def circuit(
    runway_threshold_ned_m,
    runway_heading_deg: float,
    pattern_altitude_m: float,
    speed_mps: float,
    duration_s: float,
    upwind_m: float = 2000.0,
    width_m: float = 1200.0,
    final_m: float = 1500.0,
    *,
    left_hand: bool = True,
    bank_deg: float = 25.0,
    touch_and_go: bool = True,
    climb_angle_deg: float = 6.0,
    descent_angle_deg: float = 4.0,
    start_leg: Literal["upwind", "crosswind", "downwind", "base", "final"] = "upwind",
    origin: Origin = (0.0, 0.0, 0.0),
    name: str = "circuit",
    start_time_s: float = 0.0,
    rate_hz: float = 20.0,
) -> Trajectory:
    """An airfield traffic pattern flown repeatedly at constant ground speed.

    Upwind from the threshold along the runway for ``upwind_m``, crosswind ``width_m`` to the
    downwind leg, downwind past the threshold to ``final_m`` before it, base, and final back to
    the threshold. Corners are coordinated turns of bank ``bank_deg``
    (radius ``V^2 / (g tan(bank))``). With ``touch_and_go`` the aircraft climbs from the
    threshold at ``climb_angle_deg`` to ``pattern_altitude_m`` (above the threshold) and descends
    at ``descent_angle_deg`` to touch down at the threshold; otherwise it stays level.

    Examples
    --------
    >>> traj = circuit([0.0, 0.0, 0.0], 90.0, 300.0, 40.0, 300.0, touch_and_go=False)
    >>> bank_deg = np.degrees(traj.attitude_rad[:, 2])
    >>> round(float(-traj.position_ned_m[:, 2].mean()), 6), round(float(bank_deg.min()), 1)
    (300.0, -25.0)
    """
    threshold = _vector("runway_threshold_ned_m", runway_threshold_ned_m)
    height = _check("pattern_altitude_m", pattern_altitude_m)
    speed = _check("speed_mps", speed_mps)
    upwind, width, final, radius = _circuit_sides(speed, bank_deg, upwind_m, width_m, final_m)
    if start_leg not in _CIRCUIT_LEGS:
        raise InputError(f"field 'start_leg': must be one of {list(_CIRCUIT_LEGS)} (got {start_leg!r})")
    legs = [
        upwind - radius,
        width - 2 * radius,
        upwind + final - 2 * radius,
        width - 2 * radius,
        final - radius,
    ]
    pieces = _circuit_segments(legs, radius, -1.0 if left_hand else 1.0)
    perimeter = float(sum(p[0] for p in pieces))
    t = _times(duration_s, rate_hz, start_time_s)
    starts = np.concatenate([[0.0], np.cumsum([p[0] for p in pieces])])
    s = (starts[2 * _CIRCUIT_LEGS.index(start_leg)] + speed * (t - t[0])) % perimeter
    xy, heading = _turtle(pieces, s, np.radians(float(runway_heading_deg)))
    alt, slope = _circuit_profile(s, perimeter, height, touch_and_go, climb_angle_deg, descent_angle_deg)
    pos = np.column_stack([threshold[0] + xy[:, 0], threshold[1] + xy[:, 1], threshold[2] - alt])
    vel = np.column_stack([speed * np.cos(heading), speed * np.sin(heading), -speed * slope])
    return Trajectory.from_states(t, pos, vel, origin=origin, name=name)


def _circuit_profile(
    s: np.ndarray, perimeter: float, height: float, touch_and_go: bool, climb_deg: float, descent_deg: float
) -> tuple[np.ndarray, np.ndarray]:
    """Height above the threshold (m) and its slope dh/ds along the loop."""
    if not touch_and_go:
        return np.full_like(s, height), np.zeros_like(s)
    up = np.tan(np.radians(_check("climb_angle_deg", climb_deg)))
    down = np.tan(np.radians(_check("descent_angle_deg", descent_deg)))
    if height / up + height / down > perimeter:
        raise InputError(
            f"field 'pattern_altitude_m': {height:g} m cannot be reached and left on a "
            f"{perimeter:.0f} m circuit at {climb_deg:g}/{descent_deg:g} deg; "
            "lengthen the legs or steepen the angles"
        )
    climbing, descending = s * up, (perimeter - s) * down
    alt = np.minimum(np.minimum(climbing, descending), height)
    slope = np.where(alt == climbing, up, np.where(alt == descending, -down, 0.0))
    return alt, slope


def _ownship_at(ownship: Trajectory, t_s: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Own-ship position, velocity and ground speed at ``t_s``; refused without a ground track."""
    # Beyond own-ship's span, its last (or first) state is extrapolated in a straight line.
    t_near = min(max(t_s, ownship.start_s), ownship.end_s)
    own = ownship.sample(np.array([t_near]))
    v_o = own.velocity_ned_mps[0]
    p_o = own.position_ned_m[0] + v_o * (t_s - t_near)
    ground = float(np.hypot(v_o[0], v_o[1]))
    if ground < MIN_TRACK_SPEED_MPS:
        raise InputError(
            f"field 't_cpa_s': own-ship '{ownship.name}' has no track at {t_s} s (speed {ground:.2f} m/s)"
        )
    return p_o, v_o, ground


def encounter(
    ownship: Trajectory,
    kind: Literal["head-on", "crossing", "overtaking", "converging"],
    t_cpa_s: float,
    horizontal_miss_m: float = 0.0,
    vertical_miss_m: float = 0.0,
    intruder_speed_mps: float | None = None,
    crossing_angle_deg: float | None = None,
    *,
    intruder_climb_mps: float | None = None,
    side: Literal["right", "left"] = "right",
    name: str | None = None,
    rate_hz: float = 20.0,
) -> Trajectory:
    """A straight-flying intruder whose closest point of approach to own-ship is at ``t_cpa_s``.

    Own-ship is linearised at ``t_cpa_s`` (its position and velocity there). The intruder's
    track is own-ship's track plus 180 deg (head-on), ``crossing_angle_deg`` (crossing: default
    90, converging: default 45; positive = intruder flies to own-ship's right, so it comes from
    the left), or 0 (overtaking: default speed 1.5x own-ship's). At the CPA the intruder is
    ``horizontal_miss_m`` away horizontally, on own-ship's ``side`` where the geometry allows, and
    ``vertical_miss_m`` above (negative: below). By default it climbs like own-ship at the CPA,
    so relative motion is horizontal and every miss combination is possible. The intruder
    covers own-ship's time span; ``t_cpa_s`` may lie outside it (own-ship's first or last state
    is then extrapolated in a straight line, e.g. a CPA after the end of a short recording).

    Examples
    --------
    >>> own = straight([0.0, 0.0, -1000.0], 0.0, 30.0, 60.0)
    >>> intruder = encounter(own, "head-on", 30.0, horizontal_miss_m=100.0)
    >>> t = np.linspace(0.0, 60.0, 6001)
    >>> d = np.linalg.norm(intruder.sample(t).position_ned_m - own.sample(t).position_ned_m, axis=1)
    >>> round(float(t[d.argmin()]), 2), round(float(d.min()), 3)
    (30.0, 100.0)
    """
    if kind not in ENCOUNTER_KINDS:
        raise InputError(f"field 'kind': must be one of {list(ENCOUNTER_KINDS)} (got {kind!r})")
    h_miss = _check("horizontal_miss_m", horizontal_miss_m, strict=False)
    dz = -float(vertical_miss_m)
    t_cpa_s = float(t_cpa_s)
    if not np.isfinite(t_cpa_s):
        raise InputError(f"field 't_cpa_s': must be finite (got {t_cpa_s})")
    p_o, v_o, ground = _ownship_at(ownship, t_cpa_s)
    psi = np.arctan2(v_o[1], v_o[0])
    angle = {"head-on": 180.0, "overtaking": 0.0, "crossing": 90.0, "converging": 45.0}[kind]
    if kind in ("crossing", "converging") and crossing_angle_deg is not None:
        angle = float(crossing_angle_deg)
    default_speed = 1.5 * ground if kind == "overtaking" else ground
    speed = default_speed if intruder_speed_mps is None else _check("intruder_speed_mps", intruder_speed_mps)
    track = psi + np.radians(angle)
    vd = v_o[2] if intruder_climb_mps is None else -float(intruder_climb_mps)
    v_i = np.array([speed * np.cos(track), speed * np.sin(track), vd])
    offset_h = _miss_offset(v_i - v_o, h_miss, dz, psi, side)
    p_cpa = p_o + np.array([offset_h[0], offset_h[1], dz])
    t = _times(ownship.duration_s, rate_hz, ownship.start_s)
    pos = p_cpa + np.outer(t - float(t_cpa_s), v_i)
    return Trajectory.from_states(
        t, pos, np.broadcast_to(v_i, pos.shape), origin=ownship.origin, name=name or kind
    )


def _miss_offset(v_rel: np.ndarray, h_miss: float, dz: float, psi: float, side: str) -> np.ndarray:
    """Horizontal offset d (2,) with |d| = h_miss and (d, dz) perpendicular to v_rel."""
    if side not in ("right", "left"):
        raise InputError(f"field 'side': must be 'right' or 'left' (got {side!r})")
    if np.linalg.norm(v_rel) < 1e-9:
        raise InputError("field 'intruder_speed_mps': intruder and own-ship fly the same velocity; no CPA")
    right = np.array([-np.sin(psi), np.cos(psi)])
    a, c = v_rel[:2], float(v_rel[2])
    norm_a = float(np.linalg.norm(a))
    need = -c * dz  # a . d must equal this for the CPA to fall at t_cpa
    if h_miss == 0.0 or norm_a < 1e-9:
        if abs(need) > 1e-9 * max(1.0, abs(c)):
            raise InputError(
                f"field 'vertical_miss_m': a vertical miss of {-dz:g} m with climbing relative motion "
                f"needs a horizontal miss (got {h_miss:g}); leave intruder_climb_mps unset"
            )
        perp = right if norm_a < 1e-9 else np.array([-a[1], a[0]]) / norm_a
        d = h_miss * perp
        return d if (d @ right >= 0) == (side == "right") else -d
    x = need / (h_miss * norm_a)
    if abs(x) > 1.0:
        raise InputError(
            f"field 'horizontal_miss_m': {h_miss:g} m is too small for a vertical miss of {-dz:g} m "
            f"with this relative climb; the CPA cannot fall at t_cpa"
        )
    phi = np.arctan2(a[1], a[0])
    candidates = [phi + np.arccos(x), phi - np.arccos(x)]
    offsets = [h_miss * np.array([np.cos(th), np.sin(th)]) for th in candidates]
    pick = max if side == "right" else min
    return pick(offsets, key=lambda d: float(d @ right))
