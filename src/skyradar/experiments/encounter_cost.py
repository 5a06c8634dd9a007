"""What one encounter costs end to end, per terrain and per stage (`skyradar bench encounter`).

A DAA study lives on how many encounters it can fly. This runs the first encounter of the
synthetic set (:func:`skyradar.experiments.encounter_set.make_encounters`, seed 0: head-on) through
the whole chain of the encounter experiment
(:func:`skyradar.experiments.encounter_chain.run_encounter`: simulate with the point-spread and
speckle, process with clutter suppression, track, alert; single head) once over each terrain, in
this process, and reports the process CPU seconds it took (every thread of the simulator's kernels
counted) and each stage's share of them. The baseline is the cost a 200-encounter set can
afford: ``encounter_target_cpu_s`` (9 CPU-s per encounter runs a 200-encounter set in 15 minutes
on 2 cores).

The first encounter of a process also loads the compiled kernels (numba's on-disk cache); a
clear-sky encounter and a few frames over flat ground (the terrain simulator and the clutter
suppression's kernels) are run first to take that cost out of the timed encounters.
"""

from __future__ import annotations

import time

from skyradar.experiments.encounter_chain import run_encounter
from skyradar.experiments.encounter_set import make_encounters

__all__ = ["run_encounter_bench", "BENCH_TERRAINS", "TARGET_CPU_S"]

BENCH_TERRAINS = ("flat-300", "hills", "jacksboro")
TARGET_CPU_S = 9.0
_STAGES = ("simulate", "process", "track", "alert")


def run_encounter_bench(terrains: tuple[str, ...] = BENCH_TERRAINS, seed: int = 0) -> dict:
    """CPU seconds of one encounter over each terrain, and each stage's CPU seconds.

    Keys per terrain ``T``: ``encounter_T_cpu_s``, ``encounter_T_wall_s``, ``encounter_T_frames``,
    ``encounter_T_<stage>_s`` (the stage's CPU time, s, :func:`skyradar.chain.run_chain`'s
    ``timings_s``); then the largest CPU cost over the terrains and
    whether it meets :data:`TARGET_CPU_S`.
    """
    params = make_encounters(1, seed).iloc[0]
    run_encounter(params, seed, terrain="none")  # compiled kernels loaded; not timed
    run_encounter(params, seed, terrain="flat-300", lookback_s=2.0)  # and the terrain ones
    out: dict = {"encounter_kind": str(params["kind"]), "encounter_seed": seed}
    costs = []
    for terrain in terrains:
        cpu0, wall0 = time.process_time(), time.perf_counter()
        row = run_encounter(params, seed, terrain=terrain)[0]
        cpu, wall = time.process_time() - cpu0, time.perf_counter() - wall0
        costs.append(cpu)
        out[f"encounter_{terrain}_cpu_s"] = round(cpu, 2)
        out[f"encounter_{terrain}_wall_s"] = round(wall, 2)
        out[f"encounter_{terrain}_frames"] = int(row["frames"])
        for stage in _STAGES:
            out[f"encounter_{terrain}_{stage}_s"] = round(float(row[f"{stage}_s"]), 2)
    out["encounter_max_cpu_s"] = round(max(costs), 2)
    out["encounter_target_cpu_s"] = TARGET_CPU_S
    out["encounter_meets_target"] = bool(max(costs) <= TARGET_CPU_S)
    return out
