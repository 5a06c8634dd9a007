"""Every frame time of a run, so that the tracker advances on frames without any detection.

A detections table has rows only where something was detected: in a clear sky most frames have
none. A tracker stepped only at the detections' times never counts those frames as misses and has
no row for its coasting tracks there, so a track seemed to vanish over every gap of an aircraft's
detections (``skyradar evaluate`` then scored those frames as not tracked). The frame grid is
taken from the run's own frame times when they are at hand, else rebuilt from the ``frame`` column
that ``skyradar process`` writes (frame index per detection): frame indices missing between two
known ones get their time by linear interpolation in the index, which is exact for a constant
frame rate.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

__all__ = ["frame_grid", "frame_numbers"]


def frame_grid(detections: pd.DataFrame, run_times_s: np.ndarray | None = None) -> np.ndarray:
    """Sorted frame times over which to step the tracker.

    Parameters
    ----------
    detections : DataFrame
        ``time_s`` (not decreasing) and optionally ``frame`` (the frame index within the run).
    run_times_s : ndarray, optional
        Every frame time of the run the detections came from (e.g. ``--ownship RUN.zarr``). Used
        only when every detection time is one of them (a table from another run falls back).

    Returns
    -------
    ndarray
        The run's times from the first detection on; else every frame index from the first to the
        last detection with its time; else (no usable ``frame`` column) the detections' own times.

    Examples
    --------
    >>> det = pd.DataFrame({"time_s": [0.0, 0.0, 0.3, 0.5], "frame": [0, 0, 3, 5]})
    >>> frame_grid(det).tolist()
    [0.0, 0.1, 0.2, 0.3, 0.4, 0.5]
    >>> frame_grid(det, np.arange(8) / 10).tolist()
    [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7]
    """
    t = detections["time_s"].to_numpy(float)
    own = np.unique(t)
    if own.size == 0:
        return own
    if run_times_s is not None:
        run = np.unique(np.asarray(run_times_s, float))
        k = np.clip(np.searchsorted(run, own), 0, max(run.size - 1, 0))
        if run.size and np.allclose(run[k], own, rtol=0.0, atol=1e-6):
            return run[run >= own[0] - 1e-6]
    if "frame" not in detections.columns:
        return own
    frame = pd.to_numeric(detections["frame"], errors="coerce").to_numpy(float)
    if not np.all(np.isfinite(frame)) or np.any(frame != np.round(frame)):
        return own
    idx, first = np.unique(frame.astype(np.int64), return_index=True)
    times = t[first]
    # One time per frame index, increasing with it; else the column is not a frame index we can use
    # (e.g. tables of several runs put together) and the detections' times are the grid.
    consistent = np.array_equal(np.unique(np.column_stack([frame, t]), axis=0)[:, 0], idx)
    if not consistent or np.any(np.diff(times) <= 0):
        return own
    grid = np.interp(np.arange(idx[0], idx[-1] + 1), idx, times)
    return np.union1d(grid, own)


def frame_numbers(grid_s: np.ndarray, detections: pd.DataFrame) -> np.ndarray:
    """Frame index of each grid time: the ``frame`` column where the grid has detections, else
    counted from the nearest known frame at the median frame interval (the grid index without
    a ``frame`` column).

    Examples
    --------
    >>> det = pd.DataFrame({"time_s": [0.2, 0.5], "frame": [12, 15]})
    >>> frame_numbers(np.arange(1, 9) / 10, det).tolist()
    [11, 12, 13, 14, 15, 16, 17, 18]
    """
    grid = np.asarray(grid_s, float)
    if "frame" not in detections.columns or len(detections) == 0 or grid.size == 0:
        return np.arange(grid.size, dtype=np.int64)
    t, frame = np.unique(
        np.column_stack([detections["time_s"].to_numpy(float), detections["frame"].to_numpy(float)]), axis=0
    ).T
    step = float(np.median(np.diff(grid))) if grid.size > 1 else 1.0
    k = np.clip(np.searchsorted(t, grid), 1, max(t.size - 1, 1)) if t.size > 1 else np.zeros(grid.size, int)
    if t.size > 1:  # nearest known frame on either side
        k = np.where(np.abs(grid - t[k - 1]) <= np.abs(t[k] - grid), k - 1, k)
    return np.round(frame[k] + (grid - t[k]) / step).astype(np.int64)
