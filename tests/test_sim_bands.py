"""Terrain returns into one grid by range bands (_terrain_bands) against the per-thread-cube kernel."""

from __future__ import annotations

import numpy as np

from skyradar.config import RadarConfig
from skyradar.scene.synthetic_terrain import fractal_terrain
from skyradar.sim._terrain_bands import _sampled_work, band_edges, banded_returns, frame_edges
from skyradar.sim._terrain_kernel import rotate_points, terrain_returns
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
