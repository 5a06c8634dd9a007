"""Fixtures shared by the test modules."""

from __future__ import annotations

import os
import subprocess
from collections.abc import Callable
from pathlib import Path

import pytest

from cli_helpers import skyradar, skyradar_in_process


@pytest.fixture
def cli(request, monkeypatch, capsys) -> Callable[..., subprocess.CompletedProcess]:
    """``skyradar ARGS`` in ``cwd``, as :func:`cli_helpers.skyradar` returns it.

    A test that is not parametrized, and the first case of one that is, runs the real entry point in
    a subprocess; the other cases run the same :func:`skyradar.cli.main` in this process. Each kind
    of input so crosses the process boundary once (exit code, one line on stderr, no traceback),
    and its variants of value or field do not each pay an interpreter's start and imports.
    """
    callspec = getattr(request.node, "callspec", None)
    through_subprocess = callspec is None or not any(callspec.indices.values())

    def run(*args: str, cwd: Path, timeout: float = 300) -> subprocess.CompletedProcess:
        if through_subprocess:
            return skyradar(*args, cwd=cwd, timeout=timeout)
        before = os.getcwd()
        os.chdir(cwd)
        try:
            code, out, err = skyradar_in_process(monkeypatch, capsys, *args)
        finally:
            os.chdir(before)
        return subprocess.CompletedProcess(["skyradar", *map(str, args)], code, out, err)

    return run
