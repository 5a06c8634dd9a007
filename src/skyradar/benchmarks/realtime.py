"""Benchmark: three radar heads over hills processed in real time on one core.

A DAA radar processor flies on a small computer: the shipped three-head layout
(:data:`skyradar.scene.examples.THREE_HEAD_RADARS`: nose and both wingtips) at 9.4 frames/s
each, 28.2 frames/s in all. This benchmark feeds frames to the suppressed detection chain
(:func:`skyradar.process.pipeline.process_cube` with the head's knowledge-aided clutter
prediction and the adaptive nulls) at that rate, in wall-clock time, with the whole process
pinned to one CPU core and numba and BLAS limited to one thread, and measures each frame's
latency: from its arrival to the end of its processing. The heads' frames are interleaved
(head ``h`` arrives a third of a frame period after head ``h - 1``) and processed in arrival
order; a frame that arrives while another is processed waits.

A frame **misses its deadline** when it is not done before the same head's next frame arrives
(one frame period, 106 ms at 9.4 Hz): the processor has fallen a whole frame behind that head.
``load`` is the mean processing time per frame over the mean time between frames (all heads): the
share of the core the radar asks for; ``margin`` is its complement and ``speedup_needed`` the factor
by which processing must get faster to keep up at all. The comparison baseline is the frame period
itself (a processor that just keeps up has load 1); above it the queue, and every latency, grows
with the length of the run.

Frames: the image simulator over fractal hills (60 m local height SD, the encounters' ``hills``)
with the windows' point-spread and speckle, the own-ship level at 550 m above the ground and
50 m/s, a head-on intruder and one crossing from each side; a set of distinct frames per head
(speckle and the intruders change between them) is simulated before the run and cycled through
it. The clutter prediction of each head is computed before the run, as a processor computes it
for the flight state it holds (level flight: one prediction per head).
"""

from __future__ import annotations

import os
import time
from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np

from skyradar.config import Mount, RadarConfig
from skyradar.process.clutter import clutter_subspace
from skyradar.process.pipeline import process_cube
from skyradar.scene.examples import THREE_HEAD_RADARS
from skyradar.scene.synthetic_terrain import fractal_terrain
from skyradar.sim.image import ImageSimulator, PlatformState, PointTarget

__all__ = ["head_frames", "one_core", "run_realtime"]

HILLS_SD_M, AGL_M, SPEED_MPS = 60.0, 550.0, 50.0
_MOUNTS = {"nose": "nose", "left": "left-wingtip", "right": "right-wingtip"}


def head_frames(mount: str, n_frames: int, seed: int = 0) -> tuple[RadarConfig, list[np.ndarray], object]:
    """A head's RadarConfig, ``n_frames`` simulated frames over hills and its clutter prediction.

    Parameters
    ----------
    mount : str
        A :meth:`skyradar.config.Mount.preset` name (``nose``, ``left-wingtip``, ``right-wingtip``).
    n_frames : int
        Distinct frames, one frame period (1 / 9.4 s) apart: intruders move, speckle changes.
    """
    config = RadarConfig.prototype_2022(mount=Mount.preset(mount))
    terrain = fractal_terrain(52.0, 5.0, HILLS_SD_M, 12_000.0, 30.0, seed=seed)
    ground = float(terrain.height_at(52.0, 5.0))
    sim = ImageSimulator(config, terrain, origin=(52.0, 5.0, 0.0), seed=seed, psf=True, speckle=True)
    alt = ground + AGL_M
    dt = 1.0 / 9.4
    frames = []
    for i in range(n_frames):
        t = i * dt
        own = PlatformState(
            np.array([SPEED_MPS * t, 0.0, -alt]), np.array([SPEED_MPS, 0.0, 0.0]), np.zeros(3)
        )
        intruders = [
            PointTarget(np.array([3000.0 - 50.0 * t, 0.0, -alt]), np.array([-50.0, 0.0, 0.0]), rcs_m2=2.0),
            PointTarget(np.array([1500.0, -2000.0 + 60.0 * t, -alt + 50.0]), np.array([0.0, 60.0, 0.0]), 2.0),
            PointTarget(np.array([1200.0, 1800.0 - 55.0 * t, -alt - 40.0]), np.array([0.0, -55.0, 0.0]), 2.0),
        ]
        frames.append(sim.frame(own, intruders, i))
    velocity = np.array([SPEED_MPS, 0.0, 0.0])
    prediction = clutter_subspace(config, velocity, config.mount.rotation, AGL_M, n_azimuth=720)
    return config, frames, prediction


