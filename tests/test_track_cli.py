"""`skyradar track` and `skyradar evaluate` end to end, and their bad-input errors."""

import json

import numpy as np
import pandas as pd
import pytest

from cli_helpers import skyradar_in_process
from skyradar.config import RadarConfig
from skyradar.io.frames import frames_dataset
from skyradar.track.simulated_detections import synthetic_detections


def _scene(cfg, n=120, dt=0.106):
    t = np.arange(n) * dt
    V = np.column_stack([np.full(n, -50.0), 20.0 + 10.0 * np.sin(t)])
    R = np.column_stack([550.0 + V[:, 0] * t, 120.0 + np.cumsum(V[:, 1]) * dt])
    return t, R, V


def test_track_then_evaluate_against_run_truth(tmp_path, monkeypatch, capsys):
    cfg = RadarConfig.prototype_2022(range_limit_m=600.0, n_doppler=16)
    t, R, V = _scene(cfg)
    vis = (R > 30) & (R < 590)
    det = synthetic_detections(t, R, V, vis, cfg, pd_detect=0.95, clutter_per_frame=1, seed=3)
    det_path = tmp_path / "det.parquet"
    det.attrs["radar_config"] = cfg.to_json()
    det.to_parquet(det_path)
    iq = np.zeros((t.size, cfg.n_range, cfg.n_doppler, cfg.n_rx), np.complex64)
    targets = {"tgt_range_m": R, "tgt_radial_velocity_mps": V, "tgt_visible": vis}
    frames_dataset(iq, t, cfg, targets=targets).to_zarr(tmp_path / "run.zarr", consolidated=False)
    code, out, err = skyradar_in_process(
        monkeypatch, capsys, "track", str(det_path), "-o", str(tmp_path / "trk.parquet"), "--json"
    )
    assert code == 0, err
    assert json.loads(out.strip().splitlines()[-1])["tracks"] >= 2
    code, out, err = skyradar_in_process(
        monkeypatch, capsys, "evaluate", str(tmp_path / "run.zarr"), str(tmp_path / "trk.parquet"), "--json"
    )
    assert code == 0, err
    res = json.loads(out.strip().splitlines()[-1])
    assert res["truth_tracks"] == 2 and res["tracks"] == 2
    assert res["id_switches"] == 0 and res["fragmentation"] == 0
    for key in ("gospa_mean", "innov_mean_px", "innov_p95_px", "completeness"):
        assert np.isfinite(res[key])


def test_track_bad_inputs_give_one_line_errors(tmp_path, monkeypatch, capsys):
    bad = tmp_path / "bad.parquet"
    pd.DataFrame({"time_s": [0.0, 0.1], "range_m": [1.0, 2.0]}).to_parquet(bad)
    code, _, err = skyradar_in_process(
        monkeypatch, capsys, "track", str(bad), "-o", str(tmp_path / "x.parquet")
    )
    assert code == 2
    assert err.startswith("error: ") and "radial_velocity_mps" in err and str(bad) in err
    assert len(err.strip().splitlines()) == 1
    back = tmp_path / "back.csv"
    pd.DataFrame({"time_s": [0.0, 0.2, 0.1], "range_m": [1.0] * 3, "radial_velocity_mps": [0.0] * 3}).to_csv(
        back
    )
    code, _, err = skyradar_in_process(
        monkeypatch, capsys, "track", str(back), "-o", str(tmp_path / "x.parquet")
    )
    assert code == 2 and "'time_s' goes backwards at row 2 (0.2 -> 0.1)" in err
    code, _, err = skyradar_in_process(
        monkeypatch, capsys, "track", str(back), "-o", str(tmp_path / "x.parquet"), "--model", "kf"
    )
    assert code == 2 and "--model" in err
    assert not (tmp_path / "x.parquet").exists()


@pytest.mark.parametrize("missing", ["tgt_visible"])
def test_evaluate_without_truth_is_clear_error(tmp_path, monkeypatch, capsys, missing):
    cfg = RadarConfig.prototype_2022(range_limit_m=300.0, n_doppler=8)
    iq = np.zeros((3, cfg.n_range, cfg.n_doppler, cfg.n_rx), np.complex64)
    frames_dataset(iq, np.arange(3.0), cfg).to_zarr(tmp_path / "run.zarr", consolidated=False)
    trk = tmp_path / "t.parquet"
    pd.DataFrame(
        {
            "time_s": [0.0],
            "track_id": [0],
            "range_m": [1.0],
            "radial_velocity_mps": [0.0],
            "innovation_range_m": [0.0],
            "innovation_radial_velocity_mps": [0.0],
        }
    ).to_parquet(trk)
    code, _, err = skyradar_in_process(monkeypatch, capsys, "evaluate", str(tmp_path / "run.zarr"), str(trk))
    assert code == 2 and missing in err and "run.zarr" in err


def test_evaluate_refuses_tracks_outside_the_runs_frames(tmp_path):
    """Tracks 10,000 s after the run's frames are not its tracks: one line, exit 2."""
    from cli_helpers import assert_one_line_error, skyradar

    cfg = RadarConfig.prototype_2022(range_limit_m=600.0, n_doppler=16)
    t, R, V = _scene(cfg, n=30)
    iq = np.zeros((t.size, cfg.n_range, cfg.n_doppler, cfg.n_rx), np.complex64)
    targets = {"tgt_range_m": R, "tgt_radial_velocity_mps": V, "tgt_visible": np.ones_like(R, bool)}
    frames_dataset(iq, t, cfg, targets=targets).to_zarr(tmp_path / "run.zarr", consolidated=False)
    rows = pd.DataFrame(
        {
            "time_s": t + 10_000.0,
            "track_id": 1,
            "range_m": R[:, 0],
            "radial_velocity_mps": V[:, 0],
            "innovation_range_m": 0.0,
            "innovation_radial_velocity_mps": 0.0,
            "confirmed": True,
        }
    )
    rows.to_parquet(tmp_path / "late.parquet")
    result = skyradar("evaluate", "run.zarr", "late.parquet", cwd=tmp_path)
    assert_one_line_error(result, "late.parquet", "time_s", "outside the frames of run.zarr")
