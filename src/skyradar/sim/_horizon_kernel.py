"""Compiled polar horizon of the terrain around the antenna, for the occlusion test.

For each azimuth bin and horizontal-range bin: the steepest slope (tan of the elevation angle)
of any terrain sample strictly closer along that azimuth. A facet is hidden when its own slope
is below that. Samples are taken a row of grid cells at a time: their positions one by one,
their bins and slopes (square roots, arctangents and divisions) in loops LLVM vectorises, and
the running maximum into the bins one by one again. :func:`horizon_at` gives single entries of
the same map (a target's line of sight) from only the cells that can reach that azimuth bin.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from skyradar.sim._elementary import fast_atan2, wrap_index

__all__ = ["horizon_map", "horizon_at"]


@njit(inline="always")
def _bilinear(p, i, j, u, w, out, k):
    for c in range(3):
        out[c, k] = (
            (1 - u) * (1 - w) * p[i, j, c]
            + (1 - u) * w * p[i, j + 1, c]
            + u * (1 - w) * p[i + 1, j, c]
            + u * w * p[i + 1, j + 1, c]
        )


@njit(inline="always")
def _cell_in_front(p_ned, rot_n2a, i, j):
    for ci in range(2):
        for cj in range(2):
            xa = (
                rot_n2a[0, 0] * p_ned[i + ci, j + cj, 0]
                + rot_n2a[0, 1] * p_ned[i + ci, j + cj, 1]
                + rot_n2a[0, 2] * p_ned[i + ci, j + cj, 2]
            )
            if xa > 0.0:
                return True
    return False


@njit(error_model="numpy")
def _horizontal_rows(h_, n_, e_):
    for m in range(h_.shape[0]):
        h_[m] = math.sqrt(n_[m] * n_[m] + e_[m] * e_[m])


@njit(error_model="numpy")
def _azimuth_row(a_, n_, e_, az_bin_rad):
    # Bin index as a float (exact: the value is a small non-negative integer); int() of a
    # non-negative number is its floor.
    for m in range(a_.shape[0]):
        a_[m] = math.floor((fast_atan2(e_[m], n_[m]) + math.pi) / az_bin_rad)


@njit(error_model="numpy")
def _range_slope_rows(k_, slope_, h_, d_, h_bin_m, n_h):
    for m in range(k_.shape[0]):
        h = h_[m]
        k_[m] = min(math.floor(h / h_bin_m), n_h - 1.0)
        slope_[m] = -d_[m] / max(h, 1e-9)


@njit(error_model="numpy")
def _spread_row(spread_, h_, sample_m, az_bin_rad, max_spread):
    # Each sample stands for a patch sample_m wide: the azimuth bins it spans either side.
    for m in range(spread_.shape[0]):
        spread_[m] = min(math.floor(0.5 * sample_m / (max(h_[m], 1.0) * az_bin_rad)) + 1.0, max_spread)


@njit(error_model="numpy")
def _raise_bins(best, pts, n_pts, r_lim, n_az):
    # pts rows: north, east, down, h, azimuth bin, range bin, slope, spread.
    for m in range(n_pts):
        n, e = pts[0, m], pts[1, m]
        if n * n + e * e > r_lim * r_lim:
            continue
        ia, k, slope, spread = wrap_index(int(pts[4, m]), n_az), int(pts[5, m]), pts[6, m], int(pts[7, m])
        for da in range(-spread, spread + 1):
            ib = wrap_index(ia + da, n_az)
            if slope > best[ib, k]:
                best[ib, k] = slope


@njit(error_model="numpy")
def _cell_samples(p_ned, i, j, nsub_r, nsub_c, pts, n):
    """The nsub_r x nsub_c bilinear samples of cell (i, j) into ``pts`` from row ``n``; the next free row."""
    for a in range(nsub_r):
        u = (a + 0.5) / nsub_r
        for b in range(nsub_c):
            _bilinear(p_ned, i, j, u, (b + 0.5) / nsub_c, pts, n)
            n += 1
    return n


@njit(error_model="numpy")
def _row_samples(p_ned, rot_n2a, i, nsub_r, nsub_c, pts):
    """Samples of the cells of grid row ``i`` in front of the antenna plane into ``pts``."""
    n = 0
    for j in range(p_ned.shape[1] - 1):
        if not _cell_in_front(p_ned, rot_n2a, i, j):
            continue
        n = _cell_samples(p_ned, i, j, nsub_r, nsub_c, pts, n)
    return n


@njit(parallel=True, cache=True, error_model="numpy")
def horizon_map(p_ned, rot_n2a, nsub_r, nsub_c, r_lim, az_bin_rad, h_bin_m, n_az, n_h, n_blocks, sample_m):
    """Steepest slope (tan of elevation) seen so far along each azimuth, before each range bin.

    ``p_ned`` holds grid points relative to the antenna (NED, m). Returns an (n_az, n_h) array:
    a facet in bin (a, k) is visible if its slope -down/horizontal is at least ``out[a, k]``. Only
    cells in front of the antenna plane count: a ray from the antenna to a point in front
    never passes behind the plane. Each sample stands for a patch ``sample_m`` wide, so it
    raises every azimuth bin that patch spans (near samples span many bins): without this,
    narrow bins between sparse near samples would let far terrain show through a ridge.
    """
    ny, nx = p_ned.shape[0], p_ned.shape[1]
    best = np.full((n_blocks, n_az, n_h), -np.inf, dtype=np.float32)
    for blk in prange(n_blocks):
        pts = np.empty((8, max(nx - 1, 1) * nsub_r * nsub_c))
        for i in range(blk, ny - 1, n_blocks):  # interleaved rows: blocks share the work evenly
            n = _row_samples(p_ned, rot_n2a, i, nsub_r, nsub_c, pts)
            n_, e_, d_, h_ = pts[0][:n], pts[1][:n], pts[2][:n], pts[3][:n]
            _horizontal_rows(h_, n_, e_)
            _azimuth_row(pts[4][:n], n_, e_, az_bin_rad)
            _range_slope_rows(pts[5][:n], pts[6][:n], h_, d_, h_bin_m, float(n_h))
            _spread_row(pts[7][:n], h_, sample_m, az_bin_rad, float(n_az // 4))
            _raise_bins(best[blk], pts, n, r_lim, n_az)
    # Exclusive running maximum along range: what lies strictly closer can hide a facet.
    # Serial: a few 1e4-1e5 comparisons cost less than a second fork-join of the threads,
    # which on a busy machine can wait a whole scheduler tick for a descheduled thread.
    out = np.empty((n_az, n_h), dtype=np.float32)
    for ia in range(n_az):
        running = -np.inf
        for k in range(n_h):
            out[ia, k] = running
            for blk in range(n_blocks):
                if best[blk, ia, k] > running:
                    running = best[blk, ia, k]
    return out


@njit(inline="always")
def _line_gap(p_ned, i, j, dn, de):
    """Distance of cell (i, j) (its corners' hull) from the line along (dn, de) through the antenna,
    0 when it straddles the line; and the largest horizontal distance of a corner."""
    lo, hi, h2 = 1e300, -1e300, 0.0
    for ci in range(2):
        for cj in range(2):
            n, e = p_ned[i + ci, j + cj, 0], p_ned[i + ci, j + cj, 1]
            d = n * de - e * dn
            lo, hi, h2 = min(lo, d), max(hi, d), max(h2, n * n + e * e)
    return (0.0 if lo <= 0.0 <= hi else min(abs(lo), abs(hi))), math.sqrt(h2)


@njit(error_model="numpy")
def _strip_samples(p_ned, rot_n2a, i, nsub_r, nsub_c, dn, de, sample_m, az_bin_rad, pts):
    # _row_samples for the cells of row i that can reach the azimuth along (dn, de): a sample
    # raises the bins its patch spans, within 0.5 sample_m / h + 1.5 bins of its own angle, so
    # it lies within 0.5 sample_m + 1.5 h az_bin of that azimuth's line (margin: 3 bins + 1 m).
    n = 0
    for j in range(p_ned.shape[1] - 1):
        gap, h_max = _line_gap(p_ned, i, j, dn, de)  # first: it leaves out most cells
        if gap > 0.5 * sample_m + 3.0 * h_max * az_bin_rad + 1.0 or not _cell_in_front(p_ned, rot_n2a, i, j):
            continue
        n = _cell_samples(p_ned, i, j, nsub_r, nsub_c, pts, n)
    return n


@njit(error_model="numpy")
def _column_max(best, pts, n_pts, r_lim, n_az, ia_t, k_t):
    # _raise_bins for one bin (ia_t, any range bin before k_t): the running maximum's entry there.
    for m in range(n_pts):
        n, e = pts[0, m], pts[1, m]
        if n * n + e * e > r_lim * r_lim or int(pts[5, m]) >= k_t:
            continue
        d = wrap_index(ia_t - wrap_index(int(pts[4, m]), n_az), n_az)
        if min(d, n_az - d) <= int(pts[7, m]) and pts[6, m] > best[0]:
            best[0] = pts[6, m]


@njit(cache=True, error_model="numpy")
def horizon_at(p_ned, rot_n2a, nsub_r, nsub_c, r_lim, az_bin_rad, h_bin_m, n_az, n_h, sample_m, ia, k):
    """``horizon_map(...)[ia[t], k[t]]`` for each t, equal to the map's entries, without the map.

    Only cells near the line of azimuth bin ``ia[t]`` are sampled (a target's line of sight
    needs one entry per frame: about 1/30 of the map's work on a 5 km crop).
    """
    out = np.full(ia.shape[0], -np.inf, dtype=np.float32)
    pts = np.empty((8, max(p_ned.shape[1] - 1, 1) * nsub_r * nsub_c))
    best = np.empty(1, dtype=np.float32)
    for t in range(ia.shape[0]):
        if k[t] <= 0:
            continue  # nothing lies strictly closer than the first range bin
        angle = (ia[t] + 0.5) * az_bin_rad - math.pi
        dn, de = math.cos(angle), math.sin(angle)
        best[0] = -np.inf
        for i in range(p_ned.shape[0] - 1):
            n = _strip_samples(p_ned, rot_n2a, i, nsub_r, nsub_c, dn, de, sample_m, az_bin_rad, pts)
            n_, e_, d_, h_ = pts[0][:n], pts[1][:n], pts[2][:n], pts[3][:n]
            _horizontal_rows(h_, n_, e_)
            _azimuth_row(pts[4][:n], n_, e_, az_bin_rad)
            _range_slope_rows(pts[5][:n], pts[6][:n], h_, d_, h_bin_m, float(n_h))
            _spread_row(pts[7][:n], h_, sample_m, az_bin_rad, float(n_az // 4))
            _column_max(best, pts, n, r_lim, n_az, ia[t], k[t])
        out[t] = best[0]
    return out
