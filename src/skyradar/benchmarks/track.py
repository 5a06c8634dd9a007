"""Benchmark: range-Doppler tracker frames per second with about 200 detections per frame.

Scene: ``n_targets`` intruders with smoothly varying radial velocity (aliased in the image),
detected with probability 0.9, plus uniform clutter up to ``detections_per_frame`` detections per
frame. Ours: :class:`~skyradar.track.tracker.RangeDopplerTracker` with the radar-aware model
(range-sorted gating, batched Kalman over stacked matrices, Hungarian on the contested pairs).
Baseline, in the same run on the first frames of the same data: the same tracker whose association
scores every track/detection pair in a Python loop (:func:`~skyradar.track.association.associate_naive`),
as a straightforward implementation would. ``frames_per_s`` is wall-clock; ``cpu_frames_per_s``
(CPU time of this process) and the load average are reported beside it because the benchmark
machine is often shared.
"""

from __future__ import annotations

import os
import time

import numpy as np

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.track.association import associate_naive
from skyradar.track.simulated_detections import synthetic_detections
from skyradar.track.track_table import make_model
from skyradar.track.tracker import RangeDopplerTracker

__all__ = ["bench_scene", "run"]


def bench_scene(
    n_frames: int, detections_per_frame: int, n_targets: int, seed: int, config: RadarConfig
) -> tuple[np.ndarray, list[np.ndarray]]:
    """Frame times and per-frame (m, 2) detection arrays of the benchmark scene."""
    rng = np.random.default_rng(seed)
    dt = 0.106
    t = np.arange(n_frames) * dt
    v0 = rng.uniform(-120.0, 60.0, n_targets)
    V = v0 + 8.0 * np.sin(t[:, None] / rng.uniform(2.0, 8.0, n_targets) + rng.uniform(0, 6, n_targets))
    R = rng.uniform(800.0, 4200.0, n_targets) + np.cumsum(V, axis=0) * dt
    vis = (R > 50.0) & (config.range_limit_m > R)
    clutter = max(detections_per_frame - 0.9 * n_targets, 0.0)
    det = synthetic_detections(t, R, V, vis, config, pd_detect=0.9, clutter_per_frame=clutter, seed=seed)
    z = det[["range_m", "radial_velocity_mps"]].to_numpy(float)
    bounds = np.searchsorted(det["frame"].to_numpy(), np.arange(n_frames + 1))
    return t, [z[bounds[k] : bounds[k + 1]] for k in range(n_frames)]


def _time_tracker(
    tracker: RangeDopplerTracker, t: np.ndarray, frames: list[np.ndarray]
) -> tuple[float, float, float]:
    """Wall time, CPU time of this process, and mean live tracks per frame."""
    n_tracks = 0
    start, start_cpu = time.perf_counter(), time.process_time()
    for time_s, z in zip(t, frames, strict=True):
        tracker.step(float(time_s), z)
        n_tracks += tracker.n_tracks
    return time.perf_counter() - start, time.process_time() - start_cpu, n_tracks / max(len(frames), 1)


def run(
    n_frames: int = 600,
    detections_per_frame: int = 200,
    n_targets: int = 20,
    baseline_frames: int = 15,
    seed: int = 0,
) -> dict:
    """Measure ours and the baseline; returns frames/s of both, their ratio and scene sizes.

    Examples
    --------
    >>> r = run(n_frames=20, detections_per_frame=30, n_targets=3, baseline_frames=5)
    >>> sorted(k for k in r if k.endswith("frames_per_s"))
    ['baseline_frames_per_s', 'cpu_frames_per_s', 'frames_per_s', 'target_frames_per_s']
    """
    if n_frames < 1 or detections_per_frame < 0 or n_targets < 1 or baseline_frames < 1:
        raise InputError(
            f"bench track: need n_frames >= 1, detections_per_frame >= 0, n_targets >= 1 and "
            f"baseline_frames >= 1, got {n_frames}, {detections_per_frame}, {n_targets}, {baseline_frames}"
        )
    # Upper bounds: the scene is built in memory up front (10**20 frames was a numpy traceback).
    limits = (("--frames", n_frames, 100_000), ("--detections", detections_per_frame, 10_000))
    for option, value, high in limits:
        if value > high:
            raise InputError(f"bench track: option '{option}' must be at most {high}, got {value}")
    config = RadarConfig.prototype_2022()
    t, frames = bench_scene(n_frames, detections_per_frame, n_targets, seed, config)
    pixel = (config.range_resolution_m, config.doppler_resolution_mps)
    model = make_model("radar", config)
    ours = RangeDopplerTracker(model, pixel_size=pixel)
    elapsed, cpu, mean_tracks = _time_tracker(ours, t, frames)
    nb = min(baseline_frames, n_frames)
    base = RangeDopplerTracker(model, pixel_size=pixel, associator=associate_naive)
    elapsed_b, _, _ = _time_tracker(base, t[:nb], frames[:nb])
    # The same first frames with ours, so the ratio compares like with like (track counts grow
    # over the first frames).
    ours_b = RangeDopplerTracker(model, pixel_size=pixel)
    elapsed_ob, _, _ = _time_tracker(ours_b, t[:nb], frames[:nb])
    fps = n_frames / elapsed
    return {
        "frames_per_s": fps,
        # CPU time of this process: what the tracker costs when the machine is shared.
        "cpu_frames_per_s": n_frames / cpu,
        "load_average_1min": os.getloadavg()[0],
        "baseline_frames_per_s": nb / elapsed_b,
        "speedup_same_frames": elapsed_b / elapsed_ob,
        "frames": n_frames,
        "baseline_frames": nb,
        "detections_per_frame": float(np.mean([len(f) for f in frames])),
        "live_tracks_per_frame": mean_tracks,
        "target_frames_per_s": 300.0,
        "meets_target": bool(fps >= 300.0),
    }
