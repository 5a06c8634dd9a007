"""Issue 6 acceptance, asserted on the full ch5 experiment (about 40 s on 2 cores)."""

from __future__ import annotations

import math

import pytest

from skyradar.experiments.ch5 import run


@pytest.fixture(scope="module")
def ch5(tmp_path_factory):
    return run(tmp_path_factory.mktemp("ch5"))["rate_1hz"]


def _rms(errors: dict) -> float:
    return math.hypot(errors["h_err_mean_m"], errors["h_err_sd_m"])


def test_flat_terrain_filtered_height_and_velocity(ch5):
    robust = ch5["flat"]["robust"]
    assert abs(robust["h_err_mean_m"]) <= 4.0 and robust["h_err_sd_m"] <= 3.0
    assert robust["vx_err_sd_mps"] <= 1.0 and robust["vz_err_sd_mps"] <= 1.0


def test_robust_method_at_least_as_good_as_the_thesis_on_19m_terrain(ch5):
    robust = ch5["sd19"]["robust"]
    assert abs(robust["h_err_mean_m"]) <= 10.3 and robust["h_err_sd_m"] <= 13.1


@pytest.mark.parametrize("terrain", ["sd64", "jacksboro"])
def test_terrain_aware_beats_flat_plane_methods(ch5, terrain):
    aware = _rms(ch5[terrain]["terrain"])
    for method in ("thesis", "robust"):
        errors = ch5[terrain][method]
        if errors["h_err_mean_m"] is not None and not math.isnan(errors["h_err_mean_m"]):
            assert aware < _rms(errors), (terrain, method)
