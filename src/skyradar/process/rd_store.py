"""Raw ADC recording -> range-Doppler frames store, chunk by chunk, resumable, optionally on Dask.

Each chunk is a pure function of the recording and its frame range, so a plain loop, a local
Dask cluster and a remote one write the same bytes; workers read the recording (memory-mapped)
and write their own chunk into the shared ``.partial`` store.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from skyradar.io.checks import check_finite_frames
from skyradar.io.frames import FrameStoreWriter, check_store_space, frames_dataset
from skyradar.io.outputs import check_output
from skyradar.io.recordings import read_recording
from skyradar.process.rangedoppler import RangeDopplerProcessor, window_gain_db

__all__ = ["recording_to_frames", "recording_files"]


def recording_files(recording: str | Path, frames: Any = None) -> list[Path]:
    """The files a recording is made of: the named one, its sidecar and its data file.

    Every existing NAME.{json,yaml,yml,bin,dat,npy,sigmf-meta,sigmf-data} beside it, and the
    memory-mapped data file.

    Parameters
    ----------
    recording : str or Path
        The recording as named by the user (a sidecar, a data file or a bare SigMF stem).
    frames : object, optional
        The frames as :func:`~skyradar.io.recordings.read_recording` returns them; when their
        ``raw`` attribute is a memory map, its file is added.

    Returns
    -------
    list of Path
        The existing files, each once, the named one first.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     for name in ("run.json", "run.bin", "other.bin"):
    ...         _ = (Path(tmp) / name).write_bytes(b"")
    ...     print([f.name for f in recording_files(Path(tmp) / "run.json")])
    ['run.json', 'run.bin']
    """
    path = Path(recording)
    suffixes = (".json", ".yaml", ".yml", ".bin", ".dat", ".npy", ".sigmf-meta", ".sigmf-data")
    files = [path] + [path.with_suffix(s) for s in suffixes]
    if not path.suffix:  # a SigMF recording named by its bare stem
        files += [path.with_name(path.name + s) for s in (".sigmf-meta", ".sigmf-data")]
    mapped = getattr(getattr(frames, "raw", None), "filename", None)
    if mapped:
        files.append(Path(mapped))
    return [f for f in dict.fromkeys(files) if f.exists()]


def _fingerprint(files: list[Path], options: dict[str, Any]) -> str:
    # Size and modification time of every file (hashing a multi-GB recording would cost a full read);
    # the writer adds the chunk layout, codec and package version.
    from skyradar import __version__

    stats = {str(f.resolve()): [f.stat().st_size, f.stat().st_mtime_ns] for f in files}
    text = json.dumps({"files": stats, "version": __version__, **options}, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _write_chunk(recording: str, partial: str, chunk_frames: int, options: dict[str, Any], index: int) -> int:
    frames, config = read_recording(recording)
    n_samples = frames.shape[3]
    proc = RangeDopplerProcessor(config, options["rw"], options["dw"], n_samples=n_samples)
    writer = FrameStoreWriter.attach(partial, chunk_frames, frames.shape[0], options["precision"])
    sl = writer.chunk_slice(index)
    block = np.stack([proc(frames[i], remove_dc=options["dc"]) for i in range(sl.start, sl.stop)])
    writer.write_chunk(index, block)
    return sl.stop - sl.start


def _check_samples(frames, source: str | Path, chunk_frames: int) -> None:
    """Refuse a recording with NaN/inf samples before anything is written, naming the frame."""
    if frames.raw.dtype.kind not in "fc":
        return  # integer ADC codes are always finite (and scaled by a finite factor)
    for start in range(0, len(frames), chunk_frames):
        stop = min(start + chunk_frames, len(frames))
        check_finite_frames(np.stack([frames[i] for i in range(start, stop)]), start, source, "samples")


def _checked_inputs(recording, output, overwrite: bool, chunk_frames: int, compressor: str, precision: str):
    """The recording, its radar, its files and the chunk length, once output, input and disk are checked."""
    check_output(output, recording_files(recording), overwrite, kind="frames store")
    frames, config = read_recording(recording)  # raises InputError on a bad recording
    inputs = recording_files(recording, frames)
    check_output(output, inputs, overwrite, kind="frames store")
    chunk_frames = max(1, min(int(chunk_frames), frames.shape[0]))  # a chunk is at most the whole run
    check_store_space(output, config, frames.shape[0], chunk_frames, compressor, precision)
    _check_samples(frames, recording, chunk_frames)
    return frames, config, inputs, chunk_frames


def _template(frames, config, chunk_frames: int, attrs: dict[str, Any]):
    """The store's layout: lazy zeros of the run's shape, with the recording's times and radar."""
    import dask.array as da

    shape = (frames.shape[0], config.n_range, config.n_doppler, config.n_rx)
    lazy = da.zeros(shape, dtype=np.complex64, chunks=(chunk_frames, *shape[1:]))
    return frames_dataset(lazy, frames.times_s, config, attrs=attrs)


