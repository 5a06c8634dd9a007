"""A whole frames run -> detections table, in this process or on Dask, and its summary.

The same rows either way: :func:`skyradar.process.pipeline.process_frames` in a loop over the
run, or :func:`skyradar.process.pipeline.process_chunk` on time chunks that each Dask worker reads
from the run itself (:func:`skyradar.parallel.map_frame_chunks`).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from pathlib import Path
from typing import Any, Literal

import pandas as pd
import xarray as xr

from skyradar.config import RadarConfig
from skyradar.io.frames import open_frames
from skyradar.io.frames_heads import store_heads
from skyradar.parallel import map_frame_chunks
from skyradar.process.pipeline import PFA_SECONDARY, process_chunk, process_frames
from skyradar.process.spurs import SpurMap

__all__ = ["detect_run", "detect_run_heads", "merge_head_tables", "detection_summary"]


def detect_run(
    run: str | Path,
    ds: xr.Dataset,
    config: RadarConfig,
    spurs: SpurMap | None = None,
    terrain: Any = None,
    method: Literal["cfar", "os-cfar", "shi-tomasi"] = "cfar",
    spur_mode: Literal["mask", "flag"] = "mask",
    pfa: float = 2e-8,
    scheduler: str | None = None,
    workers: int | None = None,
    chunk_frames: int = 64,
    progress: Callable[[int], None] | None = None,
    head: str | None = None,
    suppression: str = "none",
    frame_costs: list[tuple[int, float, float]] | None = None,
    pfa_secondary: float | None = PFA_SECONDARY,
) -> pd.DataFrame:
    """Detections table of the frames run at ``run`` (opened as ``ds``; radar ``head`` of it).

    Without ``scheduler`` and ``workers`` the frames are processed here; else in chunks of
    ``chunk_frames`` on an existing Dask scheduler or a local cluster of ``workers``. ``progress``
    is called with the number of frames done so far. ``suppression``, ``pfa_secondary`` and
    ``frame_costs`` (each frame's processing time, here only: frames timed on Dask workers would
    not time one processor): see :func:`process_frames`.
    """
    if scheduler is None and not workers:
        return process_frames(
            ds,
            spurs,
            terrain,
            method,
            spur_mode,
            progress=progress,
            source=str(run),
            config=config,
            pfa=pfa,
            suppression=suppression,
            frame_costs=frame_costs,
            pfa_secondary=pfa_secondary,
        )
    if frame_costs is not None:
        from skyradar.errors import InputError

        raise InputError("--realtime times frames on one processor: leave out --scheduler and --workers")
    done = 0

    def advance(n: int) -> None:
        nonlocal done
        done += n
        if progress:
            progress(done)

    job = functools.partial(
        process_chunk if head is None else _head_chunk,
        config=config,
        pfa=pfa,
        suppression=suppression,
        pfa_secondary=pfa_secondary,
    )
    job = job if head is None else functools.partial(job, head=head)
    parts = map_frame_chunks(
        job,
        str(run),
        ds.sizes["time"],
        max(1, chunk_frames),
        spurs,
        terrain,
        method,
        spur_mode,
        scheduler=scheduler,
        workers=workers,
        progress=advance,
    )
    return pd.concat(parts, ignore_index=True)


def _head_chunk(
    path: str,
    start: int,
    stop: int,
    spur_map: SpurMap | None,
    terrain: Any,
    method: Literal["cfar", "os-cfar", "shi-tomasi"],
    spur_mode: Literal["mask", "flag"],
    *,
    head: str,
    **kwargs: Any,
) -> pd.DataFrame:
    # process_chunk for one head of a multi-head run (a Dask worker opens the run itself).
    return process_frames(
        open_frames(path, head),
        spur_map,
        terrain,
        method,
        spur_mode,
        source=path,
        frames=slice(start, stop),
        **kwargs,
    )


def merge_head_tables(tables: dict[str, pd.DataFrame]) -> pd.DataFrame:
    """One detections table from each head's: a ``radar`` column (head name), rows in time order.

    Within a frame the heads keep their order, and their rows their own order.

    Examples
    --------
    >>> a = pd.DataFrame({"time_s": [0.0, 0.1], "frame": [0, 1]})
    >>> b = pd.DataFrame({"time_s": [0.0], "frame": [0]})
    >>> merge_head_tables({"nose": a, "left": b})[["frame", "radar"]].values.tolist()
    [[0, 'nose'], [0, 'left'], [1, 'nose']]
    """
    parts = [
        t.assign(radar=pd.Series([name] * len(t), index=t.index, dtype=object)) for name, t in tables.items()
    ]
    merged = pd.concat(parts, ignore_index=True)
    return merged.sort_values("time_s", kind="stable", ignore_index=True)


def detect_run_heads(
    run: str | Path,
    config: RadarConfig | None = None,
    progress: Callable[[int], None] | None = None,
    frame_costs: dict[str, list[tuple[int, float, float]]] | None = None,
    **kwargs: Any,
) -> tuple[pd.DataFrame, dict[str, RadarConfig]]:
    """Detections of every radar head of the run at ``run``, merged (:func:`merge_head_tables`).

    ``kwargs`` are :func:`detect_run`'s (spurs, terrain, method, ...). ``config`` replaces the
    stored RadarConfig of a single-head run (a multi-head run refuses it: which head would it be?).
    Returns the table and each head's RadarConfig. ``progress`` gets frames done over all heads.
    ``frame_costs`` (a dict, filled here) receives each head's :func:`process_frames` frame costs.
    """
    from skyradar.errors import InputError
    from skyradar.io.frames import radar_config_of

    names = store_heads(run)
    if names is not None and config is not None:
        raise InputError(
            f"--radar-config: {run} has {len(names)} radar heads {names}; each keeps its stored config"
        )
    tables, configs, done = {}, {}, 0
    for name in names or ["radar"]:
        ds = open_frames(run, None if names is None else name)
        cfg = config if config is not None else radar_config_of(ds, str(run))
        costs = None if frame_costs is None else frame_costs.setdefault(name, [])
        tables[name] = detect_run(
            run,
            ds,
            cfg,
            progress=functools.partial(_shifted, progress, done) if progress else None,
            head=None if names is None else name,
            frame_costs=costs,
            **kwargs,
        )
        configs[name], done = cfg, done + ds.sizes["time"]
    return merge_head_tables(tables), configs


def _shifted(progress: Callable[[int], None], offset: int, n: int) -> None:
    progress(offset + n)


def detection_summary(table: pd.DataFrame, n_frames: int) -> dict[str, Any]:
    """Frames, detections, detections per frame, ground, spur and secondary detections of a
    detections table (``secondary``: rows of the lower threshold in nulled cells, 0 without the column).

    Examples
    --------
    >>> detection_summary(pd.DataFrame({"is_ground": [True, False], "spur": [False, False]}), 4)
    {'frames': 4, 'detections': 2, 'detections_per_frame': 0.5, 'ground': 1, 'spur': 0, 'secondary': 0}
    """
    secondary = int(table["secondary"].sum()) if "secondary" in table.columns else 0
    return {
        "frames": n_frames,
        "detections": len(table),
        "detections_per_frame": len(table) / n_frames,
        "ground": int(table["is_ground"].sum()),
        "spur": int(table["spur"].sum()),
        "secondary": secondary,
    }
