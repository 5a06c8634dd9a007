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
from skyradar.parallel import map_frame_chunks
from skyradar.process.pipeline import process_chunk, process_frames
from skyradar.process.spurs import SpurMap

__all__ = ["detect_run", "detection_summary"]


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
) -> pd.DataFrame:
    """Detections table of the frames run at ``run`` (opened as ``ds``).

    Without ``scheduler`` and ``workers`` the frames are processed here; else in chunks of
    ``chunk_frames`` on an existing Dask scheduler or a local cluster of ``workers``. ``progress``
    is called with the number of frames done so far.
    """
    if scheduler is None and not workers:
        return process_frames(
            ds, spurs, terrain, method, spur_mode, progress=progress, source=str(run), config=config, pfa=pfa
        )
    done = 0

    def advance(n: int) -> None:
        nonlocal done
        done += n
        if progress:
            progress(done)

    job = functools.partial(process_chunk, config=config, pfa=pfa)
    parts = map_frame_chunks(
        job, str(run), ds.sizes["time"], max(1, chunk_frames), spurs, terrain, method, spur_mode,
        scheduler=scheduler, workers=workers, progress=advance,
    )  # fmt: skip
    return pd.concat(parts, ignore_index=True)


def detection_summary(table: pd.DataFrame, n_frames: int) -> dict[str, Any]:
    """Frames, detections, detections per frame, ground and spur detections of a detections table.

    Examples
    --------
    >>> detection_summary(pd.DataFrame({"is_ground": [True, False], "spur": [False, False]}), 4)
    {'frames': 4, 'detections': 2, 'detections_per_frame': 0.5, 'ground': 1, 'spur': 0}
    """
    return {
        "frames": n_frames,
        "detections": len(table),
        "detections_per_frame": len(table) / n_frames,
        "ground": int(table["is_ground"].sum()),
        "spur": int(table["spur"].sum()),
    }
