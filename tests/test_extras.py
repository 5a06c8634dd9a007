"""Optional extras ([geo], [web], [dask]): a command whose extra is missing fails with one line naming it.

The subprocess tests hide an extra's modules with a ``sitecustomize.py`` on PYTHONPATH (a meta-path
finder that refuses them), then run the real ``skyradar`` entry point.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from cli_helpers import assert_one_line_error
from skyradar.extras import EXTRAS, MissingExtraError, import_extra

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "src" / "skyradar" / "data" / "scenarios" / "ch2_flat_forward.yaml"
ALL_EXTRA_MODULES = sorted({m for modules in EXTRAS.values() for m in modules})

BLOCKER = '''
import os, sys

_BLOCKED = set(os.environ["SKYRADAR_TEST_BLOCK"].split(","))


class _Blocker:
    """Refuses the blocked top-level modules as if they were not installed."""

    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in _BLOCKED:
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return None


sys.meta_path.insert(0, _Blocker())
'''


def _run_without(blocked: list[str], *args: str, tmp_path: Path) -> subprocess.CompletedProcess:
    site = tmp_path / "site"
    site.mkdir(exist_ok=True)
    (site / "sitecustomize.py").write_text(BLOCKER)
    env = {**os.environ, "PYTHONPATH": str(site), "SKYRADAR_TEST_BLOCK": ",".join(blocked)}
    return subprocess.run(
        [sys.executable, "-m", "skyradar", *args],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_the_blocker_really_hides_a_module(tmp_path):
    site = tmp_path / "site"
    site.mkdir()
    (site / "sitecustomize.py").write_text(BLOCKER)
    env = {**os.environ, "PYTHONPATH": str(site), "SKYRADAR_TEST_BLOCK": "fastapi"}
    result = subprocess.run(
        [sys.executable, "-c", "import fastapi"], env=env, capture_output=True, text=True, timeout=60
    )
    assert result.returncode != 0 and "No module named 'fastapi'" in result.stderr


def test_serve_without_the_web_extra_names_it(tmp_path):
    result = _run_without(["fastapi", "uvicorn"], "serve", str(tmp_path / "run.zarr"), tmp_path=tmp_path)
    assert_one_line_error(
        result, "skyradar serve needs the optional 'web' extra: pip install 'skyradar[web]'"
    )


def test_workers_without_the_dask_extra_names_it_and_writes_nothing(tmp_path):
    out = tmp_path / "run.zarr"
    result = _run_without(
        ["distributed"], "simulate", str(SCENARIO), "--output", str(out), "--workers", "2", tmp_path=tmp_path
    )
    assert_one_line_error(result, "--workers/--scheduler", "optional 'dask' extra", "skyradar[dask]")
    assert not out.exists() and not Path(f"{out}.partial").exists()


def test_the_base_install_starts_without_any_extra(tmp_path):
    result = _run_without(ALL_EXTRA_MODULES, "scenarios", tmp_path=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "ch2_flat_forward" in result.stdout


def test_a_geotiff_without_the_geo_extra_names_it(tmp_path, monkeypatch):
    from skyradar.scene.dem_readers import read_dem

    (tmp_path / "dem.tif").write_bytes(b"II*\x00")
    monkeypatch.setitem(sys.modules, "rasterio", None)  # None in sys.modules: the import fails
    with pytest.raises(MissingExtraError, match=r"dem.tif: reading a GeoTIFF needs the optional 'geo' extra"):
        read_dem(tmp_path / "dem.tif")


def test_import_extra_refuses_an_unknown_extra():
    with pytest.raises(ValueError, match="unknown extra 'gui'"):
        import_extra("json", "gui", "x")


def test_every_extra_is_declared_in_pyproject():
    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    assert set(EXTRAS) <= set(declared)
    assert f"skyradar[{','.join(EXTRAS)}]" in declared["all"]  # all is every extra
    base = " ".join(tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"])
    for name in ("rasterio", "fastapi", "uvicorn", "distributed", "psutil"):
        assert name not in base
