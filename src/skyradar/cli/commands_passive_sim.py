"""``skyradar simulate-passive``: a simulated passive-radar recording (SigMF) of the ch7 geometry."""

from __future__ import annotations

import datetime as dt
from pathlib import Path
from typing import Annotated

import typer

from skyradar.cli.app import COUNT, POSITIVE, JsonOption, app, check_choice, console, emit_result, number_in
from skyradar.errors import InputError
from skyradar.io.outputs import OVERWRITE_HELP

__all__ = ["simulate_passive"]

SCENARIOS = ("thesis",)


def _start_time(value: str | None) -> dt.datetime | None:
    if value is None:
        return None
    try:
        t = dt.datetime.fromisoformat(value.replace("Z", "+00:00"))
    except ValueError:
        raise InputError(f"--start-time: not an ISO 8601 time, got {value!r}") from None
    return t if t.tzinfo else t.replace(tzinfo=dt.UTC)


@app.command("simulate-passive")
def simulate_passive(
    scenario: Annotated[str, typer.Argument(help="Built-in geometry: thesis (seed-brief ch7).")] = "thesis",
    output: Annotated[
        Path, typer.Option("-o", "--output", help="Recording to write: NAME.sigmf-meta (+ NAME.sigmf-data).")
    ] = Path("passive.sigmf-meta"),
    duration_s: Annotated[
        float, typer.Option("--duration-s", callback=number_in(0.0, 3600.0, low_open=True), help="Seconds.")
    ] = 40.0,
    sample_rate_hz: Annotated[
        float, typer.Option("--sample-rate-hz", callback=POSITIVE, help="Complex sample rate, Hz.")
    ] = 5e6,
    seed: Annotated[int, typer.Option("--seed", callback=number_in(0), help="Noise and clutter seed.")] = 0,
    adsb: Annotated[
        Path | None,
        typer.Option(
            "--adsb", help="ADS-B/track file (CSV, Parquet, JSON) whose aircraft replace the default."
        ),
    ] = None,
    start_time: Annotated[
        str | None,
        typer.Option(
            "--start-time", help="UTC time of the first sample (ISO 8601); aligns --adsb timestamps."
        ),
    ] = None,
    no_aircraft: Annotated[bool, typer.Option("--no-aircraft", help="Static scene only.")] = False,
    chunk_samples: Annotated[
        int, typer.Option("--chunk-samples", callback=COUNT, help="Samples simulated and written per chunk.")
    ] = 1 << 20,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """Simulate the IQ a passive receiver records near a rotating S-band ATC radar, as SigMF.

    Direct path through the radar's antenna pattern, echoes of building clusters, ground clutter and
    aircraft (bistatic radar equation, bistatic Doppler), thermal noise; streamed to disk in chunks.
    Truth for scoring goes to NAME.truth.parquet and NAME.truth.json, not into the SigMF metadata.
    """
    import dataclasses

    from skyradar.io.outputs import check_disk_space, check_output
    from skyradar.io.sigmf_io import sigmf_paths
    from skyradar.passive.scene import aircraft_from_adsb, thesis_scene
    from skyradar.passive.simulate import check_sample_rate, simulate_recording
    from skyradar.passive.truth import truth_paths

    check_choice("SCENARIO", scenario, SCENARIOS)
    if adsb is not None and no_aircraft:
        raise InputError("--adsb and --no-aircraft: choose one")
    meta, data = sigmf_paths(output)
    if meta.name != Path(output).name and Path(output).suffix not in ("", ".sigmf-data"):
        raise InputError(f"--output {output}: name the recording NAME.sigmf-meta")
    for path in (meta, data, *truth_paths(meta)):
        check_output(path, inputs=[adsb], overwrite=overwrite, kind="file")
    scene = thesis_scene(duration_s=duration_s, seed=seed, aircraft=not no_aircraft and adsb is None)
    when = _start_time(start_time)
    if when is not None:
        scene = dataclasses.replace(scene, start_time=when)
    if adsb is not None:
        planes = aircraft_from_adsb(adsb, scene.receiver, start_time=when)
        scene = dataclasses.replace(scene, aircraft=tuple(planes))
    check_sample_rate(scene, sample_rate_hz)
    total = int(round(duration_s * sample_rate_hz))
    check_disk_space(data, 8.0 * total, "the recording")

    from rich.progress import BarColumn, Progress, TimeRemainingColumn

    with Progress("simulating", BarColumn(), TimeRemainingColumn(), console=console) as bar:
        task = bar.add_task("samples", total=total)
        path = simulate_recording(
            scene, meta, sample_rate_hz, chunk_samples, overwrite=True,
            progress=lambda done, _total: bar.update(task, completed=done),
        )  # fmt: skip
    table, summary = truth_paths(path)
    result = {
        "recording": str(path),
        "samples": total,
        "duration_s": duration_s,
        "sample_rate_hz": sample_rate_hz,
        "aircraft": len(scene.aircraft),
        "static_reflectors": len(scene.reflectors),
        "truth_table": str(table),
        "truth_summary": str(summary),
    }
    emit_result(result, as_json, "passive recording")
