"""Encounter set: does the DAA chain warn in time for conflicts, and stay quiet for near misses?

Every encounter of :func:`skyradar.experiments.encounter_set.make_encounters` runs through the full
chain of :func:`skyradar.experiments.daa_chain.run_chain`: the image simulator (thesis prototype, forward
mount, thermal noise, clear sky), detection and DoA, the radar-aware tracker with 3-D state, and
the alerting stage (DO-365 non-cooperative volume, DAIDALUS alerting times, M-of-N persistence,
volumes widened by the track covariance). Frames cover the last ``lookback_s`` before the loss of
well clear (or the CPA), and start no earlier than the intruder is inside the range limit: 40 s
is the 25 s warning alerting time plus 15 s to confirm a track and let its velocity converge
(on the seed-1 set, 45 s gave the same warnings and 35 s cut the median lead by 2 s).

The encounters are independent, so they run in ``workers`` processes (one numba thread each).
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import replace
from multiprocessing import get_context
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from skyradar.daa.alerting import RADAR_ALERT_CONFIG, AlertConfig
from skyradar.errors import InputError
from skyradar.experiments.daa_chain import label_tracks, run_chain
from skyradar.experiments.encounter_set import (
    encounter_scenario,
    event_times,
    make_encounters,
    plot_encounters,
    relative_truth,
    score_encounter,
    summarise,
)
from skyradar.io.atomic import write_csv_atomic
from skyradar.io.frames_model import frame_times_s
from skyradar.io.tables import write_json_atomic, write_table
from skyradar.parallel import check_workers
from skyradar.scene.scenario import Scenario

__all__ = ["run_encounter", "run_encounters", "run", "MAX_ENCOUNTERS"]

MAX_ENCOUNTERS = 100_000  # 200 times the thesis-sized set; more is a typo, not a plan

_RANGE_MARGIN_M = 300.0
_PARTIAL = "encounters.partial.parquet"


def _window(
    p: pd.Series, frame_rate_hz: float, lookback_s: float, seed: int
) -> tuple[float, float, np.ndarray, np.ndarray]:
    """Frame window (start, duration) in s, ``lookback_s`` before the LoWC or CPA and in range,
    and the dense relative truth (times, NED m) it was chosen on."""
    built = Scenario.from_dict(encounter_scenario(p, 0.0, 1.0, frame_rate_hz, seed, None)).build()
    t, rel = relative_truth(built)
    t_lowc, t_cpa = event_times(t, rel)
    t_event = t_lowc if np.isfinite(t_lowc) else t_cpa
    in_range = np.linalg.norm(rel, axis=1) <= built.radar.range_limit_m + _RANGE_MARGIN_M
    first = float(t[np.argmax(in_range & (t <= t_event))]) if in_range.any() else t_event - lookback_s
    start = max(t_event - lookback_s, first, float(t[0]))
    end = min(t_event + 2.0, float(t[-1]))
    return start, max(end - start, 2.0 / frame_rate_hz), t, rel


def _observable(truth, fov_deg: float, min_snr_db: float) -> pd.DataFrame:
    half = np.radians(fov_deg / 2)
    az = truth["tgt_azimuth_rad"].values[:, 0]
    el = truth["tgt_elevation_rad"].values[:, 0]
    with np.errstate(invalid="ignore"):
        ok = truth["tgt_visible"].values[:, 0] & (np.abs(az) <= half) & (np.abs(el) <= half)
        ok &= truth["tgt_snr_db"].values[:, 0] >= min_snr_db
    return pd.DataFrame({"time_s": frame_times_s(truth), "observable": ok})


def run_encounter(
    p: pd.Series,
    seed: int = 0,
    frame_rate_hz: float = 4.7,
    lookback_s: float = 40.0,
    buffer: float = 1.5,
    fov_deg: float = 70.0,
    min_snr_db: float = 13.0,
    observe_window_s: float = 12.5,
    alert_config: AlertConfig | None = None,
    terrain: str | None = None,
) -> dict[str, Any]:
    """One encounter row through the full chain; its result row (times in s, NaN when none).

    ``t_warning_s`` is the first warning (level 3) of a track that follows the intruder;
    ``t_other_warning_s`` the first warning of any other track (noise).
    """
    # The frame window and terrain do not change the trajectories: one dense truth serves both.
    start, duration, t, rel = _window(p, frame_rate_hz, lookback_s, seed)
    built = Scenario.from_dict(encounter_scenario(p, start, duration, frame_rate_hz, seed, terrain)).build()
    chain = run_chain(built, alert_config or RADAR_ALERT_CONFIG, with_advice=False)
    labels = label_tracks(chain["tracks"], chain["truth"])
    alerts = chain["alerts"]
    warn = alerts[alerts["level"] >= 3] if len(alerts) else alerts
    mine = warn["track_id"].map(lambda i: labels.get(int(i)) == "intruder").to_numpy(bool)
    observed = _observable(chain["truth"], fov_deg, min_snr_db)
    row = score_encounter(t, rel, warn["time_s"].to_numpy(float)[mine], observed, buffer, observe_window_s)
    other = warn["time_s"].to_numpy(float)[~mine]
    row.update(t_other_warning_s=float(other.min()) if other.size else float("nan"),
               frames=int(built.times_s.size), t_start_s=start,
               tracks=int(chain["tracks"]["track_id"].nunique()),
               detections=len(chain["detections"]))  # fmt: skip
    return row


def _init_worker() -> None:
    import numba

    numba.set_num_threads(1)


def _run_rows(rows: list[tuple[int, dict]], kw: dict) -> list[tuple[int, dict]]:
    return [(i, run_encounter(pd.Series(p), seed=kw["seed"] + i, **kw["options"])) for i, p in rows]


def run_encounters(
    params: pd.DataFrame,
    seed: int = 0,
    workers: int | None = None,
    progress: Callable[[int], None] | None = None,
    done: dict[int, dict] | None = None,
    on_chunk: Callable[[dict[int, dict]], None] | None = None,
    **options: Any,
) -> pd.DataFrame:
    """All encounters (rows of ``params``), ``workers`` processes; one result row per encounter.

    ``progress`` is called with the number of encounters finished; ``done`` holds result rows
    already computed (skipped here) and ``on_chunk`` receives all rows so far after each chunk
    of five. Options go to :func:`run_encounter`.
    """
    workers = check_workers(workers) or min(2, os.cpu_count() or 1)  # 10**20 spawned until memory ran out
    results: dict[int, dict] = dict(done or {})
    todo = [(i, p) for i, p in enumerate(params.to_dict("records")) if i not in results]
    chunks = [todo[k : k + 5] for k in range(0, len(todo), 5)]
    kw = {"seed": seed, "options": options}

    def finished(rows: list[tuple[int, dict]]) -> None:
        results.update(dict(rows))
        if on_chunk:
            on_chunk(results)
        if progress:
            progress(len(results))

    if workers <= 1:
        for c in chunks:
            finished(_run_rows(c, kw))
    elif chunks:
        ctx = get_context("spawn")  # numba's thread pools do not survive fork
        with ProcessPoolExecutor(workers, mp_context=ctx, initializer=_init_worker) as pool:
            futures = [pool.submit(_run_rows, c, kw) for c in chunks]
            try:
                for fut in as_completed(futures):
                    finished(fut.result())
            except KeyboardInterrupt:
                for f in futures:
                    f.cancel()
                raise
    return pd.DataFrame([results[i] for i in range(len(params))])


def _partial_store(out_dir: Path, key: dict) -> tuple[dict[int, dict], Callable[[dict[int, dict]], None]]:
    """Rows of an interrupted run with the same settings, and a writer that keeps them up to date."""
    path, key_path = out_dir / _PARTIAL, out_dir / (_PARTIAL + ".json")
    done: dict[int, dict] = {}
    if path.exists() and key_path.exists() and json.loads(key_path.read_text()) == key:
        table = pd.read_parquet(path)
        done = {int(i): row for i, row in zip(table.pop("encounter"), table.to_dict("records"), strict=True)}
    write_json_atomic(key_path, key)

    def save(results: dict[int, dict]) -> None:
        rows = pd.DataFrame(list(results.values()))
        rows.insert(0, "encounter", list(results))
        write_table(rows, path)

    return done, save


def run(
    out_dir: Path,
    n_encounters: int = 500,
    seed: int = 0,
    frame_rate_hz: float = 4.7,
    late_lead_s: float = 12.5,
    buffer: float = 1.5,
    workers: int | None = None,
    uncertainty: bool = True,
    progress: Callable[[int], None] | None = None,
    terrain: str | None = None,
) -> dict:
    """Run the encounter set; write ``encounters.parquet``, ``encounters.csv``, ``summary.json`` and
    ``encounters.png`` into ``out_dir``; return the summary.

    ``uncertainty=False`` turns off the widening of the volumes by the track covariance. A warning
    with less lead than ``late_lead_s`` (default half the 25 s warning alerting time) is late.
    ``terrain="flat"`` flies the set over flat ground (clutter, slower; see
    :func:`~skyradar.experiments.encounter_set.encounter_scenario`). Finished encounters are kept
    in ``encounters.partial.parquet`` while the run goes on; a run that was interrupted resumes
    from them when started again with the same settings.
    """
    if not 1 <= n_encounters <= MAX_ENCOUNTERS:  # 10**20 was a numpy "Maximum allowed size" traceback
        raise InputError(f"--n: must be an integer >= 1 and <= {MAX_ENCOUNTERS}, got {n_encounters!r}")
    t0 = time.perf_counter()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    cfg = RADAR_ALERT_CONFIG
    if not uncertainty:
        cfg = replace(cfg, z_h_pos=0.0, z_h_vel=0.0, z_v_pos=0.0, z_v_vel=0.0)
    enc = make_encounters(n_encounters, seed)
    key = {"n": n_encounters, "seed": seed, "frame_rate_hz": frame_rate_hz, "buffer": buffer,
           "uncertainty": uncertainty, "terrain": terrain, "version": _version()}  # fmt: skip
    done, save = _partial_store(out_dir, key)
    out = run_encounters(enc, seed, workers, progress, done, save, frame_rate_hz=frame_rate_hz, buffer=buffer,
                         alert_config=cfg, terrain=terrain)  # fmt: skip
    res = pd.concat([enc, out], axis=1)
    summary = summarise(res, late_lead_s)
    summary.update(chain="full", frames=int(res["frames"].sum()), frame_rate_hz=frame_rate_hz, buffer=buffer,
                   uncertainty=uncertainty, seed=seed, terrain=terrain or "none",
                   resumed_encounters=len(done),
                   other_track_warnings=int(res["t_other_warning_s"].notna().sum()))  # fmt: skip
    write_table(res, out_dir / "encounters.parquet")
    write_csv_atomic(res, out_dir / "encounters.csv", index=False)
    plot_encounters(res, out_dir / "encounters.png", buffer, cfg.levels[-1].alerting_time_s)
    summary["runtime_s"] = round(time.perf_counter() - t0, 1)
    write_json_atomic(out_dir / "summary.json", summary)
    for name in (_PARTIAL, _PARTIAL + ".json"):
        (out_dir / name).unlink(missing_ok=True)
    return summary


def _version() -> str:
    from importlib.metadata import version

    return version("skyradar")
