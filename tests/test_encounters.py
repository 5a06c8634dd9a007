"""The encounter experiment: its set, its scoring against closed-form geometry, and the full chain."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from skyradar.daa.conflict import FT
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


def _row(kind="head-on", h=0.0, v=0.0, speed=50.0, rcs=5.0, **kw) -> pd.Series:
    base = {"kind": kind, "horizontal_miss_m": h, "vertical_miss_m": v, "intruder_speed_mps": speed,
            "crossing_angle_deg": np.nan, "climb_mps": np.nan, "side": "right", "rcs_m2": rcs}  # fmt: skip
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
    [(0.9 * D_NC, 0.9 * Z_NC, True, False), (1.2 * D_NC, 0.0, False, True), (0.0, 1.3 * Z_NC, False, True),
     (1.6 * D_NC, 0.0, False, False), (0.0, 1.6 * Z_NC, False, False)],
)  # fmt: skip
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
    res = pd.DataFrame({
        "conflict": [True, True, True, False, False, False],
        "may_alert": [False, False, False, True, False, False],
        "observable": [True, True, False, False, False, False],
        "t_lowc_s": [100.0, 100.0, 100.0, np.nan, np.nan, np.nan],
        "t_warning_s": [80.0, 95.0, np.nan, 90.0, 70.0, np.nan],
    })  # fmt: skip
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

    hit = run_encounter(_row(), seed=1)
    assert hit["conflict"] and hit["observable"]
    assert hit["t_lowc_s"] == pytest.approx(T_CPA_S - D_NC / 100.0, abs=0.06)
    # Warned well ahead of the loss of well clear, by a track that follows the intruder.
    assert 12.5 <= hit["t_lowc_s"] - hit["t_warning_s"] <= 30.0
    assert hit["tracks"] >= 1 and hit["frames"] > 150
    far = run_encounter(_row(h=2.5 * D_NC), seed=1)
    assert not far["conflict"] and not far["may_alert"]
    assert np.isnan(far["t_warning_s"]) and np.isnan(far["t_other_warning_s"])


def test_experiment_writes_its_table_figure_and_summary(tmp_path):
    from skyradar.experiments.encounters import run

    s = run(tmp_path, n_encounters=4, seed=2, workers=2)
    assert s["encounters"] == 4 and s["chain"] == "full" and s["frames"] > 4 * 50
    assert 0 <= s["missed_warnings"] <= s["observable_conflicts"] <= s["conflicts"] <= 4
    assert json.loads((tmp_path / "summary.json").read_text())["encounters"] == 4
    assert (tmp_path / "encounters.png").stat().st_size > 10_000
    table = pd.read_parquet(tmp_path / "encounters.parquet")
    assert len(table) == 4 and table["frames"].gt(0).all()


def test_interrupted_run_resumes_from_its_partial_table(tmp_path):
    from skyradar.experiments import encounters as E

    key = {
        "n": 2,
        "seed": 5,
        "frame_rate_hz": 4.7,
        "buffer": 1.5,
        "uncertainty": True,
        "terrain": None,
        "version": E._version(),
    }
    _, save = E._partial_store(tmp_path, key)
    fake = {"t_lowc_s": np.nan, "t_cpa_s": 120.0, "conflict": False, "may_alert": False,
            "observable": False, "t_warning_s": np.nan, "min_horizontal_m": 3000.0, "min_vertical_m": 0.0,
            "min_distance_m": 3000.0, "t_other_warning_s": np.nan, "frames": 7, "t_start_s": 75.0,
            "tracks": 0, "detections": 0}  # fmt: skip
    save({0: fake})  # as left by a run interrupted after its first encounter
    s = E.run(tmp_path, n_encounters=2, seed=5, workers=1)
    assert s["resumed_encounters"] == 1
    table = pd.read_parquet(tmp_path / "encounters.parquet")
    assert table.loc[0, "frames"] == 7 and table.loc[1, "frames"] > 50  # row 0 kept, row 1 computed
    assert not list(tmp_path.glob("*.partial*"))
    # Different settings never reuse another run's rows.
    save({0: fake})
    assert E._partial_store(tmp_path, {**key, "seed": 6})[0] == {}


def test_flat_terrain_variant_puts_ground_under_the_whole_window():
    d = encounter_scenario(_row(), T_CPA_S - 40.0, 42.0, 4.7, 0, terrain="flat")
    built = Scenario.from_dict(d).build()
    assert built.terrain is not None and d["simulation"]["facet_size_m"] == 30.0
    own = built.ownship.sample(built.times_s).position_ned_m
    # Own-ship passes the origin at the CPA, so the ground reaches past the range limit all along.
    assert np.abs(own[:, 0]).max() + built.radar.range_limit_m < 8000.0
    assert own[:, 2] == pytest.approx(-1000.0)
    with pytest.raises(ValueError, match="terrain"):
        encounter_scenario(_row(), 0.0, 1.0, 4.7, 0, terrain="hills")
