"""Two-dimensional CFAR over range-Doppler power images, wrapping in Doppler.

Noise pixels of a non-coherent mean over L channels follow Gamma(L, 1/L) (unit mean). For cell
averaging the ratio of the cell under test to the training mean is F(2L, 2NL) distributed, so
the threshold factor is exact for N training cells; ordered statistic (OS) CFAR integrates the
false-alarm probability over the Beta law of the order statistic.

Spur-aware cell averaging: pixels flagged in ``exclude`` (a spur map: the zero-Doppler line,
near-range leakage, fixed spurs) are left out of every training window and can never be hits,
so a bright fixed line does not blind its Doppler neighbours. The factor then uses the number of
training cells actually left in each window.

Examples
--------
>>> rng = np.random.default_rng(0)
>>> power = rng.exponential(1.0, (200, 200)).astype(np.float32)
>>> hits, noise = cfar_2d(power, pfa=1e-3)
>>> bool(abs(hits.mean() - 1e-3) < 5e-4), bool(abs(noise.mean() - 1.0) < 0.05)
(True, True)
"""

from __future__ import annotations

from functools import lru_cache
from typing import Literal

import cv2
import numpy as np
from numba import njit
from scipy import ndimage  # stats, integrate, optimize: imported where used (scipy.stats alone ~0.5 s)

from skyradar.errors import InputError
from skyradar.rx_layouts import MAX_RX

__all__ = ["cfar_factor", "cfar_2d", "cfar_2d_floor", "training_cells"]


def training_cells(guard: tuple[int, int], train: tuple[int, int]) -> int:
    """Training cells of a 2-D CA-CFAR window, the window less its guard block (guard 2x2, train 4x8: 248).

    Parameters
    ----------
    guard : (int, int)
        Guard cells on each side of the cell under test (range, Doppler), bins.
    train : (int, int)
        Training cells beyond the guard cells on each side (range, Doppler), bins.

    Returns
    -------
    int
        ``(2 (gr + tr) + 1) (2 (gd + td) + 1) - (2 gr + 1) (2 gd + 1)``.

    Examples
    --------
    >>> training_cells((2, 2), (4, 8)), training_cells((0, 0), (1, 1))  # 13 x 21 - 5 x 5; 3 x 3 - 1
    (248, 8)
    """
    (gr, gd), (tr, td) = guard, train
    return (2 * (gr + tr) + 1) * (2 * (gd + td) + 1) - (2 * gr + 1) * (2 * gd + 1)


def _window(shape: tuple[int, ...], guard, train) -> tuple[int, ...]:
    """Guard and training half-widths, their sums and the training cells, checked against the shape."""
    gr, gd = (int(v) for v in guard)
    tr, td = (int(v) for v in train)
    hr, hd = gr + tr, gd + td
    if min(gr, gd, tr, td) < 0 or hd >= shape[1] // 2 or hr >= shape[0] // 2:
        raise InputError(f"cfar: guard {guard} / train {train} do not fit an image of shape {shape}")
    return gr, gd, tr, td, hr, hd, training_cells((gr, gd), (tr, td))


@lru_cache(maxsize=64)
def _os_factor(pfa: float, n_train: int, rank: int, n_int: int) -> float:
    from scipy import integrate, optimize, stats

    cut = stats.gamma(n_int, scale=1.0 / n_int)
    order = stats.beta(rank, n_train - rank + 1)

    def pfa_of(log_alpha: float) -> float:
        alpha = np.exp(log_alpha)

        # Pfa = E_q[ S(alpha * F^-1(q)) ], q the rank-th order statistic of N uniforms (Beta law).
        def integrand(q: float) -> float:
            return order.pdf(q) * cut.sf(alpha * cut.ppf(q))

        lo, hi = order.ppf(1e-12), order.ppf(1 - 1e-12)
        val, _ = integrate.quad(integrand, lo, hi, points=[order.mean()], limit=200, epsabs=0.0, epsrel=1e-8)
        return float(np.log(max(val, 1e-300)) - np.log(pfa))

    return float(np.exp(optimize.brentq(pfa_of, np.log(1e-3), np.log(1e4), xtol=1e-6)))


