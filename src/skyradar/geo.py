"""Geodetic and local coordinates, and attitude rotations.

The world frame of a scenario is local NED (north, east, down) at a fixed geodetic origin.
It is an exact Cartesian frame (a rotated, shifted ECEF), so distances computed in it are
exact; only "down" drifts from the local vertical away from the origin (0.045 deg at 5 km),
which :func:`ned_rotation_to` corrects where attitude matters. The thesis' flat-earth mapping
is kept as an option for comparison (about 2 m error at 5 km).

Rotations follow aerospace convention: ZYX Euler angles (yaw, pitch, roll) in radians take
body-frame (forward, right, down) vectors to NED.
"""

from __future__ import annotations

import math

import numpy as np
import pymap3d
from scipy.spatial.transform import Rotation

__all__ = [
    "EARTH_RADIUS_M",
    "rotation_matrix",
    "geodetic_to_ned",
    "ned_to_geodetic",
    "ned_rotation_to",
    "direction_angles",
]

EARTH_RADIUS_M = 6_371_008.8  # mean Earth radius, used only by the flat-earth option


def rotation_matrix(
    yaw_rad: np.ndarray | float, pitch_rad: np.ndarray | float, roll_rad: np.ndarray | float
) -> np.ndarray:
    """Body-to-parent rotation matrices from ZYX Euler angles (radians).

    Returns shape (3, 3) for scalars or (n, 3, 3) for arrays.

    Examples
    --------
    >>> np.round(rotation_matrix(np.pi / 2, 0.0, 0.0) @ [1.0, 0.0, 0.0], 6).tolist()
    [0.0, 1.0, 0.0]
    """
    if np.ndim(yaw_rad) == 0 and np.ndim(pitch_rad) == 0 and np.ndim(roll_rad) == 0:
        # Closed form for one attitude: called per frame, where scipy's set-up cost dominates.
        cy, sy = np.cos(yaw_rad), np.sin(yaw_rad)
        cp, sp = np.cos(pitch_rad), np.sin(pitch_rad)
        cr, sr = np.cos(roll_rad), np.sin(roll_rad)
        return np.array(
            [
                [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                [-sp, cp * sr, cp * cr],
            ]
        )
    angles = np.stack(np.broadcast_arrays(yaw_rad, pitch_rad, roll_rad), axis=-1)
    return Rotation.from_euler("ZYX", angles).as_matrix()


def geodetic_to_ned(
    lat_deg: np.ndarray | float,
    lon_deg: np.ndarray | float,
    alt_m: np.ndarray | float,
    lat0_deg: float,
    lon0_deg: float,
    alt0_m: float = 0.0,
    flat_earth: bool = False,
) -> np.ndarray:
    """WGS84 geodetic (degrees, metres above ellipsoid) to local NED at the origin, metres.

    Returns an array of shape (..., 3).

    Examples
    --------
    >>> ned = geodetic_to_ned(52.01, 4.0, 100.0, 52.0, 4.0)
    >>> bool(abs(ned[0] - 1112.5) < 1.0 and abs(ned[2] + 100.0) < 0.2)
    True
    """
    if flat_earth:
        lat0 = np.radians(lat0_deg)
        north = np.radians(np.asarray(lat_deg) - lat0_deg) * EARTH_RADIUS_M
        east = np.radians(np.asarray(lon_deg) - lon0_deg) * EARTH_RADIUS_M * np.cos(lat0)
        down = -(np.asarray(alt_m) - alt0_m)
        return np.stack(np.broadcast_arrays(north, east, down), axis=-1).astype(float)
    n, e, d = pymap3d.geodetic2ned(lat_deg, lon_deg, alt_m, lat0_deg, lon0_deg, alt0_m)
    return np.stack(np.broadcast_arrays(n, e, d), axis=-1).astype(float)


_WGS84_A = 6378137.0
_WGS84_F = 1.0 / 298.257223563
_WGS84_B = _WGS84_A * (1.0 - _WGS84_F)
_WGS84_E2 = _WGS84_F * (2.0 - _WGS84_F)


def _geodetic_to_ecef(lat_deg: float, lon_deg: float, alt_m: float) -> np.ndarray:
    lat, lon = np.radians(lat_deg), np.radians(lon_deg)
    n = _WGS84_A / np.sqrt(1.0 - _WGS84_E2 * np.sin(lat) ** 2)
    return np.array(
        [
            (n + alt_m) * np.cos(lat) * np.cos(lon),
            (n + alt_m) * np.cos(lat) * np.sin(lon),
            (n * (1.0 - _WGS84_E2) + alt_m) * np.sin(lat),
        ]
    )


def ecef_to_geodetic_point(x: float, y: float, z: float) -> tuple[float, float, float]:
    """One ECEF point (m) to WGS84 (lat_deg, lon_deg, alt_m), Heikkinen's exact closed form.

    Called once per frame; pymap3d's general array path costs tens of times more for one point.
    """
    a2, b2 = _WGS84_A**2, _WGS84_B**2
    ep2 = (a2 - b2) / b2
    p = math.hypot(x, y)
    f = 54.0 * b2 * z * z
    g = p * p + (1.0 - _WGS84_E2) * z * z - _WGS84_E2 * (a2 - b2)
    c = _WGS84_E2**2 * f * p * p / g**3
    s = (1.0 + c + math.sqrt(c * c + 2.0 * c)) ** (1.0 / 3.0)
    k = s + 1.0 + 1.0 / s
    pp = f / (3.0 * k * k * g * g)
    q = math.sqrt(1.0 + 2.0 * _WGS84_E2**2 * pp)
    r0 = -(pp * _WGS84_E2 * p) / (1.0 + q) + math.sqrt(
        max(
            0.5 * a2 * (1.0 + 1.0 / q) - pp * (1.0 - _WGS84_E2) * z * z / (q * (1.0 + q)) - 0.5 * pp * p * p,
            0.0,
        )
    )
    u = math.hypot(p - _WGS84_E2 * r0, z)
    v = math.sqrt((p - _WGS84_E2 * r0) ** 2 + (1.0 - _WGS84_E2) * z * z)
    z0 = b2 * z / (_WGS84_A * v)
    return (
        math.degrees(math.atan2(z + ep2 * z0, p)),
        math.degrees(math.atan2(y, x)),
        u * (1.0 - b2 / (_WGS84_A * v)),
    )


def ned_to_geodetic(
    ned_m: np.ndarray, lat0_deg: float, lon0_deg: float, alt0_m: float = 0.0, flat_earth: bool = False
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Local NED (metres, shape (..., 3)) back to geodetic (lat_deg, lon_deg, alt_m).

    Parameters
    ----------
    ned_m : ndarray, shape (..., 3)
        North, east, down of the points from the origin, m.
    lat0_deg, lon0_deg : float
        Geodetic latitude and longitude of the origin, deg.
    alt0_m : float
        Altitude of the origin above the WGS84 ellipsoid, m.
    flat_earth : bool
        Use a spherical flat-earth approximation (degrees per metre at the origin) instead of the
        WGS84 ellipsoid.

    Returns
    -------
    lat_deg, lon_deg, alt_m : ndarray
        Geodetic latitude (deg), longitude (deg) and altitude (m), of shape ``ned_m.shape[:-1]``.

    Examples
    --------
    A round trip with :func:`geodetic_to_ned`:

    >>> ned = geodetic_to_ned(52.01, 4.0, 100.0, 52.0, 4.0)
    >>> [round(float(x), 6) for x in ned_to_geodetic(ned, 52.0, 4.0)]
    [52.01, 4.0, 100.0]

    On the flat earth 1 km north is ``1000 / R`` rad of latitude:

    >>> lat, lon, alt = ned_to_geodetic(np.array([[1000.0, 0.0, -50.0]]), 0.0, 0.0, flat_earth=True)
    >>> bool(np.isclose(lat[0], np.degrees(1000.0 / EARTH_RADIUS_M))), float(alt[0])
    (True, 50.0)
    """
    ned = np.asarray(ned_m, dtype=float)
    if ned.shape == (3,) and not flat_earth:
        ecef = _geodetic_to_ecef(lat0_deg, lon0_deg, alt0_m) + _ecef_from_ned(lat0_deg, lon0_deg) @ ned
        point = ecef_to_geodetic_point(*ecef)
        return np.asarray(point[0]), np.asarray(point[1]), np.asarray(point[2])
    if flat_earth:
        lat = lat0_deg + np.degrees(ned[..., 0] / EARTH_RADIUS_M)
        lon = lon0_deg + np.degrees(ned[..., 1] / (EARTH_RADIUS_M * np.cos(np.radians(lat0_deg))))
        return lat, lon, alt0_m - ned[..., 2]
    lat, lon, alt = pymap3d.ned2geodetic(ned[..., 0], ned[..., 1], ned[..., 2], lat0_deg, lon0_deg, alt0_m)
    return np.asarray(lat), np.asarray(lon), np.asarray(alt)


def _ecef_from_ned(lat_deg: float, lon_deg: float) -> np.ndarray:
    lat, lon = np.radians(lat_deg), np.radians(lon_deg)
    sl, cl, so, co = np.sin(lat), np.cos(lat), np.sin(lon), np.cos(lon)
    return np.array([[-sl * co, -so, -cl * co], [-sl * so, co, -cl * so], [cl, 0.0, -sl]])


def ned_rotation_to(lat0_deg: float, lon0_deg: float, lat_deg: float, lon_deg: float) -> np.ndarray:
    """Rotation taking vectors in the origin's NED frame to the local NED frame at (lat, lon).

    Attitude angles are relative to the local vertical at the aircraft; this accounts for the
    Earth's curvature between the scenario origin and the aircraft.

    Parameters
    ----------
    lat0_deg, lon0_deg : float
        Geodetic latitude and longitude of the origin, deg.
    lat_deg, lon_deg : float
        Geodetic latitude and longitude of the local frame, deg.

    Returns
    -------
    ndarray, shape (3, 3)
        Rotation matrix ``R`` with ``v_local = R @ v_origin``.

    Examples
    --------
    One degree of latitude further north the local vertical is tilted by one degree about east:
    the origin's ``down`` has a north component of ``sin(1 deg)`` there.

    >>> R = ned_rotation_to(0.0, 0.0, 1.0, 0.0)
    >>> round(float(np.degrees(np.arcsin(R[0, 2]))), 6), np.round(R[:, 1], 6).tolist()
    (1.0, [0.0, 1.0, 0.0])
    """
    return _ecef_from_ned(lat_deg, lon_deg).T @ _ecef_from_ned(lat0_deg, lon0_deg)


def direction_angles(vectors: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Range, azimuth and elevation of vectors in a forward-right-down frame.

    Parameters
    ----------
    vectors : ndarray, shape (..., 3)
        Vectors in a forward-right-down frame, m.

    Returns
    -------
    range_m, azimuth_rad, elevation_rad : ndarray, shape (...)
        Length (m); azimuth, positive to the right of +x (rad); elevation, positive above the x-y
        plane (rad).

    Examples
    --------
    >>> rng, az, el = direction_angles(np.array([[0.0, 100.0, -100.0], [0.0, 0.0, -50.0]]))
    >>> rng.round(3).tolist(), np.degrees(az).round(3).tolist(), np.degrees(el).round(3).tolist()
    ([141.421, 50.0], [90.0, 0.0], [45.0, 90.0])
    """
    v = np.asarray(vectors, dtype=float)
    rng = np.linalg.norm(v, axis=-1)
    az = np.arctan2(v[..., 1], v[..., 0])
    el = np.arcsin(np.clip(-v[..., 2] / np.maximum(rng, 1e-300), -1.0, 1.0))
    return rng, az, el
