"""ch6 acceptance on the full experiment through the real entry point (slow: a few minutes).

The acceptance bounds: the best thesis method at least 19 of 20 frames correct with at most 5 % decoy
false positives; the continuous search's median errors at most 10 m and 1 deg on decided frames; a 50 m
spoof detected in at least 95 % of decided frames at a false-alarm rate of at most 5 %; wing-up frames
all "no decision"; JSON as the last stdout line, figures and table written.
"""

from __future__ import annotations

import json

import pytest

from cli_helpers import skyradar

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def ch6(tmp_path_factory):
    folder = tmp_path_factory.mktemp("ch6")
    result = skyradar("experiment", "ch6", "--output", str(folder / "out"), "--json", cwd=folder, timeout=900)
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout.strip().splitlines()[-1]), folder / "out"


def test_best_thesis_method_meets_the_bound(ch6):
    result, _ = ch6
    assert result["best_correct"] >= 19 and result["best_false_positive"] <= 0.05


def test_continuous_search_errors(ch6):
    result, _ = ch6
    assert result["search_decided"] >= 10
    assert result["search_median_position_m"] <= 10.0 and result["search_median_heading_deg"] <= 1.0


def test_spoofing_and_wing_up(ch6):
    result, _ = ch6
    assert result["spoof_50m_detection"] >= 0.95 and result["roc_false_alarm"] <= 0.05
    assert result["wing_up_frames"] > 0 and result["wing_up_all_no_decision"]
    assert result["acceptance_failures"] == []


def test_outputs_written(ch6):
    _, out = ch6
    names = ("table.csv", "roc.csv", "frames.parquet", "ch6.json", "summary.md", "poses.png", "surface.png")
    for name in (*names, "roc.png"):
        assert (out / name).is_file(), name
