"""Terrain returns into one grid by range bands (_terrain_bands) against the per-thread-cube kernel."""

from __future__ import annotations

import numpy as np
from numba import njit

from skyradar.benchmarks.sim import FacetPhysics
from skyradar.config import RadarConfig
from skyradar.scene.synthetic_terrain import fractal_terrain
from skyradar.sim._terrain_bands import _sampled_work, band_edges, banded_returns, frame_edges
from skyradar.sim._terrain_kernel import _cell_nearest, rotate_points, terrain_returns
from skyradar.sim.facets import cell_counts
from skyradar.sim.image import ImageSimulator, PlatformState

ORIGIN = (47.0, 8.0, 0.0)
_NO_SPARSE = (np.empty((1, 0), np.int64), np.empty((1, 0, 1), np.complex64), np.zeros(1, np.int64))


def _setup():
    cfg = RadarConfig.prototype_2022(range_limit_m=1500.0)
    hills = fractal_terrain(ORIGIN[0], ORIGIN[1], 40.0, size_m=3400.0, spacing_m=60.0, seed=5)
    sim = ImageSimulator(cfg, hills, ORIGIN, psf=True, speckle=True, seed=3)
    # Banked and climbing, fast: range-Doppler coupling and a tilted footprint.
    own = PlatformState(np.array([0.0, 0.0, -400.0]), np.array([60.0, 8.0, -3.0]), np.array([0.2, -0.1, 0.3]))
    geom = sim.geometry(own)
    view = sim.terrain_view(geom)
    rot = geom.rot_ned_to_ant
    p_ant = rotate_points(view.p_ned, rot, np.empty(view.p_ned.shape))
    n = sim._psf.oversample
    const = cfg.pe_w * cfg.wavelength_m**2 / (4 * np.pi) ** 3
    common = (cfg.wavelength_m, cfg.range_resolution_m / n, cfg.doppler_resolution_mps / n, sim.coupling_s)
    common += (const, sim._gain2, sim._gain2_step, sim._refl_table)
    v_ground = rot @ -geom.velocity_ned_mps
    head = (view.p_ned, p_ant, -rot[:, 2], cfg.tx_position_m, cfg.rx_positions_m, v_ground)
    return sim, view, head, common


def _reference(sim, view, head, common, key):
    blocks = np.zeros((2, *sim._grid_shape), np.complex64)
    terrain_returns(
        *head,
        sim._facets.counts,
        sim._facets.adapt,
        *common,
        view.horizon,
        view.az_bin_rad,
        view.h_bin_m,
        True,
        2,
        blocks,
        _NO_SPARSE,
        1,
        key,
    )
    return blocks.sum(axis=0)


def test_bands_give_the_per_thread_cubes_sum_whatever_the_edges():
    sim, view, head, common = _setup()
    key = np.uint64(99)
    reference = _reference(sim, view, head, common, key)
    n_range = sim._grid_shape[0]

    def banded(edges):
        grid = np.zeros((1, *sim._grid_shape), np.complex64)
        used = banded_returns(*head, sim._facets, *common, view, True, grid, key, edges)
        return grid[0], used

    grid, _ = banded(band_edges(np.zeros(n_range + 1), 3))  # equal bands
    margin_m = abs(sim.coupling_s) * np.linalg.norm(head[-1]) + np.max(np.linalg.norm(head[4], axis=1))
    balanced = frame_edges(head[1], head[-1], sim._facets, common[1], n_range, margin_m, 3)
    # Every sub-facet once (same pixels, same values) up to the order of float32 additions...
    assert np.array_equal(grid != 0, reference != 0)
    np.testing.assert_allclose(grid, reference, rtol=0, atol=1e-5 * np.abs(reference).max())
    # ... the balanced edges cut through the returns ...
    filled = np.flatnonzero(np.abs(reference).sum(axis=(1, 2)))
    assert len(np.unique(np.searchsorted(balanced, filled, side="right"))) == 3
    # ... and the bands only move work between threads: the same grid (to float32 rounding: an
    # item's value may round differently in a vector body and a loop's scalar remainder).
    for edges in (balanced, np.array([0, n_range]), band_edges(np.zeros(n_range + 1), 8)):
        other = banded(edges)[0]
        assert np.array_equal(other != 0, grid != 0)
        np.testing.assert_allclose(other, grid, rtol=0, atol=1e-6 * np.abs(grid).max())


