"""The whole DAA chain on one built scenario: simulate -> process -> track -> alert.

The Python entry point of the chain (``skyradar demo`` and ``skyradar experiment encounters`` run
it too)::

    from skyradar.chain import run_chain
    from skyradar.daa.alerting import RADAR_ALERT_CONFIG
    from skyradar.scene.scenario import load_scenario

    built = load_scenario("my_scenario.yaml").build()
    out = run_chain(built, RADAR_ALERT_CONFIG)
    out["alerts"].query("level == 3")  # the warnings: time, track, range, bearing, advice

 Frames are simulated and
processed in blocks of ``block_frames`` so that memory stays bounded (a minute of frames is
~750 MB); only the detections, tracks and alerts tables are kept, plus any frames asked for.

Every radar head of the scenario (``built.heads``) is simulated and processed; the detections
table names the head in its ``radar`` column and one tracker fuses the heads in the world frame
(:mod:`skyradar.track.fusion`). :func:`track_and_alert` re-tracks a detections table with only
some heads, so one simulation scores a single head and several side by side.
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
from skyradar.errors import InputError
from skyradar.io.frames import frames_dataset
from skyradar.io.frames_model import frame_times_s
from skyradar.process.detect_run import merge_head_tables
from skyradar.process.pipeline import clutter_anchors, process_frames
from skyradar.scene.radar_heads import select_heads
from skyradar.sim.scenario_frames import make_simulator, scenario_truth, simulate_frames
from skyradar.track.fusion import restore_detection_rows
from skyradar.track.ground_tracks import default_ground_test, median_ground_down_m, terrain_surface
from skyradar.track.track_table import track_detections, tracker_detections
from skyradar.units import wrap

__all__ = [
    "run_chain",
    "track_and_alert",
    "label_tracks",
    "confirmed_rows",
    "run_attrs",
    "tracked_heads",
    "scenario_surface",
]

_MATCH_M = 300.0  # a track is an intruder's if its median distance to that truth is below this
# ... or if its range and range rate follow that truth's, medians within these (m, m/s)
_MATCH_RANGE_M, _MATCH_RATE_MPS = 50.0, 2.0


def _truth_dataset(built, simulator) -> xr.Dataset:
    """Frames Dataset of the whole run with a zero-stride placeholder ``iq`` (no memory)."""
    own, tgt, names = scenario_truth(built, simulator)
    cfg = simulator.config
    shape = (built.times_s.size, *cfg.frame_shape)
    iq = np.broadcast_to(np.zeros((), np.complex64), shape)
    return frames_dataset(iq, built.times_s, cfg, own, tgt, names, run_attrs(built))


def run_attrs(built) -> dict[str, Any]:
    """The attributes the chain's frames Datasets carry: scenario name, origin, start time.

    Parameters
    ----------
    built : BuiltScenario
        From :meth:`skyradar.scene.scenario.Scenario.build` (its ``name``, ``origin`` as (lat deg,
        lon deg, alt m) and ``start_time``, when it has one).

    Returns
    -------
    dict
        ``scenario``, ``origin_lat_deg``, ``origin_lon_deg``, ``origin_alt_m`` (m) and ``start_time``
        (None when the scenario has none).

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> run_attrs(SimpleNamespace(name="head-on", origin=(52.0, 4.0, 10.0)))
    {'scenario': 'head-on', 'origin_lat_deg': 52.0, 'origin_lon_deg': 4.0, 'origin_alt_m': 10.0,
     'start_time': None}
    """
    return {
        "scenario": built.name,
        "origin_lat_deg": built.origin[0],
        "origin_lon_deg": built.origin[1],
        "origin_alt_m": built.origin[2],
        "start_time": getattr(built, "start_time", None),
    }


def tracked_heads(built, heads: list[str] | None, caller: str) -> list:
    """The heads ``heads`` of ``built`` (all by default) that one tracker follows; InputError naming
    ``caller`` when they differ in Doppler width or range resolution (one tracker's pixel grid).

    Parameters
    ----------
    built : BuiltScenario
        From :meth:`skyradar.scene.scenario.Scenario.build` (only ``built.heads`` is read).
    heads : list of str or None
        Names of the heads to track; None: all.
    caller : str
        Name of the calling command or function in error messages.

    Returns
    -------
    list of RadarHead
        The chosen heads, in the scenario's order.

    Examples
    --------
    A head with half the bandwidth has twice the range bin (m), so no tracker follows it with the
    others:

    >>> import dataclasses
    >>> from types import SimpleNamespace
    >>> from skyradar.config import RadarConfig
    >>> from skyradar.scene.radar_heads import RadarHead
    >>> c = RadarConfig()
    >>> coarse = dataclasses.replace(c, bandwidth_hz=c.bandwidth_hz / 2)
    >>> built = SimpleNamespace(heads=[RadarHead("nose", c), RadarHead("left", c), RadarHead("tail", coarse)])
    >>> [h.name for h in tracked_heads(built, ["nose", "left"], "track")]
    ['nose', 'left']
    >>> tracked_heads(built, None, "track")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: track: heads ['nose', 'left', 'tail'] differ in Doppler width or range ...
    """
    chosen = select_heads(built.heads, heads, caller)
    if len({(h.config.v_lim_mps, h.config.range_resolution_m) for h in chosen}) > 1:
        names = [h.name for h in chosen]
        raise InputError(
            f"{caller}: heads {names} differ in Doppler width or range resolution; "
            "one tracker needs the same for all"
        )
    return chosen


def _detect(built, heads, keep_frames, block_frames, timings, options) -> tuple[pd.DataFrame, dict, dict]:
    """Detections of every head in ``heads`` (merged, ``radar`` column), each head's truth, kept frames."""
    simulators = {h.name: make_simulator(built, h.name) for h in heads}
    truths = {name: _truth_dataset(built, sim) for name, sim in simulators.items()}
    # Each block is suppressed with the whole run's clutter predictions (as `skyradar process` would).
    anchors = {name: clutter_anchors(t, built.terrain, built.name) for name, t in truths.items()}
    n = built.times_s.size
    detections: dict[str, list] = {name: [] for name in simulators}
    rd: dict = {}
    for start in range(0, n, block_frames):
        rows = np.arange(start, min(start + block_frames, n))
        for name, simulator in simulators.items():
            t0 = time.process_time()
            iq = simulate_frames(built, rows, simulator)
            timings["simulate"] += time.process_time() - t0
            for f in set(keep_frames).intersection(rows.tolist()) if name == heads[0].name else ():
                rd[f] = iq[f - start].copy()  # the first head's range-Doppler cube
            truth = truths[name]
            ds = truth.isel(time=slice(start, start + rows.size)).assign(iq=(truth["iq"].dims, iq))
            t0 = time.process_time()
            run_anchors = anchors[name]
            block = None if run_anchors is None else run_anchors[start : start + rows.size]
            det = process_frames(ds, terrain=built.terrain, source=built.name, anchors=block, **options)
            det["frame"] += start
            detections[name].append(det)
            timings["process"] += time.process_time() - t0
    merged = merge_head_tables({name: pd.concat(d, ignore_index=True) for name, d in detections.items()})
    return merged, {name: t.drop_vars("iq") for name, t in truths.items()}, rd


def run_chain(
    built,
    alert_config: AlertConfig | None = None,
    keep_frames: tuple[int, ...] = (),
    block_frames: int = 16,
    with_advice: bool = True,
    heads: list[str] | None = None,
    process_options: dict[str, Any] | None = None,
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
    heads : list of str, optional
        Radar heads to simulate and fuse (names in ``built.heads``); default all.
    process_options : dict, optional
        Keyword arguments of :func:`skyradar.process.pipeline.process_frames` (e.g. ``pfa``).

    Returns
    -------
    dict
        ``truth`` (the first head's frames Dataset without ``iq``), ``truth_by_head`` ({head:
        Dataset}: intruder angles, SNR and visibility as each head sees them), ``detections`` (with
        the ``radar`` column), ``tracks``, ``alerts``, ``ownship`` (tables), ``rd_frames`` ({frame:
        (n_range, n_doppler, n_rx) complex64} of the first head) and ``timings_s``: the CPU
        seconds of each stage (:func:`time.process_time`, which other jobs sharing the machine do
        not inflate).
    """
    chosen = select_heads(built.heads, heads, "run_chain")
    timings = {"simulate": 0.0, "process": 0.0}
    det, truths, rd = _detect(built, chosen, keep_frames, block_frames, timings, process_options or {})
    truth = truths[chosen[0].name]
    out = track_and_alert(det, built, None, alert_config, with_advice, truth)
    return {
        "truth": truth,
        "truth_by_head": truths,
        "detections": det,
        "tracks": out["tracks"],
        "alerts": out["alerts"],
        "ownship": out["ownship"],
        "rd_frames": rd,
        "timings_s": timings | out["timings_s"],
    }


def track_and_alert(
    detections: pd.DataFrame,
    built,
    heads: list[str] | None = None,
    alert_config: AlertConfig | None = None,
    with_advice: bool = True,
    truth: xr.Dataset | None = None,
) -> dict[str, Any]:
    """Track (all heads fused) and alert a detections table of ``built``, with only ``heads`` of it.

    ``truth`` is a frames Dataset of the run (own-ship variables; default: computed again). The
    chosen heads' detections are tracked as :func:`~skyradar.track.track_table.tracker_detections`
    gives them (spurs out, ground-flagged rows only inside a confirmed track's gate, without their
    direction); ``detection_row`` of the tracks indexes the returned ``detections`` (the chosen
    heads' rows). Returns ``tracks``, ``alerts``, ``ownship``, ``detections`` and ``timings_s``
    (CPU seconds of track and alert, :func:`time.process_time`).
    """
    chosen = tracked_heads(built, heads, "track_and_alert")
    truth = truth if truth is not None else _truth_dataset(built, make_simulator(built)).drop_vars("iq")
    own = ownship_from_frames(truth, built.name)
    mine = np.ones(len(detections), bool)
    if heads is not None and "radar" in detections.columns:
        mine = detections["radar"].isin([h.name for h in chosen]).to_numpy(bool)
    air, used = tracker_detections(detections[mine])
    t0 = time.process_time()
    tracks = track_detections(
        air,
        "radar",
        chosen[0].config,
        frame_times_s=built.times_s,
        origin=built.origin,
        ownship=own,
        ground_test=default_ground_test(chosen[0].config, scenario_surface(built, own)),
    )
    tracks = restore_detection_rows(tracks, used)  # detection_row indexes the chosen heads' rows
    timings = {"track": time.process_time() - t0}
    t0 = time.process_time()
    alerts = alerts_from_tracks(tracks, own, alert_config, with_advice=with_advice, source=built.name)
    timings["alert"] = time.process_time() - t0
    mine_table = detections[mine].reset_index(drop=True)
    out = {"tracks": tracks, "alerts": alerts, "ownship": own, "detections": mine_table}
    return out | {"timings_s": timings}


def scenario_surface(built, own: pd.DataFrame):
    """The scenario's ground for the track-level ground test (None: the own-ship's height above ground).

    Parameters
    ----------
    built : BuiltScenario
        From :meth:`skyradar.scene.scenario.Scenario.build` (its ``terrain`` DEM and ``origin`` as
        (lat deg, lon deg, alt m)).
    own : DataFrame
        The own-ship table (``own_down_m`` and ``own_height_agl_m``, m): its median ground under the
        own-ship is the level ground beyond the DEM.

    Returns
    -------
    callable or None
        NE points (k, 2) in m -> ``down`` of the ground, m (:func:`terrain_surface`); None without a
        DEM.

    Examples
    --------
    A DEM 200 m high up to 52.01 deg north under an origin at 1000 m; beyond it the ground under the
    own-ship (``-500 + 1400`` m down):

    >>> from types import SimpleNamespace
    >>> class Dem:
    ...     def height_at(self, lat, lon):
    ...         return np.where(np.asarray(lat) < 52.01, 200.0, np.nan)
    >>> own = pd.DataFrame({"own_down_m": [-500.0], "own_height_agl_m": [1400.0]})
    >>> surface = scenario_surface(SimpleNamespace(terrain=Dem(), origin=(52.0, 4.0, 1000.0)), own)
    >>> surface(np.array([[0.0, 0.0], [5000.0, 0.0]])).tolist()
    [800.0, 900.0]
    >>> scenario_surface(SimpleNamespace(terrain=None), own) is None
    True
    """
    if built.terrain is None or not hasattr(built.terrain, "height_at"):
        return None
    return terrain_surface(built.terrain, built.origin, median_ground_down_m(own))


def label_tracks(tracks: pd.DataFrame, truth: xr.Dataset, max_distance_m: float = _MATCH_M) -> dict[int, str]:
    """Name of the intruder each track follows (median 3-D distance to its truth), else ``'clutter'``.

    Only a track's confirmed rows count when it has any: alerts come from those, and the rows
    before them are the initiator's guesses, or a lost track's whose id the track reacquired (over
    hills a ground track's 21 s of hops took an intruder's track to 'clutter', and its warning on
    the intruder to a ground track's: :func:`confirmed_rows`).

    On rows whose height is the co-altitude prior (``altitude_measured`` False) the distance is
    taken in what the radar measured, slant range and bearing from the own-ship (``own_*`` in
    ``truth``): such a track is its intruder's even when it flies 300 m above. A track whose
    bearings are off too (directions through clutter nulls over relief scatter by tens of degrees)
    is still its intruder's when its range and range rate follow the intruder's truth
    (``tgt_range_m``, ``tgt_radial_velocity_mps``; medians within 50 m and 2 m/s): those are measured
    to a pixel whatever the directions do, and a ground point's range rate parts from an
    aircraft's within seconds, so a track that follows both over its life is that aircraft.

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
    own = None
    if all(f"own_{a}_m" in truth for a in ("north", "east", "down")):
        own = np.stack([truth[f"own_{a}_m"].values for a in ("north", "east", "down")], -1)
    labels = {}
    for tid, g in confirmed_rows(tracks).groupby("track_id"):
        idx = np.clip(np.searchsorted(times, g["time_s"].to_numpy(float)), 0, times.size - 1)
        pos = g[["north_m", "east_m", "down_m"]].to_numpy(float)
        with np.errstate(all="ignore"):
            dist = np.linalg.norm(pos[:, None, :] - truth_pos[idx], axis=-1)
            if own is not None and "altitude_measured" in g:
                prior = ~g["altitude_measured"].to_numpy(bool)
                dist[prior] = _range_bearing_distance_m(pos[prior], truth_pos[idx[prior]], own[idx[prior]])
            med = _median_per_target(dist)
        best = int(np.argmin(med)) if med.size else -1
        if not (best >= 0 and med[best] < max_distance_m):
            best = _range_rate_match(g, truth, idx)
        labels[int(tid)] = names[best] if best >= 0 else "clutter"
    return labels


def _range_rate_match(rows: pd.DataFrame, truth: xr.Dataset, idx: np.ndarray) -> int:
    """The target whose range and range rate a track's ``rows`` (at truth frames ``idx``) follow,
    medians within ``_MATCH_RANGE_M`` and ``_MATCH_RATE_MPS``; -1: none (or no such columns)."""
    columns = ("range_m", "range_rate_mps")
    if not set(columns) <= set(rows) or not {"tgt_range_m", "tgt_radial_velocity_mps"} <= set(truth):
        return -1
    with np.errstate(all="ignore"):
        d_range = np.abs(rows["range_m"].to_numpy(float)[:, None] - truth["tgt_range_m"].values[idx])
        d_rate = np.abs(
            rows["range_rate_mps"].to_numpy(float)[:, None] - truth["tgt_radial_velocity_mps"].values[idx]
        )
        med_range, med_rate = _median_per_target(d_range), _median_per_target(d_rate)
    follows = (med_range < _MATCH_RANGE_M) & (med_rate < _MATCH_RATE_MPS)
    return int(np.argmin(np.where(follows, med_range, np.inf))) if follows.any() else -1


def _median_per_target(distance: np.ndarray) -> np.ndarray:
    """Median over a track's rows of each target's column of ``distance`` (rows, targets), NaN rows
    left out; infinite for a target with no finite row."""
    with np.errstate(all="ignore"):
        return np.array([np.nanmedian(d) if np.isfinite(d).any() else np.inf for d in distance.T])


def confirmed_rows(tracks: pd.DataFrame) -> pd.DataFrame:
    """The confirmed rows of each track in a tracks table; all rows of a track that has none.

    Examples
    --------
    >>> tr = pd.DataFrame({"track_id": [1, 1, 1, 2], "confirmed": [False, True, True, False]})
    >>> confirmed_rows(tr).index.tolist()
    [1, 2, 3]
    """
    if "confirmed" not in tracks or tracks.empty:
        return tracks
    confirmed = tracks["confirmed"].to_numpy(bool)
    has = pd.Series(confirmed).groupby(tracks["track_id"].to_numpy()).transform("any").to_numpy(bool)
    return tracks[confirmed | ~has]


def _range_bearing_distance_m(
    track_pos: np.ndarray, truth_pos: np.ndarray, own_pos: np.ndarray
) -> np.ndarray:
    """Distance (m) in slant range and horizontal bearing from the own-ship: (k, 3) against (k, n, 3)."""
    rel_track, rel_truth = track_pos - own_pos, truth_pos - own_pos[:, None, :]
    d_range = np.linalg.norm(rel_track, axis=-1)[:, None] - np.linalg.norm(rel_truth, axis=-1)
    bearing = np.arctan2(rel_track[:, 1], rel_track[:, 0])[:, None] - np.arctan2(
        rel_truth[..., 1], rel_truth[..., 0]
    )
    across = np.linalg.norm(rel_truth[..., :2], axis=-1) * wrap(bearing, 2.0 * np.pi)
    return np.hypot(d_range, across)
