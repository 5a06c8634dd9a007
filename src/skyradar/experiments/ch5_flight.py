"""The ch5 own-ship flight: terrain-following at a fixed mean height above ground, and its truth.

The aircraft flies north through the terrain's centre at constant ground speed. Its altitude
follows the terrain smoothed along the track (Gaussian, ``smooth_m``) plus a constant chosen so
that the mean height above the terrain directly below is exactly ``height_m`` on every terrain
(Maas 2022, ch. 5: same flight, same mean height above ground). Vertical speed is therefore
non-zero over hilly terrain: the flight climbs and descends.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import gaussian_filter1d

from skyradar.geo import geodetic_to_ned, ned_to_geodetic
from skyradar.sim.image import PlatformState

__all__ = ["Flight", "terrain_following_flight"]


@dataclass(frozen=True)
class Flight:
    """Platform states at the frame times and their truth (V_X, V_Z positive down, height AGL)."""

    times_s: np.ndarray
    states: list[PlatformState]
    vx_mps: np.ndarray
    vz_mps: np.ndarray
    height_agl_m: np.ndarray
    attitude_rad: np.ndarray  # (n, 3) yaw, pitch, roll


def terrain_following_flight(
    terrain,
    origin: tuple[float, float, float],
    times_s: np.ndarray,
    speed_mps: float = 55.0,
    height_m: float = 600.0,
    smooth_m: float = 1500.0,
    step_m: float = 10.0,
) -> Flight:
    """Straight northbound flight centred on ``origin`` (see module docstring).

    Examples
    --------
    >>> from skyradar.scene.synthetic_terrain import flat_terrain
    >>> t = flat_terrain(52.0, 4.0, size_m=6000.0)
    >>> f = terrain_following_flight(t, (52.0, 4.0, 0.0), np.arange(5.0))
    >>> round(float(f.height_agl_m.mean()), 3), round(float(f.vx_mps[0]), 2)
    (600.0, 55.0)
    """
    times = np.asarray(times_s, float)
    lat0, lon0, alt0 = origin
    t_mid = 0.5 * (times[0] + times[-1])
    # Terrain profile along the track, padded for the smoothing kernel.
    north_track = (times - t_mid) * speed_mps
    pad = 3.0 * smooth_m
    grid_n = np.arange(north_track.min() - pad, north_track.max() + pad + step_m, step_m)
    lat_g, lon_g, _ = ned_to_geodetic(
        np.column_stack([grid_n, np.zeros_like(grid_n), np.zeros_like(grid_n)]), lat0, lon0, alt0
    )
    ground = np.asarray(terrain.height_at(lat_g, lon_g), float)
    ground = np.where(np.isfinite(ground), ground, np.nanmean(ground))
    smooth = gaussian_filter1d(ground, smooth_m / step_m, mode="nearest")
    in_flight = (grid_n >= north_track.min()) & (grid_n <= north_track.max())
    alt_g = smooth + height_m + np.mean((ground - smooth)[in_flight])
    # Sample position and derivatives at the frame times.
    alt = np.interp(north_track, grid_n, alt_g)
    climb = np.gradient(alt_g, step_m) * speed_mps
    vz = -np.interp(north_track, grid_n, climb)
    lat, lon, _ = ned_to_geodetic(
        np.column_stack([north_track, np.zeros_like(times), np.zeros_like(times)]), lat0, lon0, alt0
    )
    below = np.asarray(terrain.height_at(lat, lon), float)
    alt = alt - np.mean(alt - below) + height_m  # exact mean height at the frame times
    hagl = alt - below
    ned = geodetic_to_ned(lat, lon, alt, lat0, lon0, alt0)
    attitude = np.zeros((times.size, 3))
    states = [
        PlatformState(ned[i], np.array([speed_mps, 0.0, vz[i]]), attitude[i]) for i in range(times.size)
    ]
    return Flight(times, states, np.full(times.size, speed_mps), vz, hagl, attitude)
