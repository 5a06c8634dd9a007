"""What a scenario's flight and terrain sections read or make: DEM windows, flight files, encounters.

Kept apart from :mod:`skyradar.scene.scenario` (which validates and assembles) so each stays short.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from skyradar.errors import InputError
from skyradar.scene.trajectories import Trajectory

__all__ = ["read_dem_near", "check_plausible", "check_flyable", "read_flight", "encounter_flight"]


def read_dem_near(path: Path, bounds, origin) -> Any:
    """The DEM window ``bounds`` of ``path``; a miss names the scenario origin too."""
    from skyradar.scene.dem_coverage import DemCoverageError
    from skyradar.scene.dem_readers import read_dem

    try:
        return read_dem(path, bounds=bounds)
    except DemCoverageError as exc:
        if origin is None:
            raise
        raise DemCoverageError(f"{exc}; scenario origin lat {origin[0]:.6g}, lon {origin[1]:.6g}") from None


def check_plausible(traj: Trajectory) -> None:
    """Refuse a parametric flight faster than Mach 3 or outside [-500 m, 30 km] altitude (files: adsb)."""
    from skyradar.geo import ned_to_geodetic
    from skyradar.scene.adsb import ALT_LIMITS_M, MAX_SPEED_MPS

    speed = np.linalg.norm(traj.velocity_ned_mps, axis=1)
    if np.any(speed > MAX_SPEED_MPS):
        i = int(np.argmax(speed > MAX_SPEED_MPS))
        raise InputError(
            f"speed {speed[i]:.4g} m/s at t = {traj.time_s[i]:g} s is above Mach 3 ({MAX_SPEED_MPS:.0f} m/s)"
        )
    alt = np.asarray(ned_to_geodetic(traj.position_ned_m, *traj.origin)[2], float)
    out = (alt < ALT_LIMITS_M[0]) | (alt > ALT_LIMITS_M[1])
    if np.any(out):
        i = int(np.argmax(out))
        raise InputError(
            f"altitude {alt[i]:.4g} m at t = {traj.time_s[i]:g} s is outside "
            f"[{ALT_LIMITS_M[0]:g}, {ALT_LIMITS_M[1]:g}] m"
        )


def check_flyable(traj: Trajectory, aircraft_class: str, times_s: np.ndarray) -> None:
    """Refuse a flight whose motion over the frames ``times_s`` is beyond its class's kinematic limits.

    The flight is sampled at 20 Hz over the part of the frames it covers, and its speed and its
    velocity changes over the class's window (:func:`skyradar.scene.flyable.kinematic_violation`)
    are compared with the limits.
    """
    from skyradar.scene.flyable import AIRCRAFT_CLASSES, kinematic_violation

    limits = AIRCRAFT_CLASSES[aircraft_class]
    start = max(float(times_s[0]), traj.start_s)
    end = min(float(times_s[-1]), traj.end_s)
    if end <= start:
        return
    grid = np.union1d(np.arange(start, end, 0.05), [end])
    found = kinematic_violation(grid, traj.sample(grid).velocity_ned_mps, limits)
    if found is not None:
        when, what = found
        raise InputError(
            f"'{traj.name}' at t = {when:.6g} s: {what}; no {limits.name} aircraft flies this "
            "(set aircraft_class, or fix the path)"
        )


def read_flight(
    path: Path, icao24: str | None, origin, time_zero_s: float | None, aircraft_class: str = "ga"
) -> Trajectory:
    """A flight file's flyable path; with ``icao24`` that aircraft's track of a multi-aircraft file."""
    from skyradar.scene.adsb import read_trajectories, read_trajectory

    if icao24 is None:
        return read_trajectory(path, origin=origin, time_zero_s=time_zero_s, aircraft_class=aircraft_class)
    tracks = read_trajectories(path, origin=origin, time_zero_s=time_zero_s, aircraft_class=aircraft_class)
    if icao24 not in tracks:
        raise InputError(f"field 'icao24': {icao24!r} is not in {path} (has {sorted(tracks)[:10]})")
    return tracks[icao24]


def encounter_flight(ownship: Trajectory, params: dict[str, Any], name: str) -> Trajectory:
    """The intruder of an ``encounter`` flight section (:func:`skyradar.scene.flights.encounter`)."""
    from skyradar.scene.flights import encounter

    return encounter(ownship, name=name, **params)
