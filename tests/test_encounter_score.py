"""Honest encounter scoring: every conflict, causes of the unwarned ones, clutter and fragments,
the terrains of the set, and the command's bad input."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from cli_helpers import assert_one_line_error, skyradar
from skyradar.experiments.encounter_report import cost_ms_per_frame, summary_markdown
from skyradar.experiments.encounter_score import CAUSES, conflict_cause, summarise_layout, track_counts
from skyradar.experiments.encounter_set import make_encounters
from skyradar.experiments.encounter_terrain import mirror_below_ground, own_altitude_m, parse_terrains


def _status(**flags) -> pd.DataFrame:
    n = 11
    base = {
        "time_s": np.arange(n, dtype=float),
        "behind": np.zeros(n, bool),
        "in_beam": np.ones(n, bool),
        "in_view": np.ones(n, bool),
        "observable": np.ones(n, bool),
    }
    for name, frames in flags.items():
        base[name] = base[name].copy()
        base[name][frames] = not base[name][frames[0]]
        base["observable"][frames] = False
    return pd.DataFrame(base)


@pytest.mark.parametrize(
    ("flags", "cause"),
    [
        ({}, "missed"),
        ({"behind": [9]}, "behind"),
        ({"in_beam": [8]}, "outside_beams"),
        ({"in_view": [4]}, "terrain_masked"),
        ({"observable": [10]}, "below_13db"),
        ({"in_beam": [2], "behind": [9]}, "behind"),
        ({"in_view": [3], "in_beam": [5]}, "outside_beams"),
    ],
)
def test_conflict_cause_takes_the_first_cause_in_the_window_before_lowc(flags, cause):
    assert conflict_cause(_status(**flags), t_lowc_s=10.0, observe_window_s=8.0) == cause


def test_conflict_cause_ignores_frames_outside_the_window():
    s = _status(behind=[0, 1])  # behind long before the window: the window is clean
    assert conflict_cause(s, t_lowc_s=10.0, observe_window_s=8.0) == "missed"
    assert conflict_cause(s, t_lowc_s=np.nan, observe_window_s=8.0) == ""


def _results() -> pd.DataFrame:
    # Six conflicts (two warned in time, one late after LoWC, three never), one may-alert, two must-not.
    rows = [
        (True, False, True, 100.0, 80.0, "missed", 1, 0, 0, 0, 0),
        (True, False, False, 100.0, 90.0, "outside_beams", 2, 1, 0, 1, 0),
        (True, False, True, 100.0, 105.0, "missed", 3, 0, 0, 0, 0),
        (True, False, False, 100.0, np.nan, "behind", 0, 0, 0, 0, 0),
        (True, False, False, 100.0, np.nan, "below_13db", 1, 2, 1, 2, 1),
        (True, False, False, 100.0, np.nan, "terrain_masked", 0, 0, 0, 0, 0),
        (False, True, False, np.nan, 70.0, "", 1, 0, 0, 0, 0),
        (False, False, False, np.nan, np.nan, "", 1, 3, 0, 0, 0),
        (False, False, False, np.nan, 60.0, "", 4, 0, 0, 0, 0),
    ]
    cols = [
        "conflict",
        "may_alert",
        "observable",
        "t_lowc_s",
        "t_warning_s",
        "cause",
        "intruder_tracks",
        "clutter_tracks",
        "clutter_warning_tracks",
        "ground_tracks",
        "ground_warning_tracks",
    ]
    res = pd.DataFrame(rows, columns=cols)
    res["flight_s"] = 40.0  # 9 x 40 s = 6 minutes
    return res


def test_summary_over_all_conflicts_by_cause_with_clutter_and_fragments():
    s = summarise_layout(_results(), late_lead_s=12.5)
    assert (s["conflicts"], s["warned_before_lowc"]) == (6, 2)
    assert s["warned_before_lowc_fraction"] == pytest.approx(2 / 6)
    # Unwarned (or warned after LoWC) conflicts by cause; "missed" is the observable one.
    assert s["unwarned_by_cause"] == {
        "missed": 1,
        "behind": 1,
        "outside_beams": 0,
        "terrain_masked": 1,
        "below_13db": 1,
    }
    assert set(s["unwarned_by_cause"]) == set(CAUSES)
    assert s["missed_warnings"] == s["unwarned_by_cause"]["missed"] == 1
    assert s["must_not_alert_encounters"] == 2 and s["false_warnings"] == 1
    assert s["flight_minutes"] == pytest.approx(6.0)
    assert (s["clutter_tracks"], s["clutter_tracks_per_min"]) == (6, pytest.approx(1.0))
    assert (s["clutter_warnings"], s["encounters_with_clutter_warnings"]) == (1, 1)
    assert (s["ground_tracks"], s["ground_tracks_per_min"], s["ground_track_warnings"]) == (3, 0.5, 1)
    # Fragments over the encounters whose intruder has a track: 1, 2, 3, 1, 1, 1, 4.
    assert s["intruder_tracked_encounters"] == 7
    assert s["track_fragments_per_intruder"] == {"median": 1.0, "mean": pytest.approx(13 / 7), "max": 4}


def test_clutter_tracks_on_the_surface_or_without_a_measured_altitude_are_ground_tracks():
    from skyradar.scene.terrain import Terrain

    flat = Terrain.projected(np.full((5, 5), 100.0), 52.0, 4.0, dy_m=1000.0, dx_m=1000.0)
    rows = {  # track id: (altitude m, altitude measured); own-ship 500 m above the ground
        1: (110.0, True),  # on the surface: ground
        2: (590.0, True),  # in the air, measured: clutter only
        3: (590.0, False),  # co-altitude prior on every row: its height says nothing
        4: (600.0, True),  # the intruder
    }
    tracks = pd.DataFrame(
        [
            {"track_id": tid, "alt_m": alt, "lat_deg": 51.99, "lon_deg": 4.01, "altitude_measured": known}
            for tid, (alt, known) in rows.items()
            for _ in range(3)
        ]
    )
    labels = {1: "clutter", 2: "clutter", 3: "clutter", 4: "intruder"}
    counts = track_counts(tracks, {3}, labels, flat, own_agl_m=500.0)
    assert counts == {
        "intruder_tracks": 1,
        "clutter_tracks": 3,
        "clutter_warning_tracks": 1,
        "ground_tracks": 2,
        "ground_warning_tracks": 1,
    }
    without_flag = track_counts(tracks.drop(columns="altitude_measured"), {3}, labels, flat, own_agl_m=500.0)
    assert without_flag["ground_tracks"] == 1


def test_cost_per_frame_counts_the_shared_simulation_once():
    res = pd.DataFrame(
        {
            "terrain": "none",
            "encounter": [0, 0, 1, 1],
            "layout": ["single", "three-head"] * 2,
            "frames": [100, 100, 300, 300],
            "simulate_s": [2.0, 2.0, 6.0, 6.0],
            "process_s": [1.0, 1.0, 3.0, 3.0],
            "track_s": [0.1, 0.4, 0.3, 1.2],
            "alert_s": 0.0,
        }
    )
    c = cost_ms_per_frame(res)
    assert (c["simulate"], c["process"]) == (20.0, 10.0)
    assert (c["track_single"], c["track_three-head"]) == (1.0, 4.0)


def test_terrain_names_altitude_and_mirror():
    assert parse_terrains("none, flat-300,flat") == ["none", "flat-300", "flat-1000"]
    ground = np.array([300.0, 420.0, 550.0])  # 250 m of relief fits the 400-700 m band
    alt = own_altitude_m(ground)
    assert alt - ground.max() >= 400.0 and alt - ground.min() <= 700.0
    steep = np.array([0.0, 500.0])  # too steep for the band: clearance wins
    assert own_altitude_m(steep) - steep.max() == 400.0
    # 50 m above the ground below own-ship at 300 m AGL: flies the mirror image (550 m AGL).
    assert mirror_below_ground(np.array([50.0]), np.array([0.0]), 300.0)
    assert not mirror_below_ground(np.array([150.0]), np.array([0.0]), 300.0)


def test_jacksboro_dem_covers_every_encounter_window_and_range_limit():
    from skyradar.experiments.encounter_set import T_CPA_S, encounter_scenario
    from skyradar.scene.scenario import Scenario

    p = make_encounters(1, 0).iloc[0]
    for seed in (0, 1, 2):
        spec = encounter_scenario(p, T_CPA_S - 42.0, 44.0, 2.0, seed, "jacksboro")
        built = Scenario.from_dict(spec).build()
        own = built.ownship.sample(built.times_s)
        (lat0, lon0), r = (own.lat_deg, own.lon_deg), built.radar.range_limit_m
        for dn, de in ((r, 0.0), (-r, 0.0), (0.0, r), (0.0, -r)):  # the range limit around own-ship
            dlat, dlon = np.degrees(dn / 6.371e6), np.degrees(de / (6.371e6 * np.cos(np.radians(lat0))))
            assert np.isfinite(built.terrain.height_at(lat0 + dlat, lon0 + dlon)).all(), (seed, dn, de)


def test_bad_terrain_gives_one_line(tmp_path):
    r = skyradar("experiment", "encounters", "--terrain", "hills,moon", "--output", "o", cwd=tmp_path)
    assert_one_line_error(r, "--terrain", "moon")
    assert not (tmp_path / "o").exists()


def test_summary_markdown_says_what_was_measured_from_the_rows():
    row = {"terrain": "hills", "layout": "single", **summarise_layout(_results(), late_lead_s=12.5)}
    text = summary_markdown(
        [row], {"n": 9, "seed": 3, "family": "synthetic", "split": "development"} | {"frame_rate_hz": 4.7}
    )
    title, intro, sentence = text.split("\n\n")[:3]
    assert title == "# Encounters: synthetic, seed 3 (development set)"
    assert "9 encounters per terrain and layout, at 4.7 frames per second" in intro
    sentence = " ".join(sentence.split())
    assert "Over hills with the single layout, 2 of 6 conflicts were warned" in sentence
    assert "(33 %, 95 % interval 10 % to 70 %)" in sentence  # Wilson interval of 2 in 6
    assert "unwarned: 1 missed (observable), 1 behind, 1 terrain masked, 1 below 13 dB SNR." in sentence
    assert (
        "A warning came in 1 of the 2 encounters that must not alert, and 1 clutter track reached" in sentence
    )
    assert "| hills | single | 6 | 2 (33 %) | 10 % to 70 % |" in text and "summary.json" in text
