"""The package layering (README, "Architecture"; pyproject.toml [tool.importlinter]).

A package imports only the layers below it. The contract is checked on the real code, and on a tiny
copy of the package tree with a deliberate back-import, to show the check can fail.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LINT_IMPORTS = [
    sys.executable,
    "-c",
    "import sys; from importlinter.cli import lint_imports_command; sys.exit(lint_imports_command())",
]


def _lint(config: Path, cwd: Path, pythonpath: Path) -> subprocess.CompletedProcess:
    # A subprocess: the tiny tree must shadow the installed skyradar on sys.path.
    return subprocess.run(
        [*LINT_IMPORTS, "--config", str(config), "--no-cache", "--no-logo"],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=120,
        env={"PYTHONPATH": str(pythonpath), "PATH": "/usr/bin:/bin"},
    )


def _layer_names() -> list[str]:
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]
    (contract,) = config["contracts"]
    names = []
    for layer in contract["layers"]:
        names += [n.strip() for n in layer.split("|") if not n.strip().startswith("(")]
    return names


@pytest.fixture
def tiny_tree(tmp_path: Path) -> Path:
    """Every layer of the contract as an empty module, beside a copy of the real pyproject.toml."""
    src = tmp_path / "src" / "skyradar"
    src.mkdir(parents=True)
    (src / "__init__.py").write_text("")
    for name in _layer_names():
        if name.startswith("__"):
            (src / f"{name}.py").write_text("")
        else:
            (src / name).mkdir()
            (src / name / "__init__.py").write_text("")
    (src / "sim" / "engine.py").write_text("from skyradar.scene import models\n")  # downward: allowed
    (src / "scene" / "models.py").write_text("from skyradar import errors\n")
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    return tmp_path


def test_the_real_code_keeps_the_layers():
    result = _lint(ROOT / "pyproject.toml", ROOT, ROOT / "src")
    assert result.returncode == 0, result.stdout + result.stderr
    assert "skyradar layers KEPT" in result.stdout


def test_the_tiny_tree_passes_before_the_back_import(tiny_tree: Path):
    result = _lint(tiny_tree / "pyproject.toml", tiny_tree, tiny_tree / "src")
    assert result.returncode == 0, result.stdout + result.stderr


# Three deliberate back-imports in one tree (one lint run): each must be reported by name.
BACK_IMPORTS = {
    # A lazy import inside a function is still an import (scene imported sim.impairments so).
    "scene/lazy.py": (
        "def f():\n    from skyradar.sim import engine\n",
        "skyradar.scene.lazy -> skyradar.sim",
    ),
    "process/beside.py": ("import skyradar.sim.engine\n", "skyradar.process.beside -> skyradar.sim"),
    "errors.py": ("from skyradar.units import x\n", "skyradar.errors -> skyradar.units"),  # within layer 1
}


def test_a_deliberate_back_import_breaks_the_check(tiny_tree: Path):
    for module, (code, _) in BACK_IMPORTS.items():
        (tiny_tree / "src" / "skyradar" / module).write_text(code)
    result = _lint(tiny_tree / "pyproject.toml", tiny_tree, tiny_tree / "src")
    assert result.returncode == 1, result.stdout + result.stderr
    assert "skyradar layers BROKEN" in result.stdout
    for _, needle in BACK_IMPORTS.values():
        assert needle in result.stdout


def test_a_new_package_outside_the_layering_breaks_the_check(tiny_tree: Path):
    (tiny_tree / "src" / "skyradar" / "radarheads").mkdir()
    (tiny_tree / "src" / "skyradar" / "radarheads" / "__init__.py").write_text("")
    result = _lint(tiny_tree / "pyproject.toml", tiny_tree, tiny_tree / "src")
    assert result.returncode != 0
    assert "skyradar.radarheads" in result.stdout + result.stderr


def test_only_the_command_line_sits_above_experiments_and_benchmarks():
    # Library code (the chain, the demo, every stage) never imports the experiments or the benchmarks:
    # only the command line and ``python -m skyradar`` may.
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]
    (contract,) = config["contracts"]
    layers = [{n.strip() for n in layer.split("|")} for layer in contract["layers"]]
    assert layers[:3] == [{"__main__"}, {"cli"}, {"experiments", "benchmarks"}]


def test_no_module_imports_another_modules_private_names():
    # A leading underscore says "this module's own": another module that needs it makes it public. Names
    # of a private module (``sim._tables``, the compiled kernels) serve their package.
    import ast

    found = []
    for path in sorted((ROOT / "src" / "skyradar").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if not (isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("skyradar")):
                continue
            if node.module.split(".")[-1].startswith("_"):
                continue
            private = [a.name for a in node.names if a.name.startswith("_") and not a.name.startswith("__")]
            found += [f"{path.relative_to(ROOT)}:{node.lineno}: {node.module}.{name}" for name in private]
    assert not found, "\n".join(found)
