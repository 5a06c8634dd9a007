"""Raw-chain commands: ``skyradar rd`` (recording -> frames store) and ``skyradar bench chain``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from skyradar.cli.app import (
    COUNT,
    WORKERS,
    JsonOption,
    app,
    bench_app,
    console,
    emit_result,
    number_in,
)
from skyradar.cli.choices import Compressor, Precision
from skyradar.errors import InputError
from skyradar.io.outputs import OVERWRITE_HELP

__all__ = ["rd", "bench_chain"]

WINDOW_HELP = "hann, hamming, blackmanharris, chebyshev[:SIDELOBE_DB] or none."


@app.command()
def rd(
    recording: Annotated[
        Path,
        typer.Argument(
            help="Raw ADC recording: NAME.bin/.dat with NAME.json/.yaml sidecar, NAME.npy, or SigMF "
            "(NAME.sigmf-meta with NAME.sigmf-data)."
        ),
    ],
    output: Annotated[Path, typer.Option("-o", "--output", help="Frames store to write (Zarr directory).")],
    range_window: Annotated[str, typer.Option("--range-window", help=WINDOW_HELP)] = "hann",
    doppler_window: Annotated[str, typer.Option("--doppler-window", help=WINDOW_HELP)] = "hann",
    remove_dc: Annotated[
        bool, typer.Option("--remove-dc", help="Subtract each chirp's mean (ADC offset).")
    ] = False,
    chunk_frames: Annotated[int, typer.Option("--chunk-frames", min=1, help="Frames per Zarr chunk.")] = 32,
    scheduler: Annotated[str | None, typer.Option(help="Address of an existing Dask scheduler.")] = None,
    workers: Annotated[
        int | None, typer.Option(callback=COUNT, help="Run on a local Dask cluster of this many workers.")
    ] = None,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    compress: Annotated[
        Compressor,
        typer.Option("--compress", help="Lossless codec for the pixels (blosc: zstd, byte shuffle)."),
    ] = Compressor.none,
    precision: Annotated[
        Precision,
        typer.Option(
            "--precision",
            help="Pixel format: complex64 (exact) or cint16 (int16 I/Q, a scale per frame, range, rx).",
        ),
    ] = Precision.complex64,
    as_json: JsonOption = False,
) -> None:
    """Turn a raw ADC recording into range-Doppler frames (the same store the simulator writes).

    Windowed range FFT cropped to RLim, windowed Doppler FFT with shift, per-channel calibration
    from the sidecar's ``radar.rx_calibration``. Pixels: |iq|^2 = received power in W times the
    windows' coherent gain. Written chunk by chunk; an interrupted run resumes. The recording is
    fully checked first: a bad recording leaves no output.
    """
    from skyradar.process.rd_store import recording_to_frames
    from skyradar.process.windows import get_window

    for option, spec in (("--range-window", range_window), ("--doppler-window", doppler_window)):
        try:
            get_window(spec, 8)
        except InputError as exc:  # name the option, not the library's "window:"
            raise InputError(f"{option}: {str(exc).removeprefix('window: ')}") from None

    def report(frames: int) -> None:
        console.print(f"{frames} more frames written")

    result = recording_to_frames(
        recording,
        output,
        range_window,
        doppler_window,
        remove_dc,
        chunk_frames,
        scheduler,
        workers,
        report,
        overwrite=overwrite,
        compressor=compress.value,
        precision=precision.value,
    )
    emit_result(result, as_json, "range-Doppler frames")


@bench_app.command("chain")
def bench_chain(
    frames: Annotated[
        int,
        typer.Option(
            "--frames", callback=number_in(2, 100), help="Frames to time (held in memory): 2 to 100."
        ),
    ] = 20,
    workers: Annotated[int, typer.Option("--workers", callback=WORKERS, help="FFT threads.")] = 2,
    as_json: JsonOption = False,
) -> None:
    """ADC cube -> range-Doppler cube throughput against a per-channel numpy.fft loop.

    Prints ``raw_to_rd_fps``, ``realtime_factor`` (fps / 9.4 frames/s) and the same-run baseline
    (per-channel numpy.fft loop) with the speed-up. The whole-flight simulation on Dask is
    ``skyradar bench flight``.
    """
    from skyradar.benchmarks.range_doppler import run

    emit_result(run(n_frames=frames, workers=workers), as_json, "raw chain")
