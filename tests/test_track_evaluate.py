"""Completeness on the full chain: the tracker steps on every frame and `evaluate` scores against
what the radar could see.

Stepping only on frames holding a detection would leave a track without rows (and count no misses)
over a gap of frames without detections; counting every in-beam frame as truth would count frames far
below the detection threshold too. The completeness is checked against Stone Soup's SIAP
completeness (an independent implementation) on the same rows.
"""

from __future__ import annotations

import datetime as dt
import json

import numpy as np
import pandas as pd
import pytest
from stonesoup.dataassociator.tracktotrack import TrackToTruth  # a dev extra: missing is an error
from stonesoup.measures import Euclidean
from stonesoup.metricgenerator.manager import MultiManager
from stonesoup.metricgenerator.tracktotruthmetrics import SIAPMetrics
from stonesoup.types.groundtruth import GroundTruthPath, GroundTruthState
from stonesoup.types.state import State
from stonesoup.types.track import Track

from cli_helpers import assert_one_line_error, skyradar, skyradar_in_process
from skyradar.config import RadarConfig
from skyradar.io.frames import frames_dataset
from skyradar.track.detectable import detection_threshold_snr_db
from skyradar.track.frame_grid import frame_grid
from skyradar.track.io import Truth
from skyradar.track.metrics import existing_rows, track_metrics
from skyradar.track.simulated_detections import synthetic_detections
from skyradar.track.track_table import track_air_detections

CFG = RadarConfig.prototype_2022()
RATE_HZ = 9.4


def _siap_completeness(tracks: pd.DataFrame, truth: Truth, threshold_px: float) -> float:
    """Stone Soup's SIAP completeness of ``tracks`` against ``truth`` (pixel units, no Doppler wrap)."""
    t0 = dt.datetime(2026, 1, 1)

    def when(s: float) -> dt.datetime:
        return t0 + dt.timedelta(seconds=float(s))

    paths = set()
    for j in range(truth.visible.shape[1]):
        k = np.flatnonzero(truth.visible[:, j])
        paths.add(
            GroundTruthPath(
                [
                    GroundTruthState(
                        np.array([[truth.range_m[i, j]], [truth.radial_velocity_mps[i, j]]]),
                        timestamp=when(truth.time_s[i]),
                    )
                    for i in k
                ]
            )
        )
    tracks_ss = set()
    for _, rows in tracks.groupby("track_id"):
        xy = rows[["range_m", "radial_velocity_mps"]].to_numpy(float)
        tracks_ss.add(
            Track([State(v[:, None], timestamp=when(t)) for v, t in zip(xy, rows["time_s"], strict=True)])
        )
    siap = SIAPMetrics(position_measure=Euclidean((0, 1)), velocity_measure=Euclidean((0, 1)))
    # One pair within the threshold associates, one pair outside ends it: the per-frame rule.
    assoc = TrackToTruth(association_threshold=threshold_px, consec_pairs_confirm=1, consec_misses_end=1)
    manager = MultiManager([siap], assoc)
    manager.add_data({"groundtruth_paths": paths, "tracks": tracks_ss})
    return float(manager.generate_metrics()["siap_generator"]["SIAP Completeness"].value)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_completeness_equals_stone_soup_siap(seed):
    """Two aircraft far apart in the image; tracks with noise, late starts, coasted rows, a stretch
    off the aircraft, a truth gap and a false track. Stone Soup's association holds over a time
    interval, so every track has a row at every frame of its life (as the tracker gives)."""
    rng = np.random.default_rng(seed)
    t = np.arange(60) * 0.1
    r = np.column_stack([100 + 2 * t, 300 - 3 * t])
    v = np.column_stack([np.full(60, 10.0), np.full(60, -20.0)])
    vis = np.ones((60, 2), bool)
    vis[30:35, 1] = False
    rows = []
    for j, stop in enumerate((45, 60)):
        start, drift = rng.integers(0, 10), rng.integers(0, 6)
        for i in range(start, stop):
            off = 8.0 if 20 <= i < 20 + drift else rng.normal(0.0, 0.5)  # off the aircraft: not complete
            row = {"time_s": t[i], "track_id": j, "range_m": r[i, j] + off, "radial_velocity_mps": v[i, j]}
            rows.append(row | {"confirmed": i - start >= 4 and i % 7 != 0})  # tentative start, coasting
    for i in range(50, 54):  # a false track
        rows.append(
            {"time_s": t[i], "track_id": 9, "range_m": 500.0, "radial_velocity_mps": 0.0, "confirmed": True}
        )
    tracks = pd.DataFrame(rows).sort_values("time_s", kind="stable").reset_index(drop=True)
    tracks["innovation_range_m"] = tracks["innovation_radial_velocity_mps"] = 0.0
    truth = Truth(t, r, v, vis)
    kw = {"gap_s": 0.0, "min_duration_s": 0.0, "coasting": True}
    m = track_metrics(tracks, truth, (1.0, 1.0), None, 3.0, **kw)
    assert m["completeness"] == pytest.approx(_siap_completeness(tracks[existing_rows(tracks)], truth, 3.0))
    assert m["completeness_confirmed"] < m["completeness"] and m["false_tracks"] == 1


