"""``skyradar simulate-passive``: a simulated passive-radar recording (SigMF) of the ch7 geometry."""

from __future__ import annotations

import datetime as dt
from pathlib import Path
from typing import Annotated

import typer

from skyradar.cli.app import (
    CHUNK_SAMPLES,
    POSITIVE,
    JsonOption,
    app,
    console,
    emit_result,
    number_in,
)
from skyradar.cli.choices import PassiveScenario
from skyradar.errors import InputError
from skyradar.io.outputs import OVERWRITE_HELP

__all__ = ["simulate_passive"]


def _start_time(value: str | None) -> dt.datetime | None:
    if value is None:
        return None
    try:
        t = dt.datetime.fromisoformat(value.replace("Z", "+00:00"))
    except ValueError:
        raise InputError(f"--start-time: not an ISO 8601 time, got {value!r}") from None
    return t if t.tzinfo else t.replace(tzinfo=dt.UTC)


def _check_outputs(output: Path, adsb: Path | None, overwrite: bool) -> Path:
    """The metadata path, after checking that it, its data file and the truth files may be written."""
    from skyradar.io.outputs import check_output
    from skyradar.io.sigmf_io import sigmf_paths
    from skyradar.passive.truth import truth_paths

    meta, data = sigmf_paths(output)
    if meta.name != Path(output).name and Path(output).suffix not in ("", ".sigmf-data"):
        raise InputError(f"--output {output}: name the recording NAME.sigmf-meta")
    for path in (meta, data, *truth_paths(meta)):
        check_output(path, inputs=[adsb], overwrite=overwrite, kind="file")
    return meta


def _scene(scenario: PassiveScenario, duration_s: float, seed: int, adsb, start_time, no_aircraft: bool):
    import dataclasses

    from skyradar.passive.scene import aircraft_from_adsb, thesis_scene

    if adsb is not None and no_aircraft:
        raise InputError("--adsb and --no-aircraft: choose one")
    # PassiveScenario.thesis, the one built-in geometry (a new member needs its scene here).
    scene = thesis_scene(duration_s=duration_s, seed=seed, aircraft=not no_aircraft and adsb is None)
    when = _start_time(start_time)
    if when is not None:
        scene = dataclasses.replace(scene, start_time=when)
    if adsb is not None:
        planes = aircraft_from_adsb(adsb, scene.receiver, start_time=when)
        scene = dataclasses.replace(scene, aircraft=tuple(planes))
    return scene


def _run(scene, meta: Path, sample_rate_hz: float, chunk_samples: int, total: int) -> Path:
    from rich.progress import BarColumn, Progress, TimeRemainingColumn

    from skyradar.passive.simulate import simulate_recording

    with Progress("simulating", BarColumn(), TimeRemainingColumn(), console=console) as bar:
        task = bar.add_task("samples", total=total)
        path = simulate_recording(
            scene,
            meta,
            sample_rate_hz,
            chunk_samples,
            overwrite=True,
            progress=lambda done, _total: bar.update(task, completed=done),
        )
    return path


@app.command("simulate-passive")
def simulate_passive(
    scenario: Annotated[
        PassiveScenario, typer.Argument(help="Built-in geometry: thesis (Maas 2022, ch. 7).")
    ] = PassiveScenario.thesis,
    output: Annotated[
        Path, typer.Option("-o", "--output", help="Recording to write: NAME.sigmf-meta (+ NAME.sigmf-data).")
    ] = Path("passive.sigmf-meta"),
    duration_s: Annotated[
        float,
        typer.Option("--duration-s", callback=number_in(0.0, 3600.0, low_open=True), help="Length, s."),
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
        int,
        typer.Option(
            "--chunk-samples", callback=CHUNK_SAMPLES, help="Samples simulated and written per chunk."
        ),
    ] = 1 << 20,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """Simulate the IQ a passive receiver records near a rotating S-band ATC radar, as SigMF.

    Direct path, echoes of towns, ground clutter and aircraft, noise; streamed in chunks. Truth goes to
    NAME.truth.parquet / NAME.truth.json, not into the SigMF metadata.
    """
    from skyradar.io.outputs import check_disk_space
    from skyradar.passive.simulate import check_sample_rate
    from skyradar.passive.truth import truth_paths

    meta = _check_outputs(output, adsb, overwrite)
    scene = _scene(scenario, duration_s, seed, adsb, start_time, no_aircraft)
    try:
        check_sample_rate(scene, sample_rate_hz)
    except InputError as exc:
        raise InputError(f"--sample-rate-hz {sample_rate_hz:g}: {exc}") from None
    total = int(round(duration_s * sample_rate_hz))
    check_disk_space(meta, 8.0 * total, "the recording")
    path = _run(scene, meta, sample_rate_hz, chunk_samples, total)
    table, summary = truth_paths(path)
    result = {"recording": str(path), "samples": total, "duration_s": duration_s}
    result |= {"sample_rate_hz": sample_rate_hz, "aircraft": len(scene.aircraft)}
    result |= {
        "static_reflectors": len(scene.reflectors),
        "truth_table": str(table),
        "truth_summary": str(summary),
    }
    emit_result(result, as_json, "passive recording")
