"""Huber-loss nonlinear least squares for small bounded problems, without scipy's per-iteration overhead.

The flight-state fit (:func:`skyradar.nav.inversion.fit_robust`) has three unknowns and a few hundred
residuals; ``scipy.optimize.least_squares(loss="huber")`` spent most of a frame's time in the Python
of its trust-region iterations, not in arithmetic. :func:`huber_least_squares` minimises the same
cost, ``0.5 f_scale^2 sum rho((f / f_scale)^2)`` with scipy's Huber ``rho``, by iteratively
reweighted Gauss-Newton steps (the Huber weights make each step a weighted linear least squares
that never increases the cost) projected onto the bounds, and iterates to a much tighter tolerance
than scipy's default, so both land on the same minimum (tests/test_huber_fit.py). It returns None
when it does not converge; the caller then uses scipy.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["huber_cost", "huber_least_squares"]

_EPS = np.finfo(float).eps


def huber_cost(f: np.ndarray, f_scale: float) -> float:
    """scipy's Huber cost ``0.5 f_scale^2 sum rho((f / f_scale)^2)``.

    Examples
    --------
    >>> huber_cost(np.array([0.5, 3.0]), 1.0)  # 0.5 * (0.25 + (2 * 3 - 1))
    2.625
    """
    a = np.abs(f)
    return float(0.5 * np.sum(np.where(a <= f_scale, a * a, 2.0 * f_scale * a - f_scale * f_scale)))


def _robust_jacobian(jac: np.ndarray, f: np.ndarray, f_scale: float) -> np.ndarray:
    # What scipy's least_squares returns as ``jac`` for a robust loss: rows scaled by
    # sqrt(rho' + 2 rho'' f^2), floored at eps (scale_for_robust_loss_function).
    z = (f / f_scale) ** 2
    outer = z > 1
    rho1 = np.where(outer, np.where(outer, z, 1.0) ** -0.5, 1.0)
    rho2 = np.where(outer, -0.5 * np.where(outer, z, 1.0) ** -1.5, 0.0) / f_scale**2
    scale = rho1 + 2 * rho2 * f**2
    scale[scale < _EPS] = _EPS
    return jac * np.sqrt(scale)[:, None]


def _halving_step(fun, args: tuple, x, step, lower, upper, cost: float, f_scale: float):
    """``x + t step`` (clipped to the bounds) with ``t`` halved from 1 until the cost does not rise.

    The reweighted Gauss-Newton step is a descent direction, so a small enough ``t`` always works;
    below 1e-12 the last trial is returned. Returns the point, its residuals and its cost.
    """
    t = 1.0
    while True:
        x_new = np.clip(x + t * step, lower, upper)
        f_new = fun(x_new, *args)
        cost_new = huber_cost(f_new, f_scale)
        if cost_new <= cost or t < 1e-12:
            return x_new, f_new, cost_new
        t *= 0.5


def huber_least_squares(
    fun: Callable[..., np.ndarray],
    jac: Callable[..., np.ndarray],
    x0: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    f_scale: float,
    args: tuple = (),
    max_iter: int = 200,
    xtol: float = 1e-13,
) -> tuple[np.ndarray, np.ndarray] | None:
    """Minimise the Huber cost of ``fun(x, *args)`` within ``lower <= x <= upper``.

    Returns ``(x, robust_jacobian)`` (the Jacobian as scipy's ``least_squares(...).jac`` gives it
    for a robust loss) or None when ``max_iter`` steps did not converge to ``xtol`` (relative).

    Examples
    --------
    >>> t = np.linspace(0.0, 1.0, 30)
    >>> y = 2.0 * t + 1.0
    >>> y[5] += 50.0  # one gross outlier
    >>> def fun(x):
    ...     return x[0] * t + x[1] - y
    >>> def jac(x):
    ...     return np.column_stack([t, np.ones_like(t)])
    >>> x, _ = huber_least_squares(fun, jac, np.zeros(2), np.full(2, -9.0), np.full(2, 9.0), 1.0)
    >>> from scipy.optimize import least_squares
    >>> tight = dict(xtol=1e-15, ftol=1e-15, gtol=1e-15)
    >>> ref = least_squares(fun, np.zeros(2), jac=jac, loss="huber", bounds=(-9.0, 9.0), **tight)
    >>> bool(np.allclose(x, ref.x, atol=1e-8)), np.round(x, 3).tolist()  # the outlier pulls far less
    (True, [1.868, 1.102])
    """
    x = np.clip(np.asarray(x0, float), lower, upper)
    f = fun(x, *args)
    cost = huber_cost(f, f_scale)
    for _ in range(max_iter):
        j = jac(x, *args)
        w = np.minimum(1.0, f_scale / np.maximum(np.abs(f), 1e-300))  # Huber weights rho'
        grad = j.T @ (w * f)
        # A bound the gradient pushes against stays active; the step solves for the other unknowns.
        free = ~(((x <= lower) & (grad > 0)) | ((x >= upper) & (grad < 0)))
        if not free.any():
            return x, _robust_jacobian(j, f, f_scale)
        step = np.zeros_like(x)
        normal = j[:, free].T @ (w[:, None] * j[:, free])
        try:
            step[free] = np.linalg.solve(normal, -grad[free])
        except np.linalg.LinAlgError:
            return None
        x_new, f_new, cost_new = _halving_step(fun, args, x, step, lower, upper, cost, f_scale)
        done = np.all(np.abs(x_new - x) <= xtol * np.maximum(np.abs(x), 1.0))
        x, f, cost = x_new, f_new, min(cost, cost_new)
        if done:
            return x, _robust_jacobian(jac(x, *args), f, f_scale)
    return None
