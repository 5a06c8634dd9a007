"""Adaptive post-Doppler nulls where the knowledge-aided prediction does not explain the clutter.

The prediction of :mod:`skyradar.process.clutter_frames` assumes flat ground at the height below
the own-ship. Over relief its clutter directions are wrong: measured in the intruder's cell of a
Jacksboro encounter the raw clutter is 42-53 dB over the noise and 32-43 dB remain after the two
predicted nulls, while the clutter seen by the 4 channels there is concentrated in two directions.
This step trains on the cells around each cell instead (post-Doppler space-only adaptive
processing, Ward, "Space-time adaptive processing for airborne radar", MIT Lincoln Laboratory
TR-1015, 1994, section 4; the sample covariance of secondary data as in Reed, Mallett and
Brennan, IEEE Trans. AES 10(6), 1974):

1. Test of the prediction: a cell with measured clutter (the predicted pass's gate,
   ``clutter_to_noise > gate``) whose training ring (the ``(2 hr + 1) x (2 hd + 1)`` window
   minus the ``(2 gr + 1) x (2 gd + 1)`` guard around it, Doppler wrapping, range truncated)
   still holds a mean projected power above ``ADAPTIVE_GATE`` times the noise floor after the
   predicted nulls. The mean, not the maximum: a 96-cell ring of Gamma(L) noise has a tight mean
   (standard deviation 0.07 of the floor at L = 2), speckle has a loose maximum. Each pixel counts
   at most ``RING_CLIP`` floors: clutter left over fills the ring, while a point target's lobes
   (at most ~15 bright cells) do not lift the clipped mean over the gate, so the cells beside a
   target in clear sky are not retrained (their power feeds the peak's sub-bin interpolation).
2. For those cells the sample covariance ``R`` of the ring's calibrated snapshots (sliding box
   sums of the packed covariance entries), its ``max_nulls`` strongest eigen-pairs (compiled
   subspace iteration from the previous cell's, :func:`skyradar.process.top_eigen.top_eigenpairs`),
   and nulls on those whose eigenvalue exceeds ``EIGEN_EDGE`` times the floor (noise
   eigenvalues of a 96-sample, 4-channel covariance stay below 1.45: Marchenko-Pastur), at most
   ``max_nulls``. They replace the predicted nulls where they leave less power over the ring
   (``sum of the eigenvalues left / L`` against the ring's mean predicted-projected power: both
   are that ring's mean of ``|P z|^2 / L``).
3. The cell under test and its guard are not in ``R``: a target does not null itself (the guard
   holds a point target's Hann main lobe, +-1 range bin and +-2 Doppler bins, and half a bin of
   straddle), and ``|P z|^2 / L`` keeps the Gamma(L, 1/L) noise law of the predicted pass.
   ``unsuppressed`` (kept out of CFAR training) where the eigenvalues left over still hold more
   than the noise of clutter (``sum (lambda_i - 1)+ / n_rx > 1``, the predicted rule's ``left``).

No cell passes the test in clear sky or where the prediction holds: the step then changes
nothing (tested bit for bit).

Examples
--------
>>> rng = np.random.default_rng(0)
>>> shape = (40, 32, 4)
>>> def gauss(*s):
...     return (rng.standard_normal(s) + 1j * rng.standard_normal(s)) / np.sqrt(2)
>>> u = np.exp(1j * np.array([0.0, 1.0, 2.0, 3.0]))  # a clutter direction the prediction missed
>>> cube = (gauss(*shape) + 30.0 * gauss(*shape[:2])[..., None] * u).astype(np.complex64)
>>> raw = (np.abs(cube) ** 2).mean(axis=2).astype(np.float32)  # no predicted nulls: all clutter left
>>> power, nulls, unsup = raw.copy(), np.zeros(shape[:2], np.int8), np.zeros(shape[:2], bool)
>>> cnr = np.full(shape[:2], 900.0)  # the measured clutter level: 30 dB everywhere
>>> cells, _ = adaptive_nulls(cube, np.ones(4, np.complex64), cnr, 1.0, power, nulls, unsup)
>>> bool(cells.all()), int(nulls[20, 16]), round(float(power.mean()), 1)  # one null each, noise left
(True, 1, 1.0)
"""

