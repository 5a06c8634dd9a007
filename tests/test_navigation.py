"""Own-ship navigation with errors: the model's statistics, the scenario key, and that
the simulator's own-ship truth never enters process, track or alert."""

from __future__ import annotations

import logging

import numpy as np
import pytest

from cli_helpers import assert_one_line_error, skyradar
from skyradar.benchmarks.process import synthetic_frame
from skyradar.config import Mount, RadarConfig
from skyradar.daa.pipeline import alerts_from_tracks
from skyradar.daa.run_tables import ownship_from_frames
from skyradar.errors import InputError
from skyradar.geo import direction_angles, ned_rotation_to, ned_to_geodetic, rotation_matrix
from skyradar.io.frames import frames_dataset
from skyradar.io.navigation import navigation_state
from skyradar.process.pipeline import process_frames
from skyradar.scene.navigation_config import NAVIGATION_MODELS, navigation_config
from skyradar.scene.synthetic_terrain import flat_terrain
from skyradar.sim.navigation import navigation_solution
from skyradar.track.track_table import track_detections

ORIGIN = (52.0, 4.0, 0.0)
CFG = RadarConfig.prototype_2022(mount=Mount.preset("forward"))
_OWN_KEYS = ("north_m", "east_m", "down_m", "vn_mps", "ve_mps", "vd_mps", "yaw_rad", "pitch_rad", "roll_rad")


def _level_flight(times: np.ndarray) -> dict[str, np.ndarray]:
    """Own-ship truth: north at 50 m/s, 1000 m up, wings level, heading north."""
    n = times.size
    own = {f"own_{k}": np.zeros(n) for k in _OWN_KEYS}
    own["own_north_m"], own["own_vn_mps"], own["own_down_m"] = (
        50.0 * times,
        np.full(n, 50.0),
        np.full(n, -1000.0),
    )
    own["own_height_agl_m"] = np.full(n, 1000.0)
    return own


def test_error_statistics_match_the_model_over_many_seeds():
    # Peer: the closed-form stationary variance of bias + white noise, sd^2 = bias^2 + noise^2.
    t = np.arange(0.0, 2.0, 0.5)
    own = _level_flight(t)
    errs = {"north": [], "down": [], "yaw": [], "roll": []}
    for seed in range(1500):
        nav = navigation_solution(own, t, "ga-typical", seed, ORIGIN)
        errs["north"].append(nav["nav_north_m"][0] - own["own_north_m"][0])  # before latency matters
        errs["down"].append(nav["nav_down_m"][0] - own["own_down_m"][0])
        errs["yaw"].append(np.degrees(nav["nav_yaw_rad"][0]))
        errs["roll"].append(np.degrees(nav["nav_roll_rad"][0]))
    cfg = navigation_config("ga-typical")
    expected = {
        "north": np.hypot(cfg.gnss_horizontal_bias_m, cfg.gnss_horizontal_noise_m),
        "down": np.hypot(cfg.gnss_vertical_bias_m, cfg.gnss_vertical_noise_m),
        "yaw": np.hypot(cfg.heading_bias_deg, cfg.heading_noise_deg),
        "roll": np.hypot(cfg.roll_pitch_bias_deg, cfg.roll_pitch_noise_deg),
    }
    for key, sd in expected.items():
        assert np.std(errs[key]) == pytest.approx(sd, rel=0.08), key  # 1500 samples: SE of SD ~2 %
        assert abs(np.mean(errs[key])) < 4 * sd / np.sqrt(1500), key


def test_latency_is_the_truth_that_much_earlier_and_ablations_share_one_realisation():
    t = np.arange(0.0, 10.0, 1 / 9.4)
    own = _level_flight(t)
    late = navigation_solution(own, t, "only-latency", 3, ORIGIN)
    after = t >= 0.2
    # Closed form for a straight line at 50 m/s: 0.2 s late is 10 m behind.
    np.testing.assert_allclose(late["nav_north_m"][after], own["own_north_m"][after] - 10.0, atol=1e-9)
    full = navigation_solution(own, t, "ga-typical", 3, ORIGIN)
    heading = navigation_solution(own, t, "only-heading", 3, ORIGIN)
    # Constant attitude: the AHRS latency changes nothing, so the heading errors are the same draw.
    np.testing.assert_allclose(heading["nav_yaw_rad"], full["nav_yaw_rad"], atol=1e-12)
    np.testing.assert_array_equal(heading["nav_north_m"], own["own_north_m"])
    perfect = navigation_solution(own, t, "perfect", 3, ORIGIN)
    for key in _OWN_KEYS:
        np.testing.assert_array_equal(perfect[f"nav_{key}"], own[f"own_{key}"])
    # Geodetic and NED views of the solution agree; the height follows the vertical error.
    lat, lon, alt = ned_to_geodetic(
        np.stack([full[f"nav_{a}_m"] for a in ("north", "east", "down")], -1), *ORIGIN
    )
    np.testing.assert_allclose(full["nav_lat_deg"], lat, atol=1e-12)
    np.testing.assert_allclose(full["nav_alt_m"] - alt, 0.0, atol=1e-6)
    agl_err = full["nav_height_agl_m"] - own["own_height_agl_m"]
    np.testing.assert_allclose(
        agl_err[after], own["own_down_m"][after] - full["nav_down_m"][after], atol=1e-9
    )


