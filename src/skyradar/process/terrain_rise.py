"""How much higher the ground rises around the radar than the ground directly below it.

The range-Doppler region ground can occupy (:func:`skyradar.process.ground.in_ground_band`) depends on
the height of the ground above which the radar flies. Over relief, a ridge beside the track is
closer than the ground below and returns at ranges shorter than the height above ground; a fixed
margin calls those ranges unreachable and keeps their clutter as air. :func:`terrain_rise_m` samples
the surface around the radar and gives, for each range, the largest rise of the ground within that
horizontal distance, so the band widens only where the terrain does.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["terrain_rise_m", "rise_points"]


def terrain_rise_m(
    height_fn: Callable[[np.ndarray], np.ndarray],
    antenna_ned_m: np.ndarray,
    range_m: np.ndarray,
    n_radii: int = 16,
    n_azimuth: int = 24,
) -> np.ndarray:
    """Largest rise of the surface within horizontal distance ``range_m`` of the radar, m (>= 0).

    Parameters
    ----------
    height_fn : callable
        Height above the surface of NED points (..., 3), m (as
        :func:`skyradar.process.ground.surface_height_fn` builds it).
    antenna_ned_m : ndarray, shape (3,)
        The radar's position, NED, m.
    range_m : ndarray
        Slant ranges at which the rise is wanted, m; ground at slant range R lies within horizontal
        distance R.
    n_radii, n_azimuth : int
        Sampling rings (equally spaced out to the largest range) and points per ring. A peak
        narrower than the ring spacing can be missed: the rise is a sampled estimate.

    Returns
    -------
    ndarray
        Rise per range, m: the highest sampled surface within the ring at or beyond that range, above
        the surface directly below the radar.

    Examples
    --------
    >>> flat = lambda p: 1000.0 - np.asarray(p)[..., 2] * 0.0
    >>> terrain_rise_m(flat, np.zeros(3), np.array([500.0, 2000.0])).tolist()
    [0.0, 0.0]
    >>> ridge = lambda p: 1000.0 - 200.0 * (np.asarray(p)[..., 1] > 300.0)  # 200 m ridge 300 m east
    >>> terrain_rise_m(ridge, np.zeros(3), np.array([200.0, 600.0])).tolist()
    [0.0, 200.0]
    """
    rng = np.asarray(range_m, float)
    if rng.size == 0:
        return np.zeros(0)
    antenna = np.asarray(antenna_ned_m, float)
    radii, points = rise_points(antenna, rng, n_radii, n_azimuth)
    below = float(np.asarray(height_fn(antenna[None]), float)[0])
    rise = below - np.asarray(height_fn(points), float)  # (ring, azimuth)
    ring_max = np.maximum.accumulate(np.nan_to_num(rise, nan=0.0).max(axis=1))
    # The ring at or beyond each range: a sampled bound, never smaller than the rise nearer in.
    k = np.clip(np.searchsorted(radii, rng, side="left"), 0, radii.size - 1)
    return np.maximum(ring_max[k], 0.0)


def rise_points(
    antenna_ned_m: np.ndarray, range_m: np.ndarray, n_radii: int = 16, n_azimuth: int = 24
) -> tuple[np.ndarray, np.ndarray]:
    """The rings :func:`terrain_rise_m` samples: their radii (n_radii,), m, and their NED points
    (n_radii, n_azimuth, 3), m, at the radar's depth, out to the largest of ``range_m`` (not empty).

    Parameters
    ----------
    antenna_ned_m : ndarray (3,)
        The radar's position, NED, m.
    range_m : ndarray
        Slant ranges, m; the rings reach the largest.
    n_radii, n_azimuth : int
        Rings, equally spaced from ``max(range_m) / n_radii`` out, and points per ring (from north,
        clockwise, equally spaced).

    Returns
    -------
    radii : ndarray (n_radii,)
        Ring radii, m.
    points : ndarray (n_radii, n_azimuth, 3)
        NED points, m.

    Examples
    --------
    >>> radii, points = rise_points(np.array([0.0, 0.0, -100.0]), np.array([300.0, 1000.0]), 4, 4)
    >>> radii.tolist(), points.shape, points[0, 1].round(1).tolist()  # first ring, due east
    ([250.0, 500.0, 750.0, 1000.0], (4, 4, 3), [0.0, 250.0, -100.0])
    """
    antenna = np.asarray(antenna_ned_m, float)
    radii = np.linspace(0.0, float(np.max(range_m)), n_radii + 1)[1:]
    az = np.linspace(0.0, 2.0 * np.pi, n_azimuth, endpoint=False)
    offsets = np.stack([np.outer(radii, np.cos(az)), np.outer(radii, np.sin(az))], axis=-1)
    return radii, np.concatenate([offsets, np.zeros((*offsets.shape[:2], 1))], axis=-1) + antenna
