"""One encounter of ``skyradar experiment encounters`` through the whole chain, scored per layout.

The frames cover the last ``lookback_s`` before the loss of well clear (or the CPA), and start no
earlier than the intruder is inside the range limit: 40 s is the 25 s warning alerting time plus
15 s to confirm a track and let its velocity converge (on the seed-1 set at 4.7 Hz, 45 s gave the
same warnings and 35 s cut the median lead by 2 s). Every head of the scenario is simulated and
processed once (:func:`skyradar.chain.run_chain`: the chain a user gets, with
its default clutter suppression, ground flags and navigation errors); each layout then tracks and
alerts its own heads' detections, so a single head and the three-head layout are compared on the
same frames, noise and clutter.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd
import xarray as xr

from skyradar.chain import confirmed_rows, label_tracks, run_chain
from skyradar.daa.alerting import RADAR_ALERT_CONFIG, AlertConfig
from skyradar.daa.pipeline import alerts_from_tracks
from skyradar.daa.run_tables import ownship_from_frames, truth_tracks
from skyradar.experiments.encounter_score import frame_status, track_counts, unwarned_cause
from skyradar.experiments.encounter_set import (
    encounter_scenario,
    event_times,
    relative_truth,
    score_encounter,
)
from skyradar.experiments.encounter_terrain import OWN_AGL_RANGE_M, mirror_below_ground, own_altitude_m
from skyradar.experiments.sensor_figures import intruder_track_figures
from skyradar.scene.scenario import Scenario

__all__ = [
    "build_encounter",
    "chain_rows",
    "run_encounter",
    "score_layout",
    "truth_warning_time",
    "layout_heads",
    "warning_held",
    "warning_flickers",
    "warned_on_altitude_prior",
    "FRAME_RATE_HZ",
    "LAYOUTS",
    "SUPPRESSION",
]

FRAME_RATE_HZ = 9.4  # the prototype's frame rate
LAYOUTS = ("single", "three-head")
_RANGE_MARGIN_M = 300.0
SUPPRESSION = (
    "auto"  # skyradar process's default: knowledge-aided when own-ship's height above ground is known
)


def _window(
    p: pd.Series,
    frame_rate_hz: float,
    lookback_s: float,
    seed: int,
    terrain: str | None,
    end_s: float | None = None,
) -> tuple[float, float, np.ndarray, np.ndarray, Any]:
    """Frame window (start, duration) in s, ``lookback_s`` before the LoWC or CPA and in range, to
    2 s after that event or to ``end_s``; the dense relative truth (times, NED m) it was chosen on,
    and the scenario it was built from."""
    built = Scenario.from_dict(encounter_scenario(p, 0.0, 1.0, frame_rate_hz, seed, terrain)).build()
    t, rel = relative_truth(built)
    t_lowc, t_cpa = event_times(t, rel)
    t_event = t_lowc if np.isfinite(t_lowc) else t_cpa
    in_range = np.linalg.norm(rel, axis=1) <= built.radar.range_limit_m + _RANGE_MARGIN_M
    first = float(t[np.argmax(in_range & (t <= t_event))]) if in_range.any() else t_event - lookback_s
    start = max(t_event - lookback_s, first, float(t[0]))
    end = min(t_event + 2.0 if end_s is None else float(end_s), float(t[-1]))
    return start, max(end - start, 2.0 / frame_rate_hz), t, rel, built


def _fly_above_ground(
    p: pd.Series, built, start: float, duration: float, rel: np.ndarray, terrain: str | None
):
    """Own-ship altitude over the ground of ``built`` (None: the terrain's nominal one) and the
    encounter row, mirrored in altitude when the intruder would pass too close to the ground."""
    if built.terrain is None:
        return None, p, rel
    times = np.linspace(start, start + duration, 64)
    own = built.ownship.sample(times)
    ground_own = built.terrain.height_at(own.lat_deg, own.lon_deg)
    nominal = float(own.alt_m[0])
    agl = float(p.get("own_agl_m", np.nan))  # a family's own height above the ground, else the default range
    agl_range = (agl, agl) if np.isfinite(agl) else OWN_AGL_RANGE_M
    alt = own_altitude_m(ground_own, agl_range) if terrain in ("hills", "jacksboro") else nominal
    tgt = built.intruders[0].trajectory.sample(times)
    ground_tgt = built.terrain.height_at(tgt.lat_deg, tgt.lon_deg)
    if mirror_below_ground(tgt.alt_m + (alt - nominal), ground_tgt, alt):
        p = p.copy()
        p["vertical_miss_m"] = -p["vertical_miss_m"]
        p["climb_mps"] = -p["climb_mps"]
        rel = rel * np.array([1.0, 1.0, -1.0])  # the mirror image in own-ship's altitude
    return (None if alt == nominal else alt), p, rel


def layout_heads(built, layout: str) -> list[str]:
    """The head names of a layout: ``single`` the first (forward) head, ``three-head`` all."""
    names = [h.name for h in built.heads]
    return names[:1] if layout == "single" else names


def warning_held(warn_times_s: np.ndarray, status: pd.DataFrame, t_cpa_s: float) -> tuple[bool, float]:
    """Whether a warning, once issued, stays on every frame to the closest approach (or to the last
    frame the intruder is observable before it, when it leaves the beams first), and the longest
    gap between its frames, s. (True, 0) when never issued."""
    warn = np.unique(np.asarray(warn_times_s, float))
    if warn.size == 0:
        return True, 0.0
    ft, ok = status["time_s"].to_numpy(float), status["observable"].to_numpy(bool)
    frames = ft[(ft >= warn[0]) & (ft <= t_cpa_s) & ok]
    end = float(frames.max()) if frames.size else warn[0]
    frame_s = frame_interval_s(ft)
    shown = np.concatenate([warn[warn <= end], [end]]) if end > warn[-1] else warn[warn <= end]
    gap = float(np.diff(shown).max()) if shown.size > 1 else 0.0
    return bool(gap <= 1.5 * frame_s + 1e-9), gap


def frame_interval_s(frame_times_s: np.ndarray) -> float:
    """The run's frame interval, s: the median step between frame times (0 for one frame)."""
    return float(np.median(np.diff(frame_times_s))) if len(frame_times_s) > 1 else 0.0


def warning_flickers(warn_times_s: np.ndarray, frame_s: float, t_cpa_s: float) -> int:
    """How often a warning drops and comes back before the closest approach: the gaps longer than
    1.5 frames between the frames it is shown on.

    Examples
    --------
    >>> warning_flickers(np.array([10.0, 10.1, 10.2, 14.0, 14.1, 30.0]), 0.1, 20.0)
    1
    """
    warn = np.unique(np.asarray(warn_times_s, float))
    warn = warn[warn <= t_cpa_s]
    return int(np.sum(np.diff(warn) > 1.5 * frame_s + 1e-9)) if warn.size > 1 else 0


def truth_warning_time(truth: xr.Dataset, config: AlertConfig) -> float:
    """First warning (level 3) the alerter gives on the true states of intruder and own-ship, s.

    The same alerting settings as the chain, fed with perfect surveillance: the intruder's true
    position and velocity on every frame (in the field of view or not) and the own-ship's true
    state instead of its navigation solution. A recorded intruder that turns away after heading
    at the own-ship is predicted into a loss of well clear by any alerter that projects straight
    lines; a warning perfect surveillance gives too is the alerter's, not the sensor's. NaN: no
    warning.

    Examples
    --------
    >>> import xarray as xr
    >>> truth_warning_time(xr.Dataset(), RADAR_ALERT_CONFIG)
    nan
    """
    if "tgt_north_m" not in truth or "own_north_m" not in truth:
        return float("nan")
    own = ownship_from_frames(truth.drop_vars([v for v in truth.data_vars if str(v).startswith("nav_")]))
    tracks = truth_tracks(truth, visible_only=False)
    alerts = alerts_from_tracks(tracks, own, config, with_advice=False, source="truth")
    warn = alerts["time_s"].to_numpy(float)[alerts["level"].to_numpy(int) >= 3] if len(alerts) else []
    return float(np.min(warn)) if len(warn) else float("nan")


def warned_on_altitude_prior(warnings: pd.DataFrame) -> bool:
    """Whether the first of these warning rows (an alerts table's) rests on a co-altitude prior.

    A track none of whose elevations was measured flies at the own-ship's height (over the ground
    two clutter nulls at one elevation take the 2x2 array's whole elevation dimension): an intruder
    passing above or below then looks level, and its warning cannot be cleared by a vertical miss.
    False without warnings.

    Examples
    --------
    >>> rows = pd.DataFrame({"time_s": [12.0, 10.0], "altitude_measured": [True, False]})
    >>> [warned_on_altitude_prior(r) for r in (rows, rows.iloc[:1], rows.iloc[:0])]
    [True, False, False]
    """
    if not len(warnings):
        return False
    first = warnings["altitude_measured"].to_numpy(bool)[np.argmin(warnings["time_s"].to_numpy(float))]
    return not bool(first)


def score_layout(chain: dict, truths: list, built, t, rel, opts: dict) -> dict[str, Any]:
    """One layout's result row from its tracks and alerts (``chain``) and its heads' truth.

    ``opts`` holds the scoring options (``fov_deg``, ``min_snr_db``, ``observe_window_s``,
    ``buffer``) and, optionally, the ``alert_config`` whose warning on perfect surveillance is
    written as ``t_truth_warning_s`` (:func:`truth_warning_time`).
    """
    tracks, alerts = chain["tracks"], chain["alerts"]
    labels = label_tracks(tracks, truths[0])
    warn = alerts[alerts["level"] >= 3] if len(alerts) else alerts
    mine = warn["track_id"].map(lambda i: labels.get(int(i)) == "intruder").to_numpy(bool)
    status = frame_status(truths, opts["fov_deg"], opts["min_snr_db"])
    window = opts["observe_window_s"]
    warning_times = warn["time_s"].to_numpy(float)[mine]  # the intruder's warning frames
    row: dict[str, Any] = score_encounter(t, rel, warning_times, status, opts["buffer"], window)
    row["warning_held"], row["warning_gap_max_s"] = warning_held(warning_times, status, row["t_cpa_s"])
    frame_s = frame_interval_s(status["time_s"].to_numpy(float))
    row["warning_flickers"] = warning_flickers(warning_times, frame_s, row["t_cpa_s"])
    row["cause"] = unwarned_cause(status, row["t_lowc_s"], row["t_warning_s"], window)
    other = warn["time_s"].to_numpy(float)[~mine]
    own_agl = (
        float(np.nanmedian(truths[0]["own_height_agl_m"].values)) if built.terrain is not None else np.nan
    )
    warned = {int(i) for i in warn["track_id"]}
    row.update(track_counts(confirmed_rows(tracks), warned, labels, built.terrain, own_agl))
    row.update(intruder_track_figures(tracks, labels, truths[0]))
    row.update(
        warned_on_altitude_prior=warned_on_altitude_prior(warn[mine]),
        t_other_warning_s=float(other.min()) if other.size else float("nan"),
        tracks=int(tracks["track_id"].nunique()),
        own_agl_m=own_agl,
    )
    if opts.get("alert_config") is not None:
        row["t_truth_warning_s"] = truth_warning_time(truths[0], opts["alert_config"])
    return row


def build_encounter(
    p: pd.Series,
    seed: int,
    frame_rate_hz: float,
    lookback_s: float,
    terrain: str | None,
    layouts: tuple[str, ...],
    navigation: str | dict | None,
    simulation: dict[str, Any] | None,
    rx_layout: str,
    end_s: float | None = None,
) -> tuple[Any, dict[str, np.ndarray], dict[str, Any]]:
    """The built scenario of one encounter row, its dense relative truth and the row's shared columns.

    The frames start ``lookback_s`` before the loss of well clear (or the CPA) and no earlier than
    the intruder is in range; they end 2 s after that event, or at ``end_s`` (s, at most the
    own-ship's last time). Over hills and Jacksboro the own-ship flies at its height above the
    ground, the encounter mirrored in altitude when the intruder would pass too close to the ground.
    ``layouts`` holding ``three-head`` mounts :data:`~skyradar.scene.examples.THREE_HEAD_RADARS`.
    Returns the :class:`~skyradar.scene.scenario.BuiltScenario`, ``{"t": times (s), "rel":
    intruder-minus-own-ship NED positions (m)}`` and the columns every result row of it shares.
    """
    from skyradar.scene.examples import THREE_HEAD_RADARS

    start, duration, t, rel, ground = _window(p, frame_rate_hz, lookback_s, seed, terrain, end_s)
    vertical = p["vertical_miss_m"]
    alt, p, rel = _fly_above_ground(p, ground, start, duration, rel, terrain)
    radars = THREE_HEAD_RADARS if "three-head" in layouts else None
    spec = encounter_scenario(
        p,
        start,
        duration,
        frame_rate_hz,
        seed,
        terrain,
        radars=radars,
        navigation=navigation,
        own_altitude_m=alt,
        simulation=simulation,
        rx_layout=rx_layout,
    )
    built = Scenario.from_dict(spec).build()
    shared = {
        "frames": int(built.times_s.size),
        "t_start_s": start,
        "flight_s": float(duration),
        "mirrored": bool(p["vertical_miss_m"] != vertical),
        "vertical_miss_flown_m": float(p["vertical_miss_m"]),
        "own_altitude_m": float(-spec["ownship"]["start_ned_m"][2]),
    }
    return built, {"t": t, "rel": rel}, shared


def run_encounter(
    p: pd.Series,
    seed: int = 0,
    frame_rate_hz: float = FRAME_RATE_HZ,
    lookback_s: float = 40.0,
    buffer: float = 1.5,
    fov_deg: float = 70.0,
    min_snr_db: float = 13.0,
    observe_window_s: float = 12.5,
    alert_config: AlertConfig | None = None,
    terrain: str | None = None,
    layouts: tuple[str, ...] = ("single",),
    navigation: str | dict | None = None,
    simulation: dict[str, Any] | None = None,
    rx_layout: str = "square",
) -> list[dict[str, Any]]:
    """One encounter row through the full chain; one result row per layout (times in s, NaN when none).

    The heads are simulated and processed once; each layout (``"single"``: the nose head alone,
    ``"three-head"``: :data:`~skyradar.scene.examples.THREE_HEAD_RADARS`) tracks and alerts its
    heads' detections. ``t_warning_s`` is the first warning (level 3) of a track that follows the
    intruder; ``t_other_warning_s`` the first warning of any other track (clutter or noise).
    ``simulation`` overrides the scenario's simulator options and ``rx_layout`` names every head's
    receive array (:func:`~skyradar.experiments.encounter_set.encounter_scenario`).
    """
    cfg = alert_config or RADAR_ALERT_CONFIG
    spec_args = (p, seed, frame_rate_hz, lookback_s, terrain, layouts, navigation, simulation, rx_layout)
    built, truth, shared = build_encounter(*spec_args)
    opts = {
        "fov_deg": fov_deg,
        "min_snr_db": min_snr_db,
        "observe_window_s": observe_window_s,
        "buffer": buffer,
    }
    return chain_rows(built, truth["t"], truth["rel"], shared, layouts, cfg, opts)


def chain_rows(
    built,
    t: np.ndarray,
    rel: np.ndarray,
    shared: dict,
    layouts: tuple[str, ...],
    cfg: AlertConfig,
    opts: dict,
) -> list[dict[str, Any]]:
    """Simulate and process ``built`` once, then track, alert and score each layout's heads: one row
    per layout (:func:`score_layout` with ``opts``, the ``shared`` columns and the stage timings).
    ``t`` and ``rel`` are the dense relative truth the encounter is scored on."""
    from skyradar.chain import track_and_alert

    opts = opts | {"alert_config": cfg}
    chain = run_chain(built, cfg, with_advice=False, process_options={"suppression": SUPPRESSION})
    shared = shared | {
        f"{k}_s": float(v) for k, v in chain["timings_s"].items() if k in ("simulate", "process")
    }
    det, rows = chain["detections"], []
    for layout in layouts:
        heads = layout_heads(built, layout)
        out = chain
        if len(heads) < len(built.heads):  # a subset of the simulated heads: track and alert again
            out = track_and_alert(det, built, heads, cfg, with_advice=False, truth=chain["truth"])
        truths = [chain["truth_by_head"][h] for h in heads]
        row = score_layout(out, truths, built, t, rel, opts)
        mine = det["radar"].isin(heads).to_numpy(bool) if "radar" in det else np.ones(len(det), bool)
        timings = {f"{k}_s": float(v) for k, v in out["timings_s"].items() if k in ("track", "alert")}
        row.update(layout=layout, detections=int(mine.sum()), **shared, **timings)
        rows.append(row)
    return rows
