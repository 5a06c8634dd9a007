"""The compiled flight-state loops give exactly what scipy.ndimage / numpy give.

The references here are plain implementations of the same steps (scipy's binary closing and run
labelling, numpy's argsort and broadcast scoring) and scipy's finite-difference Jacobian.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage
from scipy.optimize._numdiff import approx_derivative

from skyradar.nav._flight_state_kernels import ridge_errors, ridge_rows, smallest_three
from skyradar.nav.inversion import _jacobian, _residuals, abc_from_state
from skyradar.nav.ridge import band_start


def _reference_rows(mask: np.ndarray, gap: int, min_len: int) -> tuple[np.ndarray, np.ndarray]:
    n = mask.shape[1]
    doubled = np.concatenate([mask, mask], axis=1)
    if gap > 0:
        doubled = ndimage.binary_closing(doubled, structure=np.ones((1, gap + 1), bool)) | doubled
    labels, n_lab = ndimage.label(doubled, structure=np.array([[0, 0, 0], [1, 1, 1], [0, 0, 0]]))
    sizes = np.concatenate([[0], np.bincount(labels.ravel(), minlength=n_lab + 1)[1:]])
    run = sizes[labels]
    run = np.maximum(run[:, :n], run[:, n:])
    clean = (doubled[:, :n] | doubled[:, n:]) & (run >= min_len)
    rows = np.flatnonzero(clean.any(axis=1) & ~clean.all(axis=1))
    return rows, band_start(clean[rows]) if rows.size else np.zeros(0, int)


def test_ridge_rows_matches_scipy_closing_labelling_and_band_start():
    rng = np.random.default_rng(7)
    for _ in range(300):
        n, gap, min_len = int(rng.integers(1, 40)), int(rng.integers(0, 6)), int(rng.integers(1, 5))
        mask = rng.random((int(rng.integers(1, 10)), n)) < rng.random()
        rows, starts = ridge_rows(mask, gap, min_len)
        ref_rows, ref_starts = _reference_rows(mask, gap, min_len)
        np.testing.assert_array_equal(rows, ref_rows)
        np.testing.assert_array_equal(starts, ref_starts)


def test_ridge_rows_on_a_prototype_size_band():
    # A band wrapping around the Doppler axis with a 2-bin fade, on 333 x 250.
    mask = np.zeros((333, 250), bool)
    mask[100:200, 240:] = True
    mask[100:200, :20] = True
    mask[100:200, 5:7] = False
    mask[300, 50] = True  # one lone pixel: dropped (shorter than min_len 2)
    rows, starts = ridge_rows(mask, 2, 2)
    np.testing.assert_array_equal(rows, np.arange(100, 200))
    assert set(starts.tolist()) == {240}


def test_smallest_three_is_the_first_three_of_an_argsort():
    keys = np.random.default_rng(3).random((300, 57))
    np.testing.assert_array_equal(smallest_three(keys), np.sort(keys.argsort(axis=1)[:, :3], axis=1))


def test_ridge_errors_are_the_broadcast_numpy_scoring_bit_for_bit():
    rng = np.random.default_rng(5)
    r = rng.uniform(300.0, 4000.0, 80)
    v = rng.normal(-25.0, 10.0, 80)
    coefs = np.array([abc_from_state(*s) for s in rng.uniform([20, -5, 200], [70, 5, 1500], (50, 3))])
    coefs[3] = np.nan  # a singular triple
    coefs[4] = (-1e-4, 0.0, 1e5)  # not a flight state
    with np.errstate(invalid="ignore", divide="ignore"):
        a, b, c = coefs.T
        h = np.sqrt(c - b * b / (4.0 * a))
        vx, vz = np.sqrt(1.0 / a), b / (2.0 * a * h)
        model = -(vx[:, None] * np.sqrt(r * r - h[:, None] ** 2) + (vz * h)[:, None]) / r
        expected = np.where(np.isfinite(model), np.abs(v - model), np.inf)
    np.testing.assert_array_equal(ridge_errors(coefs, r, v), expected)


@pytest.mark.parametrize("prior", [None, np.array([[40.0, 1.0, 600.0], [np.inf, 0.5, np.inf]])])
def test_the_analytic_jacobian_matches_finite_differences(prior):
    rng = np.random.default_rng(2)
    r = rng.uniform(700.0, 4000.0, 100)  # all beyond H: away from the clamp at r = H
    v = rng.normal(-20.0, 5.0, 100)
    x = np.array([35.0, 1.5, 600.0])
    numeric = approx_derivative(lambda y: _residuals(y, r, v, 0.1, 4.5, prior), x, method="3-point")
    np.testing.assert_allclose(_jacobian(x, r, v, 0.1, 4.5, prior), numeric, rtol=1e-6, atol=1e-9)
