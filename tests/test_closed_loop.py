"""The closed loop: the pilot flies the advice, the chain sees the aircraft the pilot flies."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from skyradar.closed_loop import (
    ClosedLoopChain,
    fly_perfect_surveillance,
    fly_unequipped,
    separation,
)
from skyradar.daa.alerting import RADAR_ALERT_CONFIG
from skyradar.experiments.closed_loop import risk_ratio, summarise_closed_loop
from skyradar.scene.scenario import Scenario


def _head_on(
    duration_s: float = 70.0,
    frame_rate_hz: float = 2.0,
    lateral_m: float = 30.0,
    ahead_m: float = 6000.0,
    behind: bool = False,
    range_limit_m: float = 3000.0,
):
    """Own-ship north at 50 m/s; an intruder ``ahead_m`` ahead flying south at 50 m/s, ``lateral_m``
    east of the own-ship's track (or, ``behind``, 600 m behind it, flying north slower)."""
    intruder = (
        {"start_ned_m": [-600.0, lateral_m, -1000.0], "heading_deg": 0.0, "speed_mps": 40.0}
        if behind
        else {"start_ned_m": [ahead_m, lateral_m, -1000.0], "heading_deg": 180.0, "speed_mps": 50.0}
    )
    spec = {
        "name": "closed-loop head-on",
        "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
        "radar": {"range_limit_m": range_limit_m},
        "ownship": {"type": "straight", "start_ned_m": [0, 0, -1000], "speed_mps": 50},
        "intruders": [{"name": "A", "type": "straight", "rcs_m2": 5.0, **intruder}],
        "frame_rate_hz": frame_rate_hz,
        "duration_s": duration_s,
    }
    return Scenario.from_dict(spec).build()


def test_with_perfect_surveillance_the_pilot_turns_away_and_keeps_well_clear():
    built = _head_on()
    intruder = built.intruders[0].trajectory
    unequipped = separation(fly_unequipped(built).flown, intruder)
    run = fly_perfect_surveillance(built, alert_config=RADAR_ALERT_CONFIG)
    equipped = separation(run.flown, intruder)
    assert unequipped["nmac"] == 1.0 and unequipped["min_horizontal_m"] == pytest.approx(30.0, abs=0.5)
    assert equipped["lowc"] == 0.0 and equipped["min_horizontal_m"] > 670.0
    # The pilot acts the corrective delay after the first corrective alert (a warning: the warning delay).
    first = float(run.alerts.loc[run.alerts["level"] >= 2, "time_s"].min())
    first_level = int(run.alerts.loc[run.alerts["time_s"] == first, "level"].max())
    delay = 3.0 if first_level >= 3 else 5.0
    assert run.first_action_s == pytest.approx(first + delay, abs=0.06)
    # It holds the turn until the traffic has passed its closest approach, then returns to the plan.
    back = run.flown.loc[run.flown["mode"] == "return", "time_s"]
    assert len(back) and float(back.iloc[0]) >= 60.0 - 0.5
    assert run.manoeuvre_s > 0.0


def test_an_intruder_that_never_alerts_leaves_the_plan_alone():
    built = _head_on(behind=True, lateral_m=2000.0)
    run = fly_perfect_surveillance(built, alert_config=RADAR_ALERT_CONFIG)
    assert np.isnan(run.first_action_s) and run.manoeuvre_s == 0.0
    plan = built.ownship.sample(run.flown["time_s"].to_numpy())
    np.testing.assert_allclose(run.flown[["north_m", "east_m", "down_m"]].to_numpy(), plan.position_ned_m)


def test_the_radar_frames_are_simulated_from_where_the_pilot_took_the_aircraft():
    built = _head_on(duration_s=30.0, frame_rate_hz=4.0, ahead_m=3000.0, range_limit_m=2500.0)
    chain = ClosedLoopChain(built, alert_config=RADAR_ALERT_CONFIG)
    chain.run()
    truth = chain.tables()["truth"]
    flown = chain.pilot.flown()
    assert np.isfinite(chain.pilot.first_action_s)  # the radar's alerts made the pilot turn
    own_east = truth["own_east_m"].values
    flown_east = np.interp(chain.built.times_s, flown["time_s"], flown["east_m"])
    assert np.abs(own_east).max() > 100.0  # the frames' own-ship left the planned track ...
    np.testing.assert_allclose(own_east, flown_east, atol=1e-6)  # ... exactly as the pilot flew


def _long_table() -> pd.DataFrame:
    """Four encounters: 0 and 1 lose well clear unequipped; equipped resolves 0, keeps 1, induces 2."""
    rows = []
    unequipped = {0: (1, 1), 1: (1, 0), 2: (0, 0), 3: (0, 0)}
    radar = {0: (0, 0), 1: (1, 0), 2: (1, 0), 3: (0, 0)}
    for enc in range(4):
        for condition, layout, (lowc, nmac) in (
            ("unequipped", "", unequipped[enc]),
            ("perfect", "", (0, 0)),
            ("radar", "single", radar[enc]),
        ):
            rows.append(
                {
                    "terrain": "none",
                    "encounter": enc,
                    "condition": condition,
                    "layout": layout,
                    "lowc": float(lowc),
                    "nmac": float(nmac),
                    "min_horizontal_m": 100.0 if lowc else 1000.0,
                    "first_action_s": np.nan if condition == "unequipped" else 10.0,
                    "manoeuvre_s": 0.0 if condition == "unequipped" else 20.0,
                    "runtime_s": 1.0,
                }
            )
    return pd.DataFrame(rows)


