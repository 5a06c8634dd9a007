"""Terrain returns into ONE shared grid, each thread owning a band of range bins.

``_terrain_kernel.terrain_returns`` gives each thread its own copy of the (oversampled) cube and
interleaves DEM rows between them: with two threads that is two 10.6 MB cubes to scatter into,
sum, and clear every frame, and the point-spread pass then reads both. Here the threads own
disjoint bands of range bins of one grid instead, so no two threads ever add into one pixel and
there is nothing to sum. Each band walks all DEM cells in order, culls them as
``terrain_returns`` does, bounds the range bins a cell's sub-facets can land in, and runs the
vectorised batches of ``_terrain_batch`` over the cells that can reach it (a cell straddling a
band edge is computed by both bands), adding only the sub-facets whose range bin is its own.

Every sub-facet is computed by the same formulas and numbered as in ``terrain_returns`` (its
speckle draw is the same), so the grid equals the interleaved kernel's up to the order of the
float32 additions per pixel (``tests/test_sim_bands.py``), whatever the edges or the number of
threads.

Load balance: the edges split this frame's sub-facets evenly (:func:`frame_edges` counts the
sub-facets of every fourth cell along each DEM axis at its middle range bin, :func:`band_edges`
cuts that histogram). They are a function of the frame alone: edges balanced on the frame before
made a frame depend on the frames simulated before it (an item's value may round differently in
a vector body and a loop's scalar remainder, and the edges move items between the two), so the
same frame index did not give the same bits twice. Any edges give the same grid to float32
rounding.

Why the bound holds: a point of a cell's bilinear patch is a convex combination of its four
corners, so its distance from the antenna is at most the largest corner distance and at least
the smallest corner component along the direction of the corners' centroid
(``_terrain_kernel._cell_nearest``, also the whole-cell range cull); the bin adds the
range-Doppler coupling (at most ``coupling * |v_ground|``) and the antennas' offsets from the
phase centre (at most their largest distance from it), and one bin for rounding.
"""

from __future__ import annotations

import math

import numpy as np
from numba import get_num_threads, njit, prange

from skyradar.sim._terrain_batch import (
    _KR,
    _VALID,
    CELL_FIELDS,
    cell_geometry,
    cell_geometry_scalar,
    item_returns,
    number_items,
    scatter_items,
)
from skyradar.sim._terrain_kernel import (
    _cell_behind,
    _cell_nearest,
    _corner_terms,
    _sub_centres,
)
from skyradar.sim.facets import cell_counts

__all__ = ["banded_returns", "band_edges", "frame_edges"]


@njit(inline="always")
def _cell_bins(p_ant, i, j, d_range, margin_m, near):
    # Lowest and highest range bin any point of cell (i, j) can land in (module docstring);
    # ``near`` is its _cell_nearest bound.
    far2 = 0.0
    for ci in range(2):
        for cj in range(2):
            x, y, z = p_ant[i + ci, j + cj, 0], p_ant[i + ci, j + cj, 1], p_ant[i + ci, j + cj, 2]
            far2 = max(far2, x * x + y * y + z * z)
    lo = math.floor((near - margin_m) / d_range + 0.5) - 1
    hi = math.floor((math.sqrt(far2) + margin_m) / d_range + 0.5) + 1
    return lo, hi


@njit(cache=True, error_model="numpy")
def band_edges(work, n_bands):
    """Range-bin edges (n_bands + 1) splitting the histogram ``work`` (sub-facets per bin) evenly.

    Examples
    --------
    >>> work = np.zeros(41)
    >>> work[[1, 11, 21, 31]] = 4.0  # four cells of 2 x 2 sub-facets
    >>> band_edges(work, 2).tolist()
    [0, 12, 40]
    """
    n_range = work.shape[0] - 1
    total = work.sum()
    edges = np.empty(n_bands + 1, np.int64)
    edges[0], edges[n_bands] = 0, n_range
    b, acc = 1, 0.0
    if total <= 0.0:  # nothing seen yet: equal bands
        for b in range(1, n_bands):
            edges[b] = n_range * b // n_bands
        return edges
    for k in range(n_range + 1):
        acc += work[k]
        while b < n_bands and acc >= total * b / n_bands:
            edges[b] = min(k + 1, n_range)
            b += 1
    while b < n_bands:
        edges[b] = n_range
        b += 1
    return edges


