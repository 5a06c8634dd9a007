"""One writer per output, through the real entry point: a second command writing an output that another
command is writing gets one line and exit 2, and the first one's output is complete.

`skyradar simulate` twice at once is the race as users meet it. The other tests make the overlap
certain instead of likely: the first writer is a real command stopped on a named pipe (FIFO) it reads
after taking its lock, or the lock is held by the test itself (or by a helper process) while the
command runs.
"""

from __future__ import annotations

import errno
import os
import subprocess
import sys
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from cli_helpers import assert_one_line_error, skyradar, skyradar_in_process, small_scenario
from skyradar.io.locks import exclusive_output, lock_path
from skyradar.io.outputs import is_ours

SCENARIO = small_scenario(
    "two writers",
    duration_s=3.0,
    frame_rate_hz=9.4,
    intruders=[{"type": "encounter", "kind": "head-on", "t_cpa_s": 30.0, "horizontal_miss_m": 100.0}],
    terrain={"type": "flat", "height_m": 0.0, "size_m": 6000.0, "spacing_m": 30.0},
)
ROUNDS = 3
REFUSAL = "another skyradar command is writing it now"
PIPES = {"stdout": subprocess.PIPE, "stderr": subprocess.PIPE, "text": True}


@pytest.mark.slow  # the race as users meet it; the tests below make the same overlap certain, in seconds
def test_a_second_writer_of_the_same_store_is_refused(tmp_path):
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(SCENARIO))
    raced: list[bool] = []
    for k in range(ROUNDS):
        out = f"run{k}.zarr"
        cmd = [sys.executable, "-m", "skyradar", "simulate", "s.yaml", "-o", out, "--chunk-frames", "4"]
        procs = [subprocess.Popen(cmd, cwd=tmp_path, **PIPES) for _ in range(2)]
        results = [(p.wait(timeout=300), *p.communicate()) for p in procs]
        codes = sorted(code for code, _out, _err in results)
        refused = [err for code, _out, err in results if code == 2]
        if codes == [0, 0]:  # the first finished before the second started: both complete, in turn
            raced.append(False)
            continue
        raced.append(True)
        assert codes == [0, 2], results
        lines = [line for line in refused[0].strip().splitlines() if line.strip()]
        assert len(lines) == 1 and REFUSAL in lines[0], refused[0]
        processed = skyradar("process", out, "-o", f"det{k}.parquet", cwd=tmp_path)
        assert processed.returncode == 0, processed.stderr  # the store that was reported is whole
        assert not (tmp_path / f".{out}.lock").exists()
    assert any(raced), "the two writers never overlapped: the test checked nothing"


def _start(args: list[str], cwd: Path) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "skyradar", *args], cwd=cwd, **PIPES)


