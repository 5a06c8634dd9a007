"""Experiment ch4: radar-aware versus traditional tracking around an airfield (Maas 2022, ch. 4).

Three own-ship flights (Circuit, Zulu, Free) with ten VFR intruders each
(:mod:`skyradar.experiments.ch4_flights`), a forward-looking prototype radar, and both trackers on
the same detections. Two detection sources:

* ``chain='full'``: frames simulated by :class:`skyradar.sim.image.ImageSimulator` (free space,
  thermal noise, range-Doppler coupling; no terrain), detected and located by
  :func:`skyradar.process.pipeline.process_cube` (CA-CFAR, sub-pixel peaks, phase-difference DoA).
* ``chain='geometry'``: detections synthesised from the truth geometry: range and aliased radial
  velocity with noise, detection probability from the expected SNR, DoA with angular noise, and
  uniform clutter (:func:`skyradar.track.simulated_detections.synthetic_detections` style).

True tracks are counted from the scenario, never from the detections being scored
(:func:`scenario_visibility`, :func:`count_truth_tracks`). An intruder is detectable in a frame when
the simulator's geometry puts it in front of the antenna, inside the range limit and in line of
sight, with an expected SNR (radar equation with the two-way antenna gain, so the beam is in it; no
noise) of at least the detection threshold: the SNR at which the CA-CFAR that ``process_cube``
runs detects with 50 % probability (:func:`detection_threshold_snr_db`, 7.5 dB for the
prototype). Detectable frames form one true track while their gaps are at most the trackers'
coasting time (``TrackerConfig.max_coast_s``, 2 s: a tracker keeps its track through a shorter gap
and closes it after a longer one, so an intruder that comes back later is a new true track). A
span counts only if it holds the trackers' confirmation, 4 detectable frames within 5 consecutive
ones (``confirm_m``/``confirm_n``, 0.32 s at 9.4 frames/s): even detected in every frame, a
shorter span cannot become a confirmed track. Both trackers are then scored against that truth
(:func:`skyradar.track.metrics.track_metrics`: tracks, false tracks, fragmentation, missed true
tracks, completeness); a track on an intruder below the threshold is matched, not false. Counts at
3 and 6 dB above the threshold are reported too. Writes ``ch4_results.json``/``.csv``,
per-scenario detection and track tables, and three figures.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pandas as pd

from skyradar.config import RadarConfig
from skyradar.experiments.ch4_flights import EPBC, SCENARIOS, Traffic, build_traffic
from skyradar.experiments.summary_md import beside, counted, number, page, write_summary
from skyradar.io.atomic import write_csv_atomic
from skyradar.io.json_results import write_json_atomic
from skyradar.io.tables import write_table
from skyradar.parallel import check_workers, close, connect
from skyradar.track.detectable import detection_threshold_snr_db
from skyradar.track.io import Truth
from skyradar.track.metrics import track_metrics, truth_segments
from skyradar.track.simulated_detections import synthetic_detections
from skyradar.track.track_table import OWNSHIP_COLUMNS, track_detections
from skyradar.track.types import TrackerConfig

__all__ = [
    "run",
    "run_scenario",
    "scenario_truth",
    "detection_threshold_snr_db",
    "scenario_visibility",
    "count_truth_tracks",
    "THESIS",
    "summary_markdown",
]

# Maas 2022, ch. 4 (pixels, counts): traditional / proposed / by hand.
THESIS = {
    "circuit": {"innov_mean": (2.1, 2.0), "innov_p95": (7.1, 4.9), "tracks": (42, 14), "truth": 14},
    "zulu": {"innov_mean": (2.7, 2.5), "innov_p95": (10.5, 7.1), "tracks": (42, 9), "truth": 9},
    "free": {"innov_mean": (4.3, 3.6), "innov_p95": (14.4, 10.7), "tracks": (54, 13), "truth": 12},
}


def scenario_visibility(truth: dict, snr_threshold_db: float) -> np.ndarray:
    """Frames (n_time, n_intruder) in which each intruder is detectable according to the scenario.

    In front, inside the range limit and in line of sight (the simulator's ``visible``) with an
    expected SNR of at least ``snr_threshold_db``; detections play no part.

    Examples
    --------
    >>> truth = {"front": np.array([[True, True, False]]), "snr_db": np.array([[9.0, 5.0, 20.0]])}
    >>> scenario_visibility(truth, 7.5).tolist()
    [[True, False, False]]
    """
    snr_db = np.nan_to_num(np.asarray(truth["snr_db"], float), nan=-np.inf)
    return np.asarray(truth["front"], bool) & (snr_db >= snr_threshold_db)


def count_truth_tracks(
    time_s: np.ndarray, visible: np.ndarray, tracker: TrackerConfig | None = None
) -> tuple[int, np.ndarray]:
    """Number of true tracks and their labels per (frame, intruder) (-1: not part of one).

    Detectable frames of one intruder separated by at most ``tracker.max_coast_s`` are one true
    track; a span counts when it holds ``confirm_m`` detectable frames within ``confirm_n``
    consecutive frames (what the tracker needs to confirm).

    Examples
    --------
    >>> t = np.arange(60) / 10.0  # 10 frames/s; coasting 2 s, confirmation 4 of 5
    >>> vis = np.zeros((60, 1), bool)
    >>> vis[0:10] = vis[40:50] = True  # a 3 s gap: two true tracks
    >>> vis[55:58] = True  # three frames after a 0.6 s gap: part of the second
    >>> count_truth_tracks(t, vis)[0]
    2
    """
    tc = tracker or TrackerConfig()
    vis = np.asarray(visible, bool)
    zeros = np.zeros(vis.shape)
    labels = truth_segments(
        Truth(np.asarray(time_s, float), zeros, zeros, vis), tc.max_coast_s, 0.0, (tc.confirm_m, tc.confirm_n)
    )
    return int(np.unique(labels[labels >= 0]).size), labels


def scenario_truth(
    name: str,
    config: RadarConfig,
    frame_rate_hz: float,
    interval_s: float,
    tail_s: float,
    traffic: Traffic | None = None,
) -> dict:
    """Frame times, own-ship samples and per-intruder truth (n_time, n_intruder) for one scenario.

    ``traffic`` replaces the generated traffic of scenario ``name`` (tests fly simple cases).
    """
    from skyradar.sim.image import ImageSimulator, PlatformState, PointTarget

    traffic = traffic or build_traffic(name, interval_s, tail_s)
    t = np.arange(0.0, traffic.duration_s, 1.0 / frame_rate_hz)
    own = traffic.ownship.sample(t)
    n, m = t.size, len(traffic.intruders)
    pos = np.full((n, m, 3), np.nan)
    vel = np.full((n, m, 3), np.nan)
    for j, flight in enumerate(traffic.intruders):
        cov = flight.covers(t)
        s = flight.sample(t[cov])
        pos[cov, j], vel[cov, j] = s.position_ned_m, s.velocity_ned_mps
    sim = ImageSimulator(config, origin=EPBC, noise=False)
    keys = ("range_m", "radial_velocity_mps", "snr_db", "azimuth_rad", "elevation_rad")
    out = {k: np.full((n, m), np.nan) for k in keys}
    front = np.zeros((n, m), bool)
    for k in range(n):
        here = np.flatnonzero(np.isfinite(pos[k, :, 0]))
        if here.size == 0:
            continue
        platform = PlatformState(own.position_ned_m[k], own.velocity_ned_mps[k], own.attitude_rad[k])
        g = sim.target_truth(platform, [PointTarget(pos[k, j], vel[k, j], 1.0) for j in here])
        for key in keys:
            out[key][k, here] = g[key]
        front[k, here] = g["visible"]
    return {"time_s": t, "own": own, "pos": pos, "vel": vel, "front": front, **out}


def _detect_full(truth: dict, config: RadarConfig, seed: int) -> pd.DataFrame:
    from skyradar.geo import rotation_matrix
    from skyradar.process.pipeline import process_cube
    from skyradar.sim.image import ImageSimulator, PlatformState, PointTarget

    sim = ImageSimulator(config, origin=EPBC, noise=True, seed=seed)
    own, t = truth["own"], truth["time_s"]
    rows = []
    for k in range(t.size):
        here = np.flatnonzero(np.isfinite(truth["pos"][k, :, 0]))
        platform = PlatformState(own.position_ned_m[k], own.velocity_ned_mps[k], own.attitude_rad[k])
        targets = [PointTarget(truth["pos"][k, j], truth["vel"][k, j], 1.0) for j in here]
        det = process_cube(sim.frame(platform, targets, k), config)
        body = np.column_stack([det["x_body_m"], det["y_body_m"], det["z_body_m"]])
        ned = own.position_ned_m[k] + body @ rotation_matrix(*own.attitude_rad[k]).T
        rows.append(
            pd.DataFrame(
                {
                    "time_s": t[k],
                    "frame": k,
                    "range_m": det["range_m"],
                    "radial_velocity_mps": det["radial_velocity_mps"],
                    "snr_db": det["snr_db"],
                    "azimuth_rad": det["azimuth_rad"],
                    "elevation_rad": det["elevation_rad"],
                    "north_m": ned[:, 0],
                    "east_m": ned[:, 1],
                    "down_m": ned[:, 2],
                }
            )
        )
    return pd.concat(rows, ignore_index=True)


def _detect_geometry(truth: dict, config: RadarConfig, seed: int, clutter_per_frame: float) -> pd.DataFrame:
    """Detections from truth, mimicking the full chain's measured behaviour: Pd from SNR (logistic,
    50 % at 6.7 dB, 0.8 dB scale), range noise 4.4 m, Doppler noise 0.093 m/s, aliasing, range-Doppler
    coupling, DoA with 0.04 rad error, and uniform clutter beyond 100 m (SNR column: 12 dB)."""
    snr = np.nan_to_num(truth["snr_db"], nan=-99.0)
    det = synthetic_detections(
        truth["time_s"],
        truth["range_m"],
        truth["radial_velocity_mps"],
        visible=truth["front"] & (truth["range_m"] < config.range_limit_m),
        config=config,
        sigma_range_m=4.4,
        sigma_velocity_mps=0.093,
        pd_detect=1.0 / (1.0 + np.exp(-(snr - 6.7) / 0.8)),
        clutter_per_frame=clutter_per_frame,
        positions_ned_m=truth["pos"],
        sigma_angle_rad=0.04,
        seed=seed,
        clutter_min_range_m=100.0,
    )
    target = det["target"].to_numpy()
    det["snr_db"] = np.where(target >= 0, snr[det["frame"].to_numpy(), np.maximum(target, 0)], 12.0)
    return det


def run_scenario(
    name: str,
    chain: str = "full",
    frame_rate_hz: float = 9.4,
    interval_s: float = 15.0,
    tail_s: float = 45.0,
    clutter_per_frame: float = 1.0,
    seed: int = 0,
    traffic: Traffic | None = None,
) -> dict:
    """Truth, detections, both trackers and their metrics for one scenario (``traffic``: see
    :func:`scenario_truth`)."""
    config = RadarConfig.prototype_2022()
    truth = scenario_truth(name, config, frame_rate_hz, interval_s, tail_s, traffic)
    t0 = time.perf_counter()
    if chain == "full":
        det = _detect_full(truth, config, seed)
    elif chain == "geometry":
        det = _detect_geometry(truth, config, seed, clutter_per_frame)
    else:
        raise ValueError(f"chain must be 'full' or 'geometry', got {chain!r}")
    t_detect = time.perf_counter() - t0
    # Truth from the scenario alone (module docstring).
    threshold_db = detection_threshold_snr_db(config)
    visible = scenario_visibility(truth, threshold_db)
    tc = TrackerConfig()
    by_margin = {
        f"+{m:g}": count_truth_tracks(truth["time_s"], scenario_visibility(truth, threshold_db + m), tc)[0]
        for m in (3.0, 6.0)
    }
    out = {
        "scenario": name,
        "chain": chain,
        "frames": int(truth["time_s"].size),
        "detections": len(det),
        "detect_s": t_detect,
        "tracks": {},
        "truth_snr_threshold_db": threshold_db,
        "truth_tracks": count_truth_tracks(truth["time_s"], visible, tc)[0],
        "truth_tracks_by_margin_db": by_margin,
    }
    _track_and_score(out, truth, det, visible, config, chain)
    out["detections_table"] = det
    out["truth"] = truth
    out["visible"] = visible
    return out


def _track_and_score(
    out: dict, truth: dict, det: pd.DataFrame, visible: np.ndarray, config: RadarConfig, chain: str
) -> None:
    """Run both trackers on ``det`` and put their tables and metrics into ``out``."""
    tc = TrackerConfig()
    pixel = (config.range_resolution_m, config.doppler_resolution_mps)
    width = 2 * config.v_lim_mps
    # Tracks are matched to every intruder in front (a track on one too faint to count is not
    # false); true tracks are the counted spans of ``visible``.
    tr = Truth(truth["time_s"], truth["range_m"], truth["radial_velocity_mps"], truth["front"])
    own = truth["own"]
    ownship = pd.DataFrame(
        {
            "time_s": truth["time_s"],
            **{
                c: own.position_ned_m[:, i] if i < 3 else own.velocity_ned_mps[:, i - 3]
                for i, c in enumerate(OWNSHIP_COLUMNS[1:])
            },
        }
    )
    # The geometry chain's DoA noise is a fixed 0.04 rad (see _detect_geometry), not the bound.
    sigma_rad = 0.04 if chain == "geometry" else None
    for model in ("radar", "traditional"):
        t1 = time.perf_counter()
        tracks = track_detections(
            det,
            model,
            config,
            frame_times_s=truth["time_s"],
            origin=EPBC,
            position_sigma_rad=sigma_rad,
            ownship=ownship,
        )
        m = track_metrics(
            tracks,
            tr,
            pixel,
            width,
            gap_s=tc.max_coast_s,
            min_duration_s=0.0,
            confirm=(tc.confirm_m, tc.confirm_n),
            counted=visible,
        )
        out[f"track_s_{model}"] = time.perf_counter() - t1
        out[f"tracks_{model}"] = m["tracks"]
        keys = (
            "false_tracks",
            "fragmentation",
            "id_switches",
            "completeness",
            "missed_truth_tracks",
            "gospa_mean",
        )
        for key in keys:
            out[f"{key}_{model}"] = m[key]
        # Confirmed tracks per true track (1 is ideal; more: fragments or false tracks).
        out[f"tracks_per_truth_{model}"] = m["tracks"] / max(out["truth_tracks"], 1)
        out[f"innov_mean_{model}"] = m["innov_mean_px"]
        out[f"innov_p95_{model}"] = m["innov_p95_px"]
        # Over confirmed rows only (without each track's first, tentative updates), for reference.
        out[f"innov_p95_confirmed_{model}"] = m["innov_p95_px_confirmed"]
        out[f"innov_range_p95_m_{model}"] = m["innov_range_p95_m"]
        out[f"gospa_{model}"] = m["gospa_mean"]
        out["tracks"][model] = tracks


def _run_one(args: tuple) -> dict:
    return run_scenario(*args)


def run(
    out_dir: Path,
    chain: str = "full",
    frame_rate_hz: float = 9.4,
    interval_s: float = 15.0,
    tail_s: float = 45.0,
    workers: int = 2,
    scenarios: tuple[str, ...] = SCENARIOS,
    seed: int = 0,
) -> dict:
    """Run all scenarios (on a local Dask cluster of ``workers`` processes), write tables and figures,
    return the summary.

    ``seed`` seeds the simulator's noise (full chain) or the synthetic detections (geometry chain).
    """
    from skyradar.errors import InputError
    from skyradar.experiments.ch4_figures import draw_figures

    # Checked before the cluster starts: a worker's error comes back as a long traceback.
    if chain not in ("full", "geometry"):
        raise InputError(f"experiment ch4: chain must be 'full' or 'geometry', got {chain!r}")
    unknown = [name for name in scenarios if name not in SCENARIOS]
    if unknown:
        raise InputError(f"experiment ch4: unknown scenario(s) {unknown}; choose from {list(SCENARIOS)}")
    if not (np.isfinite(frame_rate_hz) and frame_rate_hz > 0 and int(workers) >= 1):
        raise InputError(
            f"experiment ch4: need frame_rate_hz > 0 and workers >= 1, got {frame_rate_hz}, {workers}"
        )
    check_workers(workers)  # 10**20 local worker processes would exhaust memory
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    jobs = [(name, chain, frame_rate_hz, interval_s, tail_s, 1.0, seed) for name in scenarios]
    if workers > 1 and len(jobs) > 1:  # one Dask task per scenario on a local cluster
        client = connect(None, min(workers, len(jobs)))
        try:
            results = client.gather(client.map(_run_one, jobs, pure=False))
        finally:
            close(client, owns_cluster=True)
    else:
        results = [_run_one(j) for j in jobs]
    per_scenario = {}
    for res in results:
        name = res["scenario"]
        write_table(res["detections_table"], out_dir / f"detections_{name}.parquet")
        for model, tracks in res["tracks"].items():
            write_table(tracks, out_dir / f"tracks_{name}_{model}.parquet")
        per_scenario[name] = {
            k: v for k, v in res.items() if k not in ("tracks", "detections_table", "truth", "visible")
        }
    figures = draw_figures(results, out_dir)
    summary = _summary(per_scenario, chain, time.perf_counter() - start, figures)
    summary["seed"] = int(seed)
    write_csv_atomic(pd.DataFrame(per_scenario).T, out_dir / "ch4_results.csv")
    write_json_atomic(out_dir / "ch4_results.json", summary)
    write_summary(out_dir, summary_markdown(summary, out_dir))
    return summary


def _summary(per: dict, chain: str, elapsed_s: float, figures: list[str]) -> dict:
    source = (
        "full chain: ImageSimulator frames (free space, noise) -> process_cube detections -> trackers"
        if chain == "full"
        else "detections synthesised from the simulated geometry (noise, SNR-based Pd, aliasing, clutter)"
    )
    tc = TrackerConfig()
    flat: dict = {
        "detections_source": source,
        "elapsed_s": elapsed_s,
        "truth_rule": (
            "from the scenario, not the detections: in front, in range and line of sight with expected "
            f"SNR >= {detection_threshold_snr_db(RadarConfig.prototype_2022()):.1f} dB (CA-CFAR Pd 50 %), "
            f"gaps <= {tc.max_coast_s:g} s bridged, spans with >= {tc.confirm_m} of {tc.confirm_n} frames"
        ),
    }
    ok_innov = ok_tracks = True
    per_model = (
        "tracks",
        "false_tracks",
        "fragmentation",
        "missed_truth_tracks",
        "completeness",
        "innov_mean",
        "innov_p95",
        "gospa",
    )
    for name, r in per.items():
        keys = ["truth_tracks", "id_switches_radar"]
        for key in keys + [f"{k}_{m}" for k in per_model for m in ("radar", "traditional")]:
            flat[f"{name}_{key}"] = r[key]
        ok_innov &= r["innov_p95_radar"] < r["innov_p95_traditional"]
        ok_tracks &= r["tracks_radar"] <= r["tracks_traditional"]
    flat["radar_p95_below_traditional_all"] = bool(ok_innov)
    flat["radar_tracks_at_most_traditional_all"] = bool(ok_tracks)
    flat["scenarios"] = per
    flat["thesis"] = THESIS
    flat["figures"] = figures
    return flat


_FIGURES = {
    "ch4_tracks_range_doppler.png": "both trackers' tracks over the detections in range and Doppler",
    "ch4_tracks_body.png": "radar-aware tracks over the visible truth, own-ship's horizontal body frame",
    "ch4_innovation_hist.png": "innovation distance of both trackers, in pixels",
}
_DATA = {
    "ch4_results.csv": "one row per scenario: every count and metric of both trackers",
    "ch4_results.json": "every measured value, with the thesis' numbers",
    "detections_<scenario>.parquet": "the detections both trackers got",
    "tracks_<scenario>_<model>.parquet": "the tracks of each tracker (`radar`, `traditional`)",
}


def summary_markdown(summary: dict, out_dir: Path | None = None) -> str:
    """``summary.md`` of a ch4 run: radar-aware against traditional tracking, beside the thesis' counts.

    Parameters
    ----------
    summary : dict
        The summary :func:`run` returns (also in ``ch4_results.json``): ``scenarios`` per scenario,
        ``thesis`` (:data:`THESIS`), ``figures``.
    out_dir : Path, optional
        The run's folder: only the files present there are listed (None: all of them).

    Returns
    -------
    str
        Markdown: title, sentences, one table row per scenario, the files.

    Examples
    --------
    >>> per = {"truth_tracks": 12, "tracks_radar": 13, "tracks_traditional": 30, "false_tracks_radar": 0,
    ...        "false_tracks_traditional": 9, "missed_truth_tracks_radar": 1, "completeness_radar": 0.93,
    ...        "innov_p95_radar": 3.1, "innov_p95_traditional": 6.4}
    >>> s = {"scenarios": {"free": per}, "thesis": THESIS, "figures": ["ch4_tracks_body.png"],
    ...      "detections_source": "full chain", "radar_p95_below_traditional_all": True,
    ...      "radar_tracks_at_most_traditional_all": True, "seed": 0}
    >>> text = summary_markdown(s)
    >>> print(text.splitlines()[0])
    # ch4: radar-aware against traditional tracking
    >>> "| free | 12 (12) | 13 (13) | 30 (54) | 0 / 9 | 3.1 (10.7) | 6.4 (14.4) |" in text
    True
    >>> "`ch4_tracks_body.png`" in text, "`ch4_innovation_hist.png`" in text
    (True, False)
    """
    per, thesis = summary["scenarios"], summary["thesis"]
    rows = []
    for name, r in per.items():
        t = thesis.get(name, {"innov_p95": (None, None), "tracks": (None, None), "truth": None})
        rows.append(
            [
                name,
                beside(r["truth_tracks"], t["truth"]),
                beside(r["tracks_radar"], t["tracks"][1]),
                beside(r["tracks_traditional"], t["tracks"][0]),
                f"{r['false_tracks_radar']} / {r['false_tracks_traditional']}",
                beside(r["innov_p95_radar"], t["innov_p95"][1]),
                beside(r["innov_p95_traditional"], t["innov_p95"][0]),
            ]
        )
    header = [
        "scenario",
        "true tracks (thesis, by hand)",
        "radar-aware tracks (thesis)",
        "traditional tracks (thesis)",
        "false tracks radar-aware / traditional",
        "innovation p95 radar-aware [px] (thesis)",
        "innovation p95 traditional [px] (thesis)",
    ]
    fewer = (
        "in every scenario" if summary["radar_tracks_at_most_traditional_all"] else "not in every scenario"
    )
    tighter = "in every scenario" if summary["radar_p95_below_traditional_all"] else "not in every scenario"
    sentences = " ".join(
        f"{name}: {r['tracks_radar']} radar-aware and {r['tracks_traditional']} traditional tracks for "
        f"{r['truth_tracks']} true tracks, {r['missed_truth_tracks_radar']} of them missed by the "
        f"radar-aware tracker (completeness {number(r['completeness_radar'], 2)})."
        for name, r in per.items()
    )
    paragraphs = [
        f"{counted(len(per), 'own-ship flight')} around an airfield with VFR intruders, both trackers "
        f"on the same detections, seed {summary['seed']}: {summary['detections_source']}. True tracks come "
        "from the scenario, never from the detections.",
        f"The radar-aware tracker makes at most as many tracks as the traditional one {fewer}, and its "
        f"95th-percentile innovation is smaller {tighter}. {sentences} The thesis' numbers are in "
        "brackets in the table.",
    ]
    files = {name: _FIGURES.get(name, "figure") for name in summary["figures"]} | _DATA
    return page("ch4: radar-aware against traditional tracking", paragraphs, header, rows, files, out_dir)
