"""``skyradar experiment bluesky``: BlueSky's perfect-state conflict detection against the radar's."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer

from skyradar.cli.app import POSITIVE, JsonOption, console, emit_result, experiment_app
from skyradar.io.outputs import OVERWRITE_HELP

__all__ = ["experiment_bluesky"]


@experiment_app.command("bluesky")
def experiment_bluesky(
    scenario: Annotated[
        Path | None,
        typer.Option(
            "--scenario",
            help="A BlueSky scenario file (.scn) with radar-equipped aircraft (SKYRADAR acid ON); default "
            "the packaged skyradar_demo.scn (two equipped light aircraft over hills, 3 minutes).",
        ),
    ] = None,
    out: Annotated[Path, typer.Option("-o", "--output", help="Output directory.")] = Path("out/bluesky"),
    end: Annotated[
        float | None,
        typer.Option(
            "--end-s", callback=POSITIVE, help="Simulation time to stop at, s (default: the scenario's HOLD)."
        ),
    ] = None,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """Play a BlueSky scenario headless twice with the skyradar plugin: every aircraft on perfect state
    (BlueSky alone), then the radar-equipped ones on their radar's tracks. Reports the conflicts the
    radar found, when (against the perfect state), missed and false, and the losses of separation of
    both runs; writes conflicts.csv, separation.csv, summary.json and bluesky.png.
    """
    from skyradar.experiments.bluesky_compare import run
    from skyradar.integrations.bluesky.runner import require_bluesky
    from skyradar.io.outputs import check_output, mark_folder

    require_bluesky()
    if scenario is not None and not scenario.is_file():
        from skyradar.errors import InputError

        raise InputError(f"{scenario}: no such BlueSky scenario file")
    check_output(out, (scenario,), overwrite, kind="folder", option="--output")
    mark_folder(out)
    shown = {"truth": -10.0, "radar": -10.0}

    def progress(name: str, time_s: float) -> None:
        if time_s - shown[name] >= 30.0:
            shown[name] = time_s
            console.print(f"[dim]{name} run: t = {time_s:.0f} s[/dim]")

    command = "skyradar " + " ".join(sys.argv[1:])
    result = run(out, scenario=scenario, end_s=end, progress=progress, command=command)
    emit_result(result, as_json, "BlueSky: perfect state against the radar")
