"""Terrain-aware flight state: 3-D ground-ridge points instead of a flat ground plane (beyond the thesis).

The flat-plane inversion assumes the ground ahead is one plane; over hills the height it
returns is that of a plane fitted to kilometres of terrain ahead, not the terrain underneath.
This estimator uses the direction of arrival (:mod:`skyradar.process.doa`) of every ridge pixel:

1. **Velocity** -- every static ground point obeys ``v_r = -u . V`` whatever the terrain's
   shape, so the level-frame velocity ``V`` is a Huber-loss linear least squares over the ridge
   pixels' unit vectors ``u`` (antenna frame rotated to a heading-aligned level frame by the
   mount and the AHRS pitch and roll).
2. **Ground points** -- the Doppler fixes the angle between ``u`` and ``V`` far more precisely
   than the 2x2 array fixes elevation (0.1 m/s over 55 m/s is 0.1 deg), except near grazing.
   Each point keeps its DoA azimuth and takes the depression that fuses the DoA elevation and
   the Doppler cone by inverse variance.
3. **Terrain memory** -- the points are placed in a dead-reckoned frame (position integrated
   from ``V`` and the AHRS heading). The ground straight below the aircraft was seen ahead in
   the previous frames; a robust plane through the remembered points within ``window_m`` of
   the aircraft gives the terrain height below, hence ``H``. Until the memory covers the
   ground below, points of the current frame near the nadir are used.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from skyradar.config import RadarConfig
from skyradar.geo import rotation_matrix
from skyradar.nav.ridge import Ridge, extract_ridge
from skyradar.process.doa import doa_crlb, estimate_directions

__all__ = ["TerrainEstimate", "TerrainAwareEstimator", "level_velocity", "ground_points"]


@dataclass(frozen=True)
class TerrainEstimate:
    """One frame: (V_X, V_Z, H of the antenna) with SDs, quality, flag and point count.

    Attributes
    ----------
    vx_mps, vz_mps, h_m : float
        Horizontal ground speed (m/s), vertical speed (m/s, positive down) and height of the antenna
        above the terrain below (m); NaN when not estimated.
    vx_sd_mps, vz_sd_mps, h_sd_m : float
        One-sigma uncertainties.
    quality : float
        0..1; below 0.3 the frame is low quality.
    low_quality : bool
        The filter skips the frame.
    n_points : int
        Ridge points the velocity fit kept.

    Examples
    --------
    A frame that sees only sky:

    >>> cfg = RadarConfig.prototype_2022(range_limit_m=1000.0)
    >>> est = TerrainAwareEstimator(cfg).update(0.0, np.zeros((cfg.n_range, cfg.n_doppler, cfg.n_rx)))
    >>> est.low_quality, est.n_points, np.isnan([est.vx_mps, est.vz_mps, est.h_m]).all()
    (True, 0, np.True_)
    """

    vx_mps: float
    vz_mps: float
    h_m: float
    vx_sd_mps: float
    vz_sd_mps: float
    h_sd_m: float
    quality: float
    low_quality: bool
    n_points: int


def level_velocity(u_level: np.ndarray, radial_velocity_mps: np.ndarray, f_scale_mps: float = 0.5):
    """Velocity (forward, right, down; m/s) of the radar over static ground from unit vectors.

    Solves ``v_r = -u . V`` with a Huber loss. Returns (V, covariance (3, 3), inlier mask).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> u = rng.normal(size=(50, 3)) + [3.0, 0.0, 1.0]
    >>> u /= np.linalg.norm(u, axis=1, keepdims=True)
    >>> v, cov, inl = level_velocity(u, -u @ [50.0, 1.0, 2.0])
    >>> np.round(v, 6).tolist()
    [50.0, 1.0, 2.0]
    """
    a, y = -np.asarray(u_level, float), np.asarray(radial_velocity_mps, float)
    x0, *_ = np.linalg.lstsq(a, y, rcond=None)
    sol = least_squares(lambda x: a @ x - y, x0, loss="huber", f_scale=f_scale_mps)
    res = a @ sol.x - y
    inl = np.abs(res) < 3.0 * f_scale_mps
    s2 = max(float(np.mean(res[inl] ** 2)) if inl.any() else 1.0, 1e-4)
    cov = np.linalg.pinv(a[inl].T @ a[inl]) * s2 if inl.sum() >= 3 else np.full((3, 3), np.nan)
    return sol.x, cov, inl


def ground_points(
    range_m: np.ndarray,
    radial_velocity_mps: np.ndarray,
    u_level: np.ndarray,
    velocity_level: np.ndarray,
    elevation_sd_rad: np.ndarray,
    sigma_v_mps: float = 0.09,
) -> np.ndarray:
    """Level-frame positions (n, 3) of ridge points: DoA azimuth, DoA + Doppler-cone depression.

    Examples
    --------
    >>> v = np.array([50.0, 0.0, 0.0])
    >>> u = np.array([[np.cos(0.5), 0.0, np.sin(0.5)]])
    >>> p = ground_points(np.array([1000.0]), -u @ v, u + [0.0, 0.0, 0.02], v, np.array([0.05]))
    >>> np.round(p, 1).tolist()
    [[877.5, 0.0, 479.5]]
    """
    u = np.asarray(u_level, float)
    az = np.arctan2(u[:, 1], u[:, 0])
    dep_doa = np.arcsin(np.clip(u[:, 2] / np.linalg.norm(u, axis=1), -1.0, 1.0))
    speed = float(np.linalg.norm(velocity_level))
    # Cone: cos(dep) (Vf cos az + Vr sin az) + Vd sin(dep) = -v_r.
    a = velocity_level[0] * np.cos(az) + velocity_level[1] * np.sin(az)
    b = np.full_like(a, velocity_level[2])
    amp = np.hypot(a, b)
    ratio = np.clip(-np.asarray(radial_velocity_mps) / np.maximum(amp, 1e-9), -1.0, 1.0)
    base, half = np.arctan2(b, a), np.arccos(ratio)
    roots = np.stack([base + half, base - half])
    dep_dop = roots[np.argmin(np.abs(roots - dep_doa), axis=0), np.arange(az.size)]
    # The cone pins the depression except where u is nearly parallel to V (sin(angle) -> 0).
    sd_dop = sigma_v_mps / (speed * np.maximum(np.sqrt(1.0 - ratio**2), 1e-3))
    w_doa, w_dop = 1.0 / np.asarray(elevation_sd_rad) ** 2, 1.0 / sd_dop**2
    dep = (w_doa * dep_doa + w_dop * dep_dop) / (w_doa + w_dop)
    r = np.asarray(range_m, float)
    return np.column_stack([r * np.cos(dep) * np.cos(az), r * np.cos(dep) * np.sin(az), r * np.sin(dep)])


def _robust_plane(xy: np.ndarray, z: np.ndarray) -> tuple[float, float]:
    """Height (down) at the origin of a Huber-loss plane through points, and its SD."""
    spread = np.ptp(xy, axis=0) if len(z) else np.zeros(2)
    cols = [np.ones_like(z)] + [xy[:, i] for i in range(2) if spread[i] > 50.0]
    design = np.column_stack(cols)
    x0 = np.array([np.median(z)] + [0.0] * (design.shape[1] - 1))
    sol = least_squares(lambda p: design @ p - z, x0, loss="huber", f_scale=5.0)
    res = design @ sol.x - z
    mad = 1.4826 * float(np.median(np.abs(res))) + 1.0
    cov = np.linalg.pinv(design.T @ design) * mad**2
    return float(sol.x[0]), float(np.sqrt(max(cov[0, 0], 0.0)))


class TerrainAwareEstimator:
    """Sequential terrain-aware estimator; call :meth:`update` once per frame in time order.

    Parameters
    ----------
    config : RadarConfig
    memory_s : float
        How long ground points are remembered.
    window_m : float
        Radius around the aircraft for the terrain-below fit; grows (x2, x4) when too few points.
    min_points : int
        Fewer ridge points or fewer points in the window: low-quality frame, NaN estimates.

    Examples
    --------
    45 ridge points on flat ground 300 m below the antenna, flying at 50 m/s; each pixel holds its
    direction's receive phases, so the DoA is exact.

    >>> from skyradar.process.doa import steering_vector
    >>> cfg = RadarConfig.prototype_2022()
    >>> north, east = np.meshgrid(np.linspace(100.0, 900.0, 9), np.linspace(-200.0, 200.0, 5))
    >>> points = np.column_stack([north.ravel(), east.ravel(), np.full(north.size, 300.0)])
    >>> r = np.linalg.norm(points, axis=1)
    >>> u = points / r[:, None]  # level frame; the default mount is level and forward
    >>> n = r.size
    >>> ridge = Ridge(r, -u @ [50.0, 0.0, 0.0], np.arange(n), np.zeros(n, int), np.full(n, 30.0), 1.0, n)
    >>> cube = steering_vector(u @ cfg.mount.rotation, cfg)[:, None, :]
    >>> est = TerrainAwareEstimator(cfg).update(0.0, cube, ridge=ridge)
    >>> round(est.vx_mps, 3), round(est.vz_mps, 3), round(float(est.h_m), 1), est.low_quality, est.n_points
    (50.0, 0.0, 300.0, False, 45)
    """

    def __init__(
        self, config: RadarConfig, memory_s: float = 40.0, window_m: float = 150.0, min_points: int = 12
    ):
        self.config = config
        self.memory_s = float(memory_s)
        self.window_m = float(window_m)
        self.min_points = int(min_points)
        self._points: deque[tuple[float, np.ndarray]] = deque()
        self._pos = np.zeros(3)  # dead-reckoned (north, east, down) of the antenna
        self._last: tuple[float, np.ndarray] | None = None
        self.prior: tuple[float, float, float] | None = None

    def _advance(self, time_s: float, v_world: np.ndarray | None) -> None:
        if self._last is not None:
            t_prev, v_prev = self._last
            v = v_prev if v_world is None else 0.5 * (v_prev + v_world)
            self._pos = self._pos + v * (time_s - t_prev)
        if v_world is not None:
            self._last = (time_s, v_world)
        elif self._last is not None:
            self._last = (time_s, self._last[1])
        while self._points and self._points[0][0] < time_s - self.memory_s:
            self._points.popleft()

    def update(
        self, time_s: float, cube: np.ndarray, attitude_rad=(0.0, 0.0, 0.0), ridge: Ridge | None = None
    ) -> TerrainEstimate:
        """Estimate from one (range, doppler, rx) cube and the AHRS attitude (yaw, pitch, roll).

        Parameters
        ----------
        time_s : float
            Frame time, s (frames in time order).
        cube : ndarray, shape (range, doppler, rx), complex
            The frame.
        attitude_rad : (3,) float
            Yaw, pitch, roll from the AHRS, rad.
        ridge : Ridge, optional
            The ridge already extracted from this cube.

        Returns
        -------
        TerrainEstimate
        """
        nan = float("nan")
        failed = TerrainEstimate(nan, nan, nan, nan, nan, nan, 0.0, True, 0)
        if ridge is None:
            ridge = extract_ridge(cube, self.config, prior_state=self.prior)
        if len(ridge) < self.min_points:
            self._advance(time_s, None)
            return failed
        yaw, pitch, roll = (float(a) for a in attitude_rad)
        ant_to_level = rotation_matrix(0.0, pitch, roll) @ self.config.mount.rotation
        pixels = np.asarray(cube)[ridge.range_bin, ridge.doppler_bin, :]
        u_level = estimate_directions(pixels, self.config) @ ant_to_level.T
        vel, cov, inl = level_velocity(u_level, ridge.radial_velocity_mps)
        fit_quality = float(inl.mean() * min(1.0, inl.sum() / 50.0))
        if inl.sum() < self.min_points or fit_quality < 0.3 or not np.all(np.isfinite(cov)):
            self._advance(time_s, None)  # keep dead reckoning on the last good velocity
            return failed
        u_ant = u_level[inl] @ ant_to_level  # back to antenna angles for the bound
        snr_db = 10.0 * np.log10(np.maximum(10.0 ** (ridge.snr_db[inl] / 10.0) - 1.0, 1e-3))
        _, sd_el = doa_crlb(
            snr_db, np.arctan2(u_ant[:, 1], u_ant[:, 0]), np.arcsin(-u_ant[:, 2]), self.config
        )
        pts = ground_points(
            ridge.range_m[inl], ridge.radial_velocity_mps[inl], u_level[inl], vel, np.maximum(sd_el, 0.003)
        )
        heading = rotation_matrix(yaw, 0.0, 0.0)
        self._advance(time_s, heading @ vel)
        self._points.append((time_s, self._pos + pts @ heading.T))
        h, h_sd, n_win = self._height_below()
        vx, vz = float(np.hypot(vel[0], vel[1])), float(vel[2])
        sds = np.sqrt(np.clip(np.diag(cov), 0.0, None))
        quality = fit_quality * min(1.0, n_win / self.min_points)
        if not (np.isfinite(h) and h > 0):
            return TerrainEstimate(
                vx,
                vz,
                float("nan"),
                float(sds[0]),
                float(sds[2]),
                float("nan"),
                quality,
                True,
                int(inl.sum()),
            )
        self.prior = (vx, vz, h)
        return TerrainEstimate(
            vx, vz, h, float(sds[0]), float(sds[2]), h_sd, quality, quality < 0.3, int(inl.sum())
        )

    def _height_below(self) -> tuple[float, float, int]:
        pts = np.concatenate([p for _, p in self._points])
        d_xy = pts[:, :2] - self._pos[:2]
        dist = np.hypot(d_xy[:, 0], d_xy[:, 1])
        for scale in (1.0, 2.0, 4.0):
            near = dist < self.window_m * scale
            if near.sum() >= self.min_points:
                z, sd = _robust_plane(d_xy[near], pts[near, 2])
                return z - self._pos[2], sd, int(near.sum())
        return float("nan"), float("nan"), 0
