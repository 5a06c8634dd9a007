"""ch2 experiment: measured asymptotes, intruder pixel and wrap against closed-form geometry."""

from __future__ import annotations

import json

import pytest

from skyradar.experiments.ch2 import run


@pytest.fixture(scope="module")
def ch2(tmp_path_factory):
    out = tmp_path_factory.mktemp("ch2")
    return out, run(out, n_frames=1)


def test_asymptotes_within_one_bin(ch2):
    _, r = ch2
    assert abs(r["asymptote_range_m"] - 1000.0) <= r["range_bin_m"]
    assert abs(r["first_ground_range_m"] - 1000.0) <= r["range_bin_m"]
    assert abs(r["asymptote_velocity_mps"] - (-30.0)) <= r["doppler_bin_mps"]


def test_head_on_intruder_is_aliased_to_its_closed_form_pixel(ch2):
    _, r = ch2
    assert r["intruder_true_radial_velocity_mps"] == pytest.approx(-60.0, abs=1e-6)
    assert r["intruder_range_m"] == pytest.approx(r["intruder_expected_range_m"])
    assert r["intruder_velocity_mps"] == pytest.approx(r["intruder_expected_velocity_mps"])
    assert 17.0 < r["intruder_velocity_mps"] < 20.0  # "aliased near +20 m/s"
    assert r["intruder_snr_db"] > 13.0


def test_fast_platform_wraps_to_the_right_edge(ch2):
    _, r = ch2
    assert r["wrap60_right_edge"]
    assert (
        abs(r["wrap60_min_velocity_mps"] - r["wrap60_expected_min_velocity_mps"])
        <= 1.5 * r["doppler_bin_mps"]
    )


def test_outputs_written(ch2):
    out, r = ch2
    for name in ("ch2_flat_30mps.png", "ch2_flat_60mps.png", "ch2_table.csv", "ch2.json", "summary.md"):
        assert (out / name).stat().st_size > 0
    assert json.loads((out / "ch2.json").read_text())["intruder_range_m"] == r["intruder_range_m"]
