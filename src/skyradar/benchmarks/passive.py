"""``skyradar bench passive``: passive processing speed (real-time factor) and memory vs recording length.

One thesis-geometry recording of ``2 * seconds`` at 5 MS/s is simulated; its first half and the whole
are processed (a) streamed in 2^20-sample chunks (the shipped way) and (b) as one chunk holding the
whole recording (the baseline: the same algorithms without streaming). Reported per length: wall and
CPU seconds, the real-time factor (recording seconds per wall second) and the tracemalloc peak of a
second, memory-only run. Streaming's peak stays flat when the recording doubles; the baseline's doubles.
"""

from __future__ import annotations

import os
import tempfile
import time
import tracemalloc
from pathlib import Path
from typing import Any

__all__ = ["run"]

SAMPLE_RATE_HZ = 5e6


class _Prefix:
    """The first ``n_samples`` of a recording (same metadata): a shorter recording without a copy."""

    def __init__(self, recording, n_samples: int) -> None:
        self._rec = recording
        self.n_samples = int(min(n_samples, recording.n_samples))

    def __getattr__(self, name: str):
        return getattr(self._rec, name)

    def read(self, start: int, count: int):
        return self._rec.read(start, max(0, min(count, self.n_samples - start)))


def _measure(recording, chunk: int) -> dict[str, float]:
    from skyradar.passive.pipeline import PassiveSettings, process_recording

    settings = PassiveSettings(chunk_samples=chunk)
    wall, cpu = time.perf_counter(), time.process_time()
    result = process_recording(recording, settings)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    tracemalloc.start()
    process_recording(recording, settings)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    seconds = recording.n_samples / recording.sample_rate_hz
    return {
        "recording_s": round(seconds, 2),
        "wall_s": round(wall, 2),
        "cpu_s": round(cpu, 2),
        "real_time_factor": round(seconds / wall, 2),
        "peak_mib": round(peak / 2**20, 1),
        "detections": len(result.detections),
    }


def run(seconds: float = 3.0, workdir: Path | None = None) -> dict[str, Any]:
    """Simulate, then time and measure the processing of ``seconds`` and ``2 * seconds`` of recording."""
    from skyradar.io.sigmf_io import read_iq_recording
    from skyradar.passive.scene import thesis_scene
    from skyradar.passive.simulate import simulate_recording

    with tempfile.TemporaryDirectory(dir=workdir) as tmp:
        scene = thesis_scene(duration_s=2 * seconds, seed=0)
        meta = simulate_recording(scene, Path(tmp) / "bench.sigmf-meta", SAMPLE_RATE_HZ)
        rec = read_iq_recording(meta)
        short = _Prefix(rec, int(seconds * SAMPLE_RATE_HZ))
        out: dict[str, Any] = {"sample_rate_hz": SAMPLE_RATE_HZ, "cores": os.cpu_count()}
        for name, r in (("short", short), ("long", rec)):
            out[f"streamed_{name}"] = _measure(r, 1 << 20)
            out[f"baseline_{name}"] = _measure(r, r.n_samples)
    s_short, s_long = out["streamed_short"], out["streamed_long"]
    b_short, b_long = out["baseline_short"], out["baseline_long"]
    out |= {
        "real_time_factor": s_long["real_time_factor"],
        "speed_ratio_vs_baseline": round(b_long["wall_s"] / s_long["wall_s"], 2),
        "streamed_peak_growth": round(s_long["peak_mib"] / s_short["peak_mib"], 2),
        "baseline_peak_growth": round(b_long["peak_mib"] / b_short["peak_mib"], 2),
        "load_average_1min": round(os.getloadavg()[0], 2),
    }
    return out
