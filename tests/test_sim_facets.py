"""Sub-facets sized by their own range and Doppler extent (``skyradar.sim.facets``).

Two checks against independent measures: the extent of every sub-facet measured on a dense grid
of points of its bilinear patch (not from the corner formula the rule uses), and the clutter power
of the adaptive rule against a uniform rule four times finer (the continuous-clutter reference),
averaged over speckle.
"""

from __future__ import annotations

import numpy as np

from skyradar.config import RadarConfig
from skyradar.scene.synthetic_terrain import fractal_terrain
from skyradar.sim._terrain_kernel import cell_count_grid
from skyradar.sim.image import ImageSimulator, PlatformState

ORIGIN = (52.0, 4.36, 0.0)
SMALL = {"fs_hz": 625e3, "prf_hz": 2.5e3, "n_doppler": 64, "range_limit_m": 600.0}


def _largest_extents(p_ant, vg, n, i, j):
    """Largest range and radial-velocity change along either axis inside any sub-facet of cell (i, j).

    Measured on 8 x 8 intervals of the bilinear patch per sub-facet, not from the cell's corners.
    """
    nu, nw = n
    u, w = np.linspace(0.0, 1.0, 8 * nu + 1)[:, None, None], np.linspace(0.0, 1.0, 8 * nw + 1)[None, :, None]
    pts = (1 - u) * (1 - w) * p_ant[i, j] + u * (1 - w) * p_ant[i + 1, j]
    pts = pts + (1 - u) * w * p_ant[i, j + 1] + u * w * p_ant[i + 1, j + 1]
    r = np.linalg.norm(pts, axis=-1)
    worst = []
    for f in (r, pts @ vg / r):
        along_u = np.ptp(np.lib.stride_tricks.sliding_window_view(f, 9, axis=0)[::8], axis=-1)
        along_w = np.ptp(np.lib.stride_tricks.sliding_window_view(f, 9, axis=1)[:, ::8], axis=-1)
        worst.append(max(float(along_u.max()), float(along_w.max())))
    return worst


def test_every_sub_facet_spans_at_most_half_a_range_bin_and_half_a_doppler_bin():
    cfg = RadarConfig.prototype_2022(range_limit_m=1500.0)
    hills = fractal_terrain(ORIGIN[0], ORIGIN[1], 40.0, size_m=3400.0, spacing_m=90.0, seed=5)
    sim = ImageSimulator(cfg, hills, ORIGIN, psf=True)
    rule = sim._facets
    target_r, target_v = rule.adapt[:2]
    assert target_r == cfg.range_resolution_m / 2 and np.isclose(target_v, cfg.doppler_resolution_mps / 2)
    rng = np.random.default_rng(0)
    checked = 0
    for height_m, speed, attitude in ((300.0, 60.0, (0.3, -0.2, 0.4)), (900.0, 45.0, (0.0, 0.05, 0.0))):
        own = PlatformState(np.array([0.0, 0.0, -height_m]), np.array([speed, 5.0, 0.0]), np.array(attitude))
        geom = sim.geometry(own)
        p_ant = np.ascontiguousarray(sim.terrain_view(geom).p_ned @ geom.rot_ned_to_ant.T)
        vg = geom.rot_ned_to_ant @ -geom.velocity_ned_mps
        n = cell_count_grid(p_ant, vg, np.array(rule.counts), rule.adapt, 2 * cfg.range_limit_m)
        kept = np.argwhere((n[..., 0] > 0) & (n[..., 0] < rule.n_max[0]) & (n[..., 1] < rule.n_max[1]))
        assert len(kept) > 100
        for i, j in kept[rng.choice(len(kept), 40, replace=False)]:
            ext_r, ext_v = _largest_extents(p_ant, vg, n[i, j], i, j)
            assert ext_r <= target_r * 1.001 and ext_v <= target_v * 1.001, (i, j, n[i, j], ext_r, ext_v)
            checked += 1
    assert checked == 80


def _mean_power(sim: ImageSimulator, own: PlatformState, n_frames: int) -> np.ndarray:
    return np.mean([np.abs(sim.frame(own, frame_index=i)[..., 0]) ** 2 for i in range(n_frames)], axis=0)