def test_band_edges_split_the_work_evenly():
    rng = np.random.default_rng(0)
    work = rng.integers(0, 64, 667).astype(float)
    edges = band_edges(work, 4)
    per_band = [work[lo:hi].sum() for lo, hi in zip(edges[:-1], edges[1:], strict=True)]
    assert edges[0] == 0 and edges[-1] == 666 and np.all(np.diff(edges) > 0)
    assert sum(per_band) == work[:666].sum()
    # Each band within one range bin's worth of work of an even share.
    assert max(abs(b - work.sum() / 4) for b in per_band) <= work.max()
    assert band_edges(np.zeros(101), 4).tolist() == [0, 25, 50, 75, 100]  # nothing seen yet: equal


def test_a_frame_is_the_same_bits_whatever_was_simulated_before():
    # The default edges come from the frame itself: simulating other frames first changes nothing.
    sim, view, head, common = _setup()
    key = np.uint64(7)
    first = np.zeros((1, *sim._grid_shape), np.complex64)
    edges = banded_returns(*head, sim._facets, *common, view, True, first, key)
    other = PlatformState(np.array([300.0, 50.0, -600.0]), np.array([50.0, 0.0, 0.0]), np.zeros(3))
    sim.frame(other, frame_index=4)  # another geometry in between
    again = np.zeros_like(first)
    assert np.array_equal(banded_returns(*head, sim._facets, *common, view, True, again, key), edges)
    assert np.array_equal(again, first)


def test_frame_edges_balance_the_sub_facets_of_the_frame():
    sim, view, head, common = _setup()
    n_range = sim._grid_shape[0]
    counts, adapt = np.asarray(sim._facets.counts, np.int64), np.asarray(sim._facets.adapt, float)
    work = _sampled_work(head[1], head[-1], counts, adapt, 1.0, common[1], n_range, 1)  # every cell
    edges = frame_edges(head[1], head[-1], sim._facets, common[1], n_range, 1.0, 4)  # every 4th
    share = np.array([work[lo:hi].sum() for lo, hi in zip(edges[:-1], edges[1:], strict=True)])
    share /= work[:n_range].sum()
    assert edges[0] == 0 and edges[-1] == n_range and np.all(np.diff(edges) >= 0)
    assert np.all(np.abs(share - 0.25) < 0.05), share  # sampled edges, exact work: even within 5 %


@njit
def _nearest_bounds(p_ant):
    out = np.empty((p_ant.shape[0] - 1, p_ant.shape[1] - 1))
    for i in range(out.shape[0]):
        for j in range(out.shape[1]):
            out[i, j] = _cell_nearest(p_ant, i, j)
    return out


def _patch_distances(p_ant, n=33):
    # Distance of an n x n grid of points of every cell's bilinear patch, corners and edges included.
    t = np.linspace(0.0, 1.0, n)
    u, w = t[:, None, None, None, None], t[None, :, None, None, None]
    c00, c10, c01, c11 = p_ant[:-1, :-1], p_ant[1:, :-1], p_ant[:-1, 1:], p_ant[1:, 1:]
    pts = (1 - u) * (1 - w) * c00 + u * (1 - w) * c10 + (1 - u) * w * c01 + u * w * c11
    return np.linalg.norm(pts, axis=-1)  # (n, n, ny - 1, nx - 1)


def test_cell_nearest_bounds_every_point_of_the_cell_and_culls_cells_beyond():
    # The whole-cell cull and the band bounds rest on _cell_nearest being at most the distance
    # of every point of the cell: checked on dense grids of patch points, for the simulator's
    # own frame and for rough terrain right under, beside and far from the antenna.
    sim, view, head, common = _setup()
    rng = np.random.default_rng(11)
    grids = [head[1]]
    for offset in ([0.0, 0.0, 30.0], [400.0, -250.0, 5.0], [2500.0, 100.0, 300.0]):
        n, e = np.meshgrid(np.arange(-8, 9) * 40.0, np.arange(-8, 9) * 55.0, indexing="ij")
        z = rng.normal(0.0, 25.0, n.shape)
        grids.append(np.stack([n, e, z], -1) + np.array(offset))
    for p_ant in grids:
        p_ant = np.ascontiguousarray(p_ant)
        bound = _nearest_bounds(p_ant)
        nearest = _patch_distances(p_ant).min(axis=(0, 1))
        assert np.all(bound <= nearest), float((bound - nearest).max())
        # Tight enough to matter: within the cell's half-diagonal of the true nearest distance.
        half_diagonal = 0.5 * np.linalg.norm(p_ant[1:, 1:] - p_ant[:-1, :-1], axis=-1)
        far = nearest > 2 * half_diagonal
        assert np.all((nearest - bound)[far] <= half_diagonal[far])
    # The cull in the frame: only cells whose every point is beyond r_max, and most of those.
    p_ant, r_max = np.ascontiguousarray(head[1]), common[1] * (sim._grid_shape[0] + 2)
    bound, nearest = _nearest_bounds(p_ant), _patch_distances(p_ant).min(axis=(0, 1))
    culled = bound > r_max
    assert np.all(nearest[culled] > r_max)
    assert culled.sum() >= 0.9 * (nearest > r_max).sum() > 0


