"""Each subpackage's ``__init__`` names its public API: its docstring says what the package is and
names its public modules and every name of its ``__all__``; each of those names imports and has a
docstring; and ``import skyradar.PACKAGE`` imports nothing more (the names load on first use)."""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import subprocess
import sys
from types import ModuleType

import pytest

from skyradar.extras import EXTRAS

PACKAGES = [
    "scene",
    "sim",
    "process",
    "track",
    "daa",
    "nav",
    "passive",
    "io",
    "viz",
    "web",
    "experiments",
    "benchmarks",
    "cli",
    "integrations",
    "integrations.bluesky",
]
EXPORTS = [
    (package, name) for package in PACKAGES for name in importlib.import_module(f"skyradar.{package}").__all__
]
_EXTRA_MODULES = {module for modules in EXTRAS.values() for module in modules}


def _public_modules(package: ModuleType) -> list[str]:
    return [info.name for info in pkgutil.iter_modules(package.__path__) if not info.name.startswith("_")]


@pytest.mark.parametrize("package", PACKAGES)
def test_the_docstring_names_the_public_modules_and_exports(package):
    pkg = importlib.import_module(f"skyradar.{package}")
    doc = inspect.getdoc(pkg) or ""
    assert doc and pkg.__all__, f"skyradar.{package}: no docstring or no __all__"
    missing = [m for m in _public_modules(pkg) if f":mod:`.{m}`" not in doc and f"``{m}``" not in doc]
    assert not missing, f"skyradar.{package}'s docstring does not name its modules {missing}"
    unnamed = [name for name in pkg.__all__ if name not in doc]
    assert not unnamed, f"skyradar.{package}'s docstring does not name {unnamed} of its __all__"


@pytest.mark.parametrize(("package", "name"), EXPORTS, ids=[f"{p}.{n}" for p, n in EXPORTS])
def test_every_export_imports_and_is_documented(package, name):
    namespace: dict = {}
    try:
        exec(f"from skyradar.{package} import {name}", namespace)  # what a user writes
    except ModuleNotFoundError as exc:
        if exc.name and exc.name.split(".")[0] in _EXTRA_MODULES:
            pytest.skip(f"skyradar.{package}.{name} needs an optional extra ({exc.name})")
        raise
    obj = namespace[name]
    assert inspect.getdoc(obj), f"skyradar.{package}.{name} has no docstring"
    if inspect.isfunction(obj) or inspect.isclass(obj) or inspect.ismodule(obj):
        assert obj.__doc__, f"skyradar.{package}.{name}: its own docstring, not an inherited one"
    # A name that is also a submodule's would be replaced by the module when that is first imported.
    # skyradar.cli binds ``app`` (the Typer app) after importing the module of the same name, for good.
    modules = {
        info.name for info in pkgutil.iter_modules(importlib.import_module(f"skyradar.{package}").__path__)
    }
    shadowed = name in modules and not inspect.ismodule(obj) and (package, name) != ("cli", "app")
    assert not shadowed, f"skyradar.{package}.{name} shadows a submodule"


def test_importing_a_package_imports_none_of_its_modules():
    lazy = [p for p in PACKAGES if p != "cli"]  # the CLI registers every command as it is imported
    code = (
        "import sys, skyradar\n"
        f"for p in {lazy!r}:\n"
        "    before = set(sys.modules)\n"
        "    __import__('skyradar.' + p)\n"
        "    new = sorted(m for m in set(sys.modules) - before)\n"
        "    print(p, *new)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True
    )
    for line in out.stdout.splitlines():
        package, *new = line.split()
        new = [m for m in new if m != "skyradar.lazy_exports"]  # the shared helper, not the package's
        assert new == [f"skyradar.{package}"], f"import skyradar.{package} also imported {new[1:]}"
