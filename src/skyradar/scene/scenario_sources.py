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
    """The DEM window ``bounds`` of ``path``; a miss names the scenario origin too.

    Parameters
    ----------
    path : Path
        DEM file (SRTM ``.hgt``, GeoTIFF or ``.npz``).
    bounds : Bounds or None
        (south, west, north, east), deg; None reads the whole DEM.
    origin : (lat_deg, lon_deg, alt_m) or None
        The scenario origin, named in the error when the DEM misses ``bounds``.

    Returns
    -------
    Terrain

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from skyradar.scene.terrain import Bounds
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = pathlib.Path(d) / "N52E004.hgt"
    ...     np.full((1201, 1201), 7, ">i2").tofile(p)
    ...     window = read_dem_near(p, Bounds(52.5, 4.5, 52.51, 4.51), (52.5, 4.5, 0.0))
    ...     try:
    ...         read_dem_near(p, Bounds(10.0, 10.0, 10.1, 10.1), (10.05, 10.05, 0.0))
    ...     except InputError as exc:
    ...         print(exc)
    N52E004.hgt: the DEM covers lat 52..53, lon 4..5, outside the area the flight needs (lat 10..10.1, \
lon 10..10.1); scenario origin lat 10.05, lon 10.05
    >>> window.shape, float(window.height_at(52.505, 4.505))  # 0.01 deg at 3 arc-seconds, one more each side
    ((15, 15), 7.0)
    """
    from skyradar.scene.dem_coverage import DemCoverageError
    from skyradar.scene.dem_readers import read_dem

    try:
        return read_dem(path, bounds=bounds)
    except DemCoverageError as exc:
        if origin is None:
            raise
        raise DemCoverageError(f"{exc}; scenario origin lat {origin[0]:.6g}, lon {origin[1]:.6g}") from None


