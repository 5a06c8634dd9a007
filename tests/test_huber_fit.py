"""The reweighted Gauss-Newton Huber fit lands on scipy.optimize.least_squares' minimum (the peer)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import least_squares

from skyradar.nav.huber_fit import huber_cost, huber_least_squares
from skyradar.nav.inversion import _jacobian, _residuals, fit_robust, ridge_velocity


def _ridge_problem(seed: int, outliers: int):
    rng = np.random.default_rng(seed)
    vx, vz, h = rng.uniform(25.0, 70.0), rng.uniform(-4.0, 4.0), rng.uniform(200.0, 1500.0)
    r = np.sort(rng.uniform(h * 1.05, 4000.0, 250))
    v = ridge_velocity(r, vx, vz, h) + rng.normal(0.0, 0.1, r.size)
    v[rng.choice(r.size, outliers, replace=False)] -= rng.uniform(3.0, 30.0, outliers)
    x0 = np.array([vx * 1.05, vz + 0.5, h * 0.97])
    return r, v, x0


@pytest.mark.parametrize("seed", range(6))
def test_same_minimum_as_scipy_least_squares(seed):
    r, v, x0 = _ridge_problem(seed, outliers=25)
    prior = np.array([[np.nan, 0.0, np.nan], [np.inf, 0.5, np.inf]]) if seed % 2 else None
    args = (r, v, 0.1, 4.5, prior)
    lower, upper = np.array([1e-3, -np.inf, 1.0]), np.array([np.inf, np.inf, 0.9999 * r.min()])
    x, jac = huber_least_squares(_residuals, _jacobian, x0, lower, upper, 2.0, args)
    ref = least_squares(
        _residuals,
        x0,
        jac=_jacobian,
        loss="huber",
        f_scale=2.0,
        args=args,
        bounds=(lower, upper),
        x_scale=[10, 1, 100],
        xtol=1e-15,
        ftol=1e-15,
        gtol=1e-15,
    )
    np.testing.assert_allclose(x, ref.x, rtol=1e-7, atol=1e-7)
    assert huber_cost(_residuals(x, *args), 2.0) <= ref.cost * (1 + 1e-12)
    np.testing.assert_allclose(jac, ref.jac, rtol=1e-5, atol=1e-6)


def test_an_active_bound_is_held():
    # The model would like H above the nearest pair; the bound keeps it there, as in scipy.
    r, v, _ = _ridge_problem(1, outliers=0)
    upper_h = 0.8 * r.min()
    lower, upper = np.array([1e-3, -np.inf, 1.0]), np.array([np.inf, np.inf, upper_h])
    args = (r, v, 0.1, 4.5, None)
    x, _ = huber_least_squares(
        _residuals, _jacobian, np.array([40.0, 0.0, 0.5 * upper_h]), lower, upper, 2.0, args
    )
    ref = least_squares(
        _residuals,
        np.array([40.0, 0.0, 0.5 * upper_h]),
        jac=_jacobian,
        loss="huber",
        f_scale=2.0,
        args=args,
        bounds=(lower, upper),
        xtol=1e-15,
        ftol=1e-15,
        gtol=1e-15,
    )
    assert x[2] == pytest.approx(upper_h, rel=1e-9)
    np.testing.assert_allclose(x, ref.x, rtol=1e-6)


def test_fit_robust_recovers_the_state_through_outliers():
    r, v, _ = _ridge_problem(3, outliers=40)
    fit = fit_robust(r, v)
    rng = np.random.default_rng(3)
    vx, vz, h = rng.uniform(25.0, 70.0), rng.uniform(-4.0, 4.0), rng.uniform(200.0, 1500.0)
    assert (fit.vx_mps, fit.vz_mps, fit.h_m) == pytest.approx((vx, vz, h), rel=0.02, abs=0.3)
