"""Running the real ``skyradar`` entry point from tests, and the one-line error contract.

Imported by the test modules (pytest puts this folder on ``sys.path``); not a test module itself.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

__all__ = ["skyradar", "assert_one_line_error"]


def skyradar(*args: str, cwd: Path, timeout: float = 300) -> subprocess.CompletedProcess:
    """``python -m skyradar ARGS`` in ``cwd``: the same entry point a user's shell runs."""
    return subprocess.run(
        [sys.executable, "-m", "skyradar", *args], cwd=cwd, capture_output=True, text=True, timeout=timeout
    )


def assert_one_line_error(result: subprocess.CompletedProcess, *needles: str) -> None:
    """Exit code 2, no traceback, and one ``error: ...`` line on stderr holding every needle."""
    assert result.returncode == 2, result.stdout + result.stderr
    assert "Traceback" not in result.stderr, result.stderr
    lines = [line for line in result.stderr.strip().splitlines() if line.strip()]
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("error: "), lines[0]
    for needle in needles:
        assert needle in lines[0], lines[0]
