"""The DAA chain one radar frame at a time: simulate, process, track and alert each frame as it comes.

:class:`StreamingChain` advances every stage of :func:`skyradar.chain.run_chain` by one frame per
:meth:`~StreamingChain.step`: it simulates the next frame of every radar head, processes it, steps
the trackers and alerts that frame. Fed with the same scenario it gives the batch chain's
detections, confirmed tracks and alerts (:meth:`~StreamingChain.tables`); each stage runs the
library's own per-frame code:

- simulation: :func:`skyradar.sim.scenario_frames.simulate_frames` and
  :func:`~skyradar.sim.scenario_frames.frames_truth` of one frame, the navigation solution of the
  frame from the own-ship truth so far (:func:`skyradar.sim.navigation.navigation_at_frame`);
- processing: :func:`skyradar.process.pipeline.process_frames` on a one-frame Dataset, the clutter
  prediction's anchor from the walk of :class:`skyradar.process.clutter_anchors.AnchorWalk`;
- tracking: :class:`skyradar.track.track_table.TrackTableStream` (the batch tracker loop's body);
- alerting and advice: :class:`skyradar.daa.pipeline.AlertStream`.

The closed-loop seam is :meth:`StreamingChain.ownship_state`: the own-ship's state at a frame,
asked for just before the frame is simulated. By default it samples the scenario's own-ship
trajectory; a subclass that overrides it (a pilot model flying the advice of the frames before)
changes what every later stage sees, since the truth, the navigation solution, the frame and its
processing all follow from it.

What a stream cannot know, and so where its tables differ from the batch chain's (the tracks'
rows, :class:`~skyradar.track.track_table.TrackTableStream`, says more):

- the tracks table holds no tentative rows of a track before its confirmation (the batch keeps
  those of tracks confirmed later); its confirmed rows, and the alerts made from them, are the
  batch's;
- the ground hold judges a long track's newest detection on every frame (the batch judges the
  last detection of the run out of turn);
- beyond the DEM the ground test's level ground is the median ground under the own-ship so far
  (the batch's: over the whole run); with several heads, frames are fused as a multi-head run
  from the first.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from skyradar.chain import run_attrs, scenario_surface, tracked_heads
from skyradar.daa.alerting import AlertConfig
from skyradar.daa.pipeline import AlertStream
from skyradar.daa.run_tables import ownship_from_frames
from skyradar.io.frames import frames_dataset
from skyradar.io.ownship_states import OwnShipStates
from skyradar.io.tables import appended
from skyradar.process.clutter_anchors import AnchorWalk, frame_geometries
from skyradar.process.detect_run import merge_head_tables
from skyradar.process.pipeline import navigated_own_state, process_frames
from skyradar.scene.trajectories import TrajectorySample
from skyradar.sim.navigation import navigation_at_frame
from skyradar.sim.scenario_frames import frames_truth, make_simulator, simulate_frames
from skyradar.track.fusion import restore_detection_rows
from skyradar.track.ground_tracks import default_ground_test
from skyradar.track.track_table import TrackTableStream, empty_tracks, tracker_detections

__all__ = ["Advice", "FrameResult", "StreamingChain", "frame_advice"]

_SMOOTH_FRAMES = 5  # frame_geometries' velocity mean: this frame and the 4 before it
_ADVICE = (
    "heading_bands_deg",
    "vs_bands_mps",
    "terrain_vs_bands_mps",
    "preferred_heading_deg",
    "preferred_vs_mps",
)


@dataclass(frozen=True)
class Advice:
    """The resolution advice of one frame (:func:`skyradar.daa.advice.advice_columns`).

    Attributes
    ----------
    heading_bands_deg : list of float
        Headings in conflict with the traffic, flattened intervals ``[lo0, hi0, lo1, hi1, ...]``, deg.
    vs_bands_mps : list of float
        Vertical speeds in conflict with the traffic, flattened intervals, m/s (positive up).
    terrain_vs_bands_mps : list of float
        Vertical speeds that come too close to the terrain, flattened intervals, m/s.
    preferred_heading_deg : float
        The preferred conflict-free heading, deg (NaN: none).
    preferred_vs_mps : float
        The preferred conflict-free vertical speed, m/s, positive up (NaN: none).

    Examples
    --------
    The advice columns of an alerting frame's rows (:func:`frame_advice`):

    >>> alerts = pd.DataFrame({"level": [3], "heading_bands_deg": [[350.0, 20.0]], "vs_bands_mps": [[]],
    ...     "terrain_vs_bands_mps": [[]], "preferred_heading_deg": [80.0], "preferred_vs_mps": [np.nan]})
    >>> advice = frame_advice(alerts)
    >>> advice.heading_bands_deg, advice.preferred_heading_deg, advice.vs_bands_mps
    ([350.0, 20.0], 80.0, [])
    """

    heading_bands_deg: list[float]
    vs_bands_mps: list[float]
    terrain_vs_bands_mps: list[float]
    preferred_heading_deg: float
    preferred_vs_mps: float


@dataclass(frozen=True)
class FrameResult:
    """What one frame of the chain gives.

    Attributes
    ----------
    frame : int
        Frame number in the run, from 0.
    time_s : float
        Elapsed time of the frame since the run's start, s.
    detections : DataFrame
        The frame's detections, every head's (``radar`` column), rows of the chain's detections table.
    tracks : DataFrame
        The confirmed tracks' rows of the frame (``confirmed`` True), with the columns of
        :data:`~skyradar.track.track_table.TRACK_COLUMNS`.
    alerts : DataFrame
        The frame's alerts rows (:data:`~skyradar.daa.pipeline.ALERT_COLUMNS`).
    advice : Advice or None
        The frame's advice when an alert is issued on it and advice is on; else None.

    Examples
    --------
    The first frame of a head-on encounter (as :class:`StreamingChain`'s example):

    >>> from skyradar.scene.scenario import Scenario
    >>> spec = {"name": "head-on", "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    ...     "radar": {"range_limit_m": 1500},
    ...     "ownship": {"type": "straight", "start_ned_m": [0, 0, -2000], "speed_mps": 50},
    ...     "intruders": [{"name": "A", "type": "straight", "start_ned_m": [900, -40, -2000],
    ...                    "heading_deg": 180, "speed_mps": 40}],
    ...     "frame_rate_hz": 9.4, "duration_s": 1.0}
    >>> result = StreamingChain(Scenario.from_dict(spec).build(), with_advice=False).step()
    >>> result.frame, result.time_s, len(result.detections), len(result.tracks), result.advice
    (0, 0.0, 1, 0, None)
    """

    frame: int
    time_s: float
    detections: pd.DataFrame
    tracks: pd.DataFrame
    alerts: pd.DataFrame
    advice: Advice | None


class StreamingChain:
    """The whole DAA chain on a built scenario, advanced one radar frame per :meth:`step`.

    Parameters
    ----------
    built : BuiltScenario
        From :meth:`skyradar.scene.scenario.Scenario.build`.
    alert_config : AlertConfig, optional
        Volumes, times and gates of the alerting stage (default :class:`AlertConfig`).
    with_advice : bool
        Compute resolution advice on alerting frames.
    process_options : dict, optional
        Keyword arguments of :func:`skyradar.process.pipeline.process_frames` (e.g. ``suppression``).
    heads : list of str, optional
        Radar heads to simulate and fuse (names in ``built.heads``); default all.

    Notes
    -----
    :meth:`step` past the last frame raises ``StopIteration``, so the chain is an iterator of
    :class:`FrameResult` (``for result in chain``) and :meth:`run` steps it to the end. The
    closed-loop seam is :meth:`ownship_state`. The module docstring lists what differs from
    :func:`skyradar.chain.run_chain` and why.

    Examples
    --------
    >>> from skyradar.scene.scenario import Scenario
    >>> spec = {"name": "head-on", "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    ...     "radar": {"range_limit_m": 1500},
    ...     "ownship": {"type": "straight", "start_ned_m": [0, 0, -2000], "speed_mps": 50},
    ...     "intruders": [{"name": "A", "type": "straight", "start_ned_m": [900, -40, -2000],
    ...                    "heading_deg": 180, "speed_mps": 40}],
    ...     "frame_rate_hz": 9.4, "duration_s": 1.0}
    >>> chain = StreamingChain(Scenario.from_dict(spec).build(), with_advice=False)
    >>> first = chain.step()
    >>> first.frame, first.time_s, len(first.detections)
    (0, 0.0, 1)
    >>> results = chain.run()  # the remaining frames
    >>> len(results), chain.n_frames, len(results[-1].tracks)  # the intruder's track, confirmed
    (8, 9, 1)
    >>> sorted(chain.tables())[:4]
    ['alerts', 'detections', 'ownship', 'timings_s']
    """

    def __init__(
        self,
        built,
        alert_config: AlertConfig | None = None,
        with_advice: bool = True,
        process_options: dict[str, Any] | None = None,
        heads: list[str] | None = None,
    ) -> None:
        self.built = built
        self.heads = tracked_heads(built, heads, "StreamingChain")
        self.with_advice = with_advice
        self.process_options = dict(process_options or {})
        self._simulators = {h.name: make_simulator(built, h.name) for h in self.heads}
        self._walks = {h.name: AnchorWalk() for h in self.heads}
        self._attrs = run_attrs(built)
        self._tracker = TrackTableStream(
            "radar",
            self.heads[0].config,
            origin=built.origin,
            ground_test=default_ground_test(self.heads[0].config),
            several_heads=len(self.heads) > 1,
        )
        self._alerter = AlertStream(alert_config, with_advice=with_advice, source=built.name)
        self._next = 0
        self._own_truth: dict[str, list[float]] = {}
        self._navigated: list[OwnShipStates] = []  # the last frames' navigated own-ship states
        self._n_detections = 0
        self._own_so_far: pd.DataFrame | None = None  # the own-ship table's rows so far
        self._skipped = 0  # confirmed track rows without a state to alert on, so far
        self._used: list[np.ndarray] = []  # per frame: rows of the detections table the tracker took
        self._out: dict[str, list] = {"detections": [], "tracks": [], "alerts": [], "ownship": []}
        self._truth: dict[str, list[xr.Dataset]] = {h.name: [] for h in self.heads}
        self.timings_s = {"simulate": 0.0, "process": 0.0, "track": 0.0, "alert": 0.0}

    @property
    def n_frames(self) -> int:
        """Number of frames of the scenario."""
        return int(self.built.times_s.size)

    @property
    def frame(self) -> int:
        """Number of the next frame :meth:`step` simulates (frames done so far)."""
        return self._next

    def ownship_state(self, frame: int) -> TrajectorySample:
        """The own-ship's true state at ``frame`` (one sample): the closed loop's seam.

        Called once per frame, before the frame is simulated; everything of the frame (truth,
        navigation solution, radar frames, their processing, tracks and alerts) follows from it.
        Default: the scenario's own-ship trajectory sampled at the frame's time. A subclass may
        return any state at that time (e.g. from a pilot model flying the advice of the frames
        before); position and velocity are NED in the scenario's frame (m, m/s), attitude
        (yaw, pitch, roll) in rad, and ``lat_deg, lon_deg, alt_m`` the same position in WGS84.
        """
        return self.built.ownship.sample(self.built.times_s[frame : frame + 1])

    def step(self) -> FrameResult:
        """Simulate, process, track and alert the next frame; StopIteration past the last one."""
        i = self._next
        if i >= self.n_frames:
            raise StopIteration
        time_s = float(self.built.times_s[i])
        own_sample = self.ownship_state(i)
        det, own_row = self._detect(i, own_sample)
        air, used = tracker_detections(det)
        self._used.append(self._n_detections + used)
        self._n_detections += len(det)
        t0 = time.perf_counter()
        own_so_far = self._own_so_far = appended(self._own_so_far, own_row)
        self._tracker.set_surface(scenario_surface(self.built, own_so_far))  # causal: the ground so far
        rows = self._tracker.step(time_s, i, air, own_row)
        rows = restore_detection_rows(rows, np.concatenate(self._used)) if len(rows) else rows
        self.timings_s["track"] += time.perf_counter() - t0
        t0 = time.perf_counter()
        alerts = self._alerter.step(time_s, rows, own_row)
        self._skipped += int(alerts.attrs.get("rows_skipped_no_state", 0))
        self.timings_s["alert"] += time.perf_counter() - t0
        self._out["tracks"].append(rows)
        self._out["alerts"].append(alerts)
        self._next += 1
        confirmed = rows[rows["confirmed"].to_numpy(bool)].reset_index(drop=True)
        advice = frame_advice(alerts) if self.with_advice else None
        return FrameResult(i, time_s, det, confirmed, alerts, advice)

    def __iter__(self) -> Iterator[FrameResult]:
        return self

    def __next__(self) -> FrameResult:
        return self.step()

    def run(self) -> list[FrameResult]:
        """Step to the end of the scenario; the results of the frames not stepped before."""
        return list(self)

    def tables(self) -> dict[str, Any]:
        """The tables of the frames stepped so far, as :func:`skyradar.chain.run_chain` returns them.

        ``detections`` (every head's, ``radar`` column), ``tracks`` (every row emitted: the
        confirmed rows and those of tracks confirmed before, their ``detection_row`` indexing
        ``detections``), ``alerts``, ``ownship``, ``truth`` (the first head's frames Dataset without
        ``iq``), ``truth_by_head`` and ``timings_s`` per stage. The alerts' ``attrs`` count the
        confirmed track rows skipped for want of a state, as the batch's do.
        """
        out: dict[str, Any] = {}
        for name, parts in self._out.items():
            out[name] = pd.concat(parts, ignore_index=True) if parts else pd.DataFrame()
        if not self._out["tracks"]:
            out["tracks"] = empty_tracks()
        out["alerts"].attrs = {"rows_skipped_no_state": self._skipped}
        truths = {n: xr.concat(d, dim="time") if d else xr.Dataset() for n, d in self._truth.items()}
        return out | {
            "truth": truths[self.heads[0].name],
            "truth_by_head": truths,
            "timings_s": dict(self.timings_s),
        }

    def _detect(self, i: int, own_sample: TrajectorySample) -> tuple[pd.DataFrame, pd.DataFrame]:
        """Frame ``i`` of every head: merged detections and the own-ship table's row."""
        built, tables, own_row = self.built, {}, None
        navigation: dict[str, np.ndarray] | None = None
        for name, simulator in self._simulators.items():
            t0 = time.perf_counter()
            iq = simulate_frames(built, np.array([i]), simulator, own_sample)
            own, targets, names = frames_truth(built, np.array([i]), simulator, own_sample)
            if navigation is None:
                navigation = self._navigation(own)
            own = own | navigation
            times = built.times_s[i : i + 1]
            ds = frames_dataset(iq, times, simulator.config, own, targets, names, self._attrs)
            self._truth[name].append(ds.drop_vars("iq"))
            self.timings_s["simulate"] += time.perf_counter() - t0
            t0 = time.perf_counter()
            anchors = self._anchor(name, ds)
            det = process_frames(
                ds, terrain=built.terrain, source=built.name, anchors=anchors, **self.process_options
            )
            det["frame"] += i
            tables[name] = det
            self.timings_s["process"] += time.perf_counter() - t0
            if own_row is None:
                own_row = ownship_from_frames(ds, built.name)
                self._out["ownship"].append(own_row)
        merged = merge_head_tables(tables)
        self._out["detections"].append(merged)
        return merged, own_row

    def _navigation(self, own: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """The frame's navigation solution from the own-ship truth of the frames so far."""
        for key, value in own.items():
            self._own_truth.setdefault(key, []).append(float(np.asarray(value)[0]))
        nav = navigation_at_frame(self.built, {k: np.array(v) for k, v in self._own_truth.items()})
        return {k: np.array([v]) for k, v in nav.items()}

    def _anchor(self, name: str, ds: xr.Dataset) -> np.ndarray | None:
        """The frame's clutter-prediction anchor, (1, 6), from the walk over the run's frames so far."""
        state = navigated_own_state(ds, self.built.name)
        if state is None:
            return None
        if name == self.heads[0].name:  # one own-ship: its recent states serve every head
            self._navigated = [*self._navigated, state][-_SMOOTH_FRAMES:]
        # The recent frames' arrays with this head's flags (every head flies the one own-ship).
        recent = replace(
            OwnShipStates.concatenate(self._navigated),
            has_geo=state.has_geo,
            navigation_source=state.navigation_source,
        )
        geometry = frame_geometries(recent, self.built.terrain)[-1]
        return self._walks[name].next(geometry)[None, :]


def frame_advice(alerts: pd.DataFrame) -> Advice | None:
    """The advice of one frame's alerts rows (repeated on each row) when an alert is issued on it, else None.

    Examples
    --------
    >>> frame_advice(pd.DataFrame({"level": [0]})) is None
    True
    """
    if len(alerts) == 0 or not (alerts["level"].to_numpy() > 0).any() or _ADVICE[0] not in alerts:
        return None
    row = alerts.iloc[0]
    values = {name: row[name] for name in _ADVICE}
    bands = {k: [float(x) for x in values[k]] for k in _ADVICE[:3]}
    return Advice(
        **bands,
        preferred_heading_deg=float(values["preferred_heading_deg"]),
        preferred_vs_mps=float(values["preferred_vs_mps"]),
    )
