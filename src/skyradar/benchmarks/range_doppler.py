"""Benchmark of the raw chain: ADC cube to range-Doppler cube for the thesis prototype.

One frame is 4 rx x 250 chirps x 2032 complex samples. Ours is
:class:`skyradar.process.rangedoppler.RangeDopplerProcessor` (Hann windows, split range DFT that
computes only the 333 kept bins, complex64 end to end). The baseline, measured in the same run on
the same frames, is the obvious implementation: a per-channel loop of unwindowed ``numpy.fft``
(full range FFT, crop, Doppler FFT, shift). The plain scipy.fft path (``method='fft'``) is timed
as well.

``raw_to_rd_fps`` is the sustained throughput over the batch of frames, processed the way
recordings and flights are (:meth:`RangeDopplerProcessor.many`: ``workers`` frames in flight, one
thread each), as total frames over total wall time of the batch (median of three passes);
``realtime_factor`` is that over the prototype's 9.4 frames/s field rate. ``single_frame_ms`` is
the latency of one frame on its own with ``workers`` threads inside the frame (median over the
frames), the figure a live radar loop that cannot queue frames would see.

The machine may be shared: the load average at the start is reported with the timings, each
timing is the median over the frames, and the CPU time per frame (all threads of the process) is
reported beside the wall-clock time, since it is what other processes cannot inflate.
"""

from __future__ import annotations

import os
import time
from typing import Any

import numpy as np

from skyradar.config import RadarConfig
from skyradar.process.rangedoppler import RangeDopplerProcessor, range_doppler
from skyradar.sim.raw import adc_noise, simulate_adc

__all__ = ["FIELD_FRAME_RATE_HZ", "baseline_range_doppler", "run"]

FIELD_FRAME_RATE_HZ = 9.4  # prototype in the field: 300 frames in 32 s


def baseline_range_doppler(adc: np.ndarray, config: RadarConfig) -> np.ndarray:
    """Per-channel numpy.fft loop without windows; same axes and normalisation as ours."""
    out = np.empty((config.n_range, config.n_doppler, config.n_rx), np.complex64)
    scale = 1.0 / (adc.shape[2] * config.n_doppler)
    for k in range(config.n_rx):
        rng = np.fft.fft(adc[k], axis=1)[:, : config.n_range]
        out[..., k] = (np.fft.fftshift(np.fft.fft(rng, axis=0), axes=0) * scale).T
    return out


def _median_seconds(fn, frames: list[np.ndarray]) -> tuple[float, float]:
    """Median wall-clock and process-CPU seconds (all threads) per frame."""
    fn(frames[0])  # warm-up: plans, caches, page faults
    wall, cpu = [], []
    for frame in frames:
        c0, t0 = time.process_time(), time.perf_counter()
        fn(frame)
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return float(np.median(wall)), float(np.median(cpu))


def _batch_seconds(proc: RangeDopplerProcessor, frames: list[np.ndarray]) -> tuple[float, float]:
    """Wall-clock and process-CPU seconds per frame of the whole batch, median of three passes."""
    for _ in proc.many(frames[: proc.workers]):  # warm-up: compile cache, plans, scratch
        pass
    passes = []
    for _ in range(3):
        c0, t0 = time.process_time(), time.perf_counter()
        for _ in proc.many(frames):
            pass
        passes.append(((time.perf_counter() - t0) / len(frames), (time.process_time() - c0) / len(frames)))
    return sorted(passes)[1]


def _frames(config: RadarConfig, n_frames: int) -> list[np.ndarray]:
    # Noise plus a few targets from the chirp-level simulator, so the data are realistic.
    targets = simulate_adc(
        config,
        np.array([[800.0, 30.0, -20.0], [2100.0, -150.0, 40.0], [3900.0, 5.0, 5.0]]),
        np.array([[-25.0, 0.0, 0.0], [55.0, 3.0, 0.0], [-3.0, 0.0, 1.0]]),
        noise=False,
    )
    return [targets + adc_noise(config, seed=i) for i in range(n_frames)]


def run(n_frames: int = 20, workers: int = 2) -> dict[str, Any]:
    """Time ours and the baseline on ``n_frames`` prototype frames; returns the result dict."""
    config = RadarConfig.prototype_2022()
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    frames = _frames(config, max(2, int(n_frames)))
    ours_s, ours_cpu = _batch_seconds(RangeDopplerProcessor(config, workers=workers), frames)
    single_s, single_cpu = _median_seconds(lambda a: range_doppler(a, config, workers=workers), frames)
    full_fft_s, _ = _median_seconds(lambda a: range_doppler(a, config, method="fft", workers=workers), frames)
    base_s, base_cpu = _median_seconds(lambda a: baseline_range_doppler(a, config), frames)
    check = np.abs(
        range_doppler(frames[0], config, "none", "none") - baseline_range_doppler(frames[0], config)
    )
    fps = 1.0 / ours_s
    return {
        "raw_to_rd_fps": fps,
        "realtime_factor": fps / FIELD_FRAME_RATE_HZ,
        "frame_ms": ours_s * 1e3,
        "frame_cpu_ms": ours_cpu * 1e3,
        "throughput_mode": f"batch of {len(frames)} frames, {workers} in flight",
        "single_frame_fps": 1.0 / single_s,
        "single_frame_ms": single_s * 1e3,
        "single_frame_cpu_ms": single_cpu * 1e3,
        "baseline_frame_cpu_ms": base_cpu * 1e3,
        "method": "pruned",
        "full_fft_fps": 1.0 / full_fft_s,
        "baseline_fps": 1.0 / base_s,
        "baseline": "numpy.fft per-channel loop, no windows",
        "speedup_vs_baseline": base_s / ours_s,
        "max_abs_diff_vs_baseline": float(check.max()),
        "workers": int(workers),
        "n_frames": len(frames),
        "frame_shape": [config.n_rx, config.n_doppler, config.samples_per_chirp],
        "cpu_count": os.cpu_count(),
        "load_average_1min": load,
    }
