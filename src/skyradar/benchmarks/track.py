"""Benchmark: range-Doppler tracker frames per second with about 200 detections per frame.

Scene: ``n_targets`` intruders with smoothly varying radial velocity (aliased in the image),
detected with probability 0.9, plus uniform clutter up to ``detections_per_frame`` detections per
frame. Ours: :class:`~skyradar.track.tracker.RangeDopplerTracker` with the radar-aware model
(range-sorted gating, batched Kalman over stacked matrices, Hungarian on the contested pairs).
Baseline, in the same run on the first frames of the same data: the same tracker whose association
scores every track/detection pair in a Python loop (:func:`associate_naive`),
as a straightforward implementation would. ``frames_per_s`` is wall-clock; ``cpu_frames_per_s``
(CPU time of this process) and the load average are reported beside it because the benchmark
machine is often shared. Every frame gives the tracker the own-ship's speed (:data:`OWN_SPEED_MPS`),
as the chain does, so the range-walk initiation (:mod:`skyradar.track.range_walk`) runs in both.
"""

from __future__ import annotations

import os
import time

import numpy as np
from scipy.optimize import linear_sum_assignment

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.track.association import Association
from skyradar.track.simulated_detections import synthetic_detections
from skyradar.track.track_table import make_model
from skyradar.track.tracker import RangeDopplerTracker

__all__ = ["bench_scene", "run", "associate_naive", "OWN_SPEED_MPS"]

OWN_SPEED_MPS = 50.0  # the prototype's own-ship speed: the fastest a static point's range changes


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
        tracker.step(float(time_s), z, static_speed_mps=OWN_SPEED_MPS)
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
        "own_speed_mps": OWN_SPEED_MPS,
        "target_frames_per_s": 300.0,
        "meets_target": bool(fps >= 300.0),
    }


_NO_PAIR = 1e12  # the cost of a pair outside the gate


def associate_naive(
    z_pred: np.ndarray,
    S: np.ndarray,
    z: np.ndarray,
    gate: float,
    doppler_width_mps: float | None = None,
    range_wrap_m: np.ndarray | None = None,
    metric: str = "mahalanobis",
    pixel_size: tuple[float, float] = (1.0, 1.0),
    max_alias: int = 2,
) -> Association:
    """Same contract as :func:`skyradar.track.association.associate`, scoring every pair in a Python
    loop: the benchmark's baseline and the tests' oracle."""
    n, m = len(z_pred), len(z)
    C = np.full((n, m), _NO_PAIR)
    Y = np.zeros((n, m, 2))
    for i in range(n):
        S_inv = np.linalg.inv(S[i])
        for j in range(m):
            y = z[j] - z_pred[i]
            if doppler_width_mps is not None:
                y[1] = (y[1] + doppler_width_mps / 2) % doppler_width_mps - doppler_width_mps / 2
            if range_wrap_m is not None and np.isfinite(range_wrap_m[i]) and range_wrap_m[i] > 0:
                w = range_wrap_m[i]
                if (
                    abs(y[0])
                    > (np.sqrt(gate * S[i, 0, 0]) if metric != "l2" else gate * pixel_size[0]) + max_alias * w
                ):
                    continue
                y[0] = (y[0] + w / 2) % w - w / 2
            c = (
                float(np.hypot(y[0] / pixel_size[0], y[1] / pixel_size[1]))
                if metric == "l2"
                else float(y @ S_inv @ y)
            )
            if c < gate:
                C[i, j] = c
                Y[i, j] = y
    if n == 0 or m == 0:
        return Association(np.zeros(0, int), np.zeros(0, int), np.zeros((0, 2)), np.zeros(0))
    r, c = linear_sum_assignment(C)
    keep = C[r, c] < _NO_PAIR
    r, c = r[keep], c[keep]
    return Association(r, c, Y[r, c], C[r, c])
