"""The README's measured results name real commands, and it lists exactly the experiments that exist."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest
from typer.testing import CliRunner

import skyradar
from skyradar.cli import app

README = Path(__file__).resolve().parents[1] / "README.md"


def _results_table() -> list[list[str]]:
    text = README.read_text()
    section = text.split("## Measured results", 1)[1].split("\n## ", 1)[0]
    rows = [line for line in section.splitlines() if line.startswith("| ") and not line.startswith("| what")]
    return [[cell.strip() for cell in row.strip("|").split("|")] for row in rows]


def _commands(cell: str) -> list[list[str]]:
    return [shlex.split(command)[1:] for command in re.findall(r"`(skyradar [^`]+)`", cell)]


RESULT_COMMANDS = [args for row in _results_table() for args in _commands(row[1])]


def test_every_result_row_names_a_command():
    rows = _results_table()
    assert len(rows) >= 10
    for row in rows:
        assert _commands(row[1]), row


@pytest.mark.parametrize("args", RESULT_COMMANDS, ids=[" ".join(a) for a in RESULT_COMMANDS])
def test_result_commands_exist_with_their_options(args):
    # --help after the options: an unknown command or option fails the parse (exit 2) first.
    result = CliRunner().invoke(app, [*args, "--help"])
    assert result.exit_code == 0, result.output


def test_readme_and_package_list_the_experiments_that_exist():
    result = CliRunner().invoke(app, ["experiment", "--help"], env={"COLUMNS": "200"})
    listed = set(re.findall(r"^│ (\w+) ", result.output, flags=re.MULTILINE))
    assert listed == {"ch2", "ch3", "ch4", "ch5", "ch6", "ch7", "encounters", "clutter"}, result.output
    text = README.read_text()
    assert "`skyradar experiment ch2 | ch3 | ch4 | ch5 | ch6 | ch7 | encounters | clutter`" in text
    # ch6 and ch7 are built: neither the README nor the package docstring calls them missing.
    for doc in (text, skyradar.__doc__):
        assert "ch6" in doc and "ch7" in doc
        assert not re.search(r"[Nn]ot built yet:[^.]*(ch6|ch7|GPS check|passive)", doc)
