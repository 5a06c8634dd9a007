"""``skyradar export``: a run's own-ship state (navigation and truth) and intruder truth as Parquet."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from skyradar.cli.app import JsonOption, app, emit_result
from skyradar.io.outputs import OVERWRITE_HELP

__all__ = ["export"]


@app.command()
def export(
    run: Annotated[Path, typer.Argument(help="Frames run (Zarr) from `skyradar simulate` or a recording.")],
    output: Annotated[
        Path,
        typer.Option(
            "-o",
            "--output",
            help="Folder (gets ownship.parquet, intruders.parquet) or NAME.parquet (+NAME.intruders.parquet)",
        ),
    ],
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """Export the own-ship state per frame (the navigation solution nav_* the chain used, beside
    the truth own_*) and the intruder truth (tgt_*, one row per frame and intruder) as Parquet
    tables with time_s and utc columns."""
    from skyradar.errors import InputError
    from skyradar.io.frames import open_frames
    from skyradar.io.frames_heads import store_heads
    from skyradar.io.outputs import check_output, mark_folder
    from skyradar.io.run_export import export_paths, intruder_table, ownship_table
    from skyradar.io.run_origin import scenario_origin
    from skyradar.io.tables import write_table

    folder = output.suffix.lower() != ".parquet"
    if folder and output.suffix and not output.is_dir():  # own.csv would silently become a folder
        raise InputError(
            f"--output {output}: a table's name ends in .parquet; without it the output is a folder "
            f"(name one without a suffix, or {output.with_suffix('.parquet').name})"
        )
    own_path, intr_path = export_paths(output)
    if folder:
        check_output(output, [run], overwrite, kind="folder")
    for path in (own_path, intr_path):
        check_output(path, [run], overwrite, kind="table")
    ds = open_frames(run)
    heads = store_heads(run) or []
    views = {h: ds if i == 0 else open_frames(run, head=h) for i, h in enumerate(heads)}
    own, intr = ownship_table(ds), intruder_table(ds, views)
    if own.shape[1] <= 2 and intr.empty:
        raise InputError(f"{run}: no own-ship (nav_*, own_*) or intruder (tgt_*) state to export")
    origin = scenario_origin(ds)
    meta = {"source": str(run), "origin_lla": None if origin is None else list(origin)}
    if folder:
        mark_folder(output)
    write_table(own, own_path, metadata=meta)
    write_table(intr, intr_path, metadata=meta)
    navigation = any(c.startswith("nav_") for c in own.columns)
    result = {"ownship": str(own_path), "ownship_rows": len(own), "navigation": navigation}
    result |= {
        "intruders": str(intr_path),
        "intruder_rows": len(intr),
        "targets": int(intr["target"].nunique()),
    }
    emit_result(result, as_json, "export")
