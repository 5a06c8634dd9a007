"""Scenario files: validation messages, building, shipped examples."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import yaml

from skyradar.config import Mount, RadarConfig
from skyradar.errors import InputError
from skyradar.scene.scenario import (
    BuiltScenario,
    example_scenario,
    list_example_scenarios,
    load_scenario,
)
from skyradar.scene.trajectories import circle

BASE = {
    "name": "test",
    "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 5.0},
    "ownship": {"type": "straight", "start_ned_m": [0, 0, -500], "heading_deg": 0, "speed_mps": 30},
    "duration_s": 5,
}
SIM_KEYS = {
    "facet_size_m",
    "reflectivity",
    "occlusion",
    "noise",
    "flat_earth",
    "range_doppler_coupling",
    "seed",
    "psf",
    "speckle",
    "swerling",
}


def _write(tmp_path, data, name="bad.yaml"):
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return path


def _with(**changes):
    data = {k: (dict(v) if isinstance(v, dict) else v) for k, v in BASE.items()}
    data.update(changes)
    return data


def _range_and_rate(built: BuiltScenario, k: int):
    own = built.ownship.sample(built.times_s)
    tgt = built.intruders[k].trajectory.sample(built.times_s)
    d = tgt.position_ned_m - own.position_ned_m
    rng = np.linalg.norm(d, axis=1)
    return rng, np.sum(d * (tgt.velocity_ned_mps - own.velocity_ned_mps), axis=1) / rng


# ---- examples -----------------------------------------------------------------------------------
def test_examples_are_listed():
    assert {"ch2_flat_forward", "circuit_three_intruders", "jacksboro_forward_down"} <= set(
        list_example_scenarios()
    )
    with pytest.raises(InputError, match="nope"):
        example_scenario("nope")


@pytest.mark.parametrize("name", list_example_scenarios())
def test_every_example_loads_and_builds(name):
    built = load_scenario(example_scenario(name)).build()
    assert isinstance(built.radar, RadarConfig) and built.terrain is not None
    assert set(built.sim_options) == SIM_KEYS
    assert np.all(built.ownship.covers(built.times_s)) and built.intruders
    for intruder in built.intruders:
        assert intruder.rcs_m2 > 0 and intruder.trajectory.origin == built.origin
        assert np.any(intruder.trajectory.covers(built.times_s))
    # Own-ship stays above the ground under it.
    own = built.ownship.sample(built.times_s)
    ground = built.terrain.height_at(own.lat_deg, own.lon_deg)
    assert np.all(own.alt_m - ground > 100.0)


def test_ch2_example_matches_the_thesis_setup():
    built = load_scenario(example_scenario("ch2_flat_forward")).build()
    assert built.radar.mount == Mount.preset("forward")
    own = built.ownship.sample(built.times_s)
    np.testing.assert_allclose(
        own.alt_m - built.terrain.height_at(own.lat_deg, own.lon_deg), 1000.0, atol=0.5
    )
    np.testing.assert_allclose(np.linalg.norm(own.velocity_ned_mps, axis=1), 30.0, atol=1e-9)
    rng, rate = _range_and_rate(built, 0)
    assert rng[0] == pytest.approx(2000.0, abs=1e-3)
    np.testing.assert_allclose(rate, -60.0, atol=1e-6)
    assert len(built.times_s) == 94 and built.times_s[1] == pytest.approx(1 / 9.4)
    # The closing speed is beyond the Nyquist velocity: it aliases to -60 + 2 VLim = +18.3 m/s.
    v_lim = built.radar.v_lim_mps
    wrapped = (rate[0] + v_lim) % (2 * v_lim) - v_lim
    assert wrapped == pytest.approx(18.26, abs=0.01)


def test_circuit_example_intruders():
    built = load_scenario(example_scenario("circuit_three_intruders")).build()
    names = [i.name for i in built.intruders]
    assert names == ["collision", "fast-jet", "glider"]
    t = np.linspace(0.0, 59.0, 5901)
    own = built.ownship.sample(t).position_ned_m
    miss = np.linalg.norm(built.intruders[0].trajectory.sample(t).position_ned_m - own, axis=1)
    assert miss.min() < 0.01 and t[miss.argmin()] == pytest.approx(40.0, abs=0.01)
    _, rate = _range_and_rate(built, 1)
    approaching = built.times_s < 50.0
    assert np.all(np.abs(rate[approaching]) > built.radar.v_lim_mps)  # the fast jet aliases until its CPA
    # The glider file is the circle it was generated from, to the file's rounding.
    glider = built.intruders[2].trajectory
    truth = circle(
        [-1300, 1500, -450], 150, 25, 90, clockwise=False, climb_mps=1.2, origin=built.origin, rate_hz=1
    )
    err = np.linalg.norm(glider.sample(truth.time_s).position_ned_m - truth.position_ned_m, axis=1)
    assert err.max() < 0.5  # 1e-6 deg and 1 ft rounding
    assert glider.name == "glider" and built.intruders[2].rcs_m2 == 0.5


def test_jacksboro_origin_defaults_to_dem_centre():
    built = load_scenario(example_scenario("jacksboro_forward_down")).build()
    lat, lon = built.terrain.center_latlon
    assert built.origin[:2] == pytest.approx((lat, lon))
    assert built.origin[2] == pytest.approx(float(built.terrain.height_at(lat, lon)))
    assert built.radar.mount.pitch_deg == -30.0


# ---- building -----------------------------------------------------------------------------------
def test_paths_are_relative_to_the_yaml_and_overrides_apply(tmp_path, monkeypatch):
    sub = tmp_path / "scen"
    (sub / "tracks").mkdir(parents=True)
    t = np.arange(0.0, 21.0)
    lat = 52.0 + t * 1e-4
    pd.DataFrame({"time_s": t, "latitude": lat, "longitude": 4.36, "alt_m": 800.0}).to_csv(
        sub / "tracks" / "own.csv", index=False
    )
    pd.DataFrame({"angle_deg": [-90, 0, 90], "gain_db": [-20, 10, -20]}).to_csv(sub / "az.csv", index=False)
    pd.DataFrame({"angle_deg": [-90, 0, 90], "gain_db": [-25, 10, -25]}).to_csv(sub / "el.csv", index=False)
    data = {
        "ownship": "tracks/own.csv",
        "radar": {"range_limit_m": 3000, "antenna": {"azimuth_csv": "az.csv", "elevation_csv": "el.csv"}},
        "mount": {"preset": "forward-down", "pitch_deg": -20},
        "terrain": {"type": "flat", "height_m": 0.0, "size_m": 3000, "spacing_m": 100},
        "intruders": [
            {
                "type": "straight",
                "start_ned_m": [3000, 0, -800],
                "heading_deg": 180,
                "speed_mps": 40,
                "time_offset_s": 2,
            }
        ],
        "duration_s": 10,
        "frame_rate_hz": 5,
        "start_s": 3,
    }
    path = _write(sub, data, "s.yaml")
    monkeypatch.chdir(tmp_path)
    built = load_scenario(path).build()
    assert built.origin == (52.0, 4.36, 800.0)  # own-ship file's first point
    assert built.radar.range_limit_m == 3000 and built.radar.mount.pitch_deg == -20.0
    assert built.radar.mount.position_m == Mount.preset("forward-down").position_m
    assert float(built.radar.antenna.gain_db(np.radians(90.0), 0.0)) == pytest.approx(-20.0)
    assert float(built.radar.antenna.gain_db(0.0, np.radians(90.0))) == pytest.approx(-25.0)
    np.testing.assert_allclose(built.times_s, 3.0 + np.arange(50) / 5.0)
    intruder = built.intruders[0]
    assert intruder.name == "intruder0" and intruder.trajectory.start_s == pytest.approx(5.0)
    assert intruder.trajectory.sample([5.0]).position_ned_m[0] == pytest.approx([3000, 0, -800])


def test_frames_must_fit_the_radar_frame_time(tmp_path):
    with pytest.raises(InputError, match=r"bad.yaml: field 'frame_rate_hz': must be <= 19.68"):
        load_scenario(_write(tmp_path, _with(frame_rate_hz=25))).build()


@pytest.mark.parametrize(
    ("changes", "pattern"),
    [
        ({"frame_rate_hz": -5}, r"bad.yaml: field 'frame_rate_hz': must be > 0 \(got -5\)"),
        ({"duration_s": 0}, r"bad.yaml: field 'duration_s': must be > 0 \(got 0\)"),
        ({"intruderz": []}, r"^.*bad.yaml: unknown key 'intruderz'$"),
        ({"radar": {"fc_hz": 9e9, "fcc": 1}}, r"bad.yaml: unknown key 'radar.fcc'"),
        ({"ownship": None}, r"bad.yaml: field 'ownship': is required"),
        (
            {"ownship": {"type": "spiral"}},
            r"bad.yaml: field 'ownship': 'type' must be one of .*\(got 'spiral'\)",
        ),
        (
            {"ownship": {"type": "straight", "speed_mps": -1}},
            r"bad.yaml: field 'ownship.speed_mps': must be >= 0",
        ),
        ({"mount": "upside-down"}, r"bad.yaml: field 'mount.preset': .*'upside-down'"),
        (
            {"simulation": {"reflectivity": "mirror"}},
            r"bad.yaml: field 'simulation.reflectivity': must be one of",
        ),
        ({"terrain": {"type": "fractal"}}, r"bad.yaml: field 'terrain.local_sd_m': is required"),
        ({"radar": {"prf_hz": 2e7}}, r"bad.yaml: field 'radar': .*prf_hz"),
        (
            {"origin": {"lat_deg": 95, "lon_deg": 4}},
            r"bad.yaml: field 'origin.lat_deg': must be <= 90 \(got 95\)",
        ),
        ({"origin": None, "terrain": {"type": "flat"}}, r"bad.yaml: field 'origin': is required"),
        ({"ownship": "missing.csv"}, r"bad.yaml: field 'ownship': .*missing.csv: no such file"),
        (
            {"ownship": {"type": "straight", "speed_mps": 30, "duration_s": 2}},
            r"bad.yaml: field 'ownship': .*covers 0..2 s",
        ),
        (
            {"intruders": [{"type": "encounter", "kind": "sideways", "t_cpa_s": 3}]},
            r"bad.yaml: field 'intruders.0.kind': must be one of",
        ),
        (
            {"intruders": [{"type": "encounter", "kind": "head-on", "t_cpa_s": 3, "rcs_m2": 0}]},
            r"bad.yaml: field 'intruders.0.rcs_m2': must be > 0",
        ),
        (
            {"intruders": [{"type": "straight", "speed_mps": 3, "time_offset_s": 100}]},
            r"bad.yaml: field 'intruders.0.time_offset_s': .*outside every frame",
        ),
        (
            {
                "intruders": [
                    {
                        "type": "encounter",
                        "kind": "head-on",
                        "t_cpa_s": 3,
                        "vertical_miss_m": 50,
                        "intruder_climb_mps": 3,
                    }
                ]
            },
            r"bad.yaml: field 'intruders.0.vertical_miss_m'",
        ),
        (
            {
                "ownship": {
                    "type": "circuit",
                    "runway_heading_deg": 0,
                    "pattern_altitude_m": 300,
                    "speed_mps": 60,
                    "width_m": 300,
                }
            },
            r"bad.yaml: field 'ownship.width_m': must be >= 1574",
        ),
        ({"duration_s": "ten"}, r"bad.yaml: field 'duration_s': must be a finite number \(got 'ten'\)"),
    ],
)
def test_bad_scenarios_give_one_line_naming_file_and_field(tmp_path, changes, pattern):
    path = _write(tmp_path, _with(**changes))
    with pytest.raises(InputError, match=pattern) as info:
        load_scenario(path).build()
    assert "\n" not in str(info.value)


def test_bad_yaml_and_missing_file(tmp_path):
    path = tmp_path / "broken.yaml"
    path.write_text("name: [a\nb: c\n")
    with pytest.raises(InputError, match=r"broken.yaml: not valid YAML at line 2"):
        load_scenario(path)
    (tmp_path / "list.yaml").write_text("- 1\n- 2\n")
    with pytest.raises(InputError, match="list.yaml: must be a mapping"):
        load_scenario(tmp_path / "list.yaml")
    with pytest.raises(InputError, match="none.yaml: no such scenario file"):
        load_scenario(tmp_path / "none.yaml")


def test_icao24_selects_one_aircraft_of_a_file(tmp_path):
    rows = []
    for icao, lat0 in (("aaa111", 52.01), ("bbb222", 52.02)):
        for k in range(12):
            rows.append(
                {
                    "timestamp": 1_700_000_000 + k,
                    "icao24": icao,
                    "latitude": lat0 + k * 1e-4,
                    "longitude": 4.36,
                    "altitude": 2000.0,
                }
            )
    pd.DataFrame(rows).to_csv(tmp_path / "traffic.csv", index=False)
    data = _with(intruders=[{"type": "file", "path": "traffic.csv", "icao24": "bbb222", "name": "B"}])
    built = load_scenario(_write(tmp_path, data, "ok.yaml")).build()
    b = built.intruders[0].trajectory.sample([0.0])
    assert b.lat_deg[0] == pytest.approx(52.02) and b.alt_m[0] == pytest.approx(2000 * 0.3048)
    # A common time zero keeps recordings in step: B's row at unix 1_700_000_005 is scenario t = 3 s.
    data["intruders"][0]["time_zero_s"] = 1_700_000_002
    shifted = load_scenario(_write(tmp_path, data, "ok.yaml")).build().intruders[0].trajectory
    assert shifted.start_s == pytest.approx(-2.0)
    assert shifted.sample([3.0]).lat_deg[0] == pytest.approx(52.02 + 5e-4)
    data["intruders"][0]["icao24"] = "ccc333"
    with pytest.raises(InputError, match=r"bad.yaml: field 'intruders.0.icao24': 'ccc333'"):
        load_scenario(_write(tmp_path, data)).build()


def test_dem_file_terrain_relative_path_sets_origin(tmp_path):
    (tmp_path / "dem").mkdir()
    z = np.full((41, 41), 250.0)
    np.savez(tmp_path / "dem" / "hill.npz", elevation=z, dx=0.001, dy=0.001, xmin=4.0, ymax=52.02)
    data = _with(origin=None, terrain={"type": "file", "path": "dem/hill.npz"})
    built = load_scenario(_write(tmp_path, data, "dem.yaml")).build()
    assert built.origin == pytest.approx((52.0, 4.02, 250.0))
    own = built.ownship.sample(built.times_s[:1])
    assert own.alt_m[0] - float(built.terrain.height_at(own.lat_deg[0], own.lon_deg[0])) == pytest.approx(
        500.0, abs=0.1
    )