from __future__ import annotations

import numpy as np
from numba import njit

from skyradar.process.top_eigen import eigen_scratch, top_eigenpairs, top_two_steps

__all__ = ["adaptive_nulls", "ring_whitening", "ADAPTIVE_WINDOW", "ADAPTIVE_GATE", "EIGEN_EDGE", "RING_CLIP"]

ADAPTIVE_WINDOW = (5, 5, 2, 2)  # half sizes (range, Doppler) of the training window, then of its guard
ADAPTIVE_GATE = 2.0  # ring mean after the predicted nulls, in floors, above which the prediction failed
EIGEN_EDGE = 2.0  # eigenvalue of the ring covariance, in floors, above which a direction is clutter
RING_CLIP = 8.0  # ring pixels count at most this many floors in the test: a target's lobes do not pass it


@njit(cache=True)
def _sat_row(cube, inv_gain, hd, r, prev, out, row, z):  # pragma: no cover - compiled
    # Row r + 1 of the summed-area table of each cell's packed covariance z z^H (z = cube * inv_gain):
    # n_k real diagonal entries, then the upper triangle's (re, im) pairs row by row (the layout of
    # skyradar.process.clutter), Doppler padded by wrapping: out = prev (row r) + row r's running sums.
    n_d, n_k = cube.shape[1], cube.shape[2]
    n_q = n_k * n_k
    w = n_d + 2 * hd
    for q in range(n_q):
        row[0, q] = 0.0
    for c in range(w):
        d = c - hd  # wrapped into 0..n_d-1 by steps of n_d (one at most when hd < n_d): no integer division
        while d < 0:
            d += n_d
        while d >= n_d:
            d -= n_d
        for k in range(n_k):
            z[k] = complex(cube[r, d, k]) * complex(inv_gain[k])
        p = n_k
        for i in range(n_k):
            row[c + 1, i] = row[c, i] + z[i].real * z[i].real + z[i].imag * z[i].imag
            for j in range(i + 1, n_k):
                x = z[i] * np.conj(z[j])
                row[c + 1, p] = row[c, p] + x.real
                row[c + 1, p + 1] = row[c, p + 1] + x.imag
                p += 2
    for c in range(w + 1):
        for q in range(n_q):
            out[c, q] = prev[c, q] + row[c, q]


@njit(cache=True)
def _packed_sat(cube, inv_gain, hd):  # pragma: no cover - compiled
    # The whole summed-area table (n_r + 1, n_d + 2 hd + 1, n_k^2) of _sat_row's packed covariances:
    # the reference the rolling table of _adapt is tested against.
    n_r, n_d, n_k = cube.shape
    sat = np.zeros((n_r + 1, n_d + 2 * hd + 1, n_k * n_k))
    row, z = np.zeros((n_d + 2 * hd + 1, n_k * n_k)), np.empty(n_k, np.complex128)
    for r in range(n_r):
        _sat_row(cube, inv_gain, hd, r, sat[r], sat[r + 1], row, z)
    return sat


@njit(cache=True)
def _box(sat, r, d, hr, hd, pad, n_r, q):  # pragma: no cover - compiled
    # Sum of entry q over rows r-hr..r+hr (truncated) and Doppler d-hd..d+hd (wrapped; padded by `pad`).
    lo, hi = max(r - hr, 0), min(r + hr + 1, n_r)
    a, b = d + pad - hd, d + pad + hd + 1
    return sat[hi, b, q] - sat[lo, b, q] - sat[hi, a, q] + sat[lo, a, q]


@njit(cache=True)
def _image_sat(image, hd, clip):  # pragma: no cover - compiled
    # Summed-area table of min(image, clip), Doppler padded by wrapping.
    n_r, n_d = image.shape
    sat = np.zeros((n_r + 1, n_d + 2 * hd + 1, 1))
    for r in range(n_r):
        run = 0.0
        for c in range(n_d + 2 * hd):
            run += min(image[r, (c - hd) % n_d], clip)
            sat[r + 1, c + 1, 0] = sat[r, c + 1, 0] + run
    return sat


