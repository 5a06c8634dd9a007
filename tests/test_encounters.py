"""The encounter experiment: its set, its scoring against closed-form geometry, and the full chain."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from cli_helpers import assert_one_line_error, skyradar
from skyradar.code_version import code_version
from skyradar.daa.alert_config import config_digest
from skyradar.daa.alerting import RADAR_ALERT_CONFIG
from skyradar.daa.conflict import FT
from skyradar.errors import InputError
from skyradar.experiments.encounter_chain import truth_warning_time
from skyradar.experiments.encounter_set import (
    OWN_SPEED_MPS,
    T_CPA_S,
    encounter_scenario,
    make_encounters,
    relative_truth,
    score_encounter,
    summarise,
)
from skyradar.scene.scenario import Scenario

D_NC, Z_NC = 2200 * FT, 450 * FT
NO_FRAMES = pd.DataFrame({"time_s": [], "observable": []})
HALF_FOV_DEG, RANGE_LIMIT_M, OBSERVE_WINDOW_S = 35.0, 5000.0, 12.5  # run_encounter's defaults, 2022 prototype
# These tests are about geometry and scoring, not the simulator: its costly realism (window PSF, speckle,
# Swerling 1) stays off, and frames come at 4.7 Hz, to keep them within the test budget.
LIGHT = {"psf": False, "speckle": False, "swerling": 0}


def _closed_form_rel(p: pd.Series, t: np.ndarray) -> np.ndarray:
    """Intruder minus own-ship NED position (m) at times ``t`` (s), from the encounter definition alone.

    Own-ship flies north, level, at OWN_SPEED_MPS; the intruder flies straight at its speed on
    own-ship's track plus the kind's angle (head-on 180 deg, overtaking 0, else the crossing angle),
    climbing at ``climb_mps``; at T_CPA_S it is ``horizontal_miss_m`` away perpendicular to the
    horizontal relative velocity, on own-ship's ``side``, and ``vertical_miss_m`` above.
    """
    angle = {"head-on": 180.0, "overtaking": 0.0}.get(p["kind"], p["crossing_angle_deg"])
    track = np.radians(angle)
    a = p["intruder_speed_mps"] * np.array([np.cos(track), np.sin(track)]) - [OWN_SPEED_MPS, 0.0]
    d = p["horizontal_miss_m"] * np.array([-a[1], a[0]]) / np.linalg.norm(a)
    if (d[1] >= 0) != (p["side"] == "right"):  # own-ship's right is east
        d = -d
    climb = 0.0 if np.isnan(p["climb_mps"]) else p["climb_mps"]
    tau = np.asarray(t, float) - T_CPA_S
    return np.stack([d[0] + a[0] * tau, d[1] + a[1] * tau, -(p["vertical_miss_m"] + climb * tau)], axis=1)


def _closed_form_lowc(p: pd.Series, scale: float = 1.0) -> float:
    """First time (s) the intruder is inside ``scale`` times the DO-365 volume; NaN when it never is.

    Horizontal separation is hypot(h, |v_rel| (t - T_CPA_S)), vertical |v + climb (t - T_CPA_S)|.
    """
    d, z = scale * D_NC, scale * Z_NC
    h, v = p["horizontal_miss_m"], p["vertical_miss_m"]
    if h > d or abs(v) > z:
        return float("nan")
    angle = {"head-on": 180.0, "overtaking": 0.0}.get(p["kind"], p["crossing_angle_deg"])
    track = np.radians(angle)
    speed = np.hypot(
        p["intruder_speed_mps"] * np.cos(track) - OWN_SPEED_MPS, p["intruder_speed_mps"] * np.sin(track)
    )
    t_h = T_CPA_S - np.sqrt(d**2 - h**2) / speed
    climb = 0.0 if np.isnan(p["climb_mps"]) else abs(p["climb_mps"])  # climbing rows have v = 0
    t_v = T_CPA_S - z / climb if climb else -np.inf
    return float(max(t_h, t_v))


def _geometrically_observable(p: pd.Series, t_lowc: float) -> bool:
    """Within the 70 deg field of view (level own-ship, forward mount) and the range limit over the
    whole window before the LoWC; the SNR is well above the 13 dB threshold at these ranges."""
    rel = _closed_form_rel(p, np.arange(t_lowc - OBSERVE_WINDOW_S, t_lowc + 1e-9, 0.05))
    az = np.degrees(np.arctan2(rel[:, 1], rel[:, 0]))
    el = np.degrees(np.arctan2(-rel[:, 2], np.hypot(rel[:, 0], rel[:, 1])))
    inside = (np.abs(az) <= HALF_FOV_DEG) & (np.abs(el) <= HALF_FOV_DEG)
    return bool(np.all(inside & (np.linalg.norm(rel, axis=1) <= RANGE_LIMIT_M)))


def _row(kind="head-on", h=0.0, v=0.0, speed=50.0, rcs=5.0, **kw) -> pd.Series:
    base = {
        "kind": kind,
        "horizontal_miss_m": h,
        "vertical_miss_m": v,
        "intruder_speed_mps": speed,
        "crossing_angle_deg": np.nan,
        "climb_mps": np.nan,
        "side": "right",
        "rcs_m2": rcs,
    }
    return pd.Series({**base, **kw})


def test_encounter_set_is_seeded_and_covers_every_kind():
    a, b = make_encounters(50, seed=3), make_encounters(50, seed=3)
    pd.testing.assert_frame_equal(a, b)
    assert set(a["kind"]) == {"head-on", "crossing", "converging", "overtaking", "climbing"}
    assert a["rcs_m2"].between(1.0, 5.0).all()
    over = a[a["kind"] == "overtaking"]
    assert (over["intruder_speed_mps"] < OWN_SPEED_MPS).all()  # own-ship overtakes: it is ahead
    climb = a[a["kind"] == "climbing"]
    assert climb["climb_mps"].abs().between(2.0, 6.0).all() and (climb["vertical_miss_m"] == 0).all()
    assert not a.equals(make_encounters(50, seed=4))


def test_scoring_matches_closed_form_head_on():
    # Head-on at 100 m/s closing, zero miss at T_CPA_S: LoWC when 2200 ft apart.
    built = Scenario.from_dict(encounter_scenario(_row(), 60.0, 10.0, 4.7, 0)).build()
    t, rel = relative_truth(built)
    r = score_encounter(t, rel, np.array([T_CPA_S - 30.0]), NO_FRAMES, 1.5, 12.5)
    assert r["conflict"] and not r["may_alert"]
    assert r["t_lowc_s"] == pytest.approx(T_CPA_S - D_NC / 100.0, abs=0.06)
    assert r["t_cpa_s"] == pytest.approx(T_CPA_S, abs=0.06) and r["min_distance_m"] < 1.0
    assert r["t_warning_s"] == T_CPA_S - 30.0


@pytest.mark.parametrize(
    ("h", "v", "conflict", "may_alert"),
    [
        (0.9 * D_NC, 0.9 * Z_NC, True, False),
        (1.2 * D_NC, 0.0, False, True),
        (0.0, 1.3 * Z_NC, False, True),
        (1.6 * D_NC, 0.0, False, False),
        (0.0, 1.6 * Z_NC, False, False),
    ],
)
def test_scoring_splits_conflict_may_alert_and_must_not(h, v, conflict, may_alert):
    built = Scenario.from_dict(encounter_scenario(_row(h=h, v=v), 60.0, 10.0, 4.7, 0)).build()
    t, rel = relative_truth(built)
    r = score_encounter(t, rel, np.array([]), NO_FRAMES, 1.5, 12.5)
    assert (r["conflict"], r["may_alert"]) == (conflict, may_alert)
    assert r["min_horizontal_m"] == pytest.approx(h, abs=0.5) and r["min_vertical_m"] == pytest.approx(
        v, abs=0.5
    )


def test_observable_needs_the_whole_window_in_view():
    built = Scenario.from_dict(encounter_scenario(_row(), 60.0, 10.0, 4.7, 0)).build()
    t, rel = relative_truth(built)
    t_lowc = T_CPA_S - D_NC / 100.0
    frames = np.arange(t_lowc - 20.0, t_lowc + 1.0, 0.25)
    seen = pd.DataFrame({"time_s": frames, "observable": np.ones(frames.size, bool)})
    assert score_encounter(t, rel, np.array([]), seen, 1.5, 12.5)["observable"]
    seen.loc[seen["time_s"].between(t_lowc - 5.0, t_lowc - 4.0), "observable"] = False
    assert not score_encounter(t, rel, np.array([]), seen, 1.5, 12.5)["observable"]


def test_summary_counts():
    res = pd.DataFrame(
        {
            "conflict": [True, True, True, False, False, False],
            "may_alert": [False, False, False, True, False, False],
            "observable": [True, True, False, False, False, False],
            "t_lowc_s": [100.0, 100.0, 100.0, np.nan, np.nan, np.nan],
            "t_warning_s": [80.0, 95.0, np.nan, 90.0, 70.0, np.nan],
        }
    )
    s = summarise(res, late_lead_s=12.5)
    assert (s["conflicts"], s["observable_conflicts"], s["missed_warnings"], s["late_warnings"]) == (
        3,
        2,
        0,
        1,
    )
    assert (s["missed_warnings_unobservable"], s["may_alert_warned"]) == (1, 1)
    assert (s["must_not_alert_encounters"], s["false_warnings"], s["false_warning_rate"]) == (2, 1, 0.5)
    assert s["median_warning_lead_s"] == pytest.approx(12.5)


def test_full_chain_warns_head_on_collision_and_stays_quiet_when_far():
    from skyradar.experiments.encounters import run_encounter

    (hit,) = run_encounter(_row(), seed=1, frame_rate_hz=4.7, simulation=LIGHT)
    assert hit["conflict"] and hit["observable"]
    assert hit["t_lowc_s"] == pytest.approx(T_CPA_S - D_NC / 100.0, abs=0.06)
    # Warned well ahead of the loss of well clear, by a track that follows the intruder.
    assert 12.5 <= hit["t_lowc_s"] - hit["t_warning_s"] <= 30.0
    assert hit["tracks"] >= 1 and hit["frames"] > 150
    assert not hit["warned_on_altitude_prior"]  # clear sky: no clutter nulls, the elevation is measured
    (far,) = run_encounter(_row(h=2.5 * D_NC), seed=1, frame_rate_hz=4.7, simulation=LIGHT)
    assert not far["conflict"] and not far["may_alert"]
    assert np.isnan(far["t_warning_s"]) and np.isnan(far["t_other_warning_s"])


def test_scoring_matches_the_closed_form_on_a_seeded_set():
    # Every kind, misses on both sides of the volume and of the may-alert buffer.
    enc = make_encounters(40, seed=7)
    expected = enc.apply(_closed_form_lowc, axis=1)
    assert 5 <= expected.notna().sum() <= 35  # the set holds conflicts and non-conflicts
    for i, p in enc.iterrows():
        built = Scenario.from_dict(encounter_scenario(p, 60.0, 10.0, 4.7, 0)).build()
        t, rel = relative_truth(built)
        np.testing.assert_allclose(rel, _closed_form_rel(p, t), atol=0.05, err_msg=f"encounter {i}")
        r = score_encounter(t, rel, np.array([]), NO_FRAMES, 1.5, OBSERVE_WINDOW_S)
        assert r["conflict"] == np.isfinite(expected[i]), i
        if r["conflict"]:  # dense truth every 0.05 s: the first sample inside the volume
            assert expected[i] <= r["t_lowc_s"] < expected[i] + 0.05 + 1e-6, i
        assert r["may_alert"] == (not r["conflict"] and np.isfinite(_closed_form_lowc(p, 1.5))), i


def test_experiment_counts_match_the_geometry_and_warns_every_observable_conflict(tmp_path):
    from skyradar.experiments.encounters import run

    enc = make_encounters(4, seed=2)
    t_lowc = enc.apply(_closed_form_lowc, axis=1)
    conflict = t_lowc.notna()
    observable = pd.Series(
        [conflict[i] and _geometrically_observable(enc.loc[i], t_lowc[i]) for i in enc.index]
    )
    may_alert = ~conflict & enc.apply(_closed_form_lowc, axis=1, scale=1.5).notna()
    # This set: three conflicts (head-on, crossing, overtaking), all in view; one clear converging.
    assert (conflict.sum(), observable.sum(), may_alert.sum()) == (3, 3, 0)

    s = run(
        tmp_path, n_encounters=4, seed=2, workers=2, frame_rate_hz=4.7, layouts=("single",), simulation=LIGHT
    )
    assert s["encounters"] == 4 and s["chain"] == "full" and s["frames"] > 4 * 50
    assert (s["terrain"], s["layout"], len(s["rows"])) == ("none", "single", 1)
    assert s["warned_before_lowc"] == conflict.sum() and s["unwarned_by_cause"]["missed"] == 0
    assert (s["conflicts"], s["observable_conflicts"]) == (conflict.sum(), observable.sum())
    assert (s["may_alert_encounters"], s["must_not_alert_encounters"]) == (may_alert.sum(), 1)
    assert s["missed_warnings"] == 0 and s["false_warnings"] == 0 and s["other_track_warnings"] == 0
    table = pd.read_parquet(tmp_path / "encounters.parquet")
    assert len(table) == 4 and table["frames"].gt(0).all() and (table["layout"] == "single").all()
    assert table["conflict"].tolist() == conflict.tolist()
    assert table["observable"].tolist() == observable.tolist()
    np.testing.assert_allclose(table["t_lowc_s"], t_lowc, atol=0.06)
    warned = table[conflict]
    assert (warned["t_warning_s"] < warned["t_lowc_s"]).all()  # every conflict warned before its LoWC
    assert table.loc[~conflict, "t_warning_s"].isna().all()
    assert json.loads((tmp_path / "summary.json").read_text())["encounters"] == 4
    assert (tmp_path / "encounters.png").stat().st_size > 10_000
    words = " ".join((tmp_path / "summary.md").read_text().split())  # the run in words, from its numbers
    assert f"{s['warned_before_lowc']} of {s['conflicts']} conflicts were warned" in words
    assert f"the median warning {s['median_warning_lead_s']:.1f} s before it" in words


def test_interrupted_run_resumes_from_its_partial_table(tmp_path):
    from skyradar.experiments import encounters as E

    settings = {
        "n": 2,
        "only": None,
        "seed": 5,
        "frame_rate_hz": 4.7,
        "buffer": 1.5,
        "uncertainty": True,
        "terrains": ["none"],
        "layouts": ["single"],
        "navigation": "ga-typical",
        "suppression": "auto",
        "late_lead_s": 12.5,
        "simulation": LIGHT,
        "rx_layout": "square",
        "family": "synthetic",
        "split": "development",
        "alert_config": "radar",
        "alert_config_digest": config_digest(RADAR_ALERT_CONFIG),
    }
    key = {**settings, "version": code_version()}
    _, save = E.partial_store(tmp_path, key)
    fake = {
        "t_lowc_s": np.nan,
        "t_cpa_s": 120.0,
        "conflict": False,
        "may_alert": False,
        "observable": False,
        "t_warning_s": np.nan,
        "min_horizontal_m": 3000.0,
        "min_vertical_m": 0.0,
        "min_distance_m": 3000.0,
        "cause": "",
        "intruder_tracks": 0,
        "clutter_tracks": 0,
        "clutter_warning_tracks": 0,
        "ground_tracks": 0,
        "ground_warning_tracks": 0,
        "t_other_warning_s": np.nan,
        "tracks": 0,
        "own_agl_m": np.nan,
        "layout": "single",
        "detections": 0,
        "frames": 7,
        "t_start_s": 75.0,
        "flight_s": 1.5,
        "mirrored": False,
        "vertical_miss_flown_m": 0.0,
        "own_altitude_m": 1000.0,
        "simulate_s": 0.0,
        "process_s": 0.0,
        "track_s": 0.0,
        "alert_s": 0.0,
    }
    save({("none", 0): [fake]})  # as left by a run interrupted after its first encounter
    s = E.run(
        tmp_path, n_encounters=2, seed=5, workers=1, frame_rate_hz=4.7, layouts=("single",), simulation=LIGHT
    )
    assert s["resumed_encounters"] == 1
    table = pd.read_parquet(tmp_path / "encounters.parquet")
    assert table.loc[0, "frames"] == 7 and table.loc[1, "frames"] > 50  # row 0 kept, row 1 computed
    assert not list(tmp_path.glob("*.partial*"))
    # Alerted with other settings (a file of fields), the same set resumes nothing of a radar run.
    save({("none", 0): [fake]})
    settings_file = tmp_path.parent / "three-of-five.yaml"
    settings_file.write_text("base: radar\nm: 3\nn: 5\n")
    s = E.run(
        tmp_path,
        n_encounters=2,
        seed=5,
        workers=1,
        frame_rate_hz=4.7,
        layouts=("single",),
        simulation=LIGHT,
        alert_settings=str(settings_file),
    )
    assert s["resumed_encounters"] == 0 and s["alert_config"] == str(settings_file)
    assert s["alert_config_digest"] != config_digest(RADAR_ALERT_CONFIG)
    # Different settings never reuse another run's rows.
    save({("none", 0): [fake]})
    assert E.partial_store(tmp_path, {**key, "seed": 6})[0] == {}
    assert E.partial_store(tmp_path, {**key, "navigation": "perfect"})[0] == {}
    assert E.partial_store(tmp_path, {**key, "rx_layout": "kite"})[0] == {}
    assert E.partial_store(tmp_path, {**key, "family": "real-flights"})[0] == {}


def test_only_reruns_an_encounter_of_the_set_as_the_whole_set_runs_it(tmp_path):
    from skyradar.experiments import encounters as E

    common = {"seed": 5, "workers": 1, "frame_rate_hz": 4.7, "layouts": ("single",), "simulation": LIGHT}
    E.run(tmp_path / "all", n_encounters=2, **common)
    s = E.run(tmp_path / "one", n_encounters=2, only=(1,), **common)
    whole, alone = (pd.read_parquet(tmp_path / d / "encounters.parquet") for d in ("all", "one"))
    assert s["encounters"] == 1 and s["only"] == [1] and alone["encounter"].tolist() == [1]
    timings = ["simulate_s", "process_s", "track_s", "alert_s"]
    same_row = whole[whole["encounter"] == 1].drop(columns=timings).reset_index(drop=True)
    pd.testing.assert_frame_equal(alone.drop(columns=timings), same_row)
    # A selection is its own run: it never resumes the whole set's rows, nor they its.
    key = {"n": 2, "seed": 5}
    _, save = E.partial_store(tmp_path / "p", {**key, "only": [1]})
    save({("none", 1): [{"frames": 7}]})
    assert E.partial_store(tmp_path / "p", {**key, "only": None})[0] == {}


@pytest.mark.parametrize(("only", "named"), [("2", "got 2"), ("1,x", "'1,x'"), ("-1", "'-1'")])
def test_bad_only_gives_one_line(tmp_path, only, named, cli):
    r = cli("experiment", "encounters", "--n", "2", "--only", only, "--output", "o", cwd=tmp_path)
    assert_one_line_error(r, "--only", named)
    assert not (tmp_path / "o").exists()


def test_bad_alert_settings_file_gives_one_line(tmp_path):
    (tmp_path / "mine.yaml").write_text("base: radar\nm: 5\nn: 4\n")
    r = skyradar("experiment", "encounters", "--alert-config", "mine.yaml", "--output", "o", cwd=tmp_path)
    assert_one_line_error(r, "mine.yaml", "m=5")
    assert not (tmp_path / "o").exists()


def test_flat_terrain_variant_puts_ground_under_the_whole_window():
    d = encounter_scenario(_row(), T_CPA_S - 40.0, 42.0, 4.7, 0, terrain="flat")
    built = Scenario.from_dict(d).build()
    assert built.terrain is not None and "facet_size_m" not in d["simulation"]  # the scenario default
    own = built.ownship.sample(built.times_s).position_ned_m
    # Own-ship passes the origin at the CPA, so the ground reaches past the range limit all along.
    assert np.abs(own[:, 0]).max() + built.radar.range_limit_m < 8000.0
    assert own[:, 2] == pytest.approx(-1000.0)
    low = encounter_scenario(_row(), T_CPA_S - 40.0, 42.0, 4.7, 0, terrain="flat-300")
    low = Scenario.from_dict(low).build()
    assert low.ownship.sample(low.times_s).position_ned_m[:, 2] == pytest.approx(-300.0)
    with pytest.raises(InputError, match="terrain"):
        encounter_scenario(_row(), 0.0, 1.0, 4.7, 0, terrain="moon")


def test_one_simulation_scores_the_nose_head_and_the_three_head_layout():
    from skyradar.experiments.encounters import run_encounter

    # A converging intruder from 50-52 deg off the nose: outside the nose's +-35 deg beam, inside the
    # right wingtip head's (yawed 75 deg).
    p = make_encounters(30, seed=0).iloc[2]
    single, three = run_encounter(
        p, seed=2, frame_rate_hz=4.7, layouts=("single", "three-head"), simulation=LIGHT
    )
    assert (single["layout"], three["layout"]) == ("single", "three-head")
    assert single["frames"] == three["frames"] and single["simulate_s"] == three["simulate_s"]  # shared
    assert single["conflict"] and three["conflict"] and single["t_lowc_s"] == three["t_lowc_s"]
    # The nose head sees it only through its beam's skirt: not observable, yet it warned in time here;
    # the cause column is empty for a conflict warned before its loss of well clear.
    assert not single["observable"] and single["t_warning_s"] < single["t_lowc_s"] and single["cause"] == ""
    assert three["observable"] and three["cause"] == ""
    assert three["t_warning_s"] < three["t_lowc_s"] and three["detections"] > single["detections"]
    assert three["intruder_tracks"] == 1 and three["clutter_tracks"] == 0


def test_a_run_resumes_only_on_the_same_code(tmp_path, monkeypatch):
    import skyradar

    package = tmp_path / "pkg"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "chain.py").write_text("GATE = 16.0\n")
    monkeypatch.setattr(skyradar, "__file__", str(package / "__init__.py"))
    before = code_version()
    assert code_version() == before
    (package / "chain.py").write_text("GATE = 9.0\n")  # the chain's code changes between two runs
    assert code_version() != before


def test_run_encounter_builds_its_scenario_with_the_simulation_and_array_asked_for():
    # The simulator options reach the scenario: a "light" test must not run the costly realism.
    from skyradar.experiments.encounter_chain import build_encounter

    built, _, _ = build_encounter(_row(), 0, 4.7, 40.0, None, ("single",), None, LIGHT, "kite")
    assert {k: built.sim_options[k] for k in LIGHT} == LIGHT
    assert built.heads[0].config.rx_positions_m[3, 2] > 0.02  # the kite's tail, m below the centre


def _truth_frames(turn_at_s: float | None, intruder_east_m: float = 0.0) -> xr.Dataset:
    """Frames truth of an own-ship flying north at 50 m/s and an intruder 3 km ahead flying south at
    50 m/s, ``intruder_east_m`` to the side, turning east (50 m/s) at ``turn_at_s`` (None: never)."""
    t = np.arange(0.0, 40.0, 0.1)
    own_n = 50.0 * t
    after = np.zeros_like(t) if turn_at_s is None else np.clip(t - turn_at_s, 0.0, None)
    before = t - after
    tgt_n, tgt_e = 3000.0 - 50.0 * before, intruder_east_m + 50.0 * after
    tgt_vn = np.where(after > 0, 0.0, -50.0)
    tgt_ve = np.where(after > 0, 50.0, 0.0)
    zeros = np.zeros_like(t)
    own = {"north_m": own_n, "east_m": zeros, "down_m": zeros - 1000.0, "vn_mps": zeros + 50.0}
    own |= {"ve_mps": zeros, "vd_mps": zeros, "yaw_rad": zeros, "pitch_rad": zeros, "roll_rad": zeros}
    tgt = {"north_m": tgt_n, "east_m": tgt_e, "down_m": zeros - 1000.0, "vn_mps": tgt_vn}
    tgt |= {"ve_mps": tgt_ve, "vd_mps": zeros}
    data = {f"own_{k}": ("time", v) for k, v in own.items()}
    data |= {f"tgt_{k}": (("time", "target"), v[:, None]) for k, v in tgt.items()}
    return xr.Dataset(data, coords={"time": t})


def test_perfect_surveillance_warns_an_intruder_that_heads_at_the_ownship_before_it_turns_away():
    # Closing at 100 m/s from 3 km, the intruder is 23 s from the loss of well clear at the start:
    # the alerter warns on its true state within seconds. It turns east at 15 s, 1.5 km away, and
    # passes 1.06 km clear (1500 m / sqrt 2): outside 1.5 times the well-clear radius, so a
    # must-not-alert encounter that perfect surveillance warns all the same.
    turning = _truth_frames(turn_at_s=15.0)
    t_warn = truth_warning_time(turning, RADAR_ALERT_CONFIG)
    assert 2.0 <= t_warn < 15.0
    # Flying parallel 2 km to the side, it is never predicted inside the volume.
    assert np.isnan(truth_warning_time(_truth_frames(None, intruder_east_m=2000.0), RADAR_ALERT_CONFIG))


def test_perfect_surveillance_reads_the_true_ownship_not_its_navigation_solution():
    truth = _truth_frames(turn_at_s=15.0)
    far_off = truth.assign(
        {f"nav_{v[4:]}": truth[v] for v in truth.data_vars if str(v).startswith("own_")}
    ).assign(nav_east_m=truth["own_east_m"] + 2000.0)
    assert truth_warning_time(far_off, RADAR_ALERT_CONFIG) == truth_warning_time(truth, RADAR_ALERT_CONFIG)


def test_false_warnings_split_by_what_perfect_surveillance_warns():
    res = pd.DataFrame(
        {
            "conflict": [False, False, False, False],
            "may_alert": [False, False, False, True],
            "observable": [False, False, False, False],
            "t_lowc_s": [np.nan] * 4,
            "t_warning_s": [90.0, 70.0, np.nan, 80.0],
            "t_truth_warning_s": [85.0, np.nan, 60.0, 80.0],
        }
    )
    s = summarise(res, late_lead_s=12.5)
    assert (s["must_not_alert_encounters"], s["false_warnings"]) == (3, 2)
    assert (s["false_warnings_alerter"], s["false_warnings_sensor"], s["must_not_alert_truth_warned"]) == (
        1,
        1,
        2,
    )
    assert np.isnan(summarise(res.drop(columns="t_truth_warning_s"), 12.5)["false_warnings_sensor"])


def test_false_warnings_on_a_co_altitude_prior_are_counted_apart():
    # Only a must-not-alert encounter's warning counts: the third is not warned, the fourth may alert.
    res = pd.DataFrame(
        {
            "conflict": [False, False, False, False],
            "may_alert": [False, False, False, True],
            "observable": [False] * 4,
            "t_lowc_s": [np.nan] * 4,
            "t_warning_s": [90.0, 70.0, np.nan, 80.0],
            "warned_on_altitude_prior": [True, False, False, True],
        }
    )
    assert summarise(res, 12.5)["false_warnings_altitude_prior"] == 1
    assert np.isnan(
        summarise(res.drop(columns="warned_on_altitude_prior"), 12.5)["false_warnings_altitude_prior"]
    )