def _write_pending(
    args: tuple[str, str, int, dict[str, Any]],
    pending: list[int],
    client,
    progress: Callable[[int], None] | None,
) -> None:
    """Process and write the chunks ``pending`` here, or on the Dask ``client``."""
    if client is None:
        for index in pending:
            done = _write_chunk(*args, index)
            if progress:
                progress(done)
        return
    from skyradar.parallel import map_chunks

    map_chunks(_write_chunk, *args, client=client, chunks=pending, progress=progress)


def recording_to_frames(
    recording: str | Path,
    output: str | Path,
    range_window: str = "hann",
    doppler_window: str = "hann",
    remove_dc: bool = False,
    chunk_frames: int = 32,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: Callable[[int], None] | None = None,
    overwrite: bool = False,
    compressor: str = "none",
    precision: str = "complex64",
) -> dict[str, Any]:
    """Turn a recording into a frames store; returns a summary (frames, chunks written/resumed...).

    The output is checked first (never the recording, its sidecar or data file; an existing path
    skyradar did not write only with ``overwrite``), then the recording and the free disk space,
    all before anything is written; a bad recording leaves no output.
    """
    frames, config, inputs, chunk_frames = _checked_inputs(
        recording, output, overwrite, chunk_frames, compressor, precision
    )
    n_frames = frames.shape[0]
    RangeDopplerProcessor(config, range_window, doppler_window, n_samples=frames.shape[3])  # checks windows
    attrs = {"source": str(recording), "range_window": range_window, "doppler_window": doppler_window}
    template = _template(frames, config, chunk_frames, attrs)
    options = {"rw": range_window, "dw": doppler_window, "dc": remove_dc, "chunk": chunk_frames}
    options["precision"] = precision  # also in the writer's fingerprint; the workers need it to encode
    client = None
    if scheduler is not None or workers:
        from skyradar.parallel import connect

        client = connect(scheduler, workers)  # before any output exists: a dead address leaves nothing
    try:
        key = _fingerprint(inputs, options)
        writer = FrameStoreWriter(
            output, template, chunk_frames, key, overwrite, inputs, compressor, precision
        )
        pending = writer.pending_chunks()
        job_args = (str(recording), str(writer.partial), chunk_frames, options)
        _write_pending(job_args, pending, client, progress)
    finally:
        if client is not None:
            from skyradar.parallel import close

            close(client, owns_cluster=scheduler is None)
    writer.close()
    return {
        "frames": n_frames,
        "chunks_written": len(pending),
        "chunks_resumed": writer.n_chunks - len(pending),
        "n_range": config.n_range,
        "n_doppler": config.n_doppler,
        "n_rx": config.n_rx,
        "window_gain_db": window_gain_db(range_window, doppler_window, config),
        "precision": precision,
        "output": str(output),
    }