def _wait_for_reader(fifo: Path, proc: subprocess.Popen, timeout_s: float = 120.0) -> int:
    """The write end of ``fifo`` once ``proc`` has opened it to read (it took its output lock before)."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        try:
            fd = os.open(fifo, os.O_WRONLY | os.O_NONBLOCK)
        except OSError as exc:
            if exc.errno != errno.ENXIO:  # ENXIO: no reader yet
                raise
            if proc.poll() is not None:
                pytest.fail(f"the first writer ended before reading {fifo.name}: {proc.communicate()}")
            time.sleep(0.05)
            continue
        os.set_blocking(fd, True)
        return fd
    proc.kill()
    pytest.fail(f"the first writer never opened {fifo.name}: {proc.communicate()}")


def _feed(fd: int, text: str) -> None:
    os.write(fd, text.encode())
    os.close(fd)


def _detections_csv() -> str:
    """An aircraft closing at 60 m/s from 2 km, one detection per frame at 9.4 frames/s."""
    t = np.arange(20) / 9.4
    table = pd.DataFrame(
        {
            "time_s": t,
            "frame": np.arange(20),
            "range_m": 2000.0 - 60.0 * t,
            "radial_velocity_mps": np.full(20, -60.0),
        }
    )
    return table.to_csv(index=False)


@pytest.fixture(scope="module")
def small_run(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("run")
    (folder / "s.yaml").write_text(yaml.safe_dump(SCENARIO))
    made = skyradar("simulate", "s.yaml", "-o", "run.zarr", cwd=folder)
    assert made.returncode == 0, made.stderr
    return folder / "run.zarr"


def test_a_second_track_is_refused_while_the_first_writes(tmp_path):
    # The first `track` locks tracks.parquet, then waits on its detections (a FIFO) while the second runs.
    os.mkfifo(tmp_path / "det.csv")
    first = _start(["track", "det.csv", "-o", "tracks.parquet"], tmp_path)
    fd = _wait_for_reader(tmp_path / "det.csv", first)
    try:
        second = skyradar("track", "det.csv", "-o", "tracks.parquet", cwd=tmp_path, timeout=120)
    finally:
        _feed(fd, _detections_csv())
    assert_one_line_error(second, "--output tracks.parquet", REFUSAL)
    out, err = first.communicate(timeout=300)
    assert first.returncode == 0, err
    tracks = pd.read_parquet(tmp_path / "tracks.parquet")
    assert tracks["track_id"].nunique() == 1 and len(tracks) > 10, tracks
    assert is_ours(tmp_path / "tracks.parquet", "table")
    assert not lock_path(tmp_path / "tracks.parquet").exists()


def test_a_second_process_is_refused_while_the_first_writes(small_run, tmp_path):
    # The first `process` locks det.parquet, then waits on its --radar-config (a FIFO).
    from skyradar.io.frames import open_frames, radar_config_of

    config = radar_config_of(open_frames(small_run), str(small_run)).to_json()
    os.mkfifo(tmp_path / "radar.json")
    args = ["process", str(small_run), "--radar-config", "radar.json", "-o", "det.parquet"]
    first = _start(args, tmp_path)
    fd = _wait_for_reader(tmp_path / "radar.json", first)
    try:
        second = skyradar("process", str(small_run), "-o", "det.parquet", cwd=tmp_path, timeout=120)
    finally:
        _feed(fd, config)
    assert_one_line_error(second, "--output det.parquet", REFUSAL)
    out, err = first.communicate(timeout=300)
    assert first.returncode == 0, err
    detections = pd.read_parquet(tmp_path / "det.parquet")
    assert is_ours(tmp_path / "det.parquet", "table") and {"time_s", "range_m"} <= set(detections.columns)
    assert not lock_path(tmp_path / "det.parquet").exists()


@pytest.mark.parametrize(
    ("args", "named"),
    [
        (["export", "RUN", "-o", "own"], "--output own"),
        (["export", "RUN", "-o", "own.parquet"], "--output own.parquet"),
        (["demo", "--output", "report"], "--output report"),
    ],
    ids=["export-folder", "export-table", "demo"],
)
def test_an_output_locked_by_another_writer_is_refused_then_written(small_run, tmp_path, args, named):
    args = [str(small_run) if a == "RUN" else a for a in args]
    output = tmp_path / named.split()[1]
    with exclusive_output(output):  # this test is the first writer
        refused = skyradar(*args, cwd=tmp_path, timeout=120)
        assert_one_line_error(refused, named, REFUSAL)
        assert not output.exists()
    if args[0] == "demo":
        return  # the demo's run is minutes; that it writes its folder is tested with the demo
    written = skyradar(*args, cwd=tmp_path)
    assert written.returncode == 0, written.stderr
    assert output.exists() and not lock_path(output).exists()


def test_a_lock_left_by_a_killed_writer_blocks_nobody(tmp_path):
    os.mkfifo(tmp_path / "det.csv")
    first = _start(["track", "det.csv", "-o", "tracks.parquet"], tmp_path)
    fd = _wait_for_reader(tmp_path / "det.csv", first)
    first.kill()  # SIGKILL: no clean-up runs
    first.communicate(timeout=60)
    os.close(fd)
    assert lock_path(tmp_path / "tracks.parquet").exists()
    (tmp_path / "det.csv").unlink()
    (tmp_path / "det.csv").write_text(_detections_csv())
    again = skyradar("track", "det.csv", "-o", "tracks.parquet", cwd=tmp_path)
    assert again.returncode == 0, again.stderr
    assert not lock_path(tmp_path / "tracks.parquet").exists()


@contextmanager
def _held_by_another_process(path: Path):
    """``path`` locked by a helper process for the block (a lock this process held would be its own)."""
    code = (
        "import sys\nfrom skyradar.io.locks import exclusive_output\n"
        f"with exclusive_output({str(path)!r}):\n    print('held', flush=True)\n    sys.stdin.read()\n"
    )
    holder = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE, **PIPES)
    try:
        assert holder.stdout.readline().strip() == "held", holder.communicate()
        yield
    finally:
        holder.stdin.close()
        holder.wait(timeout=60)


# Every command that writes an output, with inputs that need not exist: the lock comes before any
# reading. (`evaluate`, `serve`, `scenarios` and `bench` write nothing.)
WRITERS = {
    "simulate": (["simulate", "s.yaml", "-o", "run.zarr"], "--output run.zarr"),
    "sweep": (
        ["sweep", "s.yaml", "--param", "duration_s", "--values", "1,2", "-o", "sweep.csv"],
        "--output sweep.csv",
    ),
    "rd": (["rd", "rec.npy", "-o", "rd.zarr"], "--output rd.zarr"),
    "process": (["process", "run.zarr", "-o", "det.parquet"], "--output det.parquet"),
    "calibrate": (
        [
            "calibrate",
            "run.zarr",
            "-o",
            "cal.json",
            "--range-m",
            "100",
            "--azimuth-deg",
            "0",
            "--elevation-deg",
            "0",
        ],
        "--output cal.json",
    ),
    "spur-map": (["spur-map", "run.zarr", "-o", "spurs.npz"], "--output spurs.npz"),
    "track": (["track", "det.parquet", "-o", "tracks.parquet"], "--output tracks.parquet"),
    "alert": (
        ["alert", "tracks.parquet", "--ownship", "run.zarr", "-o", "alerts.parquet"],
        "--output alerts.parquet",
    ),
    "state": (["state", "run.zarr", "-o", "state.parquet"], "--output state.parquet"),
    "gpscheck": (["gpscheck", "run.zarr", "--map", "m.tif", "-o", "check.parquet"], "--output check.parquet"),
    "export": (["export", "run.zarr", "-o", "own"], "--output own"),
    "passive": (["passive", "rec.sigmf-meta", "-o", "passive.parquet"], "--output passive.parquet"),
    "simulate-passive": (["simulate-passive", "-o", "sim.sigmf-meta"], "--output sim.sigmf-meta"),
    "flight": (["flight", "fixes.csv", "-o", "path.csv"], "--output path.csv"),
    "make-encounter": (["make-encounter", "a.csv", "b.csv", "-o", "enc.yaml"], "--output enc.yaml"),
    "demo": (["demo", "--output", "report"], "--output report"),
    **{
        f"experiment {name}": (["experiment", name, "--output", f"x-{name}"], f"--output x-{name}")
        for name in ("ch2", "ch3", "ch4", "ch5", "ch6", "ch7", "clutter", "encounters")
    },
}


@pytest.mark.parametrize("command", list(WRITERS))
def test_every_writing_command_is_refused_while_another_writes_its_output(
    command, tmp_path, monkeypatch, capsys
):
    args, named = WRITERS[command]
    monkeypatch.chdir(tmp_path)
    output = tmp_path / named.split()[1]
    with _held_by_another_process(output):
        code, _out, err = skyradar_in_process(monkeypatch, capsys, *args)
    lines = [line for line in err.strip().splitlines() if line.strip()]
    assert code == 2 and len(lines) == 1, err
    assert lines[0].startswith(f"error: {named}: {REFUSAL}"), lines[0]
    assert not output.exists()