@contextmanager
def one_core() -> Iterator[int]:
    """Pin this process to one CPU core with one numba and one BLAS thread; restore on exit.

    Yields the core's number. Where the operating system has no CPU affinity the threads are still
    limited to one.
    """
    import numba
    from threadpoolctl import threadpool_limits

    can_pin = hasattr(os, "sched_getaffinity")
    cores = os.sched_getaffinity(0) if can_pin else set()
    core = min(cores) if cores else -1
    threads = numba.get_num_threads()
    try:
        if can_pin:
            os.sched_setaffinity(0, {core})
        numba.set_num_threads(1)
        with threadpool_limits(1):
            yield core
    finally:
        numba.set_num_threads(threads)
        if can_pin:
            os.sched_setaffinity(0, cores)


def run_realtime(
    seconds: float = 60.0, frame_rate_hz: float = 9.4, distinct_frames: int = 16, seed: int = 0
) -> dict:
    """Process three heads' frames at ``frame_rate_hz`` each for ``seconds`` of wall time on one core.

    Returns deadline misses, latency and processing-time percentiles (ms), the load on the core and
    the margin.
    """
    heads = []
    for head in THREE_HEAD_RADARS:
        heads.append(head_frames(_MOUNTS[head["name"]], distinct_frames, seed))
    period = 1.0 / frame_rate_hz
    n_per_head = int(np.floor(seconds * frame_rate_hz))
    order = [(k, h) for k in range(n_per_head) for h in range(len(heads))]
    arrival = np.array([k * period + h * period / len(heads) for k, h in order])
    latency, processing, detections = np.empty(len(order)), np.empty(len(order)), np.empty(len(order))
    with one_core() as core:
        for config, frames, prediction in heads:  # compile and warm the caches first
            for cube in frames[:2]:
                process_cube(cube, config, clutter=prediction)
        cpu0 = time.process_time()
        start = time.perf_counter() + 0.2
        for n, (k, h) in enumerate(order):
            config, frames, prediction = heads[h]
            wait = start + arrival[n] - time.perf_counter()
            if wait > 0:
                time.sleep(wait)
            c0 = time.process_time()
            out = process_cube(frames[k % len(frames)], config, clutter=prediction)
            processing[n] = time.process_time() - c0
            latency[n] = time.perf_counter() - (start + arrival[n])
            detections[n] = len(out["range_m"])
        wall = time.perf_counter() - start
        cpu = time.process_time() - cpu0
    misses = int(np.sum(latency > period))
    # The share of the core the frames ask for: mean processing time over the mean time between
    # frames (all heads). Above 1 the queue only grows, whatever the run's length.
    load = float(processing.mean() * len(heads) * frame_rate_hz)
    return {
        "realtime_heads": len(heads),
        "realtime_frame_rate_hz_per_head": frame_rate_hz,
        "realtime_frames": len(order),
        "realtime_seconds": float(wall),
        "realtime_core": core,
        "realtime_threads": 1,
        "realtime_deadline_s": period,
        "realtime_deadline_misses": misses,
        "realtime_latency_median_ms": 1e3 * float(np.median(latency)),
        "realtime_latency_p99_ms": 1e3 * float(np.quantile(latency, 0.99)),
        "realtime_latency_max_ms": 1e3 * float(latency.max()),
        "realtime_processing_median_ms": 1e3 * float(np.median(processing)),
        "realtime_processing_p99_ms": 1e3 * float(np.quantile(processing, 0.99)),
        "realtime_load": load,
        "realtime_margin": 1.0 - load,
        "realtime_speedup_needed": max(load, 1.0),
        "realtime_process_cpu_s": float(cpu),
        "realtime_detections_per_frame": float(detections.mean()),
    }