def test_tracker_steps_on_frames_without_any_detection():
    """Frame stepping (the deleter's clock): a 1.5 s stretch of frames with no detection at all still
    gives the track a row at each of those frames, coasted."""
    t = np.arange(0.0, 12.0, 1 / RATE_HZ)
    r = (2500.0 - 40.0 * t)[:, None]
    det = synthetic_detections(t, r, np.full_like(r, -40.0), config=CFG, sigma_range_m=4.4, seed=1)
    gap = (t >= 5.0) & (t < 6.5)
    det = det[~np.isin(det["frame"], np.flatnonzero(gap))].reset_index(drop=True)
    assert np.allclose(frame_grid(det), t, rtol=0, atol=1e-9)  # the frames without detections are back
    tracks, _ = track_air_detections(det, "radar", CFG)
    in_gap = tracks[np.isin(tracks["frame"], np.flatnonzero(gap))]
    assert len(in_gap) == gap.sum() and in_gap["coasted"].all() and tracks["track_id"].nunique() == 1
    assert np.array_equal(np.sort(tracks["frame"].unique()), np.arange(tracks["frame"].min(), t.size))
    truth = Truth(t, r, np.full_like(r, -40.0), np.ones_like(r, bool))
    pixel = (CFG.range_resolution_m, CFG.doppler_resolution_mps)
    m = track_metrics(tracks, truth, pixel, 2 * CFG.v_lim_mps, coasting=True)
    assert m["completeness"] > 0.95 and m["completeness_confirmed"] < m["completeness"]
    assert m["tracks_per_target"] == [1]


def _run_with_snr(tmp_path, snr_db: np.ndarray, t: np.ndarray, r: np.ndarray, v: np.ndarray):
    cfg = RadarConfig.prototype_2022(range_limit_m=3000.0, n_doppler=64)
    iq = np.zeros((t.size, cfg.n_range, cfg.n_doppler, cfg.n_rx), np.complex64)
    targets = {
        "tgt_range_m": r,
        "tgt_radial_velocity_mps": v,
        "tgt_visible": np.ones_like(r, bool),
        "tgt_snr_db": snr_db,
    }
    frames_dataset(iq, t, cfg, targets=targets).to_zarr(tmp_path / "run.zarr", consolidated=False)
    return cfg


def test_evaluate_truth_is_what_the_radar_could_see(tmp_path, monkeypatch, capsys):
    """Truth: an aircraft in the beam for 12 s, its expected SNR below the CA-CFAR threshold for the
    first 6 (no detections there, as a CFAR would give). Scored on the beam, completeness is about 0.5."""
    t = np.arange(0.0, 12.0, 1 / RATE_HZ)
    r, v = (2500.0 - 30.0 * t)[:, None], np.full((t.size, 1), -30.0)
    snr = np.where(t < 6.0, 2.0, 15.0)[:, None]
    cfg = _run_with_snr(tmp_path, snr, t, r, v)
    det = synthetic_detections(t, r, v, visible=snr >= 7.5, config=cfg, sigma_range_m=4.4, seed=2)
    det.attrs["radar_config"] = cfg.to_json()
    det.to_parquet(tmp_path / "det.parquet")
    code, _, err = skyradar_in_process(
        monkeypatch, capsys, "track", str(tmp_path / "det.parquet"), "-o", str(tmp_path / "trk.parquet")
    )
    assert code == 0, err
    results = {}
    for mode in ("detectable", "beam"):
        code, out, err = skyradar_in_process(
            monkeypatch,
            capsys,
            "evaluate",
            str(tmp_path / "run.zarr"),
            str(tmp_path / "trk.parquet"),
            "--truth",
            mode,
            "--json",
        )
        assert code == 0, err
        results[mode] = json.loads(out.strip().splitlines()[-1])
    good, beam = results["detectable"], results["beam"]
    assert good["truth_snr_threshold_db"] == pytest.approx(detection_threshold_snr_db(cfg))
    assert good["completeness"] > 0.9 and good["tracks_per_target"] == [1] and good["false_tracks"] == 0
    assert beam["completeness"] < 0.55


def test_evaluate_bad_options_one_line(tmp_path):
    for args, needle in ((["--truth", "seen"], "--truth"), (["--min-snr-db", "nan"], "--min-snr-db")):
        result = skyradar("evaluate", "run.zarr", "trk.parquet", *args, cwd=tmp_path)
        assert_one_line_error(result, needle)


def test_truth_of_several_heads_is_their_union(tmp_path):
    """Several heads: a target is truth where any head sees it, with the strongest head's values."""
    from skyradar.io.frames_heads import write_heads_root
    from skyradar.track.io import truth_from_frames

    cfg = RadarConfig.prototype_2022(range_limit_m=600.0, n_doppler=8)
    t = np.arange(6) * 0.1
    iq = np.zeros((t.size, cfg.n_range, cfg.n_doppler, cfg.n_rx), np.complex64)
    first = (t < 0.3)[:, None]
    write_heads_root(tmp_path / "run.zarr", {}, ["left", "nose"])
    for name, vis, r, snr in (("left", first, 100.0, 9.0), ("nose", ~first, 101.0, 12.0)):
        targets = {
            "tgt_range_m": np.full((t.size, 1), r),
            "tgt_radial_velocity_mps": np.zeros((t.size, 1)),
            "tgt_visible": vis,
            "tgt_snr_db": np.where(vis, snr, -30.0),
        }
        frames_dataset(iq, t, cfg, targets=targets).to_zarr(
            tmp_path / "run.zarr", group=name, consolidated=False
        )
    truth, _ = truth_from_frames(tmp_path / "run.zarr")
    assert truth.visible[:, 0].all()
    assert truth.range_m[:, 0].tolist() == [100.0] * 3 + [101.0] * 3
    assert truth.snr_db[:, 0].tolist() == [9.0] * 3 + [12.0] * 3
