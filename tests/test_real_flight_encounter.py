"""A recorded own-ship flight, its fixes made worse as real ADS-B is, against a collision-course glider.

The own-ship is a calibration aircraft's real flight (5-s OpenSky fixes, velocity columns off its
course) with more faults added: time stamps jittered by up to 0.3 s, 10 m of position noise and 5 %
stale positions. The intruder is a real glider's recorded track, moved to pass 100 m from the
own-ship at the same height. The scenario flies the fixes file itself (``ownship: {type: file}``),
so the chain sees the flyable path built from the faulty fixes, and must warn at least 12.5 s
before the loss of well clear and hold the warning to the closest approach.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import yaml

from skyradar.chain import label_tracks, run_chain
from skyradar.daa.alerting import RADAR_ALERT_CONFIG
from skyradar.experiments.encounter_set import event_times, relative_truth
from skyradar.scene.adsb import read_trajectory
from skyradar.scene.encounter_from_tracks import encounter_from_tracks, encounter_scenario, trajectory_table
from skyradar.scene.sample_flights import sample_flight
from skyradar.scene.scenario import Scenario

T_CPA_S = 900.0  # a straight leg of the calibration flight, 63 m/s at about 400 m
GLIDER_TIME_S = 5000.0


def _faulty_fixes(folder, rng) -> float:
    """The own-ship's recorded fixes around the meeting, made worse; returns the unix time of t = 0."""
    raw = pd.read_json(sample_flight("calibration/cardiff"))
    unix = (pd.to_datetime(raw["timestamp"], utc=True) - pd.Timestamp(0, tz="UTC")).dt.total_seconds()
    zero = float(unix.min())
    raw["timestamp"] = unix + rng.uniform(-0.3, 0.3, len(raw))
    raw["latitude"] += rng.normal(0.0, 10.0 / 111_200.0, len(raw))
    raw["longitude"] += rng.normal(0.0, 10.0 / 69_400.0, len(raw))
    stale = np.flatnonzero(rng.random(len(raw)) < 0.05)
    stale = stale[stale > 0]
    raw.loc[stale, ["latitude", "longitude"]] = raw.loc[stale - 1, ["latitude", "longitude"]].to_numpy()
    near = np.abs(unix - zero - T_CPA_S) < 150.0
    raw[near].to_csv(folder / "own_fixes.csv", index=False)
    return zero


@pytest.fixture(scope="module")
def chain(tmp_path_factory):
    folder = tmp_path_factory.mktemp("real_flight")
    zero = _faulty_fixes(folder, np.random.default_rng(0))
    own = read_trajectory(folder / "own_fixes.csv", time_zero_s=zero)
    glider = read_trajectory(sample_flight("gliders/cevennes"), aircraft_class="glider")
    glider = glider.shifted(-glider.start_s).between(GLIDER_TIME_S - 150.0, GLIDER_TIME_S + 150.0)
    own, intruder = encounter_from_tracks(own, glider, T_CPA_S, 100.0, 0.0, intruder_time_s=GLIDER_TIME_S)
    trajectory_table(intruder).to_csv(folder / "glider.csv", index=False)
    scenario = encounter_scenario(own, intruder, "own_fixes.csv", "glider.csv", T_CPA_S, 60.0, 8.0)
    scenario["ownship"]["time_zero_s"] = zero  # the raw fixes file, on the recording's clock
    scenario["intruders"][0]["aircraft_class"] = "glider"
    scenario["frame_rate_hz"] = 9.4
    (folder / "enc.yaml").write_text(yaml.safe_dump(scenario))
    built = Scenario.from_dict(scenario, source=folder / "enc.yaml").build()
    return built, run_chain(built, RADAR_ALERT_CONFIG, with_advice=False)


