"""A static point seen from a moving own-ship: its range and Doppler history, and a fit on the ground.

For a point ``P`` seen from ``o(t)`` moving at ``v(t)``: ``r = |P - o|``, ``dr/dt = -(P - o) . v / r``,
apparent range ``r + c dr/dt`` (range-Doppler coupling ``c``), Doppler modulo the image width.
:func:`fits_static_ground` asks whether one point on the surface explains a detection history
(used by :mod:`skyradar.track.ground_tracks`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from skyradar.quantiles import chi2_upper_quantile
from skyradar.units import wrap

__all__ = [
    "static_point_measurements",
    "fits_static_ground",
    "static_ground_points",
    "flat_surface",
    "terrain_surface",
]

_EARTH_RADIUS_M = 6_371_000.0


def flat_surface(down_m: float) -> Callable[[np.ndarray], np.ndarray]:
    """Surface function (NE points (k, 2) -> surface ``down`` (k,), m) of a level ground.

    Examples
    --------
    >>> flat_surface(300.0)(np.zeros((2, 2))).tolist()
    [300.0, 300.0]
    """
    return lambda ne: np.full(np.asarray(ne).shape[0], float(down_m))


def static_point_measurements(
    point_ned: np.ndarray, own_position_m: np.ndarray, own_velocity_mps: np.ndarray, coupling_s: float
) -> tuple[np.ndarray, np.ndarray]:
    """Apparent range ``r + c dr/dt`` (m) and radial velocity ``dr/dt`` (m/s) of static points.

    ``point_ned`` (3,) or (k, 3), own-ship positions and velocities (k, 3), NED.

    Examples
    --------
    >>> rho, v = static_point_measurements(np.array([1000.0, 0, 0]), np.zeros((1, 3)),
    ...                                    np.array([[50.0, 0, 0]]), 0.2)
    >>> float(rho[0]), float(v[0])
    (990.0, -50.0)
    """
    d = np.asarray(point_ned, float) - np.asarray(own_position_m, float)
    r = np.linalg.norm(d, axis=-1)
    v = -np.sum(d * np.asarray(own_velocity_mps, float), axis=-1) / np.maximum(r, 1e-9)
    return r + coupling_s * v, v


def trimmed_sum(z2: np.ndarray, trim: float) -> tuple[float, int]:
    """Sum of the smallest ``1 - trim`` of the squared normalised residuals, and how many."""
    keep = z2.size - int(np.floor(trim * z2.size))
    return float(np.sum(np.partition(z2, keep - 1)[:keep])), keep


def _ring_candidates(rng, vel, own_p, own_v, width, coupling, surface_down, n_phi: int = 90) -> np.ndarray:
    """NE points of the surface with one detection's range and (aliased) static Doppler, (m, 2).

    A static point with radial velocity ``V`` lies on the cone ``-u . v = V`` around the velocity;
    at range ``r`` that is a ring, which meets the surface where its height above it changes sign.
    A ring that misses the surface (near the velocity axis the ring is small, and one detection's
    Doppler error changes its radius by tens of metres) gives its point nearest to it.
    """
    speed = float(np.linalg.norm(own_v))
    if speed < 1.0:
        return np.zeros((0, 2))
    axis = own_v / speed
    e1 = np.cross(axis, [0.0, 0.0, 1.0] if abs(axis[2]) < 0.9 else [1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(axis, e1)
    phi = np.linspace(0.0, 2.0 * np.pi, n_phi, endpoint=False)
    ring = np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2
    out = []
    for k in range(-int(np.ceil(2 * speed / width)) - 1, int(np.ceil(2 * speed / width)) + 2):
        v_true = vel + k * width
        if abs(v_true) > speed:
            continue
        cos_a = -v_true / speed
        points = own_p + (rng - coupling * v_true) * (cos_a * axis + np.sqrt(1.0 - cos_a**2) * ring)
        above = surface_down(points[:, :2]) - points[:, 2]
        nxt = np.roll(above, -1)
        crossing = np.flatnonzero(np.isfinite(above) & np.isfinite(nxt) & ((above > 0) != (nxt > 0)))
        for i in crossing:
            f = above[i] / (above[i] - nxt[i])
            j = (i + 1) % n_phi
            out.append(points[i, :2] + f * (points[j, :2] - points[i, :2]))
        if crossing.size == 0 and np.isfinite(above).any():  # the ring misses it by its errors
            out.append(points[np.nanargmin(np.abs(above)), :2])
    return np.array(out).reshape(-1, 2)


def fits_static_ground(
    range_m: np.ndarray,
    radial_velocity_mps: np.ndarray,
    own_position_m: np.ndarray,
    own_velocity_mps: np.ndarray,
    surface_down: Callable[[np.ndarray], np.ndarray],
    width_mps: float,
    coupling_s: float,
    sigma_range_m: float = 8.0,
    sigma_velocity_mps: float = 0.25,
    tail: float = 1e-3,
    trim: float = 0.1,
) -> bool:
    """Whether one static point on the surface explains a detection history (chi-square test).

    ``range_m`` (apparent) and ``radial_velocity_mps`` (aliased, modulo ``width_mps``) of the
    detections, the own-ship's NED position and velocity (k, 3) at their times, and the
    surface's ``down`` at NE points (:func:`flat_surface`); :func:`static_ground_points` finds the
    points. ``sigma_*``: one detection's errors; ``tail``: the chi-square test's false-rejection
    probability; ``trim``: fraction of worst-fitting detections left out (another scatterer of the
    same clutter patch, a noise hit in the gate).

    Examples
    --------
    >>> t = np.arange(30) * 0.1
    >>> own = np.column_stack([50.0 * t, 0 * t, 0 * t]); vel = np.tile([50.0, 0, 0], (30, 1))
    >>> P = np.array([2000.0, 800.0, 500.0])  # a point on flat ground 500 m below
    >>> rho, v = static_point_measurements(P, own, vel, 0.19)
    >>> fits_static_ground(rho, v, own, vel, flat_surface(500.0), 78.3, 0.19)
    True
    >>> fits_static_ground(rho - 2.0 * t * 10, v, own, vel, flat_surface(500.0), 78.3, 0.19)  # 20 m/s off
    False
    """
    points = static_ground_points(
        range_m,
        radial_velocity_mps,
        own_position_m,
        own_velocity_mps,
        surface_down,
        width_mps,
        coupling_s,
        sigma_range_m,
        sigma_velocity_mps,
        tail,
        trim,
    )
    return len(points) > 0


def static_ground_points(
    range_m: np.ndarray,
    radial_velocity_mps: np.ndarray,
    own_position_m: np.ndarray,
    own_velocity_mps: np.ndarray,
    surface_down: Callable[[np.ndarray], np.ndarray],
    width_mps: float,
    coupling_s: float,
    sigma_range_m: float = 8.0,
    sigma_velocity_mps: float = 0.25,
    tail: float = 1e-3,
    trim: float = 0.1,
) -> np.ndarray:
    """The static points on the surface that explain a detection history, NED (m, 3), m.

    Arguments as :func:`fits_static_ground`. The points start where the newest, the middle and the
    oldest detection's ring meets the surface (:func:`_ring_candidates`) and move on the surface by
    Gauss-Newton steps; those whose trimmed chi-square passes the test are returned (several: the
    rings meet the surface left and right of the own-ship's track, and one minimum may be reached
    from several starts). None: no static point explains the history.

    Examples
    --------
    >>> t = np.arange(30) * 0.1
    >>> own = np.column_stack([50.0 * t, 0 * t, 0 * t]); vel = np.tile([50.0, 0, 0], (30, 1))
    >>> rho, v = static_point_measurements(np.array([2000.0, 800.0, 500.0]), own, vel, 0.19)
    >>> points = static_ground_points(rho, v, own, vel, flat_surface(500.0), 78.3, 0.19)
    >>> np.unique(points.round(), axis=0).tolist()  # in level flight its mirror has its history too
    [[2000.0, -800.0, 500.0], [2000.0, 800.0, 500.0]]
    """
    rng, vel = np.asarray(range_m, float), np.asarray(radial_velocity_mps, float)
    own_p, own_v = np.asarray(own_position_m, float), np.asarray(own_velocity_mps, float)
    n = rng.size
    starts = [
        _ring_candidates(rng[i], vel[i], own_p[i], own_v[i], width_mps, coupling_s, surface_down)
        for i in sorted({n - 1, n // 2, 0})
    ]
    candidates = np.concatenate(starts) if starts else np.zeros((0, 2))
    if candidates.size == 0:
        return np.zeros((0, 3))
    sig = np.array([sigma_range_m, sigma_velocity_mps])

    def residuals(ne: np.ndarray) -> np.ndarray:  # (m, 2) candidates -> (m, 2n) normalised residuals
        points = np.column_stack([ne, surface_down(ne)])
        rho, v = static_point_measurements(points[:, None, :], own_p, own_v, coupling_s)
        return np.concatenate([(rng - rho) / sig[0], wrap(vel - v, width_mps) / sig[1]], axis=1)

    ne, cost, keep = _gauss_newton(residuals, candidates, n, trim)
    fit = ne[cost <= chi2_upper_quantile(tail, 2 * keep - 2)]
    return np.column_stack([fit, surface_down(fit)]) if len(fit) else np.zeros((0, 3))


def _kept_rows(z2: np.ndarray, trim: float) -> np.ndarray:
    """Rows (last axis) of the smallest ``1 - trim`` of the squared normalised residuals."""
    keep = z2.shape[-1] - int(np.floor(trim * z2.shape[-1]))
    return z2 <= np.partition(z2, keep - 1, axis=-1)[..., keep - 1 : keep]


def _gauss_newton(residuals: Callable, ne: np.ndarray, n: int, trim: float, steps: int = 8) -> tuple:
    """Trimmed least squares of static points' NE positions from several starts at once.

    ``residuals(ne)`` maps (m, 2) starts to (m, 2n) normalised residuals (the ``n`` detections'
    ranges, then their Doppler); the Jacobian is taken by 1 m differences (the surface may be a
    DEM). Levenberg-Marquardt: a start moves only when its trimmed chi-square drops, else its
    damping grows. Plain Gauss-Newton steps overshoot along the fit's long valley (the point
    slides along the iso-range, iso-Doppler line with little change) and over a DEM's kinks,
    and miss minima well inside the test's limit.
    Returns the points reached (m, 2), each one's trimmed chi-square (m,) and the number of
    detections kept.
    """
    ne = np.asarray(ne, float).copy()
    keep = n - int(np.floor(trim * n))
    cost, e = _trimmed_cost(residuals(ne), n, keep)
    damping = np.full(len(ne), 1e-3)
    for _ in range(steps):
        w = np.tile(_kept_rows(e[:, :n] ** 2 + e[:, n:] ** 2, trim), 2) & np.isfinite(e)
        e0 = np.where(w, e, 0.0)
        J = np.stack([np.where(w, residuals(ne + d), 0.0) - e0 for d in np.eye(2)], axis=-1)  # (m, 2n, 2)
        JTJ = np.einsum("mki,mkj->mij", J, J)
        diag = np.einsum("mii->mi", JTJ)
        lhs = JTJ + (damping[:, None] * np.maximum(diag, 1e-9))[..., None] * np.eye(2)
        step = np.linalg.solve(lhs, -np.einsum("mki,mk->mi", J, e0)[..., None])[..., 0]
        trial = ne + np.clip(np.nan_to_num(step), -500.0, 500.0)
        trial_cost, trial_e = _trimmed_cost(residuals(trial), n, keep)
        better = trial_cost < cost
        ne[better], e[better], cost[better] = trial[better], trial_e[better], trial_cost[better]
        damping = np.where(better, damping / 3.0, damping * 4.0)
    return ne, cost, keep


def _trimmed_cost(e: np.ndarray, n: int, keep: int) -> tuple[np.ndarray, np.ndarray]:
    """Each row's sum of its ``keep`` smallest squared detection residuals (non-finite: inf), and ``e``."""
    z2 = np.where(np.isfinite(e[:, :n] + e[:, n:]), e[:, :n] ** 2 + e[:, n:] ** 2, np.inf)
    return np.sum(np.partition(z2, keep - 1, axis=1)[:, :keep], axis=1), e


