"""bench sim: ours and both numpy baselines compute the same cube; the JSON says what was measured."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from skyradar.benchmarks.sim import FacetPhysics, numpy_baseline_frame, thesis_baseline_frame
from skyradar.config import Mount, RadarConfig
from skyradar.scene.synthetic_terrain import fractal_terrain
from skyradar.sim.image import ImageSimulator, PlatformState

ORIGIN = (52.0, 4.36, 100.0)


@pytest.mark.parametrize(
    ("mount", "rx"),
    [
        ("forward", "square"),
        ("forward-down", "square"),
        ("forward", [[0.0, 0.0, 0.0]]),
        ("forward", "ura-2x3"),
    ],
)
def test_ours_and_both_baselines_give_the_same_cube(mount, rx):
    config = RadarConfig.prototype_2022(range_limit_m=1500.0, mount=Mount.preset(mount), rx_positions_m=rx)
    terrain = fractal_terrain(52.0, 4.36, 30.0, size_m=5000.0, spacing_m=50.0, seed=3, mean_height_m=100.0)
    ours = ImageSimulator(
        config, terrain, ORIGIN, facet_size_m=float("inf"), occlusion=False, flat_earth=True, noise=False
    )
    platform = PlatformState(
        np.array([100.0, -50.0, -600.0]), np.array([45.0, 5.0, 1.0]), np.radians([20.0, 3.0, -5.0])
    )
    cube = ours.frame(platform)
    geom = ours.geometry(platform)
    physics = FacetPhysics(config)
    ny, nx = terrain.shape
    lat, lon = terrain.latlon_of(np.arange(ny, dtype=float)[:, None], np.arange(nx, dtype=float)[None, :])
    thesis = thesis_baseline_frame(lat, lon, terrain.elevation_m.astype(float), ORIGIN, geom, physics, None)
    grid = terrain.points_ned(*ORIGIN, flat_earth=True)
    vectorised = numpy_baseline_frame(terrain, grid, geom, physics, None)
    # Thousands of terrain pixels, all in the same bins with the same values (to complex64).
    assert np.count_nonzero(cube) > 1000
    scale = float(np.abs(cube).max())
    for other in (thesis, vectorised):
        np.testing.assert_array_equal(other != 0, cube != 0)
        np.testing.assert_allclose(other, cube, rtol=0, atol=1e-6 * scale)


def test_baselines_add_thermal_noise_of_the_configured_power():
    config = RadarConfig.prototype_2022(range_limit_m=600.0)
    terrain = fractal_terrain(52.0, 4.36, 0.0, size_m=1000.0, spacing_m=100.0, mean_height_m=-5000.0)
    geom = ImageSimulator(config, terrain, ORIGIN, flat_earth=True).geometry(
        PlatformState(np.zeros(3), np.array([40.0, 0, 0]), np.zeros(3))
    )
    grid = terrain.points_ned(*ORIGIN, flat_earth=True)
    cube = numpy_baseline_frame(terrain, grid, geom, FacetPhysics(config), np.random.default_rng(0))
    # The ground is 5 km below: only noise, E|n|^2 = noise_power_w (to 1 % over 20000 pixels).
    assert np.mean(np.abs(cube) ** 2) == pytest.approx(config.noise_power_w, rel=0.01)


@pytest.mark.slow
def test_bench_sim_json_names_synthetic_terrain_and_both_ratios(tmp_path):
    result = subprocess.run(
        [sys.executable, "-m", "skyradar", "bench", "sim", "--json", "--frames", "1", "--min-time-s", "0"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout.strip().splitlines()[-1])
    assert data["terrain_synthetic"] is True and "not SRTM data" in data["terrain"]
    for key in ("speedup_vs_thesis_baseline", "speedup_vs_numpy_baseline"):
        assert data[key] > 0
    fps = data["frames_per_s"]
    assert data["speedup_vs_numpy_baseline"] == pytest.approx(fps / data["numpy_baseline_frames_per_s"])
    assert data["speedup_vs_thesis_baseline"] == pytest.approx(fps / data["thesis_baseline_frames_per_s"])
    for name in ("rx1", "rx6", "rx8"):  # the other receive arrays, each against its own baseline
        ratio = data[f"{name}_frames_per_s"] / data[f"{name}_numpy_baseline_frames_per_s"]
        assert data[f"{name}_speedup_vs_numpy_baseline"] == pytest.approx(ratio)
    assert data["mimo_2x4_vs_rx8"] == pytest.approx(data["mimo_2x4_frames_per_s"] / data["rx8_frames_per_s"])
    one = data["fine_psf_one_thread_cpu_ms_per_frame"]
    assert data["fine_psf_thread_cpu_overhead"] == pytest.approx(data["fine_psf_cpu_ms_per_frame"] / one)
    wide = {**os.environ, "COLUMNS": "200"}  # the help text unwrapped
    help_text = subprocess.run(
        [sys.executable, "-m", "skyradar", "bench", "sim", "--help"],
        capture_output=True,
        text=True,
        timeout=120,
        env=wide,
    ).stdout
    assert "SYNTHETIC" in help_text and "np.bincount" in help_text
