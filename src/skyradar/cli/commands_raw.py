"""Raw-chain commands: ``skyradar rd`` (recording -> frames store) and ``skyradar bench chain``."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Annotated

import typer

from skyradar.cli.app import app, bench_app, console, emit_result

__all__ = ["rd", "bench_chain"]

WINDOW_HELP = "hann, hamming, blackmanharris, chebyshev[:SIDELOBE_DB] or none."


def _fingerprint(path: Path, options: dict) -> str:
    stat = path.stat()
    text = json.dumps(
        {"path": str(path.resolve()), "size": stat.st_size, "mtime": stat.st_mtime_ns, **options}
    )
    return hashlib.sha256(text.encode()).hexdigest()[:16]


@app.command()
def rd(
    recording: Annotated[
        Path,
        typer.Argument(help="Raw ADC recording: NAME.bin/.dat with NAME.json/.yaml sidecar, or NAME.npy."),
    ],
    output: Annotated[Path, typer.Option("-o", "--output", help="Frames store to write (Zarr directory).")],
    range_window: Annotated[str, typer.Option("--range-window", help=WINDOW_HELP)] = "hann",
    doppler_window: Annotated[str, typer.Option("--doppler-window", help=WINDOW_HELP)] = "hann",
    remove_dc: Annotated[
        bool, typer.Option("--remove-dc", help="Subtract each chirp's mean (ADC offset).")
    ] = False,
    chunk_frames: Annotated[int, typer.Option("--chunk-frames", min=1, help="Frames per Zarr chunk.")] = 32,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the summary as JSON (last stdout line).")
    ] = False,
) -> None:
    """Turn a raw ADC recording into range-Doppler frames (the same store the simulator writes).

    Windowed range FFT cropped to RLim, windowed Doppler FFT with shift, per-channel calibration
    from the sidecar's ``radar.rx_calibration``. Pixels: |iq|^2 = received power in W times the
    windows' coherent gain. Written chunk by chunk; an interrupted run resumes. The recording is
    fully checked first: a bad recording leaves no output.
    """
    import dask.array as da
    import numpy as np

    from skyradar.io.frames import FrameStoreWriter, frames_dataset
    from skyradar.io.recordings import read_recording
    from skyradar.process.rangedoppler import RangeDopplerProcessor, window_gain_db

    frames, config = read_recording(recording)
    n_frames, _, _, n_samples = frames.shape
    proc = RangeDopplerProcessor(config, range_window, doppler_window, n_samples=n_samples)
    shape = (n_frames, config.n_range, config.n_doppler, config.n_rx)
    lazy = da.zeros(shape, dtype=np.complex64, chunks=(chunk_frames, *shape[1:]))
    attrs = {"source": str(recording), "range_window": range_window, "doppler_window": doppler_window}
    template = frames_dataset(lazy, frames.times_s, config, attrs=attrs)
    options = {"rw": range_window, "dw": doppler_window, "dc": remove_dc, "chunk": chunk_frames}
    writer = FrameStoreWriter(output, template, chunk_frames, _fingerprint(Path(recording), options))
    pending = writer.pending_chunks()
    for index in pending:
        sl = writer.chunk_slice(index)
        block = np.stack([proc(frames[i], remove_dc=remove_dc) for i in range(sl.start, sl.stop)])
        writer.write_chunk(index, block)
        console.print(f"chunk {index + 1}/{writer.n_chunks} ({sl.stop} of {n_frames} frames)")
    writer.close()
    result = {
        "frames": n_frames,
        "chunks_written": len(pending),
        "chunks_resumed": writer.n_chunks - len(pending),
        "n_range": config.n_range,
        "n_doppler": config.n_doppler,
        "n_rx": config.n_rx,
        "window_gain_db": window_gain_db(range_window, doppler_window, config),
        "output": str(output),
    }
    emit_result(result, as_json, "range-Doppler frames")


@bench_app.command("chain")
def bench_chain(
    frames: Annotated[int, typer.Option("--frames", min=2, help="Frames to time.")] = 20,
    workers: Annotated[int, typer.Option("--workers", min=1, help="FFT threads.")] = 2,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the result as JSON (last stdout line).")
    ] = False,
    flight_frames: Annotated[
        int, typer.Option(help="Frames of the whole-flight simulation run on 1 and 2 Dask workers (0: skip).")
    ] = 600,
) -> None:
    """ADC cube -> range-Doppler cube throughput, and whole-flight simulation on 1 vs 2 Dask workers.

    Prints ``raw_to_rd_fps``, ``realtime_factor`` (fps / 9.4 frames/s) and the same-run baseline
    (per-channel numpy.fft loop) with the speed-up; then ``sim_fps_1_worker``,
    ``sim_fps_2_workers`` and ``sim_speedup_2_workers`` for a flight at SRTM spacing.
    """
    from skyradar.benchmarks import flight
    from skyradar.benchmarks.chain import run

    result = run(n_frames=frames, workers=workers)
    if flight_frames:
        result |= flight.run(frames=flight_frames)
    emit_result(result, as_json, "raw chain and whole-flight simulation")
