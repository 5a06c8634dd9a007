"""The command line never crashes and never accepts nonsense: usage errors, empty inputs, bad values.

Every case runs the real entry point in a subprocess, as a user would.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest


def _skyradar(*args: str, cwd: Path, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "skyradar", *args], cwd=cwd, capture_output=True, text=True, timeout=timeout
    )


def _assert_one_line_error(result: subprocess.CompletedProcess, *needles: str) -> None:
    assert result.returncode == 2, result.stderr
    lines = [line for line in result.stderr.strip().splitlines() if line.strip()]
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("error: "), lines[0]
    assert "Traceback" not in result.stderr
    for needle in needles:
        assert needle in lines[0], lines[0]


# --- usage errors and help -------------------------------------------------------------------------


@pytest.mark.parametrize("args", [(), ("experiment",), ("bench",)])
def test_bare_command_prints_help_and_exits_0(tmp_path, args):
    result = _skyradar(*args, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "Usage" in result.stdout
    assert "Traceback" not in result.stderr


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (("track",), "Missing argument"),
        (("--bogus",), "No such option"),
        (("bench", "track", "--frames", "x"), "--frames"),
        (("simulate", "a.yaml", "-o", "b.zarr", "--chunk-frames", "1.5"), "--chunk-frames"),
    ],
)
def test_usage_error_is_short_with_exit_2(tmp_path, args, needle):
    result = _skyradar(*args, cwd=tmp_path)
    assert result.returncode == 2, result.stderr
    assert "Traceback" not in result.stderr
    assert len(result.stderr.strip().splitlines()) <= 4, result.stderr
    assert result.stderr.strip().splitlines()[-1].startswith("Error:")
    assert needle in result.stderr


# --- ordinary input that used to crash ---------------------------------------------------------------


def _detections(path: Path, n: int, ground: bool) -> Path:
    table = pd.DataFrame(
        {
            "time_s": np.arange(n) * 0.1,
            "range_m": np.full(n, 500.0),
            "radial_velocity_mps": np.full(n, -5.0),
            "north_m": np.full(n, 500.0),
            "east_m": np.zeros(n),
            "down_m": np.zeros(n),
            "is_ground": np.full(n, ground),
        }
    )
    table.to_parquet(path)
    return path


@pytest.mark.parametrize(("n", "ground"), [(0, False), (12, True)])
@pytest.mark.parametrize("model", ["radar", "traditional"])
def test_track_without_air_detections_writes_empty_table(tmp_path, n, ground, model):
    from skyradar.track.run import TRACK_COLUMNS

    source = _detections(tmp_path / "det.parquet", n, ground)
    result = _skyradar("track", str(source), "-o", "trk.parquet", "--model", model, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "no tracks" in result.stderr
    tracks = pd.read_parquet(tmp_path / "trk.parquet")
    assert len(tracks) == 0
    assert list(tracks.columns) == TRACK_COLUMNS
    assert tracks["detection_row"].dtype == np.int64


@pytest.mark.parametrize(
    ("args", "needles"),
    [
        (("bench", "state", "--seconds", "nan"), ["--seconds", "nan"]),
        (("bench", "process", "--seconds", "-1"), ["--seconds", "-1"]),
        (("bench", "track", "--frames", "0"), ["--frames", "0"]),
        (("bench", "flight", "--frames", "0"), ["--frames", "0"]),
        (("experiment", "ch4", "--chain", "bogus"), ["--chain", "bogus"]),
        (("experiment", "ch5", "--duration", "-1"), ["--duration", "-1"]),
        (("experiment", "ch5", "--fast-duration", "inf"), ["--fast-duration", "inf"]),
        (("experiment", "encounters", "--frame-rate", "nan"), ["--frame-rate", "nan"]),
        (("process", "run.zarr", "-o", "d.parquet", "--pfa", "5"), ["--pfa", "5"]),
        (("process", "run.zarr", "-o", "d.parquet", "--pfa", "-1"), ["--pfa", "-1"]),
        (("calibrate", "r.zarr", "-o", "c.json", "--range", "-5", "--azimuth", "0", "--elevation", "0"),
         ["--range", "-5"]),
        (("spur-map", "r.zarr", "-o", "s.npz", "--threshold", "2"), ["--threshold", "2"]),
        (("simulate", "s.yaml", "-o", "r.zarr", "--workers", "0"), ["--workers", "0"]),
        (("track", "d.parquet", "-o", "t.parquet", "--origin", "95,4,0"), ["--origin", "lat_deg", "95"]),
        (("evaluate", "r.zarr", "t.parquet", "--gospa-c", "nan"), ["--gospa-c", "nan"]),
    ],
)  # fmt: skip
def test_bad_option_values_give_one_line(tmp_path, args, needles):
    _detections(tmp_path / "d.parquet", 3, False)
    result = _skyradar(*args, cwd=tmp_path, timeout=60)
    _assert_one_line_error(result, *needles)
    assert not (tmp_path / "out").exists()  # refused before any work


# --- hostile YAML ------------------------------------------------------------------------------------


def _billion_laughs(path: Path) -> Path:
    """357 bytes that stand for 9^9 (387 million) strings through nested aliases."""
    lines = ["name:", '  - &a ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]']
    for prev, level in zip("abcdefgh", "bcdefghi", strict=True):
        lines.append(f"  - &{level} [" + ",".join([f"*{prev}"] * 9) + "]")
    path.write_text("\n".join(lines) + "\n")
    return path


def _limit_memory() -> None:  # runs in the child: a bomb must fail fast, not take the machine
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))


@pytest.mark.parametrize("command", ["simulate", "sweep"])
def test_yaml_alias_bomb_is_refused_quickly(tmp_path, command):
    bomb = _billion_laughs(tmp_path / "bomb.yaml")
    args = ["simulate", str(bomb), "-o", "run.zarr"]
    if command == "sweep":
        args = ["sweep", str(bomb), "--param", "duration_s", "--values", "1", "-o", "t.csv"]
    try:
        result = subprocess.run(
            [sys.executable, "-m", "skyradar", *args], cwd=tmp_path, capture_output=True, text=True,
            timeout=60, preexec_fn=_limit_memory,
        )  # fmt: skip
    except subprocess.TimeoutExpired:
        pytest.fail("the YAML bomb was expanded (no answer within 60 s)")
    _assert_one_line_error(result, "bomb.yaml", "aliases expand")


def test_recursive_yaml_alias_is_refused(tmp_path):
    scenario = tmp_path / "loop.yaml"
    scenario.write_text("name: &a [1, *a]\n")
    _assert_one_line_error(_skyradar("simulate", str(scenario), "-o", "run.zarr", cwd=tmp_path), "loop.yaml")