@njit(cache=True)
def _candidates(power, cnr, gate, level, clip, window):  # pragma: no cover - compiled
    # Cells with measured clutter whose ring mean of the (predicted-)projected image, each pixel
    # clipped at `clip` (W), exceeds `level` (W); flat indices and the unclipped ring means.
    hr, hd, gr, gd = window
    n_r, n_d = power.shape
    sat = _image_sat(power, hd, clip)
    idx = np.empty(n_r * n_d, np.int64)
    n = 0
    for r in range(n_r):
        rows = min(r + hr + 1, n_r) - max(r - hr, 0)
        guard = min(r + gr + 1, n_r) - max(r - gr, 0)
        count = rows * (2 * hd + 1) - guard * (2 * gd + 1)
        if count < 16:  # 4 samples a channel at least
            continue
        for d in range(n_d):
            if cnr[r, d] > gate:
                ring = _box(sat, r, d, hr, hd, hd, n_r, 0) - _box(sat, r, d, gr, gd, hd, n_r, 0)
                if ring > level * count:
                    idx[n] = r * n_d + d
                    n += 1
    mean = np.empty(n)
    if n > 0:
        sat = _image_sat(power, hd, np.inf)
        for c in range(n):
            r, d = idx[c] // n_d, idx[c] % n_d
            rows = min(r + hr + 1, n_r) - max(r - hr, 0)
            guard = min(r + gr + 1, n_r) - max(r - gr, 0)
            ring = _box(sat, r, d, hr, hd, hd, n_r, 0) - _box(sat, r, d, gr, gd, hd, n_r, 0)
            mean[c] = ring / (rows * (2 * hd + 1) - guard * (2 * gd + 1))
    return idx[:n], mean


@njit(cache=True)
def _ring_direct(cube, inv_gain, r, d, window, a):  # pragma: no cover - compiled
    # _ring_matrix summed over the ring's snapshots directly.
    hr, hd, gr, gd = window
    n_r, n_d, n_k = cube.shape
    z = np.empty(n_k, np.complex128)
    a[:, :] = 0.0
    count = 0
    for rr in range(max(r - hr, 0), min(r + hr + 1, n_r)):
        for dd in range(d - hd, d + hd + 1):
            if abs(rr - r) <= gr and abs(dd - d) <= gd:
                continue
            for k in range(n_k):
                z[k] = complex(cube[rr, dd % n_d, k]) * complex(inv_gain[k])
            for i in range(n_k):
                for j in range(i, n_k):
                    a[i, j] += z[i] * np.conj(z[j])
            count += 1
    trace = 0.0
    for i in range(n_k):
        for j in range(i, n_k):
            a[i, j] /= count
            a[j, i] = np.conj(a[i, j])
        trace += a[i, i].real
    return trace


@njit(cache=True)
def _slot_box(sat, lo, hi, d, hd, pad, q):  # pragma: no cover - compiled
    # _box with the table's rows given as slots (lo, hi) of a rolling table.
    a, b = d + pad - hd, d + pad + hd + 1
    return sat[hi, b, q] - sat[lo, b, q] - sat[hi, a, q] + sat[lo, a, q]


@njit(cache=True)
def _ring_matrix(sat, r, d, window, n_r, a, rows, scale):  # pragma: no cover - compiled
    # The ring's sample covariance of cell (r, d) times `scale` into a (n_k, n_k) from the packed
    # sums; its trace. Table row t is held in slot t % rows (rows = n_r + 1: the whole table; fewer:
    # a rolling one that holds at least the 2 hr + 2 rows around r). The sums are scaled by one real
    # factor, scale / count (numba divides a complex number by a real one as complex division).
    hr, hd, gr, gd = window
    n_k = a.shape[0]
    lo, hi = max(r - hr, 0), min(r + hr + 1, n_r)
    g_lo, g_hi = max(r - gr, 0), min(r + gr + 1, n_r)
    factor = scale / ((hi - lo) * (2 * hd + 1) - (g_hi - g_lo) * (2 * gd + 1))
    lo, hi, g_lo, g_hi = lo % rows, hi % rows, g_lo % rows, g_hi % rows
    trace = 0.0
    for i in range(n_k):
        box = _slot_box(sat, lo, hi, d, hd, hd, i) - _slot_box(sat, g_lo, g_hi, d, gd, hd, i)
        a[i, i] = box * factor
        trace += box * factor
    p = n_k
    for i in range(n_k):
        for j in range(i + 1, n_k):
            re = _slot_box(sat, lo, hi, d, hd, hd, p) - _slot_box(sat, g_lo, g_hi, d, gd, hd, p)
            im = _slot_box(sat, lo, hi, d, hd, hd, p + 1) - _slot_box(sat, g_lo, g_hi, d, gd, hd, p + 1)
            a[i, j] = complex(re * factor, im * factor)
            a[j, i] = complex(re * factor, -im * factor)
            p += 2
    return trace


