"""Benchmark: detection + DoA frames per second on prototype-size cubes (333 x 250 x 4).

The same for other receive arrays (``rx{n}_frames_per_s``, ``rx{n}_cpu_frames_per_s``): one
channel (no direction), ``ura-2x3`` (6) and ``ura-2x4`` (8), on cubes of the same targets.

Ours: :func:`skyradar.process.pipeline.process_cube` (compiled channel integration, box-filter
CA-CFAR with Doppler wrap, blob peaks, vectorised phase least squares). Baseline, measured in the
same run on the same cubes: the textbook numpy/scipy version (``np.abs(.)**2`` mean,
``ndimage.uniform_filter`` CA-CFAR, ``ndimage.label`` + ``maximum_position`` per blob,
``np.linalg.lstsq`` DoA per detection).

Also, on terrain cubes with knowledge-aided clutter suppression on, ours against a numpy
baseline of the same steps (``suppressed_*`` keys, :mod:`skyradar.benchmarks.process_clutter`),
and over relief the adaptive nulls against a numpy version of the same rule (``relief_*`` keys,
:mod:`skyradar.benchmarks.process_adaptive`).

Also home of :func:`synthetic_frame`, the reference cube generator used by the tests: point
targets placed with the exact two-way phase formula plus complex Gaussian noise.
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence

import numpy as np
from scipy import ndimage

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.process.detect import cfar_factor
from skyradar.process.doa import direction_from_angles
from skyradar.process.pipeline import process_cube
from skyradar.process.spurs import SpurMap

__all__ = ["synthetic_frame", "baseline_process", "run", "run_arrays"]


def synthetic_frame(
    config: RadarConfig,
    targets: Sequence[tuple[float, float, float, float, float]] = (),
    rng: np.random.Generator | None = None,
    rx_gain: np.ndarray | None = None,
    noise: bool = True,
) -> tuple[np.ndarray, list[tuple[int, int]]]:
    """One (n_range, n_doppler, n_rx) complex64 frame with point targets and thermal noise.

    Parameters
    ----------
    targets : sequence of (range_m, radial_velocity_mps, azimuth_rad, elevation_rad, snr_db)
        Each placed in its nearest pixel with per-channel SNR ``snr_db`` and the exact two-way
        phase ``2 pi (|p - tx| + |p - rx_k|) / lambda`` (antenna frame), random common phase.
    rx_gain : ndarray (n_rx,), complex, optional
        Per-channel gain errors multiplied into the signal (uncalibrated hardware).

    Returns
    -------
    cube, pixels : ndarray, list of (range_index, doppler_index)
    """
    rng = np.random.default_rng() if rng is None else rng
    shape = (config.n_range, config.n_doppler, config.n_rx)
    cube = np.zeros(shape, np.complex64)
    if noise:
        sigma = np.float32(np.sqrt(config.noise_power_w / 2.0))
        cube = (rng.standard_normal((*shape, 2), dtype=np.float32) * sigma).view(np.complex64)[..., 0]
    gain = np.ones(config.n_rx) if rx_gain is None else np.asarray(rx_gain)
    pixels = []
    for range_m, v_mps, az, el, snr_db in targets:
        p = range_m * direction_from_angles(az, el)
        path = np.linalg.norm(p - config.tx_position_m) + np.linalg.norm(p - config.rx_positions_m, axis=1)
        amp = np.sqrt(config.noise_power_w * 10 ** (snr_db / 10.0))
        value = amp * np.exp(
            1j * (2 * np.pi * np.mod(path / config.wavelength_m, 1.0) + rng.uniform(0, 2 * np.pi))
        )
        k, j = int(config.range_bin(range_m)), int(config.doppler_bin(v_mps))
        cube[k, j, :] += (value * gain).astype(np.complex64)
        pixels.append((k, j))
    return cube, pixels


def baseline_process(cube: np.ndarray, config: RadarConfig, pfa: float = 2e-8) -> np.ndarray:
    """Straightforward numpy/scipy detection + DoA; returns (n, 3) antenna-frame positions."""
    power = (np.abs(cube / config.rx_calibration) ** 2).mean(axis=2)
    outer, inner = (13, 21), (5, 5)
    n_train = outer[0] * outer[1] - inner[0] * inner[1]
    mode = ("reflect", "wrap")
    s_out = ndimage.uniform_filter(power, outer, mode=mode) * (outer[0] * outer[1])
    s_in = ndimage.uniform_filter(power, inner, mode=mode) * (inner[0] * inner[1])
    noise = (s_out - s_in) / n_train
    hits = power > cfar_factor(pfa, n_train, config.n_rx) * noise
    labels, n = ndimage.label(hits, structure=np.ones((3, 3)))
    peaks = ndimage.maximum_position(power, labels, range(1, n + 1)) if n else []
    k = 2 * np.pi / config.wavelength_m
    design = -k * (config.rx_positions_m[1:] - config.rx_positions_m[0])[:, 1:]
    out = []
    for r, d in peaks:
        z = cube[r, d] / config.rx_calibration
        psi = np.angle(z[1:] * np.conj(z[0]))
        yz = np.linalg.lstsq(design, psi, rcond=None)[0]
        x = np.sqrt(max(1.0 - yz @ yz, 0.0))
        out.append(r * config.range_resolution_m * np.array([x, *yz]))
    return np.array(out).reshape(-1, 3)


def _frames_per_s(fn, cubes: list[np.ndarray], min_time_s: float) -> tuple[float, float]:
    """(wall-clock, process-CPU) frames per second; CPU time is robust to a busy shared machine."""
    if not 0.0 < min_time_s < float("inf"):  # NaN never compares >=: the loop would never end
        raise InputError(f"bench process: min_time_s must be finite and > 0, got {min_time_s}")
    fn(cubes[0])  # warm-up (numba compile, caches)
    n, t0, c0 = 0, time.perf_counter(), time.process_time()
    while True:
        fn(cubes[n % len(cubes)])
        n += 1
        elapsed = time.perf_counter() - t0
        if elapsed >= min_time_s and n >= len(cubes):
            return n / elapsed, n / max(time.process_time() - c0, 1e-9)


_OTHER_ARRAYS = {1: [[0.0, 0.0, 0.0]], 6: "ura-2x3", 8: "ura-2x4"}


def _synthetic_cubes(config: RadarConfig, n_cubes: int, n_targets: int, seed: int) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    cubes = []
    for _ in range(n_cubes):
        targets = [
            (
                rng.uniform(300, 4500),
                rng.uniform(-35, 35),
                rng.uniform(-0.5, 0.5),
                rng.uniform(-0.5, 0.5),
                25.0,
            )
            for _ in range(n_targets)
        ]
        cubes.append(synthetic_frame(config, targets, rng)[0])
    return cubes


def run_arrays(n_cubes: int = 4, n_targets: int = 5, min_time_s: float = 1.0, seed: int = 0) -> dict:
    """``process_cube`` frames per second (wall clock and per CPU second) of the 1-, 6- and 8-channel
    arrays (``rx1_*``, ``rx6_*``, ``rx8_*``)."""
    out = {}
    for n_rx, rx in _OTHER_ARRAYS.items():
        config = RadarConfig.prototype_2022(rx_positions_m=rx)
        cubes = _synthetic_cubes(config, n_cubes, n_targets, seed)
        wall, cpu = _frames_per_s(lambda c, cfg=config: process_cube(c, cfg), cubes, min_time_s)
        out[f"rx{n_rx}_frames_per_s"], out[f"rx{n_rx}_cpu_frames_per_s"] = float(wall), float(cpu)
    return out


def run(n_cubes: int = 8, n_targets: int = 5, min_time_s: float = 2.0, seed: int = 0) -> dict:
    """Measure detection + DoA throughput of ours and the baseline on the same cubes.

    Returns ``frames_per_s`` (wall clock), ``baseline_frames_per_s``, ``speedup``, the same per
    process-CPU second (``cpu_frames_per_s``: what a free core would do), the machine's load
    average, the cube shape and the detections per frame of each (they should agree); and
    :func:`run_arrays`' frames per second of other receive arrays.
    """
    config = RadarConfig.prototype_2022()
    cubes = _synthetic_cubes(config, n_cubes, n_targets, seed)
    ours, ours_cpu = _frames_per_s(lambda c: process_cube(c, config), cubes, min_time_s)
    # With a spur map (zero-Doppler column and near-range rows masked): spur-aware CFAR.
    freq = np.zeros((config.n_range, config.n_doppler), np.float32)
    freq[:7] = freq[:, config.n_doppler // 2] = 1.0
    spur_map = SpurMap(freq, 0.05, 1)
    masked, _ = _frames_per_s(lambda c: process_cube(c, config, spur_map), cubes, min_time_s / 2)
    base, base_cpu = _frames_per_s(lambda c: baseline_process(c, config), cubes, min_time_s)
    n_ours = np.mean([len(process_cube(c, config)["range_m"]) for c in cubes])
    n_base = np.mean([len(baseline_process(c, config)) for c in cubes])
    # With knowledge-aided clutter suppression on terrain cubes (skyradar.benchmarks.process_clutter).
    from skyradar.benchmarks.process_clutter import run_suppressed  # the simulator only when benchmarking

    suppressed = run_suppressed(min_time_s=min_time_s, seed=seed)
    # Over relief, the adaptive nulls against their numpy baseline (skyradar.benchmarks.process_adaptive).
    from skyradar.benchmarks.process_adaptive import run_adaptive

    return (
        suppressed
        | run_adaptive(seed=seed)
        | run_arrays(n_targets=n_targets, min_time_s=min_time_s / 2, seed=seed)
        | {
            "frames_per_s": float(ours),
            "baseline_frames_per_s": float(base),
            "speedup": float(ours / base),
            "cpu_frames_per_s": float(ours_cpu),
            "frames_per_s_with_spur_map": float(masked),
            "baseline_cpu_frames_per_s": float(base_cpu),
            "load_average_1min": float(os.getloadavg()[0]),
            "cube_shape": [config.n_range, config.n_doppler, config.n_rx],
            "targets_per_frame": n_targets,
            "detections_per_frame": float(n_ours),
            "baseline_detections_per_frame": float(n_base),
        }
    )
