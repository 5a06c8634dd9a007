"""``skyradar experiment encounters``: the encounter set through the whole DAA chain."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer

from skyradar.cli.app import (
    NON_NEGATIVE,
    SCHEDULER,
    JsonOption,
    bench_app,
    emit_measurement,
    emit_result,
    experiment_app,
    number_in,
)
from skyradar.cli.choices import EncounterTerrain, Family, Layout, Navigation, RxLayout, Split
from skyradar.io.outputs import OVERWRITE_HELP

__all__ = [
    "experiment_encounters",
    "bench_encounter",
    "EncounterWorkersOption",
    "LAYOUTS_SCORED",
    "EncounterSchedulerOption",
    "SplitOption",
    "check_split",
    "parse_only",
]

# The layouts each --layout scores.
LAYOUTS_SCORED = {
    Layout.both: ("single", "three-head"),
    Layout.single: ("single",),
    Layout.three_head: ("three-head",),
}

_N = Annotated[
    int | None,
    typer.Option(
        "--n",
        callback=number_in(1, 100_000),
        help="Encounters per terrain (at most 100000; default 20 in clear sky, both layouts, 2 workers "
        "in under 5 minutes on 2 cores; 3 when a terrain is asked for, about 160 CPU-s each).",
    ),
]
_FRAME_RATE = Annotated[
    float,
    typer.Option(
        "--frame-rate-hz", callback=number_in(0.5, 100.0), help="Radar frame rate, Hz (the prototype's)."
    ),
]
_BUFFER = Annotated[
    float,
    typer.Option(
        callback=number_in(1.0, 100.0), help="May-alert zone: this many times the well-clear volume."
    ),
]
_TERRAIN = Annotated[
    str,
    typer.Option(
        help="Comma-separated terrains, each a row of the result: none (clear sky), flat-300, flat-1000 "
        "(flat ground that far below; 'flat' = flat-1000), hills (fractal, 60 m local SD), jacksboro "
        "(real DEM); own-ship 400-700 m above hills and jacksboro. 'all' = every one."
    ),
]
_LAYOUT = Annotated[
    Layout,
    typer.Option(
        help="Radar heads scored: single (forward +-35 deg), three-head (nose and wingtips, +-110 deg) "
        "or both (one simulation, tracked and alerted per layout)."
    ),
]
_NAVIGATION = Annotated[
    Navigation,
    typer.Option(
        help="Own-ship navigation errors the chain sees (a scenario's 'navigation:' model; only-X: the "
        "typical errors of X alone); scoring always uses the truth."
    ),
]

_ONLY = Annotated[
    str | None,
    typer.Option(
        "--only",
        help="Comma-separated encounter numbers (0 to --n - 1) to run alone, each exactly as the whole "
        "set of --n encounters runs it (the set's parameters depend on --n and --seed).",
    ),
]


def parse_only(text: str | None) -> tuple[int, ...] | None:
    """``--only``'s encounter numbers (None: every encounter); InputError naming ``--only`` unless
    the text is comma-separated non-negative integers.

    Examples
    --------
    >>> parse_only("7, 3,7"), parse_only(None)
    ((7, 3, 7), None)
    """
    from skyradar.errors import InputError

    if text is None:
        return None
    parts = [part.strip() for part in text.split(",")]
    if not all(part.isdigit() for part in parts):
        raise InputError(f"--only: must be comma-separated encounter numbers (0, 1, ...), got {text!r}")
    return tuple(int(part) for part in parts)


EncounterWorkersOption = Annotated[
    int | None,
    typer.Option(
        min=1,
        help="Worker processes of a local Dask cluster, one encounter per task (default: up to 2, one "
        "per core; 1 runs here, without Dask).",
    ),
]
EncounterSchedulerOption = Annotated[
    str | None,
    typer.Option(
        "--scheduler",
        callback=SCHEDULER,
        help="Address of an existing Dask scheduler (tcp://HOST:PORT) to run the encounters on.",
    ),
]
SplitOption = Annotated[
    Split | None,
    typer.Option(
        "--split",
        help="Which split the seed must belong to: development (seeds below 7000: tune on these) or "
        "evaluation (7000 and up: report on these, never tune). Refused when the seed is in the "
        "other; the summary records the split either way.",
    ),
]


def check_split(seed: int, split: Split | None) -> None:
    """InputError unless ``seed`` belongs to ``split`` (None: either)."""
    from skyradar.errors import InputError
    from skyradar.experiments.encounters import EVALUATION_SEEDS_FROM

    if split is not None and (seed >= EVALUATION_SEEDS_FROM) != (split is Split.evaluation):
        where = (
            f"{EVALUATION_SEEDS_FROM} and up"
            if split is Split.evaluation
            else f"below {EVALUATION_SEEDS_FROM}"
        )
        raise InputError(f"--seed {seed}: not in the {split.value} split (its seeds are {where})")


_RX_LAYOUT = Annotated[
    RxLayout,
    typer.Option(
        "--rx-layout",
        help="Receive array of every head (scenario 'radar.rx_layout:'): square (the prototype's 2x2) "
        "kite (no centre of symmetry: keeps the elevation of targets in flat-ground clutter), or the "
        "uniform rectangular arrays ura-2x3, ura-2x4 and ura-4x2 (rows x columns, half-wavelength "
        "spacing), or mimo-2x4 (2 transmitters x 4 receivers taking turns: a 2x4 virtual array with "
        "half the unambiguous Doppler).",
    ),
]


@experiment_app.command("encounters")
def experiment_encounters(
    out: Annotated[Path, typer.Option("-o", "--output", help="Output directory.")] = Path("out/encounters"),
    n: _N = None,
    seed: Annotated[int, typer.Option("--seed", callback=NON_NEGATIVE, help="Random seed.")] = 0,
    workers: EncounterWorkersOption = None,
    scheduler: EncounterSchedulerOption = None,
    frame_rate: _FRAME_RATE = 9.4,
    buffer: _BUFFER = 1.5,
    no_uncertainty: Annotated[
        bool, typer.Option("--no-uncertainty", help="Do not widen the volumes by the track covariance.")
    ] = False,
    terrain: _TERRAIN = "none",
    layout: _LAYOUT = Layout.both,
    navigation: _NAVIGATION = Navigation.ga_typical,
    rx_layout: _RX_LAYOUT = RxLayout.square,
    family: Annotated[
        Family,
        typer.Option(
            "--family",
            help="synthetic (parametric flights), real-flights (recorded own-ship and intruder "
            "flights of the 'flights' extra, moved to meet) or fast-closures (head-on and wide "
            "crossings whose closing speed aliases into the ground's Doppler band; own-ship "
            "300-700 m above hills and Jacksboro).",
        ),
    ] = Family.synthetic,
    split: SplitOption = None,
    only: _ONLY = None,
    alert_settings: Annotated[
        str,
        typer.Option(
            "--alert-config",
            help="Alerting settings the chain warns with: radar (the default, every result of the docs), "
            "do365b (DAIDALUS' DO-365B non-cooperative alerter), default (AlertConfig's own defaults) "
            "or FILE.yaml (fields of skyradar.daa.alert_config, as for 'skyradar alert --config').",
        ),
    ] = "radar",
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """Encounter set (head-on, crossing, converging, overtaking, climbing; conflicts and near misses),
    each through the full chain (simulate every head, detect + DoA, track, alert) per terrain and
    layout: warnings before the loss of well clear over all conflicts, the unwarned ones by cause,
    missed, late and false warnings, clutter and ground tracks, track fragments, warning lead.
    """
    from skyradar.cli.commands_sim import frame_progress
    from skyradar.daa.alert_config import alert_config
    from skyradar.experiments.encounter_terrain import parse_terrains
    from skyradar.experiments.encounters import (
        DEFAULT_ENCOUNTERS,
        DEFAULT_TERRAIN_ENCOUNTERS,
        run,
    )
    from skyradar.io.outputs import check_output, mark_folder
    from skyradar.parallel import check_workers

    check_workers(workers)
    check_split(seed, split)
    selected = parse_only(only)
    alert_config(alert_settings, option="--alert-config")  # a bad setting is named before any output
    if family is Family.real_flights:
        from skyradar.scene.sample_flights import sample_flights

        sample_flights("gliders")  # the 'flights' extra, before any output is made
    terrains, layouts = parse_terrains(terrain), LAYOUTS_SCORED[layout]
    if n is None:  # over terrain an encounter costs minutes: the default keeps a run within 5 minutes
        n = DEFAULT_ENCOUNTERS if terrains == ["none"] else DEFAULT_TERRAIN_ENCOUNTERS
    if selected is not None:  # a bad number is named before any output
        from skyradar.experiments.encounters import check_only

        selected = tuple(check_only(selected, n))
    check_output(out, (), overwrite, kind="folder", option="--output")
    mark_folder(out)
    total = (n if selected is None else len(selected)) * len(terrains)
    with frame_progress(total, "encounters") as bar:
        task = bar.add_task("encounters", total=total)
        result = run(
            out,
            n_encounters=n,
            seed=seed,
            frame_rate_hz=frame_rate,
            buffer=buffer,
            workers=workers,
            uncertainty=not no_uncertainty,
            progress=lambda k: bar.update(task, completed=k),
            terrains=tuple(terrains),
            layouts=layouts,
            navigation=navigation.value,
            rx_layout=rx_layout.value,
            family=family.value,
            command="skyradar " + " ".join(sys.argv[1:]),
            scheduler=scheduler,
            alert_settings=alert_settings,
            only=selected,
        )
    emit_result(result, as_json, "encounters")


@bench_app.command("encounter")
def bench_encounter(
    terrain: Annotated[
        list[EncounterTerrain] | None,
        typer.Option(
            "--terrain",
            help="Terrain to fly the encounter over (repeat; default flat-300, hills, jacksboro).",
        ),
    ] = None,
    as_json: JsonOption = False,
) -> None:
    """CPU seconds of one encounter end to end per terrain, with each stage's time, against 9 CPU-s."""
    from skyradar.experiments.encounter_cost import BENCH_TERRAINS, run_encounter_bench

    terrains = tuple(t.value for t in terrain) if terrain else BENCH_TERRAINS
    emit_measurement(run_encounter_bench(terrains), as_json, "bench encounter")
