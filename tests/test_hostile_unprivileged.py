"""Hostile paths as a user without the right to override file permissions.

As root every file is readable and every folder writable, so unreadable inputs and read-only
outputs never happen in a root test run. When the suite runs as root these commands run under
``setpriv`` with the capabilities that bypass file permissions (``dac_override``,
``dac_read_search``) dropped: permissions then bind as they bind a normal user. As a normal user
they run as they are.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest
import yaml

from cli_helpers import assert_one_line_error, small_scenario

DROP = [
    "setpriv",
    "--inh-caps=-dac_override,-dac_read_search",
    "--bounding-set=-dac_override,-dac_read_search",
]
BASE = small_scenario("unprivileged")


def _skyradar(*args: str, cwd) -> subprocess.CompletedProcess:
    prefix = DROP if os.geteuid() == 0 else []
    cmd = [*prefix, sys.executable, "-m", "skyradar", *args]
    return subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=300)


@pytest.fixture
def folder(tmp_path):
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(BASE))
    (tmp_path / "track.csv").write_text(
        "timestamp,latitude,longitude,altitude\n0,52,4,1000\n10,52.001,4,1000\n"
    )
    yield tmp_path
    for path in tmp_path.rglob("*"):  # give back what the test took away, so pytest can clean up
        path.chmod(0o755 if path.is_dir() else 0o644)


def test_permissions_bind_in_these_runs(folder):
    (folder / "secret.txt").write_text("x")
    (folder / "secret.txt").chmod(0)
    prefix = DROP if os.geteuid() == 0 else []
    seen = subprocess.run([*prefix, "cat", "secret.txt"], cwd=folder, capture_output=True, text=True)
    assert seen.returncode != 0  # else the tests below would check nothing


def test_an_unreadable_input_is_refused_without_a_traceback(folder):
    (folder / "s.yaml").chmod(0)
    result = _skyradar("simulate", "s.yaml", "-o", "run.zarr", cwd=folder)  # a usage error: usage + one line
    assert result.returncode == 2 and "'s.yaml' is not readable" in result.stderr
    assert "Traceback" not in result.stderr
    (folder / "track.csv").chmod(0)
    result = _skyradar("flight", "track.csv", "-o", "p.csv", cwd=folder)
    assert result.returncode == 2 and "'track.csv' is not readable" in result.stderr
    assert "Traceback" not in result.stderr
    assert not (folder / "run.zarr").exists() and not (folder / "p.csv").exists()


def test_a_read_only_output_folder_is_one_line_and_stays_empty(folder):
    (folder / "ro").mkdir()
    (folder / "ro").chmod(0o555)
    result = _skyradar("flight", "track.csv", "-o", "ro/p.csv", cwd=folder)
    assert_one_line_error(result, "cannot write in", "ro")
    result = _skyradar("simulate", "s.yaml", "-o", "ro/run.zarr", cwd=folder)
    assert_one_line_error(result, "cannot write in", "ro")
    assert list((folder / "ro").iterdir()) == []
