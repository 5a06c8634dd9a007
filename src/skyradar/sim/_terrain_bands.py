"""Terrain returns into ONE shared grid, each thread owning a band of range bins.

``_terrain_kernel.terrain_returns`` gives each thread its own copy of the (oversampled) cube and
interleaves DEM rows between them: with two threads that is two 10.6 MB cubes to scatter into,
sum, and clear every frame, and the point-spread pass then reads both. Here the threads own
disjoint bands of range bins of one grid instead, so no two threads ever add into one pixel and
there is nothing to sum:

1. a parallel pass over the DEM cells culls them, cuts them (the same ``cell_counts`` rule) and
   bounds the range bins their sub-facets can land in;
2. the band edges split the frame's sub-facets evenly (by each cell's middle bin);
3. each band runs the vectorised batches of ``_terrain_batch`` over the cells that can reach it
   (a cell straddling an edge is computed by both bands) and adds only the sub-facets whose
   range bin is its own.

Every sub-facet is computed by the same formulas and numbered as in ``terrain_returns`` (its
speckle draw is the same), so the grid equals the interleaved kernel's up to the order of the
float32 additions per pixel (``tests/test_sim_bands.py``).

Why the bound holds: a point of a cell's bilinear patch is a convex combination of its four
corners, so its distance from the antenna is at most the largest corner distance and at least
the nearest corner's minus the cell's extent (the ``_cell_beyond`` bound); the bin adds the
range-Doppler coupling (at most ``coupling * |v_ground|``) and the antennas' offsets from the
phase centre (at most their largest distance from it), and one bin for rounding.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

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
from skyradar.sim._terrain_kernel import _cell_behind, _cell_beyond, _corner_terms, _sub_centres
from skyradar.sim.facets import cell_counts

__all__ = ["banded_returns", "band_edges"]


@njit(inline="always")
def _cell_bins(p_ant, i, j, d_range, margin_m):
    # Lowest and highest range bin any point of cell (i, j) can land in (module docstring).
    near, far, extent = 1e300, 0.0, 0.0
    for ci in range(2):
        for cj in range(2):
            x, y, z = p_ant[i + ci, j + cj, 0], p_ant[i + ci, j + cj, 1], p_ant[i + ci, j + cj, 2]
            r = math.sqrt(x * x + y * y + z * z)
            near, far = min(near, r), max(far, r)
    for c in range(3):
        extent += abs(p_ant[i + 1, j + 1, c] - p_ant[i, j, c]) + abs(p_ant[i + 1, j, c] - p_ant[i, j + 1, c])
    lo = math.floor((max(near - extent, 0.0) - margin_m) / d_range + 0.5) - 1
    hi = math.floor((far + margin_m) / d_range + 0.5) + 1
    return lo, hi


@njit(parallel=True, cache=True, error_model="numpy")
def _plan(p_ant, v_ground_ant, counts, adapt, r_max, d_range, margin_m, cells):
    """Per cell (ny - 1, nx - 1, 4): sub-facets per axis (0: culled), lowest and highest range bin."""
    n_min_r, n_min_c, n_max_r, n_max_c = counts
    for i in prange(p_ant.shape[0] - 1):
        for j in range(p_ant.shape[1] - 1):
            cell = cells[i, j]
            if _cell_behind(p_ant, i, j) or _cell_beyond(p_ant, i, j, r_max):
                cell[0] = 0
                continue
            nu, nw = cell_counts(p_ant, i, j, v_ground_ant, n_min_r, n_min_c, n_max_r, n_max_c, adapt)
            lo, hi = _cell_bins(p_ant, i, j, d_range, margin_m)
            cell[0], cell[1], cell[2], cell[3] = nu, nw, lo, hi


@njit(cache=True, error_model="numpy")
def band_edges(cells, n_range, n_bands):
    """Range-bin edges (n_bands + 1) splitting the planned sub-facets evenly, by each cell's middle bin.

    Examples
    --------
    >>> cells = np.zeros((1, 4, 4), np.int64)
    >>> cells[0, :, :2] = 2  # four cells of 2 x 2 sub-facets
    >>> cells[0, :, 2] = [0, 10, 20, 30]
    >>> cells[0, :, 3] = cells[0, :, 2] + 2
    >>> band_edges(cells, 40, 2).tolist()
    [0, 12, 40]
    """
    work = np.zeros(n_range + 1)
    total = 0.0
    for i in range(cells.shape[0]):
        for j in range(cells.shape[1]):
            c = cells[i, j]
            if c[0] == 0:
                continue
            mid = min(max((c[2] + c[3]) // 2, 0), n_range)
            work[mid] += c[0] * c[1]
            total += c[0] * c[1]
    edges = np.empty(n_bands + 1, np.int64)
    edges[0], edges[n_bands] = 0, n_range
    b, acc = 1, 0.0
    for k in range(n_range + 1):
        acc += work[k]
        while b < n_bands and acc >= total * b / n_bands:
            edges[b] = k + 1
            b += 1
    while b < n_bands:  # no work left: empty bands at the far end
        edges[b] = n_range
        b += 1
    return edges


@njit(inline="always")
def _keep_band(s, k, lo, hi):
    # Items outside the band are another band's: not valid here.
    for m in range(k):
        kr = s[_KR, m]
        if kr < lo or kr >= hi:
            s[_VALID, m] = 0.0


@njit(inline="always")
def _flush(scratch, k, tx, rx, r_rx_sub, cos_sin, v_ground_ant, r_max, d_range, d_vel, coupling, n_range,
           n_dopp, inv_wl, power_const, gain2, gain2_step, refl_table, horizon, az_bin_rad, h_bin_m,
           use_horizon, out, sparse, speckle_key, lo, hi):  # fmt: skip
    # terrain_returns' flush, keeping only the band's items.
    item_returns(
        scratch, k, tx, rx, r_rx_sub, cos_sin, v_ground_ant, r_max, d_range, d_vel, coupling, n_range,
        n_dopp, inv_wl, power_const, gain2, gain2_step, refl_table, horizon, az_bin_rad, h_bin_m,
        use_horizon, speckle_key,
    )  # fmt: skip
    _keep_band(scratch, k, lo, hi)
    scatter_items(out, sparse, 0, scratch, cos_sin, k)


@njit(parallel=True, cache=True, fastmath=True, error_model="numpy")
def _band_pass(
    p_ned, p_ant, up_ant, tx, rx, v_ground_ant, cells, edges, n_cell_max, wavelength, d_range, d_vel,
    coupling, power_const, gain2, gain2_step, refl_table, horizon, az_bin_rad, h_bin_m, use_horizon, out,
    speckle_key,
):  # fmt: skip
    ny, nx = p_ned.shape[0], p_ned.shape[1]
    n_range, n_dopp = out.shape[1], out.shape[2]
    r_max = d_range * (n_range + 2)
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
        k = 0
        for i in range(ny - 1):
            for j in range(nx - 1):
                c = cells[i, j]
                if c[0] == 0 or c[3] < lo or c[2] >= hi:
                    continue
                nu, nw = c[0], c[1]
                n_sub = nu * nw
                if k + n_sub > cap:
                    _flush(scratch, k, tx, rx, r_rx_sub, cos_sin, v_ground_ant, r_max, d_range, d_vel,
                           coupling, n_range, n_dopp, inv_wl, power_const, gain2, gain2_step, refl_table,
                           horizon, az_bin_rad, h_bin_m, use_horizon, out, sparse, speckle_key, lo,
                           hi)  # fmt: skip
                    k = 0
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
            _flush(scratch, k, tx, rx, r_rx_sub, cos_sin, v_ground_ant, r_max, d_range, d_vel, coupling,
                   n_range, n_dopp, inv_wl, power_const, gain2, gain2_step, refl_table, horizon, az_bin_rad,
                   h_bin_m, use_horizon, out, sparse, speckle_key, lo, hi)  # fmt: skip


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
    n_bands: int,
    out: np.ndarray,
    speckle_key: np.uint64,
    cells: np.ndarray | None = None,
) -> np.ndarray:
    """Add terrain returns into ``out`` (1, n_range, n_doppler, n_rx), ``n_bands`` threads' bands.

    The arguments are ``terrain_returns``' (``rule`` a :class:`~skyradar.sim.facets.FacetRule`,
    ``view`` the frame's :class:`~skyradar.sim.geometry.TerrainView`), always in its vectorised
    mode into a dense grid. ``cells`` (ny - 1, nx - 1, 4) int64 is the per-cell plan's storage
    (None: a fresh one). Returns the band edges (range bins).
    """
    ny, nx = p_ant.shape[:2]
    if cells is None or cells.shape != (ny - 1, nx - 1, 4):
        cells = np.empty((ny - 1, nx - 1, 4), np.int64)
    n_range = out.shape[1]
    r_max = d_range * (n_range + 2)
    antennas = np.vstack([np.reshape(tx, (1, 3)), rx])
    reach_m = float(np.max(np.linalg.norm(antennas, axis=1)))
    margin_m = abs(coupling) * float(np.linalg.norm(v_ground_ant)) + reach_m
    counts = np.asarray(rule.counts, np.int64)
    _plan(p_ant, v_ground_ant, counts, np.asarray(rule.adapt, float), r_max, d_range, margin_m, cells)
    edges = band_edges(cells, n_range, max(1, int(n_bands)))
    _band_pass(
        p_ned, p_ant, up_ant, tx, rx, v_ground_ant, cells, edges, rule.per_cell_max, wavelength, d_range,
        d_vel, coupling, power_const, gain2, gain2_step, refl_table, view.horizon, view.az_bin_rad,
        view.h_bin_m, use_horizon, out, speckle_key,
    )  # fmt: skip
    return edges
