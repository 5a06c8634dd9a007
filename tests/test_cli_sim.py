"""The simulate command end to end, and its one-line errors on bad input."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from cli_helpers import assert_one_line_error as _assert_one_line_error
from cli_helpers import skyradar as _skyradar
from skyradar.io.frames import FrameStoreWriter, open_frames
from skyradar.scene.scenario import Scenario, example_scenario
from skyradar.sim.fingerprint import fingerprint
from skyradar.sim.scenario_frames import make_simulator
from skyradar.sim.simulate_store import _template, simulate_to_zarr

BASE = {
    "name": "tiny",
    "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    "mount": "forward",
    "terrain": {"type": "flat", "size_m": 3000, "spacing_m": 60},
    "ownship": {"type": "straight", "start_ned_m": [0, 0, -500], "heading_deg": 0, "speed_mps": 40},
    "intruders": [{"name": "A", "type": "encounter", "kind": "head-on", "t_cpa_s": 20, "rcs_m2": 1.0}],
    "frame_rate_hz": 5.0,
    "duration_s": 1.0,
    "simulation": {"facet_size_m": 30.0},
}


def _write(tmp_path: Path, data: dict, name: str = "scenario.yaml") -> Path:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return path


def test_simulate_writes_frames_and_truth(tmp_path):
    scenario = _write(tmp_path, BASE)
    result = _skyradar("simulate", str(scenario), "-o", "run.zarr", "--chunk-frames", "2", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    ds = open_frames(tmp_path / "run.zarr")
    assert ds.iq.shape == (5, 333, 250, 4)
    assert np.all(np.isfinite(ds.own_height_agl_m.values))
    assert ds.own_height_agl_m.values[0] == pytest.approx(500.0, abs=1.0)
    assert list(ds.target.values) == ["A"]
    assert not (tmp_path / "run.zarr.partial").exists()


def test_resume_skips_finished_chunks(tmp_path):
    built = Scenario.from_dict(BASE, source=tmp_path / "s.yaml").build()
    path = tmp_path / "run.zarr"
    writer = FrameStoreWriter(path, _template(built, 2, make_simulator(built)), 2, fingerprint(built))
    sentinel = np.full((2, 333, 250, 4), 7 + 7j, np.complex64)
    writer.write_chunk(0, sentinel)  # as if a run was interrupted after its first chunk
    simulate_to_zarr(built, path, chunk_frames=2)
    iq = open_frames(path).iq.values
    np.testing.assert_array_equal(iq[:2], sentinel)  # finished chunk kept, not recomputed
    assert not np.any(iq[2:] == 7 + 7j)


@pytest.mark.parametrize(
    ("change", "needles"),
    [
        ({"intruderz": []}, ["scenario.yaml", "intruderz"]),
        ({"frame_rate_hz": -5}, ["scenario.yaml", "frame_rate_hz"]),
        ({"radar": {"rx_positions_m": [[0, 0, 0]] * 4}}, ["scenario.yaml", "rx_positions_m"]),
    ],
)
def test_bad_scenario_gives_one_line(tmp_path, change, needles, cli):
    scenario = _write(tmp_path, {**BASE, **change})
    result = cli("simulate", str(scenario), "-o", "run.zarr", cwd=tmp_path)
    _assert_one_line_error(result, *needles)
    assert not any(tmp_path.glob("run.zarr*"))


def test_dem_with_too_many_voids(tmp_path):
    elevation = np.full((101, 101), 10.0)
    elevation[:20, :20] = np.nan  # 4% voids, above the 1% fill limit
    np.savez(tmp_path / "dem.npz", elevation=elevation, dx=1 / 1200, dy=1 / 1200, xmin=4.3, ymax=52.05)
    scenario = _write(tmp_path, {**BASE, "terrain": {"type": "file", "path": "dem.npz"}})
    _assert_one_line_error(
        _skyradar("simulate", str(scenario), "-o", "run.zarr", cwd=tmp_path), "dem.npz", "elevation"
    )


def test_dem_without_finite_heights(tmp_path):
    elevation = np.full((101, 101), np.nan)
    np.savez(tmp_path / "dem.npz", elevation=elevation, dx=1 / 1200, dy=1 / 1200, xmin=4.3, ymax=52.05)
    scenario = _write(tmp_path, {**BASE, "terrain": {"type": "file", "path": "dem.npz"}})
    _assert_one_line_error(
        _skyradar("simulate", str(scenario), "-o", "run.zarr", cwd=tmp_path),
        "dem.npz",
        "field 'elevation'",
        "no finite heights",
    )


def test_wrong_hgt_size(tmp_path):
    (tmp_path / "N52E004.hgt").write_bytes(b"\x00" * 100)
    scenario = _write(tmp_path, {**BASE, "terrain": {"type": "file", "path": "N52E004.hgt"}})
    _assert_one_line_error(
        _skyradar("simulate", str(scenario), "-o", "run.zarr", cwd=tmp_path), "N52E004.hgt", "size"
    )


@pytest.mark.parametrize(
    ("csv", "needles"),
    [
        (
            # Two fixes 11 km apart at one time: two aircraft in one file, which no cleaning can repair
            # (rows merely out of order are sorted and reported instead: tests/test_adsb_clean.py).
            "timestamp,latitude,longitude,altitude\n0,52.0,4.36,1000\n1,52.001,4.36,1000\n1,52.1,4.36,1000\n",
            ["track.csv", "timestamp", "two aircraft"],
        ),
        ("timestamp,longitude,altitude\n0,4.36,1000\n1,4.36,1000\n", ["track.csv", "latitude"]),
    ],
)
def test_bad_trajectory_file(tmp_path, csv, needles, cli):
    (tmp_path / "track.csv").write_text(csv)
    scenario = _write(tmp_path, {**BASE, "ownship": "track.csv"})
    _assert_one_line_error(cli("simulate", str(scenario), "-o", "run.zarr", cwd=tmp_path), *needles)


def test_help_on_every_command(tmp_path):
    result = _skyradar("--help", cwd=tmp_path)
    assert result.returncode == 0
    for command in ("simulate", "scenarios", "experiment", "bench"):
        sub = _skyradar(command, "--help", cwd=tmp_path)
        assert sub.returncode == 0, sub.stderr
        assert "Usage" in sub.stdout


def test_example_scenarios_listed(tmp_path):
    result = _skyradar("scenarios", cwd=tmp_path)
    assert result.returncode == 0
    assert "ch2_flat_forward" in result.stdout
    assert Path(example_scenario("ch2_flat_forward")).exists()


def test_ctrl_c_keeps_finished_chunks_and_rerun_resumes(tmp_path):
    import signal
    import time

    # 48 frames in 12 chunks, with the default facets (<= dR/2) over 6 km of hills (level ground skips
    # the horizon and was fast enough to finish before the interrupt): seconds of work left when the
    # first chunk is done, so the interrupt always lands mid-run.
    hills = {"type": "fractal", "local_sd_m": 30.0, "size_m": 6000, "spacing_m": 30, "seed": 1}
    heavy = {**BASE, "duration_s": 9.6, "terrain": hills}
    scenario = _write(tmp_path, {**heavy, "simulation": {}})
    command = [
        sys.executable,
        "-m",
        "skyradar",
        "simulate",
        str(scenario),
        "-o",
        "run.zarr",
        "--chunk-frames",
        "4",
    ]
    # A shell without job control starts background jobs with SIGINT ignored, and Python then installs
    # no KeyboardInterrupt handler: give the command the default disposition a terminal's Ctrl-C meets.
    proc = subprocess.Popen(
        command,
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    marks = tmp_path / "run.zarr.partial.done"
    deadline = time.time() + 240
    while not (marks / "0").exists() and time.time() < deadline and proc.poll() is None:
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 130, stderr
    assert "rerun the same command to resume" in stderr
    done_before = {p.name for p in marks.iterdir()}
    assert "0" in done_before and not (tmp_path / "run.zarr").exists()
    first_chunk = open_frames_partial(tmp_path / "run.zarr.partial")[:4]
    result = _skyradar("simulate", str(scenario), "-o", "run.zarr", "--chunk-frames", "4", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    ds = open_frames(tmp_path / "run.zarr")
    assert ds.iq.shape[0] == 48
    np.testing.assert_array_equal(ds.iq.values[:4], first_chunk)


def open_frames_partial(path: Path) -> np.ndarray:
    import xarray as xr

    return xr.open_zarr(path, consolidated=False).iq.values
