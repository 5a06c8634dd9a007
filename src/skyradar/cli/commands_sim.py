"""Commands: ``simulate``, ``scenarios``, ``experiment ch2``, ``bench sim``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

from skyradar.cli.app import (
    COUNT,
    SCHEDULER,
    JsonOption,
    app,
    bench_app,
    console,
    emit_measurement,
    emit_result,
    experiment_app,
    notes_after_inputs,
    number_in,
)
from skyradar.cli.choices import Compressor, Precision
from skyradar.io.outputs import OVERWRITE_HELP

OutDir = Annotated[Path, typer.Option("-o", "--output", help="Folder for figures and tables.")]


def frame_progress(total: int, label: str) -> Progress:
    """A rich progress bar on stderr for a per-frame job."""
    return Progress(
        TextColumn(label),
        BarColumn(),
        MofNCompleteColumn(),
        TimeRemainingColumn(),
        console=console,
        transient=True,
    )


_CompressOpt = Annotated[
    Compressor,
    typer.Option(
        "--compress",
        help="Lossless codec for the pixels: none (8 bytes per complex pixel), zstd, or blosc "
        "(zstd with byte shuffle). Readable by every command.",
    ),
]
_PrecisionOpt = Annotated[
    Precision,
    typer.Option(
        "--precision",
        help="Pixel format: complex64 (exact, 8 bytes per pixel) or cint16 (int16 I/Q with a scale "
        "per frame, range bin and rx: 4 bytes per pixel, rounding error at most half a step). "
        "Readable by every command.",
    ),
]


@app.command()
def simulate(
    scenario: Annotated[Path, typer.Argument(help="Scenario YAML file (see `skyradar scenarios`).")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Output run store (Zarr directory).")],
    chunk_frames: Annotated[
        int, typer.Option(callback=COUNT, help="Frames per chunk: the unit of work and of resumption.")
    ] = 16,
    scheduler: Annotated[
        str | None, typer.Option(callback=SCHEDULER, help="Address of an existing Dask scheduler.")
    ] = None,
    workers: Annotated[
        int | None, typer.Option(callback=COUNT, help="Run on a local Dask cluster of this many workers.")
    ] = None,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    compress: _CompressOpt = Compressor.none,
    precision: _PrecisionOpt = Precision.complex64,
) -> None:
    """Simulate a scenario into a frames store (range x Doppler x rx per frame, plus truth).

    The store is written chunk by chunk as OUTPUT.partial and renamed when complete; after an
    interruption, the same command resumes without recomputing finished chunks.
    """
    from skyradar.errors import InputError
    from skyradar.io.outputs import check_output
    from skyradar.io.store_size import check_store_space
    from skyradar.scene.scenario import load_scenario
    from skyradar.sim.simulate_store import simulate_to_zarr

    if chunk_frames < 1:
        raise InputError(f"--chunk-frames must be >= 1, got {chunk_frames}")
    check_output(output, [scenario], overwrite, kind="frames store")  # before any work
    with notes_after_inputs():  # a refused file is the one line, not the note of the file before it
        loaded = load_scenario(scenario)
        # Before the build: a huge run is refused in a second, not after minutes of truth geometry.
        n_heads = len(loaded.model.radars or [None])  # several radar heads: a group of frames each
        check_store_space(
            output,
            loaded.radar_config(),
            n_heads * loaded.frame_times().size,
            n_heads * chunk_frames,
            compress.value,
            precision.value,
        )
        built = loaded.build()
    n = built.times_s.size
    with frame_progress(n, f"simulate {built.name}") as bar:
        task = bar.add_task("frames", total=n)
        path = simulate_to_zarr(
            built,
            output,
            chunk_frames,
            scheduler,
            workers,
            progress=lambda k: bar.advance(task, k),
            overwrite=overwrite,
            compressor=compress.value,
            precision=precision.value,
        )
    heads = f" of {len(built.heads)} radar heads ({', '.join(h.name for h in built.heads)})"
    console.print(f"wrote {n} frames{heads if len(built.heads) > 1 else ''} to {path}")


@app.command()
def scenarios() -> None:
    """List the example scenarios shipped with skyradar (pass the printed path to `simulate`)."""
    from skyradar.scene.scenario import example_scenario, list_example_scenarios

    for name in list_example_scenarios():
        print(f"{name}\t{example_scenario(name)}")


@experiment_app.command("ch2")
def experiment_ch2(
    json_out: JsonOption = False,
    out: OutDir = Path("out/ch2"),
    frames: Annotated[
        int,
        typer.Option(callback=number_in(1, 200), help="Frames per case, at most 200 (timing uses them all)."),
    ] = 3,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
) -> None:
    """Flat ground at 1000 m: asymptotes R = H and V = -speed, aliased head-on intruder, 60 m/s wrap."""
    from skyradar.experiments.ch2 import run
    from skyradar.io.outputs import check_output, mark_folder

    check_output(out, (), overwrite, kind="folder", option="--output")
    result = run(mark_folder(out), n_frames=frames)
    console.print(f"summary in {out / 'summary.md'}; figures and table in {out}")
    emit_result(result, json_out, "ch2: simulator against closed form")


@bench_app.command("sim")
def bench_sim(
    json_out: JsonOption = False,
    frames: Annotated[
        int,
        typer.Option(
            callback=number_in(1, 10_000), help="Frames timed at DEM spacing, at least (fine: a quarter)."
        ),
    ] = 20,
    seconds: Annotated[
        float,
        typer.Option("--min-time-s", help="Time each implementation for at least this long, s (0 to 600)."),
    ] = 2.0,
) -> None:
    """Simulator frames/s against two numpy baselines, same run, same physics.

    The terrain is SYNTHETIC: rolling hills in a 1201 x 1201 tile
    in SRTM-3 .hgt format (3 arc-seconds, about 90 m), not SRTM data.
    Baselines: the thesis' approach (whole tile each frame, np.unique loop)
    and a straightforward vectorised numpy one (cropped facets, np.bincount).
    """
    import math

    from skyradar.benchmarks.sim import run
    from skyradar.errors import InputError

    if not (math.isfinite(seconds) and 0.0 <= seconds <= 600.0):
        raise InputError(f"--min-time-s: must be a finite number >= 0 and <= 600, got {seconds!r}")
    emit_measurement(run(n_frames=frames, min_seconds=seconds), json_out, "bench sim")


@app.command()
def sweep(
    scenario: Annotated[Path, typer.Argument(help="Scenario YAML file.")],
    param: Annotated[
        str, typer.Option(help="Dotted path in the scenario, e.g. terrain.local_sd_m, intruders.0.rcs_m2.")
    ],
    values: Annotated[str, typer.Option(help="Comma-separated values, e.g. 0,19.2,39.9.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Table of all runs (.csv or .parquet).")],
    scheduler: Annotated[
        str | None, typer.Option(callback=SCHEDULER, help="Address of an existing Dask scheduler.")
    ] = None,
    workers: Annotated[
        int | None, typer.Option(callback=COUNT, help="Run on a local Dask cluster of this many workers.")
    ] = None,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    json_out: JsonOption = False,
) -> None:
    """Run one scenario over a list of parameter values and collect each run's detectability table."""
    from skyradar.errors import InputError
    from skyradar.io.outputs import check_output
    from skyradar.io.tables import write_table
    from skyradar.sim.sweep import parse_values
    from skyradar.sim.sweep import sweep as run_sweep

    if output.suffix.lower() not in (".csv", ".parquet"):
        raise InputError(
            f"-o/--output: {output}: must end in .csv or .parquet (the table's format), "
            f"got {output.suffix or 'no suffix'!r}"
        )
    kind = "file" if output.suffix.lower() == ".csv" else "table"
    check_output(output, [scenario], overwrite, kind=kind)
    value_list = parse_values(values)
    with frame_progress(len(value_list), f"sweep {param}") as bar:
        task = bar.add_task("runs", total=len(value_list))
        table = run_sweep(
            scenario, param, value_list, scheduler, workers, progress=lambda k: bar.advance(task, k)
        )
    if output.suffix.lower() == ".csv":
        from skyradar.io.atomic import write_csv_atomic

        write_csv_atomic(table, output, index=False)
    else:
        write_table(table, output)
    console.print(table.to_string(index=False))
    if json_out:
        import json

        print(json.dumps({"param": param, "runs": json.loads(table.to_json(orient="records"))}))


@bench_app.command("flight")
def bench_flight(
    json_out: JsonOption = False,
    frames: Annotated[
        int,
        typer.Option(
            callback=number_in(1, 10_000_000), help="Frames for the 1- versus 2-worker throughput runs."
        ),
    ] = 2400,
    long_frames: Annotated[
        int,
        typer.Option(
            callback=number_in(0, 10_000_000), help="Also run a whole flight of this many frames (memory)."
        ),
    ] = 0,
) -> None:
    """Whole-flight simulation throughput on Dask with 1 and 2 workers, and peak memory over a long flight."""
    from skyradar.benchmarks.flight import run

    emit_measurement(run(frames=frames, long_frames=long_frames), json_out, "bench flight")
