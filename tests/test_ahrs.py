"""The AHRS attitude-error model that replaces the true attitude in ch5's second run."""

from __future__ import annotations

import numpy as np
import pytest

from skyradar.errors import InputError
from skyradar.sim.navigation import AhrsModel, ahrs_attitude


def test_errors_have_the_model_sizes_over_a_long_record():
    t = np.arange(0.0, 50_000.0)  # 500 pitch/roll and 170 heading bias correlation times
    err = np.degrees(ahrs_attitude(np.zeros((t.size, 3)), t, seed=1))
    model = AhrsModel()
    rp = np.hypot(model.roll_pitch_noise_deg, model.roll_pitch_bias_deg)
    assert err[:, 1].std() == pytest.approx(rp, rel=0.15)
    assert err[:, 2].std() == pytest.approx(rp, rel=0.15)
    heading = np.hypot(model.heading_noise_deg, model.heading_bias_deg)
    assert err[:, 0].std() == pytest.approx(heading, rel=0.3)
    # The bias varies slowly: frame-to-frame changes are the white noise, far below the total.
    step = np.diff(err[:, 1]).std() / np.sqrt(2.0)
    assert step == pytest.approx(model.roll_pitch_noise_deg, rel=0.15)


def test_seeded_and_added_to_the_truth():
    t = np.arange(0.0, 30.0)
    truth = np.column_stack([np.full(t.size, 0.5), np.full(t.size, 0.02), np.full(t.size, -0.1)])
    a = ahrs_attitude(truth, t, seed=3)
    assert np.array_equal(a, ahrs_attitude(truth, t, seed=3))
    assert not np.array_equal(a, ahrs_attitude(truth, t, seed=4))
    assert np.all(np.abs(np.degrees(a - truth)[:, 1:]) < 2.0) and np.all(a != truth)


def test_zero_model_returns_the_truth():
    t = np.arange(0.0, 10.0)
    truth = np.random.default_rng(0).uniform(-0.5, 0.5, (t.size, 3))
    zero = AhrsModel(0.0, 0.0, 100.0, 0.0, 0.0, 300.0)
    assert np.array_equal(ahrs_attitude(truth, t, zero), truth)


@pytest.mark.parametrize(
    ("truth", "times", "model", "field"),
    [
        (np.zeros((5, 2)), np.arange(5.0), AhrsModel(), "attitude_rad"),
        (np.zeros((4, 3)), np.arange(5.0), AhrsModel(), "attitude_rad"),
        (np.zeros((3, 3)), np.array([0.0, 2.0, 1.0]), AhrsModel(), "times_s"),
        (np.zeros((3, 3)), np.array([0.0, np.nan, 1.0]), AhrsModel(), "times_s"),
        (np.zeros((3, 3)), np.arange(3.0), AhrsModel(roll_pitch_bias_deg=-0.3), "roll_pitch_bias_deg"),
        (np.zeros((3, 3)), np.arange(3.0), AhrsModel(heading_tau_s=0.0), "heading_tau_s"),
        (np.zeros((3, 3)), np.arange(3.0), AhrsModel(heading_noise_deg=float("nan")), "heading_noise_deg"),
    ],
)
def test_bad_input_names_the_field(truth, times, model, field):
    with pytest.raises(InputError, match=field):
        ahrs_attitude(truth, times, model)


def test_state_estimation_uses_the_ahrs_attitude_not_the_runs_truth():
    # The cubes carry no direction information (identical channels), so only "same" / "different"
    # is checked here; the physical size (V_Z error ~ -V * pitch error) is checked on simulated
    # frames in test_flight_state_experiment.py.
    from pandas.testing import assert_frame_equal

    from skyradar.io.frames import frames_dataset
    from skyradar.nav.flight_state import estimate_run
    from test_flight_state_ridge import CFG, flat_ground_cube

    cubes = np.stack([flat_ground_cube(45.0, 0.0, 600.0, seed=s) for s in range(3)])
    ds = frames_dataset(cubes, np.arange(3.0), CFG, ownship={"own_pitch_rad": np.zeros(3)})
    truth = estimate_run(ds, method="terrain")
    zero = AhrsModel(0.0, 0.0, 100.0, 0.0, 0.0, 300.0)
    assert_frame_equal(estimate_run(ds, method="terrain", ahrs=zero), truth)
    tilted = estimate_run(ds, method="terrain", ahrs=AhrsModel(roll_pitch_bias_deg=2.0), ahrs_seed=0)
    assert np.all(tilted["vz_raw_mps"] != truth["vz_raw_mps"])