@njit(cache=True)
def _adapt(
    cube,
    inv_gain,
    cand,
    ring_mean,
    inv_floor,
    max_nulls,
    edge,
    window,
    power,
    nulls,
    unsuppressed,
    mask,
    vectors,
):  # pragma: no cover - compiled
    # Per candidate: ring covariance, its max_nulls strongest eigen-pairs (warm from the previous
    # candidate), nulls on those above `edge` floors when they leave less over the ring than the
    # prediction did, then |P z|^2 / L of the cell itself.
    n_r, n_d, n_k = cube.shape
    hr, hd, gr, gd = window
    # A few cells: their rings summed directly; many: sliding sums over the whole frame (cheaper
    # past about one ring sample per frame cell), from a rolling summed-area table: the candidates
    # come in range order, so only the 2 hr + 2 table rows around the current one are held (in the
    # second-level cache, where the whole table, 11 MB for a prototype frame, is not), each row
    # built once and from the same sums as the whole table.
    # (An empty table, not None, marks the direct sums: an optional array costs a check per access.)
    direct = cand.size * (2 * hr + 1) * (2 * hd + 1) <= n_r * n_d
    rows = 2 * hr + 2
    n_q = n_k * n_k
    sat = np.zeros((0, 0, 0) if direct else (rows, n_d + 2 * hd + 1, n_q))
    row = np.zeros((n_d + 2 * hd + 1, n_q))
    z_row = np.empty(n_k, np.complex128)
    built = 0  # table rows 0..built are in their slots (row 0, zeros, in slot 0)
    a = np.empty((n_k, n_k), np.complex128)
    v = np.eye(n_k, max_nulls).astype(np.complex128)
    lam = np.empty(max_nulls)
    z = np.empty(n_k, np.complex128)
    scratch = eigen_scratch(n_k, max_nulls)
    w, vu, wu = scratch[0], scratch[1], scratch[2]
    for c in range(cand.size):
        r, d = cand[c] // n_d, cand[c] % n_d
        if direct:
            trace = _ring_direct(cube, inv_gain, r, d, window, a) * inv_floor
            for i in range(n_k):
                for j in range(n_k):
                    a[i, j] *= inv_floor  # in floors
        else:
            while built < min(r + hr + 1, n_r):
                _sat_row(cube, inv_gain, hd, built, sat[built % rows], sat[(built + 1) % rows], row, z_row)
                built += 1
            trace = _ring_matrix(sat, r, d, window, n_r, a, rows, inv_floor)  # in floors
        # a in floors: a null leaves 1e-4 of the noise of its direction
        if max_nulls == 2:
            top_two_steps(a, v, lam, edge, 1e-4, 50, w, vu, wu)
        else:
            top_eigenpairs(a, v, lam, edge, 1e-4, 50, scratch)
        m = 0
        for i in range(max_nulls):
            if lam[i] > edge:
                m = i + 1
        if m == 0:
            continue
        kept = trace
        for i in range(m):
            kept -= lam[i]
        if not kept / (n_k - m) < ring_mean[c] * inv_floor:  # the prediction leaves less over the ring
            continue
        total = 0.0
        for k in range(n_k):
            z[k] = complex(cube[r, d, k]) * complex(inv_gain[k])
            total += z[k].real * z[k].real + z[k].imag * z[k].imag
        for i in range(m):
            t = 0j
            for k in range(n_k):
                t += np.conj(v[k, i]) * z[k]
            total -= t.real * t.real + t.imag * t.imag
        power[r, d] = max(total, 0.0) / (n_k - m)
        nulls[r, d] = m
        # Clutter left: the eigenvalues past the nulls over the noise (their sum less one floor each).
        unsuppressed[r, d] = (kept - (n_k - m)) / n_k > 1.0
        mask[r, d] = True
        for i in range(n_k):
            for j in range(n_k):
                vectors[r, d, i, j] = v[i, j] if j < max_nulls else 0.0


