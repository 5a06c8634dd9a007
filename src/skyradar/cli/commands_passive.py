"""``skyradar passive``, ``skyradar experiment ch7`` and ``skyradar bench passive`` (Maas 2022, ch. 7)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from skyradar.cli.app import (
    CHUNK_SAMPLES,
    NON_NEGATIVE,
    POSITIVE,
    JsonOption,
    app,
    bench_app,
    console,
    emit_measurement,
    emit_result,
    experiment_app,
)
from skyradar.cli.choices import PassivePulse
from skyradar.io.outputs import OVERWRITE_HELP

__all__ = ["passive", "experiment_ch7", "bench_passive"]


@app.command()
def passive(
    recording: Annotated[
        Path,
        typer.Argument(
            help="IQ recording: NAME.sigmf-meta (or -data), or a raw NAME.cf32/NAME.ci16 with a "
            "NAME.json/NAME.yaml sidecar; must name the illuminator and its position."
        ),
    ],
    output: Annotated[Path, typer.Option("-o", "--output", help="Detections table to write (Parquet).")],
    pulse: Annotated[
        PassivePulse,
        typer.Option(
            "--pulse",
            help="Matched-filter template: 'metadata' (the illuminator's long pulse as described) or "
            "'recording' (the strongest direct-path pulse of the first rotation).",
        ),
    ] = PassivePulse.metadata,
    max_range_m: Annotated[
        float,
        typer.Option("--max-range-m", callback=POSITIVE, help="Largest bistatic range R1+R2-L, m."),
    ] = 45_000.0,
    chunk_samples: Annotated[
        int,
        typer.Option("--chunk-samples", callback=CHUNK_SAMPLES, help="Samples per chunk (bounds memory)."),
    ] = 1 << 20,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """Passive bistatic detections from an ATC-radar-illuminated recording.

    Finds the direct-path pulses and the scan phase, matched-filters (Hann), cancels static returns
    over pulses, integrates each dwell, runs CFAR and places each echo on its bistatic ellipse along
    the beam. Writes one row per detection: time_s, sweep, channel (static/moving), bistatic_range_m,
    doppler_hz, snr_db, azimuth_deg, east_m, north_m (from the receiver), r_tx_m, r_rx_m.
    """
    from skyradar.io.outputs import check_output
    from skyradar.io.sigmf_io import read_iq_recording, sigmf_paths
    from skyradar.io.tables import write_table
    from skyradar.passive.pipeline import PassiveSettings, process_recording

    inputs = [recording, *_recording_files(recording, sigmf_paths)]
    check_output(output, inputs, overwrite, kind="table")
    rec = read_iq_recording(recording)
    settings = PassiveSettings(
        max_bistatic_range_m=max_range_m, pulse=pulse.value, chunk_samples=chunk_samples
    )
    with _progress(rec.n_samples) as update:
        result = process_recording(rec, settings, progress=update)
    meta = {"source": str(recording), "pulse": pulse.value, "scan_period_s": result.scan_period_s}
    write_table(result.detections, output, metadata=meta)
    emit_result(_summary(result, output), as_json, "passive detections")


def _summary(result, output: Path) -> dict:
    det = result.detections
    return {
        "pulses": result.n_pulses,
        "dwells": result.n_dwells,
        "sweeps": int(det["sweep"].nunique()),
        "detections": len(det),
        "moving": int((det["channel"] == "moving").sum()),
        "static": int((det["channel"] == "static").sum()),
        "blind_zone_dropped": result.masked,
        "scan_period_s": result.scan_period_s,
        "output": str(output),
    }


def _recording_files(path: Path, sigmf_paths) -> list[Path]:
    """The files a recording consists of (so none of them can be the output)."""
    name = path.name
    if name.endswith((".sigmf-meta", ".sigmf-data")) or path.suffix == "":
        return list(sigmf_paths(path))
    return [path.with_suffix(".json"), path.with_suffix(".yaml")]


class _progress:
    """A rich bar over recording samples; a no-op when stderr is not a terminal."""

    def __init__(self, total: int) -> None:
        from skyradar.cli.commands_sim import frame_progress

        self.total = total
        self.bar = frame_progress(total, "passive: samples")

    def __enter__(self):
        self.bar.__enter__()
        task = self.bar.add_task("passive", total=self.total)
        return lambda done, total: self.bar.update(task, completed=done)

    def __exit__(self, *exc) -> None:
        self.bar.__exit__(*exc)


@experiment_app.command("ch7")
def experiment_ch7(
    out: Annotated[
        Path, typer.Option("-o", "--output", help="Output directory for figures and tables.")
    ] = Path("out/ch7"),
    seconds: Annotated[
        float,
        typer.Option("--duration-s", callback=POSITIVE, help="Recording length, s (thesis: 40 s, 9 sweeps)."),
    ] = 40.0,
    seed: Annotated[int, typer.Option("--seed", callback=NON_NEGATIVE, help="Random seed of the scene.")] = 0,
    keep_recording: Annotated[
        bool,
        typer.Option("--keep-recording", help="Keep the simulated recording (1.6 GB for 40 s) in --output."),
    ] = False,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """ch7: passive radar with an ATC radar as illuminator: test pulse, thesis geometry, 9 sweeps."""
    from rich.progress import TaskID

    from skyradar.cli.commands_sim import frame_progress
    from skyradar.experiments.ch7 import run as run_ch7
    from skyradar.io.outputs import check_output, mark_folder

    check_output(out, (), overwrite, kind="folder", option="--output")
    mark_folder(out)
    with frame_progress(1, "ch7: samples") as bar:
        tasks: dict[str, TaskID] = {}

        def progress(stage: str, done: int, total: int) -> None:
            if stage not in tasks:
                tasks[stage] = bar.add_task(stage, total=total)
            bar.update(tasks[stage], completed=done)

        result = run_ch7(out, seconds=seconds, seed=seed, progress=progress, keep_recording=keep_recording)
    emit_result(result, as_json, "ch7: passive bistatic radar")


@bench_app.command("passive")
def bench_passive(
    seconds: Annotated[
        float,
        typer.Option("--duration-s", callback=POSITIVE, help="Length of the shorter test recording, s."),
    ] = 3.0,
    as_json: JsonOption = False,
) -> None:
    """Passive processing speed (real-time factor at 5 MS/s) and memory for two recording lengths."""
    from skyradar.benchmarks.passive import run as run_bench

    console.print("bench passive: simulating two recordings, then processing them", soft_wrap=True)
    emit_measurement(run_bench(seconds=seconds), as_json, "bench passive")
