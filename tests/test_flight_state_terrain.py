"""Terrain-aware flight state: velocity from ridge directions, ground points, terrain memory."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyradar.benchmarks.flight_state import flat_ground_frame
from skyradar.config import Mount, RadarConfig
from skyradar.nav.terrain_aware import TerrainAwareEstimator, ground_points, level_velocity

CFG = RadarConfig.prototype_2022(mount=Mount.preset("forward-down"), range_limit_m=2500.0)


def _hilly_points(rng, n=300, h=700.0):
    """Ground points ahead of the radar (level frame: forward, right, down) on a bumpy surface."""
    x = rng.uniform(50.0, 2400.0, n)
    y = rng.uniform(-0.3, 0.3, n) * x
    z = h - 60.0 * np.sin(x / 300.0) - 30.0 * np.cos(y / 200.0)
    return np.column_stack([x, y, z])


@given(st.floats(20.0, 80.0), st.floats(-8.0, 8.0), st.floats(-5.0, 5.0), st.integers(0, 1000))
@settings(max_examples=30, deadline=None)
def test_level_velocity_exact_for_any_terrain(vx, vz, vy, seed):
    p = _hilly_points(np.random.default_rng(seed))
    u = p / np.linalg.norm(p, axis=1, keepdims=True)
    v_true = np.array([vx, vy, vz])
    vel, cov, inl = level_velocity(u, -u @ v_true)
    np.testing.assert_allclose(vel, v_true, atol=1e-6)
    assert inl.all() and np.all(np.isfinite(cov))


def test_level_velocity_ignores_outliers():
    rng = np.random.default_rng(1)
    p = _hilly_points(rng)
    u = p / np.linalg.norm(p, axis=1, keepdims=True)
    v = -u @ np.array([55.0, 0.0, 2.0]) + rng.uniform(-0.15, 0.15, len(u))
    v[::10] -= 12.0  # an intruder, faded bins
    vel, _, inl = level_velocity(u, v)
    np.testing.assert_allclose(vel, [55.0, 0.0, 2.0], atol=0.1)
    assert not inl[::10].any()


def test_ground_points_use_the_doppler_cone_where_it_is_sharp():
    rng = np.random.default_rng(2)
    p = _hilly_points(rng)
    r = np.linalg.norm(p, axis=1)
    u = p / r[:, None]
    v_true = np.array([55.0, 0.0, 1.5])
    noisy = u + rng.normal(0.0, 0.02, u.shape)  # about 1 deg of DoA noise
    got = ground_points(r, -u @ v_true, noisy, v_true, np.full(len(r), 0.02))
    doa_only = r[:, None] * noisy / np.linalg.norm(noisy, axis=1, keepdims=True)
    near = r < 1500.0  # not grazing: the cone angle is well defined
    err = np.abs(got[near, 2] - p[near, 2])
    assert np.median(err) < 0.2 * np.median(np.abs(doa_only[near, 2] - p[near, 2]))
    assert np.median(err) < 3.0


@pytest.mark.parametrize(("vx", "vz"), [(45.0, 0.0), (60.0, 2.0)])
def test_estimator_on_flat_plane_frames(vx, vz):
    # Flat ground looks the same from every horizontal position: only the height changes.
    aware = TerrainAwareEstimator(CFG)
    heights = 600.0 - vz * np.arange(3.0)
    estimates = [
        aware.update(float(t), flat_ground_frame(CFG, vx, vz, h, 150_000, seed=t))
        for t, h in enumerate(heights)
    ]
    last = estimates[-1]
    assert not last.low_quality
    # Random scatterers share ridge pixels with neighbours in azimuth: DoA of a mixture, 0.3 m/s.
    assert last.vx_mps == pytest.approx(vx, abs=0.3) and last.vz_mps == pytest.approx(vz, abs=0.3)
    assert last.h_m == pytest.approx(heights[-1], abs=4.0)


def test_estimator_flags_empty_frames():
    aware = TerrainAwareEstimator(CFG)
    est = aware.update(0.0, np.zeros((CFG.n_range, CFG.n_doppler, CFG.n_rx), np.complex64))
    assert est.low_quality and np.isnan(est.h_m) and np.isnan(est.vx_mps)
