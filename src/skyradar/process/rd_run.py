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

from skyradar.io.frames import FrameStoreWriter, frames_dataset
from skyradar.io.recordings import read_recording
from skyradar.process.rangedoppler import RangeDopplerProcessor, window_gain_db

__all__ = ["recording_to_frames"]


def _fingerprint(path: Path, options: dict[str, Any]) -> str:
    stat = path.stat()
    text = json.dumps(
        {"path": str(path.resolve()), "size": stat.st_size, "mtime": stat.st_mtime_ns, **options}
    )
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _write_chunk(recording: str, partial: str, chunk_frames: int, options: dict[str, Any], index: int) -> int:
    frames, config = read_recording(recording)
    n_samples = frames.shape[3]
    proc = RangeDopplerProcessor(config, options["rw"], options["dw"], n_samples=n_samples)
    writer = FrameStoreWriter.attach(partial, chunk_frames, frames.shape[0])
    sl = writer.chunk_slice(index)
    block = np.stack([proc(frames[i], remove_dc=options["dc"]) for i in range(sl.start, sl.stop)])
    writer.write_chunk(index, block)
    return sl.stop - sl.start


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
) -> dict[str, Any]:
    """Turn a recording into a frames store; returns a summary (frames, chunks written/resumed...).

    The recording is fully checked before anything is written; a bad recording leaves no output.
    """
    import dask.array as da

    frames, config = read_recording(recording)  # raises InputError on a bad recording
    n_frames = frames.shape[0]
    RangeDopplerProcessor(config, range_window, doppler_window, n_samples=frames.shape[3])  # checks windows
    shape = (n_frames, config.n_range, config.n_doppler, config.n_rx)
    lazy = da.zeros(shape, dtype=np.complex64, chunks=(chunk_frames, *shape[1:]))
    attrs = {"source": str(recording), "range_window": range_window, "doppler_window": doppler_window}
    options = {"rw": range_window, "dw": doppler_window, "dc": remove_dc, "chunk": chunk_frames}
    client = None
    if scheduler is not None or workers:
        from skyradar.sim.cluster import connect

        client = connect(scheduler, workers)  # before any output exists: a dead address leaves nothing
    try:
        template = frames_dataset(lazy, frames.times_s, config, attrs=attrs)
        writer = FrameStoreWriter(output, template, chunk_frames, _fingerprint(Path(recording), options))
        pending = writer.pending_chunks()
        args = (str(recording), str(writer.partial), chunk_frames, options)
        if client is None:
            for index in pending:
                done = _write_chunk(*args, index)
                if progress:
                    progress(done)
        else:
            from skyradar.sim.cluster import map_chunks

            map_chunks(_write_chunk, *args, client=client, chunks=pending, progress=progress)
    finally:
        if client is not None:
            from skyradar.sim.cluster import close

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
        "output": str(output),
    }
