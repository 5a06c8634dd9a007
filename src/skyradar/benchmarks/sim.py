"""Benchmark of the image-domain simulator against a re-implementation of the thesis' approach.

Both run in the same process on the same 1201 x 1201 SRTM-3 tile (one degree, about 90 m
spacing, written to disk and read back as a real ``.hgt``), with the seed prototype at 1000 m
above the terrain. The baseline does what the thesis' code did each frame: map the whole tile
to flat-earth coordinates, build per-surface arrays, drop surfaces beyond RLim or behind the
antenna, then accumulate pixels by looping ``np.unique`` until every surface is placed.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from skyradar.config import RadarConfig
from skyradar.geo import EARTH_RADIUS_M, rotation_matrix
from skyradar.sim.image import ImageSimulator, PlatformState

__all__ = ["thesis_baseline_frame", "benchmark_tile", "run"]


def thesis_baseline_frame(
    elevation_m: np.ndarray,
    lat_axis_deg: np.ndarray,
    lon_axis_deg: np.ndarray,
    config: RadarConfig,
    radar_lat_lon_alt: tuple[float, float, float],
    velocity_ned_mps: np.ndarray,
    attitude_rad: np.ndarray,
    rng: np.random.Generator,
) -> np.ndarray:
    """One frame the thesis' way (whole tile, per-surface arrays, repeated ``np.unique``).

    Returns the (n_range, n_doppler, n_rx) complex cube. Used only as the speed baseline.
    """
    lat_r, lon_r, alt_r = radar_lat_lon_alt
    lat = np.repeat(lat_axis_deg[:, None], lon_axis_deg.size, axis=1)
    lon = np.repeat(lon_axis_deg[None, :], lat_axis_deg.size, axis=0)
    k = EARTH_RADIUS_M * np.pi / 180.0
    north = (lat - lat_r) * k
    east = (lon - lon_r) * k * np.cos(np.radians(lat))
    down = alt_r - elevation_m
    area = (
        (k * abs(lat_axis_deg[1] - lat_axis_deg[0]))
        * (k * abs(lon_axis_deg[1] - lon_axis_deg[0]))
        * np.cos(np.radians(lat))
    )
    ned = np.stack([north.ravel(), east.ravel(), down.ravel()], axis=1)
    rot = (rotation_matrix(*attitude_rad) @ config.mount.rotation).T
    ant = ned @ rot.T
    rng_m = np.linalg.norm(ant, axis=1)
    keep = (rng_m < config.range_limit_m) & (ant[:, 0] > 0)
    ant, rng_m, area, down = ant[keep], rng_m[keep], area.ravel()[keep], down.ravel()[keep]
    unit = ant / rng_m[:, None]
    refl = np.clip(down / rng_m, 0.0, 1.0)  # cosine of incidence on a level facet
    az, el = np.arctan2(unit[:, 1], unit[:, 0]), np.arcsin(-unit[:, 2])
    gain_db = config.antenna.gain_db(az, el)
    power = (
        config.pe_w
        * 10 ** (gain_db / 5)
        * area
        * refl
        * config.wavelength_m**2
        / ((4 * np.pi) ** 3 * rng_m**4)
    )
    v_r = unit @ (rot @ -np.asarray(velocity_ned_mps))
    k_r = np.round(rng_m / config.range_resolution_m).astype(int)
    k_d = (
        np.round(v_r / config.doppler_resolution_mps).astype(int) + config.n_doppler // 2
    ) % config.n_doppler
    cube = np.zeros((config.n_range, config.n_doppler, config.n_rx), complex)
    inside = k_r < config.n_range
    for q in range(config.n_rx):
        path = np.linalg.norm(ant - config.tx_position_m, axis=1) + np.linalg.norm(
            ant - config.rx_positions_m[q], axis=1
        )
        values = (np.sqrt(power) * np.exp(2j * np.pi * path / config.wavelength_m))[inside]
        flat = (k_r * config.n_doppler + k_d)[inside]
        cube[..., q] = _unique_scatter(flat, values, cube.shape[:2])
    noise = rng.standard_normal((*cube.shape, 2)) * np.sqrt(config.noise_power_w / 2)
    return cube + noise[..., 0] + 1j * noise[..., 1]


def _unique_scatter(flat: np.ndarray, values: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """The thesis' accumulation: place one surface per pixel per pass with ``np.unique`` until done."""
    plane = np.zeros(shape[0] * shape[1], complex)
    while flat.size:
        pixels, first = np.unique(flat, return_index=True)
        plane[pixels] += values[first]
        rest = np.ones(flat.size, bool)
        rest[first] = False
        flat, values = flat[rest], values[rest]
    return plane.reshape(shape)


