"""Importing skyradar shortens libgomp's spin at barriers unless the user chose a value."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

_PRINT = "import skyradar, os; print(os.environ['GOMP_SPINCOUNT'])"


@pytest.mark.parametrize(("given", "expected"), [(None, "10000"), ("250", "250")])
def test_gomp_spincount_default_and_user_value(given, expected):
    env = {k: v for k, v in os.environ.items() if k != "GOMP_SPINCOUNT"}
    if given is not None:
        env["GOMP_SPINCOUNT"] = given
    out = subprocess.run([sys.executable, "-c", _PRINT], env=env, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == expected