def test_model_names_overrides_and_bad_values():
    assert set(NAVIGATION_MODELS) >= {"perfect", "ga-typical", "only-heading", "only-latency"}
    assert navigation_config("perfect").is_perfect and not navigation_config().is_perfect
    only = navigation_config({"model": "only-gnss-position", "gnss_horizontal_bias_m": 4})
    assert only.gnss_horizontal_bias_m == 4.0 and only.heading_bias_deg == 0.0
    for bad, field in (("sloppy", "model"), ({"heading_bias_deg": -1}, "heading_bias_deg"), (3, "mapping")):
        with pytest.raises(InputError, match=field):
            navigation_config(bad)


def _scene(n_frames: int = 24, seed: int = 0):
    """Nose radar, own-ship north at 50 m/s banked a little; an aircraft closing head-on at 60 m/s.

    The frames are made with the NAVIGATION attitude and position the Dataset's nav_* hold (so
    world positions come out right from nav_*); own_* truth is set to something else entirely.
    """
    rng = np.random.default_rng(seed)
    times = np.arange(n_frames) / 9.4
    own = np.stack([50.0 * times, np.zeros(n_frames), np.full(n_frames, -600.0)], -1)
    att = np.array([[0.05, 0.02, 0.1]] * n_frames)
    lat, lon, alt = ned_to_geodetic(own, *ORIGIN)
    cubes = []
    for i, t in enumerate(times):
        body_to_ned = ned_rotation_to(ORIGIN[0], ORIGIN[1], lat[i], lon[i]).T @ rotation_matrix(*att[i])
        ant_to_ned = body_to_ned @ CFG.mount.rotation
        antenna = own[i] + body_to_ned @ np.array(CFG.mount.position_m)
        p = np.array([1800.0 - 60.0 * t, 30.0, -600.0])
        v_r = (np.array([-60.0, 0.0, 0.0]) - [50.0, 0, 0]) @ (p - antenna) / np.linalg.norm(p - antenna)
        r, az, el = direction_angles(ant_to_ned.T @ (p - antenna))
        cubes.append(synthetic_frame(CFG, [(float(r), float(v_r), float(az), float(el), 35.0)], rng)[0])
    nav = {
        "nav_north_m": own[:, 0],
        "nav_east_m": own[:, 1],
        "nav_down_m": own[:, 2],
        "nav_vn_mps": np.full(n_frames, 50.0),
        "nav_ve_mps": np.zeros(n_frames),
        "nav_vd_mps": np.zeros(n_frames),
        "nav_lat_deg": lat,
        "nav_lon_deg": lon,
        "nav_alt_m": alt,
        "nav_yaw_rad": att[:, 0],
        "nav_pitch_rad": att[:, 1],
        "nav_roll_rad": att[:, 2],
        "nav_height_agl_m": -own[:, 2],
    }
    attrs = {"origin_lat_deg": ORIGIN[0], "origin_lon_deg": ORIGIN[1], "origin_alt_m": ORIGIN[2]}
    return frames_dataset(np.stack(cubes), times, CFG, ownship=nav | _truth(nav, 0.0), attrs=attrs)


def _truth(nav: dict, offset: float) -> dict:
    """own_* truth: the navigation values moved by ``offset`` (m, rad) in every variable."""
    return {f"own_{k[4:]}": np.asarray(v) + offset for k, v in nav.items()}


def _chain(ds):
    terrain = flat_terrain(*ORIGIN[:2], height_m=0.0, size_m=8000.0, spacing_m=60.0)
    det = process_frames(ds, terrain=terrain)
    own = ownship_from_frames(ds)
    tracks = track_detections(
        det[~det.is_ground], "radar", CFG, frame_times_s=np.asarray(own.time_s), origin=ORIGIN, ownship=own
    )
    return det, tracks, alerts_from_tracks(tracks, own, with_advice=True)


