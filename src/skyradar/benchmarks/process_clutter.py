"""Benchmark: detection + DoA with knowledge-aided clutter suppression on terrain cubes.

Cubes: the image simulator over flat ground 1000 m below the prototype radar (own-ship 50 m/s,
head-on intruder closing at 100 m/s between 1.8 and 3 km), one cube per intruder range. Ours:
:func:`skyradar.process.pipeline.process_cube` with the frame geometry's
:class:`~skyradar.process.clutter.ClutterSubspace` (predicted once per geometry and cached in the
pipeline; its cost is reported separately as ``subspace_s``). Baseline, measured in the same run
on the same cubes: the same steps written straightforwardly in numpy/scipy (per-cell projector
matrices ``I - E E^H`` applied with ``einsum``, ``ndimage.maximum_filter`` for the clutter level,
``ndimage.uniform_filter`` cell averaging with the clutter cells left out of training,
``ndimage.label`` blobs), detection only.
"""

from __future__ import annotations

import time

import numpy as np
from scipy import ndimage, stats

from skyradar.config import RadarConfig
from skyradar.process.clutter import ClutterSubspace, clutter_subspace
from skyradar.process.clutter_suppress import null_count
from skyradar.process.pipeline import process_cube
from skyradar.scene.synthetic_terrain import flat_terrain
from skyradar.sim.image import ImageSimulator, PlatformState, PointTarget

__all__ = ["terrain_cubes", "baseline_suppressed", "run_suppressed"]

HEIGHT_M, SPEED_MPS = 1000.0, 50.0


def terrain_cubes(config: RadarConfig, n_cubes: int, seed: int = 0) -> list[np.ndarray]:
    """Frames over flat ground 1000 m below with a head-on intruder at ranges 3 km down to 1.8 km."""
    sim = ImageSimulator(
        config, flat_terrain(52.0, 5.0, 0.0, 12_000.0, 30.0), origin=(52.0, 5.0, 0.0), seed=seed
    )
    own = PlatformState(np.array([0.0, 0.0, -HEIGHT_M]), np.array([SPEED_MPS, 0.0, 0.0]), np.zeros(3))
    cubes = []
    for i, rng_m in enumerate(np.linspace(3000.0, 1800.0, n_cubes)):
        intruder = PointTarget(np.array([rng_m, 0.0, -HEIGHT_M]), np.array([-50.0, 0.0, 0.0]), rcs_m2=2.0)
        cubes.append(sim.frame(own, [intruder], i))
    return cubes


def baseline_suppressed(cube: np.ndarray, sub: ClutterSubspace, config: RadarConfig, pfa: float = 2e-8):
    """Straightforward numpy/scipy suppression + CA-CFAR; returns (range_index, doppler_index) peaks."""
    z = cube / config.rx_calibration
    noise = config.noise_power_w
    raw = np.linalg.norm(z, axis=-1) ** 2 / config.n_rx
    ring = np.ones((3, 7), bool)
    ring[:, 2:5] = False
    ring_cnr = np.maximum(ndimage.maximum_filter(raw / noise, footprint=ring, mode="wrap") - 1.0, 0.0)
    own = raw / noise - 1.0
    peak = (ring_cnr <= 3.0) & (own + 1.0 > 4.0 * (ring_cnr + 1.0))  # a point target is not clutter
    cnr = np.where(peak, ring_cnr, np.maximum(ring_cnr, own))
    nulls, unsuppressed = null_count(sub.fractions, cnr)
    keep = np.arange(config.n_rx) < nulls[..., None]
    e = sub.vectors * keep[..., None, :]
    proj = np.eye(config.n_rx) - np.einsum("rdki,rdli->rdkl", e, np.conj(e))
    y = np.einsum("rdkl,rdl->rdk", proj, z)
    channels = config.n_rx - nulls
    power = np.linalg.norm(y, axis=-1) ** 2 / channels
    valid = (~unsuppressed).astype(float)
    outer, inner = (13, 21), (5, 5)
    mode = ("reflect", "wrap")

    def ring_sum(image: np.ndarray) -> np.ndarray:
        big = ndimage.uniform_filter(image, outer, mode=mode) * (outer[0] * outer[1])
        return big - ndimage.uniform_filter(image, inner, mode=mode) * (inner[0] * inner[1])

    count = np.rint(ring_sum(valid)).astype(int)
    clean = ring_sum(power * valid) / np.maximum(count, 1)
    plain = ring_sum(power) / (outer[0] * outer[1] - inner[0] * inner[1])
    est = np.maximum(np.where(unsuppressed, plain, np.where(count >= 16, clean, noise)), noise)
    n_train = np.where(
        unsuppressed, outer[0] * outer[1] - inner[0] * inner[1], np.where(count >= 16, count, 0)
    )
    alpha = np.where(
        n_train > 0,
        stats.f.isf(pfa, 2 * channels, 2 * np.maximum(n_train, 1) * channels),
        stats.gamma.isf(pfa, channels, scale=1.0 / channels),
    )
    labels, n = ndimage.label(power > alpha * est, structure=np.ones((3, 3)))
    peaks = ndimage.maximum_position(power, labels, range(1, n + 1)) if n else []
    return np.array(peaks, int).reshape(-1, 2)


