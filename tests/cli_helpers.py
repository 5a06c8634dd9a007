"""Running the real ``skyradar`` entry point from tests, and the one-line error contract.

Imported by the test modules (pytest puts this folder on ``sys.path``); not a test module itself.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

__all__ = ["skyradar", "skyradar_in_process", "assert_one_line_error", "small_scenario"]


def small_scenario(name: str, duration_s: float = 1.0, frame_rate_hz: float = 5.0, **changes) -> dict:
    """A scenario dict that builds in a moment: a straight own-ship at 1 km over the North Sea coast."""
    return {
        "name": name,
        "origin": {"lat_deg": 52.5, "lon_deg": 4.36, "alt_m": 0.0},
        "duration_s": duration_s,
        "frame_rate_hz": frame_rate_hz,
        "ownship": {"type": "straight", "start_ned_m": [0, 0, -1000], "heading_deg": 0, "speed_mps": 50},
        **changes,
    }


def skyradar(*args: str, cwd: Path, timeout: float = 300) -> subprocess.CompletedProcess:
    """``python -m skyradar ARGS`` in ``cwd``: the same entry point a user's shell runs."""
    return subprocess.run(
        [sys.executable, "-m", "skyradar", *args], cwd=cwd, capture_output=True, text=True, timeout=timeout
    )


def skyradar_in_process(monkeypatch, capsys, *args: str) -> tuple[int, str, str]:
    """``skyradar ARGS`` through :func:`skyradar.cli.main` in this process: (exit code, stdout, stderr).

    For main paths whose cost is the work, not the start-up; bad input goes through :func:`skyradar`.
    """
    from skyradar.cli import main

    monkeypatch.setattr(sys, "argv", ["skyradar", *map(str, args)])
    code = 0
    try:
        main()
    except SystemExit as exc:
        code = int(exc.code or 0)
    out = capsys.readouterr()
    return code, out.out, out.err


def assert_one_line_error(result: subprocess.CompletedProcess, *needles: str) -> None:
    """Exit code 2, no traceback, and one ``error: ...`` line on stderr holding every needle."""
    assert result.returncode == 2, result.stdout + result.stderr
    assert "Traceback" not in result.stderr, result.stderr
    lines = [line for line in result.stderr.strip().splitlines() if line.strip()]
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("error: "), lines[0]
    for needle in needles:
        assert needle in lines[0], lines[0]
