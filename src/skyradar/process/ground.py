"""Separate airborne objects from ground and terrain returns.

A detection is ground only when its 3-D position lies on the surface within its uncertainty, or
its Doppler and angle match the ground there (:func:`classify_ground`):

* position: its height ``h`` above the terrain under it (``Terrain.height_at``, or a flat ground
  at the height of the ground under the own-ship) against its standard deviation ``sd``
  (:func:`height_sd_m`: the DoA Cramer-Rao bound at its SNR times the range, the range error,
  the surface's own error). ``h <= 3 sd`` is "on the surface"; ``h < -3 sd`` is below it.
* Doppler: a static surface point in direction ``u`` (NED unit vector from the radar) has radial
  velocity ``-v_own . u`` (positive receding); the measured one matches it, modulo ``2 VLim``,
  within the resolution and 3 sd of that value's change with the DoA error
  (:func:`static_doppler_sd_mps`: near the velocity vector it hardly changes).

Ground = (on the surface AND (static Doppler OR ``3 sd <= 30 m``, a position that precise))
OR (static Doppler AND the ray reaches the surface within two range bins: range sidelobes and
straddle) OR below the surface. So a slow, crossing or circling aircraft above the terrain is
kept even when its radial velocity equals the static one, and an uncertain position leaves the
decision to the Doppler. Without a height above ground (no terrain, no own-ship height) nothing
is ground: Doppler alone cannot tell an aircraft crossing the line of sight from the ground.
Pixels whose direction is unreliable are handled by :func:`flag_ground`.

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
from skyradar.process.ground_elevation import elevation_points, ground_in_elevation
from skyradar.process.terrain_rise import rise_points, terrain_rise_m

__all__ = [
    "static_radial_velocity_mps",
    "doppler_matches_static",
    "in_ground_band",
    "height_above_ground_m",
    "classify_ground",
    "height_sd_m",
    "direction_derivatives",
    "static_doppler_sd_mps",
    "ground_in_elevation",
    "surface_height_fn",
    "flag_ground",
]

# NED points (..., 3) -> their (lat_deg, lon_deg, alt_m), as skyradar.geo.ned_to_geodetic.
GeodeticFn = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]

_ONE_DEG = float(np.radians(1.0))
_CHI2_2DOF_3SD = 11.829  # chi-square quantile of 2 degrees of freedom at 0.9973 (3 sd in one)
_ENDFIRE_COSINE = float(np.sin(np.radians(45.0)))
# DoA error floor beyond the Cramer-Rao bound (attitude and calibration errors), and the surface's
# own height uncertainty (DEM error, relief inside a range cell, navigation altitude error).
ANGLE_FLOOR_RAD = float(np.radians(0.3))
SURFACE_SD_M = 10.0
TERRAIN_MARGIN_M = 30.0  # ground this much above the ground below is in the band anywhere
_ALTITUDE_LEAK_BINS = 2.0  # range bins the altitude return leaks (window sidelobes, straddle)


def static_radial_velocity_mps(direction_ned: np.ndarray, own_velocity_ned_mps: np.ndarray) -> np.ndarray:
    """Radial velocity of a static point seen along unit vectors ``direction_ned`` (n, 3), m/s.

    Parameters
    ----------
    direction_ned : ndarray (..., 3)
        Unit vectors from the radar, NED (any frame, the same as the velocity's).
    own_velocity_ned_mps : ndarray (3,)
        Radar velocity over the ground, m/s.

    Returns
    -------
    ndarray (...)
        ``-v . u``, m/s, positive receding (not aliased).

    Examples
    --------
    Flying north at 50 m/s: a point ahead closes at 50 m/s, one 60 deg to the right at
    ``50 cos 60 deg``, the point straight below not at all:

    >>> u = np.array([[1.0, 0.0, 0.0], [0.5, np.sqrt(3.0) / 2.0, 0.0], [0.0, 0.0, 1.0]])
    >>> (static_radial_velocity_mps(u, np.array([50.0, 0.0, 0.0])) + 0.0).round(6).tolist()
    [-50.0, -25.0, 0.0]
    """
    u = np.asarray(direction_ned, float)
    return -np.einsum("...i,...i->...", u, np.broadcast_to(np.asarray(own_velocity_ned_mps, float), u.shape))


def doppler_matches_static(
    radial_velocity_mps: np.ndarray,
    expected_mps: np.ndarray,
    config: RadarConfig,
    tolerance_mps: np.ndarray | float,
) -> np.ndarray:
    """True where measured and expected radial velocity agree within the tolerance, modulo ``2 VLim``.

    Parameters
    ----------
    radial_velocity_mps : ndarray
        Measured (aliased) radial velocity, m/s.
    expected_mps : ndarray
        Expected radial velocity of a static point, m/s (any alias).
    config : RadarConfig
        Its ``v_lim_mps`` sets the alias period ``2 VLim``, m/s.
    tolerance_mps : float or ndarray
        Largest difference still agreeing, m/s.

    Returns
    -------
    ndarray of bool

    Examples
    --------
    The prototype's velocities alias with a period of 78.26 m/s, so -50 m/s shows at 28.26 m/s:

    >>> from skyradar.config import RadarConfig
    >>> doppler_matches_static(np.array([28.26, 0.0]), -50.0, RadarConfig.prototype_2022(), 0.5).tolist()
    [True, False]
    """
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
    terrain_margin_m: np.ndarray | float = TERRAIN_MARGIN_M,
) -> np.ndarray:
    """True where some static point of the ground at this range can have this (aliased) radial velocity.

    Needs no direction: ground ``h`` below the radar is seen at range R along unit vectors with
    down component ``u_d = h / R``, whose static radial velocities fill
    ``-v_d u_d +- |v_horizontal| sqrt(1 - u_d^2)`` (the clutter region of the range-Doppler
    image, bounded by R = h and V = -speed). Used for pixels whose direction is unreliable (a
    pixel summing ground to the left and right of the track).

    Parameters
    ----------
    range_m : ndarray
        Slant ranges, m.
    radial_velocity_mps : ndarray
        Measured (aliased) radial velocities, m/s.
    own_velocity_ned_mps : ndarray (3,)
        Radar velocity over the ground, NED, m/s.
    own_height_agl_m : float
        Height above the ground directly below, m.
    config : RadarConfig
        Alias period (``2 v_lim_mps``), Doppler and range resolution.
    tolerance_mps : float, optional
        Doppler slack, m/s; default 1.5 Doppler bins.
    terrain_margin_m : float or ndarray
        Allows for ground up to that much higher than the ground directly below, m (it widens the band).

    Returns
    -------
    ndarray of bool

    Examples
    --------
    Flying level at 20 m/s, 500 m up: at 1000 m the ground is 30 deg down or less, so its static
    radial velocity is within ``20 cos 30 deg = 17.3`` m/s (plus the slack); nearer than the
    height less the margin there is no ground:

    >>> from skyradar.config import RadarConfig
    >>> cfg = RadarConfig.prototype_2022()
    >>> rng, v_r = np.array([1000.0, 1000.0, 300.0]), np.array([10.0, 30.0, 0.0])
    >>> in_ground_band(rng, v_r, np.array([20.0, 0.0, 0.0]), 500.0, cfg).tolist()
    [True, False, False]
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
    """Altitude above the terrain (``terrain.height_at`` or a callable) or a flat ground, m (NaN: unknown).

    Parameters
    ----------
    lat_deg, lon_deg : ndarray
        Geodetic position, deg.
    alt_m : ndarray
        Altitude, m (the terrain's datum).
    terrain : Terrain or callable(lat, lon), optional
        Ground height, m, at each position; first choice.
    ground_alt_m : float, optional
        Altitude of a flat ground, m, without ``terrain``.

    Returns
    -------
    ndarray
        Height above the ground, m; NaN without ``terrain`` and ``ground_alt_m``.

    Examples
    --------
    >>> hills = lambda lat, lon: np.full(np.shape(lat), 100.0)  # ground at 100 m
    >>> height_above_ground_m(np.array([52.0]), np.array([4.0]), np.array([600.0]), hills).tolist()
    [500.0]
    >>> float(height_above_ground_m(52.0, 4.0, 600.0, ground_alt_m=50.0))
    550.0
    >>> float(height_above_ground_m(52.0, 4.0, 600.0))  # neither: unknown
    nan
    """
    alt = np.asarray(alt_m, float)
    if terrain is not None:
        height_at: Callable = terrain.height_at if hasattr(terrain, "height_at") else terrain
        return alt - np.asarray(height_at(np.asarray(lat_deg, float), np.asarray(lon_deg, float)), float)
    if ground_alt_m is not None:
        return alt - float(ground_alt_m)
    return np.full(alt.shape, np.nan)


def direction_derivatives(u_ant: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Derivatives of antenna-frame unit vectors (n, 3) with respect to azimuth and elevation, (n, 3) each.

    Examples
    --------
    >>> d_az, d_el = direction_derivatives(np.array([[1.0, 0.0, 0.0]]))
    >>> d_az.tolist(), d_el.tolist()  # boresight: azimuth moves it right, elevation up (-z)
    ([[-0.0, 1.0, 0.0]], [[-0.0, -0.0, -1.0]])
    """
    u = np.asarray(u_ant, float)
    az = np.arctan2(u[:, 1], u[:, 0])
    el = np.arcsin(np.clip(-u[:, 2], -1.0, 1.0))
    d_az = np.stack([-np.cos(el) * np.sin(az), np.cos(el) * np.cos(az), np.zeros_like(az)], axis=1)
    d_el = np.stack([-np.sin(el) * np.cos(az), -np.sin(el) * np.sin(az), -np.cos(el)], axis=1)
    return d_az, d_el


def static_doppler_sd_mps(
    u_ant: np.ndarray,
    sd_az_rad: np.ndarray,
    sd_el_rad: np.ndarray,
    ant_to_ned: np.ndarray,
    own_velocity_ned_mps: np.ndarray,
) -> np.ndarray:
    """Standard deviation of the static radial velocity ``-v . u`` of a direction known to the DoA error, m/s.

    Near the velocity vector (straight ahead in level flight) the static Doppler hardly changes
    with the angle, so the test stays sharp there even at low SNR; abeam it changes fastest.

    Examples
    --------
    >>> ahead = static_doppler_sd_mps(np.array([[1.0, 0, 0]]), 0.05, 0.05, np.eye(3), np.array([50.0, 0, 0]))
    >>> abeam = static_doppler_sd_mps(np.array([[0, 1.0, 0]]), 0.05, 0.05, np.eye(3), np.array([50.0, 0, 0]))
    >>> round(float(ahead[0]), 3), round(float(abeam[0]), 3)
    (0.0, 2.5)
    """
    d_az, d_el = direction_derivatives(u_ant)
    v_ant = np.asarray(ant_to_ned, float).T @ np.asarray(own_velocity_ned_mps, float)
    return np.hypot((d_az @ v_ant) * sd_az_rad, (d_el @ v_ant) * sd_el_rad)


def height_sd_m(
    range_m: np.ndarray,
    sd_az_rad: np.ndarray,
    sd_el_rad: np.ndarray,
    u_ant: np.ndarray,
    ant_to_ned: np.ndarray,
    config: RadarConfig,
    surface_sd_m: float = 10.0,
) -> np.ndarray:
    """Standard deviation of a detection's height above the surface, m.

    The DoA errors (``sd_az_rad``, ``sd_el_rad``, antenna frame) move the point by
    ``R d(u_down)/d(angle)``; the range error (half a bin: straddle) moves it by ``sd_R u_down``;
    ``surface_sd_m`` is the uncertainty of the surface itself (DEM error, relief inside a cell,
    navigation altitude error). ``ant_to_ned`` (3, 3) rotates antenna-frame vectors to NED.

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> u = np.array([[1.0, 0.0, 0.0]])  # boresight, level: only the elevation error moves it vertically
    >>> float(np.round(height_sd_m(np.array([2000.0]), 0.01, 0.01, u, np.eye(3), cfg, 0.0), 1)[0])
    20.0
    """
    u = np.asarray(u_ant, float)
    d_az, d_el = direction_derivatives(u)
    down = np.asarray(ant_to_ned, float)[2]  # NED "down" row: u_down = down . u_ant
    rng = np.asarray(range_m, float)
    sd_range = 0.5 * config.range_resolution_m
    return np.sqrt(
        (rng * (d_az @ down) * sd_az_rad) ** 2
        + (rng * (d_el @ down) * sd_el_rad) ** 2
        + (sd_range * (u @ down)) ** 2
        + surface_sd_m**2
    )


def classify_ground(
    range_m: np.ndarray,
    radial_velocity_mps: np.ndarray,
    direction_ned: np.ndarray,
    config: RadarConfig,
    own_velocity_ned_mps: np.ndarray | None = None,
    height_agl_m: np.ndarray | None = None,
    angle_sd_rad: np.ndarray | float = _ONE_DEG,
    height_margin_m: float = 30.0,
    height_sd: np.ndarray | None = None,
    leakage_bins: float = 2.0,
    doppler_sd: np.ndarray | None = None,
    below_is_ground: np.ndarray | bool = True,
) -> np.ndarray:
    """True for ground returns: on the surface, or in a ground direction at ground Doppler.

    The rule is the module docstring's. ``range_m``, ``radial_velocity_mps`` (aliased) and
    ``height_agl_m`` (:func:`height_above_ground_m`, NaN: unknown) have shape (n,);
    ``direction_ned`` (n, 3) are unit vectors radar -> detection; ``angle_sd_rad`` is the DoA
    error. ``height_sd`` (:func:`height_sd_m`, default ``range * angle_sd_rad``) and
    ``doppler_sd`` (:func:`static_doppler_sd_mps`, default ``speed * angle_sd_rad``) are the
    standard deviations of the height and of the static radial velocity; ``height_margin_m`` is
    the 3-sd height below which the position alone proves ground; ``leakage_bins`` the range
    bins a ground return leaks (window sidelobes, straddle). No height: nothing is ground.
    ``below_is_ground`` (bool or (n,)): a position more than 3 sd below the surface is ground (a
    measured direction: nothing flies there); False where the direction is a hypothesis that
    holds only at the surface (an alias: along it the ground lies nearer than the range).

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> u = np.array([[0.8, 0.0, 0.6], [0.8, 0.0, 0.6], [0.8, 0.0, 0.6]])  # 37 deg down, ahead
    >>> v_static = float(static_radial_velocity_mps(u[:1], np.array([50.0, 0, 0]))[0])
    >>> h = np.array([5.0, 250.0, 5.0])  # on the ground, an aircraft 250 m up, a mover on the ground
    >>> classify_ground(np.full(3, 1000.0), np.array([v_static, v_static, 20.0]), u, cfg,
    ...                 np.array([50.0, 0, 0]), h, height_sd=np.full(3, 8.0)).tolist()
    [True, False, True]
    """
    rng = np.asarray(range_m, float)
    if height_agl_m is None:
        return np.zeros(rng.shape, bool)
    h = np.asarray(height_agl_m, float)
    sd = rng * np.asarray(angle_sd_rad, float) if height_sd is None else np.asarray(height_sd, float)
    u = np.asarray(direction_ned, float)
    z_v = np.full(rng.shape, np.inf)  # Doppler distance from a static point in that direction, in sd
    if own_velocity_ned_mps is not None and np.all(np.isfinite(own_velocity_ned_mps)):
        speed = float(np.linalg.norm(own_velocity_ned_mps))
        expected = static_radial_velocity_mps(u, own_velocity_ned_mps)
        spread = speed * np.asarray(angle_sd_rad, float) if doppler_sd is None else np.asarray(doppler_sd)
        width = 2.0 * config.v_lim_mps
        diff = (np.asarray(radial_velocity_mps, float) - expected + width / 2.0) % width - width / 2.0
        z_v = np.nan_to_num(np.abs(diff) / np.hypot(0.5 * config.doppler_resolution_mps, spread), nan=np.inf)
    with np.errstate(invalid="ignore"):
        leak = leakage_bins * config.range_resolution_m * np.abs(np.nan_to_num(u[:, 2]))
        # Position and Doppler tested jointly: both within 3 sd together (chi-square, 2 dof, 99.73 %),
        # the position allowed to fall short of the surface by the range leakage.
        # Only a measured direction may fall below the surface: along an alias the ground is nearer.
        z_h = np.maximum(h - leak, np.where(below_is_ground, 0.0, np.maximum(-h, 0.0))) / sd
        joint = z_h**2 + z_v**2 <= _CHI2_2DOF_3SD
        conclusive = (h <= 3.0 * sd) & (3.0 * sd <= height_margin_m) & (below_is_ground | (h >= -3.0 * sd))
        below = h < -3.0 * sd
    return np.isfinite(h) & (joint | conclusive | (below & below_is_ground))


def surface_height_fn(
    flat_down_m: float, terrain: Any, geodetic: GeodeticFn | None
) -> Callable[[np.ndarray], np.ndarray]:
    """Height above the surface of NED points (..., 3): the DEM, else a flat ground at ``flat_down_m``.

    ``geodetic`` maps NED points to (lat, lon, alt); beyond the DEM the flat ground is used.

    Examples
    --------
    >>> f = surface_height_fn(1000.0, None, None)
    >>> f(np.array([[0.0, 0.0, 800.0]])).tolist()
    [200.0]
    """

    def height(points: np.ndarray) -> np.ndarray:
        points = np.asarray(points, float)
        flat = flat_down_m - points[..., 2]
        if terrain is None:
            return flat
        assert geodetic is not None  # a terrain is placed through its geodetic mapping
        dem = height_above_ground_m(*geodetic(points), terrain)
        return np.where(np.isfinite(dem), dem, flat)

    return height


def flag_ground(
    out: dict[str, np.ndarray],
    u_ned: np.ndarray,
    own_velocity_ned_mps: np.ndarray,
    ant_to_ned: np.ndarray,
    height_fn: Callable[[np.ndarray], np.ndarray],
    own_height_agl_m: float,
    config: RadarConfig,
    hypothesis: bool = False,
) -> np.ndarray:
    """``is_ground`` of one frame's detections (dict of columns as built by the pipeline).

    Reliable directions: :func:`classify_ground` with each detection's height uncertainty
    (:func:`height_sd_m` from the Cramer-Rao bound at its SNR, floored for attitude and
    calibration errors). Unreliable ones (outside the field of view, or one plane wave explaining
    the pixel badly: ground left and right of the track in one cell, or an aircraft mixed with
    ground) are ground only when the ground can produce their range and Doppler
    (:func:`in_ground_band`) AND their elevation points at the surface for some azimuth
    (:func:`ground_in_elevation`): an aircraft mixed with ground pulls the elevation up and is kept.
    Near the end-fire of a baseline (direction cosine above sin 45 deg) the mirrored direction is
    tested too: the phase step is near +-pi there, and the ground straight below (the altitude
    return) is otherwise read as a direction above the aircraft; read so, it is ground when its
    range and Doppler are the ground's within the DoA's cone around the nadir. A time-division
    MIMO radar's direction is tested too as each wrong residue would have shifted it
    (:func:`skyradar.process.mimo.residue_shifts`): for ``mimo-2x4`` the other residue reads the
    altitude return near the boresight, a level target a few hundred metres ahead.

    Parameters
    ----------
    out : dict of ndarray
        The frame's detection columns: ``range_m`` (m), ``snr_db`` (dB), ``azimuth_rad`` and
        ``elevation_rad`` (antenna frame, rad), ``north_m``, ``east_m``, ``down_m`` (NED
        position, m), ``radial_velocity_mps`` (aliased, m/s), ``u_ant`` (n, 3), ``coherence`` and
        optionally ``elevation_measured`` (bool).
    u_ned : ndarray (n, 3)
        The detections' unit directions, NED.
    own_velocity_ned_mps : ndarray (3,)
        Radar velocity over the ground, m/s.
    ant_to_ned : ndarray (3, 3)
        Rotation of antenna-frame vectors into NED.
    height_fn : callable
        Height above the surface of NED points (..., 3), m (:func:`surface_height_fn`).
    own_height_agl_m : float
        Height above the ground directly below, m.
    config : RadarConfig
        Antenna positions and pattern (DoA bound, field of view), Doppler and range axes.
    hypothesis : bool
        The directions are hypotheses, not measurements (a MIMO detection's runner-up residue):
        a position below the surface along them, or along their aliases, is not ground, because
        the ground along such a direction lies nearer than the detection.

    Returns
    -------
    ndarray of bool (n,)
        ``is_ground``.

    Examples
    --------
    Flying north at 50 m/s, level, 500 m over flat ground (antenna frame = NED): a detection at
    1000 m, 30 deg down, lies on the ground, and with the static Doppler there,
    ``-50 cos 30 deg = -43.3`` m/s, it is ground; one level 10 deg right, closing at 20 m/s, is not:

    >>> from skyradar.config import RadarConfig
    >>> from skyradar.process.doa import direction_from_angles
    >>> cfg = RadarConfig.prototype_2022()
    >>> az, el, rng = np.radians([0.0, 10.0]), np.radians([-30.0, 0.0]), np.array([1000.0, 1000.0])
    >>> u = direction_from_angles(az, el)
    >>> north, east, down = (rng[:, None] * u).T
    >>> out = {"range_m": rng, "snr_db": np.full(2, 25.0), "azimuth_rad": az, "elevation_rad": el,
    ...        "north_m": north, "east_m": east, "down_m": down, "u_ant": u, "coherence": np.ones(2),
    ...        "radial_velocity_mps": np.array([-43.3, -20.0])}
    >>> surface = surface_height_fn(500.0, None, None)
    >>> flag_ground(out, u, np.array([50.0, 0.0, 0.0]), np.eye(3), surface, 500.0, cfg)
    array([ True, False])
    """
    from skyradar.process.calibration import in_field_of_view
    from skyradar.process.doa import doa_crlb

    rng = np.asarray(out["range_m"], float)
    if rng.size == 0:
        return np.zeros(0, bool)
    sd_az, sd_el = doa_crlb(out["snr_db"], out["azimuth_rad"], out["elevation_rad"], config)
    sd_az, sd_el = (np.clip(np.nan_to_num(s, nan=0.2), ANGLE_FLOOR_RAD, 0.2) for s in (sd_az, sd_el))
    points = np.stack([out["north_m"], out["east_m"], out["down_m"]], axis=1)
    antenna = points[0] - rng[0] * u_ned[0]
    v_r, u_ant = out["radial_velocity_mps"], np.asarray(out["u_ant"], float)
    unreliable = ~in_field_of_view(out["azimuth_rad"], out["elevation_rad"], config, 12.0)
    unreliable |= out["coherence"] < 0.5
    # Every surface height this frame asks for, in one call of height_fn: over a DEM each call
    # converts its points to geodetic and looks them up, a fixed cost larger than the points'.
    el = np.asarray(out["elevation_rad"], float)[unreliable]
    u_alias, alias_row, alias_below = _alias_directions(u_ant, config, np.maximum(sd_az, sd_el))
    aliases = (u_alias, alias_row, alias_below & (not hypothesis))
    queries = _surface_queries(u_ant, rng, unreliable, el, antenna, ant_to_ned, aliases)
    heights = _Prefetched(height_fn, queries)
    args = (antenna, ant_to_ned, heights, own_velocity_ned_mps, config)
    ground = _ground_along(u_ant, rng, v_r, sd_az, sd_el, *args, not hypothesis)
    # Over relief, ground beside the track can be nearer than the ground below: widen the band by
    # the terrain's rise around the radar (zero over flat ground, where the fixed margin stays).
    margin_m = np.full(rng.shape, TERRAIN_MARGIN_M)
    if unreliable.any():
        margin_m[unreliable] += terrain_rise_m(heights, antenna, rng[unreliable])
    band = in_ground_band(rng, v_r, own_velocity_ned_mps, own_height_agl_m, config, terrain_margin_m=margin_m)
    mirrored = _mirrored_ground(aliases, rng, v_r, sd_az, sd_el, band, own_height_agl_m, args)
    ground |= mirrored
    sel = unreliable & band
    hit = sel & mirrored
    if sel.any():
        # Tested for every unreliable detection (the heights fetched above), kept where selected:
        # each detection's test depends on its own row only.
        margin = 3.0 * np.hypot(rng[unreliable] * sd_el[unreliable], SURFACE_SD_M)
        tested = ground_in_elevation(rng[unreliable], el, heights, antenna, ant_to_ned, margin)
        hit[sel] |= tested[sel[unreliable]]
    # An elevation the nulls left unobservable is a prior (elevation 0), not a measurement: such a
    # detection is ground here by the mirror rule, or when it lies in the altitude ring and its
    # azimuth cone meets that ring where the ground has its Doppler; its track's history decides
    # the rest.
    measured = np.asarray(out.get("elevation_measured", np.ones(rng.size, bool)), bool)
    ring = np.zeros(rng.shape, bool)
    if not measured.all():
        free = ~measured
        ring[free] = _ring_ground(u_ant[free], rng[free], v_r[free], sd_az[free], own_height_agl_m, args)
    return np.where(measured, np.where(unreliable, hit, ground), mirrored | ring)


def _ring_ground(u_ant, rng, v_r, sd_az, own_agl_m, args) -> np.ndarray:
    """Detections of unmeasured elevation that the altitude ring explains.

    The ground nearest the radar lies straight below; at a range ``R`` just beyond the height
    ``h`` it forms a ring at the angle ``acos(h / R)`` around the nadir, seen at near-normal
    incidence (the strongest ground of the frame) through the sidelobes at every azimuth and
    either side of the array's plane. A detection whose elevation the nulls left unmeasured lies
    somewhere on the cone of its measured horizontal direction cosine ``c``. On that cone,
    ``u = (sqrt(1 - c^2) cos t, c, sqrt(1 - c^2) sin t)`` (antenna frame), a static point's radial
    velocity ``-v . u`` equals the detection's (any alias) at two angles ``t`` in closed form; the
    flat ground ``h`` below lies along each at the range ``h / (u . down)``. Within the altitude
    return's leak plus one range cell of the height, the detection is ground when one of those
    ranges is its own within the leak and half a cell and the surface is there
    (:func:`classify_ground` at that point, which also allows the cone's azimuth uncertainty).
    Farther out a detection's unmeasured elevation is left to its track: there an aircraft in a
    ground cell is as likely.
    """
    antenna, ant_to_ned, heights, vel, config = args
    cell = config.range_resolution_m
    reach_m = _ALTITUDE_LEAK_BINS * cell + 0.5 * cell
    ground = np.zeros(rng.shape, bool)
    near = np.flatnonzero(rng <= own_agl_m + reach_m + 0.5 * cell)
    if not near.size or not np.isfinite(own_agl_m) or own_agl_m <= 0.0 or not np.all(np.isfinite(vel)):
        return ground
    rotation = np.asarray(ant_to_ned, float)
    down_axis = rotation[2]  # the NED down axis in the antenna frame
    v_ant = rotation.T @ np.asarray(vel, float)
    across = np.clip(u_ant[near, 1], -1.0, 1.0)
    radius = np.sqrt(1.0 - across**2)
    a, b = v_ant[0] * radius, v_ant[2] * radius
    amplitude = np.maximum(np.hypot(a, b), 1e-12)
    width = 2.0 * config.v_lim_mps
    n_alias = int(np.ceil(np.linalg.norm(vel) / width)) + 1
    directions, rows, ranges = [], [], []
    for k in range(-n_alias, n_alias + 1):
        needed = -(v_r[near] + k * width) - v_ant[1] * across  # = a cos t + b sin t
        ratio = needed / amplitude
        meets = np.abs(ratio) <= 1.0
        spread = np.arccos(np.clip(ratio, -1.0, 1.0))
        for side in (-1.0, 1.0):
            t = np.arctan2(b, a) + side * spread
            u = np.column_stack([radius * np.cos(t), across, radius * np.sin(t)])
            down = u @ down_axis
            with np.errstate(divide="ignore", invalid="ignore"):
                r_ground = own_agl_m / down
            ok = meets & (down > 0.0) & (np.abs(r_ground - rng[near]) <= reach_m)
            directions.append(u[ok])
            rows.append(near[ok])
            ranges.append(r_ground[ok])
    row = np.concatenate(rows)
    if not row.size:
        return ground
    sd = sd_az[row]  # the cone's; the ring sets the rest of the direction
    u_ring, r_ring = np.concatenate(directions), np.concatenate(ranges)
    hit = _ground_along(
        u_ring, r_ring, v_r[row], sd, sd, antenna, ant_to_ned, heights, vel, config, below=False
    )
    np.logical_or.at(ground, row, hit)
    return ground


def _mirrored_ground(aliases, rng, v_r, sd_az, sd_el, band, own_agl_m, args) -> np.ndarray:
    """Ground read through the other directions the array reads as the detections' (aliases).

    Near the end-fire of a baseline the phase step is close to +-pi and noise flips its sign, so
    the mirrored direction is as plausible: the ground straight below read as straight above; a
    time-division MIMO radar's wrong residue reads the ground below near the boresight. The return
    of the ground below (the altitude return, the strongest of all: normal incidence at the shortest
    range) is ground when its range and Doppler are in the ground band and its range is one that
    ground within the DoA's 3-sd cone around that direction can have: at the pole the linearised
    Doppler error of :func:`classify_ground` vanishes, though every direction of that cone is as
    likely.
    """
    antenna, ant_to_ned, heights, vel, config = args
    u_alias, row, measured_below = aliases
    mirrored = np.zeros(rng.shape, bool)
    if not row.size:
        return mirrored
    r, sa, se = rng[row], sd_az[row], sd_el[row]
    hit = _ground_along(
        u_alias, r, v_r[row], sa, se, antenna, ant_to_ned, heights, vel, config, measured_below
    )
    cone_cos = np.cos(3.0 * np.maximum(sa, se))
    leak = _ALTITUDE_LEAK_BINS * config.range_resolution_m
    down = (u_alias @ np.asarray(ant_to_ned, float).T)[:, 2]
    with np.errstate(invalid="ignore"):
        hit |= band[row] & (down >= cone_cos) & (r * cone_cos <= own_agl_m + leak)
    np.logical_or.at(mirrored, row, hit)
    return mirrored


def _alias_directions(
    u_ant: np.ndarray, config: RadarConfig, sd_rad: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The other directions (m, 3) the array reads as detections' directions ``u_ant``, the
    detection row (m,) of each, and whether a position below the surface along it is ground (m,).

    The end-fire mirror: direction cosines beyond sin 45 deg with their sign flipped (a phase
    step near +-pi). A time-division MIMO radar's residue shifts
    (:func:`skyradar.process.mimo.residue_shifts`): the direction cosines across the array moved
    by each shift, where they stay inside the unit circle within 3 DoA sd (``sd_rad``, rad; the
    ground below read slightly beyond it is brought back onto it), the forward component's sign
    kept; a residue's direction is ground only at the surface (below it, the ground along that
    direction is nearer than the detection, which the other residue then does not explain).
    """
    from skyradar.process.mimo import residue_shifts

    mirror = u_ant.copy()
    mirror[:, 1:] *= np.where(np.abs(u_ant[:, 1:]) > _ENDFIRE_COSINE, -1.0, 1.0)
    changed = np.flatnonzero(np.any(mirror != u_ant, axis=1))
    directions, rows = [mirror[changed]], [changed]
    for shift in residue_shifts(config):
        across = u_ant[:, 1:] + shift[1:]
        norm = np.linalg.norm(across, axis=1)
        with np.errstate(invalid="ignore"):
            inside = np.flatnonzero(norm <= 1.0 + 3.0 * sd_rad)
        across = across[inside] / np.maximum(norm[inside], 1.0)[:, None]
        rest = np.maximum(1.0 - np.sum(across**2, axis=1), 0.0)
        forward = np.where(u_ant[inside, 0] < 0.0, -1.0, 1.0) * np.sqrt(rest)
        directions.append(np.column_stack([forward, across]))
        rows.append(inside)
    below = np.concatenate([np.full(len(r), k == 0) for k, r in enumerate(rows)])
    return np.concatenate(directions), np.concatenate(rows), below


def _along_points(
    u_ant: np.ndarray, rng: np.ndarray, antenna: np.ndarray, ant_to_ned: np.ndarray
) -> np.ndarray:
    """NED points (n, 3) at ``rng`` along antenna-frame directions ``u_ant`` from the antenna."""
    return antenna + rng[:, None] * (u_ant @ np.asarray(ant_to_ned, float).T)


def _surface_queries(u_ant, rng, unreliable, el, antenna, ant_to_ned, aliases) -> list[np.ndarray]:
    """The point sets :func:`flag_ground` asks the surface height of, built as its steps build them."""
    u_alias, row, _ = aliases
    queries = [_along_points(u_ant, rng, antenna, ant_to_ned)]
    if row.size:
        queries.append(_along_points(u_alias, rng[row], antenna, ant_to_ned))
    if unreliable.any():
        queries.append(antenna[None])
        queries.append(rise_points(antenna, rng[unreliable])[1])
        queries.append(elevation_points(rng[unreliable], el, antenna, ant_to_ned))
    return queries


class _Prefetched:
    """A surface height function evaluated once on several point sets together.

    Asked for one of those sets (the same shape and values, bit for bit) it returns that set's
    heights; any other points go to the function itself. The heights are the same as separate
    calls give: the height of a point depends on that point alone (elementwise geodetic
    conversion and DEM interpolation, :func:`surface_height_fn`).
    """

    def __init__(self, height_fn: Callable[[np.ndarray], np.ndarray], queries: list[np.ndarray]):
        self._fn = height_fn
        flat = [np.asarray(q, float).reshape(-1, 3) for q in queries]
        values = np.asarray(height_fn(np.concatenate(flat)), float)
        ends = np.cumsum([len(f) for f in flat])[:-1]
        self._sets = [
            (np.asarray(q, float), v.reshape(np.shape(q)[:-1]))
            for q, v in zip(queries, np.split(values, ends), strict=True)
        ]

    def __call__(self, points: np.ndarray) -> np.ndarray:
        points = np.asarray(points, float)
        for query, values in self._sets:
            if query.shape == points.shape and query.tobytes() == points.tobytes():
                return values.copy()
        return self._fn(points)


def _ground_along(
    u_ant, rng, v_r, sd_az, sd_el, antenna, ant_to_ned, height_fn, vel, config, below=True
) -> np.ndarray:
    """:func:`classify_ground` of detections at ``rng`` along antenna-frame directions ``u_ant``."""
    u_ned = u_ant @ np.asarray(ant_to_ned, float).T
    h = height_fn(antenna + rng[:, None] * u_ned)
    sd_h = height_sd_m(rng, sd_az, sd_el, u_ant, ant_to_ned, config, SURFACE_SD_M)
    sd_v = static_doppler_sd_mps(u_ant, sd_az, sd_el, ant_to_ned, vel)
    sigma = np.maximum(sd_az, sd_el)
    return classify_ground(
        rng, v_r, u_ned, config, vel, h, sigma, height_sd=sd_h, doppler_sd=sd_v, below_is_ground=below
    )
