"""``skyradar experiment closed-loop``: the encounter set flown by a pilot who follows the advice."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer

from skyradar.cli.app import NON_NEGATIVE, JsonOption, emit_result, experiment_app, number_in
from skyradar.cli.choices import ClosedLoopFamily, Layout, Manoeuvre
from skyradar.cli.commands_encounters import (
    LAYOUTS_SCORED,
    EncounterSchedulerOption,
    EncounterWorkersOption,
    SplitOption,
    check_split,
)
from skyradar.io.outputs import OVERWRITE_HELP

__all__ = ["experiment_closed_loop"]


@experiment_app.command("closed-loop")
def experiment_closed_loop(
    out: Annotated[Path, typer.Option("-o", "--output", help="Output directory.")] = Path("out/closed-loop"),
    n: Annotated[
        int,
        typer.Option(
            "--n",
            callback=number_in(1, 100_000),
            help="Encounters per terrain (default 6: clear sky, single head, 2 workers, within 5 minutes "
            "on 2 cores; over terrain an encounter costs minutes).",
        ),
    ] = 6,
    seed: Annotated[int, typer.Option("--seed", callback=NON_NEGATIVE, help="Random seed.")] = 0,
    terrain: Annotated[
        str,
        typer.Option(
            help="Comma-separated terrains, each a row of the result: none (clear sky), flat-300, "
            "flat-1000, hills, jacksboro; 'all' = every one."
        ),
    ] = "none",
    layout: Annotated[
        Layout,
        typer.Option(
            help="Radar heads in the loop: single (forward +-35 deg), three-head (nose and wingtips) or "
            "both (one closed-loop run each)."
        ),
    ] = Layout.single,
    family: Annotated[
        ClosedLoopFamily,
        typer.Option("--family", help="synthetic (parametric encounters) or fast-closures."),
    ] = ClosedLoopFamily.synthetic,
    manoeuvre: Annotated[
        Manoeuvre,
        typer.Option(help="What the pilot flies: the preferred heading or the preferred vertical speed."),
    ] = Manoeuvre.horizontal,
    corrective_delay: Annotated[
        float,
        typer.Option(
            "--corrective-delay-s",
            callback=number_in(0.0, 120.0),
            help="Pilot's reaction delay after a corrective alert, s.",
        ),
    ] = 5.0,
    warning_delay: Annotated[
        float,
        typer.Option(
            "--warning-delay-s",
            callback=number_in(0.0, 120.0),
            help="Pilot's reaction delay after a warning, s.",
        ),
    ] = 3.0,
    workers: EncounterWorkersOption = None,
    scheduler: EncounterSchedulerOption = None,
    split: SplitOption = None,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """Closed loop: each encounter flown unequipped, with perfect surveillance and with the radar in
    the loop, the pilot following the advice after a reaction delay. Rates of loss of well clear and
    NMAC, risk ratios against unequipped, induced losses, separation, time spent manoeuvring.
    """
    from skyradar.cli.commands_sim import frame_progress
    from skyradar.experiments.closed_loop import run
    from skyradar.experiments.encounter_terrain import parse_terrains
    from skyradar.io.outputs import check_output, mark_folder
    from skyradar.parallel import check_workers
    from skyradar.pilot import PilotConfig

    check_workers(workers)
    check_split(seed, split)
    terrains = parse_terrains(terrain)
    pilot = PilotConfig(
        manoeuvre=manoeuvre.value, corrective_delay_s=corrective_delay, warning_delay_s=warning_delay
    )
    check_output(out, (), overwrite, kind="folder", option="--output")
    mark_folder(out)
    total = n * len(terrains)
    with frame_progress(total, "encounters") as bar:
        task = bar.add_task("encounters", total=total)
        result = run(
            out,
            n_encounters=n,
            seed=seed,
            terrains=tuple(terrains),
            layouts=LAYOUTS_SCORED[layout],
            family=family.value,
            pilot=pilot,
            workers=workers,
            scheduler=scheduler,
            progress=lambda k: bar.update(task, completed=k),
            command="skyradar " + " ".join(sys.argv[1:]),
        )
    emit_result(result, as_json, "closed loop")
