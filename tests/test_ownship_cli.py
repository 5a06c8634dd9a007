"""`track --ownship` and `alert --ownship` take the same inputs (the run, or a table such as `skyradar
export`'s), read the navigation solution (nav_*) and never the truth beside it; the origin comes from
the store; `alert --config radar|default|FILE.yaml`."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from cli_helpers import assert_one_line_error, skyradar, skyradar_in_process
from skyradar.daa.alert_config import alert_config
from skyradar.daa.alerting import RADAR_ALERT_CONFIG, AlertConfig
from skyradar.errors import InputError
from skyradar.io.frames import FrameStoreWriter
from skyradar.io.frames_model import frame_times_s
from skyradar.web.sample import sample_run_dataset

NAV_BIAS_M = 400.0  # navigation north error: big enough to move the warnings
_STATE = ("north_m", "east_m", "down_m", "vn_mps", "ve_mps", "vd_mps")


def _write_run(path, bias_m: float):
    ds = sample_run_dataset(n_frames=50)
    nav = {f"nav_{c}": ds[f"own_{c}"] + (bias_m if c == "north_m" else 0.0) for c in _STATE}
    ds = ds.assign(nav).assign_attrs(origin_lat_deg=47.0, origin_lon_deg=11.0, origin_alt_m=500.0)
    writer = FrameStoreWriter(path, ds.assign(iq=ds["iq"].chunk({"time": 25})), 25, fingerprint="own-test")
    for k in writer.pending_chunks():
        writer.write_chunk(k, ds["iq"].values[writer.chunk_slice(k)])
    writer.close()
    return ds


def _detections(ds) -> pd.DataFrame:
    """Noise-free detections of the visible intruders (absolute NED, range and range rate)."""
    t = frame_times_s(ds)
    rows = []
    for k in range(ds.sizes["target"]):
        vis = ds["tgt_visible"].values[:, k]
        rows.append(
            pd.DataFrame(
                {
                    "time_s": t[vis],
                    "range_m": ds["tgt_range_m"].values[vis, k],
                    "radial_velocity_mps": ds["tgt_radial_velocity_mps"].values[vis, k],
                    **{c: ds[f"tgt_{c}"].values[vis, k] for c in ("north_m", "east_m", "down_m")},
                }
            )
        )
    return pd.concat(rows).sort_values("time_s", kind="stable").reset_index(drop=True)


def test_run_and_table_give_the_same_tracks_and_alerts_from_navigation(tmp_path, monkeypatch, capsys):
    ds = _write_run(tmp_path / "run.zarr", NAV_BIAS_M)
    _write_run(tmp_path / "true_nav.zarr", 0.0)
    _detections(ds).to_parquet(tmp_path / "det.parquet")
    assert (
        skyradar_in_process(
            monkeypatch, capsys, "export", str(tmp_path / "run.zarr"), "-o", str(tmp_path / "tables")
        )[0]
        == 0
    )
    table = tmp_path / "tables" / "ownship.parquet"
    results = {}
    for name, own in (("run", tmp_path / "run.zarr"), ("table", table), ("true", tmp_path / "true_nav.zarr")):
        trk, alerts = tmp_path / f"trk_{name}.parquet", tmp_path / f"al_{name}.parquet"
        code, out, err = skyradar_in_process(
            monkeypatch,
            capsys,
            "track",
            str(tmp_path / "det.parquet"),
            "--ownship",
            str(own),
            "-o",
            str(trk),
            "--json",
        )
        assert code == 0, err
        results[name] = json.loads(out.strip().splitlines()[-1])
        code, out, err = skyradar_in_process(
            monkeypatch, capsys, "alert", str(trk), "--ownship", str(own), "-o", str(alerts), "--json"
        )
        assert code == 0, err
        results[name] |= json.loads(out.strip().splitlines()[-1])
        results[name] |= {"alerts_df": pd.read_parquet(alerts), "tracks_df": pd.read_parquet(trk)}
    run, tab, true = results["run"], results["table"], results["true"]
    pd.testing.assert_frame_equal(run["tracks_df"], tab["tracks_df"])
    pd.testing.assert_frame_equal(run["alerts_df"], tab["alerts_df"])
    assert (
        run["origin_from"] == f"--ownship {tmp_path / 'run.zarr'}"
        and tab["origin_from"] == f"--ownship {table}"
    )
    assert np.isfinite(run["tracks_df"]["lat_deg"]).all()  # the store's origin put the tracks on the map
    assert run["config"] == "radar"
    # The navigation error reached the alerts: with the truth as navigation the warning comes otherwise.
    assert run["first_warning_s"] != true["first_warning_s"]


def test_alert_config_names_and_file(tmp_path):
    assert alert_config("radar") is RADAR_ALERT_CONFIG and alert_config("default") == AlertConfig()
    good = tmp_path / "a.yaml"
    good.write_text("base: default\nm: 3\nn: 5\nperiod_s: null\nflarm_thresholds_s: [20, 15, 10]\n")
    cfg = alert_config(good)
    assert (cfg.m, cfg.n, cfg.period_s, cfg.flarm_thresholds_s) == (3, 5, None, (20.0, 15.0, 10.0))
    assert cfg.max_velocity_sigma_mps is None  # from base: default
    assert alert_config(tmp_path / "a.yaml").levels == AlertConfig().levels
    for text, needle in [
        ("m: 5\nn: 4\n", "need 1 <= m <= n"),
        ("hysteresis_s: -1\n", "field 'hysteresis_s': must be a finite number from 0 to 1e+06, got -1"),
        ("m: 2.5\n", "field 'm': must be an integer from 1 to 1e+06"),
        ("persistance_s: 4\n", "field 'persistance_s' is not an alert setting"),
        ("levels: [{name: warning, dthr_m: 600}]\n", "field 'levels'.0: must have name"),
        ("base: fast\n", "field 'base' must be radar, default or do365b"),
        ("[1, 2\n", "not valid YAML"),
    ]:
        (tmp_path / "b.yaml").write_text(text)
        with pytest.raises(InputError, match="b.yaml") as info:
            alert_config(tmp_path / "b.yaml")
        assert needle in str(info.value) and "\n" not in str(info.value), str(info.value)


def test_alert_bad_config_through_the_real_entry_point(tmp_path):
    (tmp_path / "alerts.yaml").write_text("z_h_pos: .nan\n")
    result = skyradar(
        "alert",
        "trk.parquet",
        "--ownship",
        "run.zarr",
        "-o",
        "al.parquet",
        "--config",
        "alerts.yaml",
        cwd=tmp_path,
    )
    assert_one_line_error(result, "alerts.yaml: field 'z_h_pos'", "nan")


def test_text_in_an_own_ship_column_is_one_line_through_the_real_entry_point(tmp_path):
    # Non-numeric columns of an own-ship table were dropped silently: a text own_height_agl_m took
    # the ground's range-Doppler band away (track.elevation_trust) without a word.
    t = np.arange(5) / 9.4
    pd.DataFrame({"time_s": t, "range_m": 1500.0 - 40 * t, "radial_velocity_mps": -40.0}).to_parquet(
        tmp_path / "d.parquet"
    )
    own = {
        c: 0.0 * t
        for c in ("own_north_m", "own_east_m", "own_down_m", "own_vn_mps", "own_ve_mps", "own_vd_mps")
    }
    table = pd.DataFrame({"time_s": t, **own, "own_height_agl_m": ["500", "high", "500", "500", "500"]})
    table.to_parquet(tmp_path / "own.parquet")
    result = skyradar("track", "d.parquet", "-o", "t.parquet", "--ownship", "own.parquet", cwd=tmp_path)
    assert_one_line_error(result, "own.parquet", "'own_height_agl_m'", "row 1", "'high'")
    assert not (tmp_path / "t.parquet").exists()
