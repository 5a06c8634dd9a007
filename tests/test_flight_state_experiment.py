"""The ch5 experiment end to end on a short flat-terrain flight (slow: simulator kernel)."""

from __future__ import annotations

import json

import pytest

from skyradar.experiments.ch5 import run


@pytest.mark.slow
def test_ch5_short_run_writes_table_json_and_figures(tmp_path):
    result = run(tmp_path, duration_s=4.0, fast_duration_s=0.0, terrains=("flat",), warmup_s=0.0)
    saved = json.loads((tmp_path / "ch5.json").read_text())
    for method in ("thesis", "robust", "terrain"):
        errors = saved["rate_1hz"]["flat"][method]
        assert {"h_err_mean_m", "h_err_sd_m", "vx_err_sd_mps", "vz_err_sd_mps"} <= set(errors)
    robust = result["rate_1hz"]["flat"]["robust"]
    assert abs(robust["h_err_mean_m"]) <= 4.0 and robust["h_err_sd_m"] <= 3.0
    assert robust["vx_err_sd_mps"] <= 1.0 and robust["vz_err_sd_mps"] <= 1.0
    assert (tmp_path / "ch5_flat_rate_1hz.png").stat().st_size > 10_000
    assert (tmp_path / "ch5_table.csv").exists()
