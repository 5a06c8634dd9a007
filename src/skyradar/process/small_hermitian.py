"""Eigen-pairs of small Hermitian matrices (the 4 x 4 channel covariances of a range-Doppler cell).

Compiled (numba) helpers shared by the clutter prediction (:mod:`skyradar.process.clutter`) and the
adaptive nulls' strongest pairs (:mod:`skyradar.process.top_eigen`): a cyclic complex Jacobi
solver, and the change of basis ``v^H a v`` a Rayleigh-Ritz step needs.

Examples
--------
>>> a = np.array([[2.0, 1j], [-1j, 2.0]])
>>> v = np.array([[1.0, 1.0], [1j, -1j]]) / np.sqrt(2.0)
>>> h = rotate_into(a, v, np.empty((2, 2), complex), np.empty((2, 2), complex))  # v^H a v
>>> np.diag(h).real.round(9).tolist(), float(abs(h[0, 1]).round(9))
([1.0, 3.0], 0.0)
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["hermitian_eigh", "rotate_into"]


@njit(cache=True)
def _jacobi_rotate(a, v, p, q):  # pragma: no cover - compiled
    # One complex Jacobi rotation J zeroing a[p, q]: a <- J^H a J, v <- v J. A phase turns the pair
    # real, then the real rotation of Numerical Recipes (section 11.1): t = tan(theta), smaller root.
    # J = diag(1, conj(phase)) R on (p, q); a stays Hermitian, so only column p, q are computed
    # and mirrored, and the diagonal pair moves by -+ t |a_pq|.
    n = a.shape[0]
    mag = abs(a[p, q])
    if mag == 0.0:
        return
    ph = np.conj(a[p, q] / mag)
    theta = (a[q, q].real - a[p, p].real) / (2.0 * mag)
    t = (1.0 if theta >= 0 else -1.0) / (abs(theta) + np.sqrt(theta * theta + 1.0))
    c = 1.0 / np.sqrt(t * t + 1.0)
    s = t * c
    for k in range(n):
        vkp, vkq = v[k, p], v[k, q] * ph
        v[k, p], v[k, q] = c * vkp - s * vkq, s * vkp + c * vkq
        if k in (p, q):
            continue
        akp, akq = a[k, p], a[k, q] * ph
        a[k, p], a[k, q] = c * akp - s * akq, s * akp + c * akq
        a[p, k], a[q, k] = np.conj(a[k, p]), np.conj(a[k, q])
    a[p, p], a[q, q] = a[p, p].real - t * mag, a[q, q].real + t * mag
    a[p, q], a[q, p] = 0j, 0j


@njit(cache=True)
def hermitian_eigh(a, v, lam, order, tol=1e-7, max_sweeps=12):  # pragma: no cover - compiled
    """Eigen-pairs of a small Hermitian matrix ``a`` (overwritten) by cyclic Jacobi sweeps.

    ``v`` receives the eigenvectors as columns, ``lam`` the eigenvalues in the same order and
    ``order`` the column indices by decreasing eigenvalue. The rotations start from the identity
    (a warm start from a neighbouring cell's basis made the clutter prediction's eigen-pairs depend
    on the order cells were needed in, :func:`skyradar.process.clutter.decompose_cell`). Sweeps stop
    when the off-diagonal power falls below ``tol**2`` times the diagonal's (quadratic convergence:
    3-5 sweeps at n = 4 from the identity).

    >>> a = np.array([[2.0, 1j], [-1j, 2.0]])
    >>> v, lam, order = np.empty((2, 2), complex), np.empty(2), np.empty(2, np.int64)
    >>> hermitian_eigh(a, v, lam, order)
    >>> lam[order].round(9).tolist(), bool(np.allclose(v.conj().T @ v, np.eye(2)))
    ([3.0, 1.0], True)
    """
    n = a.shape[0]
    for i in range(n):
        for j in range(n):
            v[i, j] = 1.0 if i == j else 0.0
    scale = 0.0
    for i in range(n):
        scale += a[i, i].real ** 2
    for _ in range(max_sweeps):
        off = 0.0
        for i in range(n):
            for j in range(i + 1, n):
                off += a[i, j].real ** 2 + a[i, j].imag ** 2
        if off <= tol * tol * scale:
            break
        for p in range(n):
            for q in range(p + 1, n):
                _jacobi_rotate(a, v, p, q)
    for i in range(n):
        lam[i] = a[i, i].real
        order[i] = i
    for i in range(1, n):  # insertion sort, decreasing
        k, j = order[i], i
        while j > 0 and lam[order[j - 1]] < lam[k]:
            order[j] = order[j - 1]
            j -= 1
        order[j] = k


@njit(cache=True)
def rotate_into(a, v, w, h):  # pragma: no cover - compiled
    """``h = v^H a v`` for a Hermitian ``a`` (n, n) and a basis ``v`` (n, m); ``w`` (n, m) holds
    ``a v``. ``h`` may be ``a`` itself (``a v`` is complete before ``h`` is written)."""
    n, m = v.shape
    for c in range(m):
        for i in range(n):
            t = 0j
            for k in range(n):
                t += a[i, k] * v[k, c]
            w[i, c] = t
    for b in range(m):
        for c in range(m):
            t = 0j
            for i in range(n):
                t += np.conj(v[i, b]) * w[i, c]
            h[b, c] = t
    return h
