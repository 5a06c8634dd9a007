"""Run a built scenario through the image-domain simulator: in memory, or chunked into Zarr.

Frames are computed chunk by chunk along time. Each chunk is a pure function of the scenario
and its frame indices (noise is seeded per frame), so a plain loop, a local Dask cluster and a
remote one write the same bytes, and an interrupted run resumes where it stopped.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from skyradar.io.frames import FrameStoreWriter, check_store_space, frames_dataset
from skyradar.io.outputs import check_output
from skyradar.sim.image import ImageSimulator, PlatformState, PointTarget
from skyradar.sim.impairments import apply_impairments

__all__ = [
    "make_simulator",
    "scenario_truth",
    "simulate_frames",
    "simulate",
    "simulate_to_zarr",
    "fingerprint",
    "referenced_files",
]

_SIM_KEYS = (
    "facet_size_m",
    "reflectivity",
    "occlusion",
    "noise",
    "flat_earth",
    "range_doppler_coupling",
    "seed",
)


def make_simulator(built) -> ImageSimulator:
    """An :class:`ImageSimulator` for a BuiltScenario, with its ``sim_options`` and impairments."""
    options = {k: v for k, v in built.sim_options.items() if k in _SIM_KEYS and v is not None}
    impairments = getattr(built, "impairments", None)
    if impairments is not None:
        options["ground_reflectivity_db"] = impairments.ground_reflectivity_db
        if impairments.noise is not None and impairments.noise.enabled:
            options["noise"] = False  # the impairment's receiver noise replaces the simulator's
    return ImageSimulator(built.radar, built.terrain, built.origin, **options)


def _states(built, indices: np.ndarray):
    times = built.times_s[indices]
    own = built.ownship.sample(times)
    intruders = []
    for intruder in built.intruders:
        present = intruder.trajectory.covers(times)
        sample = intruder.trajectory.sample(times[present]) if present.any() else None
        intruders.append((intruder, present, sample))
    return own, intruders


def _frame_inputs(own, intruders, i: int) -> tuple[PlatformState, list[PointTarget], list[int]]:
    platform = PlatformState(own.position_ned_m[i], own.velocity_ned_mps[i], own.attitude_rad[i])
    targets, which = [], []
    for t, (intruder, present, sample) in enumerate(intruders):
        if present[i]:
            k = int(present[: i + 1].sum()) - 1
            targets.append(PointTarget(sample.position_ned_m[k], sample.velocity_ned_mps[k], intruder.rcs_m2))
            which.append(t)
    return platform, targets, which


def simulate_frames(built, indices: np.ndarray, simulator: ImageSimulator | None = None) -> np.ndarray:
    """Frames ``indices`` of the scenario as an (n, range, doppler, rx) complex64 array."""
    simulator = simulator or make_simulator(built)
    indices = np.asarray(indices)
    own, intruders = _states(built, indices)
    cfg = built.radar
    out = np.empty((indices.size, cfg.n_range, cfg.n_doppler, cfg.n_rx), np.complex64)
    impairments = getattr(built, "impairments", None)
    for i, frame_index in enumerate(indices):
        platform, targets, _ = _frame_inputs(own, intruders, i)
        simulator.frame(platform, targets, frame_index=int(frame_index), out=out[i])
        if impairments is not None:
            # Seeded per frame like the thermal noise: any chunking gives the same bytes.
            out[i] = apply_impairments(out[i], cfg, impairments, int(frame_index))
    return out


_TRUTH_FROM_GEOMETRY = {  # frames variable -> ImageSimulator.target_truth key
    "tgt_range_m": "range_m",
    "tgt_radial_velocity_mps": "radial_velocity_mps",
    "tgt_azimuth_rad": "azimuth_rad",
    "tgt_elevation_rad": "elevation_rad",
    "tgt_snr_db": "snr_db",
    "tgt_visible": "visible",
}
_XYZ = ("north", "east", "down")
_VXYZ = ("vn", "ve", "vd")


def _ownship_truth(built, own) -> dict[str, np.ndarray]:
    agl = np.full(own.time_s.size, np.nan)
    if built.terrain is not None:
        agl = own.alt_m - built.terrain.height_at(own.lat_deg, own.lon_deg)
    truth = {f"own_{a}_m": own.position_ned_m[:, c] for c, a in enumerate(_XYZ)}
    truth |= {f"own_{a}_mps": own.velocity_ned_mps[:, c] for c, a in enumerate(_VXYZ)}
    truth |= {f"own_{a}_rad": own.attitude_rad[:, c] for c, a in enumerate(("yaw", "pitch", "roll"))}
    truth |= {"own_lat_deg": own.lat_deg, "own_lon_deg": own.lon_deg, "own_alt_m": own.alt_m}
    return truth | {"own_height_agl_m": agl}


def _intruder_truth(built, own, intruders, simulator: ImageSimulator) -> dict[str, np.ndarray]:
    n, n_t = own.time_s.size, len(intruders)
    keys = [f"tgt_{a}_m" for a in _XYZ] + [f"tgt_{a}_mps" for a in _VXYZ]
    keys += ["tgt_lat_deg", "tgt_lon_deg", "tgt_alt_m", "tgt_rcs_m2", *list(_TRUTH_FROM_GEOMETRY)[:-1]]
    truth = {k: np.full((n, n_t), np.nan) for k in keys} | {"tgt_visible": np.zeros((n, n_t), bool)}
    for t, (intruder, present, sample) in enumerate(intruders):
        if sample is None:
            continue
        rows = np.nonzero(present)[0]
        for c in range(3):
            truth[f"tgt_{_XYZ[c]}_m"][rows, t] = sample.position_ned_m[:, c]
            truth[f"tgt_{_VXYZ[c]}_mps"][rows, t] = sample.velocity_ned_mps[:, c]
        truth["tgt_lat_deg"][rows, t], truth["tgt_lon_deg"][rows, t] = sample.lat_deg, sample.lon_deg
        truth["tgt_alt_m"][rows, t] = sample.alt_m
        truth["tgt_rcs_m2"][rows, t] = intruder.rcs_m2
    for i in range(n):
        platform, point_targets, which = _frame_inputs(own, intruders, i)
        if point_targets:
            geometry = simulator.target_truth(platform, point_targets)
            for key, src in _TRUTH_FROM_GEOMETRY.items():
                truth[key][i, which] = geometry[src]
    return truth


def scenario_truth(built, simulator: ImageSimulator | None = None) -> tuple[dict, dict, list[str]]:
    """Own-ship truth on time and intruder truth on (time, target), named as in ``skyradar.io.frames``."""
    simulator = simulator or make_simulator(built)
    own, intruders = _states(built, np.arange(built.times_s.size))
    targets = _intruder_truth(built, own, intruders, simulator) if intruders else {}
    return _ownship_truth(built, own), targets, [i.name for i in built.intruders]


def referenced_files(built) -> list[Path]:
    """Every file the scenario file of ``built`` refers to (trajectories, DEMs, antenna cuts).

    Read from the scenario's own fields named ``path`` or ``*_csv``, resolved as the scenario
    resolves them (relative to its folder). Empty when the scenario has no source file.
    """
    source = getattr(built, "source", None)
    if not source or not Path(source).is_file():
        return []
    from skyradar.scene.scenario import load_scenario

    scenario = load_scenario(source)
    found: list[Path] = []

    def walk(value: Any, key: str) -> None:
        if isinstance(value, dict):
            for k, v in value.items():
                walk(v, str(k))
        elif isinstance(value, list | tuple):
            for v in value:
                walk(v, key)
        elif isinstance(value, str) and (key == "path" or key.endswith("_csv")):
            found.append(scenario._path(value))

    walk(scenario.model.model_dump(), "")
    return found


def _file_digest(path: Path) -> str:
    try:
        with open(path, "rb") as f:
            return hashlib.file_digest(f, "sha256").hexdigest()  # streams: big DEMs are fine
    except OSError:
        return "unreadable"


def fingerprint(built) -> str:
    """Hash of everything that determines the frames.

    The scenario text, every file it refers to (contents), radar, times, options and the package
    version. (:class:`~skyradar.io.frames.FrameStoreWriter` adds the chunk layout and codec.)
    """
    from skyradar import __version__

    source_text = (
        built.source.read_text() if getattr(built, "source", None) and Path(built.source).exists() else ""
    )
    payload = {
        "name": built.name,
        "origin": list(built.origin),
        "radar": built.radar.to_json(),
        "times": [float(built.times_s[0]), float(built.times_s[-1]), int(built.times_s.size)],
        "options": {k: str(v) for k, v in sorted(built.sim_options.items())},
        "source": source_text,
        "files": {str(p): _file_digest(p) for p in referenced_files(built)},
        "version": __version__,
        "format": "frames/1",
    }
    return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()[:16]


def simulate(built, progress: Callable[[int], None] | None = None) -> xr.Dataset:
    """Whole scenario in memory (small runs, tests)."""
    simulator = make_simulator(built)
    n = built.times_s.size
    iq = np.empty((n, built.radar.n_range, built.radar.n_doppler, built.radar.n_rx), np.complex64)
    for i in range(n):
        iq[i] = simulate_frames(built, np.array([i]), simulator)[0]
        if progress:
            progress(1)
    ownship, targets, names = scenario_truth(built, simulator)
    return frames_dataset(iq, built.times_s, built.radar, ownship, targets, names, _attrs(built))


def _attrs(built) -> dict[str, Any]:
    return {
        "scenario": built.name,
        "origin_lat_deg": built.origin[0],
        "origin_lon_deg": built.origin[1],
        "origin_alt_m": built.origin[2],
        "sim_options": json.dumps({k: str(v) for k, v in built.sim_options.items()}),
    }


def _template(built, chunk_frames: int, simulator: ImageSimulator) -> xr.Dataset:
    import dask.array as da

    cfg = built.radar
    shape = (built.times_s.size, cfg.n_range, cfg.n_doppler, cfg.n_rx)
    iq = da.zeros(shape, dtype=np.complex64, chunks=(chunk_frames, -1, -1, -1))
    ownship, targets, names = scenario_truth(built, simulator)
    return frames_dataset(iq, built.times_s, cfg, ownship, targets, names, _attrs(built))


_WORKER_SIMULATORS: dict[str, ImageSimulator] = {}


def _chunk_job(built, key: str, path: str, chunk_frames: int, precision: str, index: int) -> int:
    # Runs on a Dask worker: one simulator per scenario per worker process (terrain set-up once).
    import numba

    numba.set_num_threads(1)  # one worker per core; threads inside would oversubscribe
    if key not in _WORKER_SIMULATORS:
        _WORKER_SIMULATORS.clear()
        _WORKER_SIMULATORS[key] = make_simulator(built)
    writer = FrameStoreWriter.attach(path, chunk_frames, built.times_s.size, precision)
    sl = writer.chunk_slice(index)
    writer.write_chunk(index, simulate_frames(built, np.arange(sl.start, sl.stop), _WORKER_SIMULATORS[key]))
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

    Before any work the output is checked (:func:`skyradar.io.outputs.check_output`) and the
    disk must hold the estimated store.
    """
    inputs = (getattr(built, "source", None), *referenced_files(built))
    check_output(path, inputs, overwrite, kind="frames store")
    # A chunk longer than the run is the whole run (--chunk-frames 10**20 must not size a 10^20 chunk).
    chunk_frames = max(1, min(int(chunk_frames), built.times_s.size))
    check_store_space(path, built.radar, built.times_s.size, chunk_frames, compressor, precision)
    client = None
    if scheduler is not None or workers:
        from skyradar.sim.cluster import close, connect, map_chunks

        client = connect(scheduler, workers)  # before any output exists: a dead address leaves nothing
    try:
        simulator = make_simulator(built)
        key = fingerprint(built)
        template = _template(built, chunk_frames, simulator)
        writer = FrameStoreWriter(path, template, chunk_frames, key, overwrite, inputs, compressor, precision)
        pending = writer.pending_chunks()
        if progress and len(pending) < writer.n_chunks:
            progress(built.times_s.size - sum(_chunk_len(writer, i) for i in pending))
        if client is None:
            for index in pending:
                sl = writer.chunk_slice(index)
                writer.write_chunk(index, simulate_frames(built, np.arange(sl.start, sl.stop), simulator))
                if progress:
                    progress(sl.stop - sl.start)
        else:
            map_chunks(
                _chunk_job,
                built,
                key,
                str(writer.partial),
                chunk_frames,
                precision,
                client=client,
                chunks=pending,
                progress=progress,
            )
    finally:
        if client is not None:
            close(client, owns_cluster=scheduler is None)
    return writer.close()
