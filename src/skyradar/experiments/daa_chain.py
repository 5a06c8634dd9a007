"""The whole DAA chain on one built scenario: simulate -> process -> track -> alert.

Used by ``skyradar demo`` and ``skyradar experiment encounters``. Frames are simulated and
processed in blocks of ``block_frames`` so that memory stays bounded (a minute of frames is
~750 MB); only the detections, tracks and alerts tables are kept, plus any frames asked for.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from skyradar.daa.alerting import AlertConfig
from skyradar.daa.pipeline import alerts_from_tracks
from skyradar.daa.run_tables import ownship_from_frames
from skyradar.io.frames import frames_dataset
from skyradar.io.frames_model import frame_times_s
from skyradar.process.pipeline import process_frames
from skyradar.sim.scenario_frames import make_simulator, scenario_truth, simulate_frames
from skyradar.track.track_table import track_detections

__all__ = ["run_chain", "label_tracks"]

_MATCH_M = 300.0  # a track is an intruder's if its median distance to that truth is below this


def _truth_dataset(built, simulator) -> xr.Dataset:
    """Frames Dataset of the whole run with a zero-stride placeholder ``iq`` (no memory)."""
    own, tgt, names = scenario_truth(built, simulator)
    cfg = built.radar
    shape = (built.times_s.size, cfg.n_range, cfg.n_doppler, cfg.n_rx)
    attrs = {"scenario": built.name, "origin_lat_deg": built.origin[0], "origin_lon_deg": built.origin[1],
             "origin_alt_m": built.origin[2], "start_time": getattr(built, "start_time", None)}  # fmt: skip
    iq = np.broadcast_to(np.zeros((), np.complex64), shape)
    return frames_dataset(iq, built.times_s, cfg, own, tgt, names, attrs)


def _detect(built, keep_frames, block_frames, timings) -> tuple[pd.DataFrame, xr.Dataset, dict]:
    simulator = make_simulator(built)
    truth = _truth_dataset(built, simulator)
    n = built.times_s.size
    detections, rd = [], {}
    for start in range(0, n, block_frames):
        rows = np.arange(start, min(start + block_frames, n))
        t0 = time.perf_counter()
        iq = simulate_frames(built, rows, simulator)
        timings["simulate"] += time.perf_counter() - t0
        for f in set(keep_frames).intersection(rows.tolist()):
            rd[f] = iq[f - start].copy()
        ds = truth.isel(time=slice(start, start + rows.size)).assign(iq=(truth["iq"].dims, iq))
        t0 = time.perf_counter()
        det = process_frames(ds, terrain=built.terrain, source=built.name)
        det["frame"] += start
        detections.append(det)
        timings["process"] += time.perf_counter() - t0
    return pd.concat(detections, ignore_index=True), truth.drop_vars("iq"), rd


def run_chain(
    built,
    alert_config: AlertConfig | None = None,
    keep_frames: tuple[int, ...] = (),
    block_frames: int = 16,
    with_advice: bool = True,
) -> dict[str, Any]:
    """Simulate, process, track and alert a built scenario; return every intermediate product.

    Parameters
    ----------
    built : BuiltScenario
        From :meth:`skyradar.scene.scenario.Scenario.build`.
    alert_config : AlertConfig, optional
        Volumes, times and gates of the alerting stage (default :class:`AlertConfig`).
    keep_frames : tuple of int
        Frame numbers whose range-Doppler cube is returned in ``rd_frames``.
    block_frames : int
        Frames simulated and processed at a time (memory bound).
    with_advice : bool
        Compute resolution advice on alerting frames (off for scoring runs: faster).

    Returns
    -------
    dict
        ``truth`` (frames Dataset without ``iq``), ``detections``, ``tracks``, ``alerts``,
        ``ownship`` (tables), ``rd_frames`` ({frame: (n_range, n_doppler, n_rx) complex64}) and
        ``timings_s`` per stage.
    """
    timings = {"simulate": 0.0, "process": 0.0}
    det, truth, rd = _detect(built, keep_frames, block_frames, timings)
    own = ownship_from_frames(truth, built.name)
    t0 = time.perf_counter()
    keep = ~(det["is_ground"].to_numpy(bool) | det["spur"].to_numpy(bool))
    tracks = track_detections(
        det[keep].reset_index(drop=True), "radar", built.radar,
        frame_times_s=built.times_s, origin=built.origin, ownship=own,
    )  # fmt: skip
    timings["track"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    alerts = alerts_from_tracks(tracks, own, alert_config, with_advice=with_advice, source=built.name)
    timings["alert"] = time.perf_counter() - t0
    return {"truth": truth, "detections": det, "tracks": tracks, "alerts": alerts, "ownship": own,
            "rd_frames": rd, "timings_s": timings}  # fmt: skip


def label_tracks(tracks: pd.DataFrame, truth: xr.Dataset, max_distance_m: float = _MATCH_M) -> dict[int, str]:
    """Name of the intruder each track follows (median 3-D distance to its truth), else ``'clutter'``.

    Examples
    --------
    >>> t = xr.Dataset({"tgt_north_m": (("time", "target"), [[0.0]]), "tgt_east_m": (("time", "target"),
    ...     [[0.0]]), "tgt_down_m": (("time", "target"), [[0.0]])}, coords={"time": [0.0], "target": ["a"]})
    >>> tr = pd.DataFrame({"time_s": [0.0, 0.0], "track_id": [1, 2], "north_m": [10.0, 900.0],
    ...     "east_m": [0.0, 0.0], "down_m": [0.0, 0.0]})
    >>> label_tracks(tr, t)
    {1: 'a', 2: 'clutter'}
    """
    times = frame_times_s(truth)
    names = [str(x) for x in truth["target"].values]
    truth_pos = np.stack([truth[f"tgt_{a}_m"].values for a in ("north", "east", "down")], -1)
    labels = {}
    for tid, g in tracks.groupby("track_id"):
        idx = np.clip(np.searchsorted(times, g["time_s"].to_numpy(float)), 0, times.size - 1)
        err = g[["north_m", "east_m", "down_m"]].to_numpy(float)[:, None, :] - truth_pos[idx]
        with np.errstate(all="ignore"):
            dist = np.linalg.norm(err, axis=-1)
            med = np.array([np.nanmedian(d) if np.isfinite(d).any() else np.inf for d in dist.T])
        best = int(np.argmin(med)) if med.size else -1
        labels[int(tid)] = names[best] if best >= 0 and med[best] < max_distance_m else "clutter"
    return labels
