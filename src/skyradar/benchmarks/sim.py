"""Benchmark of the image-domain simulator against two numpy baselines: same run, same physics.

Terrain: a SYNTHETIC 1201 x 1201 tile in SRTM-3 ``.hgt`` format (one degree at 3 arc-seconds,
about 90 m; rolling hills from seeded noise, written to disk and read back by the ``.hgt``
reader). It is not SRTM data: it only has the size, spacing and file format of an SRTM-3 tile.
The radar is the thesis prototype 1000 m above the tile's centre, flying level at 50 m/s.

Three implementations of one physics, timed by one rule (median frame time after a warm-up):
a facet per DEM cell (its bilinear centre, exact normal and area), the thesis' flat-earth
mapping of the DEM, no occlusion, cosine reflectivity, the simulator's two-way gain table, the
radar equation, the exact two-way path phase per receiver, Doppler wrap, the range-Doppler
coupling, and thermal noise.

- ours: :class:`~skyradar.sim.image.ImageSimulator` with ``flat_earth=True``,
  ``occlusion=False`` and DEM-spacing facets;
- thesis baseline (:func:`thesis_baseline_frame`): what the thesis' code did each frame: map
  the whole tile to flat-earth coordinates, build per-facet arrays over the whole tile, drop
  facets beyond RLim or behind the antenna, then place them with a loop of ``np.unique`` until
  every facet is in;
- numpy baseline (:func:`numpy_baseline_frame`): the straightforward vectorised version: the
  tile mapped once, cropped to the radar's reach each frame, per-facet arrays over the crop,
  and ``np.bincount`` over the flat pixel index for the real and imaginary part per receiver.

Ours is also timed with its full physics (exact geodesy, occlusion), at DEM spacing and at
facets of at most dR/2, and at dR/2 with the windows' point-spread and speckle
(``frames_per_s_fine_psf``, its ratio to the same run's fine figure, and its multiple of the
9.4 Hz field rate); no baseline does that work, so those have no baseline ratio. The
``frames_per_s`` physics is timed again with one receive channel, the 2x3 and the 2x4 URA
(``rx1_*``, ``rx6_*``, ``rx8_*``, each against the numpy baseline of that array), and with the
``mimo-2x4`` radar (``mimo_2x4_*``: eight virtual channels over half the Doppler bins, against
``rx8``; the baselines model one transmitter).
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path
from typing import Any

import numba
import numpy as np

from skyradar.config import RadarConfig
from skyradar.geo import geodetic_to_ned
from skyradar.sim._terrain_kernel import cell_count_grid
from skyradar.sim.geometry import AntennaGeometry
from skyradar.sim.image import ImageSimulator, PlatformState, reflectivity_table, two_way_gain_table
from skyradar.units import nearest_bin

__all__ = [
    "FacetPhysics",
    "facet_returns",
    "thesis_baseline_frame",
    "numpy_baseline_frame",
    "benchmark_tile",
    "run",
]

TERRAIN_NOTE = "synthetic terrain (rolling hills, seed 0) in SRTM-3 .hgt format, not SRTM data"
FIELD_RATE_HZ = 9.4  # the prototype's frame rate in flight
THESIS_FRAMES_PER_S = 3.3  # Maas 2022, ch. 2: 727 frames in 219 s on the thesis' PC (not re-measured)


class FacetPhysics:
    """The per-frame constants every implementation shares: radar, gain and reflectivity tables.

    Parameters
    ----------
    config : RadarConfig
        Radar hardware, antenna pattern and mount.
    coupling : bool
        Apply the range-Doppler coupling (as ``ImageSimulator(range_doppler_coupling=True)``).
    """

    def __init__(self, config: RadarConfig, coupling: bool = True) -> None:
        self.config = config
        self.gain2, self.gain2_step = two_way_gain_table(config)
        self._gain2_f64 = self.gain2.astype(float)  # the kernel reads float32 into float64 math
        self.refl_table = reflectivity_table("cosine")
        self.coupling_s = config.range_doppler_coupling_s if coupling else 0.0
        self.power_const = config.pe_w * config.wavelength_m**2 / (4 * np.pi) ** 3
        self.r_max_m = config.range_resolution_m * (config.n_range + 2)

    def gain(self, uy: np.ndarray, uz: np.ndarray) -> np.ndarray:
        """Two-way linear gain, bilinear on the table of direction cosines (the kernel's lookup)."""
        fy, fz = (uy + 1.0) / self.gain2_step, (uz + 1.0) / self.gain2_step
        n = self.gain2.shape[0] - 1
        iy, iz = np.clip(fy.astype(int), 0, n - 1), np.clip(fz.astype(int), 0, n - 1)
        ty, tz = np.clip(fy - iy, 0.0, 1.0), np.clip(fz - iz, 0.0, 1.0)
        g = self._gain2_f64
        return (1 - ty) * ((1 - tz) * g[iy, iz] + tz * g[iy, iz + 1]) + ty * (
            (1 - tz) * g[iy + 1, iz] + tz * g[iy + 1, iz + 1]
        )

    def reflectivity(self, cos_inc: np.ndarray) -> np.ndarray:
        """Reflectivity factor, linear on the table over cos(incidence) in [0, 1]."""
        return np.interp(cos_inc, np.linspace(0.0, 1.0, self.refl_table.size), self.refl_table)


def facet_returns(
    p_ant: np.ndarray, geom: AntennaGeometry, physics: FacetPhysics
) -> tuple[np.ndarray, np.ndarray]:
    """Flat pixel index and complex value per receiver of every DEM cell that returns, with numpy.

    ``p_ant`` (ny, nx, 3) is the grid relative to the antenna phase centre in the antenna
    frame, m. A cell's facet sits at its bilinear centre with the patch normal and area there,
    exactly as the compiled kernel does at DEM spacing. Returns (m,) int64 and (m, n_rx)
    complex128.
    """
    cfg = physics.config
    centre = 0.25 * (p_ant[:-1, :-1] + p_ant[1:, :-1] + p_ant[:-1, 1:] + p_ant[1:, 1:])
    r0 = np.sqrt(np.einsum("...c,...c->...", centre, centre))
    i, j = np.nonzero((centre[..., 0] > 0.0) & (r0 <= physics.r_max_m))  # cull before the real work
    p, r0 = centre[i, j], r0[i, j]
    e1, e2 = p_ant[i + 1, j] - p_ant[i, j], p_ant[i, j + 1] - p_ant[i, j]
    e3 = p_ant[i + 1, j + 1] - p_ant[i + 1, j] - p_ant[i, j + 1] + p_ant[i, j]
    normal = np.cross(e1 + 0.5 * e3, e2 + 0.5 * e3)
    up = -geom.rot_ned_to_ant[:, 2]
    normal[normal @ up < 0.0] *= -1.0
    area = np.linalg.norm(normal, axis=1)
    cos_inc = -np.einsum("mc,mc->m", normal, p) / (area * r0 + 1e-300)
    r_tx = np.linalg.norm(p - cfg.tx_position_m, axis=1)
    r_rx = np.linalg.norm(p[:, None, :] - cfg.rx_positions_m[None], axis=2)  # (m, n_rx)
    rng = 0.5 * (r_tx + r_rx.mean(axis=1))
    v_r = p @ (geom.rot_ned_to_ant @ -geom.velocity_ned_mps) / r0
    kr = nearest_bin(rng + physics.coupling_s * v_r, cfg.range_resolution_m)
    kd = cfg.doppler_bin(v_r)
    ok = (cos_inc > 0.0) & (kr >= 0) & (kr < cfg.n_range)
    power = (
        physics.power_const
        * physics.gain(p[ok, 1] / r0[ok], p[ok, 2] / r0[ok])
        * physics.reflectivity(cos_inc[ok])
        * area[ok]
    )
    amp = np.sqrt(power) / rng[ok] ** 2
    values = amp[:, None] * np.exp(2j * np.pi * (r_tx[ok, None] + r_rx[ok]) / cfg.wavelength_m)
    return (kr[ok] * cfg.n_doppler + kd[ok]).astype(np.int64), values


def _add_noise(cube: np.ndarray, config: RadarConfig, rng: np.random.Generator | None) -> np.ndarray:
    if rng is None:
        return cube
    noise = rng.standard_normal((*cube.shape, 2)) * np.sqrt(config.noise_power_w / 2)
    return cube + noise[..., 0] + 1j * noise[..., 1]


def thesis_baseline_frame(
    lat_deg: np.ndarray,
    lon_deg: np.ndarray,
    elevation_m: np.ndarray,
    origin: tuple[float, float, float],
    geom: AntennaGeometry,
    physics: FacetPhysics,
    rng: np.random.Generator | None,
) -> np.ndarray:
    """One frame the thesis' way: whole tile mapped each frame, repeated ``np.unique`` placement.

    ``lat_deg``, ``lon_deg``, ``elevation_m`` are the DEM samples (ny, nx); ``origin`` the
    scenario's geodetic origin; ``geom`` the antenna pose; ``rng`` None leaves out the noise.
    Returns the (n_range, n_doppler, n_rx) complex128 cube.
    """
    cfg = physics.config
    grid = geodetic_to_ned(lat_deg, lon_deg, elevation_m, *origin, flat_earth=True)
    p_ant = (grid - geom.origin_ned_m) @ geom.rot_ned_to_ant.T
    flat, values = facet_returns(p_ant, geom, physics)
    cube = np.zeros((cfg.n_range, cfg.n_doppler, cfg.n_rx), complex)
    for q in range(cfg.n_rx):
        cube[..., q] = _unique_scatter(flat, values[:, q], cube.shape[:2])
    return _add_noise(cube, cfg, rng)


def _unique_scatter(flat: np.ndarray, values: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """The thesis' accumulation: place one facet per pixel per pass with ``np.unique`` until done."""
    plane = np.zeros(shape[0] * shape[1], complex)
    while flat.size:
        pixels, first = np.unique(flat, return_index=True)
        plane[pixels] += values[first]
        rest = np.ones(flat.size, bool)
        rest[first] = False
        flat, values = flat[rest], values[rest]
    return plane.reshape(shape)


def numpy_baseline_frame(
    terrain,
    grid_ned: np.ndarray,
    geom: AntennaGeometry,
    physics: FacetPhysics,
    rng: np.random.Generator | None,
) -> np.ndarray:
    """One frame the straightforward vectorised way: crop, per-facet arrays, ``np.bincount``.

    ``grid_ned`` is ``terrain.points_ned(*origin, flat_earth=True)``, computed once. Returns
    the (n_range, n_doppler, n_rx) complex64 cube (no noise when ``rng`` is None).

    Examples
    --------
    >>> from skyradar.scene.synthetic_terrain import flat_terrain
    >>> cfg = RadarConfig.prototype_2022(range_limit_m=1000.0)
    >>> origin = (52.0, 4.36, 0.0)
    >>> ground = flat_terrain(*origin, size_m=3000.0, spacing_m=50.0)
    >>> sim = ImageSimulator(cfg, ground, origin, facet_size_m=float("inf"), occlusion=False, flat_earth=True)
    >>> geom = sim.geometry(PlatformState(np.array([0.0, 0, -500]), np.array([40.0, 0, 0]), np.zeros(3)))
    >>> grid = ground.points_ned(*origin, flat_earth=True)
    >>> cube = numpy_baseline_frame(ground, grid, geom, FacetPhysics(cfg), None)
    >>> first = np.flatnonzero(np.abs(cube).sum(axis=(1, 2)))[0]
    >>> round(float(cfg.range_axis_m[first]))  # nearest ground return: the height, 500 m
    495
    """
    cfg = physics.config
    n_pix = cfg.n_range * cfg.n_doppler
    if rng is None:
        cube = np.zeros((n_pix, cfg.n_rx), np.complex64)
    else:  # float32 noise viewed as complex64: the cube's own precision, half the work
        noise = rng.standard_normal((n_pix, cfg.n_rx, 2), dtype=np.float32)
        noise *= np.float32(np.sqrt(cfg.noise_power_w / 2))
        cube = noise.view(np.complex64)[..., 0]
    reach = physics.r_max_m + 2 * max(terrain.spacing_m) + float(np.linalg.norm(cfg.mount.position_m))
    rows, cols = terrain.crop_window(geom.lat_deg, geom.lon_deg, reach)
    if rows.stop - rows.start >= 2 and cols.stop - cols.start >= 2:
        p_ant = (grid_ned[rows, cols] - geom.origin_ned_m) @ geom.rot_ned_to_ant.T
        flat, values = facet_returns(p_ant, geom, physics)
        for q in range(cfg.n_rx):
            cube[:, q] += np.bincount(flat, values[:, q].real, n_pix) + 1j * np.bincount(
                flat, values[:, q].imag, n_pix
            )
    return cube.reshape(cfg.n_range, cfg.n_doppler, cfg.n_rx)


def benchmark_tile(directory: Path, seed: int = 0):
    """Write a SYNTHETIC 1201 x 1201 tile in SRTM-3 format (N45E006.hgt, rolling hills), read it back."""
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
    return _time_frames_cpu(fn, n_frames, min_seconds)[0]


def _time_frames_cpu(fn, n_frames: int, min_seconds: float) -> tuple[float, float]:
    """Frames/s (median wall time) and the median CPU-ms per frame, all threads (process time)."""
    fn(0)
    times: list[float] = []
    cpu: list[float] = []
    start = time.perf_counter()
    while len(times) < n_frames or time.perf_counter() - start < min_seconds:
        t0, c0 = time.perf_counter(), time.process_time()
        fn(len(times) + 1)
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
        if time.perf_counter() - start > 10 * max(min_seconds, 1.0):
            break
    return 1.0 / float(np.median(times)), 1e3 * float(np.median(cpu))


def _baseline_fps(config, terrain, origin, geometry, n_frames, baseline_frames, min_seconds) -> tuple:
    """Frames/s of the thesis-style and the numpy baseline, on the same tile and geometry as ours."""
    physics, rng = FacetPhysics(config), np.random.default_rng(1)
    ny, nx = terrain.shape
    lat, lon = terrain.latlon_of(np.arange(ny, dtype=float)[:, None], np.arange(nx, dtype=float)[None, :])
    elevation = terrain.elevation_m.astype(float)
    fps_thesis = _time_frames(
        lambda i: thesis_baseline_frame(lat, lon, elevation, origin, geometry(i), physics, rng),
        baseline_frames,
        min_seconds,
    )
    return fps_thesis, _numpy_baseline_fps(config, terrain, origin, geometry, n_frames, min_seconds)


def _numpy_baseline_fps(config, terrain, origin, geometry, n_frames: int, min_seconds: float) -> float:
    """Frames/s of the numpy baseline on the tile and geometry ours is timed on."""
    physics, rng = FacetPhysics(config), np.random.default_rng(1)
    grid = terrain.points_ned(*origin, flat_earth=True)
    return _time_frames(
        lambda i: numpy_baseline_frame(terrain, grid, geometry(i), physics, rng), n_frames, min_seconds
    )


# Receive arrays timed besides the prototype's four channels: one channel, 2x3 and 2x4 URAs.
_OTHER_ARRAYS = {"rx1": [[0.0, 0.0, 0.0]], "rx6": "ura-2x3", "rx8": "ura-2x4"}


def _array_keys(terrain, origin, platform, n_frames: int, baseline_frames: int, min_seconds: float) -> dict:
    """Frames/s of the same-physics frames (DEM-cell facets, flat earth, no occlusion) for 1, 6 and 8
    receive channels, each with the numpy baseline of the same array in this run, and of the
    ``mimo-2x4`` radar (8 virtual channels over half the Doppler bins), against ``rx8``'s."""
    out: dict[str, Any] = {}
    layouts: dict[str, Any] = {**_OTHER_ARRAYS, "mimo_2x4": "mimo-2x4"}
    for name, rx in layouts.items():
        config = RadarConfig.prototype_2022(rx_positions_m=rx)
        sim = ImageSimulator(
            config, terrain, origin, facet_size_m=float("inf"), occlusion=False, flat_earth=True
        )
        buffer = np.empty(config.frame_shape, np.complex64)
        fps = _time_frames(
            lambda i, sim=sim, out=buffer: sim.frame(platform(i), frame_index=i, out=out),
            n_frames,
            min_seconds,
        )
        out[f"{name}_frames_per_s"] = fps
        if config.n_tx > 1:  # the baselines model one transmitter
            out[f"{name}_vs_rx8"] = fps / out["rx8_frames_per_s"]
            continue
        geometry = (config, terrain, origin, lambda i, sim=sim: sim.geometry(platform(i)))
        fps_numpy = _numpy_baseline_fps(*geometry, min(n_frames, 3 * baseline_frames), min_seconds)
        out[f"{name}_numpy_baseline_frames_per_s"] = fps_numpy
        out[f"{name}_speedup_vs_numpy_baseline"] = fps / fps_numpy
    return out


def _sub_facets(sim: ImageSimulator, platform: PlatformState) -> int:
    """Sub-facets the simulator cuts the terrain in view into for one frame (cells culled whole: 0)."""
    geom = sim.geometry(platform)
    view = sim.terrain_view(geom)
    if view is None:  # no terrain in range
        return 0
    p_ant = np.ascontiguousarray(view.p_ned @ geom.rot_ned_to_ant.T)
    v_ground = geom.rot_ned_to_ant @ -geom.velocity_ned_mps
    rule, cfg = sim._facets, sim.config
    r_max = cfg.range_resolution_m * (cfg.n_range + 2)  # the kernel's
    counts = cell_count_grid(p_ant, v_ground, np.array(rule.counts), rule.adapt, r_max)
    return int(np.prod(counts, axis=-1).sum())


def _psf_keys(config, terrain, origin, platform, ours, n: int, fps_fine: float) -> dict[str, Any]:
    """The point-spread keys: fine facets with the windows' point-spread and speckle, by both facet rules.

    ``ours(sim, n)`` times a simulator: (frames/s, CPU-ms per frame).
    """
    # Cells cut by their range and Doppler extent (the default with psf), and by ground size (uniform).
    fine_psf = ImageSimulator(config, terrain, origin, seed=1, psf=True, speckle=True)
    uniform_psf = ImageSimulator(
        config, terrain, origin, seed=1, psf=True, speckle=True, adaptive_facets=False
    )
    fps_fine_psf, cpu_fine_psf = ours(fine_psf, n)
    fps_uniform_psf, cpu_uniform_psf = ours(uniform_psf, n)
    threads = numba.get_num_threads()
    numba.set_num_threads(1)  # the work of a frame, without waits for other threads (or other jobs)
    try:
        fps_one, cpu_one = ours(fine_psf, n)
    finally:
        numba.set_num_threads(threads)
    return {
        "frames_per_s_fine_psf": fps_fine_psf,
        "fine_psf_vs_fine": fps_fine_psf / fps_fine,
        "fine_psf_x_field_rate": fps_fine_psf / FIELD_RATE_HZ,
        "fine_psf_cpu_ms_per_frame": cpu_fine_psf,
        "frames_per_s_fine_psf_one_thread": fps_one,
        "fine_psf_one_thread_cpu_ms_per_frame": cpu_one,
        # CPU time all threads spend on a frame over one thread's: the cost of splitting it.
        "fine_psf_thread_cpu_overhead": cpu_fine_psf / cpu_one,
        "fine_psf": "sub-facets <= dR/2 in range and <= half a Doppler bin (cut per cell by its extent), "
        "exact geodesy, occlusion, Hann x Hann point-spread, speckle (ours only)",
        "sub_facets_per_frame_fine_psf": _sub_facets(fine_psf, platform(0)),
        "frames_per_s_fine_psf_uniform": fps_uniform_psf,
        "fine_psf_uniform_cpu_ms_per_frame": cpu_uniform_psf,
        "sub_facets_per_frame_fine_psf_uniform": _sub_facets(uniform_psf, platform(0)),
        "fine_psf_vs_uniform": fps_fine_psf / fps_uniform_psf,
        "fine_psf_uniform": "as fine_psf, every cell cut into facets <= dR/2 on the ground (the baseline)",
    }


def run(n_frames: int = 40, baseline_frames: int = 6, min_seconds: float = 2.0) -> dict[str, Any]:
    """Frames/s of the simulator and of both baselines on the synthetic tile, in one run."""
    load_before = os.getloadavg()[0]
    config = RadarConfig.prototype_2022()
    with tempfile.TemporaryDirectory() as tmp:
        terrain = benchmark_tile(Path(tmp))
    lat_c, lon_c = terrain.center_latlon
    origin = (lat_c, lon_c, float(terrain.height_at(lat_c, lon_c)))
    speed = 50.0

    def platform(i: int) -> PlatformState:
        return PlatformState(
            np.array([speed * i / 9.4, 0.0, -1000.0]), np.array([speed, 0.0, 0.0]), np.zeros(3)
        )

    # Into one preallocated frame, as simulate_frames writes into its stack of frames.
    buffer = np.empty(config.frame_shape, np.complex64)

    def ours_cpu(sim: ImageSimulator, n: int) -> tuple[float, float]:
        return _time_frames_cpu(lambda i: sim.frame(platform(i), frame_index=i, out=buffer), n, min_seconds)

    same = ImageSimulator(
        config, terrain, origin, facet_size_m=float("inf"), occlusion=False, flat_earth=True
    )
    full = ImageSimulator(config, terrain, origin, facet_size_m=float("inf"), seed=1)
    fine = ImageSimulator(config, terrain, origin, seed=1)
    fps, fps_full = ours_cpu(same, n_frames)[0], ours_cpu(full, n_frames)[0]
    fps_fine = ours_cpu(fine, max(3, n_frames // 4))[0]
    psf_keys = _psf_keys(config, terrain, origin, platform, ours_cpu, max(3, n_frames // 4), fps_fine)

    ours_geometry = (config, terrain, origin, lambda i: same.geometry(platform(i)))
    fps_thesis, fps_numpy = _baseline_fps(*ours_geometry, n_frames, baseline_frames, min_seconds)
    arrays = _array_keys(terrain, origin, platform, n_frames, baseline_frames, min_seconds)
    ny, nx = terrain.shape
    return {
        "terrain": f"{ny}x{nx} {TERRAIN_NOTE}",
        "terrain_synthetic": True,
        "physics": "DEM-cell facets, flat earth, no occlusion, cosine reflectivity, noise (all three)",
        "frames_per_s": fps,
        "thesis_baseline_frames_per_s": fps_thesis,
        "numpy_baseline_frames_per_s": fps_numpy,
        "speedup_vs_thesis_baseline": fps / fps_thesis,
        "speedup_vs_numpy_baseline": fps / fps_numpy,
        "frames_per_s_full_physics": fps_full,
        "facet_size_fine_m": round(fine._facet_m, 3),
        "frames_per_s_fine": fps_fine,
        **psf_keys,
        "full_physics": "exact WGS84 geodesy and occlusion (ours only; no baseline ratio)",
        **arrays,
        "arrays": "rx1, rx6 (ura-2x3), rx8 (ura-2x4): the frames_per_s physics with that receive array, "
        "each against its numpy baseline; mimo_2x4: 8 virtual channels over half the Doppler bins, "
        "against rx8",
        "thesis_code_frames_per_s": THESIS_FRAMES_PER_S,
        "speedup_vs_thesis_code": fps / THESIS_FRAMES_PER_S,
        "timing": f"median frame time after one warm-up frame, at least {min_seconds:g} s per implementation",
        "load_average_1min": [load_before, os.getloadavg()[0]],
        # Ours runs on numba threads: under load they wait for each other (see the README).
        "numba_threads": numba.get_num_threads(),
        "numba_threading_layer": numba.threading_layer(),
    }