def terrain_surface(terrain, origin: tuple[float, float, float], flat_down_m: float) -> Callable:
    """Surface function (NE points (k, 2) -> ``down`` of the surface, m) of a DEM seen from a
    scenario ``origin`` (lat, lon, alt); a level ground at ``flat_down_m`` beyond the DEM.

    The fit calls it thousands of times with a few points, so the NED-to-geodetic conversion is
    linearised at the origin (degrees per metre north and east, and the Earth's curvature dropping
    the surface by ``(n^2 + e^2) / 2R``): under 0.1 m off at 15 km.

    Parameters
    ----------
    terrain : object
        A DEM with ``height_at(lat_deg, lon_deg)`` giving the height above the ellipsoid, m (NaN
        outside it).
    origin : (float, float, float)
        Latitude (deg), longitude (deg) and altitude (m) of the NED origin.
    flat_down_m : float
        ``down`` of the level ground beyond the DEM, m.

    Returns
    -------
    callable
        NE points (k, 2) in m -> ``down`` of the surface, m, shape (k,).

    Examples
    --------
    A DEM 200 m high up to 52.01 deg north under an origin at 1000 m: 800 m down under the origin,
    the level ground beyond the DEM's edge, and the curvature's ``(10 km)^2 / 2R = 7.85`` m drop at 10 km
    east:

    >>> class Dem:
    ...     def height_at(self, lat, lon):
    ...         return np.where(np.asarray(lat) < 52.01, 200.0, np.nan)
    >>> surface = terrain_surface(Dem(), (52.0, 4.0, 1000.0), 900.0)
    >>> surface(np.array([[0.0, 0.0], [5000.0, 0.0], [0.0, 10000.0]])).round(2).tolist()
    [800.0, 900.0, 807.85]
    """
    from skyradar.geo import ned_to_geodetic

    probe = np.array([[0.0, 0.0, 0.0], [1e3, 0.0, 0.0], [0.0, 1e3, 0.0]])
    lat, lon, _ = (np.asarray(v, float) for v in ned_to_geodetic(probe, *origin))
    per_m = np.array([(lat[1] - lat[0]) / 1e3, (lon[2] - lon[0]) / 1e3])

    def surface_down(ne: np.ndarray) -> np.ndarray:
        ne = np.asarray(ne, float).reshape(-1, 2)
        curvature = np.sum(ne**2, axis=1) / (2.0 * _EARTH_RADIUS_M)
        h = np.asarray(terrain.height_at(lat[0] + ne[:, 0] * per_m[0], lon[0] + ne[:, 1] * per_m[1]), float)
        down = origin[2] - h + curvature
        return np.where(np.isfinite(down), down, flat_down_m)

    return surface_down