def test_the_recorded_ownship_is_flown_as_an_aircraft_flies(chain):
    built, _out = chain
    s = built.ownship.sample(built.times_s)
    speed = np.linalg.norm(s.velocity_ned_mps, axis=1)
    accel = np.linalg.norm(np.gradient(s.velocity_ned_mps, s.time_s, axis=0)[:, :2], axis=1)
    assert speed.min() > 30.0 and speed.max() < 100.0  # the file says 62-64 m/s ground speed
    assert accel.max() <= 10.0 + 0.5  # within the 'ga' class (finite differences of the spline)


def test_a_collision_course_glider_is_warned_early_and_the_warning_held(chain):
    built, out = chain
    t, rel = relative_truth(built)
    t_lowc, t_cpa = event_times(t, rel)
    assert np.isfinite(t_lowc)
    labels = label_tracks(out["tracks"], out["truth"])
    intruder_ids = [i for i, name in labels.items() if name == built.intruders[0].name]
    assert len(intruder_ids) == 1  # one track for the glider, none for anything else
    alerts = out["alerts"]
    warning = np.sort(
        alerts.loc[(alerts["level"] >= 3) & alerts["track_id"].isin(intruder_ids), "time_s"].unique()
    )
    assert warning.size and t_lowc - warning[0] >= 12.5, (t_lowc, warning[:3])
    # Held from its first issue to the closest approach, or to when the glider leaves the forward
    # head's beams just before it (it passes 100 m abeam): no frame without it.
    truth = out["truth"]
    visible = truth["tgt_visible"].values.reshape(truth.sizes["time"], -1)[:, 0]
    last_seen = float(np.asarray(built.times_s)[visible][-1])
    assert np.diff(warning).max() < 0.25
    assert warning[-1] >= min(t_cpa, last_seen) - 0.25, (warning[-1], t_cpa, last_seen)


@pytest.mark.slow
def test_the_real_flight_family_is_seeded_and_its_geometry_is_flown():
    from skyradar.daa.conflict import WellClearVolume
    from skyradar.experiments.encounter_real import make_real_encounters, real_pair
    from skyradar.scene.encounter_from_tracks import horizontal_cpa

    a, b = make_real_encounters(6, seed=3), make_real_encounters(6, seed=3)
    pd.testing.assert_frame_equal(a, b)
    vol = WellClearVolume.do365_noncoop()
    assert (a["horizontal_miss_m"] <= 3.0 * vol.dthr_m).all() and (
        a["vertical_miss_m"].abs() <= 3 * vol.zthr_m
    ).all()
    for _, p in a.head(3).iterrows():
        own, intruder = real_pair(p)
        t, h_m, v_m = horizontal_cpa(own, intruder, window=(60.0, 130.0))
        # The drawn miss is met at the meeting time, unless the flights turn there (then their real
        # closest approach is nearby: what the scenario flies is what is scored).
        assert abs(t - 120.0) < 15.0 and h_m <= p["horizontal_miss_m"] + 1.0
        speed = np.linalg.norm(own.sample(np.arange(0.0, 130.0)).velocity_ned_mps, axis=1)
        assert speed.min() >= 35.0 and speed.max() <= 90.0  # the stretches are chosen at GA speeds


def test_a_warning_is_held_only_when_no_frame_drops_it():
    from skyradar.experiments.encounter_chain import warning_held

    ft = np.arange(0.0, 20.0, 0.1)
    status = pd.DataFrame({"time_s": ft, "observable": ft < 18.0})  # leaves the beams at 18 s
    continuous = ft[(ft >= 5.0) & (ft < 18.0)]
    assert warning_held(continuous, status, t_cpa_s=19.0) == (True, pytest.approx(0.1))
    dropped = continuous[(continuous < 9.0) | (continuous > 10.0)]  # a second without it
    held, gap = warning_held(dropped, status, t_cpa_s=19.0)
    assert not held and gap == pytest.approx(1.2, abs=0.01)  # 8.9 s to 10.1 s
    ended_early = continuous[continuous < 12.0]  # gone 6 s before the intruder left the beams
    assert not warning_held(ended_early, status, t_cpa_s=19.0)[0]
    assert warning_held(np.array([]), status, t_cpa_s=19.0) == (True, 0.0)
