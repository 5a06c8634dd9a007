"""`kill` (SIGTERM) stops a long job like Ctrl-C: its worker processes end, the rerun resumes."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.skipif(not Path("/proc").is_dir(), reason="reads child processes from /proc")


def _children(pid: int) -> set[int]:
    found = set()
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:  # the process ended while listed
            continue
        if int(fields[1]) == pid:
            found.add(int(stat.parent.name))
    return found


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    stat = Path(f"/proc/{pid}/stat")
    try:  # a zombie waiting for its (re)parent is gone for our purpose
        return stat.read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def test_sigterm_ends_the_encounter_workers_and_says_how_to_resume(tmp_path):
    command = [
        sys.executable,
        "-m",
        "skyradar",
        "experiment",
        "encounters",
        "--n",
        "8",
        "--workers",
        "2",
        "--layout",
        "single",
        "--output",
        str(tmp_path / "out"),
        "--json",
    ]
    proc = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline, workers = time.time() + 120, set()
    while time.time() < deadline and proc.poll() is None and len(workers) < 2:
        time.sleep(0.2)
        # spawn starts a resource tracker and the workers: the workers run the chain for seconds
        workers = {p for p in _children(proc.pid) if b"spawn_main" in Path(f"/proc/{p}/cmdline").read_bytes()}
    assert proc.poll() is None and len(workers) >= 2, "the run ended before its workers were seen"
    proc.send_signal(signal.SIGTERM)
    _, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 130, stderr
    assert "rerun the same command to resume" in stderr and "Traceback" not in stderr
    deadline = time.time() + 15
    while time.time() < deadline and any(_alive(p) for p in workers):
        time.sleep(0.2)
    assert not any(_alive(p) for p in workers), "encounter workers outlived the command"
    assert not (tmp_path / "out" / "encounters.parquet").exists()  # not finished: no final table
