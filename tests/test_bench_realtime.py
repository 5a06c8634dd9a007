"""The real-time benchmark's schedule bookkeeping, its one-core pinning and its command line."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numba
import numpy as np
import pytest

from skyradar.benchmarks.realtime import one_core
from skyradar.process.realtime import paced_latencies


def _lindley(arrival: np.ndarray, cost: np.ndarray) -> np.ndarray:
    # Waiting times of a single-server queue (Lindley's recursion): w_{n+1} = max(0, w_n + s_n - a_{n+1}).
    wait, out = 0.0, []
    for n in range(len(arrival)):
        if n:
            wait = max(0.0, wait + cost[n - 1] - (arrival[n] - arrival[n - 1]))
        out.append(wait + cost[n])
    return np.array(out)


def test_latencies_follow_the_single_server_queue():
    rng = np.random.default_rng(1)
    arrival = np.cumsum(rng.exponential(0.035, 500))
    cost = rng.gamma(4.0, 0.009, 500)  # about the arrival rate: queues build and drain
    np.testing.assert_allclose(paced_latencies(arrival, cost), _lindley(arrival, cost), atol=1e-12)
    # a processor always faster than the gap between frames: latency is the processing time
    np.testing.assert_allclose(paced_latencies(np.arange(10.0), np.full(10, 0.5)), 0.5)


def test_one_core_pins_the_process_and_its_threads_and_restores_them():
    before_cores = os.sched_getaffinity(0) if hasattr(os, "sched_getaffinity") else None
    before_threads = numba.get_num_threads()
    with one_core() as core:
        if before_cores is not None:
            assert os.sched_getaffinity(0) == {core}
        assert numba.get_num_threads() == 1
    assert numba.get_num_threads() == before_threads
    if before_cores is not None:
        assert os.sched_getaffinity(0) == before_cores


@pytest.mark.parametrize("args", [("--duration-s", "1"), ("--frame-rate-hz", "0"), ("--duration-s", "nan")])
def test_bench_realtime_refuses_settings_out_of_range_in_one_line(args):
    run = subprocess.run(
        [sys.executable, "-m", "skyradar", "bench", "realtime", *args], capture_output=True, text=True
    )
    assert run.returncode == 2
    assert "Traceback" not in run.stderr and args[0] in run.stderr


@pytest.mark.slow
def test_bench_realtime_prints_its_json_last():
    run = subprocess.run(
        [sys.executable, "-m", "skyradar", "bench", "realtime", "--duration-s", "5", "--json"],
        capture_output=True,
        text=True,
        check=True,
    )
    result = json.loads(run.stdout.strip().splitlines()[-1])
    assert result["realtime_frames"] == 3 * 47 and result["realtime_threads"] == 1
    assert result["realtime_latency_p99_ms"] >= result["realtime_latency_median_ms"] > 0