@lru_cache(maxsize=256)
def cfar_factor(
    pfa: float, n_train: int, n_integrated: int = 1, kind: Literal["ca", "os"] = "ca", rank: int | None = None
) -> float:
    """Threshold multiplier alpha so that ``P(cut > alpha * noise_estimate) = pfa`` in pure noise.

    Noise pixels are means of ``n_integrated`` unit exponentials (Gamma(L, 1/L)). For cell averaging
    the ratio of the cell under test to the training mean is F(2L, 2NL) distributed, so
    ``alpha = F.isf(pfa, 2L, 2NL)`` exactly. For ordered statistic (rank k of N) the false-alarm
    probability is integrated over the Beta(k, N-k+1) law of the order statistic and solved for alpha.

    Examples
    --------
    >>> round(cfar_factor(1e-6, 16), 3) == round(16 * (1e-6 ** (-1 / 16) - 1), 3)  # classic CA formula
    True
    """
    from scipy import stats

    if not 0.0 < pfa < 1.0:
        raise InputError(f"cfar: field 'pfa' must be in (0, 1), got {pfa}")
    if n_train < 1:
        raise InputError(f"cfar: need at least one training cell, got {n_train}")
    if kind == "ca":
        return float(stats.f.isf(pfa, 2 * n_integrated, 2 * n_train * n_integrated))
    if kind == "os":
        k = int(round(0.75 * n_train)) if rank is None else int(rank)
        if not 1 <= k <= n_train:
            raise InputError(f"cfar: field 'rank' must be in [1, {n_train}], got {k}")
        return _os_factor(float(pfa), int(n_train), k, int(n_integrated))
    raise InputError(f"cfar: field 'kind' must be 'ca' or 'os', got {kind!r}")


def _pad(image: np.ndarray, pr: int, pd: int) -> np.ndarray:
    """Pad by ``pr`` rows (range edges reflect) and ``pd`` columns (Doppler wraps, aliasing)."""
    n_r, n_d = image.shape
    out = np.empty((n_r + 2 * pr, n_d + 2 * pd), image.dtype)
    out[pr : pr + n_r, pd : pd + n_d] = image
    if pd:
        out[pr : pr + n_r, :pd] = image[:, n_d - pd :]
        out[pr : pr + n_r, pd + n_d :] = image[:, :pd]
    if pr:
        out[:pr] = out[2 * pr : pr : -1]
        out[pr + n_r :] = out[pr + n_r - 2 : n_r - 2 : -1]
    return out


def _box_sum(padded: np.ndarray, hr: int, hd: int, pr: int, pd: int, shape: tuple[int, int]) -> np.ndarray:
    s = cv2.boxFilter(
        padded, cv2.CV_32F, (2 * hd + 1, 2 * hr + 1), normalize=False, borderType=cv2.BORDER_REPLICATE
    )
    return s[pr : pr + shape[0], pd : pd + shape[1]]


_MASK_CACHE: dict[tuple, tuple] = {}