@njit(cache=True, error_model="numpy")
def _sampled_work(p_ant, v_ground_ant, counts, adapt, margin_m, d_range, n_range, stride):
    # Sub-facets per middle range bin of every stride-th cell along each axis, times stride^2.
    ny, nx = p_ant.shape[0], p_ant.shape[1]
    n_min_r, n_min_c, n_max_r, n_max_c = counts
    r_max = d_range * (n_range + 2)
    work = np.zeros(n_range + 1)
    for i in range(0, ny - 1, stride):
        for j in range(0, nx - 1, stride):
            if _cell_behind(p_ant, i, j):
                continue
            near = _cell_nearest(p_ant, i, j)  # one bound for the cull and the bins
            if near > r_max:
                continue
            c_lo, c_hi = _cell_bins(p_ant, i, j, d_range, margin_m, near)
            nu, nw = cell_counts(p_ant, i, j, v_ground_ant, n_min_r, n_min_c, n_max_r, n_max_c, adapt)
            work[min(max((c_lo + c_hi) // 2, 0), n_range)] += nu * nw * stride * stride
    return work


def frame_edges(
    p_ant: np.ndarray,
    v_ground_ant: np.ndarray,
    rule,
    d_range: float,
    n_range: int,
    margin_m: float,
    n_bands: int,
    stride: int = 4,
) -> np.ndarray:
    """Range-bin edges (n_bands + 1) that split this frame's sub-facets evenly between the bands.

    ``p_ant`` (ny, nx, 3) are the DEM points in the antenna frame (m), ``v_ground_ant`` the
    ground's velocity there (m/s), ``rule`` the :class:`~skyradar.sim.facets.FacetRule`,
    ``d_range`` the bin size (m) of the ``n_range`` bins and ``margin_m`` the bound's margin (module
    docstring). Every ``stride``-th cell along each axis is counted: the edges only balance the
    threads (any edges give the same grid), and they depend on the frame alone.

    Examples
    --------
    >>> from skyradar.sim.facets import FacetRule
    >>> n, e = np.meshgrid(np.arange(0.0, 400.0, 20.0), np.arange(-200.0, 200.0, 20.0), indexing="ij")
    >>> p_ant = np.stack([n + 10.0, e, np.full_like(n, 100.0)], -1)  # flat ground 100 m below
    >>> edges = frame_edges(p_ant, np.zeros(3), FacetRule((1, 1), (1, 1), (0.0,) * 4), 3.0, 160, 0.1, 2)
    >>> edges[0], edges[-1], bool(40 < edges[1] < 120)
    (np.int64(0), np.int64(160), True)
    """
    counts = np.asarray(rule.counts, np.int64)
    adapt = np.asarray(rule.adapt, float)
    work = _sampled_work(p_ant, v_ground_ant, counts, adapt, margin_m, d_range, n_range, int(stride))
    return band_edges(work, n_bands)


@njit(inline="always")
def _keep_band(s, k, lo, hi):
    # Items outside the band are another band's: not valid here.
    for m in range(k):
        kr = s[_KR, m]
        if kr < lo or kr >= hi:
            s[_VALID, m] = 0.0


@njit(inline="always")
def _flush(
    scratch,
    k,
    tx,
    rx,
    r_rx_sub,
    cos_sin,
    v_ground_ant,
    r_max,
    d_range,
    d_vel,
    coupling,
    n_range,
    n_dopp,
    inv_wl,
    power_const,
    gain2,
    gain2_step,
    refl_table,
    horizon,
    az_bin_rad,
    h_bin_m,
    use_horizon,
    out,
    sparse,
    speckle_key,
    lo,
    hi,
):
    # terrain_returns' flush, keeping only the band's items.
    item_returns(
        scratch,
        k,
        tx,
        rx,
        r_rx_sub,
        cos_sin,
        v_ground_ant,
        r_max,
        d_range,
        d_vel,
        coupling,
        n_range,
        n_dopp,
        inv_wl,
        power_const,
        gain2,
        gain2_step,
        refl_table,
        horizon,
        az_bin_rad,
        h_bin_m,
        use_horizon,
        speckle_key,
    )
    _keep_band(scratch, k, lo, hi)
    scatter_items(out, sparse, 0, scratch, cos_sin, k)


@njit(parallel=True, cache=True, fastmath=True, error_model="numpy")
def _band_pass(
    p_ned,
    p_ant,
    up_ant,
    tx,
    rx,
    v_ground_ant,
    counts,
    adapt,
    margin_m,
    edges,
    wavelength,
    d_range,
    d_vel,
    coupling,
    power_const,
    gain2,
    gain2_step,
    refl_table,
    horizon,
    az_bin_rad,
    h_bin_m,
    use_horizon,
    out,
    speckle_key,
):
    ny, nx = p_ned.shape[0], p_ned.shape[1]
    n_range, n_dopp = out.shape[1], out.shape[2]
    r_max = d_range * (n_range + 2)
    n_min_r, n_min_c, n_max_r, n_max_c = counts
    n_cell_max = n_max_r * n_max_c
    cap = max(n_cell_max, 512)
    inv_wl = 1.0 / wavelength
    n_bands = edges.shape[0] - 1
    for band in prange(n_bands):
        lo, hi = edges[band], edges[band + 1]
        sparse = (np.empty((1, 0), np.int64), np.empty((1, 0, 1), np.complex64), np.zeros(1, np.int64))
        ta, tn = np.empty((4, 3)), np.empty((4, 3))
        us, ws = np.empty(n_cell_max), np.empty(n_cell_max)
        scratch = np.zeros((CELL_FIELDS, cap))
        r_rx_sub, cos_sin = np.empty((rx.shape[0], cap)), np.empty((2, rx.shape[0], cap), np.float32)
        k = np.int64(0)  # typed int64, not the literal 0, as in terrain_returns
        for i in range(ny - 1):
            for j in range(nx - 1):
                if _cell_behind(p_ant, i, j):
                    continue
                near = _cell_nearest(p_ant, i, j)  # _cell_beyond's bound, also the lowest bin's
                if near > r_max:
                    continue
                c_lo, c_hi = _cell_bins(p_ant, i, j, d_range, margin_m, near)
                if c_hi < lo or c_lo >= hi:
                    continue
                nu, nw = cell_counts(p_ant, i, j, v_ground_ant, n_min_r, n_min_c, n_max_r, n_max_c, adapt)
                n_sub = nu * nw
                if k + n_sub > cap:
                    _flush(
                        scratch,
                        k,
                        tx,
                        rx,
                        r_rx_sub,
                        cos_sin,
                        v_ground_ant,
                        r_max,
                        d_range,
                        d_vel,
                        coupling,
                        n_range,
                        n_dopp,
                        inv_wl,
                        power_const,
                        gain2,
                        gain2_step,
                        refl_table,
                        horizon,
                        az_bin_rad,
                        h_bin_m,
                        use_horizon,
                        out,
                        sparse,
                        speckle_key,
                        lo,
                        hi,
                    )
                    k = np.int64(0)
                _sub_centres(us, ws, nu, nw)
                _corner_terms(p_ant, i, j, ta)
                if use_horizon:
                    _corner_terms(p_ned, i, j, tn)
                if n_sub >= 16:  # as terrain_returns
                    cell_geometry(scratch, k, ta, tn, us[:n_sub], ws[:n_sub], up_ant, use_horizon)
                else:
                    cell_geometry_scalar(scratch, k, ta, tn, us[:n_sub], ws[:n_sub], up_ant, use_horizon)
                number_items(scratch, k, float((i * (nx - 1) + j) * n_cell_max), n_sub)
                k += n_sub
        if k > 0:
            _flush(
                scratch,
                k,
                tx,
                rx,
                r_rx_sub,
                cos_sin,
                v_ground_ant,
                r_max,
                d_range,
                d_vel,
                coupling,
                n_range,
                n_dopp,
                inv_wl,
                power_const,
                gain2,
                gain2_step,
                refl_table,
                horizon,
                az_bin_rad,
                h_bin_m,
                use_horizon,
                out,
                sparse,
                speckle_key,
                lo,
                hi,
            )


def banded_returns(
    p_ned: np.ndarray,
    p_ant: np.ndarray,
    up_ant: np.ndarray,
    tx: np.ndarray,
    rx: np.ndarray,
    v_ground_ant: np.ndarray,
    rule,
    wavelength: float,
    d_range: float,
    d_vel: float,
    coupling: float,
    power_const: float,
    gain2: np.ndarray,
    gain2_step: float,
    refl_table: np.ndarray,
    view,
    use_horizon: bool,
    out: np.ndarray,
    speckle_key: np.uint64,
    edges: np.ndarray | None = None,
) -> np.ndarray:
    """Add terrain returns into ``out`` (1, n_range, n_doppler, n_rx), one thread per band of ``edges``.

    The arguments are ``terrain_returns``' (``rule`` a :class:`~skyradar.sim.facets.FacetRule`,
    ``view`` the frame's :class:`~skyradar.sim.geometry.TerrainView`), always in its vectorised
    mode into a dense grid. ``edges`` (n_bands + 1) int64 are the range-bin band edges, from 0 to
    n_range; default: :func:`frame_edges` for numba's thread count (any edges give the same grid
    to float32 rounding; the default ones depend on this frame alone). Returns the edges used.
    """
    n_range = out.shape[1]
    antennas = np.vstack([np.reshape(tx, (1, 3)), rx])
    reach_m = float(np.max(np.linalg.norm(antennas, axis=1)))
    margin_m = abs(coupling) * float(np.linalg.norm(v_ground_ant)) + reach_m
    if edges is None:
        edges = frame_edges(p_ant, v_ground_ant, rule, d_range, n_range, margin_m, get_num_threads())
    if edges[0] != 0 or edges[-1] != n_range or np.any(np.diff(edges) < 0):
        raise ValueError(f"banded_returns: edges must rise from 0 to {n_range}, got {edges}")
    _band_pass(
        p_ned,
        p_ant,
        up_ant,
        tx,
        rx,
        v_ground_ant,
        np.asarray(rule.counts, np.int64),
        np.asarray(rule.adapt, float),
        margin_m,
        edges,
        wavelength,
        d_range,
        d_vel,
        coupling,
        power_const,
        gain2,
        gain2_step,
        refl_table,
        view.horizon,
        view.az_bin_rad,
        view.h_bin_m,
        use_horizon,
        out,
        speckle_key,
    )
    return edges
