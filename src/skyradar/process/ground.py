"""Separate airborne objects from ground and terrain returns.

Two independent tests, combined with AND where both are available:

* height: the detection's altitude against the terrain under its 3-D position (``Terrain.height_at``
  at the detection's latitude/longitude, or a flat ground altitude). A return within the height
  margin of the ground, or below it, is a ground candidate. The margin grows with range because
  the vertical position error is about ``range * sd(elevation)``.
* Doppler: a static surface point in direction ``u`` (NED unit vector from the radar) has radial
  velocity ``-v_own . u`` (positive receding). A return whose measured radial velocity matches
  that value, modulo the aliasing width ``2 VLim``, is consistent with a static surface.

With neither test available (no terrain and no own-ship velocity) nothing is called ground.
Aircraft flying perpendicular to the line of sight share the static Doppler; the height test is
what keeps them airborne, so give a terrain when there is one.

Examples
--------
>>> from skyradar.config import RadarConfig
>>> cfg = RadarConfig.prototype_2022()
>>> u = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # ahead, straight down
>>> static_radial_velocity_mps(u, np.array([30.0, 0.0, 0.0])).tolist()
[-30.0, -0.0]
>>> doppler_matches_static(np.array([-30.0, 48.0]), np.array([-30.0, -30.0]), cfg, 1.0).tolist()  # 48 aliases
[True, True]
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from skyradar.config import RadarConfig

__all__ = [
    "static_radial_velocity_mps",
    "doppler_matches_static",
    "in_ground_band",
    "height_above_ground_m",
    "classify_ground",
]


def static_radial_velocity_mps(direction_ned: np.ndarray, own_velocity_ned_mps: np.ndarray) -> np.ndarray:
    """Radial velocity of a static point seen along unit vectors ``direction_ned`` (n, 3), m/s."""
    u = np.asarray(direction_ned, float)
    return -np.einsum("...i,...i->...", u, np.broadcast_to(np.asarray(own_velocity_ned_mps, float), u.shape))


def doppler_matches_static(
    radial_velocity_mps: np.ndarray,
    expected_mps: np.ndarray,
    config: RadarConfig,
    tolerance_mps: np.ndarray | float,
) -> np.ndarray:
    """True where measured and expected radial velocity agree within the tolerance, modulo ``2 VLim``."""
    width = 2.0 * config.v_lim_mps
    diff = np.asarray(radial_velocity_mps, float) - np.asarray(expected_mps, float)
    return np.abs((diff + width / 2.0) % width - width / 2.0) <= tolerance_mps


def in_ground_band(
    range_m: np.ndarray,
    radial_velocity_mps: np.ndarray,
    own_velocity_ned_mps: np.ndarray,
    own_height_agl_m: float,
    config: RadarConfig,
    tolerance_mps: float | None = None,
    terrain_margin_m: float = 30.0,
) -> np.ndarray:
    """True where some static point of the ground at this range can have this (aliased) radial velocity.

    Needs no direction: ground ``h`` below the radar is seen at range R along unit vectors with
    down component ``u_d = h / R``, whose static radial velocities fill
    ``-v_d u_d +- |v_horizontal| sqrt(1 - u_d^2)`` (the clutter region of the range-Doppler
    image, bounded by R = h and V = -speed). ``terrain_margin_m`` allows for ground up to that
    much higher than the ground directly below (it widens the band). Used for pixels whose
    direction is unreliable (a pixel summing ground to the left and right of the track).
    """
    rng = np.maximum(np.asarray(range_m, float), 1e-9)
    v = np.asarray(own_velocity_ned_mps, float)
    tol = 1.5 * config.doppler_resolution_mps if tolerance_mps is None else tolerance_mps
    u_hi = np.clip(own_height_agl_m / rng, 0.0, 1.0)
    u_lo = np.clip((own_height_agl_m - terrain_margin_m) / rng, 0.0, 1.0)
    centre = -v[2] * 0.5 * (u_lo + u_hi)
    half = np.hypot(v[0], v[1]) * np.sqrt(1.0 - u_lo**2) + abs(v[2]) * 0.5 * (u_hi - u_lo) + tol
    width = 2.0 * config.v_lim_mps
    diff = (np.asarray(radial_velocity_mps, float) - centre + width / 2.0) % width - width / 2.0
    reachable = rng >= own_height_agl_m - terrain_margin_m - config.range_resolution_m
    return reachable & ((np.abs(diff) <= half) | (2.0 * half >= width))


def height_above_ground_m(
    lat_deg: np.ndarray,
    lon_deg: np.ndarray,
    alt_m: np.ndarray,
    terrain: Any = None,
    ground_alt_m: float | None = None,
) -> np.ndarray:
    """Altitude above the terrain (``terrain.height_at`` or a callable) or a flat ground, m (NaN: unknown)."""
    alt = np.asarray(alt_m, float)
    if terrain is not None:
        height_at: Callable = terrain.height_at if hasattr(terrain, "height_at") else terrain
        return alt - np.asarray(height_at(np.asarray(lat_deg, float), np.asarray(lon_deg, float)), float)
    if ground_alt_m is not None:
        return alt - float(ground_alt_m)
    return np.full(alt.shape, np.nan)


def classify_ground(
    range_m: np.ndarray,
    radial_velocity_mps: np.ndarray,
    direction_ned: np.ndarray,
    config: RadarConfig,
    own_velocity_ned_mps: np.ndarray | None = None,
    height_agl_m: np.ndarray | None = None,
    angle_sd_rad: float = np.radians(1.0),
    height_margin_m: float = 30.0,
) -> np.ndarray:
    """True for detections that look like ground returns.

    Parameters
    ----------
    range_m, radial_velocity_mps : ndarray, shape (n,)
        Measured range and (aliased) radial velocity.
    direction_ned : ndarray, shape (n, 3)
        Unit vectors from the radar to the detections in NED (NaN where no DoA).
    config : RadarConfig
        Doppler resolution and aliasing width.
    own_velocity_ned_mps : ndarray, shape (3,), optional
        Own-ship velocity; enables the Doppler test.
    height_agl_m : ndarray, shape (n,), optional
        Height above the ground (:func:`height_above_ground_m`); enables the height test.
    angle_sd_rad : float
        Expected DoA error, widens both tolerances.
    height_margin_m : float
        Smallest height margin.
    """
    rng = np.asarray(range_m, float)
    result = np.ones(rng.shape, bool)
    tested = False
    if height_agl_m is not None:
        h = np.asarray(height_agl_m, float)
        if np.any(np.isfinite(h)):
            margin = np.maximum(height_margin_m, 3.0 * rng * angle_sd_rad)
            result &= np.isfinite(h) & (h <= margin)
            tested = True
    if own_velocity_ned_mps is not None and np.all(np.isfinite(own_velocity_ned_mps)):
        speed = float(np.linalg.norm(own_velocity_ned_mps))
        u = np.asarray(direction_ned, float)
        expected = static_radial_velocity_mps(u, own_velocity_ned_mps)
        tol = 1.5 * config.doppler_resolution_mps + 3.0 * speed * angle_sd_rad
        # A stationary radar sees everything static at zero Doppler: only useful together with height.
        if speed > config.doppler_resolution_mps or tested:
            result &= np.isfinite(expected) & doppler_matches_static(
                radial_velocity_mps, expected, config, tol
            )
            tested = True
    return result if tested else np.zeros(rng.shape, bool)
