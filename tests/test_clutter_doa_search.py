"""The projected direction search's compiled kernels against their per-point versions, bit for bit.

The kernels of :mod:`skyradar.process.clutter_doa` form each lattice row's azimuth and each column's
elevation trigonometry once and score the coarse grid in cache-sized blocks of points; the per-point
versions below form everything at every point and score the grid in whole-grid passes. Both do the
same floating-point operations in the same order per point, so the scores, the best lattice points
and the directions are equal exactly, not only within a tolerance.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from skyradar.config import RadarConfig
from skyradar.process.clutter import steering_into
from skyradar.process.clutter_doa import (
    _COARSE_DEG,
    _FINE_STEP_DEG,
    _MID_STEP,
    _coarse,
    _directions,
    _grid_best,
    _grid_scores,
    _one_direction,
    _score,
)

CFG = RadarConfig.prototype_2022()


@njit(cache=True)
def _grid_best_per_point(az0, el0, i_lo, i_hi, j_lo, j_hi, step, step_rad, rx, wavenumber, z, p):
    pz = p @ z
    s = np.empty(z.size, np.complex128)
    best, bi, bj = -1.0, 0, 0
    for i in range(i_lo, i_hi + 1, step):
        az = az0 + i * step_rad
        for j in range(j_lo, j_hi + 1, step):
            el = el0 + j * step_rad
            u0, u1, u2 = np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)
            steering_into(u0, u1, u2, rx, wavenumber, s)
            score = _score(s, pz, p)
            if score > best:
                best, bi, bj = score, i, j
    return bi, bj


@njit(cache=True)
def _grid_scores_whole_passes(basis, z, p, out):
    n_k = z.size
    pz = p @ z
    num_re, num_im = np.zeros(out.size), np.zeros(out.size)
    out[:] = 0.0
    for k in range(n_k):
        sr, si = basis[2 * k], basis[2 * k + 1]
        pr, pi = pz[k].real, pz[k].imag
        for n in range(out.size):
            num_re[n] += sr[n] * pr + si[n] * pi
            num_im[n] += sr[n] * pi - si[n] * pr
    row = 2 * n_k
    for k in range(n_k):
        g, w = basis[row], p[k, k].real
        for n in range(out.size):
            out[n] += w * g[n]
        row += 1
        for m in range(k + 1, n_k):
            g_re, g_im, w_re, w_im = basis[row], basis[row + 1], p[k, m].real, p[k, m].imag
            for n in range(out.size):
                out[n] += w_re * g_re[n] - w_im * g_im[n]
            row += 2
    for n in range(out.size):
        out[n] = (num_re[n] * num_re[n] + num_im[n] * num_im[n]) / max(out[n], 1e-9)
    return out


def _cases(rng, n):
    """Snapshots with projectors of 0-2 nulls and ring whitenings (inverse sample covariances)."""
    for c in range(n):
        z = rng.standard_normal(4) + 1j * rng.standard_normal(4)
        m = c % 3
        q = np.linalg.qr(rng.standard_normal((4, 4)) + 1j * rng.standard_normal((4, 4)))[0][:, :m]
        x = rng.standard_normal((4, 40)) + 1j * rng.standard_normal((4, 40))
        for p in (np.eye(4) - q @ q.conj().T, np.linalg.inv(x @ x.conj().T / 40 + 0.01 * np.eye(4))):
            yield z, np.ascontiguousarray(p, complex)


def test_blocked_coarse_scores_equal_the_whole_grid_passes_exactly():
    rng = np.random.default_rng(21)
    basis = _coarse(CFG)
    for z, p in _cases(rng, 12):
        got = _grid_scores(basis, z, p, np.empty(basis.shape[1]))
        ref = _grid_scores_whole_passes(basis, z, p, np.empty(basis.shape[1]))
        np.testing.assert_array_equal(got, ref)


def test_lattice_search_with_hoisted_angles_finds_the_per_point_search_best_point():
    rng = np.random.default_rng(22)
    rx = np.ascontiguousarray(CFG.rx_positions_m, float)
    wavenumber, step_rad = 2.0 * np.pi / CFG.wavelength_m, np.radians(_FINE_STEP_DEG)
    windows = [(-30, 30, -30, 30, _MID_STEP), (-7, 7, -7, 7, 1), (-30, -23, 20, 30, 1), (-30, 30, 0, 0, 1)]
    for z, p in _cases(rng, 12):
        az0, el0 = rng.uniform(-1.2, 1.2), rng.uniform(-1.2, 1.2)
        for i_lo, i_hi, j_lo, j_hi, step in windows:
            args = (az0, el0, i_lo, i_hi, j_lo, j_hi, step, step_rad, rx, wavenumber, z, p)
            assert _grid_best(*args) == _grid_best_per_point(*args)


def test_batched_directions_equal_one_search_per_snapshot():
    rng = np.random.default_rng(23)
    cases = list(_cases(rng, 9))
    z_all = np.ascontiguousarray([z for z, _ in cases])
    p_all = np.ascontiguousarray([p for _, p in cases])
    rx = np.ascontiguousarray(CFG.rx_positions_m, float)
    rule = (np.radians(_COARSE_DEG), rx, 2.0 * np.pi / CFG.wavelength_m, np.radians(_FINE_STEP_DEG), 30)
    got = _directions(_coarse(CFG), *rule, z_all, p_all)
    ref = np.array([_one_direction(_coarse(CFG), *rule, z, p) for z, p in cases])
    np.testing.assert_array_equal(got, ref)
