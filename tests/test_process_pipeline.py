"""Frames -> detections table: world positions against truth, ground flag, bad input, CLI."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from hypothesis import given
from hypothesis import strategies as st

from cli_helpers import skyradar_in_process as run_cli
from skyradar.benchmarks.process import synthetic_frame
from skyradar.config import Mount, RadarConfig
from skyradar.errors import InputError
from skyradar.geo import direction_angles, ned_rotation_to, ned_to_geodetic, rotation_matrix
from skyradar.io.frames import frames_dataset
from skyradar.process.pipeline import DETECTION_COLUMNS, process_frames
from skyradar.process.realtime import paced_latencies
from skyradar.process.smoothing import hann_smooth, hann_window
from skyradar.process.spurs import SpurMap
from skyradar.scene.synthetic_terrain import flat_terrain

ORIGIN = (52.0, 4.0, 0.0)
CFG = RadarConfig.prototype_2022(mount=Mount.preset("forward-down"))


def scene(n_frames=3, seed=0):
    """Own-ship at 1000 m turning and climbing; an aircraft and a ground point, exact geometry."""
    rng = np.random.default_rng(seed)
    times = np.arange(n_frames) * 0.1
    own = np.array([[300.0 + 40 * t, -200.0, -1000.0] for t in times])
    att = np.array([[np.radians(20.0), np.radians(4.0), np.radians(10.0)]] * n_frames)
    own_v = np.array([40.0, 0.0, 0.0])
    lat, lon, alt = ned_to_geodetic(own, *ORIGIN)
    aircraft = np.array([2300.0, 700.0, -1150.0])
    cubes, truth = [], []
    for i in range(n_frames):
        body_to_ned = ned_rotation_to(ORIGIN[0], ORIGIN[1], lat[i], lon[i]).T @ rotation_matrix(*att[i])
        ant_to_ned = body_to_ned @ CFG.mount.rotation
        antenna = own[i] + body_to_ned @ np.array(CFG.mount.position_m)
        ground = antenna + ant_to_ned @ (1800.0 * np.array([np.cos(0.2), 0.1, np.sin(0.2)]))
        ground[2] = 0.0  # on the terrain
        targets = []
        for p, v in ((aircraft, np.array([-50.0, 0.0, 0.0])), (ground, np.zeros(3))):
            p_ant = ant_to_ned.T @ (p - antenna)
            rng_m, az, el = direction_angles(p_ant)
            v_r = (v - own_v) @ (p - antenna) / np.linalg.norm(p - antenna)
            targets.append((float(rng_m), float(v_r), float(az), float(el), 40.0))
        cubes.append(synthetic_frame(CFG, targets, rng)[0])
        truth.append((aircraft, ground))
    ownship = {
        "own_north_m": own[:, 0],
        "own_east_m": own[:, 1],
        "own_down_m": own[:, 2],
        "own_vn_mps": np.full(n_frames, own_v[0]),
        "own_ve_mps": np.zeros(n_frames),
        "own_vd_mps": np.zeros(n_frames),
        "own_lat_deg": lat,
        "own_lon_deg": lon,
        "own_alt_m": alt,
        "own_yaw_rad": att[:, 0],
        "own_pitch_rad": att[:, 1],
        "own_roll_rad": att[:, 2],
    }
    attrs = {"origin_lat_deg": ORIGIN[0], "origin_lon_deg": ORIGIN[1], "origin_alt_m": ORIGIN[2]}
    return frames_dataset(np.stack(cubes), times, CFG, ownship=ownship, attrs=attrs), truth


def test_world_positions_match_truth_and_ground_is_flagged():
    ds, truth = scene()
    terrain = flat_terrain(*ORIGIN[:2], height_m=0.0, size_m=8000.0, spacing_m=60.0)
    table = process_frames(ds, terrain=terrain)
    assert list(table.columns) == DETECTION_COLUMNS
    assert len(table) == 2 * ds.sizes["time"]
    for frame, (aircraft, ground) in enumerate(truth):
        rows = table[table.frame == frame]
        ned = rows[["north_m", "east_m", "down_m"]].to_numpy()
        for point, is_ground in ((aircraft, False), (ground, True)):
            err = np.linalg.norm(ned - point, axis=1)
            k = int(np.argmin(err))
            # Range quantisation (7.5 m) and 40 dB DoA noise (0.1 deg at 2 km = 4 m).
            assert err[k] < 15.0
            assert bool(rows.is_ground.iloc[k]) is is_ground
        lat, lon, alt = ned_to_geodetic(ned, *ORIGIN)
        np.testing.assert_allclose(rows.lat_deg, lat, atol=1e-9)
        np.testing.assert_allclose(rows.alt_m, alt, atol=1e-3)
        # The right axis is the one the azimuth is measured about: the direction cosine along it of
        # each true point, seen from the antenna, is sin(azimuth) cos(elevation).
        right = rows[["right_axis_north", "right_axis_east", "right_axis_down"]].to_numpy()
        np.testing.assert_allclose(np.linalg.norm(right, axis=1), 1.0, atol=1e-12)
        for point in (aircraft, ground):
            k = int(np.argmin(np.linalg.norm(ned - point, axis=1)))
            own = np.array([ds[f"own_{a}_m"].values[frame] for a in ("north", "east", "down")])
            sight = (point - own) / np.linalg.norm(point - own)
            az, el = rows.azimuth_rad.iloc[k], rows.elevation_rad.iloc[k]
            assert abs(sight @ right[k] - np.sin(az) * np.cos(el)) < 0.01


def test_body_frame_without_ownship_and_nan_world():
    ds, _ = scene(n_frames=1)
    bare = ds.drop_vars([v for v in ds.data_vars if v.startswith("own_")])
    table = process_frames(bare)
    assert np.isnan(table.north_m).all() and np.isnan(table.lat_deg).all()
    assert not table.is_ground.any()
    body = table[["x_body_m", "y_body_m", "z_body_m"]].to_numpy()
    np.testing.assert_allclose(
        np.linalg.norm(body - np.array(CFG.mount.position_m), axis=1), table.range_m, rtol=1e-9
    )


def test_spur_map_masks_or_flags():
    ds, _ = scene(n_frames=1)
    table = process_frames(ds)
    mask = np.zeros((CFG.n_range, CFG.n_doppler), np.float32)
    first = table.iloc[0]
    mask[int(round(first.range_bin)), int(round(first.doppler_bin)) % CFG.n_doppler] = 1.0
    spurs = SpurMap(mask, 0.5, 10)
    masked = process_frames(ds, spurs)
    flagged = process_frames(ds, spurs, spur_mode="flag")
    assert len(masked) == len(table) - 1 and not masked.spur.any()
    assert len(flagged) == len(table) and flagged.spur.sum() == 1


def test_bad_input():
    ds, _ = scene(n_frames=1)
    with pytest.raises(InputError, match="empty run"):
        process_frames(ds.isel(time=slice(0, 0)))
    with pytest.raises(InputError, match="'rx' has 3"):
        process_frames(ds.isel(rx=slice(0, 3)))
    with pytest.raises(InputError, match="spur map"):
        process_frames(ds, SpurMap(np.zeros((5, 5)), 0.5, 1))


def test_cli_process_writes_the_table_and_reports_bad_input(tmp_path, monkeypatch, capsys):
    ds, _ = scene(n_frames=2)
    ds.to_zarr(tmp_path / "run.zarr", consolidated=False)
    out = tmp_path / "det.parquet"
    code, stdout, _ = run_cli(monkeypatch, capsys, "process", tmp_path / "run.zarr", "-o", out, "--json")
    assert code == 0
    table = pd.read_parquet(out)
    assert list(table.columns) == [*DETECTION_COLUMNS, "radar"] and len(table) == 4
    assert set(table["radar"]) == {"radar"}  # one head: its default name
    assert '"detections": 4' in stdout.strip().splitlines()[-1]
    # A spur map learned from the same frames masks both objects.
    spur_map = ("spur-map", tmp_path / "run.zarr", "-o", tmp_path / "s.npz", "--threshold", 0.4)
    assert run_cli(monkeypatch, capsys, *spur_map)[0] == 0
    masked = ("process", tmp_path / "run.zarr", "-o", out, "--spur-map", tmp_path / "s.npz")
    assert run_cli(monkeypatch, capsys, *masked)[0] == 0
    assert len(pd.read_parquet(out)) == 0
    ds.isel(rx=slice(0, 3)).to_zarr(tmp_path / "bad.zarr", consolidated=False)
    code, _, stderr = run_cli(monkeypatch, capsys, "process", tmp_path / "bad.zarr", "-o", out)
    assert code == 2 and stderr.startswith("error: ")
    assert run_cli(monkeypatch, capsys, "process", tmp_path / "missing.zarr", "-o", out)[0] == 2


CH3_KEYS = (
    "az_sd_deg",
    "el_sd_deg",
    "az_crlb_deg",
    "el_crlb_deg",
    "dist_mean_m",
    "calib_phase_err_deg",
    "detected_frames",
    "frames",
    "false_alarms_per_frame",
)


def test_ch3_experiment_smoke(tmp_path):
    from skyradar.experiments.ch3 import run

    result = run(tmp_path, n_frames=8, n_static=10)
    assert all(k in result for k in CH3_KEYS)
    assert result["calib_phase_err_deg"] <= 1.0
    assert result["detected_frames"] >= 7 and result["false_alarms_per_frame"] <= 0.01
    for name in ("ch3_range_doppler.png", "ch3_track_3d.png", "ch3_errors.png", "ch3.json", "ch3_table.csv"):
        assert (tmp_path / name).exists()


def test_cli_calibrate_then_process_with_the_calibrated_config(tmp_path, monkeypatch, capsys):
    from skyradar.process.calibration import calibration_phase_error_deg

    cfg = RadarConfig.prototype_2022()
    rng = np.random.default_rng(7)
    offsets = np.exp(1j * np.radians([0.0, 70.0, -120.0, 160.0]))
    building = (438.0, 0.0, np.radians(5.0), np.radians(-1.0), 45.0)
    aircraft = (1500.0, 20.0, np.radians(-12.0), np.radians(8.0), 35.0)
    cubes = np.stack([synthetic_frame(cfg, [building, aircraft], rng, rx_gain=offsets)[0] for _ in range(4)])
    frames_dataset(cubes, np.arange(4) * 0.1, cfg).to_zarr(tmp_path / "run.zarr", consolidated=False)
    args = ["--range-m", 438, "--azimuth-deg", 5, "--elevation-deg", -1]
    calibrate = ("calibrate", tmp_path / "run.zarr", "-o", tmp_path / "radar.json", *args)
    assert run_cli(monkeypatch, capsys, *calibrate)[0] == 0
    cal = RadarConfig.from_json((tmp_path / "radar.json").read_text())
    assert calibration_phase_error_deg(cal.rx_calibration, offsets) <= 1.0
    out = tmp_path / "det.parquet"
    calibrated = ("process", tmp_path / "run.zarr", "-o", out, "--radar-config", tmp_path / "radar.json")
    assert run_cli(monkeypatch, capsys, *calibrated)[0] == 0
    table = pd.read_parquet(out)
    plane = table[np.abs(table.range_m - 1500.0) < 10]
    assert len(plane) == 4
    assert np.degrees(np.abs(plane.azimuth_rad + np.radians(12.0))).max() < 1.0
    assert np.degrees(np.abs(plane.elevation_rad - np.radians(8.0))).max() < 1.0
    wide = ["--range-m", 438, "--azimuth-deg", 80, "--elevation-deg", 0]
    x_json = tmp_path / "x.json"
    code, _, stderr = run_cli(monkeypatch, capsys, "calibrate", tmp_path / "run.zarr", "-o", x_json, *wide)
    assert code == 2 and "field of view" in stderr


def test_simulated_flight_over_flat_ground_separates_terrain_from_the_intruder():
    from skyradar.sim.image import ImageSimulator, PlatformState, PointTarget

    cfg = RadarConfig.prototype_2022(mount=Mount.preset("forward-down"))
    terrain = flat_terrain(*ORIGIN[:2], height_m=0.0, size_m=10000.0, spacing_m=60.0)
    sim = ImageSimulator(cfg, terrain, origin=ORIGIN, seed=1)
    times = np.array([0.0, 0.1])
    own = np.array([[30.0 * t, 0.0, -1000.0] for t in times])
    # Flying away at 62 m/s: 32 m/s receding, clear of the ground clutter band (|v| < 26 m/s at 2 km);
    # inside the band the intruder is clutter-limited, a different problem.
    intruder = np.array([[2000.0 + 62.0 * t, 100.0, -1000.0] for t in times])
    cubes = [
        sim.frame(
            PlatformState(own[i], np.array([30.0, 0, 0]), np.zeros(3)),
            [PointTarget(intruder[i], np.array([62.0, 0, 0]), 10.0)],
            i,
        )
        for i in range(2)
    ]
    lat, lon, alt = ned_to_geodetic(own, *ORIGIN)
    ownship = {
        "own_north_m": own[:, 0],
        "own_east_m": own[:, 1],
        "own_down_m": own[:, 2],
        "own_vn_mps": np.full(2, 30.0),
        "own_ve_mps": np.zeros(2),
        "own_vd_mps": np.zeros(2),
        "own_lat_deg": lat,
        "own_lon_deg": lon,
        "own_alt_m": alt,
    }
    attrs = {"origin_lat_deg": ORIGIN[0], "origin_lon_deg": ORIGIN[1], "origin_alt_m": ORIGIN[2]}
    ds = frames_dataset(np.stack(cubes), times, cfg, ownship=ownship, attrs=attrs)
    table = process_frames(ds, terrain=terrain)
    for i in range(2):
        rows = table[table.frame == i]
        err = np.linalg.norm(rows[["north_m", "east_m", "down_m"]].to_numpy() - intruder[i], axis=1)
        k = int(np.argmin(err))
        assert err[k] < 100.0 and not rows.is_ground.iloc[k]
        others = rows.drop(rows.index[k])
        assert len(others) >= 3 and others.is_ground.mean() >= 0.9


@given(value=st.floats(-1e4, 1e4), window=st.integers(1, 15), n=st.integers(1, 40))
def test_hann_smoothing_keeps_constants_and_fills_gaps(value, window, n):
    x = np.full((n, 3), value)
    x[n // 2] = np.nan
    y = hann_smooth(x, window)
    if n > 1:
        np.testing.assert_allclose(y[np.isfinite(y)], value, rtol=1e-12, atol=1e-9)


def test_hann_smoothing_reduces_white_noise_by_the_window_power():
    rng = np.random.default_rng(0)
    noise = rng.standard_normal(200_000)
    w = hann_window(9)
    ratio = np.std(hann_smooth(noise, 9)[10:-10]) / np.std(noise)
    assert ratio == pytest.approx(np.sqrt(np.sum(w**2)), rel=0.02)
    with pytest.raises(InputError, match="window"):
        hann_smooth(noise, 0)


def test_cli_process_realtime_times_every_frame_against_its_head_interval(tmp_path, monkeypatch, capsys):
    ds, _ = scene(n_frames=3)
    ds.to_zarr(tmp_path / "run.zarr", consolidated=False)
    out = tmp_path / "det.parquet"
    code, stdout, _ = run_cli(
        monkeypatch, capsys, "process", tmp_path / "run.zarr", "-o", out, "--realtime", "--json"
    )
    assert code == 0
    result = json.loads(stdout.strip().splitlines()[-1])
    timed = pd.DataFrame(json.loads(pd.read_parquet(out).attrs["frame_timing"]))
    assert timed["frame"].tolist() == [0, 1, 2] and (timed["processing_s"] > 0).all()
    # latency: the queue of one processor fed at the recorded frame times
    np.testing.assert_allclose(timed["latency_s"], paced_latencies(timed["time_s"], timed["processing_s"]))
    assert result["realtime_frames"] == 3
    assert result["realtime_deadline_misses"] == int((timed["latency_s"] > timed["deadline_s"]).sum())
    # frames timed on Dask workers would not time one processor: refused before any work
    both = ("process", tmp_path / "run.zarr", "-o", tmp_path / "d2.parquet", "--realtime", "--workers", 2)
    code, _, stderr = run_cli(monkeypatch, capsys, *both)
    assert code == 2 and "--realtime" in stderr and not (tmp_path / "d2.parquet").exists()
