"""``skyradar experiment arrays``: the receive-array trade study over terrains on the same encounters."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer

from skyradar.cli.app import NON_NEGATIVE, JsonOption, emit_result, experiment_app, number_in
from skyradar.cli.commands_encounters import (
    EncounterSchedulerOption,
    EncounterWorkersOption,
    SplitOption,
    check_split,
)
from skyradar.io.outputs import OVERWRITE_HELP

__all__ = ["experiment_arrays"]


@experiment_app.command("arrays")
def experiment_arrays(
    out: Annotated[Path, typer.Option("-o", "--output", help="Output directory.")] = Path("out/arrays"),
    arrays: Annotated[
        str,
        typer.Option(
            "--arrays",
            help="Comma-separated receive arrays, each simulated with its own channels: square (the "
            "prototype's 2x2), kite, ura-2x3, ura-2x4, ura-4x2, or mimo-2x4 (2 transmitters x 4 receivers "
            "taking turns).",
        ),
    ] = "square,ura-2x3",
    terrain: Annotated[
        str,
        typer.Option(
            help="Comma-separated terrains, each flown by every array: none (clear sky), flat-300, "
            "flat-1000, hills, jacksboro; 'all' = every one."
        ),
    ] = "none,flat-300",
    n: Annotated[
        int,
        typer.Option(
            "--n",
            callback=number_in(1, 100_000),
            help="Encounters per array and terrain, the same for every array (default 2: the defaults "
            "took 3 min 16 s on 2 cores at load 3-4; over flat-300 an encounter took about 45 s of "
            "one core).",
        ),
    ] = 2,
    seed: Annotated[int, typer.Option("--seed", callback=NON_NEGATIVE, help="Random seed.")] = 0,
    split: SplitOption = None,
    workers: EncounterWorkersOption = None,
    scheduler: EncounterSchedulerOption = None,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """Receive arrays x terrains on the same encounters (single forward head): missed, late and false
    warnings, median lead, ground and clutter tracks per minute, fragments per intruder; per array
    the minimum detectable velocity and usable Doppler fraction after the clutter nulls, DoA error
    against its Cramer-Rao bound at three SNRs, and processing frames per second.
    """
    from skyradar.cli.commands_sim import frame_progress
    from skyradar.experiments.arrays import parse_arrays, run
    from skyradar.experiments.encounter_terrain import parse_terrains
    from skyradar.io.outputs import check_output, mark_folder
    from skyradar.parallel import check_workers

    names = parse_arrays(arrays)
    terrains = parse_terrains(terrain)
    check_workers(workers)
    check_split(seed, split)
    check_output(out, (), overwrite, kind="folder", option="--output")
    mark_folder(out)
    total = n * len(terrains) * len(names)
    with frame_progress(total, "encounters") as bar:
        task = bar.add_task("encounters", total=total)
        result = run(
            out,
            arrays=names,
            terrains=terrains,
            n_encounters=n,
            seed=seed,
            workers=workers,
            scheduler=scheduler,
            progress=lambda k: bar.update(task, completed=k),
            command="skyradar " + " ".join(sys.argv[1:]),
        )
    emit_result(result, as_json, "receive arrays")
