"""bench alert: the numba range-only miss distance and the numpy baseline agree; the JSON says what ran."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from skyradar.benchmarks.alert import bench_tables, range_miss_baseline
from skyradar.daa.range_miss import range_miss_distance


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_ours_and_the_baseline_give_the_same_miss_distances(seed):
    tracks, own = bench_tables(4, 300, seed)
    rng = np.random.default_rng(seed)
    rate = tracks["range_rate_mps"].to_numpy(float).copy()
    rate[rng.random(rate.size) < 0.01] = np.nan  # rows with no range rate: the fit refuses their windows
    t = tracks["time_s"].to_numpy(float)
    own_v = np.tile([50.0, 0.0, 0.0], (t.size, 1))
    own_v[t > 20.0, 1] = 5.0  # a turn: windows across it refuse
    args = (tracks["track_id"].to_numpy(), t, tracks["range_m"].to_numpy(float), rate, own_v)
    ours, base = range_miss_distance(*args), range_miss_baseline(*args)
    assert np.isfinite(ours[0]).sum() > 100 and np.isnan(ours[0]).sum() > 100  # both branches ran
    for a, b in zip(ours, base, strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-6)


def _cli(*args: str) -> subprocess.CompletedProcess:
    env = os.environ | {"COLUMNS": "200"}
    return subprocess.run(
        [sys.executable, "-m", "skyradar", "bench", "alert", *args],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )


def test_bench_alert_prints_json_last():
    out = _cli("--tracks", "3", "--frames", "60", "--json")
    assert out.returncode == 0, out.stderr
    result = json.loads(out.stdout.strip().splitlines()[-1])
    assert result["same_miss_distances"] and result["frames"] == 60 and result["tracks"] == 3
    assert result["frames_per_s"] > 0 and result["miss_speedup"] > 0
    assert result["same_stream_alerts"] and result["stream_frames"] == 60 and result["stream_speedup"] > 0


@pytest.mark.parametrize("args", [("--frames", "0"), ("--tracks", "200000", "--frames", "100000")])
def test_bench_alert_bad_sizes_are_one_line(args):
    out = _cli(*args)
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert len(out.stderr.strip().splitlines()) == 1, out.stderr