def adaptive_nulls(
    cube: np.ndarray,
    inv_gain: np.ndarray,
    clutter_to_noise: np.ndarray,
    floor_w: float,
    power: np.ndarray,
    nulls: np.ndarray,
    unsuppressed: np.ndarray,
    max_nulls: int = 2,
    gate: float = 3.0,
    window: tuple[int, int, int, int] = ADAPTIVE_WINDOW,
) -> tuple[np.ndarray, np.ndarray]:
    """Replace the predicted nulls by adaptive ones where the prediction left clutter (in place).

    Parameters
    ----------
    cube : ndarray (n_range, n_doppler, n_rx), complex64
        One frame, uncalibrated (amplitude, sqrt(W)).
    inv_gain : ndarray (n_rx,), complex
        Inverse calibration gains: ``z = cube * inv_gain`` is calibrated.
    clutter_to_noise : ndarray (n_range, n_doppler)
        The predicted pass's measured clutter level (power ratio, linear); cells above ``gate``
        are candidates.
    floor_w : float
        The frame's thermal noise per pixel (channel mean), W.
    power, nulls, unsuppressed : ndarray (n_range, n_doppler)
        The predicted pass's projected image (W, channel count ``n_rx - nulls``), null count and
        unsuppressed flags, overwritten in the cells that take adaptive nulls.
    max_nulls : int
        Most adaptive nulls per cell.
    gate : float
        Clutter-to-noise ratio (linear) above which a cell is a candidate.
    window : (int, int, int, int)
        Half sizes (range, Doppler) of the training window, then of its guard, bins.

    Returns
    -------
    adaptive : ndarray of bool (n_range, n_doppler)
        Cells whose nulls are now adaptive.
    vectors : ndarray (n_range, n_doppler, n_rx, n_rx), complex64
        Their ring covariance's strongest eigenvectors, columns by decreasing eigenvalue (the
        first ``nulls`` are nulled; columns past ``max_nulls`` are 0); undefined where
        ``adaptive`` is False.

    Examples
    --------
    Clutter from two directions the prediction missed (30 dB and 26 dB over unit noise): every
    cell takes two nulls, whose vectors span both directions, and the noise is left:

    >>> rng = np.random.default_rng(1)
    >>> shape = (40, 32, 4)
    >>> def gauss(*s):
    ...     return (rng.standard_normal(s) + 1j * rng.standard_normal(s)) / np.sqrt(2)
    >>> u1, u2 = np.exp(1j * np.array([0.0, 1.0, 2.0, 3.0])), np.exp(-1j * np.array([0.0, 2.0, 4.0, 6.0]))
    >>> clutter = 30.0 * gauss(*shape[:2])[..., None] * u1 + 20.0 * gauss(*shape[:2])[..., None] * u2
    >>> cube = (gauss(*shape) + clutter).astype(np.complex64)
    >>> power = (np.abs(cube) ** 2).mean(axis=2).astype(np.float32)  # no predicted nulls
    >>> nulls, unsup = np.zeros(shape[:2], np.int8), np.zeros(shape[:2], bool)
    >>> cnr = np.full(shape[:2], 1300.0)
    >>> cells, vectors = adaptive_nulls(cube, np.ones(4, np.complex64), cnr, 1.0, power, nulls, unsup)
    >>> bool(cells.all()), np.unique(nulls).tolist(), round(float(power.mean()), 1)
    (True, [2], 1.0)
    >>> basis = np.linalg.qr(vectors[20, 16, :, :2])[0]
    >>> [round(float(np.linalg.norm(basis.conj().T @ u) ** 2 / 4), 4) for u in (u1, u2)]
    [1.0, 1.0]
    """
    n_r, n_d, n_k = cube.shape
    mask = np.zeros((n_r, n_d), np.bool_)
    vectors = np.empty((n_r, n_d, n_k, n_k), np.complex64)
    window = (int(window[0]), int(window[1]), int(window[2]), int(window[3]))
    level, clip = ADAPTIVE_GATE * floor_w, RING_CLIP * floor_w
    cand, ring_mean = _candidates(power, clutter_to_noise, float(gate), level, clip, window)
    if cand.size:
        z = np.ascontiguousarray(cube, np.complex64)
        rule = (1.0 / floor_w, int(max_nulls), EIGEN_EDGE, window)
        out = (power, nulls, unsuppressed, mask, vectors)
        _adapt(z, np.asarray(inv_gain, np.complex64), cand, ring_mean, *rule, *out)
    return mask, vectors


