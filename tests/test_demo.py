"""``skyradar demo``: the embedded scenario end to end, its helpers and the alerting velocity gate."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
import xarray as xr
from typer.testing import CliRunner

from skyradar.cli import app
from skyradar.cli.commands_demo import format_timeline
from skyradar.daa.alerting import AlertConfig
from skyradar.daa.pipeline import alerts_from_tracks
from skyradar.demo import alert_timeline, demo_scenario_path, label_tracks, run_demo
from skyradar.errors import InputError
from skyradar.scene.scenario import load_scenario
from skyradar.viz.report import intruder_outcomes, summary_sentences


def _collision(sigma_v_mps: float, dt: float = 0.5, duration_s: float = 40.0):
    """Own-ship north at 50 m/s; intruder head-on at 50 m/s, impact at t = 30 s; velocity sigma given."""
    t = np.arange(0.0, duration_s, dt)
    own = pd.DataFrame(
        {
            "time_s": t,
            "own_north_m": 50.0 * t,
            "own_east_m": 0.0,
            "own_down_m": -1000.0,
            "own_vn_mps": 50.0,
            "own_ve_mps": 0.0,
            "own_vd_mps": 0.0,
        }
    )
    tracks = pd.DataFrame(
        {
            "time_s": t,
            "track_id": 1,
            "north_m": 3000.0 - 50.0 * t,
            "east_m": 0.0,
            "down_m": -1000.0,
            "vn_mps": -50.0,
            "ve_mps": 0.0,
            "vd_mps": 0.0,
        }
    )
    for i in range(3):
        for j in range(3):
            tracks[f"cov_vv_{i}{j}"] = sigma_v_mps**2 if i == j else 0.0
            tracks[f"cov_pp_{i}{j}"] = 1.0 if i == j else 0.0
    return tracks, own


@pytest.mark.parametrize("sigma_v", [1.0, 30.0])
def test_velocity_gate_silences_only_unconverged_tracks(sigma_v):
    tracks, own = _collision(sigma_v)
    gate = AlertConfig(max_velocity_sigma_mps=10.0)
    gated = alerts_from_tracks(tracks, own, gate, with_advice=False)
    ungated = alerts_from_tracks(tracks, own, AlertConfig(), with_advice=False)
    assert ungated["level"].max() == 3  # a head-on collision warns without the gate
    # sqrt(sigma^2 + sigma^2) is the horizontal velocity sigma; the gate bounds sigma times the time
    # to CPA, floored at 8 s, by 10 m/s x 25 s, so 42 m/s never warns, even at the collision.
    expected = 3 if np.sqrt(2) * sigma_v * 8.0 <= 10.0 * 25.0 else 0
    assert gated["level"].max() == expected
    if expected:
        np.testing.assert_array_equal(gated["level"], ungated["level"])


def _truth(names=("a", "b")):
    t = np.arange(5.0)
    north = np.stack([100.0 * t, -100.0 * t], -1)
    zeros = np.zeros_like(north)
    dims = ("time", "target")
    data = {"tgt_north_m": (dims, north), "tgt_east_m": (dims, zeros), "tgt_down_m": (dims, zeros)}
    return xr.Dataset(data, coords={"time": t, "target": list(names)})


def test_label_tracks_follows_nearest_truth_and_flags_clutter():
    truth = _truth()
    t = np.arange(5.0)
    tracks = pd.concat(
        [
            pd.DataFrame(
                {"time_s": t, "track_id": 7, "north_m": -100.0 * t + 20, "east_m": 10.0, "down_m": 0.0}
            ),
            pd.DataFrame({"time_s": t, "track_id": 8, "north_m": 100.0 * t, "east_m": 5.0, "down_m": -30.0}),
            pd.DataFrame({"time_s": t, "track_id": 9, "north_m": 0.0, "east_m": 2000.0, "down_m": 0.0}),
        ]
    )
    assert label_tracks(tracks, truth) == {7: "b", 8: "a", 9: "clutter"}


def test_label_tracks_matches_a_prior_height_track_by_range_and_bearing():
    # Intruder "a" 339 m above the own-ship (at the origin), closing from 700 m north; its track
    # has no measured elevation and flies co-altitude at the same slant range and bearing.
    t = np.arange(5.0)
    north = 700.0 - 20.0 * t
    dims = ("time", "target")
    data = {
        "tgt_north_m": (dims, north[:, None]),
        "tgt_east_m": (dims, np.zeros((5, 1))),
        "tgt_down_m": (dims, np.full((5, 1), -339.0)),
    }
    data |= {f"own_{axis}_m": ("time", np.zeros(5)) for axis in ("north", "east", "down")}
    truth = xr.Dataset(data, coords={"time": t, "target": ["a"]})
    slant = np.hypot(north, 339.0)
    track = pd.DataFrame({"time_s": t, "track_id": 5, "north_m": slant, "east_m": 0.0, "down_m": 0.0})
    assert label_tracks(track.assign(altitude_measured=False), truth) == {5: "a"}
    # The same positions said to be measured are 340 m off: not the intruder's.
    assert label_tracks(track.assign(altitude_measured=True), truth) == {5: "clutter"}
    # A prior-height track elsewhere in bearing is still clutter.
    aside = track.assign(north_m=0.0, east_m=slant, altitude_measured=False)
    assert label_tracks(aside, truth) == {5: "clutter"}


def test_label_tracks_matches_a_track_by_range_and_range_rate_when_its_bearing_is_off():
    # Over relief a closure's directions come through clutter nulls and scatter by tens of degrees:
    # its co-altitude track sits 60 deg off the intruder's bearing (500-700 m across), but its
    # range and range rate are the intruder's to a pixel. A ground track at the same ranges whose
    # range rate is a static point's (-50 m/s, the own-ship's speed) is not the intruder's.
    t = np.arange(0.0, 5.0, 0.5)
    north = 700.0 - 100.0 * t  # closing head-on at 100 m/s, own-ship at the origin
    dims = ("time", "target")
    data = {
        "tgt_north_m": (dims, north[:, None]),
        "tgt_east_m": (dims, np.zeros((t.size, 1))),
        "tgt_down_m": (dims, np.zeros((t.size, 1))),
        "tgt_range_m": (dims, north[:, None]),
        "tgt_radial_velocity_mps": (dims, np.full((t.size, 1), -100.0)),
    }
    data |= {f"own_{axis}_m": ("time", np.zeros(t.size)) for axis in ("north", "east", "down")}
    truth = xr.Dataset(data, coords={"time": t, "target": ["a"]})
    off = np.radians(60.0)
    track = pd.DataFrame(
        {
            "time_s": t,
            "track_id": 5,
            "north_m": north * np.cos(off),
            "east_m": north * np.sin(off),
            "down_m": 0.0,
            "range_m": north + 3.0,
            "range_rate_mps": -100.2,
            "altitude_measured": False,
        }
    )
    assert label_tracks(track, truth) == {5: "a"}
    assert label_tracks(track.drop(columns=["range_m", "range_rate_mps"]), truth) == {5: "clutter"}
    assert label_tracks(track.assign(range_rate_mps=-50.0), truth) == {5: "clutter"}


def test_alert_timeline_lists_each_level_change():
    alerts = pd.DataFrame(
        {
            "time_s": [0, 1, 2, 3, 4, 0, 1, 2],
            "track_id": [1, 1, 1, 1, 1, 2, 2, 2],
            "level": [0, 1, 3, 3, 0, 0, 0, 0],
            "range_m": 1.0,
            "bearing_deg": 0.0,
            "rel_alt_m": 0.0,
            "time_to_impact_s": np.nan,
        }
    )
    tl = alert_timeline(alerts, {1: "x"})
    assert tl[["time_s", "track_id", "level"]].values.tolist() == [[1, 1, 1], [2, 1, 3], [4, 1, 0]]
    assert tl["intruder"].tolist() == ["x"] * 3
    assert tl["level_name"].tolist() == ["preventive", "WARNING", "none"]
    assert "WARNING" in format_timeline(tl)
    assert format_timeline(tl.iloc[:0]) == "alert timeline: no alerts"
    # A range-only row (a one-channel radar) has no bearing or height to print.
    ranged = format_timeline(tl.assign(bearing_deg=np.nan, rel_alt_m=np.nan))
    assert "no bearing" in ranged and "rel alt unknown" in ranged and "nan" not in ranged


def test_demo_out_must_be_a_directory(tmp_path):
    (tmp_path / "f").write_text("x")
    with pytest.raises(InputError, match="--output must be a directory"):
        run_demo(tmp_path / "f")


def test_demo_scenario_is_package_data_and_valid():
    built = load_scenario(demo_scenario_path()).build()
    assert [i.name for i in built.intruders] == ["collision", "fast-jet", "glider"]
    assert built.terrain is not None


@pytest.fixture(scope="module")
def demo_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo")
    result = CliRunner().invoke(app, ["demo", "--output", str(out), "--json"])
    assert result.exit_code == 0, result.output
    return out, result.stdout


def test_demo_warns_for_collision_only(demo_run):
    out, stdout = demo_run
    summary = json.loads(stdout.strip().splitlines()[-1])
    per = summary["intruders"]
    assert per["collision"]["max_level"] == 3
    # The warning comes before the scenario's impact at t = 40 s, with time to manoeuvre.
    assert per["collision"]["first_warning_s"] < 40.0 - 10.0
    assert all(v["max_level"] < 3 for k, v in per.items() if k != "collision")
    assert per["fast-jet"]["tracks"] >= 1 and per["glider"]["tracks"] >= 1  # seen, tracked, not warned
    assert summary["acceptance"] is True
    alerts = pd.read_parquet(out / "alerts.parquet")
    tracks = pd.read_parquet(out / "tracks.parquet")
    assert set(alerts["track_id"]) <= set(tracks.loc[tracks["confirmed"], "track_id"])
    assert "alert timeline" in stdout and "collision" in stdout and "WARNING" in stdout


def test_demo_writes_report(demo_run):
    out, _ = demo_run
    page = (out / "index.html").read_text()
    for name in ("range_doppler.png", "plan_view.png", "alert_timeline.png"):
        assert (out / name).stat().st_size > 5000
        assert f'src="{name}"' in page
    assert "PASS" in page and "Advice" in page
    # The page opens with the run in words, then the figures; the numbers stay in summary.json.
    summary = page.index("<h2>Summary</h2>")
    assert summary < page.index("range_doppler.png") and "collision: warning at " in page
    assert page.count("skyradar demo") == 2 and '<a href="summary.json">' in page  # title, h1
    assert not list(out.glob("*.partial*"))
    timeline = pd.read_csv(out / "alert_timeline.csv")
    assert (timeline.loc[timeline["intruder"] == "collision", "level"] == 3).any()


def test_summary_sentences_come_from_the_summary_and_timeline():
    summary = {
        "frames": 200,
        "detections": 900,
        "detections_ground": 700,
        "detections_spur": 3,
        "tracks": 4,
        "acceptance": False,
        "intruders": {
            "collision": {"tracks": 2, "max_level": 3},
            "jet": {"tracks": 1, "max_level": 2},
            "glider": {"tracks": 0, "max_level": 0},
            "clutter": {"tracks": 1, "max_level": 3},
        },
    }
    timeline = pd.DataFrame(
        {
            "time_s": [12.0, 15.5, 16.0, 30.0, 31.0],
            "intruder": ["collision", "collision", "jet", "clutter", "jet"],
            "level": [1, 3, 2, 3, 0],
        }
    )
    outcomes = intruder_outcomes(summary, timeline)
    assert outcomes["highest_level_s"].tolist()[:2] == [15.5, 16.0]
    lines = summary_sentences(summary, outcomes, 42.6)
    assert lines == [
        "200 frames over 43 s: 900 detections (700 on the ground, 3 on radar spurs), 4 tracks.",
        "collision: warning at 15.5 s (first alert, preventive, at 12.0 s), from 2 tracks.",
        "jet: corrective at 16.0 s, from 1 track.",
        "glider: never tracked.",
        "1 track follows no intruder (clutter); highest level warning.",
        "Acceptance (a warning for the collision intruder, none for anything else): FAIL.",
    ]