def test_adaptive_facets_give_the_clutter_of_facets_four_times_finer():
    cfg = RadarConfig.prototype_2022(**SMALL)
    hills = fractal_terrain(ORIGIN[0], ORIGIN[1], 15.0, size_m=1500.0, spacing_m=30.0, seed=2)
    own = PlatformState(np.array([0.0, 0.0, -200.0]), np.array([35.0, 4.0, 0.0]), np.radians([0.0, -12, 0]))
    options = {"noise": False, "speckle": True, "psf": True}

    def fine(seed):
        sim = ImageSimulator(
            cfg, hills, ORIGIN, facet_size_m=3.75, adaptive_facets=False, seed=seed, **options
        )
        return _mean_power(sim, own, 32)

    adaptive = ImageSimulator(cfg, hills, ORIGIN, **options)
    assert adaptive._facets.adapt[0] == cfg.range_resolution_m / 2
    reference, redraw, got = fine(0), fine(7), _mean_power(adaptive, own, 32)
    cells = reference > reference.max() * 1e-3
    assert cells.sum() > 300
    diff_db = 10 * np.log10(got[cells] / reference[cells])
    speckle_db = np.mean(np.abs(10 * np.log10(redraw[cells] / reference[cells])))
    # No bias, and no more scatter per cell than a new speckle draw of the reference itself
    # (32 looks: about 0.85 dB mean |difference|).
    assert abs(np.mean(diff_db)) < 0.15, np.mean(diff_db)
    assert np.mean(np.abs(diff_db)) < 1.1 * speckle_db, (np.mean(np.abs(diff_db)), speckle_db)


def test_adaptive_cells_in_the_vectorised_batches_match_the_scalar_reference():
    # Cells of different sub-facet counts share a batch; the scalar loop cuts each cell alone.
    cfg = RadarConfig.prototype_2022(range_limit_m=1500.0)
    hills = fractal_terrain(ORIGIN[0], ORIGIN[1], 40.0, size_m=3400.0, spacing_m=60.0, seed=5)
    sim = ImageSimulator(cfg, hills, ORIGIN, adaptive_facets=True, seed=3)
    own = PlatformState(np.array([0.0, 0.0, -400.0]), np.array([50.0, 8.0, 0.0]), np.array([0.2, -0.1, 0.1]))
    cubes = []
    for mode in (0, 1):
        sim._kernel_mode = mode
        cubes.append(sim.frame(own, frame_index=3))
    reference, batched = cubes
    assert np.abs(reference).max() > 1e3 * np.sqrt(cfg.noise_power_w)
    np.testing.assert_allclose(batched, reference, rtol=0, atol=1e-6 * np.abs(reference).max())


def test_level_terrain_skips_the_horizon_and_keeps_the_frame():
    # A level surface is convex: nothing in range is hidden (its horizon is 25 km away at 50 m).
    from skyradar.scene.synthetic_terrain import flat_terrain

    cfg = RadarConfig.prototype_2022(range_limit_m=2000.0)
    level = flat_terrain(ORIGIN[0], ORIGIN[1], 0.0, size_m=6000.0)
    own = PlatformState(
        np.array([500.0, -800.0, -300.0]), np.array([50.0, 0.0, 0.0]), np.array([0.3, 0.05, 0.4])
    )
    sim = ImageSimulator(cfg, level, ORIGIN, noise=False)
    assert sim.terrain_view(sim.geometry(own)).horizon.shape == (1, 1)
    skipped = np.abs(sim.frame(own)) ** 2
    sim._level = False  # the full horizon, as for any other terrain
    assert sim.terrain_view(sim.geometry(own)).horizon.shape[0] > 100
    full = np.abs(sim.frame(own)) ** 2
    assert skipped.sum() > 0 and abs(full.sum() / skipped.sum() - 1.0) < 1e-4
    np.testing.assert_allclose(
        full.sum(axis=(1, 2)), skipped.sum(axis=(1, 2)), rtol=1e-3, atol=1e-6 * full.max()
    )
    # Hills keep their horizon; so does level ground less than 50 m below the antenna.
    hills = ImageSimulator(cfg, fractal_terrain(ORIGIN[0], ORIGIN[1], 20.0, size_m=6000.0, seed=1), ORIGIN)
    assert hills.terrain_view(hills.geometry(own)).horizon.shape[0] > 100
    low = PlatformState(np.array([0.0, 0.0, -30.0]), np.array([50.0, 0.0, 0.0]), np.zeros(3))
    fresh = ImageSimulator(cfg, level, ORIGIN, noise=False)
    assert fresh.terrain_view(fresh.geometry(low)).horizon.shape[0] > 100
