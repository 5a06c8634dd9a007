"""The test suite itself: nothing installs from inside a test, nothing skips a whole file silently,
the docstring examples run with the tests, and ``make test`` installs the browser visibly first."""

from __future__ import annotations

import ast
import os
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
TEST_FILES = sorted(p for p in (ROOT / "tests").rglob("*.py") if p.name != Path(__file__).name)
INSTALLERS = ({"apt-get", "install"}, {"apt", "install"}, {"pip", "install"}, {"pip3", "install"})
RUNNERS = {"run", "call", "check_call", "check_output", "Popen", "system", "getoutput", "getstatusoutput"}


def _literal_words(node: ast.AST) -> set[str]:
    """String constants of a list/tuple literal, and the words of a single string constant."""
    if isinstance(node, ast.List | ast.Tuple):
        return {e.value for e in node.elts if isinstance(e, ast.Constant) and isinstance(e.value, str)}
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return set(node.value.split())
    return set()


def _install_commands(tree: ast.AST) -> list[int]:
    """Lines of command literals (lists, tuples, strings run by subprocess/os) that install packages."""
    lines = []
    for node in ast.walk(tree):
        candidates = [node] if isinstance(node, ast.List | ast.Tuple) else []
        name = getattr(node.func, "attr", getattr(node.func, "id", "")) if isinstance(node, ast.Call) else ""
        if name in RUNNERS:  # a command given as one string: os.system("pip install x")
            candidates += [a for a in node.args if isinstance(a, ast.Constant)]
        lines += [c.lineno for c in candidates if any(w <= _literal_words(c) for w in INSTALLERS)]
    return lines


@pytest.mark.parametrize("path", TEST_FILES, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_test_installs_packages_or_skips_silently(path):
    tree = ast.parse(path.read_text(), filename=str(path))
    assert not _install_commands(tree), f"{path.name}: installs packages (lines {_install_commands(tree)})"
    # importorskip turns a broken import of our own code or a declared dev dependency into a skip.
    calls = [n for n in ast.walk(tree) if isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute)]
    skips = [n.lineno for n in calls if n.func.attr == "importorskip"]
    assert not skips, f"{path.name}: pytest.importorskip at lines {skips}; import normally"
    module_skips = [n.lineno for n in calls if any(k.arg == "allow_module_level" for k in n.keywords)]
    assert not module_skips, f"{path.name}: module-level skip at lines {module_skips}"


def test_the_installer_check_sees_the_forms_it_guards_against():
    src = 'subprocess.run(["apt-get", "install", "x"])\nos.system("pip install x")\nc = ("pip", "install")'
    assert sorted(_install_commands(ast.parse(src))) == [1, 2, 3]
    assert (
        _install_commands(ast.parse('pytest.fail("missing: run apt-get install -y chromium as root")')) == []
    )


def test_pytest_runs_the_docstring_examples_and_reports_every_skip():
    opts = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["pytest"]["ini_options"]
    assert "-ra" in opts["addopts"].split()  # a skip prints its reason in the summary
    assert "src/skyradar" in opts["testpaths"]
    proc = subprocess.run(
        [sys.executable, "-m", "pytest", "--co", "-q", "-p", "no:cacheprovider", "src/skyradar/config.py"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert "src/skyradar/config.py::skyradar.config.RadarConfig" in proc.stdout, proc.stdout + proc.stderr


@pytest.mark.skipif(shutil.which("make") is None, reason="make is not installed")
def test_make_test_installs_chromium_first_and_only_when_missing(tmp_path):
    missing = tmp_path / "no-chromium"
    env = {**os.environ, "MAKEFLAGS": ""}
    for target in ("test", "test-browser"):
        out = subprocess.run(
            ["make", "-n", "-C", str(ROOT), target, f"CHROMIUM={missing}"],
            capture_output=True,
            text=True,
            timeout=60,
            env=env,
        ).stdout
        assert "apt-get install -y" in out and "chromium" in out, out
        assert out.index("apt-get install") < out.index("-m pytest"), out
    present = subprocess.run(
        ["make", "-n", "-C", str(ROOT), "browser-deps", f"CHROMIUM={sys.executable}"],
        capture_output=True,
        text=True,
        timeout=60,
        env=env,
    ).stdout
    assert "apt-get" not in present, present
