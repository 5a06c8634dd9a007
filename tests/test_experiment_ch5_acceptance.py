"""ch5 acceptance on the full experiment (default options), true attitude and AHRS attitude.

Every (attitude, rate, terrain, method) case is judged against :data:`skyradar.experiments.ch5.ACCEPTANCE`
(minimum share of frames with a filtered and with a raw estimate, finite errors): a method that
returns nothing fails, and a case nobody stated a bound for fails too.
"""

from __future__ import annotations

import math

import pytest

from skyradar.experiments.ch5 import ACCEPTANCE, run
from skyradar.experiments.ch5_report import acceptance_failures

# The whole ch5 experiment (about 1.5-2 CPU-minutes): `make test-slow`. `make test` keeps the short
# run of the same code in tests/test_flight_state_experiment.py.
pytestmark = pytest.mark.slow

SOURCES = ("true", "ahrs")


@pytest.fixture(scope="module")
def ch5(tmp_path_factory):
    result = run(tmp_path_factory.mktemp("ch5"))
    return {"true": result, "ahrs": result["ahrs"]}


def _rms(errors: dict) -> float:
    return math.hypot(errors["h_err_mean_m"], errors["h_err_sd_m"])


@pytest.mark.parametrize("rate", ["rate_1hz", "rate_9p4hz"])
def test_every_case_meets_its_valid_fraction_bound(ch5, rate):
    assert acceptance_failures({src: ch5[src][rate] for src in SOURCES}, ACCEPTANCE) == []


def test_the_run_reports_its_own_acceptance(ch5):
    assert ch5["true"]["acceptance_failures"] == []


@pytest.mark.parametrize("source", SOURCES)
def test_flat_terrain_filtered_height_and_velocity(ch5, source):
    robust = ch5[source]["rate_1hz"]["flat"]["robust"]
    assert abs(robust["h_err_mean_m"]) <= 4.0 and robust["h_err_sd_m"] <= 3.0
    assert robust["vx_err_sd_mps"] <= 1.0 and robust["vz_err_sd_mps"] <= 1.0


@pytest.mark.parametrize("source", SOURCES)
def test_robust_method_at_least_as_good_as_the_thesis_on_19m_terrain(ch5, source):
    robust = ch5[source]["rate_1hz"]["sd19"]["robust"]
    assert abs(robust["h_err_mean_m"]) <= 10.3 and robust["h_err_sd_m"] <= 13.1


@pytest.mark.parametrize("source", SOURCES)
@pytest.mark.parametrize("terrain", ["sd64", "jacksboro"])
def test_terrain_aware_beats_flat_plane_methods(ch5, source, terrain):
    per_method = ch5[source]["rate_1hz"][terrain]
    aware = _rms(per_method["terrain"])
    for method in ("thesis", "robust"):
        # No skip: both flat-plane methods estimate here (the bound test above), so a NaN fails.
        assert aware < _rms(per_method[method]), (source, terrain, method)


def test_the_ahrs_run_used_attitude_errors(ch5):
    # The truth run is given no attitude error; the AHRS run a heading error of the model's size.
    for terrain, per_method in ch5["ahrs"]["rate_1hz"].items():
        ahrs, true = per_method["terrain"], ch5["true"]["rate_1hz"][terrain]["terrain"]
        assert true["yaw_err_mean_deg"] == 0.0 and true["pitch_err_mean_deg"] == 0.0
        assert 0.0 < abs(ahrs["yaw_err_mean_deg"]) < 6.0 and 0.0 < abs(ahrs["pitch_err_mean_deg"]) < 1.5
