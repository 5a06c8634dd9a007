"""The pilot model: reaction delays, DAIDALUS kinematics, the return to the plan."""

from __future__ import annotations

import numpy as np
import pytest

from skyradar.errors import InputError
from skyradar.pilot import FPM_MPS, Pilot, PilotConfig
from skyradar.scene.trajectories import GRAVITY_MPS2, Trajectory

SPEED = 50.0


def _plan(duration_s: float = 400.0) -> Trajectory:
    t = np.array([0.0, duration_s])
    return Trajectory.from_states(
        t, [[0.0, 0.0, -1000.0], [SPEED * duration_s, 0.0, -1000.0]], origin=(52.0, 4.0, 0.0)
    )


def _fly(pilot: Pilot, times, level=2, heading=90.0, vs=np.nan, alert_until=np.inf):
    states = []
    for t in times:
        states.append(pilot.advance(t))
        if t <= alert_until:
            pilot.observe(t, level, heading, vs)
    return states


def _heading_deg(state) -> float:
    return float(np.degrees(state.attitude_rad[0, 0]))


def test_before_the_action_the_aircraft_is_the_plan():
    plan, pilot = _plan(), Pilot(_plan())
    times = np.arange(10.0, 14.9, 0.1)
    states = _fly(pilot, times)  # corrective from 10 s: the action is due at 15 s
    for t, state in zip(times, states, strict=True):
        np.testing.assert_array_equal(state.position_ned_m, plan.sample(t).position_ned_m)
    assert pilot.mode == "plan" and np.isnan(pilot.first_action_s)


@pytest.mark.parametrize(("level", "delay"), [(2, 5.0), (3, 3.0)])
def test_the_pilot_acts_a_reaction_delay_after_the_first_frame_of_the_alert(level, delay):
    pilot = Pilot(_plan())
    _fly(pilot, np.arange(20.0, 40.0, 0.1), level=level)
    assert pilot.first_action_s == pytest.approx(20.0 + delay)


def test_a_warning_while_a_corrective_reaction_is_pending_brings_it_forward():
    pilot = Pilot(_plan())
    _fly(pilot, np.arange(20.0, 21.0, 0.1), level=2)  # corrective: due at 25 s
    _fly(pilot, np.arange(21.0, 30.0, 0.1), level=3)  # warning at 21 s: due at 24 s
    assert pilot.first_action_s == pytest.approx(24.0)


def test_a_preventive_alert_and_an_alert_gone_for_clear_s_by_the_action_time_change_nothing():
    pilot = Pilot(_plan())
    _fly(pilot, np.arange(20.0, 40.0, 0.1), level=1)
    assert np.isnan(pilot.first_action_s)
    slow = PilotConfig(corrective_delay_s=8.0)  # due at 28 s; the alert is last seen at 20.5 s
    pilot = Pilot(_plan(), slow)
    _fly(pilot, np.arange(20.0, 40.0, 0.1), alert_until=20.5)
    assert np.isnan(pilot.first_action_s) and pilot.mode == "plan"
    pilot = Pilot(_plan(), slow)  # seen until 23.5 s: still within clear_s at 28 s, so the pilot acts
    _fly(pilot, np.arange(20.0, 40.0, 0.1), alert_until=23.5)
    assert pilot.first_action_s == pytest.approx(28.0)


def test_the_turn_is_standard_rate_and_coordinated():
    pilot = Pilot(_plan())
    states = _fly(pilot, np.arange(10.0, 30.0, 0.1), heading=90.0)
    # Acting at 15 s, 3 deg/s: 40 deg at 28.33 s; the bank of a coordinated turn is atan(v omega / g).
    state = states[-1]  # 29.9 s
    assert _heading_deg(state) == pytest.approx(3.0 * (29.9 - 15.0), abs=0.05)
    bank = np.degrees(np.arctan(SPEED * np.radians(3.0) / GRAVITY_MPS2))
    assert np.degrees(state.attitude_rad[0, 2]) == pytest.approx(bank, abs=1e-6)
    assert np.hypot(*state.velocity_ned_mps[0, :2]) == pytest.approx(SPEED)  # the speed is kept
    # Turning the shorter way: to 300 deg is a left turn.
    pilot = Pilot(_plan())
    states = _fly(pilot, np.arange(10.0, 20.0, 0.1), heading=300.0)
    assert _heading_deg(states[-1]) == pytest.approx(-3.0 * (19.9 - 15.0), abs=0.05)


def test_a_vertical_manoeuvre_changes_the_vertical_speed_at_a_quarter_g_and_by_at_least_500_fpm():
    pilot = Pilot(_plan(), PilotConfig(manoeuvre="vertical"))
    states = _fly(pilot, np.arange(10.0, 30.0, 0.05), heading=90.0, vs=1.0)  # asks for 1 m/s up
    vs = np.array([-s.velocity_ned_mps[0, 2] for s in states])
    assert vs.max() == pytest.approx(500.0 * FPM_MPS, rel=1e-6)  # at least a 500 ft/min change
    rate = np.diff(vs) / 0.05
    assert rate.max() <= 0.25 * GRAVITY_MPS2 + 1e-6
    assert _heading_deg(states[-1]) == pytest.approx(0.0, abs=1e-9)  # the heading is kept


def test_clear_of_conflict_the_pilot_returns_to_the_planned_path():
    cfg = PilotConfig()
    pilot = Pilot(_plan(), cfg)
    _fly(pilot, np.arange(10.0, 200.0, 0.1), heading=60.0, alert_until=40.0)
    assert pilot.mode == "rejoined"
    flown = pilot.flown()
    assert flown["east_m"].max() > 300.0  # it did leave the path
    last = flown.iloc[-1]
    assert abs(last["east_m"]) <= cfg.rejoin_tolerance_m and abs(last["down_m"] + 1000.0) <= 1e-6
    # Time off the plan: from the action (15 s) to the rejoin, avoiding included.
    rejoined_at = float(flown.loc[flown["mode"] == "rejoined", "time_s"].iloc[0])
    assert pilot.manoeuvre_s == pytest.approx(rejoined_at - 15.0, abs=0.1)


def test_time_never_goes_back_and_bad_settings_are_refused():
    pilot = Pilot(_plan())
    pilot.advance(10.0)
    with pytest.raises(ValueError, match="before the last state"):
        pilot.advance(9.0)
    for bad in (
        {"turn_rate_dps": 0.0},
        {"corrective_delay_s": -1.0},
        {"clear_s": np.nan},
        {"respond_level": 4},
    ):
        with pytest.raises(InputError, match="pilot: field"):
            PilotConfig(**bad)