@njit
def _every_cell_count(p_ant, vg, counts, adapt):
    # The facet rule's counts for every cell, culled or not.
    out = np.empty((p_ant.shape[0] - 1, p_ant.shape[1] - 1, 2), np.int64)
    for i in range(out.shape[0]):
        for j in range(out.shape[1]):
            out[i, j] = cell_counts(p_ant, i, j, vg, counts[0], counts[1], counts[2], counts[3], adapt)
    return out


def _numpy_grid(sim, head, common):
    """Every sub-facet of every cell (no whole-cell culls), exact distances, no speckle or horizon."""
    _, p_ant, up, tx, rx, vg = head
    wavelength, d_range, d_vel, coupling, power_const = common[:5]
    n_range, n_dopp, n_rx = sim._grid_shape
    physics = FacetPhysics(sim.config)
    counts = _every_cell_count(p_ant, vg, np.asarray(sim._facets.counts), np.asarray(sim._facets.adapt))
    grid = np.zeros((n_range * n_dopp, n_rx), complex)
    for nu, nw in {tuple(c) for c in counts.reshape(-1, 2).tolist()}:
        i, j = np.nonzero((counts[..., 0] == nu) & (counts[..., 1] == nw))
        u = np.repeat((np.arange(nu) + 0.5) / nu, nw)[None, :, None]
        w = np.tile((np.arange(nw) + 0.5) / nw, nu)[None, :, None]
        c00, c10, c01, c11 = (p_ant[i + a, j + b][:, None, :] for a, b in ((0, 0), (1, 0), (0, 1), (1, 1)))
        e1, e2, e3 = c10 - c00, c01 - c00, c11 - c10 - c01 + c00
        p = c00 + u * e1 + w * e2 + u * w * e3  # (cells, sub-facets, 3)
        normal = np.cross(e1 + w * e3, e2 + u * e3)
        normal *= np.where(normal @ up < 0.0, -1.0, 1.0)[..., None]
        area, r0 = np.linalg.norm(normal, axis=-1), np.linalg.norm(p, axis=-1)
        cos_inc = -np.einsum("...c,...c->...", normal, p) / (area * r0)
        r_tx = np.linalg.norm(p - tx, axis=-1)
        r_rx = np.linalg.norm(p[..., None, :] - rx, axis=-1)  # (cells, sub-facets, n_rx)
        rng = 0.5 * (r_tx + r_rx.mean(axis=-1))
        v_r = p @ vg / r0
        kr = np.floor((rng + coupling * v_r) / d_range + 0.5).astype(int)
        kd = (np.floor(v_r / d_vel + 0.5).astype(int) + n_dopp // 2) % n_dopp
        ok = (p[..., 0] > 0) & (r0 <= d_range * (n_range + 2)) & (cos_inc > 0) & (kr >= 0) & (kr < n_range)
        power = power_const * physics.gain(p[..., 1] / r0, p[..., 2] / r0)
        power *= physics.reflectivity(cos_inc) * area / (nu * nw)
        value = (np.sqrt(power) / rng**2)[..., None] * np.exp(
            2j * np.pi * (r_tx[..., None] + r_rx) / wavelength
        )
        for q in range(n_rx):
            grid[:, q] += np.bincount((kr * n_dopp + kd)[ok], value[..., q][ok].real, n_range * n_dopp)
            grid[:, q] += 1j * np.bincount((kr * n_dopp + kd)[ok], value[..., q][ok].imag, n_range * n_dopp)
    return grid.reshape(sim._grid_shape)


def test_bands_equal_a_numpy_reference_of_every_sub_facet():
    # The compiled pass (whole-cell culls, band bounds, receivers' distances without a square
    # root, float32 phase polynomials) against straightforward numpy over every sub-facet of every
    # cell: the same pixels, the same values to float32 precision (1e-5 of the largest pixel).
    sim, view, head, common = _setup()
    want = _numpy_grid(sim, head, common)
    n_range = sim._grid_shape[0]
    for edges in (None, band_edges(np.zeros(n_range + 1), 3)):
        grid = np.zeros((1, *sim._grid_shape), np.complex64)
        banded_returns(*head, sim._facets, *common, view, False, grid, np.uint64(0), edges)
        assert np.count_nonzero(want) > 10_000
        np.testing.assert_array_equal(grid[0] != 0, want != 0)
        np.testing.assert_allclose(grid[0], want, rtol=0, atol=1e-5 * np.abs(want).max())