def benchmark_tile(directory: Path, seed: int = 0):
    """Write a synthetic 1201 x 1201 SRTM-3 tile (N45E006.hgt, rolling hills) and read it back."""
    from skyradar.scene.dem_readers import read_hgt

    rng = np.random.default_rng(seed)
    n = 1201
    spectrum = (rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n))) / np.maximum(
        np.hypot(*np.meshgrid(np.fft.fftfreq(n), np.fft.fftfreq(n), indexing="ij")), 1.0 / n
    ) ** 1.8
    hills = np.real(np.fft.ifft2(spectrum))
    elevation = 400.0 + 150.0 * (hills - hills.mean()) / hills.std()
    path = directory / "N45E006.hgt"
    path.write_bytes(np.round(elevation).astype(">i2").tobytes())
    return read_hgt(path)


def _time_frames(fn, n_frames: int, min_seconds: float) -> float:
    """Frames/s from the median frame time after one warm-up frame (numba compile, caches)."""
    fn(0)
    times, start = [], time.perf_counter()
    while len(times) < n_frames or time.perf_counter() - start < min_seconds:
        t0 = time.perf_counter()
        fn(len(times) + 1)
        times.append(time.perf_counter() - t0)
        if time.perf_counter() - start > 10 * max(min_seconds, 1.0):
            break
    return 1.0 / float(np.median(times))


THESIS_FRAMES_PER_S = 3.3  # seed-brief.md ch2: 727 frames in 219 s on the thesis' PC


def run(n_frames: int = 40, baseline_frames: int = 6, min_seconds: float = 2.0) -> dict[str, Any]:
    """Measure frames/s of the simulator (SRTM spacing and fine facets) and of the thesis baseline."""
    config = RadarConfig.seed_prototype()
    with tempfile.TemporaryDirectory() as tmp:
        terrain = benchmark_tile(Path(tmp))
    lat_c, lon_c = terrain.center_latlon
    ground = float(terrain.height_at(lat_c, lon_c))
    origin = (lat_c, lon_c, ground)
    speed = 50.0

    def platform(i: int) -> PlatformState:
        return PlatformState(
            np.array([speed * i / 9.4, 0.0, -1000.0]), np.array([speed, 0.0, 0.0]), np.zeros(3)
        )

    coarse = ImageSimulator(config, terrain, origin, facet_size_m=float("inf"), seed=1)
    fine = ImageSimulator(config, terrain, origin, seed=1)
    # Into one preallocated frame, as simulate_frames writes into its stack of frames.
    buffer = np.empty((config.n_range, config.n_doppler, config.n_rx), np.complex64)
    fps = _time_frames(lambda i: coarse.frame(platform(i), frame_index=i, out=buffer), n_frames, min_seconds)
    fps_fine = _time_frames(
        lambda i: fine.frame(platform(i), frame_index=i, out=buffer), max(3, n_frames // 4), min_seconds
    )

    ny, nx = terrain.shape
    lat_axis = terrain.lat_deg - terrain.dy * np.arange(ny)
    lon_axis = terrain.lon_deg + terrain.dx * np.arange(nx)
    elevation = terrain.elevation_m.astype(float)
    rng = np.random.default_rng(1)

    def baseline(i: int) -> np.ndarray:
        lat = lat_c + platform(i).position_ned_m[0] / (EARTH_RADIUS_M * np.pi / 180)
        return thesis_baseline_frame(
            elevation,
            lat_axis,
            lon_axis,
            config,
            (lat, lon_c, ground + 1000.0),
            np.array([speed, 0, 0]),
            np.zeros(3),
            rng,
        )

    fps_base = _time_frames(baseline, baseline_frames, min_seconds)  # same timing rule as ours
    return {
        "tile": f"{ny}x{nx} SRTM-3",
        "facet_size_fine_m": round(fine._facet_m, 3),
        "frames_per_s": fps,
        "frames_per_s_fine": fps_fine,
        "baseline_frames_per_s": fps_base,
        "speedup": fps / fps_base,
        "speedup_fine": fps_fine / fps_base,
        "thesis_frames_per_s": THESIS_FRAMES_PER_S,
        "speedup_vs_thesis": fps / THESIS_FRAMES_PER_S,
        "speedup_fine_vs_thesis": fps_fine / THESIS_FRAMES_PER_S,
        "timing": "median frame time after one warm-up frame",
    }
