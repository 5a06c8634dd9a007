"""Whether a processor keeps up with its radar: the latency of each frame on one processor.

A radar head delivers a frame every ``1 / frame_rate`` seconds. One processor that takes the
frames of all heads in arrival order, each as soon as it has arrived and the previous one is done,
gives each frame a latency (arrival to end of processing) that follows the single-server queue:
``finish_n = max(finish_(n-1), arrival_n) + processing_n``. A frame **keeps up** when it is done
before the same head's next frame arrives (latency at most that head's frame interval); otherwise
the processor has fallen a whole frame behind that head.

Examples
--------
>>> frames = pd.DataFrame({"radar": ["nose", "left", "nose", "left"], "time_s": [0.0, 0.05, 0.1, 0.15],
...                        "processing_s": [0.04, 0.08, 0.04, 0.04]})
>>> timed = frame_latencies(frames)
>>> timed["latency_s"].round(3).tolist(), timed["kept_up"].tolist()
([0.04, 0.08, 0.07, 0.06], [True, True, True, True])
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

__all__ = ["paced_latencies", "frame_latencies", "realtime_summary"]


def paced_latencies(arrival_s: np.ndarray, processing_s: np.ndarray) -> np.ndarray:
    """Latency of each frame (arrival to end of processing, s) on one processor taking frames in
    arrival order, each as soon as it has arrived and the previous one is done.

    Parameters
    ----------
    arrival_s, processing_s : ndarray (n,)
        Arrival times, increasing, and processing times of the frames, s.

    Returns
    -------
    latency_s : ndarray (n,)

    Examples
    --------
    >>> paced_latencies(np.array([0.0, 0.1, 0.2]), np.array([0.15, 0.05, 0.01])).round(3).tolist()
    [0.15, 0.1, 0.01]
    """
    arrival_s = np.asarray(arrival_s, float)
    finish = np.empty(len(arrival_s))
    free = -np.inf
    for i, (arrival, cost) in enumerate(zip(arrival_s, np.asarray(processing_s, float), strict=True)):
        free = max(free, arrival) + cost
        finish[i] = free
    return finish - arrival_s


def frame_latencies(frames: pd.DataFrame) -> pd.DataFrame:
    """Each frame's latency and whether it kept up, frames of all heads on one processor.

    Parameters
    ----------
    frames : DataFrame
        One row per frame: ``radar`` (head name), ``time_s`` (when the frame was recorded: its
        arrival) and ``processing_s`` (its processing time), any order.

    Returns
    -------
    DataFrame
        The rows in arrival order with ``latency_s`` and ``deadline_s`` (the head's median frame
        interval) and ``kept_up`` (``latency_s <= deadline_s``) added.

    Examples
    --------
    One head at 10 Hz: the first frame takes 0.15 s, longer than the 0.1 s until the next, which
    then waits 0.05 s:

    >>> frames = pd.DataFrame(
    ...     {"radar": "nose", "time_s": [0.2, 0.0, 0.1], "processing_s": [0.01, 0.15, 0.05]}
    ... )
    >>> timed = frame_latencies(frames)
    >>> timed["time_s"].tolist(), timed["latency_s"].round(3).tolist(), timed["kept_up"].tolist()
    ([0.0, 0.1, 0.2], [0.15, 0.1, 0.01], [False, True, True])
    """
    timed = frames.sort_values("time_s", kind="stable", ignore_index=True)
    timed["latency_s"] = paced_latencies(timed["time_s"].to_numpy(), timed["processing_s"].to_numpy())
    interval = timed.groupby("radar")["time_s"].transform(
        lambda t: np.median(np.diff(t)) if len(t) > 1 else np.inf
    )
    timed["deadline_s"] = interval
    timed["kept_up"] = timed["latency_s"] <= timed["deadline_s"]
    return timed


def realtime_summary(timed: pd.DataFrame) -> dict[str, Any]:
    """Frames, deadline misses and latency and processing percentiles (ms) of :func:`frame_latencies`.

    ``load`` is the processing time over the span of the frames' arrivals plus the last one's
    processing (the share of one processor the frames ask for; above 1 the queue only grows); its
    complement is the margin.

    Examples
    --------
    >>> timed = frame_latencies(pd.DataFrame({"radar": "nose", "time_s": [0.0, 0.1, 0.2],
    ...                                       "processing_s": [0.05, 0.05, 0.05]}))
    >>> s = realtime_summary(timed)
    >>> s["deadline_misses"], round(s["latency_p99_ms"], 1), round(s["load"], 2)
    (0, 50.0, 0.6)
    """
    latency, processing = timed["latency_s"].to_numpy(), timed["processing_s"].to_numpy()
    span = float(timed["time_s"].max() - timed["time_s"].min() + processing[-1]) if len(timed) else 0.0
    load = float(processing.sum() / span) if span > 0 else float("nan")
    q = (lambda x, p: 1e3 * float(np.quantile(x, p))) if len(timed) else (lambda x, p: float("nan"))
    return {
        "frames": int(len(timed)),
        "deadline_misses": int((~timed["kept_up"]).sum()),
        "kept_up_fraction": float(timed["kept_up"].mean()) if len(timed) else float("nan"),
        "latency_median_ms": q(latency, 0.5),
        "latency_p99_ms": q(latency, 0.99),
        "latency_max_ms": 1e3 * float(latency.max()) if len(timed) else float("nan"),
        "processing_median_ms": q(processing, 0.5),
        "processing_p99_ms": q(processing, 0.99),
        "load": load,
        "margin": 1.0 - load,
    }
