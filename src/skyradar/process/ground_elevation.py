"""Ground tested by elevation alone, for pixels whose azimuth means nothing.

A range-Doppler cell can sum ground to the left and right of the track (the same static Doppler
on both sides): one plane wave explains such a pixel badly and its azimuth is meaningless, but
returns from the same antenna elevation add up with the same phase step across the vertical
baseline, so its elevation is still that of the ground. :func:`ground_in_elevation` asks whether
some azimuth puts the pixel on the surface (used by :func:`skyradar.process.ground.flag_ground`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["ground_in_elevation", "elevation_points"]


def ground_in_elevation(
    range_m: np.ndarray,
    elevation_rad: np.ndarray,
    height_fn: Callable[[np.ndarray], np.ndarray],
    antenna_ned_m: np.ndarray,
    ant_to_ned: np.ndarray,
    margin_m: np.ndarray | float,
    max_azimuth_rad: float = np.radians(70.0),
    n_azimuth: int = 29,
) -> np.ndarray:
    """True where some azimuth within ``+-max_azimuth_rad`` puts ``(range, elevation)`` on the surface.

    For pixels whose azimuth means nothing (ground to the left and right of the track in one
    range-Doppler cell). Returns from the same antenna elevation add up with the same phase step
    across the vertical baseline, so the elevation of such a mixture is still that of the
    ground; an aircraft mixed with ground pulls it towards the aircraft.

    Parameters
    ----------
    range_m : ndarray (n,)
        Slant ranges, m.
    elevation_rad : ndarray (n,)
        Antenna-frame elevations, rad, positive up.
    height_fn : callable
        Maps NED points (m, shape (..., 3)) to heights above the surface, m (NaN: unknown, not ground).
    antenna_ned_m : ndarray (3,)
        Antenna position, NED, m.
    ant_to_ned : ndarray (3, 3)
        Rotation of antenna-frame vectors into NED.
    margin_m : float or ndarray (n,)
        Largest distance from the surface still counted as on it, m.
    max_azimuth_rad : float
        Azimuths tried span ``+-max_azimuth_rad``, rad.
    n_azimuth : int
        Azimuths tried.

    Returns
    -------
    ndarray of bool (n,)

    Examples
    --------
    Flat ground 500 m below a level radar is at elevation ``-asin(500 / 1000) = -30 deg`` at
    1000 m, whatever the azimuth:

    >>> flat = lambda p: 500.0 - np.asarray(p)[..., 2]  # height above a ground 500 m down
    >>> el = np.radians([-30.0, -10.0])
    >>> ground_in_elevation(np.full(2, 1000.0), el, flat, np.zeros(3), np.eye(3), 20.0)
    array([ True, False])
    """
    el = np.asarray(elevation_rad, float)[:, None]
    h = height_fn(
        elevation_points(range_m, elevation_rad, antenna_ned_m, ant_to_ned, max_azimuth_rad, n_azimuth)
    )
    margin = np.broadcast_to(np.asarray(margin_m, float), el.shape[:1])[:, None]
    with np.errstate(invalid="ignore"):
        return np.any(np.abs(h) <= margin, axis=1)


def elevation_points(
    range_m: np.ndarray,
    elevation_rad: np.ndarray,
    antenna_ned_m: np.ndarray,
    ant_to_ned: np.ndarray,
    max_azimuth_rad: float = np.radians(70.0),
    n_azimuth: int = 29,
) -> np.ndarray:
    """NED points (n, n_azimuth, 3), m, that :func:`ground_in_elevation` tests: each detection's
    range and antenna elevation at ``n_azimuth`` azimuths within ``+-max_azimuth_rad``. Each row
    depends on its own detection only.

    Parameters
    ----------
    range_m : ndarray (n,)
        Slant ranges, m.
    elevation_rad : ndarray (n,)
        Antenna-frame elevations, rad, positive up.
    antenna_ned_m : ndarray (3,)
        Antenna position, NED, m.
    ant_to_ned : ndarray (3, 3)
        Rotation of antenna-frame vectors into NED.
    max_azimuth_rad : float
        The azimuths span ``+-max_azimuth_rad``, rad, equally spaced.
    n_azimuth : int
        Azimuths per detection.

    Returns
    -------
    ndarray (n, n_azimuth, 3)
        NED points, m.

    Examples
    --------
    1000 m at 30 deg below a level radar: 500 m down, 866 m out, at -70, 0 and 70 deg azimuth:

    >>> pts = elevation_points(np.array([1000.0]), np.radians([-30.0]), np.zeros(3), np.eye(3), n_azimuth=3)
    >>> pts.round(1).tolist()
    [[[296.2, -813.8, 500.0], [866.0, 0.0, 500.0], [296.2, 813.8, 500.0]]]
    """
    az = np.linspace(-max_azimuth_rad, max_azimuth_rad, n_azimuth)
    el = np.asarray(elevation_rad, float)[:, None]
    u_ant = np.stack(np.broadcast_arrays(np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)), -1)
    return np.asarray(antenna_ned_m, float) + np.asarray(range_m, float)[:, None, None] * (
        u_ant @ np.asarray(ant_to_ned, float).T
    )
