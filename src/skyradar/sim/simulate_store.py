"""A built scenario simulated into a Zarr frames store chunk by chunk: resumable, optionally on Dask.

Each chunk is a pure function of the scenario and its frame indices (noise is seeded per frame), so
a plain loop, a local Dask cluster and a remote one write the same bytes, and an interrupted run
resumes where it stopped. A scenario with several radar heads writes one Zarr group per head
(:mod:`skyradar.io.frames_heads`); one head writes the store as before.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import xarray as xr

from skyradar.io.frames import FrameStoreWriter, check_store_space, frames_dataset
from skyradar.io.locks import exclusive_output
from skyradar.io.outputs import check_output
from skyradar.sim.fingerprint import fingerprint, referenced_files
from skyradar.sim.image import ImageSimulator
from skyradar.sim.scenario_frames import frames_attrs, make_simulator, scenario_truth, simulate_frames

__all__ = ["simulate_to_zarr"]


def _template(built, chunk_frames: int, simulator: ImageSimulator) -> xr.Dataset:
    import dask.array as da

    cfg = simulator.config
    shape = (built.times_s.size, *cfg.frame_shape)
    iq = da.zeros(shape, dtype=np.complex64, chunks=(chunk_frames, -1, -1, -1))
    ownship, targets, names = scenario_truth(built, simulator)
    return frames_dataset(iq, built.times_s, cfg, ownship, targets, names, frames_attrs(built))


def _templates(built, chunk_frames: int, simulators: list) -> xr.Dataset | dict[str, xr.Dataset]:
    """One head: its Dataset (the store as before); several: {head name: Dataset}, a group each."""
    if len(simulators) == 1:
        return _template(built, chunk_frames, simulators[0])
    return {
        h.name: _template(built, chunk_frames, sim) for h, sim in zip(built.heads, simulators, strict=True)
    }


def _frames(built, rows: np.ndarray, simulators: list) -> np.ndarray | dict[str, np.ndarray]:
    """Frames ``rows`` of every head, in the form :meth:`FrameStoreWriter.write_chunk` takes."""
    if len(simulators) == 1:
        return simulate_frames(built, rows, simulators[0])
    return {h.name: simulate_frames(built, rows, s) for h, s in zip(built.heads, simulators, strict=True)}


_WORKER_SIMULATORS: dict[str, list] = {}


def _chunk_job(built, key: str, path: str, chunk_frames: int, precision: str, index: int) -> int:
    # Runs on a Dask worker: one simulator per scenario per worker process (terrain set-up once).
    import numba

    numba.set_num_threads(1)  # one worker per core; threads inside would oversubscribe
    if key not in _WORKER_SIMULATORS:
        _WORKER_SIMULATORS.clear()
        _WORKER_SIMULATORS[key] = [make_simulator(built, h) for h in range(len(built.heads))]
    writer = FrameStoreWriter.attach(path, chunk_frames, built.times_s.size, precision)
    sl = writer.chunk_slice(index)
    writer.write_chunk(index, _frames(built, np.arange(sl.start, sl.stop), _WORKER_SIMULATORS[key]))
    return sl.stop - sl.start


def _chunk_len(writer: FrameStoreWriter, index: int) -> int:
    sl = writer.chunk_slice(index)
    return sl.stop - sl.start


def simulate_to_zarr(
    built,
    path: str | Path,
    chunk_frames: int = 16,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: Callable[[int], None] | None = None,
    overwrite: bool = False,
    compressor: str = "none",
    precision: str = "complex64",
) -> Path:
    """Simulate into a Zarr store chunk by chunk; rerunning resumes an interrupted run.

    Parameters
    ----------
    built : BuiltScenario
    path : path
        Output store; written as ``path.partial`` and renamed when complete.
    chunk_frames : int
        Frames per chunk along time (the unit of work and of resumption).
    scheduler : str, optional
        Address of an existing Dask scheduler (``tcp://host:8786``).
    workers : int, optional
        Start a local Dask cluster with this many single-threaded workers. Without ``scheduler``
        and ``workers`` the chunks run in a plain loop in this process.
    progress : callable, optional
        Called with the number of frames finished after each chunk.
    overwrite : bool
        Replace an existing ``path`` skyradar did not write (never the scenario or its files).
    compressor : {"none", "zstd", "blosc"}
        Lossless codec for ``iq``.
    precision : {"complex64", "cint16"}
        Pixel format; cint16 halves the raw size at a bounded rounding error
        (:mod:`skyradar.io.cint16`).

    Before any work the output is checked (:func:`skyradar.io.outputs.check_output`), locked
    against a second writer (:func:`skyradar.io.locks.exclusive_output`), and the disk must hold the
    estimated store.
    """
    inputs = (getattr(built, "source", None), *referenced_files(built))
    check_output(path, inputs, overwrite, kind="frames store")
    with exclusive_output(path):  # a second writer of the same store is refused, not interleaved
        return _simulate_locked(
            built, path, chunk_frames, scheduler, workers, progress, overwrite, compressor, precision, inputs
        )


def _simulate_locked(
    built, path, chunk_frames, scheduler, workers, progress, overwrite, compressor, precision, inputs
) -> Path:
    """:func:`simulate_to_zarr` once the output is checked and locked."""
    # A chunk longer than the run is the whole run (--chunk-frames 10**20 must not size a 10^20 chunk).
    chunk_frames = max(1, min(int(chunk_frames), built.times_s.size))
    n = len(built.heads)  # several heads: n times the frames (sized with the first head's hardware)
    check_store_space(path, built.radar, n * built.times_s.size, n * chunk_frames, compressor, precision)
    client = None
    if scheduler is not None or workers:
        from skyradar.parallel import close, connect

        client = connect(scheduler, workers)  # before any output exists: a dead address leaves nothing
    try:
        simulators = [make_simulator(built, h) for h in range(len(built.heads))]
        key = fingerprint(built)
        template = _templates(built, chunk_frames, simulators)
        writer = FrameStoreWriter(path, template, chunk_frames, key, overwrite, inputs, compressor, precision)
        _write_pending(built, writer, simulators, key, client, progress)
    finally:
        if client is not None:
            close(client, owns_cluster=scheduler is None)
    return writer.close()


def _write_pending(built, writer: FrameStoreWriter, simulators: list, key: str, client, progress) -> None:
    """Simulate and write the chunks the store still lacks, here or on the Dask ``client``."""
    from skyradar.parallel import map_chunks

    pending = writer.pending_chunks()
    if progress and len(pending) < writer.n_chunks:  # resumed: count the chunks already there
        progress(built.times_s.size - sum(_chunk_len(writer, i) for i in pending))
    if client is None:
        for index in pending:
            sl = writer.chunk_slice(index)
            writer.write_chunk(index, _frames(built, np.arange(sl.start, sl.stop), simulators))
            if progress:
                progress(sl.stop - sl.start)
        return
    job_args = (built, key, str(writer.partial), writer.chunk_frames, writer.precision)
    map_chunks(_chunk_job, *job_args, client=client, chunks=pending, progress=progress)
