"""A pilot who follows the DAA advice, and an aircraft that answers: the own-ship of a closed loop.

The own-ship flies its plan (a :class:`~skyradar.scene.trajectories.Trajectory`) until an alert
calls for action. What the pilot does, and why:

- **Which alerts.** An alert of level ``respond_level`` or higher (default 2, DO-365's corrective
  alert: the first level that asks the pilot to manoeuvre) starts the pilot's reaction; a lower one
  (preventive) only informs.
- **When.** The pilot acts a reaction delay after the first frame of the alert: ``corrective_delay_s``
  for a corrective alert, ``warning_delay_s`` for a warning (a warning while a corrective reaction is
  pending brings the action forward). An alert gone for ``clear_s`` by the action time cancels it.
- **What.** The pilot flies the newest preferred manoeuvre of the advice
  (:func:`skyradar.daa.advice.advice_columns`): with ``manoeuvre="horizontal"`` the preferred heading
  (the preferred vertical speed when no heading is conflict-free) and ``heading_margin_deg`` past it,
  away from the conflict band (the preferred heading lies at the band's edge: flown exactly, the
  next frame's band takes it back), with ``"vertical"`` the preferred
  vertical speed (the heading when no vertical speed is), a vertical-speed change being at least
  ``min_vs_change_mps`` (500 ft/min). The aircraft turns toward the heading the shorter way at
  ``turn_rate_dps`` (3 deg/s, a standard-rate turn), changes its vertical speed at
  ``vertical_accel_mps2`` (0.25 g) and keeps its ground speed: DAIDALUS' kinematic assumptions.
- **Back to the plan.** Once no alert at ``respond_level`` has been seen for ``clear_s`` and the
  traffic that alerted has passed its predicted closest approach (the display shows it behind; an
  alert that clears while the traffic is still ahead only says the manoeuvre works), the pilot
  returns to the planned path: a lookahead path follower (the heading aims at the point of the path
  ``lookahead_s`` of flight ahead of the nearest one) and a vertical speed of at most
  ``min_vs_change_mps`` toward the planned altitude. The manoeuvre ends when the aircraft is back
  within ``rejoin_tolerance_m`` of the path, horizontally and vertically, and within 3 deg of its
  course; from then on it follows the path with the same law.

Before its first manoeuvre the aircraft is the plan, sampled at the asked time (so an encounter
flown equipped is the unequipped one until the pilot acts); afterwards it is integrated in steps
of at most ``max_step_s``.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np
import pandas as pd

from skyradar.errors import InputError
from skyradar.geo import ned_to_geodetic
from skyradar.scene.trajectories import GRAVITY_MPS2, Trajectory, TrajectorySample
from skyradar.units import wrap_angle

__all__ = ["PilotConfig", "Pilot", "MODES", "FPM_MPS"]

FPM_MPS = 0.3048 / 60.0  # one foot per minute, m/s
MODES = ("plan", "avoid", "return", "rejoined")
_PATH_STEP_S = 0.5  # the planned path is searched for its nearest point on samples this far apart
_REJOIN_COURSE_RAD = np.radians(3.0)


@dataclass(frozen=True)
class PilotConfig:
    """How the pilot reacts to alerts and how the aircraft manoeuvres (SI units).

    Attributes
    ----------
    respond_level : int
        Lowest alert level the pilot acts on (1 preventive, 2 corrective, 3 warning).
    corrective_delay_s : float
        Reaction delay after the first frame of a corrective alert, s.
    warning_delay_s : float
        Reaction delay after the first frame of a warning, s.
    manoeuvre : str
        ``"horizontal"`` (fly the preferred heading) or ``"vertical"`` (fly the preferred vertical speed).
    turn_rate_dps : float
        Turn rate, deg/s.
    vertical_accel_mps2 : float
        Vertical acceleration while the vertical speed changes, m/s^2.
    min_vs_change_mps : float
        Smallest vertical-speed change of a vertical manoeuvre, and the largest vertical speed of the
        return to the planned altitude, m/s.
    heading_margin_deg : float
        How far past the preferred heading the pilot turns, away from the conflict band, deg.
    clear_s : float
        Time without an alert at ``respond_level`` after which the pilot returns to the plan (once
        the traffic has passed its closest approach), s.
    lookahead_s : float
        Lookahead of the path follower that brings the aircraft back to its plan, s of flight.
    rejoin_tolerance_m : float
        Distance from the planned path (horizontal and vertical) at which the manoeuvre ends, m.
    max_step_s : float
        Longest integration step of the aircraft's motion, s.

    Examples
    --------
    >>> PilotConfig().turn_rate_dps, round(PilotConfig().min_vs_change_mps, 2)
    (3.0, 2.54)
    >>> PilotConfig(manoeuvre="sideways")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: pilot: field 'manoeuvre' must be horizontal or vertical, got 'sideways'
    """

    respond_level: int = 2
    corrective_delay_s: float = 5.0
    warning_delay_s: float = 3.0
    manoeuvre: str = "horizontal"
    turn_rate_dps: float = 3.0
    vertical_accel_mps2: float = 0.25 * GRAVITY_MPS2
    min_vs_change_mps: float = 500.0 * FPM_MPS
    heading_margin_deg: float = 5.0
    clear_s: float = 5.0
    lookahead_s: float = 10.0
    rejoin_tolerance_m: float = 15.0
    max_step_s: float = 0.05

    def __post_init__(self) -> None:
        if self.manoeuvre not in ("horizontal", "vertical"):
            raise InputError(
                f"pilot: field 'manoeuvre' must be horizontal or vertical, got {self.manoeuvre!r}"
            )
        if self.respond_level not in (1, 2, 3):
            raise InputError(f"pilot: field 'respond_level' must be 1, 2 or 3, got {self.respond_level!r}")
        for f in fields(self):
            if f.name in ("manoeuvre", "respond_level"):
                continue
            value = getattr(self, f.name)
            positive = f.name not in (
                "corrective_delay_s",
                "warning_delay_s",
                "clear_s",
                "heading_margin_deg",
            )
            if not np.isfinite(value) or value < 0 or (positive and value == 0) or value > 1e4:
                bound = "> 0" if positive else ">= 0"
                raise InputError(f"pilot: field '{f.name}' must be finite, {bound} and <= 1e4, got {value!r}")


def _wrap(angle_rad: float) -> float:
    return float(wrap_angle(angle_rad))


class Pilot:
    """The own-ship of a closed loop: its plan, the pilot's reactions to alerts and its motion.

    Call :meth:`advance` with each new time (s, never decreasing) to get the aircraft's state then,
    and :meth:`observe` after each frame's alerting with the highest alert level of the frame and its
    advice. :meth:`flown` gives the states flown so far.

    Parameters
    ----------
    plan : Trajectory
        The own-ship's planned flight (the scenario's own-ship trajectory).
    config : PilotConfig, optional
        Reactions and kinematics (default :class:`PilotConfig`).
    start_s : float, optional
        Time of the first state, s (default the plan's start).

    Examples
    --------
    A level plan north at 50 m/s; from 10 s on, a corrective alert on every frame advises heading
    090 deg: the pilot acts 5 s after its first frame and turns at 3 deg/s, so the heading is
    45 deg 15 s after the action. When the alert has been gone for 5 s, the pilot turns back.

    >>> t = np.array([0.0, 200.0])
    >>> plan = Trajectory.from_states(t, [[0, 0, -1000], [10000, 0, -1000]], origin=(52.0, 4.0, 0.0))
    >>> pilot = Pilot(plan)
    >>> for time_s in np.arange(10.0, 30.01, 0.5):
    ...     state = pilot.advance(time_s)
    ...     pilot.observe(time_s, level=2, preferred_heading_deg=90.0)
    >>> pilot.mode, pilot.first_action_s, round(float(np.degrees(state.attitude_rad[0, 0])), 1)
    ('avoid', 15.0, 45.0)
    >>> round(float(state.position_ned_m[0, 2]), 6)  # level: the horizontal manoeuvre keeps the altitude
    -1000.0
    >>> state = pilot.advance(36.0)  # turned to 60 deg by 35 s, then back toward the path for 1 s
    >>> pilot.mode, round(float(np.degrees(state.attitude_rad[0, 0])))
    ('return', 57)
    """

    def __init__(self, plan: Trajectory, config: PilotConfig | None = None, start_s: float | None = None):
        self.plan = plan
        self.config = config or PilotConfig()
        self.time_s = float(plan.time_s[0] if start_s is None else start_s)
        self.mode = "plan"
        self._deviated = False
        self._act_at_s = np.inf  # when the pending reaction is due, s
        self._last_alert_s = -np.inf
        self._passes_s = -np.inf  # when the traffic that alerted passes its closest approach, s
        self._heading_deg = np.nan  # the newest advice
        self._vs_mps = np.nan
        self._target_vs_mps = np.nan
        self._vs_at_action = 0.0
        self._heading_at_action = 0.0
        self.manoeuvre_s = 0.0
        self.first_action_s = np.nan
        state = plan.sample(self.time_s)
        self._pos = state.position_ned_m[0].copy()
        self._set_motion(state.velocity_ned_mps[0])
        self._turn_rate = 0.0
        path_t = np.arange(plan.time_s[0], plan.time_s[-1], _PATH_STEP_S)
        self._path = plan.sample(np.append(path_t, plan.time_s[-1]))
        self._log: list[tuple[float, ...]] = []
        self._record(state.velocity_ned_mps[0])

    # ---- what the pilot sees -----------------------------------------------------------
    def observe(
        self,
        time_s: float,
        level: int,
        preferred_heading_deg: float = np.nan,
        preferred_vs_mps: float = np.nan,
        closest_approach_s: float = np.nan,
    ) -> None:
        """The pilot reads the display at ``time_s`` (s): the frame's highest alert level and its advice.

        ``preferred_heading_deg`` (deg from north) and ``preferred_vs_mps`` (m/s, positive up) are
        the advice's preferred manoeuvre, NaN when it has none; ``closest_approach_s`` is when the
        alerting traffic is predicted to pass its closest approach (s, NaN: not known).
        """
        cfg = self.config
        if level < cfg.respond_level:
            return
        self._last_alert_s = float(time_s)
        if np.isfinite(closest_approach_s):
            self._passes_s = max(self._passes_s, float(closest_approach_s))
        if np.isfinite(preferred_heading_deg) or np.isfinite(preferred_vs_mps):
            self._heading_deg, self._vs_mps = float(preferred_heading_deg), float(preferred_vs_mps)
        if self.mode == "avoid":
            self._aim_vertical()
            return
        delay = cfg.warning_delay_s if level >= 3 else cfg.corrective_delay_s
        self._act_at_s = min(self._act_at_s, float(time_s) + delay)

    # ---- how the aircraft moves --------------------------------------------------------
    def advance(self, time_s: float) -> TrajectorySample:
        """Fly to ``time_s`` (s, not before the last time asked) and return the state there (one sample)."""
        time_s = float(time_s)
        if time_s < self.time_s - 1e-9:
            raise ValueError(f"pilot: time {time_s} s is before the last state's {self.time_s} s")
        while self.time_s < time_s - 1e-12:
            dt = min(self.config.max_step_s, time_s - self.time_s, max(self._act_at_s - self.time_s, 1e-6))
            self._step(dt)
        return self.state()

    def state(self) -> TrajectorySample:
        """The aircraft's state now: NED position and velocity (m, m/s), attitude (rad) and WGS84."""
        if not self._deviated:
            return self.plan.sample(self.time_s)
        velocity = self._velocity()
        pitch = np.arctan2(self._vs, max(self._speed, 1e-9))
        roll = np.arctan(self._speed * self._turn_rate / GRAVITY_MPS2)  # a coordinated turn
        attitude = np.array([[_wrap(self._heading), pitch, roll]])
        lat, lon, alt = ned_to_geodetic(self._pos, *self.plan.origin)
        return TrajectorySample(
            np.array([self.time_s]),
            self._pos[None, :].copy(),
            velocity[None, :],
            attitude,
            np.atleast_1d(lat).astype(float),
            np.atleast_1d(lon).astype(float),
            np.atleast_1d(alt).astype(float),
        )

    def flown(self) -> pd.DataFrame:
        """The states flown so far, one row per integration step: ``time_s``, ``north_m``, ``east_m``,
        ``down_m`` (m), ``vn_mps``, ``ve_mps``, ``vd_mps`` (m/s) and ``mode``."""
        columns = ["time_s", "north_m", "east_m", "down_m", "vn_mps", "ve_mps", "vd_mps", "mode"]
        table = pd.DataFrame(self._log, columns=columns)
        table["mode"] = np.asarray(MODES)[table["mode"].to_numpy(int)]
        return table

    def _set_motion(self, velocity: np.ndarray) -> None:
        self._speed = float(np.hypot(velocity[0], velocity[1]))
        self._heading = float(np.arctan2(velocity[1], velocity[0]))
        self._vs = float(-velocity[2])

    def _velocity(self) -> np.ndarray:
        return np.array([self._speed * np.cos(self._heading), self._speed * np.sin(self._heading), -self._vs])

    def _record(self, velocity: np.ndarray) -> None:
        self._log.append((self.time_s, *self._pos, *velocity, MODES.index(self.mode)))

    def _aim_vertical(self) -> None:
        """The vertical speed a vertical manoeuvre flies: the advice's, at least the minimum change away
        from the vertical speed the manoeuvre started at."""
        if not np.isfinite(self._vs_mps):
            self._target_vs_mps = np.nan
            return
        change = self._vs_mps - self._vs_at_action
        if abs(change) < self.config.min_vs_change_mps:
            direction = change if change != 0 else (self._vs_mps or 1.0)
            change = np.copysign(self.config.min_vs_change_mps, direction)
        self._target_vs_mps = self._vs_at_action + change

    def _start_action(self) -> None:
        self._act_at_s = np.inf
        if self.time_s - self._last_alert_s > self.config.clear_s:  # the alert is gone: nothing to do
            return
        if not self._deviated:
            state = self.plan.sample(self.time_s)
            self._pos = state.position_ned_m[0].copy()
            self._set_motion(state.velocity_ned_mps[0])
            self._deviated = True
        if np.isnan(self.first_action_s):
            self.first_action_s = self.time_s
        self._vs_at_action = self._vs
        self._heading_at_action = self._heading
        self.mode = "avoid"
        self._aim_vertical()

    def _targets(self) -> tuple[float, float]:
        """Heading (rad) and vertical speed (m/s, up) the aircraft turns and climbs toward now."""
        cfg = self.config
        if self.mode == "avoid":
            horizontal = np.isfinite(self._heading_deg) and (
                cfg.manoeuvre == "horizontal" or not np.isfinite(self._target_vs_mps)
            )
            heading = self._avoid_heading() if horizontal else self._heading
            vs = self._vs if horizontal or not np.isfinite(self._target_vs_mps) else self._target_vs_mps
            return float(heading), float(vs)
        return self._path_targets()

    def _avoid_heading(self) -> float:
        """The preferred heading, ``heading_margin_deg`` further from the heading at the action, rad."""
        preferred = np.radians(self._heading_deg)
        side = np.sign(_wrap(preferred - self._heading_at_action))
        return float(preferred + side * np.radians(self.config.heading_margin_deg))

    def _nearest_path_point(self) -> int:
        d = np.hypot(*(self._path.position_ned_m[:, :2] - self._pos[:2]).T)
        return int(np.argmin(d))

    def _path_targets(self) -> tuple[float, float]:
        """The path follower: heading to the path point a lookahead ahead, vertical speed to its altitude."""
        cfg = self.config
        k = self._nearest_path_point()
        path = self._path.position_ned_m
        ahead = min(k + max(int(round(cfg.lookahead_s / _PATH_STEP_S)), 1), len(path) - 1)
        aim = path[ahead] - self._pos
        heading = float(np.arctan2(aim[1], aim[0])) if np.hypot(aim[0], aim[1]) > 1.0 else self._heading
        climb = (self._pos[2] - path[k, 2]) / cfg.lookahead_s  # the planned altitude in a lookahead
        planned_vs = float(-self._path.velocity_ned_mps[k, 2])
        vs = planned_vs + float(np.clip(climb, -cfg.min_vs_change_mps, cfg.min_vs_change_mps))
        return heading, vs

    def _rejoined(self) -> bool:
        k = self._nearest_path_point()
        offset = self._pos - self._path.position_ned_m[k]
        course = np.arctan2(self._path.velocity_ned_mps[k, 1], self._path.velocity_ned_mps[k, 0])
        tol = self.config.rejoin_tolerance_m
        return bool(
            np.hypot(offset[0], offset[1]) <= tol
            and abs(offset[2]) <= tol
            and abs(_wrap(self._heading - course)) <= _REJOIN_COURSE_RAD
        )

    def _step(self, dt: float) -> None:
        cfg = self.config
        if self.time_s >= self._act_at_s - 1e-9:
            self._start_action()
        clear = self.time_s - self._last_alert_s >= cfg.clear_s and self.time_s >= self._passes_s
        if self.mode == "avoid" and clear:
            self.mode = "return"
        if not self._deviated:
            self.time_s += dt
            state = self.plan.sample(self.time_s)
            self._pos = state.position_ned_m[0].copy()
            self._record(state.velocity_ned_mps[0])
            return
        heading, vs = self._targets()
        max_turn = np.radians(cfg.turn_rate_dps) * dt
        turn = float(np.clip(_wrap(heading - self._heading), -max_turn, max_turn))
        dvs = float(np.clip(vs - self._vs, -cfg.vertical_accel_mps2 * dt, cfg.vertical_accel_mps2 * dt))
        self._heading += turn / 2.0
        self._vs += dvs / 2.0
        self._pos = self._pos + self._velocity() * dt  # the midpoint's velocity over the step
        self._heading = _wrap(self._heading + turn / 2.0)
        self._vs += dvs / 2.0
        self._turn_rate = turn / dt
        self.time_s += dt
        if self.mode in ("avoid", "return"):
            self.manoeuvre_s += dt
        if self.mode == "return" and self._rejoined():
            self.mode = "rejoined"
        self._record(self._velocity())
