"""Measured results name real commands, and the README lists exactly the experiments that exist."""

from __future__ import annotations

import json
import re
import shlex
from pathlib import Path

import pytest
from typer.testing import CliRunner

import skyradar
from skyradar.cli import app

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
# The encounter summaries and the clutter experiment's.
RECORDS = sorted((ROOT / "docs" / "results").glob("*.json")) + sorted(
    (ROOT / "docs" / "results" / "clutter").glob("*.json")
)


# A result records its command as it ran, at the version it names. An option renamed since
# (CHANGELOG.md) is read under its current name: the check is that the command, as the CLI now spells
# it, still runs.
RENAMED = {"--out": "--output"}


def _command(record: Path) -> list[str]:
    command = json.loads(record.read_text())["command"]
    args = shlex.split(command)
    assert args[0] == "skyradar", command
    return [RENAMED.get(arg, arg) for arg in args[1:]]


def test_there_are_measured_results():
    assert len(RECORDS) >= 4


@pytest.mark.parametrize("record", RECORDS, ids=[r.name for r in RECORDS])
def test_every_result_names_the_command_that_measured_it(record):
    # --help after the options: an unknown command or option fails the parse (exit 2) first.
    result = CliRunner().invoke(app, [*_command(record), "--help"])
    assert result.exit_code == 0, result.output
    data = json.loads(record.read_text())
    assert data["version"] and data["date_utc"]


def test_readme_and_package_list_the_experiments_that_exist():
    result = CliRunner().invoke(app, ["experiment", "--help"], env={"COLUMNS": "200"})
    listed = set(re.findall(r"^│ (\w[\w-]*) ", result.output, flags=re.MULTILINE))
    others = {"encounters", "closed-loop", "clutter", "bluesky", "arrays"}
    assert listed == {"ch2", "ch3", "ch4", "ch5", "ch6", "ch7", *others}, result.output
    text = README.read_text()
    assert "`skyradar experiment ch2 ... ch7`" in text
    for name in sorted(others):
        assert f"`skyradar experiment {name}`" in text
    # ch6 and ch7 are built: neither the README nor the package docstring calls them missing.
    for doc in (text, skyradar.__doc__):
        assert not re.search(r"[Nn]ot built yet:[^.]*(ch6|ch7|GPS check|passive)", doc)
