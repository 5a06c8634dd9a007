"""Compiled inner loops of the flight-state estimator (``bench state``), the same numbers as numpy.

:func:`ridge_rows` does, one range row at a time, what ``scipy.ndimage.binary_closing`` and
``scipy.ndimage.label`` then :func:`skyradar.nav.ridge.band_start` did on whole images (close fades,
drop short runs, find the band's first bin after the widest empty gap, all circularly);
:func:`smallest_three` and :func:`ridge_errors` are the sampling and scoring of
:func:`skyradar.nav.inversion.fit_ransac`. The numpy versions made many full-size temporaries per
frame; here each row or candidate is one pass. Every float is computed with the same operations in
the same order as the numpy code (no ``fastmath``), so results are bitwise equal
(tests/test_flight_state_kernels.py compares them with scipy.ndimage and the numpy versions).
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["ridge_rows", "smallest_three", "ridge_errors"]


@njit(cache=True, error_model="numpy")
def _closed_runs(mask_row, gap, doubled, run):
    # ``doubled`` = [row, row] with every gap of at most ``gap`` empty bins between two occupied ones
    # filled: what scipy's binary_closing with ones(1, gap + 1), OR the original, gives. Its erosion
    # counts the outside as empty, so bins nearer the ends than the structure's reach stay empty.
    # ``run`` = the length of the occupied run each bin belongs to.
    n = mask_row.size
    m = 2 * n
    reach_left = (gap + 1) // 2  # the structure's centre: scipy's origin 0 for length gap + 1
    first, stop = reach_left, m - (gap - reach_left)  # erosion keeps only bins in [first, stop)
    last = -1
    for p in range(m):
        occupied = mask_row[p % n]
        doubled[p] = occupied
        if occupied:
            if last >= 0 and 0 < p - last - 1 <= gap:
                for q in range(max(last + 1, first), min(p, stop)):
                    doubled[q] = True
            last = p
    p = 0
    while p < m:
        if not doubled[p]:
            run[p] = 0
            p += 1
            continue
        q = p
        while q < m and doubled[q]:
            q += 1
        for k in range(p, q):
            run[k] = q - p
        p = q


@njit(cache=True, error_model="numpy")
def ridge_rows(mask: np.ndarray, gap: int, min_len: int) -> tuple[np.ndarray, np.ndarray]:
    """Rows with a ground band (some but not all bins kept) and each band's first Doppler bin.

    ``mask`` is the (range, doppler) occupancy above the noise gate; ``gap`` the longest fade that is
    closed, ``min_len`` the shortest run kept (see :func:`skyradar.nav.ridge.extract_ridge`).
    """
    n_rows, n = mask.shape
    doubled = np.zeros(2 * n, np.bool_)
    run = np.zeros(2 * n, np.int64)
    clean = np.zeros(n, np.bool_)
    rows = np.empty(n_rows, np.int64)
    starts = np.empty(n_rows, np.int64)
    count = 0
    for i in range(n_rows):
        _closed_runs(mask[i], gap, doubled, run)
        n_clean = 0
        for j in range(n):
            clean[j] = (doubled[j] or doubled[j + n]) and max(run[j], run[j + n]) >= min_len
            n_clean += clean[j]
        if n_clean == 0 or n_clean == n:
            continue
        # Widest empty run ending at each position of the unrolled circle; the first widest wins.
        best, best_at, last = -1, 0, -1
        for p in range(2 * n):
            if clean[p % n]:
                last = p
            elif p - last > best:
                best, best_at = p - last, p
        rows[count] = i
        starts[count] = (best_at + 1) % n
        count += 1
    return rows[:count], starts[:count]


@njit(cache=True, error_model="numpy")
def smallest_three(keys: np.ndarray) -> np.ndarray:
    """Per row, the column indices of its three smallest keys, ascending (keys are distinct)."""
    n_rows, n = keys.shape
    out = np.empty((n_rows, 3), np.int64)
    for i in range(n_rows):
        b0, b1, b2 = np.inf, np.inf, np.inf
        a0, a1, a2 = -1, -1, -1
        for j in range(n):
            k = keys[i, j]
            if k < b2:
                if k < b1:
                    b2, a2 = b1, a1
                    if k < b0:
                        b1, a1 = b0, a0
                        b0, a0 = k, j
                    else:
                        b1, a1 = k, j
                else:
                    b2, a2 = k, j
        # The three indices ascending: a sorting network in scalars (np.sort would compile a
        # general sort for three numbers).
        if a0 > a1:
            a0, a1 = a1, a0
        if a1 > a2:
            a1, a2 = a2, a1
        if a0 > a1:
            a0, a1 = a1, a0
        out[i, 0], out[i, 1], out[i, 2] = a0, a1, a2
    return out


@njit(cache=True, error_model="numpy")
def ridge_errors(coefs: np.ndarray, r: np.ndarray, v: np.ndarray) -> np.ndarray:
    """|v - ridge model| of every candidate (a, b, c) row at every pair; inf where the model is not finite."""
    n_trials, n = coefs.shape[0], r.size
    err = np.empty((n_trials, n))
    for t in range(n_trials):
        a, b, c = coefs[t, 0], coefs[t, 1], coefs[t, 2]
        h = np.sqrt(c - b * b / (4.0 * a))
        vx, vz = np.sqrt(1.0 / a), b / (2.0 * a * h)
        vzh = vz * h
        h2 = h**2
        for j in range(n):
            model = -(vx * np.sqrt(r[j] * r[j] - h2) + vzh) / r[j]
            err[t, j] = np.abs(v[j] - model) if np.isfinite(model) else np.inf
    return err
