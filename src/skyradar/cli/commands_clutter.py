"""``skyradar experiment clutter``: SINR loss, improvement factor, MDV and usable Doppler over flat ground."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from skyradar.cli.app import COUNT, NON_NEGATIVE, JsonOption, emit_result, experiment_app
from skyradar.io.outputs import OVERWRITE_HELP

__all__ = ["experiment_clutter"]


@experiment_app.command("clutter")
def experiment_clutter(
    out: Annotated[
        Path, typer.Option("-o", "--output", "--out", help="Output directory for figures and tables.")
    ] = Path("out/clutter"),
    frames: Annotated[
        int,
        typer.Option(
            "--frames", callback=COUNT, help="Frames per case, spread over the intruder's 5 to 1.3 km."
        ),
    ] = 24,
    seed: Annotated[int, typer.Option("--seed", callback=NON_NEGATIVE, help="Noise seed.")] = 0,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """Knowledge-aided clutter suppression over flat ground 1000 m and 300 m below, head-on intruder."""
    from skyradar.experiments.clutter import run
    from skyradar.io.outputs import check_output, mark_folder

    check_output(out, (), overwrite, kind="folder", option="--out")
    mark_folder(out)
    result = run(out, n_frames=frames, seed=seed)
    emit_result(result, as_json, "clutter: knowledge-aided suppression")
