"""The states the image-domain simulator works with: platform, point target, antenna, terrain view."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["PlatformState", "PointTarget", "TerrainView", "AntennaGeometry"]


@dataclass(frozen=True)
class PlatformState:
    """Own-ship state in the scenario NED frame: position (m), velocity (m/s), yaw/pitch/roll (rad).

    Parameters
    ----------
    position_ned_m : ndarray, shape (3,)
        Position (north, east, down), m.
    velocity_ned_mps : ndarray, shape (3,)
        Velocity (north, east, down), m/s.
    attitude_rad : ndarray, shape (3,)
        Yaw, pitch and roll, rad.

    Examples
    --------
    A radar on an aircraft flying north at 30 m/s sees a still point 1 km ahead at 1 km,
    closing at 30 m/s, straight ahead:

    >>> from skyradar.config import RadarConfig
    >>> from skyradar.sim.image import ImageSimulator
    >>> sim = ImageSimulator(RadarConfig.prototype_2022(), noise=False)
    >>> own = PlatformState(np.zeros(3), np.array([30.0, 0, 0]), np.zeros(3))
    >>> truth = sim.target_truth(own, [PointTarget(np.array([1000.0, 0, 0]), np.zeros(3))])
    >>> round(float(truth["range_m"][0]), 3), float(truth["radial_velocity_mps"][0])
    (1000.0, -30.0)
    >>> own = PlatformState(np.zeros(3), np.array([0.0, 30.0, 0]), np.array([np.pi / 2, 0, 0]))
    >>> truth = sim.target_truth(own, [PointTarget(np.array([0.0, 1000.0, 0]), np.zeros(3))])
    >>> float(truth["radial_velocity_mps"][0]), round(float(truth["azimuth_rad"][0]), 6)  # yawed east
    (-30.0, 0.0)
    """

    position_ned_m: np.ndarray
    velocity_ned_mps: np.ndarray
    attitude_rad: np.ndarray


@dataclass(frozen=True)
class PointTarget:
    """A point scatterer (e.g. an aircraft) in the scenario NED frame with its RCS in m^2.

    Parameters
    ----------
    position_ned_m : ndarray, shape (3,)
        Position (north, east, down), m.
    velocity_ned_mps : ndarray, shape (3,)
        Velocity (north, east, down), m/s.
    rcs_m2 : float
        Radar cross-section, m^2.

    Examples
    --------
    A 2 m^2 target 1 km ahead on the prototype's boresight (gain G = 9.25 dBi) returns the radar
    equation's power ``Pe G^2 lambda^2 sigma / ((4 pi)^3 R^4)``, 7.2e-16 W (-121.4 dBm):

    >>> from skyradar.config import RadarConfig
    >>> from skyradar.sim.targets import target_geometry
    >>> cfg = RadarConfig.prototype_2022()
    >>> geom = AntennaGeometry(np.zeros(3), np.eye(3), np.zeros(3), 52.0, 4.0)
    >>> target = PointTarget(np.array([1000.0, 0, 0]), np.zeros(3), rcs_m2=2.0)
    >>> power = target_geometry(cfg, geom, [target], 0.0, np.array([True]))["power_w"][0]
    >>> gain = 10 ** (float(cfg.antenna.gain_db(0.0, 0.0)) / 10)
    >>> expected = cfg.pe_w * gain**2 * cfg.wavelength_m**2 * 2.0 / ((4 * np.pi) ** 3 * 1000.0**4)
    >>> f"{power:.2e}", bool(np.isclose(power, expected))
    ('7.23e-16', True)
    """

    position_ned_m: np.ndarray
    velocity_ned_mps: np.ndarray
    rcs_m2: float = 1.0


@dataclass(frozen=True)
class TerrainView:
    """Terrain cropped around the antenna for one frame, and its polar horizon.

    Parameters
    ----------
    p_ned : ndarray, shape (rows, cols, 3)
        Grid points relative to the antenna, NED, m.
    horizon : ndarray, shape (n_az, n_h)
        Per azimuth and horizontal-distance bin, the slope (-down / horizontal distance) a point
        must reach to be seen; a 1 x 1 array of -inf: no occlusion.
    az_bin_rad : float
        Azimuth bin width, rad.
    h_bin_m : float
        Horizontal-distance bin width, m.

    Examples
    --------
    A horizon of slope -0.1 everywhere hides a point 1 km out and 200 m below the antenna
    (slope -0.2), not one 200 m above it:

    >>> from skyradar.sim.geometry import AntennaGeometry, PointTarget
    >>> from skyradar.sim.targets import line_of_sight
    >>> view = TerrainView(np.zeros((1, 1, 3)), np.full((4, 3), -0.1), np.pi / 2, 500.0)
    >>> geom = AntennaGeometry(np.zeros(3), np.eye(3), np.zeros(3), 52.0, 4.0)
    >>> low, high = (PointTarget(np.array([1000.0, 0, d]), np.zeros(3)) for d in (200.0, -200.0))
    >>> line_of_sight(view, geom, [low, high]).tolist()
    [False, True]
    """

    p_ned: np.ndarray  # grid points relative to the antenna, NED, m
    horizon: np.ndarray  # (n_az, n_h) slope -down/horizontal to beat (1 x 1 of -inf: no occlusion)
    az_bin_rad: float
    h_bin_m: float


@dataclass(frozen=True)
class AntennaGeometry:
    """Where the antenna is and how it is turned in the scenario NED frame for one frame.

    Parameters
    ----------
    origin_ned_m : ndarray, shape (3,)
        Antenna phase-centre reference point, NED, m.
    rot_ned_to_ant : ndarray, shape (3, 3)
        Rotation of a NED vector into the antenna frame (x along boresight).
    velocity_ned_mps : ndarray, shape (3,)
        Antenna velocity, NED, m/s.
    lat_deg, lon_deg : float
        Platform position, deg (the antenna is metres away: the same terrain crop).

    Examples
    --------
    An antenna yawed 90 deg looks east: a point 1 km east is on its boresight (azimuth 0),
    one 1 km north is 90 deg to its left and out of view (behind the antenna plane):

    >>> from skyradar.config import RadarConfig
    >>> from skyradar.sim.targets import target_geometry
    >>> yaw90 = np.array([[0.0, 1, 0], [-1, 0, 0], [0, 0, 1]])
    >>> geom = AntennaGeometry(np.zeros(3), yaw90, np.zeros(3), 52.0, 4.0)
    >>> east, north = (PointTarget(np.array(p), np.zeros(3)) for p in ([0.0, 1000, 0], [1000.0, 0, 0]))
    >>> g = target_geometry(RadarConfig.prototype_2022(), geom, [east, north], 0.0, np.ones(2, bool))
    >>> np.degrees(g["azimuth_rad"]).round(6).tolist(), g["visible"].tolist()
    ([0.0, -90.0], [True, False])
    """

    origin_ned_m: np.ndarray  # antenna phase-centre reference point
    rot_ned_to_ant: np.ndarray  # 3x3, NED vector -> antenna-frame vector
    velocity_ned_mps: np.ndarray
    lat_deg: float  # platform position (the antenna is metres away: same crop)
    lon_deg: float