def check_plausible(traj: Trajectory) -> None:
    """Refuse a parametric flight faster than Mach 3 or outside [-500 m, 30 km] altitude (files: adsb).

    Parameters
    ----------
    traj : Trajectory
        The flight, its altitudes from its NED positions and origin.

    Raises
    ------
    InputError
        Naming the first sample too fast or too high or low, and its time.

    Examples
    --------
    >>> from skyradar.scene.flights import straight
    >>> check_plausible(straight([0, 0, -1000], 0.0, 50.0, 10.0, origin=(52.0, 4.0, 0.0)))
    >>> check_plausible(straight([0, 0, -1000], 0.0, 1200.0, 10.0, origin=(52.0, 4.0, 0.0)))
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: speed 1200 m/s at t = 0 s is above Mach 3 (1029 m/s)
    >>> check_plausible(straight([0, 0, -31000], 0.0, 50.0, 10.0, origin=(52.0, 4.0, 0.0)))
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: altitude 3.1e+04 m at t = 0 s is outside [-500, 30000] m
    """
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

    Parameters
    ----------
    traj : Trajectory
        The flight.
    aircraft_class : str
        A key of :data:`skyradar.scene.flyable.AIRCRAFT_CLASSES`.
    times_s : ndarray
        The frame times, s; only the part the flight covers is checked.

    Raises
    ------
    InputError
        Naming the flight, the first time it breaks a limit and the limit.

    Examples
    --------
    A 60 m/s turn of 600 m radius pulls 6 m/s^2; one of 100 m radius changes velocity by
    2 v sin(v T / 2 r) = 33.9 m/s over T = 2 s, beyond the class's 10 m/s^2:

    >>> from skyradar.scene.flights import circle
    >>> frames = np.arange(0.0, 20.0, 1.0)
    >>> check_flyable(circle([0, 0, -1000], 600.0, 60.0, 20.0, origin=(52.0, 4.0, 0.0)), "ga", frames)
    >>> check_flyable(circle([0, 0, -1000], 100.0, 60.0, 20.0, origin=(52.0, 4.0, 0.0)), "ga", frames)
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: 'circle' at t = 0 s: horizontal acceleration 33.9 m/s^2 over 2 s (ga limit ...
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
    """A flight file's flyable path; with ``icao24`` that aircraft's track of a multi-aircraft file.

    Parameters
    ----------
    path : Path
        The flight file (:func:`skyradar.scene.adsb.read_trajectory`).
    icao24 : str or None
        The aircraft to take from a file of several; None for a file of one.
    origin : (lat_deg, lon_deg, alt_m) or None
        The scenario's NED frame origin (deg, deg, m); None: the file's first point.
    time_zero_s : float or None
        File timestamp that becomes scenario time 0, s; None: the file's first.
    aircraft_class : str
        A key of :data:`skyradar.scene.flyable.AIRCRAFT_CLASSES`.

    Returns
    -------
    Trajectory

    Examples
    --------
    >>> import tempfile, pathlib
    >>> rows = "0,abc123,52,4,300\\n10,abc123,52.001,4,300\\n0,def456,52,4.01,600\\n10,def456,52,4.011,600\\n"
    >>> with tempfile.TemporaryDirectory() as d:
    ...     f = pathlib.Path(d) / "two.csv"
    ...     _ = f.write_text("time_s,icao24,latitude,longitude,alt_m\\n" + rows)
    ...     b = read_flight(f, "def456", (52.0, 4.0, 0.0), None)
    ...     try:
    ...         read_flight(f, "ffffff", None, None)
    ...     except InputError as exc:
    ...         print(str(exc).replace(d, "DIR"))
    field 'icao24': 'ffffff' is not in DIR/two.csv (has ['abc123', 'def456'])
    >>> b.name, np.round(b.sample([0.0]).position_ned_m, 1).tolist()  # 0.01 deg east, 600 m up
    ('def456', [[0.0, 686.8, -600.0]])
    """
    from skyradar.scene.adsb import read_trajectories, read_trajectory

    if icao24 is None:
        return read_trajectory(path, origin=origin, time_zero_s=time_zero_s, aircraft_class=aircraft_class)
    tracks = read_trajectories(path, origin=origin, time_zero_s=time_zero_s, aircraft_class=aircraft_class)
    if icao24 not in tracks:
        raise InputError(f"field 'icao24': {icao24!r} is not in {path} (has {sorted(tracks)[:10]})")
    return tracks[icao24]


def encounter_flight(ownship: Trajectory, params: dict[str, Any], name: str) -> Trajectory:
    """The intruder of an ``encounter`` flight section (:func:`skyradar.scene.flights.encounter`).

    Parameters
    ----------
    ownship : Trajectory
        The own-ship the encounter is placed against.
    params : dict
        The section's fields (:class:`~skyradar.scene.scenario_models.EncounterFlight`) but
        ``type``, ``name``, ``rcs_m2``, ``time_offset_s`` and ``aircraft_class``.
    name : str
        The intruder's name.

    Returns
    -------
    Trajectory

    Examples
    --------
    Head-on with a 200 m miss: at the CPA the intruder is 200 m to the right (east) of a
    north-bound own-ship, flying south at its speed:

    >>> from skyradar.scene.flights import straight
    >>> own = straight([0, 0, -1000], 0.0, 50.0, 60.0, origin=(52.0, 4.0, 0.0))
    >>> a = encounter_flight(own, {"kind": "head-on", "t_cpa_s": 30.0, "horizontal_miss_m": 200.0}, "A")
    >>> offset = a.sample([30.0]).position_ned_m - own.sample([30.0]).position_ned_m
    >>> a.name, np.round(offset, 3).tolist(), np.round(a.sample([30.0]).velocity_ned_mps, 3).tolist()
    ('A', [[0.0, 200.0, 0.0]], [[-50.0, 0.0, 0.0]])
    """
    from skyradar.scene.flights import encounter

    return encounter(ownship, name=name, **params)