@njit(cache=True)
def _whitening(cube, inv_gain, rr, dd, window, inv_floor, out):  # pragma: no cover - compiled
    n_k = cube.shape[2]
    a = np.empty((n_k, n_k), np.complex128)
    for c in range(rr.size):
        _ring_direct(cube, inv_gain, rr[c], dd[c], window, a)
        out[c] = np.linalg.inv(a * inv_floor)
    return out


def ring_whitening(
    cube: np.ndarray,
    inv_gain: np.ndarray,
    range_index: np.ndarray,
    doppler_index: np.ndarray,
    floor_w: float,
    window: tuple[int, int, int, int] = ADAPTIVE_WINDOW,
) -> np.ndarray:
    """``floor_w R^-1`` (n, n_rx, n_rx) of the given cells, ``R`` their ring's sample covariance.

    The whitening an adaptive cell's direction is estimated through
    (:func:`skyradar.process.clutter_frames.detect_suppressed`): the projected matched filter
    ``|s^H W z|^2 / (s^H W s)`` with ``W = R^-1`` is the adaptive matched filter (Robey et al.,
    IEEE Trans. AES 28(1), 1992), whose best ``s`` weighs every direction by the clutter the ring
    holds there, also what the nulls left; the nulls' projector weighs the directions left equally.

    Parameters
    ----------
    cube : ndarray (n_range, n_doppler, n_rx), complex64
        One frame, uncalibrated (amplitude, sqrt(W)).
    inv_gain : ndarray (n_rx,), complex
        Inverse calibration gains: ``z = cube * inv_gain`` is calibrated.
    range_index, doppler_index : ndarray of int (n,)
        The cells.
    floor_w : float
        The frame's thermal noise per pixel (channel mean), W; ``W`` is in units of it.
    window : (int, int, int, int)
        Half sizes (range, Doppler) of the training window, then of its guard, bins.

    Returns
    -------
    ndarray (n, n_rx, n_rx), complex128
        ``floor_w R^-1`` per cell (Hermitian).

    Examples
    --------
    Unit noise and clutter 30 dB over it from ``u``: ``R ~ I + 900 u u^H``, so ``W`` keeps a
    direction orthogonal to ``u`` (``w^H W w ~ |w|^2 = 4``) and suppresses ``u`` itself
    (``u^H W u ~ 4 / 3601``):

    >>> rng = np.random.default_rng(0)
    >>> shape = (40, 32, 4)
    >>> def gauss(*s):
    ...     return (rng.standard_normal(s) + 1j * rng.standard_normal(s)) / np.sqrt(2)
    >>> u = np.exp(1j * np.array([0.0, 1.0, 2.0, 3.0]))
    >>> cube = (gauss(*shape) + 30.0 * gauss(*shape[:2])[..., None] * u).astype(np.complex64)
    >>> w = np.array([1.0, -1.0, 1.0, -1.0]) * u  # orthogonal to u
    >>> W = ring_whitening(cube, np.ones(4, np.complex64), np.array([20]), np.array([16]), 1.0)[0]
    >>> round(float((u.conj() @ W @ u).real), 3), round(float((w.conj() @ W @ w).real), 1)
    (0.001, 3.8)
    """
    rr, dd = (np.ascontiguousarray(x, np.int64) for x in (range_index, doppler_index))
    out = np.empty((rr.size, cube.shape[2], cube.shape[2]), np.complex128)
    z = np.ascontiguousarray(cube, np.complex64)
    window = (int(window[0]), int(window[1]), int(window[2]), int(window[3]))
    return _whitening(z, np.asarray(inv_gain, np.complex64), rr, dd, window, 1.0 / floor_w, out)