def _per_s(fn, cubes: list[np.ndarray], min_time_s: float) -> tuple[float, float]:
    """Frames/s (wall, CPU) of the fastest pass over ``cubes``, passes repeated for ``min_time_s``.

    One whole pass first warms every cube's lazily filled state; the best pass, as ``timeit``
    advises, keeps another process's burst on a shared machine out of the figure (single timed
    spans varied by 30 % between runs at load 1).
    """
    for cube in cubes:
        fn(cube)
    best_wall, best_cpu, start = np.inf, np.inf, time.perf_counter()
    while time.perf_counter() - start < min_time_s or not np.isfinite(best_wall):
        t0, c0 = time.perf_counter(), time.process_time()
        for cube in cubes:
            fn(cube)
        best_wall = min(best_wall, time.perf_counter() - t0)
        best_cpu = min(best_cpu, time.process_time() - c0)
    return len(cubes) / best_wall, len(cubes) / max(best_cpu, 1e-9)


def run_suppressed(n_cubes: int = 6, min_time_s: float = 2.0, seed: int = 0) -> dict:
    """Frames per second (wall clock and per process-CPU second) of ours and the numpy baseline."""
    config = RadarConfig.prototype_2022()
    cubes = terrain_cubes(config, n_cubes, seed)
    t0 = time.perf_counter()
    sub = clutter_subspace(
        config, np.array([SPEED_MPS, 0.0, 0.0]), config.mount.rotation, HEIGHT_M, n_azimuth=720
    )
    sub.ensure()  # every cell's eigen-pairs: the whole prediction, as before cells were decomposed lazily
    subspace_s = time.perf_counter() - t0
    ours, ours_cpu = _per_s(lambda c: process_cube(c, config, clutter=sub), cubes, min_time_s)
    plain, plain_cpu = _per_s(lambda c: process_cube(c, config), cubes, min_time_s / 2)
    base, base_cpu = _per_s(lambda c: baseline_suppressed(c, sub, config), cubes, min_time_s)
    return {
        "suppressed_frames_per_s": float(ours),
        "suppressed_cpu_frames_per_s": float(ours_cpu),
        "suppressed_baseline_frames_per_s": float(base),
        "suppressed_baseline_cpu_frames_per_s": float(base_cpu),
        "suppressed_speedup_cpu": float(ours_cpu / base_cpu),
        "terrain_unsuppressed_cpu_frames_per_s": float(plain_cpu),
        "terrain_unsuppressed_frames_per_s": float(plain),
        "subspace_s": float(subspace_s),
        # Primary detections: the numpy baseline has no secondary threshold.
        "suppressed_detections_per_frame": float(
            np.mean([len(_primary(process_cube(c, config, clutter=sub))) for c in cubes])
        ),
        "suppressed_baseline_detections_per_frame": float(
            np.mean([len(baseline_suppressed(c, sub, config)) for c in cubes])
        ),
        "terrain_unsuppressed_detections_per_frame": float(
            np.mean([len(process_cube(c, config)["range_m"]) for c in cubes])
        ),
    }


def _primary(out: dict) -> np.ndarray:
    """The range of each primary detection of a :func:`process_cube` result."""
    return out["range_m"][~out["secondary"]]
