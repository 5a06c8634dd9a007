"""Experiment ch4 plumbing on a short geometry-chain run (the full run is `skyradar experiment ch4`)."""

import json

import numpy as np

from skyradar.experiments.ch4 import run
from skyradar.experiments.ch4_flights import build_traffic, fly


def test_fly_turn_is_round_and_speed_clipped():
    tr = fly(np.zeros(3), 0.0, 50.0, [(36.0, 0.0, 10.0, 0.0)])  # 360 deg at 10 deg/s
    assert np.linalg.norm(tr.position_ned_m[-1] - tr.position_ned_m[0]) < 5.0
    fast = fly(np.zeros(3), 0.0, 80.0, [(20.0, 2.0, 0.0, 0.0)])
    assert np.linalg.norm(fast.velocity_ned_mps[-1]) <= 85.0 + 1e-9


def test_traffic_is_reproducible_and_in_ga_speed_range():
    a, b = build_traffic("free", 5.0, 10.0), build_traffic("free", 5.0, 10.0)
    np.testing.assert_array_equal(a.intruders[3].position_ned_m, b.intruders[3].position_ned_m)
    speeds = np.concatenate([np.linalg.norm(i.velocity_ned_mps[:, :2], axis=1) for i in a.intruders])
    assert speeds.min() >= 35.0 and speeds.max() <= 85.0 + 1e-9


def test_short_geometry_run_writes_tables_and_figures(tmp_path):
    res = run(tmp_path, chain="geometry", interval_s=4.0, tail_s=40.0, workers=1, scenarios=("free",))
    assert "synthesised" in res["detections_source"]
    keys = (
        "truth_tracks",
        "tracks_radar",
        "tracks_traditional",
        "innov_mean_radar",
        "innov_p95_radar",
        "innov_mean_traditional",
        "innov_p95_traditional",
        "gospa_radar",
        "gospa_traditional",
    )
    for key in keys:
        assert key in res["scenarios"]["free"]
    assert res["free_truth_tracks"] >= 1
    saved = json.loads((tmp_path / "ch4_results.json").read_text())
    assert saved["free_tracks_radar"] == res["free_tracks_radar"]
    for name in res["figures"]:
        assert (tmp_path / name).stat().st_size > 10_000
    assert (tmp_path / "tracks_free_radar.parquet").exists()
    assert "`tracks_<scenario>_<model>.parquet`" in (tmp_path / "summary.md").read_text()


def test_bench_track_reports_ours_baseline_and_ratio():
    from skyradar.benchmarks.track import run as bench

    r = bench(n_frames=15, detections_per_frame=40, n_targets=3, baseline_frames=3)
    for key in ("frames_per_s", "cpu_frames_per_s", "baseline_frames_per_s", "speedup_same_frames"):
        assert r[key] > 0
    assert 30 <= r["detections_per_frame"] <= 50
    assert r["own_speed_mps"] == 50.0  # the range walks run, as in the chain
