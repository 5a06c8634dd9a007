"""Tracks the ground explains are held back from confirmation: a track-level ground test.

A detection's direction can be wrong (sidelobe ground, ground left and right of the track in one
cell, the residual of clutter suppression), but its range and Doppler are measured to a pixel, and
the own-ship's motion fixes the range and Doppler history of every static point: for a point ``P``
seen from ``o(t)`` moving at ``v(t)``, ``r = |P - o|`` and ``dr/dt = -(P - o) . v / r`` (the
apparent range is ``r + c dr/dt``, range-Doppler coupling ``c``). A track is *ground* while a
single static point on the surface explains its whole history of detections (range, and Doppler
modulo the image width ``2 VLim``) within the measurement errors (:func:`fits_static_ground`),
whatever its DoA said. A track is *not an object* while its ranges contradict its Doppler: for
every real scatterer ``dr/dt`` is its (de-aliased) radial velocity (:func:`range_doppler_consistent`);
residual clutter hopping between cells fails this.

Why aircraft are kept: in straight flight the history of a point moving at relative velocity
``w`` has ``d(r dr/dt)/dt = |w|^2``, a static point's ``|v|^2``; so an aircraft fits a static
point only while its relative speed equals the own-ship's speed, and then that point lies at its
miss distance from the own-ship's line of flight: it can be ground only when that miss distance
reaches the terrain (a conflict's miss distance is smaller than the height above ground unless
the own-ship is very low). A circling aircraft's ``w`` turns and fits no static point. The price
is time: an aircraft inside the ground's range-Doppler band is held until its history departs
from a static point's (seconds when ``|w|`` differs from the own-ship's speed by a few m/s).

:func:`hold_ground_tracks` applies both tests causally (a row uses only the detections up to it)
to a tracks table: rows of a track while the ground explains it, or while it is not an object,
are not ``confirmed``; a track never confirmed is dropped, like a tentative track.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.stats import chi2

_EARTH_RADIUS_M = 6_371_000.0
_CLEAR_S = 3.0  # judged an object off the ground this long on end: not judged again

__all__ = [
    "GroundTrackTest",
    "static_point_measurements",
    "fits_static_ground",
    "range_doppler_consistent",
    "hold_ground_tracks",
    "flat_surface",
    "terrain_surface",
]


@dataclass(frozen=True)
class GroundTrackTest:
    """Settings of the track-level ground test.

    Parameters
    ----------
    sigma_range_m, sigma_velocity_mps : float
        Errors of one detection's range (half a 15 m bin: straddle, window sidelobes, own-ship
        position) and radial velocity (half a Doppler bin and the own-ship's velocity error).
    tail : float
        False-rejection probability of each chi-square test.
    trim : float
        Fraction of the worst-fitting detections left out of each fit (another scatterer of the
        same clutter patch, a noise hit in the gate).
    min_detections : int
        Detections of a track in the table (its first one starts it and is not there) before it
        can be judged; fewer: held.
    max_history : int
        The most recent detections a fit uses.
    surface_down : callable, optional
        NE points (k, 2) -> ``down`` of the ground surface, m (:func:`terrain_surface`); default:
        a level ground at the own-ship's ``own_height_agl_m``.
    """

    sigma_range_m: float = 8.0
    sigma_velocity_mps: float = 0.35
    tail: float = 1e-3
    trim: float = 0.1
    min_detections: int = 3
    max_history: int = 120
    surface_down: Callable[[np.ndarray], np.ndarray] | None = None


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


def _wrap(x: np.ndarray, width: float) -> np.ndarray:
    return (x + width / 2.0) % width - width / 2.0


def _trimmed_sum(z2: np.ndarray, trim: float) -> tuple[float, int]:
    """Sum of the smallest ``1 - trim`` of the squared normalised residuals, and how many."""
    keep = z2.size - int(np.floor(trim * z2.size))
    return float(np.sum(np.partition(z2, keep - 1)[:keep])), keep


def _ring_candidates(rng, vel, own_p, own_v, width, coupling, surface_down, n_phi: int = 90) -> np.ndarray:
    """NE points of the surface with one detection's range and (aliased) static Doppler, (m, 2).

    A static point with radial velocity ``V`` lies on the cone ``-u . v = V`` around the velocity;
    at range ``r`` that is a ring, which meets the surface where its height above it changes sign.
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
        for i in np.flatnonzero(np.isfinite(above) & np.isfinite(nxt) & ((above > 0) != (nxt > 0))):
            f = above[i] / (above[i] - nxt[i])
            j = (i + 1) % n_phi
            out.append(points[i, :2] + f * (points[j, :2] - points[i, :2]))
    return np.array(out).reshape(-1, 2)


def fits_static_ground(
    range_m: np.ndarray,
    radial_velocity_mps: np.ndarray,
    own_position_m: np.ndarray,
    own_velocity_mps: np.ndarray,
    surface_down: Callable[[np.ndarray], np.ndarray],
    width_mps: float,
    coupling_s: float,
    test: GroundTrackTest | None = None,
) -> bool:
    """Whether one static point on the surface explains a detection history (chi-square test).

    ``range_m`` (apparent) and ``radial_velocity_mps`` (aliased, modulo ``width_mps``) of the
    detections, the own-ship's NED position and velocity (k, 3) at their times, and the
    surface's ``down`` at NE points (:func:`flat_surface`). The point starts where the newest,
    the middle and the oldest detection's ring meets the surface (:func:`_ring_candidates`) and
    moves on the surface by Gauss-Newton steps.

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
    test = test or GroundTrackTest()
    rng, vel = np.asarray(range_m, float), np.asarray(radial_velocity_mps, float)
    own_p, own_v = np.asarray(own_position_m, float), np.asarray(own_velocity_mps, float)
    n = rng.size
    starts = [
        _ring_candidates(rng[i], vel[i], own_p[i], own_v[i], width_mps, coupling_s, surface_down)
        for i in sorted({n - 1, n // 2, 0})
    ]
    candidates = np.concatenate(starts) if starts else np.zeros((0, 2))
    if candidates.size == 0:
        return False
    sig = np.array([test.sigma_range_m, test.sigma_velocity_mps])

    def residuals(ne: np.ndarray) -> np.ndarray:  # (m, 2) candidates -> (m, 2n) normalised residuals
        points = np.column_stack([ne, surface_down(ne)])
        rho, v = static_point_measurements(points[:, None, :], own_p, own_v, coupling_s)
        return np.concatenate([(rng - rho) / sig[0], _wrap(vel - v, width_mps) / sig[1]], axis=1)

    cost, keep = _gauss_newton(residuals, candidates, n, test.trim)
    return bool(np.any(cost <= chi2.isf(test.tail, 2 * keep - 2)))


def _kept_rows(z2: np.ndarray, trim: float) -> np.ndarray:
    """Rows (last axis) of the smallest ``1 - trim`` of the squared normalised residuals."""
    keep = z2.shape[-1] - int(np.floor(trim * z2.shape[-1]))
    return z2 <= np.partition(z2, keep - 1, axis=-1)[..., keep - 1 : keep]


def _gauss_newton(residuals: Callable, ne: np.ndarray, n: int, trim: float, steps: int = 6) -> tuple:
    """Trimmed least squares of static points' NE positions from several starts at once.

    ``residuals(ne)`` maps (m, 2) starts to (m, 2n) normalised residuals (the ``n`` detections'
    ranges, then their Doppler); the Jacobian is taken by 1 m differences (the surface may be a
    DEM). Returns each start's trimmed chi-square (m,) and the number of detections kept.
    """
    ne = np.asarray(ne, float).copy()
    for _ in range(steps):
        e = residuals(ne)
        w = np.tile(_kept_rows(e[:, :n] ** 2 + e[:, n:] ** 2, trim), 2) & np.isfinite(e)
        e = np.where(w, e, 0.0)
        J = np.stack([np.where(w, residuals(ne + d), 0.0) - e for d in np.eye(2)], axis=-1)  # (m, 2n, 2)
        JTJ = np.einsum("mki,mkj->mij", J, J) + 1e-6 * np.eye(2)
        step = np.linalg.solve(JTJ, -np.einsum("mki,mk->mi", J, e)[..., None])[..., 0]
        ne += np.clip(np.nan_to_num(step), -500.0, 500.0)
    e = residuals(ne)
    z2 = np.where(np.isfinite(e[:, :n] + e[:, n:]), e[:, :n] ** 2 + e[:, n:] ** 2, np.inf)
    keep = n - int(np.floor(trim * n))
    return np.sum(np.partition(z2, keep - 1, axis=1)[:, :keep], axis=1), keep


def range_doppler_consistent(
    time_s: np.ndarray,
    range_m: np.ndarray,
    radial_velocity_mps: np.ndarray,
    width_mps: float,
    coupling_s: float,
    test: GroundTrackTest | None = None,
    max_alias: int = 2,
) -> bool:
    """Whether a detection history's ranges follow its Doppler: ``dr/dt`` is the de-aliased radial velocity.

    The radial velocities are unwrapped by continuity, integrated over time, and shifted by a
    whole number of image widths (the alias, ``|k| <= max_alias``); the apparent ranges must follow
    within the range error (trimmed chi-square).

    Examples
    --------
    >>> t = np.arange(10) * 0.1
    >>> range_doppler_consistent(t, 3000.0 - 90.0 * t, np.full(10, -90.0 + 78.3), 78.3, 0.19)
    True
    >>> hops = np.array([0.0, 24.0, 80.0, 420.0, 300.0, 310.0, 390.0, 200.0, 260.0, 150.0])
    >>> range_doppler_consistent(t, 3000.0 + hops, np.full(10, 33.0), 78.3, 0.19)  # residual clutter
    False
    """
    test = test or GroundTrackTest()
    t = np.asarray(time_s, float)
    rng = np.asarray(range_m, float)
    v = np.unwrap(np.asarray(radial_velocity_mps, float), period=width_mps)
    moved = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))]) + coupling_s * (v - v[0])
    limit = chi2.isf(test.tail, max(rng.size - int(np.floor(test.trim * rng.size)) - 1, 1))
    for k in range(-max_alias, max_alias + 1):
        res = rng - moved - k * width_mps * (t - t[0])
        z2 = ((res - np.median(res)) / test.sigma_range_m) ** 2
        if _trimmed_sum(z2, test.trim)[0] <= limit:
            return True
    return False


def terrain_surface(terrain, origin: tuple[float, float, float], flat_down_m: float) -> Callable:
    """Surface function (NE points (k, 2) -> ``down`` of the surface, m) of a DEM seen from a
    scenario ``origin`` (lat, lon, alt); a level ground at ``flat_down_m`` beyond the DEM.

    The fit calls it thousands of times with a few points, so the NED-to-geodetic conversion is
    linearised at the origin (degrees per metre north and east, and the Earth's curvature dropping
    the surface by ``(n^2 + e^2) / 2R``): under 0.1 m off at 15 km.
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


def _own_state(ownship: pd.DataFrame, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Own-ship NED position and velocity (k, 3) interpolated at ``times``."""
    t = ownship["time_s"].to_numpy(float)
    cols = [[np.interp(times, t, ownship[f"own_{a}"].to_numpy(float)) for a in names]
            for names in (("north_m", "east_m", "down_m"), ("vn_mps", "ve_mps", "vd_mps"))]  # fmt: skip
    return np.column_stack(cols[0]), np.column_stack(cols[1])


def _history_held(t, rng, vel, own_p, own_v, surface_down, width, coupling, test) -> np.ndarray:
    """Per detection of one track: held (ground, or not an object) on the detections up to it.

    Judged at every detection for the first 30, then at every fifth. A track judged an object
    off the ground for :data:`_CLEAR_S` on end is not judged again (it was confirmed all that
    time already, so a later verdict could not undo its count; the fits cost time).
    """
    n = rng.size
    held = np.ones(n, bool)
    last, clear_since = True, np.inf
    for k in range(test.min_detections - 1, n):
        if t[k] - clear_since >= _CLEAR_S:
            held[k:] = False
            break
        if k < 30 or k % 5 == 0 or k == n - 1:
            sl = slice(max(0, k + 1 - test.max_history), k + 1)
            last = not range_doppler_consistent(t[sl], rng[sl], vel[sl], width, coupling, test)
            if not last and surface_down is not None:
                last = fits_static_ground(rng[sl], vel[sl], own_p[sl], own_v[sl], surface_down, width,
                                          coupling, test)  # fmt: skip
            clear_since = np.inf if last else min(clear_since, t[k])
        held[k] = last
    return held


def hold_ground_tracks(
    tracks: pd.DataFrame,
    detections: pd.DataFrame,
    ownship: pd.DataFrame | None,
    width_mps: float,
    coupling_s: float,
    surface_down: Callable[[np.ndarray], np.ndarray] | None = None,
    test: GroundTrackTest | None = None,
) -> pd.DataFrame:
    """A tracks table with the rows the ground explains (or that are no object) not ``confirmed``.

    ``detection_row`` of ``tracks`` indexes ``detections`` (``time_s, range_m,
    radial_velocity_mps``). ``ownship`` (``own_*`` NED columns, optionally ``own_height_agl_m``)
    gives the static points' history; without ``surface_down`` the surface is a level ground at
    the own-ship's height above ground, and without either only the range-Doppler test applies.
    A row takes the decision of the track's newest detection at or before it; tracks left
    without a confirmed row are dropped.
    """
    test = test or GroundTrackTest()
    if len(tracks) == 0:
        return tracks
    if surface_down is None and ownship is not None and "own_height_agl_m" in ownship:
        ground = (ownship["own_down_m"] + ownship["own_height_agl_m"]).to_numpy(float)
        if np.isfinite(ground).any():
            surface_down = flat_surface(float(np.nanmedian(ground)))
    det_t = detections["time_s"].to_numpy(float)
    det_r = detections["range_m"].to_numpy(float)
    det_v = detections["radial_velocity_mps"].to_numpy(float)
    rows = tracks["detection_row"].to_numpy()
    held = np.ones(len(tracks), bool)
    for _, idx in tracks.groupby("track_id", sort=False).indices.items():
        has = idx[rows[idx] >= 0]
        if has.size == 0:
            continue
        d = rows[has]
        own_p, own_v = _own_state(ownship, det_t[d]) if ownship is not None else (None, None)
        ground = surface_down if ownship is not None else None
        h = _history_held(det_t[d], det_r[d], det_v[d], own_p, own_v, ground, width_mps, coupling_s, test)
        # Each row (coasting ones too) takes the decision of the newest detection at or before it.
        pos = np.searchsorted(has, idx, side="right") - 1
        held[idx] = np.where(pos >= 0, h[np.maximum(pos, 0)], True)
    out = tracks.assign(confirmed=tracks["confirmed"].to_numpy(bool) & ~held)
    real = np.unique(out["track_id"].to_numpy()[out["confirmed"].to_numpy()])
    return out[np.isin(out["track_id"].to_numpy(), real)].reset_index(drop=True)
