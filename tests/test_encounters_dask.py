"""The encounter set on a Dask cluster gives the rows of the same set run in one process."""

from __future__ import annotations

import json

import distributed
import pandas as pd

from cli_helpers import assert_one_line_error, skyradar

# Wall times differ run to run; everything else in a row is the encounter's result.
_TIMINGS = ["simulate_s", "process_s", "track_s", "alert_s"]


def test_encounters_on_a_dask_scheduler_match_the_local_run(tmp_path):
    common = (
        "experiment",
        "encounters",
        "--n",
        "2",
        "--layout",
        "single",
        "--frame-rate-hz",
        "4.7",
        "--json",
    )
    with distributed.LocalCluster(
        n_workers=1,
        threads_per_worker=1,
        processes=True,
        dashboard_address=":0",
        scheduler_kwargs={"dashboard": False},
    ) as cluster:  # the test's own scheduler, as a user's cluster would be
        on_dask = skyradar(
            *common, "--output", "dask", "--scheduler", cluster.scheduler_address, cwd=tmp_path
        )
    here = skyradar(*common, "--output", "here", "--workers", "1", cwd=tmp_path)
    assert on_dask.returncode == 0, on_dask.stderr
    assert here.returncode == 0, here.stderr
    tables = [
        pd.read_parquet(tmp_path / name / "encounters.parquet").drop(columns=_TIMINGS)
        for name in ("dask", "here")
    ]
    pd.testing.assert_frame_equal(*tables)
    summaries = [json.loads(run.stdout.strip().splitlines()[-1]) for run in (on_dask, here)]
    assert summaries[0]["rows"] == summaries[1]["rows"]
    assert summaries[0]["scheduler"] == cluster.scheduler_address and summaries[1]["scheduler"] is None


def test_a_scheduler_that_does_not_answer_is_one_line(tmp_path):
    result = skyradar(
        "experiment",
        "encounters",
        "--n",
        "1",
        "--scheduler",
        "tcp://127.0.0.1:9",
        "--output",
        "o",
        cwd=tmp_path,
    )
    assert_one_line_error(result, "--scheduler", "tcp://127.0.0.1:9")
