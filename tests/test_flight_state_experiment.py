"""The ch5 experiment end to end on short flat-terrain flights: valid fractions and the AHRS run."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from skyradar.experiments.ch5 import run
from skyradar.experiments.ch5_report import acceptance_failures
from skyradar.sim.navigation import AhrsModel, ahrs_attitude

SHORT = {"duration_s": 4.0, "fast_duration_s": 0.0, "terrains": ("flat",), "warmup_s": 1.0}
SPEED_MPS = 55.0  # ch5's ground speed


@pytest.fixture(scope="module")
def short(tmp_path_factory):
    out = tmp_path_factory.mktemp("ch5_short")
    return out, run(out, **SHORT)


def test_short_run_writes_table_json_and_figures(short):
    out, result = short
    saved = json.loads((out / "ch5.json").read_text())
    for block in (saved["rate_1hz"], saved["ahrs"]["rate_1hz"]):
        for method in ("thesis", "robust", "terrain"):
            errors = block["flat"][method]
            assert {"h_err_mean_m", "h_err_sd_m", "vx_err_sd_mps", "vz_err_sd_mps"} <= set(errors)
            # Over flat ground every method estimates every frame.
            assert errors["valid_fraction"] == 1.0 and errors["raw_valid_fraction"] == 1.0, method
    assert saved["ahrs_model"]["seed"] == 5
    robust = result["rate_1hz"]["flat"]["robust"]
    assert abs(robust["h_err_mean_m"]) <= 4.0 and robust["h_err_sd_m"] <= 3.0
    assert robust["vx_err_sd_mps"] <= 1.0 and robust["vz_err_sd_mps"] <= 1.0
    assert (out / "ch5_flat_rate_1hz.png").stat().st_size > 10_000
    assert "`ch5_flat_rate_1hz.png`" in (out / "summary.md").read_text()
    table = pd.read_csv(out / "ch5_table.csv")
    assert sorted(set(table["attitude"])) == ["ahrs", "true"] and len(table) == 6


def test_the_ahrs_run_estimates_with_the_ahrs_attitude(short):
    out, _ = short
    state = pd.read_parquet(out / "state_flat_rate_1hz_terrain_ahrs.parquet")
    times = state["time_s"].to_numpy()
    expected = ahrs_attitude(np.zeros((times.size, 3)), times, seed=5)
    used = state[["used_yaw_rad", "used_pitch_rad", "used_roll_rad"]].to_numpy()
    np.testing.assert_array_equal(used, expected)
    assert np.all(used != 0.0)
    truth_run = pd.read_parquet(out / "state_flat_rate_1hz_terrain.parquet")
    assert np.all(truth_run[["used_yaw_rad", "used_pitch_rad", "used_roll_rad"]].to_numpy() == 0.0)


def test_estimators_follow_the_given_attitude_not_the_truth(tmp_path):
    # A zero-error AHRS must reproduce the true-attitude run exactly ...
    zero = run(tmp_path / "zero", **SHORT, ahrs=AhrsModel(0.0, 0.0, 100.0, 0.0, 0.0, 300.0))
    assert zero["ahrs"]["rate_1hz"] == zero["rate_1hz"]
    # ... and a pitch bias must tilt the terrain-aware velocity: V_Z error ~ -V * pitch error.
    tilted = AhrsModel(roll_pitch_noise_deg=0.0, roll_pitch_bias_deg=2.0, roll_pitch_tau_s=1e6)
    res = run(tmp_path / "tilted", **SHORT, ahrs=tilted, seed=0)
    ahrs, true = res["ahrs"]["rate_1hz"]["flat"]["terrain"], res["rate_1hz"]["flat"]["terrain"]
    pitch_rad = np.radians(ahrs["pitch_err_mean_deg"])
    assert abs(ahrs["pitch_err_mean_deg"]) > 0.5  # this seed's bias is large enough to see
    shift = ahrs["vz_err_mean_mps"] - true["vz_err_mean_mps"]
    assert shift == pytest.approx(-SPEED_MPS * pitch_rad, rel=0.1)


def _case(valid: float, raw: float, h: float = 2.0) -> dict[str, float]:
    return {
        "h_err_mean_m": h,
        "h_err_sd_m": 0.3,
        "vx_err_sd_mps": 0.01,
        "vz_err_sd_mps": 0.03,
        "valid_fraction": valid,
        "raw_valid_fraction": raw,
    }


def test_acceptance_fails_a_method_that_returns_nothing():
    bound = {("flat", "robust"): (1.0, 0.8), ("flat", "thesis"): (1.0, 0.8)}
    good = {"flat": {"robust": _case(1.0, 1.0), "thesis": _case(1.0, 0.9)}}
    assert acceptance_failures({"true": good}, bound) == []
    nothing = {"flat": {"robust": _case(0.0, 0.0, h=float("nan")), "thesis": _case(1.0, 0.9)}}
    assert any("true/flat/robust" in f for f in acceptance_failures({"true": nothing}, bound))
    # JSON nulls are "no estimate" too.
    null = {"flat": {"robust": {**_case(1.0, 1.0), "h_err_sd_m": None}, "thesis": _case(1.0, 0.9)}}
    assert acceptance_failures({"true": null}, bound) == ["true/flat/robust: h_err_sd_m is not finite"]
    # A filter coasting on predictions (filtered valid, few raw estimates) fails the raw bound.
    coasting = {"flat": {"robust": _case(1.0, 0.1), "thesis": _case(1.0, 0.9)}}
    assert acceptance_failures({"ahrs": coasting}, bound) == [
        "ahrs/flat/robust: raw_valid_fraction 0.1 < 0.8"
    ]


def test_acceptance_judges_every_case():
    results = {"true": {"flat": {"robust": _case(1.0, 1.0), "terrain": _case(1.0, 1.0)}}}
    failures = acceptance_failures(results, {("flat", "robust"): (1.0, 0.8), ("flat", "terrain"): None})
    assert failures == ["true/flat/terrain: stated to give no estimate, valid_fraction 1"]
    assert acceptance_failures(results, {("flat", "robust"): (1.0, 0.8)}) == [
        "true/flat/terrain: no stated bound"
    ]


@pytest.mark.parametrize(
    ("args", "needles"),
    [
        (["--duration", "4"], ["--duration", "warm-up", "4"]),
        (["--duration", "20", "--fast-duration", "2"], ["--fast-duration", "2"]),
    ],
)
def test_cli_refuses_a_flight_shorter_than_the_warmup(tmp_path, args, needles):
    # Run anyway, every error would be NaN (no frame after the 5 s warm-up) with exit code 0.
    result = subprocess.run(
        [sys.executable, "-m", "skyradar", "experiment", "ch5", "--output", str(tmp_path / "o"), *args],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 2, result.stderr
    lines = [line for line in result.stderr.strip().splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: ") and "Traceback" not in result.stderr
    for needle in needles:
        assert needle in lines[0], lines[0]
    assert not (tmp_path / "o").exists()


def test_without_ahrs_noise_only_the_true_attitude_run_is_reported(tmp_path):
    result = run(tmp_path, **SHORT, ahrs=None)
    assert result["ahrs"] is None and result["ahrs_model"] is None
    assert {row["attitude"] for row in result["table"]} == {"true"}
    assert not list(tmp_path.glob("*_ahrs.parquet"))
