"""Flight state (V_X, V_Z, H) from ground-ridge pairs (range, radial velocity) over a flat plane.

Over a flat, static ground plane every ground point moves at ``-V`` relative to the radar. At
range ``r`` the ground forms a circle; its point straight ahead on the track has the largest
closing speed, i.e. the most *negative* radial velocity (radial velocity is positive
receding). For that point (Maas 2022, ch. 5)::

    V_r r + V_Z H = -V_X sqrt(r^2 - H^2)

with ``V_X`` the horizontal ground speed, ``V_Z`` the vertical speed (positive downwards) and
``H`` the radar height above the plane. Squaring gives a model linear in ``a, b, c``::

    (V_r r)^2 a + (V_r r) b + c = r^2,
    a = 1 / V_X^2,  b = 2 V_Z H / V_X^2,  c = H^2 (V_X^2 + V_Z^2) / V_X^2.

:func:`fit_thesis` is the thesis' algebraic least squares; :func:`fit_ransac` finds the
consensus set of three-point minimal solutions; :func:`fit_robust` refines with a Huber loss on
the radial-velocity residuals of the unsquared model (scipy.optimize.least_squares), which also
gives standard deviations.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from skyradar.nav._flight_state_kernels import ridge_errors, smallest_three
from skyradar.nav.huber_fit import huber_least_squares

__all__ = [
    "StateFit",
    "abc_from_state",
    "state_from_abc",
    "ridge_velocity",
    "fit_thesis",
    "fit_ransac",
    "fit_robust",
]


@dataclass(frozen=True)
class StateFit:
    """One frame's flight-state estimate.

    Attributes
    ----------
    vx_mps, vz_mps, h_m : float
        Horizontal ground speed, vertical speed (positive down) and height above the
        ground plane; NaN when the fit failed.
    vx_sd_mps, vz_sd_mps, h_sd_m : float
        One-sigma uncertainties (NaN when unknown).
    inliers : ndarray of bool
        Which input pairs the fit kept.
    rms_mps : float
        RMS radial-velocity residual of the kept pairs, m/s.

    Examples
    --------
    >>> r = np.linspace(600.0, 4000.0, 40)
    >>> fit = fit_robust(r, ridge_velocity(r, 50.0, 1.0, 400.0))
    >>> fit.ok, int(fit.inliers.sum()), round(fit.h_m, 1), fit.rms_mps < 1e-6
    (True, 40, 400.0, True)
    >>> StateFit.failed(3).ok, StateFit.failed(3).inliers.tolist()
    (False, [False, False, False])
    """

    vx_mps: float
    vz_mps: float
    h_m: float
    vx_sd_mps: float
    vz_sd_mps: float
    h_sd_m: float
    inliers: np.ndarray
    rms_mps: float

    @property
    def ok(self) -> bool:
        return bool(np.isfinite(self.vx_mps) and np.isfinite(self.vz_mps) and np.isfinite(self.h_m))

    @classmethod
    def failed(cls, n: int) -> StateFit:
        nan = float("nan")
        return cls(nan, nan, nan, nan, nan, nan, np.zeros(n, bool), nan)


def abc_from_state(vx_mps: float, vz_mps: float, h_m: float) -> tuple[float, float, float]:
    """Coefficients (a, b, c) of the squared ridge model for a flight state.

    Examples
    --------
    >>> abc_from_state(50.0, 0.0, 500.0)
    (0.0004, 0.0, 250000.0)
    """
    a = 1.0 / vx_mps**2
    return a, 2.0 * vz_mps * h_m * a, h_m**2 * (vx_mps**2 + vz_mps**2) * a


def state_from_abc(a: float, b: float, c: float) -> tuple[float, float, float]:
    """Invert :func:`abc_from_state`: (V_X, V_Z, H); NaNs when (a, b, c) is not a flight state.

    Examples
    --------
    >>> [round(x, 6) for x in state_from_abc(*abc_from_state(45.0, -3.0, 700.0))]
    [45.0, -3.0, 700.0]
    """
    h2 = c - b * b / (4.0 * a) if a > 0 else -1.0
    if not (np.isfinite(h2) and h2 > 0.0):
        return float("nan"), float("nan"), float("nan")
    h = float(np.sqrt(h2))
    # V_Z = b / sqrt(4 a^2 c - a b^2) = b / (2 a H).
    return float(np.sqrt(1.0 / a)), float(b / (2.0 * a * h)), h


def ridge_velocity(range_m: np.ndarray, vx_mps: float, vz_mps: float, h_m: float) -> np.ndarray:
    """Radial velocity of the ridge (largest closing speed) at each range, m/s; NaN below H.

    Examples
    --------
    >>> ridge_velocity(np.array([500.0, 1000.0]), 50.0, 0.0, 500.0).round(2).tolist()
    [-0.0, -43.3]
    """
    r = np.asarray(range_m, float)
    with np.errstate(invalid="ignore"):
        ground = np.sqrt(r * r - h_m * h_m)
    return -(vx_mps * ground + vz_mps * h_m) / r


def _design(range_m: np.ndarray, v_mps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    q = v_mps * range_m
    return np.stack([q * q, q, np.ones_like(q)], axis=-1), range_m * range_m


def _abc_sd(a: float, b: float, c: float, cov_abc: np.ndarray) -> tuple[float, float, float]:
    # First-order propagation of the (a, b, c) covariance through the inversion.
    x0 = np.array([a, b, c])
    s0 = np.array(state_from_abc(a, b, c))
    jac = np.empty((3, 3))
    for i in range(3):
        step = 1e-6 * max(abs(x0[i]), 1e-12)
        x1 = x0.copy()
        x1[i] += step
        jac[:, i] = (np.array(state_from_abc(*x1)) - s0) / step
    cov = jac @ cov_abc @ jac.T
    return tuple(float(np.sqrt(max(d, 0.0))) for d in np.diag(cov))  # type: ignore[return-value]


def fit_thesis(range_m: np.ndarray, radial_velocity_mps: np.ndarray) -> StateFit:
    """The thesis' algebraic least squares for (a, b, c), then V_X, V_Z, H.

    Parameters
    ----------
    range_m, radial_velocity_mps : ndarray, shape (n,)
        Ridge pairs: range and (unaliased, negative for ground ahead) radial velocity.

    Examples
    --------
    >>> r = np.linspace(600.0, 4000.0, 50)
    >>> fit = fit_thesis(r, ridge_velocity(r, 50.0, 2.0, 500.0))
    >>> round(fit.vx_mps, 3), round(fit.vz_mps, 3), round(fit.h_m, 3)
    (50.0, 2.0, 500.0)
    """
    r = np.asarray(range_m, float)
    v = np.asarray(radial_velocity_mps, float)
    good = np.isfinite(r) & np.isfinite(v)
    if good.sum() < 4:
        return StateFit.failed(r.size)
    design, rhs = _design(r[good], v[good])
    # Column scaling keeps the normal equations well conditioned (a ~ 1e-4, c ~ 1e5).
    scale = np.abs(design).max(axis=0)
    scale[scale == 0] = 1.0
    coef, *_ = np.linalg.lstsq(design / scale, rhs, rcond=None)
    a, b, c = coef / scale
    vx, vz, h = state_from_abc(a, b, c)
    if not np.isfinite(h):
        return StateFit.failed(r.size)
    resid = rhs - design @ (coef / scale)
    dof = max(int(good.sum()) - 3, 1)
    dn = design / scale
    cov = np.linalg.pinv(dn.T @ dn) * (resid @ resid / dof) / np.outer(scale, scale)
    sds = _abc_sd(a, b, c, cov)
    rms = float(np.sqrt(np.mean((v[good] - ridge_velocity(r[good], vx, vz, h)) ** 2)))
    return StateFit(vx, vz, h, *sds, good, rms)


def _minimal_solutions(range_m: np.ndarray, v_mps: np.ndarray, triples: np.ndarray) -> np.ndarray:
    """(a, b, c) for each row of index triples; NaN rows for singular triples."""
    design, rhs = _design(range_m, v_mps)
    scale = np.abs(design).max(axis=0)
    mats = design[triples] / scale
    det = np.linalg.det(mats)
    ok = np.abs(det) > 1e-9
    out = np.full((len(triples), 3), np.nan)
    out[ok] = np.linalg.solve(mats[ok], rhs[triples[ok]][..., None])[..., 0] / scale
    return out


def fit_ransac(
    range_m: np.ndarray,
    radial_velocity_mps: np.ndarray,
    threshold_mps: float = 0.6,
    n_trials: int = 300,
    seed: int = 0,
) -> StateFit:
    """RANSAC on three-point minimal solutions; the consensus set is refitted by :func:`fit_thesis`.

    A pair is an inlier when its radial velocity is within ``threshold_mps`` of the ridge
    of the candidate state. Outliers are, e.g., intruders closing faster than the ground,
    spurs, and range bins where the true ridge faded into the noise.

    Examples
    --------
    >>> r = np.linspace(600.0, 4000.0, 60)
    >>> v = ridge_velocity(r, 50.0, 0.0, 500.0)
    >>> v[::7] -= 15.0  # every seventh pair is an outlier
    >>> round(fit_ransac(r, v).h_m, 3)
    500.0
    """
    r = np.asarray(range_m, float)
    v = np.asarray(radial_velocity_mps, float)
    idx = np.flatnonzero(np.isfinite(r) & np.isfinite(v))
    if idx.size < 4:
        return StateFit.failed(r.size)
    rng = np.random.default_rng(seed)
    # Each trial's three pairs: those with the smallest random keys (the first three of an argsort).
    triples = smallest_three(rng.random((n_trials, idx.size)))
    coefs = _minimal_solutions(r[idx], v[idx], triples)
    # Score every candidate at once: (trials, pairs) radial-velocity errors of the ridge model.
    err = ridge_errors(coefs, r[idx], v[idx])
    with np.errstate(invalid="ignore", divide="ignore"):
        a, b, c = coefs.T
        h = np.sqrt(c - b * b / (4.0 * a))
    valid = (a > 0) & np.isfinite(h) & (h > 0)
    counts = np.where(valid, (err < threshold_mps).sum(axis=1), 0)
    costs = np.where(valid, np.minimum(err, threshold_mps).sum(axis=1), np.inf)
    if counts.max(initial=0) < 4:
        return StateFit.failed(r.size)
    order = np.lexsort((costs, -counts))
    best = err[order[0]] < threshold_mps
    keep = np.zeros(r.size, bool)
    keep[idx[best]] = True
    fit = fit_thesis(np.where(keep, r, np.nan), v)
    return StateFit(
        fit.vx_mps, fit.vz_mps, fit.h_m, fit.vx_sd_mps, fit.vz_sd_mps, fit.h_sd_m, keep, fit.rms_mps
    )


def _residuals(
    x: np.ndarray,
    r: np.ndarray,
    v: np.ndarray,
    sigma_v: float,
    sigma_r: float,
    prior: np.ndarray | None = None,
) -> np.ndarray:
    if prior is not None:
        # Prior rows (x - mean) / sd for the components with a finite prior SD.
        used = np.isfinite(prior[1])
        return np.concatenate([_residuals(x, r, v, sigma_v, sigma_r), ((x - prior[0]) / prior[1])[used]])
    vx, vz, h = x
    ground = np.sqrt(np.maximum(r * r - h * h, 1e-6))
    model = -(vx * ground + vz * h) / r
    # Effective variance: a range error moves the ridge along its slope dv/dr.
    slope = -vx / ground + (vx * ground + vz * h) / (r * r)
    sigma = np.sqrt(sigma_v**2 + (slope * sigma_r) ** 2)
    return (v - model) / sigma


def _jacobian(
    x: np.ndarray,
    r: np.ndarray,
    v: np.ndarray,
    sigma_v: float,
    sigma_r: float,
    prior: np.ndarray | None = None,
) -> np.ndarray:
    """d :func:`_residuals` / d (V_X, V_Z, H), analytic (scipy's finite differences cost 3 more calls)."""
    vx, vz, h = x
    inside = r * r - h * h > 1e-6
    ground = np.sqrt(np.maximum(r * r - h * h, 1e-6))
    dg_dh = np.where(inside, -h / ground, 0.0)
    along = vx * ground + vz * h
    model = -along / r
    slope = -vx / ground + along / (r * r)
    sigma = np.sqrt(sigma_v**2 + (slope * sigma_r) ** 2)
    d_model = np.stack([-ground / r, -h / r, -(vx * dg_dh + vz) / r], axis=1)
    d_slope = np.stack(
        [-1.0 / ground + ground / (r * r), h / (r * r), vx * dg_dh / ground**2 + (vx * dg_dh + vz) / (r * r)],
        axis=1,
    )
    d_sigma = (slope * sigma_r**2 / sigma)[:, None] * d_slope
    jac = -d_model / sigma[:, None] - ((v - model) / sigma**2)[:, None] * d_sigma
    if prior is not None:
        used = np.isfinite(prior[1])
        jac = np.concatenate([jac, np.diag(1.0 / prior[1])[used]])
    return jac


def fit_robust(
    range_m: np.ndarray,
    radial_velocity_mps: np.ndarray,
    sigma_v_mps: float = 0.1,
    sigma_r_m: float = 4.5,
    f_scale: float = 2.0,
    seed: int = 0,
    prior: tuple[np.ndarray, np.ndarray] | None = None,
) -> StateFit:
    """RANSAC start, then Huber-loss nonlinear least squares on the unsquared ridge model.

    Parameters
    ----------
    range_m, radial_velocity_mps : ndarray, shape (n,)
        Ridge pairs.
    sigma_v_mps, sigma_r_m : float
        Measurement noise of one pair (bin quantisation: dV/sqrt(12), dR/sqrt(12)).
    f_scale : float
        Huber transition, in units of the normalised residual.
    prior : (mean, sd), optional
        Gaussian prior on (V_X, V_Z, H), e.g. the filter's prediction; an infinite SD leaves
        that component free. Over rough terrain the ridge cannot separate H from V_Z well
        (both bend the ridge near the nadir); a prior on the slowly varying V_Z steadies H.

    Examples
    --------
    >>> r = np.linspace(520.0, 4000.0, 80)
    >>> v = ridge_velocity(r, 60.0, -3.0, 500.0)
    >>> fit = fit_robust(r, v)
    >>> round(fit.vx_mps, 2), round(fit.vz_mps, 2), round(fit.h_m, 1)
    (60.0, -3.0, 500.0)
    """
    r = np.asarray(range_m, float)
    v = np.asarray(radial_velocity_mps, float)
    start = fit_ransac(r, v, threshold_mps=max(6 * sigma_v_mps, 0.5), seed=seed)
    if not start.ok:
        start = fit_thesis(r, v)
    if not start.ok:
        return StateFit.failed(r.size)
    pri = None if prior is None else np.array([np.asarray(prior[0], float), np.asarray(prior[1], float)])
    x0 = np.array([start.vx_mps, start.vz_mps, start.h_m])
    if pri is not None and np.all(np.isfinite(pri[0])):
        x0 = np.where(np.isfinite(pri[1]), pri[0], x0)
    # No ground point is nearer than the plane below: H stays below the nearest ridge pair. Over
    # rough terrain that is the nearest hill, which keeps H from running off with V_Z.
    good = np.isfinite(r) & np.isfinite(v)
    if good.sum() < 4:
        return StateFit.failed(r.size)
    rg, vg = r[good], v[good]
    h_max = 0.9999 * rg.min()
    x0 = np.clip(x0, [1e-3, -np.inf, 1.0], [np.inf, np.inf, 0.999 * h_max])
    args = (rg, vg, sigma_v_mps, sigma_r_m, pri)
    bounds = ([1e-3, -np.inf, 1.0], [np.inf, np.inf, h_max])
    x_fit, jac_fit = _huber_fit(x0, bounds, f_scale, args)
    return _robust_result(x_fit, jac_fit, args, good, f_scale)


def _huber_fit(x0: np.ndarray, bounds, f_scale: float, args: tuple) -> tuple[np.ndarray, np.ndarray]:
    """Huber-loss minimum and Jacobian of the ridge residuals within ``bounds``."""
    # The same Huber minimum as scipy's least_squares, without its per-iteration overhead (most of
    # a frame's time); scipy when the reweighted Gauss-Newton does not converge.
    lower, upper = (np.array(b) for b in bounds)
    fast = huber_least_squares(_residuals, _jacobian, x0, lower, upper, f_scale, args)
    if fast is None:
        sol = least_squares(
            _residuals,
            x0,
            jac=_jacobian,
            loss="huber",
            f_scale=f_scale,
            args=args,
            x_scale=[10, 1, 100],
            bounds=bounds,
        )
        fast = sol.x, sol.jac
    return fast


def _robust_result(x_fit, jac_fit, args: tuple, good: np.ndarray, f_scale: float) -> StateFit:
    """The fit with its inliers (normalised residual below 3 f_scale) and residual-scaled SDs.

    ``args`` are the residual arguments (finite ranges, velocities, noise SDs, prior); ``good``
    marks those pairs among all the input pairs.
    """
    rg, vg, sigma_v_mps, sigma_r_m, _ = args
    vx, vz, h = (float(x) for x in x_fit)
    res = _residuals(x_fit, rg, vg, sigma_v_mps, sigma_r_m)
    inl = np.abs(res) < 3.0 * f_scale
    if inl.sum() < 4 or not (vx > 0 and h > 0):
        return StateFit.failed(good.size)
    jac = jac_fit[: rg.size][inl]
    # Scale the covariance by the observed residual spread (at least the assumed noise).
    s2 = max(float(np.mean(res[inl] ** 2)), 1.0)
    cov = np.linalg.pinv(jac.T @ jac) * s2
    sds = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    keep = np.zeros(good.size, bool)
    keep[np.flatnonzero(good)[inl]] = True
    rms = float(np.sqrt(np.mean((vg[inl] - ridge_velocity(rg[inl], vx, vz, h)) ** 2)))
    return StateFit(vx, vz, h, float(sds[0]), float(sds[1]), float(sds[2]), keep, rms)
