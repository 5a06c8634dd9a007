"""The README's example works as written: its scenario through its four commands and its Python example.

Its scenario uses only keys of the scenario model, and its results table is the one the measured JSON gives.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pandas as pd

from skyradar.experiments.readme_results import END, README_RESULTS, START, readme_table

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()
HISTORY = re.compile(
    r"session [0-9]|issue [0-9]|encounter [0-9]+|\b[0-9a-f]{7}\b \(|seed[-]brief", flags=re.IGNORECASE
)


def _blocks(language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", README, flags=re.DOTALL)


def test_the_readme_is_short_and_tells_no_history():
    assert len(README.splitlines()) <= 200
    assert not HISTORY.findall(README)
    assert _blocks("sh")[0].split("\n")[:2] == [
        "make demo   # creates .venv, installs skyradar, runs the end-to-end demo on the embedded scenario",
        "make test   # creates .venv with the dev extras and runs the test suite (doctests included)",
    ]


def test_the_readme_scenario_runs_through_its_commands_and_its_python_example(tmp_path):
    (scenario,) = _blocks("yaml")
    (tmp_path / "head_on.yaml").write_text(scenario)
    chain = next(b for b in _blocks("sh") if "skyradar simulate" in b)
    for line in chain.strip().splitlines():
        command = line.split("#")[0].split()
        assert command[0] == "skyradar"
        done = subprocess.run(
            [sys.executable, "-m", "skyradar", *command[1:]],
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert done.returncode == 0, (line, done.stderr[-2000:])
    alerts = pd.read_parquet(tmp_path / "alerts.parquet")
    assert (alerts["level"] == 3).any()  # the head-on glider is warned
    (example,) = _blocks("python")
    done = subprocess.run(
        [sys.executable, "-c", example], cwd=tmp_path, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert "time_s" in done.stdout and "preferred_heading_deg" in done.stdout


def test_the_readme_results_table_is_generated_from_the_measured_json():
    # The table between the markers is exactly what the measured summaries give: a hand edit fails here.
    assert README.count(START) == 1 and README.count(END) == 1
    shown = README.split(START, 1)[1].split(END, 1)[0].strip()
    results = ROOT / "docs" / "results"
    assert shown == readme_table(results, README_RESULTS)
    assert len(shown.splitlines()) >= 2 + len(README_RESULTS)
