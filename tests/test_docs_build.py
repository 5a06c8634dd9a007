"""The documentation site builds offline with warnings as errors, and its generated pages hold what
they are generated from: the results page the numbers of docs/results/*.json, the CLI reference the
commands of the Typer app."""

from __future__ import annotations

import html
import importlib.util
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SOURCE = ROOT / "docs" / "source"
RESULTS = ROOT / "docs" / "results"

pytestmark = [
    pytest.mark.docs,
    pytest.mark.skipif(
        importlib.util.find_spec("sphinx") is None,
        reason="sphinx is not installed: install the docs extra (pip install -e '.[docs]', part of dev)",
    ),
]


def _text(page: Path) -> str:
    """A built page's text, tags dropped and whitespace collapsed."""
    return re.sub(r"\s+", " ", html.unescape(re.sub(r"<[^>]+>", " ", page.read_text())))


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("docs")
    html_dir, doctrees = out / "html", out / "doctrees"
    cmd = [sys.executable, "-m", "sphinx", "-b", "html", "-W", "--keep-going", "-q", "-d", str(doctrees)]
    proc = subprocess.run(
        [*cmd, str(SOURCE), str(html_dir)], capture_output=True, text=True, timeout=170, cwd=ROOT
    )
    assert proc.returncode == 0, f"sphinx build failed:\n{proc.stdout}\n{proc.stderr}"
    return html_dir


def test_results_page_holds_the_measured_numbers(site):
    sys.path.insert(0, str(SOURCE / "_ext"))
    try:
        from skyradar_docs import format_value
    finally:
        sys.path.remove(str(SOURCE / "_ext"))
    text = _text(site / "results.html")
    files = sorted(RESULTS.glob("*.json"))
    assert files, "no measured summaries in docs/results"
    for path in files:
        summary = json.loads(path.read_text())
        row = summary["rows"][0]
        assert path.name in text
        assert summary["date_utc"] in text
        assert summary["command"] in text
        # The row's terrain, layout and headline numbers, in the page's table order.
        columns = ("terrain", "layout", "encounters", "conflicts", "observable_conflicts", "missed_warnings")
        columns += ("false_warnings", "false_warning_rate", "median_warning_lead_s")
        cells = [format_value(k, row[k]) for k in columns]
        assert " ".join(cells) in text, f"{path.name}: first row {cells} not on the results page"


def test_cli_reference_names_the_commands(site):
    text = _text(site / "cli.html")
    for command in ("simulate", "process", "track", "alert", "experiment encounters"):
        assert f"skyradar {command}" in text
    assert "--output" in text and "--ownship" in text


def test_pages_of_every_stage_are_built(site):
    for page in ("getting-started", "user-guide/simulate", "how-it-works/alerting", "api/track", "changelog"):
        assert (site / f"{page}.html").is_file(), page
    assert "Unreleased" in _text(site / "changelog.html")  # CHANGELOG.md is included
