"""Whole-flight simulation throughput on Dask, 1 versus 2 workers, and memory over a long flight.

The flight circles (radius 20 km, 50 m/s, 1000 m above the terrain) over the synthetic 1201 x
1201 SRTM-3-format tile of :mod:`skyradar.benchmarks.sim`, at the prototype's 9.4 frames/s, with
DEM-spacing facets. Each chunk of frames is simulated on a worker and reduced there to a per-frame summary
(total received power, strongest pixel), so a 20000-frame flight is measured without writing
53 GB of frames; ``store=True`` writes the frames to Zarr instead (bounded by disk, not memory).
Peak resident memory is read from every process (client and workers) after each chunk, so
constant memory shows as a flat curve.
"""

from __future__ import annotations

import resource
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from skyradar.benchmarks.sim import benchmark_tile

__all__ = ["flight_scenario", "run_flight", "run"]


def flight_scenario(n_frames: int, directory: Path):
    """BuiltScenario of the benchmark flight over the benchmark tile (written to ``directory``)."""
    from skyradar.scene.scenario import Scenario

    terrain = benchmark_tile(directory)
    lat, lon = terrain.center_latlon
    ground = float(terrain.height_at(lat, lon))
    data = {
        "name": f"whole flight, {n_frames} frames",
        "origin": {"lat_deg": lat, "lon_deg": lon, "alt_m": ground},
        "mount": "forward",
        "terrain": {"type": "file", "path": str(directory / "N45E006.hgt")},
        "ownship": {
            "type": "circle",
            "center_ned_m": [0, 0, -1400],
            "radius_m": 20000,
            "speed_mps": 50,
            "duration_s": n_frames / 9.4 + 1.0,
        },
        "intruders": [{"name": "A", "type": "encounter", "kind": "head-on", "t_cpa_s": 60.0, "rcs_m2": 1.0}],
        "frame_rate_hz": 9.4,
        "duration_s": n_frames / 9.4,
        "simulation": {"facet_size_m": 1.0e9, "seed": 1},
    }
    return Scenario.from_dict(data, source=directory / "flight.yaml").build()


_SIMULATORS: dict[int, Any] = {}


def _summary_job(built, chunk_frames: int, index: int) -> dict[str, Any]:
    import numba

    from skyradar.sim.scenario_frames import make_simulator, simulate_frames

    numba.set_num_threads(1)
    key = id(built)
    if key not in _SIMULATORS:
        _SIMULATORS.clear()
        _SIMULATORS[key] = make_simulator(built)
    start = index * chunk_frames
    idx = np.arange(start, min(start + chunk_frames, built.times_s.size))
    frames = simulate_frames(built, idx, _SIMULATORS[key])
    power = np.abs(frames) ** 2
    return {
        "frames": idx.size,
        "total_power_w": power.sum(axis=(1, 2, 3)).tolist(),
        "peak_pixel_w": power.max(axis=(1, 2, 3)).tolist(),
        "rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
    }


def run_flight(built, workers: int, chunk_frames: int = 64, store: Path | None = None) -> dict[str, Any]:
    """Simulate the whole flight on a local cluster of ``workers``; frames/s and memory per chunk."""
    from skyradar.extras import import_extra
    from skyradar.parallel import close, connect
    from skyradar.sim.simulate_store import simulate_to_zarr

    as_completed = import_extra("distributed", "dask", "skyradar bench flight").as_completed
    n = built.times_s.size
    client = connect(None, workers)
    try:
        client.run(lambda: __import__("skyradar.sim.simulate_store"))  # imports, numba caches before timing
        built_future = client.scatter(built, broadcast=True)
        warm = [client.submit(_summary_job, built_future, 1, i, pure=False) for i in range(workers)]
        client.gather(warm)
        start = time.perf_counter()
        if store is not None:
            close(client, owns_cluster=True)
            client = None
            simulate_to_zarr(built, store, chunk_frames=chunk_frames, workers=workers)
            rss = []
        else:
            futures = [
                client.submit(_summary_job, built_future, chunk_frames, i, pure=False)
                for i in range(-(-n // chunk_frames))
            ]
            rss = [f.result()["rss_mb"] for f in as_completed(futures)]
        seconds = time.perf_counter() - start
    finally:
        if client is not None:
            close(client, owns_cluster=True)
    client_rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    early = rss[: max(1, len(rss) // 10)]
    return {
        "frames": n,
        "workers": workers,
        "seconds": seconds,
        "frames_per_s": n / seconds,
        "worker_peak_rss_mb": max(rss) if rss else float("nan"),
        "worker_rss_first_10pct_mb": max(early) if rss else float("nan"),
        "client_peak_rss_mb": client_rss,
    }


def run(frames: int = 2400, long_frames: int = 0, chunk_frames: int = 64) -> dict[str, Any]:
    """Throughput with 1 and 2 workers on ``frames``; with ``long_frames``, also a whole flight for memory.

    At about 250 frames/s per worker, 2400 frames time ~10 s per run: 600 (the old default) gave
    2.5 s runs whose 1-worker rate swung by 30 % and the speed-up with it (1.4-2.3).
    """
    with tempfile.TemporaryDirectory() as tmp:
        built = flight_scenario(frames, Path(tmp))
        one = run_flight(built, 1, chunk_frames)
        two = run_flight(built, 2, chunk_frames)
        result = {
            "flight_frames": frames,
            "sim_fps_1_worker": one["frames_per_s"],
            "sim_fps_2_workers": two["frames_per_s"],
            "sim_speedup_2_workers": two["frames_per_s"] / one["frames_per_s"],
        }
        if long_frames:
            whole = run_flight(flight_scenario(long_frames, Path(tmp)), 2, chunk_frames)
            result.update(
                {
                    "whole_flight_frames": whole["frames"],
                    "whole_flight_fps": whole["frames_per_s"],
                    "whole_flight_worker_peak_rss_mb": whole["worker_peak_rss_mb"],
                    "whole_flight_worker_rss_first_10pct_mb": whole["worker_rss_first_10pct_mb"],
                    "whole_flight_client_peak_rss_mb": whole["client_peak_rss_mb"],
                }
            )
    return result
