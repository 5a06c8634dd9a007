"""Ground discrimination that keeps aircraft, terrains by name, and their bad input."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from cli_helpers import assert_one_line_error, skyradar
from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.experiments.ground_scenes import SCENES, score_scene, simulate_scene
from skyradar.io.frames import FrameStoreWriter, open_frames
from skyradar.process.doa import direction_from_angles, estimate_directions, steering_vector
from skyradar.process.ground import (
    classify_ground,
    ground_in_elevation,
    static_doppler_sd_mps,
    static_radial_velocity_mps,
)
from skyradar.process.pipeline import process_frames
from skyradar.scene.scenario import Scenario
from skyradar.scene.terrain_names import recorded_terrain, terrain_for_run
from skyradar.sim.simulate_store import simulate_to_zarr

CFG = RadarConfig.prototype_2022()
BASE = {
    "name": "tiny",
    "origin": {"lat_deg": 52.5, "lon_deg": 4.36, "alt_m": 0.0},
    "mount": "forward",
    "radar": {"range_limit_m": 600.0},
    "ownship": {"type": "straight", "start_ned_m": [0, 0, -300], "heading_deg": 0, "speed_mps": 40},
    "frame_rate_hz": 5.0,
    "duration_s": 0.6,
    "simulation": {"facet_size_m": 30.0},
}


def test_circling_glider_in_clear_sky_keeps_its_detections():
    # The Doppler test alone (no terrain, no own-ship height) flags many of a circling glider's
    # detections as ground (158 of 348 on one glider). Here the slow crossing aircraft and the glider often
    # have the radial velocity of a static point in their direction; none of them is ground.
    ds, truth, terrain = simulate_scene(SCENES["clear-sky"], n_frames=8, step_s=2.0, ahead_m=1500.0)
    table = process_frames(ds, terrain=terrain)
    scores = score_scene(table, truth, ds.sizes["doppler"])
    assert scores["glider_detections"] >= 6 and scores["slow_detections"] >= 6
    assert not table.is_ground.any()


def test_slow_aircraft_over_hills_is_not_ground_and_the_clutter_is():
    ds, truth, terrain = simulate_scene(SCENES["hills"], n_frames=3, step_s=1.0, ahead_m=1500.0)
    scores = score_scene(process_frames(ds, terrain=terrain), truth, ds.sizes["doppler"])
    assert scores["slow_detections"] == 3 and scores["slow_flagged"] == 0.0
    assert scores["ground"] > 500 and scores["ground_flagged"] > 0.95


def test_aircraft_above_the_surface_at_static_doppler_is_kept_and_ground_is_not():
    # 1000 m above flat ground, 50 m/s north; all three points seen 2 km away, 30 deg down.
    own_v = np.array([50.0, 0.0, 0.0])
    u = np.tile([np.cos(np.radians(30)), 0.0, np.sin(np.radians(30))], (4, 1))
    static = static_radial_velocity_mps(u, own_v)
    v = np.array([static[0], static[0], static[0] + 10.0, static[0] + 10.0])
    h = np.array([2.0, 200.0, 2.0, -150.0])  # ground, glider crossing, car, below the surface
    flags = classify_ground(
        np.full(4, 2000.0), v, u, CFG, own_v, h, np.radians(0.3), height_sd=np.full(4, 8.0)
    )
    assert flags.tolist() == [True, False, True, True]
    # A position too uncertain to decide (3 sd = 300 m): Doppler decides, the moving ones stay
    # (150 m below the surface is not conclusive at that uncertainty).
    loose = classify_ground(
        np.full(4, 2000.0), v, u, CFG, own_v, h, np.radians(3.0), height_sd=np.full(4, 100.0)
    )
    assert loose.tolist() == [True, True, False, False]


@given(az=st.floats(-1.2, 1.2), el=st.floats(-1.2, 1.2), yaw=st.floats(-3.0, 3.0), vd=st.floats(-10, 10))
def test_static_doppler_spread_is_the_first_order_change_with_angle(az, el, yaw, vd):
    # Independent peer: central differences of -v . u(az, el) through the same rotation.
    c, s = np.cos(yaw), np.sin(yaw)
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    v = np.array([45.0, -12.0, vd])
    h = 1e-6

    def doppler(a, e):
        return -(rot @ direction_from_angles(a, e)) @ v

    g_az = (doppler(az + h, el) - doppler(az - h, el)) / (2 * h)
    g_el = (doppler(az, el + h) - doppler(az, el - h)) / (2 * h)
    sd = static_doppler_sd_mps(direction_from_angles(az, el)[None], 0.01, 0.02, rot, v)[0]
    assert sd == pytest.approx(np.hypot(0.01 * g_az, 0.02 * g_el), abs=1e-5)


def _elevation_of_mixture(directions: list[np.ndarray], amplitudes: list[complex]) -> float:
    z = sum(a * steering_vector(u, CFG) for u, a in zip(directions, amplitudes, strict=True))
    u = estimate_directions(np.asarray(z)[None], CFG, calibrated=True)[0]
    return float(np.arcsin(-u[2]))


def test_a_mixed_pixel_of_ground_left_and_right_is_ground_and_one_with_an_aircraft_is_not():
    # Level antenna 500 m above flat ground: ground 1500 m away at -19.5 deg, 40 deg left and right.
    el_ground = -np.arcsin(500.0 / 1500.0)
    left, right = direction_from_angles(-0.7, el_ground), direction_from_angles(0.7, el_ground)
    aircraft = direction_from_angles(0.1, np.radians(2.0))

    def height(points):
        return 500.0 - points[..., 2]  # antenna at the origin, ground 500 m below

    mixtures = {
        "ground": _elevation_of_mixture([left, right], [1.0, 0.8j]),
        "aircraft+ground": _elevation_of_mixture([left, right, aircraft], [0.5, 0.4j, 1.0]),
    }
    assert mixtures["ground"] == pytest.approx(el_ground, abs=np.radians(0.5))
    flags = ground_in_elevation(
        np.full(2, 1500.0), np.array(list(mixtures.values())), height, np.zeros(3), np.eye(3), 60.0
    )
    assert flags.tolist() == [True, False]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """A clear-sky run at 52.5 N and a run over recorded fractal hills."""
    base = tmp_path_factory.mktemp("runs")
    plain = Scenario.from_dict(BASE, source=base / "s.yaml").build()
    simulate_to_zarr(plain, base / "run.zarr", chunk_frames=5)
    hills = {"type": "fractal", "local_sd_m": 60.0, "size_m": 3000.0, "spacing_m": 60.0, "seed": 3}
    built = Scenario.from_dict({**BASE, "terrain": hills}, source=base / "h.yaml").build()
    simulate_to_zarr(built, base / "hills.zarr", chunk_frames=5)
    # The same clear-sky frames with no own-ship state at all (neither navigation nor truth).
    ds = open_frames(base / "run.zarr")
    bare = ds.drop_vars([v for v in ds.data_vars if v.startswith(("own_", "nav_"))]).load()
    writer = FrameStoreWriter(base / "bare.zarr", bare.assign(iq=bare["iq"].chunk({"time": 3})), 3, "bare")
    for k in writer.pending_chunks():
        writer.write_chunk(k, bare["iq"].values[writer.chunk_slice(k)])
    writer.close()
    return base, built


def test_a_run_records_its_scenario_terrain_and_process_can_rebuild_it(runs):
    base, built = runs
    ds = open_frames(base / "hills.zarr")
    assert recorded_terrain(open_frames(base / "run.zarr"), "run.zarr") is None
    again = recorded_terrain(ds, "hills.zarr")
    np.testing.assert_array_equal(again.elevation_m, built.terrain.elevation_m)
    by_name = terrain_for_run("fractal", ds, 600.0, "hills.zarr")
    np.testing.assert_array_equal(by_name.elevation_m, built.terrain.elevation_m)
    flat = terrain_for_run("flat", open_frames(base / "run.zarr"), 600.0, "run.zarr")
    assert float(flat.height_at(52.5, 4.36)) == pytest.approx(0.0, abs=0.01)


def test_terrain_by_name_refuses_what_it_cannot_place(runs):
    base, _ = runs
    ds = open_frames(base / "run.zarr")
    with pytest.raises(InputError, match="does not record its fractal terrain"):
        terrain_for_run("fractal", ds, 600.0, "run.zarr")
    bare = ds.drop_vars([v for v in ds.data_vars if v.startswith(("own_", "nav_"))])
    with pytest.raises(InputError, match=r"run.zarr: option '--terrain' needs the run's own-ship position"):
        terrain_for_run("jacksboro", bare, 600.0, "run.zarr")


def test_process_terrain_bad_name_and_missing_own_ship_give_one_line(runs):
    base, _ = runs
    args = ["process", "run.zarr", "-o", "det.parquet", "--terrain"]
    assert_one_line_error(skyradar(*args, "moon", cwd=base), "--terrain", "moon", "flat, fractal, jacksboro")
    # Ground discrimination with a terrain needs the own-ship state (navigation): one line without it.
    result = skyradar("process", "bare.zarr", "-o", "det.parquet", "--terrain", "flat", cwd=base)
    assert_one_line_error(result, "bare.zarr", "--terrain", "own-ship position", "nav_lat_deg")
    assert not (base / "det.parquet").exists()


def test_jacksboro_by_name_refuses_a_run_that_is_not_over_it(runs):
    # The Jacksboro DEM is in Tennessee; this run flies at 52.5 N (a file DEM off the flight is
    # refused through the real `skyradar process` in test_silent_inputs: the same check).
    base, _ = runs
    with pytest.raises(InputError, match=r"jacksboro_fault_dem.npz: .* lat 52.5.* does not cover the flight"):
        terrain_for_run("jacksboro", open_frames(base / "run.zarr"), 600.0, "run.zarr")


def test_track_takes_the_run_terrain_for_its_ground_test_and_names_bad_terrain(runs):
    from skyradar.cli.commands_track import _ground_test
    from skyradar.io.navigation import navigation_state
    from skyradar.io.run_origin import scenario_origin
    from skyradar.track.ground_tracks import GroundTrackTest

    base, built = runs
    ds = open_frames(base / "hills.zarr")
    own, origin = navigation_state(ds, "hills.zarr"), scenario_origin(ds)
    test = _ground_test(None, ds, base / "hills.zarr", own, origin, built.radar)
    assert isinstance(test, GroundTrackTest)  # the recorded fractal hills, not level ground
    lat, lon = np.array([origin[0]]), np.array([origin[1]])
    ground = float(built.terrain.height_at(lat, lon)[0])
    assert test.surface_down(np.zeros((1, 2)))[0] == pytest.approx(origin[2] - ground, abs=0.5)
    assert _ground_test("none", ds, base / "hills.zarr", own, origin, built.radar) is True
    assert _ground_test(None, None, None, None, None, built.radar) is True  # no own-ship: level ground
    det = base / "det_track.csv"
    det.write_text("time_s,range_m,radial_velocity_mps\n0.0,1000.0,-20.0\n0.1,998.0,-20.0\n")
    args = ["track", str(det), "-o", str(base / "t.parquet")]
    result = skyradar(*args, "--terrain", "flat", cwd=base)
    assert_one_line_error(result, "--terrain", "flat", "--ownship")
    result = skyradar(*args, "--ownship", "hills.zarr", "--terrain", "moon", cwd=base)
    assert_one_line_error(result, "--terrain", "moon", "flat, fractal, jacksboro")
    assert not (base / "t.parquet").exists()