def test_the_summary_counts_risk_ratios_induced_and_resolved_losses():
    rows = summarise_closed_loop(_long_table())
    perfect, radar = rows
    assert (perfect["condition"], radar["condition"], radar["layout"]) == ("perfect", "radar", "single")
    assert perfect["lowc_risk_ratio"] == 0.0 and perfect["lowc_resolved"] == 2
    assert radar["lowc_unequipped"] == 2 and radar["lowc_equipped"] == 2
    assert radar["lowc_risk_ratio"] == 1.0 and radar["lowc_induced"] == 1 and radar["lowc_resolved"] == 1
    assert radar["nmac_risk_ratio"] == 0.0 and radar["nmac_resolved"] == 1
    lo, hi = radar["lowc_risk_ratio_interval"]
    assert lo <= 1.0 <= hi


def test_the_risk_ratio_interval_narrows_with_more_encounters():
    rng = np.random.default_rng(0)
    base = rng.random(400) < 0.5
    equipped = base & (rng.random(400) < 0.2)
    ratio, (lo, hi) = risk_ratio(equipped, base)
    _, (lo_small, hi_small) = risk_ratio(equipped[:40], base[:40])
    assert lo <= ratio <= hi and hi - lo < hi_small - lo_small
    assert ratio == pytest.approx(0.2, abs=0.07)


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--family", "real-flights"], "--family"),
        (["--corrective-delay-s", "-1"], "--corrective-delay-s"),
        (["--terrain", "moon"], "--terrain"),
        (["--seed", "5", "--split", "evaluation"], "--seed 5"),
    ],
)
def test_bad_input_gets_one_line_and_exit_code_2(tmp_path, args, needle):
    cmd = [sys.executable, "-m", "skyradar", "experiment", "closed-loop", "-o", str(tmp_path / "o"), *args]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert needle in proc.stderr and "Traceback" not in proc.stderr
    assert not (tmp_path / "o").exists()


@pytest.mark.slow
def test_the_experiment_runs_from_the_command_line_and_prints_its_json_last(tmp_path):
    out = tmp_path / "cl"
    cmd = [sys.executable, "-m", "skyradar", "experiment", "closed-loop", "--n", "1", "--workers", "1"]
    proc = subprocess.run([*cmd, "-o", str(out), "--json"], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    summary = json.loads(proc.stdout.strip().splitlines()[-1])
    assert [(r["condition"], r["layout"]) for r in summary["rows"]] == [("perfect", ""), ("radar", "single")]
    for name in ("closed_loop.parquet", "closed_loop.csv", "summary.json", "summary.md", "closed_loop.png"):
        assert (out / name).exists()
    assert not (out / "closed-loop.partial.parquet").exists()


def test_the_experiment_writes_its_tables_summary_and_figure_and_resumes(tmp_path, monkeypatch):
    """The set's plumbing (runner, partial table, summary, report) with each encounter's flights
    replaced by fixed rows: encounter i loses well clear unequipped when i is even, and the radar
    resolves every loss but the first encounter's."""
    import skyradar.experiments.closed_loop as experiment

    calls = []

    def flights(p, seed=0, terrain=None, layouts=("single",), **_):
        i = seed - 100
        calls.append(i)
        lost = float(i % 2 == 0)
        base = {"min_horizontal_m": 300.0 if lost else 900.0, "first_action_s": np.nan, "manoeuvre_s": 0.0}
        rows = [
            {"condition": "unequipped", "layout": "", "lowc": lost, "nmac": 0.0, **base, "runtime_s": 0.0}
        ]
        rows.append({**rows[0], "condition": "perfect", "lowc": 0.0, "min_horizontal_m": 800.0})
        radar_lost = float(lost and i == 0)
        rows += [
            {**rows[0], "condition": "radar", "layout": layout, "lowc": radar_lost, "first_action_s": 10.0}
            for layout in layouts
        ]
        return rows

    monkeypatch.setattr(experiment, "run_closed_loop_encounter", flights)
    summary = experiment.run(tmp_path / "a", n_encounters=4, seed=100, workers=1)
    assert sorted(calls) == [0, 1, 2, 3]
    perfect, radar = summary["rows"]
    assert (perfect["lowc_unequipped"], perfect["lowc_equipped"], radar["lowc_equipped"]) == (2, 0, 1)
    assert radar["lowc_risk_ratio"] == 0.5 and radar["lowc_resolved"] == 1 and radar["lowc_induced"] == 0
    for name in ("closed_loop.parquet", "closed_loop.csv", "summary.json", "summary.md", "closed_loop.png"):
        assert (tmp_path / "a" / name).exists()
    assert "| none | radar, single | 2/4 | 1/4 | 0.50" in (tmp_path / "a" / "summary.md").read_text()
    # An interrupted run resumes from its partial table when started again with the same settings.
    calls.clear()
    done, save = experiment_partial(tmp_path / "b", summary["settings"])
    save({("none", 0): flights(None, seed=100), ("none", 1): flights(None, seed=101)})
    calls.clear()
    resumed = experiment.run(tmp_path / "b", n_encounters=4, seed=100, workers=1)
    assert sorted(calls) == [2, 3] and resumed["resumed_encounters"] == 2
    assert resumed["rows"][1]["lowc_equipped"] == 1


def experiment_partial(out_dir, settings):
    from skyradar.code_version import code_version
    from skyradar.experiments.encounters import partial_store

    out_dir.mkdir(parents=True)
    return partial_store(out_dir, {**settings, "version": code_version()}, "closed-loop.partial.parquet")
