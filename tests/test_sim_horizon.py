"""A target's line of sight from single horizon entries (the truth pass) against the whole horizon map."""

from __future__ import annotations

import numpy as np

from skyradar.config import RadarConfig
from skyradar.scene.synthetic_terrain import centred_grid, flat_terrain
from skyradar.sim._horizon_kernel import horizon_at, horizon_map
from skyradar.sim.image import ImageSimulator, PlatformState, PointTarget
from skyradar.sim.targets import line_of_sight, target_geometry

CFG = RadarConfig.prototype_2022(range_limit_m=2500.0)


def _ridges(spacing_m: float = 40.0, n: int = 151):
    rng = np.random.default_rng(8)
    y, x = np.mgrid[0:n, 0:n] * spacing_m
    z = 90.0 * np.sin(x / 500.0) * np.cos(y / 400.0) + rng.normal(0.0, 8.0, (n, n))
    z[n // 3 : n // 3 + 2, :] += 200.0
    return centred_grid(z, 47.0, 8.0, spacing_m, "ridges")


def test_horizon_entries_equal_the_map_everywhere():
    terrain = _ridges(50.0, n=41)
    p_ned = terrain.points_ned(47.0, 8.0, 0.0) - np.array([0.0, 0.0, -300.0])
    rot = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # looking east
    bins = (900.0, 2 * np.pi / 90, 25.0, 90, 37)  # r_lim, azimuth bin, range bin, n_az, n_h
    full = horizon_map(p_ned, rot, 2, 2, *bins, 2, 25.0)
    ia, k = np.meshgrid(np.arange(90), np.arange(37), indexing="ij")
    entries = horizon_at(p_ned, rot, 2, 2, *bins, 25.0, ia.ravel(), k.ravel())
    assert np.isfinite(full).sum() > 500
    np.testing.assert_array_equal(entries, full.ravel())  # bit for bit, -inf included


def test_truth_visibility_and_snr_are_the_frames_without_the_whole_horizon():
    sim = ImageSimulator(CFG, _ridges(), (47.0, 8.0, 0.0), psf=True)
    rng = np.random.default_rng(3)
    hidden = seen = 0
    for _ in range(6):
        own = PlatformState(
            np.array([*rng.uniform(-1500, 1500, 2), -rng.uniform(120.0, 350.0)]),
            np.array([50.0, 0.0, 0.0]),
            np.array([rng.uniform(-3, 3), rng.uniform(-0.2, 0.2), rng.uniform(-0.6, 0.6)]),
        )
        geom = sim.geometry(own)
        offsets = np.c_[rng.uniform(-2400, 2400, (30, 2)), rng.uniform(-50, 350, 30)]
        targets = [PointTarget(geom.origin_ned_m + d, np.zeros(3)) for d in offsets]
        clear = line_of_sight(sim.terrain_view(geom), geom, targets)  # the frame's test, whole map
        want = target_geometry(CFG, geom, targets, sim.coupling_s, clear, sim.noise_per_pixel_w)
        got = sim.target_truth(own, targets)
        np.testing.assert_array_equal(got["visible"], want["visible"])
        np.testing.assert_array_equal(got["snr_db"], want["snr_db"])
        hidden, seen = hidden + int((~clear).sum()), seen + int(clear.sum())
    assert hidden > 20 and seen > 20  # both cases occur


def test_level_ground_well_below_hides_no_target():
    ground = flat_terrain(47.0, 8.0, 0.0, size_m=6000.0, spacing_m=30.0)
    sim = ImageSimulator(CFG, ground, (47.0, 8.0, 0.0))
    own = PlatformState(np.array([0.0, 0.0, -300.0]), np.array([50.0, 0.0, 0.0]), np.zeros(3))
    low = PointTarget(np.array([2000.0, 0.0, -1.0]), np.zeros(3))  # 1 m above the ground
    assert sim.target_truth(own, [low])["visible"].all()
