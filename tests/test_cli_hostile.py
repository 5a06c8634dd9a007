"""Hostile inputs against the integrated CLI: each ends in one line naming file/option, field and value,
never in a traceback, a two-line error, a fork bomb or a silently wrong answer.

Every case runs through the real entry point (``python -m skyradar``). One tiny simulated run is
shared by the module (a few seconds); tracks tables are made from its truth in-process.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from cli_helpers import assert_one_line_error as _assert_one_line_error
from cli_helpers import skyradar as _skyradar

BASE = {
    "name": "tiny",
    "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    "mount": "forward",
    "terrain": {"type": "flat", "size_m": 3000, "spacing_m": 60},
    "ownship": {"type": "straight", "start_ned_m": [0, 0, -500], "heading_deg": 0, "speed_mps": 40},
    "intruders": [{"name": "A", "type": "encounter", "kind": "head-on", "t_cpa_s": 20, "rcs_m2": 1.0}],
    "frame_rate_hz": 5.0,
    "duration_s": 0.8,
    "simulation": {"facet_size_m": 30.0},
}


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory) -> Path:
    """A 4-frame simulated run plus a tracks table made from its intruder truth."""
    from skyradar.daa.pipeline import truth_tracks
    from skyradar.io.frames import open_frames

    folder = tmp_path_factory.mktemp("hostile")
    (folder / "s.yaml").write_text(yaml.safe_dump(BASE))
    result = _skyradar("simulate", "s.yaml", "-o", "run.zarr", "--chunk-frames", "4", cwd=folder)
    assert result.returncode == 0, result.stderr
    tracks = truth_tracks(open_frames(folder / "run.zarr"), visible_only=False)
    assert len(tracks) >= 2
    tracks.to_parquet(folder / "tracks.parquet", index=False)
    return folder


def _tracks_variant(folder: Path, name: str, change) -> str:
    import pandas as pd

    tracks = pd.read_parquet(folder / "tracks.parquet")
    change(tracks)
    tracks.to_parquet(folder / name, index=False)
    return name


def _set(column: str, value, rows=slice(0, 1)):
    def change(df):
        if isinstance(value, str):
            df[column] = df[column].astype(object)
        elif column == "track_id":
            df[column] = df[column].astype(float)
        df.loc[df.index[rows], column] = value

    return change


def _add_flag(column: str, first_value):
    def change(df):
        df[column] = [first_value] + ["yes"] * (len(df) - 1)  # parquet: one type per column

    return change


@pytest.mark.parametrize(
    ("name", "change", "needles"),
    [
        # NaN time or id went through np.interp into alerts with NaN times, exit 0.
        ("nan_time.parquet", _set("time_s", np.nan), ["nan_time.parquet", "'time_s'", "row 0"]),
        ("nan_id.parquet", _set("track_id", np.nan), ["nan_id.parquet", "'track_id'", "row 0"]),
        # A string velocity is one line, not a ValueError traceback.
        ("str_v.parquet", _set("vn_mps", "fast", slice(None)), ["str_v.parquet", "'vn_mps'", "fast"]),
        # An infinite position was dropped like a missing one: no alert and no word.
        ("inf_n.parquet", _set("north_m", np.inf, slice(None)), ["inf_n.parquet", "'north_m'", "inf"]),
        # 1e308 is finite: it passed, overflowed in the conflict geometry and gave alerts at range inf.
        ("big_n.parquet", _set("north_m", 1e308), ["big_n.parquet", "'north_m'", "1e+308", "row 0"]),
        # The altitude flag is read as a boolean; "maybe" must not become True.
        (
            "alt_flag.parquet",
            _add_flag("altitude_measured", "maybe"),
            ["alt_flag.parquet", "'altitude_measured'", "maybe"],
        ),
    ],
)
def test_alert_refuses_corrupt_track_values(tiny_run, name, change, needles, cli):
    _tracks_variant(tiny_run, name, change)
    result = cli("alert", name, "--ownship", "run.zarr", "-o", f"alerts_{name}", cwd=tiny_run)
    _assert_one_line_error(result, *needles)
    assert not (tiny_run / f"alerts_{name}").exists()


def test_alert_counts_rows_without_velocity(tiny_run):
    # NaN velocity means "no direction of arrival": skipped, and the skip is reported.
    name = _tracks_variant(tiny_run, "nan_v.parquet", _set("vn_mps", np.nan, slice(None)))
    result = _skyradar(
        "alert", name, "--ownship", "run.zarr", "-o", "alerts_nan_v.parquet", "--json", cwd=tiny_run
    )
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout.strip().splitlines()[-1])
    assert summary["rows"] == 0
    assert summary["rows_skipped_no_state"] > 0


def test_parquet_named_csv_is_one_line(tiny_run):
    # pandas' CSV parser error spans two lines; the CLI printed both.
    (tiny_run / "tracks_as.csv").write_bytes((tiny_run / "tracks.parquet").read_bytes())
    result = _skyradar("track", "tracks_as.csv", "-o", "t.parquet", cwd=tiny_run)
    _assert_one_line_error(result, "tracks_as.csv")


@pytest.mark.parametrize(
    ("change", "needles"),
    [
        # YAML true was read as 1.0 frames/s: one frame simulated, exit 0.
        ({"frame_rate_hz": True}, ["frame_rate_hz", "boolean"]),
        # start_s 1e308 was blamed on the trajectory's time_s.
        ({"start_s": 1e308}, ["'start_s'", "1e+308"]),
    ],
)
def test_scenario_wrong_types_are_refused(tmp_path, change, needles, cli):
    (tmp_path / "s.yaml").write_text(yaml.safe_dump({**BASE, **change}))
    result = cli("simulate", "s.yaml", "-o", "run.zarr", cwd=tmp_path)
    _assert_one_line_error(result, "s.yaml", *needles)
    assert not any(tmp_path.glob("run.zarr*"))


@pytest.mark.parametrize("command", ["simulate", "process"])
def test_huge_worker_count_is_refused_before_any_process_starts(tiny_run, command, cli):
    # --workers 10**20 started a local cluster and the machine ran out of memory (exit 137).
    source = "s.yaml" if command == "simulate" else "run.zarr"
    output = "w.zarr" if command == "simulate" else "w.parquet"
    result = cli(command, source, "-o", output, "--workers", str(10**20), cwd=tiny_run)
    _assert_one_line_error(result, "--workers", str(10**20))
    assert not any(tiny_run.glob("w.*"))


@pytest.mark.parametrize(
    ("args", "needles"),
    [
        # --frames 10**20 was blamed on the ch2 scenario's duration_s.
        (["experiment", "ch2", "--frames", str(10**20)], ["--frames", str(10**20)]),
        # --duration 1e308 and --n 10**20 would ask numpy for arrays beyond "Maximum allowed size".
        (["experiment", "ch5", "--duration", "1e308"], ["--duration", "1e+308"]),
        (["experiment", "encounters", "--n", str(10**20)], ["--n", str(10**20)]),
        (["experiment", "encounters", "--rx-layout", "ring"], ["--rx-layout", "'ring'"]),
    ],
)
def test_experiment_sizes_are_bounded_before_the_output_folder(tmp_path, args, needles, cli):
    result = cli(*args, "--output", "out", cwd=tmp_path)
    _assert_one_line_error(result, *needles)
    assert not (tmp_path / "out").exists()  # refused before the folder is made


def test_evaluate_refuses_nan_radial_velocity(tiny_run):
    # A NaN in a scored column would reach scipy's assignment ("matrix contains invalid numeric entries").
    import pandas as pd

    tracks = pd.read_parquet(tiny_run / "tracks.parquet").assign(
        range_m=1000.0, radial_velocity_mps=np.nan, innovation_range_m=0.0, innovation_radial_velocity_mps=0.0
    )
    tracks.to_parquet(tiny_run / "eval_nan.parquet", index=False)
    result = _skyradar("evaluate", "run.zarr", "eval_nan.parquet", cwd=tiny_run)
    _assert_one_line_error(result, "eval_nan.parquet", "'radial_velocity_mps'", "row 0")


@pytest.mark.parametrize(
    ("args", "needles"),
    [
        # Each would raise inside numpy ("Maximum allowed size exceeded", "lam value too large") or blame
        # a temporary scenario file's duration_s: refused under the option's own name instead.
        (["bench", "chain", "--workers", str(10**20)], ["--workers", str(10**20)]),
        (["bench", "track", "--detections", str(10**20)], ["--detections", str(10**20)]),
        (["bench", "flight", "--frames", str(10**20)], ["--frames", str(10**20)]),
    ],
)
def test_bench_sizes_are_bounded(tmp_path, args, needles, cli):
    _assert_one_line_error(cli(*args, cwd=tmp_path), *needles)


def test_duplicate_yaml_key_is_refused(tmp_path):
    # PyYAML kept the last duration_s without a word: a 1 s scenario became a 50000 s run.
    text = yaml.safe_dump(BASE) + "duration_s: 50000\n"
    (tmp_path / "s.yaml").write_text(text)
    result = _skyradar("simulate", "s.yaml", "-o", "run.zarr", cwd=tmp_path)
    _assert_one_line_error(result, "s.yaml", "'duration_s'", "twice")
    assert not any(tmp_path.glob("run.zarr*"))


def test_serve_bad_host_is_one_line(tiny_run):
    # The non-loopback warning was printed before the address was checked: two lines.
    result = _skyradar("serve", "run.zarr", "--host", "999.1.1.1", "--port", "0", cwd=tiny_run)
    _assert_one_line_error(result, "--host", "999.1.1.1")


def test_chunk_larger_than_the_run_is_the_whole_run(tmp_path):
    # --chunk-frames 10**20 once sized the disk check for a 10^20-frame chunk ("needs 2.66e+17 GB").
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(BASE))
    result = _skyradar("simulate", "s.yaml", "-o", "run.zarr", "--chunk-frames", str(10**20), cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    from skyradar.io.frames import open_frames

    assert open_frames(tmp_path / "run.zarr").sizes["time"] == 4


def test_directory_as_table_and_sweep_suffix(tmp_path):
    (tmp_path / "folder.parquet").mkdir()
    _assert_one_line_error(
        _skyradar("track", "folder.parquet", "-o", "t.parquet", cwd=tmp_path),
        "folder.parquet",
        "is a directory",
    )
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(BASE))
    result = _skyradar(
        "sweep", "s.yaml", "--param", "intruders.0.rcs_m2", "--values", "1,2", "-o", "x.txt", cwd=tmp_path
    )
    _assert_one_line_error(result, "x.txt", ".csv or .parquet")
    assert not (tmp_path / "x.txt").exists()


@pytest.mark.parametrize(
    ("column", "value", "needles"),
    [
        ("right_axis_north", "abc", ["'right_axis_north'", "not a finite number", "row 2", "'abc'"]),
        ("azimuth_rad", 7.0, ["'azimuth_rad'", "is 7 rad at row 2", "not a direction"]),
        ("right_axis_east", 1e308, ["'right_axis_east'", "row 2"]),
        ("north_m", "abc", ["'north_m'", "not a finite number", "row 2", "'abc'"]),
        ("down_m", 1e308, ["'down_m'", "row 2", "not a radar measurement"]),
        ("other_north_m", "abc", ["'other_north_m'", "not a finite number", "row 2", "'abc'"]),
        ("other_residue", 7, ["'other_residue'", "is 7 at row 2", "whole number"]),
        ("other_residue", "abc", ["'other_residue'", "not a finite number", "row 2"]),
        ("other_elevation_rad", 2.0, ["'other_elevation_rad'", "is 2 rad at row 2", "not a direction"]),
        ("other_azimuth_rad", "abc", ["'other_azimuth_rad'", "not a finite number", "row 2", "'abc'"]),
    ],
)
def test_track_refuses_directions_that_are_not_directions(tmp_path, column, value, needles, cli):
    # The ground hold reads each detection's direction and the antenna's right axis, the 3-D filter
    # its position: text or an impossible value there is one line naming the file, field and row
    # (text is never read as NaN, a table silently without positions); NaN (not known) is taken.
    import pandas as pd

    t = np.arange(20) * 0.1
    detections = pd.DataFrame(
        {
            "time_s": t,
            "range_m": 1000.0 - 40.0 * t,
            "radial_velocity_mps": -40.0,
            "azimuth_rad": 0.1,
            "elevation_rad": np.nan,
            "right_axis_north": 0.0,
            "right_axis_east": 1.0,
            "right_axis_down": 0.0,
            "north_m": 1000.0 - 40.0 * t,
            "east_m": 100.0,
            "down_m": 0.0,
            "other_residue": -1,
            "other_north_m": np.nan,
            "other_east_m": np.nan,
            "other_down_m": np.nan,
            "other_azimuth_rad": np.nan,
            "other_elevation_rad": np.nan,
        }
    ).astype({column: object})
    detections.loc[2, column] = value
    detections.to_csv(tmp_path / "det.csv", index=False)
    result = cli("track", "det.csv", "-o", "tracks.parquet", cwd=tmp_path)
    _assert_one_line_error(result, "det.csv", *needles)
    assert not (tmp_path / "tracks.parquet").exists()
    detections.loc[2, column] = np.nan
    detections.to_csv(tmp_path / "det.csv", index=False)
    assert cli("track", "det.csv", "-o", "tracks.parquet", cwd=tmp_path).returncode == 0


@pytest.mark.parametrize("given", ["/dev/null", "empty.csv"])
def test_track_refuses_a_table_that_is_no_file_or_empty(tmp_path, given, cli):
    # A device (pyarrow reports /dev/null as missing) and an empty file are named for what they are;
    # a named pipe stays a table streamed in (tests/test_exclusive_writer.py reads one).
    (tmp_path / "empty.csv").write_text("")
    result = cli("track", given, "-o", "tracks.parquet", cwd=tmp_path)
    reason = "is a device" if given == "/dev/null" else "is empty"
    _assert_one_line_error(result, given, reason)
    assert not (tmp_path / "tracks.parquet").exists()


@pytest.mark.parametrize("content", ["csv", "parquet"])
def test_track_reads_a_table_from_a_pipe_or_a_file_without_suffix_by_its_content(tmp_path, content):
    # A shell's process substitution hands the command a pipe named /dev/fd/N: no suffix says the
    # format, so the content does (Parquet's magic bytes); the tracks are those of the named file.
    import subprocess
    import sys

    import pandas as pd

    t = np.arange(30) * 0.1
    detections = pd.DataFrame(
        {"time_s": t, "range_m": 1000.0 - 40.0 * t, "radial_velocity_mps": -40.0, "azimuth_rad": 0.1}
    )
    named = tmp_path / f"det.{content}"
    detections.to_csv(named, index=False) if content == "csv" else detections.to_parquet(named)
    (tmp_path / "det_no_suffix").write_bytes(named.read_bytes())
    assert _skyradar("track", named.name, "-o", "named.parquet", cwd=tmp_path).returncode == 0
    assert _skyradar("track", "det_no_suffix", "-o", "bare.parquet", cwd=tmp_path).returncode == 0
    piped = subprocess.run(
        ["bash", "-c", f'"{sys.executable}" -m skyradar track <(cat {named.name}) -o piped.parquet'],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert piped.returncode == 0, piped.stderr
    expected = pd.read_parquet(tmp_path / "named.parquet")
    assert len(expected) > 0
    for other in ("bare.parquet", "piped.parquet"):
        pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / other), expected)
