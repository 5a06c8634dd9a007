"""Encounter set: does the DAA chain warn in time for conflicts, and stay quiet for near misses?

Every encounter of :func:`skyradar.experiments.encounter_set.make_encounters` runs through the full
chain (:func:`skyradar.experiments.encounter_chain.run_encounter`): the image simulator at the
prototype's 9.4 Hz, every radar head of the layout, own-ship navigation with the errors of typical
GA avionics (``ga-typical``; scoring alone uses the truth), processing with clutter suppression and
ground flags, the world-frame tracker and the alerting stage (DO-365 non-cooperative volume,
DAIDALUS alerting times, M-of-N persistence, volumes widened by the track covariance). Each
terrain (:mod:`skyradar.experiments.encounter_terrain`) flies the same encounter set; each layout
(``single``: the forward +-35 deg head; ``three-head``: nose and both wingtips, +-110 deg) is
scored on the same simulated frames. Results: one row per terrain and layout
(:func:`~skyradar.experiments.encounter_score.summarise_layout`).

The encounters are independent, so they run in ``workers`` processes (one numba thread each).
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import pandas as pd

from skyradar.code_version import code_version, provenance
from skyradar.daa.alert_config import alert_config, config_digest
from skyradar.errors import InputError
from skyradar.experiments.encounter_chain import FRAME_RATE_HZ, LAYOUTS, SUPPRESSION, run_encounter
from skyradar.experiments.encounter_report import write_report
from skyradar.experiments.encounter_set import make_encounters, make_fast_closures
from skyradar.experiments.encounter_terrain import TERRAINS
from skyradar.io.json_results import write_json_atomic
from skyradar.io.tables import write_table
from skyradar.parallel import check_workers, close, connect
from skyradar.rx_layouts import check_rx_layout

__all__ = [
    "run_encounter",
    "run_encounters",
    "run",
    "MAX_ENCOUNTERS",
    "DEFAULT_ENCOUNTERS",
    "DEFAULT_TERRAIN_ENCOUNTERS",
    "FAMILIES",
    "EVALUATION_SEEDS_FROM",
    "partial_store",
    "check_encounter_set",
    "select_encounters",
    "check_only",
]

MAX_ENCOUNTERS = 100_000  # 200 times the thesis-sized set; more is a typo, not a plan
DEFAULT_ENCOUNTERS = 20  # clear sky, both layouts (23 CPU-s each), 2 workers: within 5 minutes on 2 cores
# Over terrain one single-head encounter (395 frames, psf + speckle, suppression on) cost about 160 CPU-s
# (flat-1000, measured 04:50 UTC at load 3.6 on 56 frames and scaled): 3 per terrain fit 5 minutes on 2 cores.
DEFAULT_TERRAIN_ENCOUNTERS = 3
FAMILIES = ("synthetic", "real-flights", "fast-closures")
EVALUATION_SEEDS_FROM = 7000  # seeds from here on are held out: report on them, never tune on them
_PARTIAL = "encounters.partial.parquet"


def _run_rows(tasks: list[tuple[str, int, dict]], kw: dict) -> list[tuple[str, int, list[dict]]]:
    one: Callable[..., list[dict[str, Any]]]  # run_encounter or run_real_encounter: their options differ
    if kw.get("loop") == "closed":
        from skyradar.experiments.closed_loop import run_closed_loop_encounter as one
    elif kw["family"] == "real-flights":
        from skyradar.experiments.encounter_real import run_real_encounter as one
    else:
        one = run_encounter
    return [
        (terrain, i, one(pd.Series(p), seed=kw["seed"] + i, terrain=terrain, **kw["options"]))
        for terrain, i, p in tasks
    ]


def _dask_rows(tasks: list[tuple[str, int, dict]], kw: dict) -> list[tuple[str, int, list[dict]]]:
    """:func:`_run_rows` in a Dask worker: one numba thread (the workers already fill the cores)."""
    import numba

    numba.set_num_threads(1)
    return _run_rows(tasks, kw)


def run_encounters(
    params: pd.DataFrame,
    seed: int = 0,
    workers: int | None = None,
    progress: Callable[[int], None] | None = None,
    done: dict[tuple[str, int], list[dict]] | None = None,
    on_chunk: Callable[[dict], None] | None = None,
    terrains: tuple[str, ...] = ("none",),
    family: str = "synthetic",
    scheduler: str | None = None,
    loop: str = "open",
    **options: Any,
) -> pd.DataFrame:
    """All encounters (rows of ``params``) over every terrain: here, or one Dask task per encounter.

    With ``scheduler`` (a Dask scheduler's address) the encounters run on that cluster; else with
    ``workers`` > 1 (default: up to 2, one per core) on a local Dask cluster of that many worker
    processes; with ``workers=1`` in this process. The rows do not depend on where they ran (each
    encounter's seed is ``seed`` plus its index, the row's label in ``params``: a selection of a
    set's rows runs each as the whole set runs it).

    Returns one row per terrain, encounter and layout (columns ``terrain``, ``encounter``,
    ``layout``, the encounter's parameters and its result). ``progress`` is called with the number
    of encounters finished; ``done`` holds result rows already computed ({(terrain, i): rows},
    skipped here) and ``on_chunk`` receives all rows so far after each encounter. Interrupted
    (Ctrl-C, SIGTERM), the encounters in flight are cancelled and a local cluster is shut down; what
    finished has reached ``on_chunk``. Options go to
    :func:`~skyradar.experiments.encounter_chain.run_encounter` (``family="real-flights"``:
    :func:`~skyradar.experiments.encounter_real.run_real_encounter`; ``loop="closed"``:
    :func:`~skyradar.experiments.closed_loop.run_closed_loop_encounter`).
    """
    workers = check_workers(workers) or min(2, os.cpu_count() or 1)  # 10**20 spawned until memory ran out
    results: dict[tuple[str, int], list[dict]] = dict(done or {})
    records = list(zip(params.index.tolist(), params.to_dict("records"), strict=True))
    todo = [(tr, int(i), p) for tr in terrains for i, p in records if (tr, i) not in results]
    kw = {"seed": seed, "options": options, "family": family, "loop": loop}

    def finished(rows: list[tuple[str, int, list[dict]]]) -> None:
        results.update({(tr, i): r for tr, i, r in rows})
        if on_chunk:
            on_chunk(results)
        if progress:
            progress(len(results))

    if scheduler is None and workers <= 1:
        for task in todo:
            finished(_run_rows([task], kw))
    elif todo:
        from distributed import as_completed

        client = connect(scheduler, workers)  # an interrupt while it starts: it is closed, then raised
        futures = []
        try:
            futures = [client.submit(_dask_rows, [task], kw, pure=False) for task in todo]
            for future in as_completed(futures):
                finished(future.result())
        except BaseException:  # Ctrl-C or SIGTERM: stop now; what finished is saved by on_chunk
            client.cancel(futures)
            raise
        finally:
            close(client, owns_cluster=scheduler is None)
    return _long_table(params, results, terrains)


def _long_table(params: pd.DataFrame, results: dict, terrains) -> pd.DataFrame:
    rows = []
    for tr in terrains:
        for i, p in zip(params.index.tolist(), params.to_dict("records"), strict=True):
            rows += [{"terrain": tr, "encounter": int(i), **p, **r} for r in results[(tr, i)]]
    return pd.DataFrame(rows)


def partial_store(out_dir: Path, key: dict, name: str = _PARTIAL) -> tuple[dict, Callable[[dict], None]]:
    """Rows of an interrupted run with the same settings ``key`` (``{(terrain, encounter): rows}``,
    from ``out_dir / name``), and a writer that keeps that file up to date with the rows so far."""
    path, key_path = out_dir / name, out_dir / (name + ".json")
    done: dict[tuple[str, int], list[dict]] = {}
    if path.exists() and key_path.exists() and json.loads(key_path.read_text()) == key:
        table = pd.read_parquet(path)
        for (tr, i), g in table.groupby(["terrain", "encounter"], sort=False):
            done[(str(tr), int(i))] = g.drop(columns=["terrain", "encounter"]).to_dict("records")
    write_json_atomic(key_path, key)

    def save(results: dict) -> None:
        rows = [{"terrain": tr, "encounter": i, **r} for (tr, i), rs in results.items() for r in rs]
        write_table(pd.DataFrame(rows), path)

    return done, save


def check_only(only: tuple[int, ...], n_encounters: int) -> list[int]:
    """The encounter numbers ``only`` of a set of ``n_encounters``, sorted, each once; InputError
    naming ``--only`` for a number outside the set (or none at all).

    Examples
    --------
    >>> check_only((4, 1, 4), 5)
    [1, 4]
    """
    picked = sorted({int(i) for i in only})
    outside = [i for i in picked if not 0 <= i < n_encounters]
    if outside or not picked:
        got = outside[0] if outside else "nothing"
        raise InputError(
            f"--only: encounters are numbered 0 to {n_encounters - 1} (--n {n_encounters}), got {got}"
        )
    return picked


def select_encounters(params: pd.DataFrame, only: tuple[int, ...] | None) -> pd.DataFrame:
    """The rows of an encounter set whose index is in ``only`` (None: all), labels kept, in order.

    An encounter's parameters and seed follow from the set's size and seed and its index, so a
    selection reruns exactly those encounters of the whole set (``--only``); :func:`check_only`
    refuses a number outside the set.

    Examples
    --------
    >>> enc = make_fast_closures(5, seed=3)
    >>> picked = select_encounters(enc, (4, 1))
    >>> picked.index.tolist(), bool(picked.loc[4].equals(enc.loc[4]))
    ([1, 4], True)
    """
    return params if only is None else params.loc[check_only(only, len(params))]


def check_encounter_set(n_encounters: int, terrains: tuple[str, ...], layouts: tuple[str, ...]) -> None:
    """InputError naming the option unless the set's size, terrains and layouts are ones it can fly."""
    if not 1 <= n_encounters <= MAX_ENCOUNTERS:  # 10**20 was a numpy "Maximum allowed size" traceback
        raise InputError(f"--n: must be an integer >= 1 and <= {MAX_ENCOUNTERS}, got {n_encounters!r}")
    if not terrains or any(t not in TERRAINS for t in terrains):
        raise InputError(f"--terrain: must be among {', '.join(TERRAINS)}, got {','.join(terrains)!r}")
    if not layouts or any(x not in LAYOUTS for x in layouts):
        raise InputError(f"--layout: must be among {', '.join(LAYOUTS)}, got {','.join(layouts)!r}")


def run(
    out_dir: Path,
    n_encounters: int = DEFAULT_ENCOUNTERS,
    seed: int = 0,
    frame_rate_hz: float = FRAME_RATE_HZ,
    late_lead_s: float = 12.5,
    buffer: float = 1.5,
    workers: int | None = None,
    uncertainty: bool = True,
    progress: Callable[[int], None] | None = None,
    terrains: tuple[str, ...] = ("none",),
    layouts: tuple[str, ...] = LAYOUTS,
    navigation: str = "ga-typical",
    simulation: dict[str, Any] | None = None,
    rx_layout: str = "square",
    family: str = "synthetic",
    command: str | None = None,
    scheduler: str | None = None,
    alert_settings: str = "radar",
    only: tuple[int, ...] | None = None,
) -> dict:
    """Run the encounter set; write ``encounters.parquet``/``.csv`` (one row per terrain, encounter
    and layout), ``summary.json``, ``summary_rows.csv`` and the figures into ``out_dir``; return the
    summary.

    The summary's top-level keys are those of the first terrain and last layout (three-head when it
    runs); ``rows`` holds every terrain and layout. ``uncertainty=False`` turns off the widening of
    the volumes by the track covariance. A warning with less lead than ``late_lead_s`` (default half
    the 25 s warning alerting time) is late. ``navigation`` is the scenarios' ``navigation:`` model;
    ``simulation`` overrides their simulator options (default: PSF, speckle, Swerling 1) and
    ``rx_layout`` names the receive array (:mod:`skyradar.rx_layouts`; default the prototype's square).
    ``family`` is ``synthetic`` (:func:`~skyradar.experiments.encounter_set.make_encounters`) or
    ``real-flights`` (:func:`~skyradar.experiments.encounter_real.make_real_encounters`: recorded
    flights, the ``flights`` extra) or ``fast-closures``
    (:func:`~skyradar.experiments.encounter_set.make_fast_closures`: closing speeds that alias into
    the ground's Doppler band, own-ship 300-700 m above the ground). The summary records its
    provenance (:func:`skyradar.code_version.provenance`): ``command`` (as the caller ran it, by
    default this process' command line), the version with a digest of the source, the UTC date and
    the load average, and its ``split``: seeds from :data:`EVALUATION_SEEDS_FROM` are
    the evaluation split, never looked at while tuning; smaller ones are for development.
    Finished encounters are kept in ``encounters.partial.parquet`` while the run goes on; a run that
    was interrupted resumes from them when started again with the same settings. ``scheduler`` and
    ``workers``: where the encounters run (:func:`run_encounters`). ``alert_settings`` names the
    alerting settings (:func:`skyradar.daa.alert_config.alert_config`: ``radar``, ``do365b``,
    ``default`` or a YAML file of fields); the summary records the name and a digest of every field
    (:func:`~skyradar.daa.alert_config.config_digest`), and a run resumes only with the same settings.
    ``only`` runs those encounters of the set alone (:func:`select_encounters`: each as the whole
    set runs it); the summary counts them alone and records the selection.
    """
    terrains, layouts = tuple(terrains), tuple(x for x in LAYOUTS if x in layouts)
    check_encounter_set(n_encounters, terrains, tuple(layouts) or ("",))
    check_rx_layout(rx_layout, "--rx-layout:", mimo=True)
    t0 = time.perf_counter()
    cfg = alert_config(alert_settings, option="--alert-config")
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    if not uncertainty:
        cfg = replace(cfg, z_h_pos=0.0, z_h_vel=0.0, z_v_pos=0.0, z_v_vel=0.0)
    if family not in FAMILIES:
        raise InputError(f"--family: must be one of {', '.join(FAMILIES)}, got {family!r}")
    if family == "real-flights":
        from skyradar.experiments.encounter_real import make_real_encounters

        enc = make_real_encounters(n_encounters, seed)
    elif family == "fast-closures":
        enc = make_fast_closures(n_encounters, seed)
    else:
        enc = make_encounters(n_encounters, seed)
    enc = select_encounters(enc, only)
    settings = {
        "n": n_encounters,
        "only": None if only is None else enc.index.tolist(),
        "seed": seed,
        "frame_rate_hz": frame_rate_hz,
        "buffer": buffer,
        "uncertainty": uncertainty,
        "terrains": list(terrains),
        "layouts": list(layouts),
        "navigation": navigation,
        "suppression": SUPPRESSION,
        "late_lead_s": late_lead_s,
        "alert_config": str(alert_settings),
        "alert_config_digest": config_digest(cfg),
        "simulation": simulation or {},
        "rx_layout": rx_layout,
        "family": family,
        "split": "evaluation" if seed >= EVALUATION_SEEDS_FROM else "development",
    }
    version = code_version()
    done, save = partial_store(out_dir, {**settings, "version": version})
    res = run_encounters(
        enc,
        seed,
        workers,
        progress,
        done,
        save,
        terrains=terrains,
        family=family,
        scheduler=scheduler,
        layouts=layouts,
        frame_rate_hz=frame_rate_hz,
        buffer=buffer,
        alert_config=cfg,
        navigation=navigation,
        simulation=simulation,
        rx_layout=rx_layout,
    )
    summary = write_report(res, out_dir, settings, late_lead_s, cfg.levels[-1].alerting_time_s)
    workers = check_workers(workers) or min(2, os.cpu_count() or 1)
    summary.update(
        resumed_encounters=len(done),
        workers=workers if scheduler is None else None,
        scheduler=scheduler,
        runtime_s=round(time.perf_counter() - t0, 1),
        **provenance(command, version),
    )
    write_json_atomic(out_dir / "summary.json", summary)
    for name in (_PARTIAL, _PARTIAL + ".json"):
        (out_dir / name).unlink(missing_ok=True)
    return summary
