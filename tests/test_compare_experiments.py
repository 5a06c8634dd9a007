"""The before/after comparison of experiment results (``scripts/compare_experiments.py``) compares
what a run measured and leaves out what timed it or says where and when it ran."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "compare_experiments.py"
spec = importlib.util.spec_from_file_location("compare_experiments", SCRIPT)
assert spec is not None and spec.loader is not None
compare_experiments = importlib.util.module_from_spec(spec)
spec.loader.exec_module(compare_experiments)


def _result(**changes):
    base = {
        "version": "0.1.0+abc",
        "date_utc": "2026-01-01T00:00:00Z",
        "runtime_s": 12.5,
        "load_average_1min": [1.0, 2.0],
        "cost_ms_per_frame": {"simulate": 30.1, "process": 40.2},
        "missed_warnings": 0,
        "median_warning_lead_s": 17.5,
        "rows": [{"late_lead_s": 3.0, "runtime_s_mean": 40.0}],
        "sensor": {"rms_m": float("nan")},
    }
    return base | changes


def test_timings_and_provenance_are_left_out():
    before = _result()
    after = _result(version="0.1.0+def", runtime_s=3.0, cost_ms_per_frame={"simulate": 9.0, "process": 1.0})
    after["rows"] = [{"late_lead_s": 3.0, "runtime_s_mean": 11.0}]
    after["load_average_1min"] = [5.0, 6.0]
    assert compare_experiments.compare(before, after, compare_experiments.DEFAULT_IGNORE) == []


def test_a_measured_value_that_moves_is_named_by_its_path():
    before, after = _result(), _result(missed_warnings=1)
    after["rows"] = [{"late_lead_s": 2.5, "runtime_s_mean": 40.0}]
    after["extra"] = 1
    differing = compare_experiments.compare(before, after, compare_experiments.DEFAULT_IGNORE)
    assert differing == ["extra", "missed_warnings", "rows.0.late_lead_s"]


def test_an_unknown_experiment_is_one_line_with_exit_code_2():
    done = subprocess.run(
        [sys.executable, str(SCRIPT), "HEAD", "--only", "ch9"], capture_output=True, text=True, check=False
    )
    assert done.returncode == 2
    assert done.stderr.strip() == "compare_experiments: --only: unknown experiment 'ch9'"


def test_an_unknown_revision_is_one_line_with_exit_code_2(tmp_path):
    done = subprocess.run(
        [sys.executable, str(SCRIPT), "no-such-rev", "--work", str(tmp_path / "w")],
        capture_output=True,
        text=True,
        check=False,
        cwd=SCRIPT.parents[1],
    )
    assert done.returncode == 2
    assert (
        done.stderr.strip()
        == "compare_experiments: revision 'no-such-rev' is not a commit of this repository"
    )


def test_a_tolerance_lets_floats_round_differently_but_never_counts():
    before = _result()
    after = _result(median_warning_lead_s=17.5 * (1 + 3e-6))
    ignore = compare_experiments.DEFAULT_IGNORE
    assert compare_experiments.compare(before, after, ignore) == ["median_warning_lead_s"]
    assert compare_experiments.compare(before, after, ignore, rtol=1e-5) == []
    assert 2e-6 < compare_experiments.largest_relative_difference(before, after, ignore) < 4e-6
    assert compare_experiments.compare(before, _result(missed_warnings=1), ignore, rtol=10.0) == [
        "missed_warnings"
    ]


def test_stage_timings_are_left_out():
    before = {"scenarios": {"zulu": {"detect_s": 1.0, "track_s_radar": 2.0, "rmse_m": 3.0}}, "seconds": 4.0}
    after = {"scenarios": {"zulu": {"detect_s": 9.0, "track_s_radar": 8.0, "rmse_m": 3.0}}, "seconds": 7.0}
    assert compare_experiments.compare(before, after, compare_experiments.DEFAULT_IGNORE) == []


def test_every_experiment_command_is_compared():
    import click
    import typer.main

    from skyradar.cli import app

    root = typer.main.get_command(app)
    ctx = click.Context(root)
    experiment = root.get_command(ctx, "experiment")
    names = experiment.list_commands(click.Context(experiment, parent=ctx))
    assert sorted(names) == sorted(compare_experiments.EXPERIMENTS)