def _mask_setup(
    exclude: np.ndarray, guard: tuple[int, int], half: tuple[int, int], table: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per-pixel weights, 1/training count, threshold factor and usable flag of an exclusion mask.

    Cached for read-only masks (``SpurMap.mask``): a spur map is the same for every frame.
    """
    key = (id(exclude), exclude.shape, guard, half, id(table))
    hit = _MASK_CACHE.get(key)
    if hit is not None and hit[0] is exclude and hit[1] is table:
        return hit[2:]
    (gr, gd), (hr, hd) = guard, half
    valid = (~exclude).astype(np.float32)
    v_pad = _pad(valid, hr, hd)
    count = _box_sum(v_pad, hr, hd, hr, hd, exclude.shape) - _box_sum(v_pad, gr, gd, hr, hd, exclude.shape)
    n_cells = np.clip(np.rint(count).astype(np.int64), 0, table.size - 1)
    setup = (valid, 1.0 / np.maximum(count, np.float32(1.0)), table[n_cells], (valid > 0) & (n_cells > 0))
    if not exclude.flags.writeable:  # a writeable mask could change under the same identity
        if len(_MASK_CACHE) > 8:
            _MASK_CACHE.clear()
        _MASK_CACHE[key] = (exclude, table, *setup)
    return setup


def _ca(
    power: np.ndarray,
    exclude: np.ndarray | None,
    guard: tuple[int, int],
    half: tuple[int, int],
    table: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    (gr, gd), (hr, hd) = guard, half
    n_train = table.size - 1
    if exclude is None:
        padded = _pad(power, hr, hd)
        total = _box_sum(padded, hr, hd, hr, hd, power.shape) - _box_sum(padded, gr, gd, hr, hd, power.shape)
        noise = np.maximum(total / np.float32(n_train), np.float32(1e-38))
        return power > table[n_train] * noise, noise
    if exclude.shape != power.shape:
        raise InputError(f"cfar: field 'exclude' has shape {exclude.shape}, image has {power.shape}")
    valid, inv_count, alpha, usable = _mask_setup(np.asarray(exclude, bool), (gr, gd), (hr, hd), table)
    p_pad = _pad(power * valid, hr, hd)
    total = _box_sum(p_pad, hr, hd, hr, hd, power.shape) - _box_sum(p_pad, gr, gd, hr, hd, power.shape)
    noise = np.maximum(total * inv_count, np.float32(1e-38))
    return (power > alpha * noise) & usable, noise


def cfar_2d(
    power: np.ndarray,
    guard: tuple[int, int] = (2, 2),
    train: tuple[int, int] = (4, 8),
    pfa: float = 2e-8,
    kind: Literal["ca", "os"] = "ca",
    n_integrated: int = 1,
    rank: int | None = None,
    exclude: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Two-dimensional CFAR over a (range, Doppler) power image, wrapping in Doppler.

    Parameters
    ----------
    power : ndarray, shape (n_range, n_doppler)
        Power image (linear, e.g. from :func:`integrate_channels`).
    guard : (int, int)
        Guard cells on each side of the cell under test (range, Doppler).
    train : (int, int)
        Training cells beyond the guard cells on each side (range, Doppler).
    pfa : float
        False-alarm probability per pixel in homogeneous noise.
    kind : {"ca", "os"}
        Cell averaging (mean of the training ring) or ordered statistic (its ``rank``-th value;
        default 3/4 of the ring), which resists bright neighbours. OS uses scipy's rank filter
        and is about 100 times slower than CA (a few hundred ms per prototype frame).
    n_integrated : int
        Channels averaged non-coherently into each pixel.
    rank : int, optional
        Order statistic of the ring for ``kind="os"`` (1 is the smallest); default 3/4 of the ring.
    exclude : ndarray of bool, optional
        Pixels (e.g. a spur map) kept out of the training cells and out of the hits.

    Returns
    -------
    hits : ndarray of bool
        Pixels above ``alpha * noise``.
    noise : ndarray of float32
        Noise estimate per pixel, W.

    Examples
    --------
    One bright pixel on a flat unit background is the only hit; its training ring holds the
    background, so its noise estimate is exactly 1:

    >>> power = np.ones((64, 64), np.float32)
    >>> power[20, 30] = 1000.0
    >>> hits, noise = cfar_2d(power, pfa=1e-6)
    >>> np.argwhere(hits).tolist(), float(noise[20, 30])
    ([[20, 30]], 1.0)
    >>> int(cfar_2d(power, pfa=1e-6, exclude=power > 10.0)[0].sum())  # an excluded pixel is never a hit
    0
    """
    power = np.asarray(power, dtype=np.float32)
    gr, gd, tr, td, hr, hd, n_train = _window(power.shape, guard, train)
    if not 0.0 < pfa < 1.0:  # the CA table below skips cfar_factor's check (pfa 5 gave NaN thresholds)
        raise InputError(f"cfar: field 'pfa' must be in (0, 1), got {pfa}")
    if kind == "ca":
        table = _ca_factor_table(float(pfa), n_train, int(n_integrated))
        return _ca(power, exclude, (gr, gd), (hr, hd), table)
    alpha = cfar_factor(pfa, n_train, n_integrated, kind, rank)
    k = int(round(0.75 * n_train)) if rank is None else int(rank)
    return _os(power, exclude, (gr, gd), (tr, td), k, alpha)


def _os(power, exclude, guard: tuple[int, int], train: tuple[int, int], k: int, alpha: float):
    """OS-CFAR: the ``k``-th smallest training cell (scipy rank filter) as the noise estimate."""
    (gr, gd), (tr, td) = guard, train
    hr, hd = gr + tr, gd + td
    if exclude is not None:
        # Fill excluded pixels with the image median, a noise-like value.
        power = np.where(exclude, np.median(power), power).astype(np.float32)
    padded = _pad(power, hr, hd)
    footprint = np.ones((2 * hr + 1, 2 * hd + 1), bool)
    footprint[tr : tr + 2 * gr + 1, td : td + 2 * gd + 1] = False
    full = ndimage.rank_filter(padded, k - 1, footprint=footprint, mode="nearest")
    noise = np.maximum(full[hr : hr + power.shape[0], hd : hd + power.shape[1]], np.float32(1e-38))
    hits = power > np.float32(alpha) * noise
    return (hits & ~exclude if exclude is not None else hits), noise


@lru_cache(maxsize=16)
def _ca_factor_table(pfa: float, n_max: int, n_integrated: int) -> np.ndarray:
    from scipy import stats

    n = np.arange(1, n_max + 1)
    return np.r_[np.inf, stats.f.isf(pfa, 2 * n_integrated, 2 * n * n_integrated)].astype(np.float32)


@njit(cache=True)
def _ring(sat, i, j, hr, hd, gr, gd):  # pragma: no cover - compiled
    # Sum over the (2hr+1) x (2hd+1) window at padded (i + hr, j + hd) minus its guard block.
    outer = sat[i + 2 * hr + 1, j + 2 * hd + 1] - sat[i, j + 2 * hd + 1] - sat[i + 2 * hr + 1, j] + sat[i, j]
    a, b, c, d = i + hr - gr, i + hr + gr + 1, j + hd - gd, j + hd + gd + 1
    return outer - (sat[b, d] - sat[a, d] - sat[b, c] + sat[a, c])


@njit(cache=True)
def _floor_decide(
    power, sat_p, sat_c, sat_v, half, skip, big_l, table, floor, n_train, min_train, hits, noise, only
):  # pragma: no cover - compiled
    # Per pixel: plain CA for excluded cells, CA over the cells left (or the floor) for the others.
    # With `only` true, pixels whose `hits` is already False (no hit possible) are left as they are.
    hr, hd, gr, gd = half
    n_r, n_d = power.shape
    for i in range(n_r):
        for j in range(n_d):
            if only and not hits[i, j]:
                continue
            if skip[i, j]:
                n, est = n_train, _ring(sat_p, i, j, hr, hd, gr, gd) / n_train
            else:
                count = _ring(sat_v, i, j, hr, hd, gr, gd)
                n = min(int(count + 0.5), n_train)
                if n >= min_train:
                    est = _ring(sat_c, i, j, hr, hd, gr, gd) / count
                else:
                    n, est = 0, floor
            est = max(est, floor)
            noise[i, j] = est
            hits[i, j] = power[i, j] > table[big_l[i, j], n] * est


@njit(cache=True)
def _floor_sparse(power, skip, big_l, table, floor, half, n_train, min_n, hits, noise):  # pragma: no cover
    # _floor_decide with window sums taken only where a hit is possible: the smallest threshold any
    # pixel can have is the known-floor factor times the floor (every F-based factor is larger and
    # no estimate goes below the floor), and after suppression almost every pixel is below it.
    # Returns False when more than 1 % of the pixels could be hits (`hits` then holds that mask and
    # nothing is decided): summed-area tables are cheaper than direct window sums for so many.
    hr, hd, gr, gd = half
    n_r, n_d = power.shape
    n_cand = 0
    for i in range(n_r):
        for j in range(n_d):
            hits[i, j] = power[i, j] > table[big_l[i, j], 0] * floor
            n_cand += hits[i, j]
    if n_cand > n_r * n_d // 100:
        return False
    for i in range(n_r):
        for j in range(n_d):
            if not hits[i, j]:
                continue
            sp, sc, sv = 0.0, 0.0, 0
            for di in range(-hr, hr + 1):
                ii = i + di
                ii = -ii if ii < 0 else (2 * (n_r - 1) - ii if ii >= n_r else ii)  # reflect, as _pad
                for dj in range(-hd, hd + 1):
                    if abs(di) <= gr and abs(dj) <= gd:
                        continue
                    jj = (j + dj) % n_d
                    v = power[ii, jj]
                    sp += v
                    if not skip[ii, jj]:
                        sc += v
                        sv += 1
            if skip[i, j]:
                n, est = n_train, sp / n_train
            elif min(sv, n_train) >= min_n:
                n, est = min(sv, n_train), sc / sv
            else:
                n, est = 0, floor
            est = max(est, floor)
            noise[i, j] = est
            hits[i, j] = power[i, j] > table[big_l[i, j], n] * est
    return True


@lru_cache(maxsize=16)
def _floor_tables(pfa: float, n_max: int) -> np.ndarray:
    """``alpha[L, n]``: CA factor, Gamma(L, 1/L) cell, ``n`` training cells; ``n = 0``: known floor."""
    from scipy import stats

    n = np.arange(1, n_max + 1)
    rows = [np.full(n_max + 1, np.inf)]
    for big_l in range(1, MAX_RX + 1):
        known = stats.gamma.isf(pfa, big_l, scale=1.0 / big_l)  # noise mean known exactly
        rows.append(np.r_[known, stats.f.isf(pfa, 2 * big_l, 2 * n * big_l)])
    return np.asarray(rows, np.float32)


def cfar_2d_floor(
    power: np.ndarray,
    channels: np.ndarray,
    noise_floor_w: float,
    train_exclude: np.ndarray | None = None,
    guard: tuple[int, int] = (2, 2),
    train: tuple[int, int] = (4, 8),
    pfa: float = 2e-8,
    min_train: int = 16,
    noise_map: bool = True,
) -> tuple[np.ndarray, np.ndarray]:
    """CA-CFAR for a clutter-suppressed image: per-pixel channel count, training that skips clutter.

    Each pixel is a mean of ``channels[i, j]`` unit-noise channels (Gamma(L, 1/L) noise, see
    :mod:`skyradar.process.clutter_suppress`). Pixels in ``train_exclude`` (predicted clutter the
    suppression could not remove, the ground ridge) are left out of the training windows of the
    other pixels, so they cannot raise the threshold of a target beside them; they themselves keep
    plain CA-CFAR over their whole window. Noise estimates never go below the calibrated thermal
    floor ``noise_floor_w``; a window with fewer than ``min_train`` cells left uses the floor itself
    with the known-noise factor. Thresholds use the cell under test's
    ``L`` for both the cell and its training cells (exact where they agree).

    ``noise_map=False`` may return the noise estimate only where a hit was possible (NaN
    elsewhere): a pixel at or below the smallest threshold it could have (the known-floor factor
    times the floor) is decided without its window. The hits are the same; after suppression
    almost every pixel is such a one (``detect`` uses it). With more than 1 % of the pixels above
    that bound the full map is computed anyway (summed-area tables are then cheaper).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> power = rng.gamma(2.0, 0.5, (200, 200)).astype(np.float32)
    >>> hits, noise = cfar_2d_floor(power, np.full(power.shape, 2, np.int8), 1.0, pfa=1e-3)
    >>> bool(hits.mean() < 2e-3), bool(abs(np.median(noise) - 1.0) < 0.05)
    (True, True)
    """
    power = np.asarray(power, dtype=np.float32)
    gr, gd, tr, td, hr, hd, n_train = _window(power.shape, guard, train)
    if not 0.0 < pfa < 1.0:
        raise InputError(f"cfar: field 'pfa' must be in (0, 1), got {pfa}")
    table = _floor_tables(float(pfa), n_train)
    skip = np.zeros(power.shape, np.bool_) if train_exclude is None else np.asarray(train_exclude, np.bool_)
    big_l = np.ascontiguousarray(np.clip(channels, 1, MAX_RX), np.int8)
    floor = np.float32(noise_floor_w)
    hits = np.empty(power.shape, np.bool_)
    only = not noise_map
    noise = np.full(power.shape, np.nan, np.float32) if only else np.empty(power.shape, np.float32)
    half = (hr, hd, gr, gd)
    if only and _floor_sparse(power, skip, big_l, table, floor, half, n_train, min_train, hits, noise):
        return hits, noise
    valid = (~skip).astype(np.float32)
    # Summed-area tables (float64) of the padded images: every window sum is four lookups.
    sat_p, sat_c, sat_v = (
        cv2.integral(_pad(x, hr, hd), sdepth=cv2.CV_64F) for x in (power, power * valid, valid)
    )
    _floor_decide(
        power, sat_p, sat_c, sat_v, half, skip, big_l, table, floor, n_train, min_train, hits, noise, only
    )
    return hits, noise