def test_truth_never_enters_process_track_or_alert():
    ds = _scene()
    det, tracks, alerts = _chain(ds)
    assert det.attrs["navigation_source"] == "navigation"
    assert tracks["confirmed"].any() and len(alerts) > 0  # a real track and alerts to compare
    # Corrupt every own_* truth variable: nothing the chain produces may change.
    corrupt = ds.copy()
    for name in [v for v in ds.data_vars if v.startswith("own_")]:
        corrupt[name] = ds[name] + 500.0
    det2, tracks2, alerts2 = _chain(corrupt)
    for a, b in ((det, det2), (tracks, tracks2), (alerts, alerts2)):
        assert a.equals(b)
    # ...while moving the navigation state does move the world positions (the test can fail).
    moved = ds.copy()
    moved["nav_east_m"] = ds["nav_east_m"] + 50.0
    det3 = process_frames(moved)
    assert not np.allclose(det3.east_m, process_frames(ds).east_m)


def test_stores_written_before_navigation_fall_back_to_truth_with_a_note(caplog):
    ds = _scene(n_frames=2)
    old = ds.drop_vars([v for v in ds.data_vars if v.startswith("nav_")])
    with caplog.at_level(logging.INFO, logger="skyradar.io.navigation"):
        state = navigation_state(old, "old.zarr")
        table = process_frames(old)
    assert state.attrs["navigation_source"] == "truth" and table.attrs["navigation_source"] == "truth"
    assert "old.zarr" in caplog.text and "own-ship truth" in caplog.text
    np.testing.assert_array_equal(state["own_north_m"], old["own_north_m"].values)
    assert ownship_from_frames(old).attrs["navigation_source"] == "truth"


def test_scenario_frames_carry_navigation_beside_truth_and_a_bad_model_is_one_line(tmp_path):
    from skyradar.scene.scenario import load_scenario
    from skyradar.sim.navigation import navigation_variables

    text = (
        "name: nav\nownship: {type: straight, heading_deg: 90, speed_mps: 50, start_ned_m: [0, 0, -500]}\n"
        "duration_s: 3\nterrain: {type: flat, height_m: 0}\norigin: {lat_deg: 52, lon_deg: 4}\n"
    )
    path = tmp_path / "s.yaml"
    for model, seed in (("ga-typical", 0), ("perfect", 0), ("{model: only-heading, seed: 7}", 7)):
        path.write_text(text + f"navigation: {model}\nsimulation: {{seed: 2}}\n")
        built = load_scenario(path).build()
        own = _level_flight(built.times_s)
        nav = navigation_variables(built, own)
        assert set(nav) >= {f"nav_{k}" for k in _OWN_KEYS} | {"nav_lat_deg", "nav_height_agl_m"}
        if model == "perfect":
            np.testing.assert_array_equal(nav["nav_yaw_rad"], own["own_yaw_rad"])
        else:  # seeded from simulation.seed unless the section names its own seed
            ref = navigation_solution(
                own, built.times_s, built.navigation, seed or 2, built.origin, built.terrain.height_at
            )
            np.testing.assert_array_equal(nav["nav_yaw_rad"], ref["nav_yaw_rad"])
    path.write_text(text + "navigation: {model: ga-typical, heading_bias_deg: -2}\n")
    assert_one_line_error(
        skyradar("simulate", str(path), "--output", str(tmp_path / "r.zarr"), cwd=tmp_path),
        "navigation.heading_bias_deg",
        "-2",
    )


def test_radar_height_replaces_the_gnss_height_where_the_estimator_was_trusted():
    import pandas as pd

    from skyradar.nav.radar_height import with_radar_height
    from skyradar.process.pipeline import navigated_own_state

    ds = _scene(n_frames=4)
    t = np.arange(4) / 9.4  # _scene's frame times
    # Estimates a few ms off the frame times (nearest within half a frame), one not trusted, one unsorted.
    state = pd.DataFrame(
        {
            "time_s": t[[3, 0, 1, 2]] + 0.004,
            "h_m": [603.0, 590.0, 591.0, 592.0],
            "used_by_filter": [True, True, True, False],
        }
    )
    out = with_radar_height(ds, state)
    gnss = ds["nav_height_agl_m"].values
    np.testing.assert_array_equal(out["nav_height_agl_m"].values, [590.0, 591.0, gnss[2], 603.0])
    np.testing.assert_array_equal(out["own_height_agl_m"].values, ds["own_height_agl_m"].values)
    np.testing.assert_array_equal(navigated_own_state(out).height_agl_m, [590.0, 591.0, gnss[2], 603.0])
    with pytest.raises(InputError, match="h_m"):
        with_radar_height(ds, state.drop(columns="h_m"))
