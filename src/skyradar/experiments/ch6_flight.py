"""ch6's flight over the map: straight legs, a turn with the radar wing down, and one with it up.

A coordinated turn at speed ``v`` and bank ``phi`` turns at ``g tan(phi) / v``; the path is integrated
in small steps and sampled once per second (the thesis' rate for its 20 random frames).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skyradar.units import wrap_angle

__all__ = ["Leg", "Flight", "fly"]

G_MPS2 = 9.80665


@dataclass(frozen=True)
class Leg:
    """A piece of the flight: ``duration_s`` at bank ``bank_deg`` (positive right wing down)."""

    duration_s: float
    bank_deg: float = 0.0


@dataclass(frozen=True)
class Flight:
    """Own-ship states at the frame times (NED metres, m/s, rad yaw/pitch/roll)."""

    times_s: np.ndarray
    position_ned_m: np.ndarray
    velocity_ned_mps: np.ndarray
    attitude_rad: np.ndarray


def fly(
    start_ned_m: tuple[float, float, float],
    heading_deg: float,
    legs: list[Leg],
    speed_mps: float = 50.0,
    frame_interval_s: float = 1.0,
    step_s: float = 0.05,
) -> Flight:
    """Integrate level coordinated flight through ``legs``; states every ``frame_interval_s``.

    Examples
    --------
    >>> f = fly((0.0, 0.0, -200.0), 0.0, [Leg(10.0), Leg(10.0, 30.0)])
    >>> round(float(f.position_ned_m[10, 0])), round(float(np.degrees(f.attitude_rad[-1, 2])))
    (500, 30)
    """
    total = sum(leg.duration_s for leg in legs)
    n_steps = int(round(total / step_s))
    ends = np.cumsum([leg.duration_s for leg in legs])
    t = np.arange(n_steps + 1) * step_s
    bank = np.radians(
        [legs[min(np.searchsorted(ends, ti, side="right"), len(legs) - 1)].bank_deg for ti in t]
    )
    rate = G_MPS2 * np.tan(bank) / speed_mps
    heading = np.radians(heading_deg) + np.concatenate([[0.0], np.cumsum(rate[:-1] * step_s)])
    vn, ve = speed_mps * np.cos(heading), speed_mps * np.sin(heading)
    north = start_ned_m[0] + np.concatenate([[0.0], np.cumsum(vn[:-1] * step_s)])
    east = start_ned_m[1] + np.concatenate([[0.0], np.cumsum(ve[:-1] * step_s)])
    pick = np.arange(0, n_steps + 1, int(round(frame_interval_s / step_s)))
    position = np.column_stack([north, east, np.full(t.size, start_ned_m[2])])[pick]
    velocity = np.column_stack([vn, ve, np.zeros(t.size)])[pick]
    yaw = wrap_angle(heading[pick])
    attitude = np.column_stack([yaw, np.zeros(pick.size), bank[pick]])
    return Flight(t[pick], position, velocity, attitude)
