"""The ch4 airfield traffic: three own-ship flights and ten VFR intruders each, generated reproducibly.

The thesis replayed ten ADS-B flights of one SR22T around Warsaw-Babice (EPBC) as intruders around
three simulated own-ship flights. We have no ADS-B history here, so the flights are generated from
a seed with the same character: GA speeds of 40-80 m/s, accelerations, coordinated turns, climbs and
descents. Each flight is a list of manoeuvre segments ``(duration_s, accel_mps2, turn_rate_dps,
climb_mps)`` integrated at 20 Hz and turned into a :class:`~skyradar.scene.trajectories.Trajectory`
(attitude of coordinated flight).

* ``circuit``: own-ship flies the left-hand traffic pattern at 300 m; intruders arrive from 4-6 km
  out, descending and slowing down, and turn towards the field.
* ``zulu``: own-ship departs and turns towards exit point Zulu (8 km south-west), climbing;
  intruders depart from the runway, accelerate, climb and turn towards their exit points.
* ``free``: own-ship in free airspace at 900 m with sudden turns and altitude changes; intruders at
  500-1500 m cross ahead of it with turns and climbs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skyradar.scene.flights import circuit
from skyradar.scene.trajectories import Trajectory

__all__ = ["EPBC", "SCENARIOS", "Traffic", "build_traffic", "fly"]

EPBC = (52.2685, 20.9108, 106.0)  # Warsaw-Babice aerodrome reference point (lat, lon, alt)
SCENARIOS = ("circuit", "zulu", "free")
RUNWAY_HEADING_DEG = 130.0
_RATE_HZ = 20.0


@dataclass(frozen=True)
class Traffic:
    """Own-ship and intruder trajectories of one scenario, in the scenario NED frame at EPBC."""

    name: str
    ownship: Trajectory
    intruders: list[Trajectory]
    duration_s: float


def fly(
    start_ned_m: np.ndarray,
    heading_deg: float,
    speed_mps: float,
    segments: list[tuple[float, float, float, float]],
    start_time_s: float = 0.0,
    name: str = "flight",
) -> Trajectory:
    """Integrate manoeuvre segments ``(duration_s, accel_mps2, turn_rate_dps, climb_mps)``.

    Speed is the horizontal speed and is kept within 35-85 m/s.

    Examples
    --------
    >>> tr = fly(np.zeros(3), 90.0, 50.0, [(10.0, 0.0, 0.0, 2.0)])
    >>> [round(float(v)) for v in tr.position_ned_m[-1]]
    [0, 500, -20]
    """
    dt = 1.0 / _RATE_HZ
    pos = np.array(start_ned_m, float)
    psi, v = np.radians(heading_deg), float(speed_mps)
    rows_p, rows_v = [], []
    for duration, accel, turn_dps, climb in segments:
        for _ in range(int(round(duration * _RATE_HZ))):
            vel = np.array([v * np.cos(psi), v * np.sin(psi), -climb])
            rows_p.append(pos.copy())
            rows_v.append(vel)
            v_next = float(np.clip(v + accel * dt, 35.0, 85.0))
            psi_next = psi + np.radians(turn_dps) * dt
            # Trapezoidal step keeps turns round and speeds smooth.
            vel_next = np.array([v_next * np.cos(psi_next), v_next * np.sin(psi_next), -climb])
            pos = pos + 0.5 * (vel + vel_next) * dt
            v, psi = v_next, psi_next
    rows_p.append(pos.copy())
    rows_v.append(np.array([v * np.cos(psi), v * np.sin(psi), -segments[-1][3]]))
    t = start_time_s + np.arange(len(rows_p)) * dt
    return Trajectory.from_states(t, np.array(rows_p), np.array(rows_v), origin=EPBC, name=name)


def _heading_to(src: np.ndarray, dst: np.ndarray) -> float:
    d = dst - src
    return float(np.degrees(np.arctan2(d[1], d[0])))


def _polar(bearing_deg: float, dist_m: float, down_m: float) -> np.ndarray:
    b = np.radians(bearing_deg)
    return np.array([dist_m * np.cos(b), dist_m * np.sin(b), down_m])


def _ownship(name: str, duration_s: float) -> Trajectory:
    if name == "circuit":
        return circuit(
            [0.0, 0.0, 0.0],
            RUNWAY_HEADING_DEG,
            300.0,
            45.0,
            duration_s,
            touch_and_go=False,
            start_leg="downwind",
            origin=EPBC,
            name="own-circuit",
        )
    if name == "zulu":
        # Inbound from Zulu (6 km south-west, 500 m) over the field, 180-deg turn, back out to Zulu.
        start = _polar(220.0, 6000.0, -500.0)
        segs = [(110.0, 0.0, 0.0, -1.0), (60.0, 0.0, 3.0, 1.0), (duration_s, 0.0, 0.0, 2.0)]
        return fly(start, 40.0, 55.0, segs, name="own-zulu")
    rng = np.random.default_rng(42)
    segs = []
    while sum(s[0] for s in segs) < duration_s + 5:
        segs.append((float(rng.uniform(20, 40)), 0.0, 0.0, float(rng.choice([0.0, 3.0, -3.0]))))
        segs.append(
            (float(rng.uniform(8, 15)), float(rng.uniform(-0.5, 0.5)), float(rng.choice([-6.0, 6.0])), 0.0)
        )
    return fly(np.array([-3000.0, 0.0, -900.0]), 20.0, 55.0, segs, name="own-free")


def _intruder(name: str, i: int, start_s: float, own: Trajectory, rng: np.random.Generator) -> Trajectory:
    speed = float(rng.uniform(50.0, 75.0))
    if name == "circuit":
        # Overhead join: inbound from 4-6 km, descending and slowing, then a left orbit around the
        # field while descending to circuit height.
        bearing = float(rng.uniform(0.0, 360.0))
        dist = float(rng.uniform(4000.0, 6000.0))
        start = _polar(bearing, dist, -float(rng.uniform(600.0, 900.0)))
        inbound = max((dist - 1200.0) / speed, 10.0)
        segs = [(inbound, -0.2, 0.0, -2.5), (130.0, -0.1, -2.8, -1.5), (30.0, 0.0, 0.0, -2.0)]
        return fly(start, _heading_to(start, np.zeros(3)), speed, segs, start_s, f"arrival-{i}")
    if name == "zulu":
        exit_bearing = float(rng.choice([220.0, 180.0, 260.0, 300.0, 40.0]))
        start = np.array([0.0, 0.0, -10.0])
        turn = float(np.sign(((exit_bearing - RUNWAY_HEADING_DEG + 180) % 360) - 180)) * 3.0
        turn_time = abs(((exit_bearing - RUNWAY_HEADING_DEG + 180) % 360) - 180) / 3.0
        segs = [
            (25.0, 1.0, 0.0, 4.0),
            (turn_time, 0.3, turn, 3.5),
            (120.0, 0.2, 0.0, float(rng.uniform(1, 3))),
        ]
        return fly(start, RUNWAY_HEADING_DEG, 40.0, segs, start_s, f"departure-{i}")
    # Free airspace: start ahead of the own-ship, heading roughly across or towards it.
    s = own.sample(np.array([start_s]))
    hdg_own = float(np.degrees(s.attitude_rad[0, 0]))
    ahead = hdg_own + float(rng.uniform(-25, 25))
    dist = float(rng.uniform(3000.0, 4500.0))
    start = s.position_ned_m[0] + _polar(ahead, dist, 0.0)
    start[2] = -float(rng.uniform(500.0, 1500.0))
    hdg = ahead + 180.0 + float(rng.uniform(-70, 70))
    segs = [
        (float(rng.uniform(15, 30)), float(rng.uniform(-0.5, 0.8)), 0.0, float(rng.uniform(-3, 3))),
        (float(rng.uniform(8, 15)), 0.0, float(rng.choice([-5.0, 5.0])), 0.0),
        (float(rng.uniform(20, 40)), 0.0, 0.0, float(rng.uniform(-4, 4))),
        (10.0, 0.0, float(rng.choice([-6.0, 6.0])), 2.0),
        (30.0, 0.0, 0.0, 0.0),
    ]
    return fly(start, hdg, speed, segs, start_s, f"free-{i}")


def build_traffic(name: str, interval_s: float = 20.0, tail_s: float = 60.0, seed: int = 4) -> Traffic:
    """Own-ship and ten intruders of scenario ``name``; intruder ``i`` starts at ``i * interval_s``.

    Examples
    --------
    >>> tr = build_traffic("zulu", interval_s=5.0, tail_s=10.0)
    >>> len(tr.intruders), tr.duration_s
    (10, 55.0)
    """
    if name not in SCENARIOS:
        raise ValueError(f"scenario must be one of {SCENARIOS}, got {name!r}")
    duration = 9 * interval_s + tail_s
    own = _ownship(name, duration + 1.0)
    rng = np.random.default_rng([seed, SCENARIOS.index(name)])
    intruders = [_intruder(name, i, i * interval_s, own, rng) for i in range(10)]
    return Traffic(name, own, intruders, duration)
