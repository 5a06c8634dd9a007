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

from cli_helpers import assert_one_line_error as _assert_one_line_error
from cli_helpers import skyradar as _skyradar

# --- usage errors and help -------------------------------------------------------------------------


@pytest.mark.parametrize("args", [(), ("experiment",), ("bench",)])
def test_bare_command_prints_help_and_exits_0(tmp_path, args, cli):
    result = cli(*args, cwd=tmp_path)
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
def test_usage_error_is_short_with_exit_2(tmp_path, args, needle, cli):
    result = cli(*args, cwd=tmp_path)
    assert result.returncode == 2, result.stderr
    assert "Traceback" not in result.stderr
    assert len(result.stderr.strip().splitlines()) <= 4, result.stderr
    assert result.stderr.strip().splitlines()[-1].startswith("Error:")
    assert needle in result.stderr


# --- ordinary input that must not crash ---------------------------------------------------------------


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


@pytest.mark.parametrize(("n", "ground", "model"), [(0, False, "radar"), (12, True, "traditional")])
def test_track_without_air_detections_writes_empty_table(tmp_path, n, ground, model, cli):
    from skyradar.track.track_table import TRACK_COLUMNS

    source = _detections(tmp_path / "det.parquet", n, ground)
    result = cli("track", str(source), "-o", "trk.parquet", "--model", model, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "no tracks" in result.stderr
    tracks = pd.read_parquet(tmp_path / "trk.parquet")
    assert len(tracks) == 0
    assert list(tracks.columns) == TRACK_COLUMNS
    assert tracks["detection_row"].dtype == np.int64


@pytest.mark.parametrize(
    ("args", "needles"),
    [
        (("bench", "state", "--min-time-s", "nan"), ["--min-time-s", "nan"]),
        (("bench", "process", "--min-time-s", "-1"), ["--min-time-s", "-1"]),
        (("bench", "track", "--frames", "0"), ["--frames", "0"]),
        (("bench", "flight", "--frames", "0"), ["--frames", "0"]),
        (("bench", "encounter", "--terrain", "marsh"), ["--terrain", "marsh"]),
        (("bench", "realtime", "--frame-rate-hz", "inf"), ["--frame-rate-hz", "inf"]),
        (("experiment", "ch4", "--chain", "bogus"), ["--chain", "bogus"]),
        (("experiment", "ch5", "--duration", "-1"), ["--duration", "-1"]),
        (("experiment", "ch5", "--fast-duration", "inf"), ["--fast-duration", "inf"]),
        (("experiment", "encounters", "--frame-rate-hz", "nan"), ["--frame-rate-hz", "nan"]),
        (("experiment", "encounters", "--split", "evaluation", "--seed", "5"), ["--seed 5", "evaluation"]),
        (
            ("experiment", "encounters", "--split", "development", "--seed", "7001"),
            ["--seed 7001", "development"],
        ),
        (("experiment", "encounters", "--alert-config", "fast"), ["--alert-config", "fast"]),
        (("experiment", "clutter", "--terrain", "hills,marsh"), ["--terrain", "marsh", "jacksboro"]),
        (("process", "run.zarr", "-o", "d.parquet", "--pfa", "5"), ["--pfa", "5"]),
        (("process", "run.zarr", "-o", "d.parquet", "--pfa", "-1"), ["--pfa", "-1"]),
        (("process", "run.zarr", "-o", "d.parquet", "--pfa-secondary", "1"), ["--pfa-secondary", "1"]),
        (("process", "run.zarr", "-o", "d.parquet", "--pfa-secondary", "nan"), ["--pfa-secondary", "nan"]),
        (
            (
                "calibrate",
                "r.zarr",
                "-o",
                "c.json",
                "--range-m",
                "-5",
                "--azimuth-deg",
                "0",
                "--elevation-deg",
                "0",
            ),
            ["--range-m", "-5"],
        ),
        (("spur-map", "r.zarr", "-o", "s.npz", "--threshold", "2"), ["--threshold", "2"]),
        (("simulate", "s.yaml", "-o", "r.zarr", "--workers", "0"), ["--workers", "0"]),
        (("track", "d.parquet", "-o", "t.parquet", "--origin", "95,4,0"), ["--origin", "lat_deg", "95"]),
        (("evaluate", "r.zarr", "t.parquet", "--gospa-c", "nan"), ["--gospa-c", "nan"]),
    ],
)
def test_bad_option_values_give_one_line(tmp_path, args, needles, cli):
    _detections(tmp_path / "d.parquet", 3, False)
    result = cli(*args, cwd=tmp_path, timeout=60)
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
            [sys.executable, "-m", "skyradar", *args],
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=60,
            preexec_fn=_limit_memory,
        )
    except subprocess.TimeoutExpired:
        pytest.fail("the YAML bomb was expanded (no answer within 60 s)")
    _assert_one_line_error(result, "bomb.yaml", "aliases expand")


def test_deeply_nested_yaml_is_one_line(tmp_path):
    # [[[[... deeper than the parser's stack was a RecursionError traceback of 3000 lines.
    (tmp_path / "deep.yaml").write_text("[" * 100_000 + "]" * 100_000)
    result = _skyradar("simulate", "deep.yaml", "-o", "run.zarr", cwd=tmp_path)
    _assert_one_line_error(result, "deep.yaml", "nested too deeply")


def test_deeply_nested_json_sidecars_are_refused(tmp_path):
    # The other JSON a command reads: a radar config, a recording's sidecar, a raw IQ file's sidecar.
    from skyradar.cli.commands_process import _read_config
    from skyradar.errors import InputError
    from skyradar.io.iq_raw import read_raw_iq
    from skyradar.io.recordings import _load_sidecar

    deep = "[" * 100_000 + "]" * 100_000
    for name in ("radar.json", "rec.json", "iq.json"):
        (tmp_path / name).write_text(deep)
    (tmp_path / "iq.cf32").write_bytes(b"\0" * 64)
    for read, name in ((_read_config, "radar.json"), (_load_sidecar, "rec.json"), (read_raw_iq, "iq.cf32")):
        with pytest.raises(InputError, match="nested too deeply"):
            read(tmp_path / name)


def test_recursive_yaml_alias_is_refused(tmp_path):
    scenario = tmp_path / "loop.yaml"
    scenario.write_text("name: &a [1, *a]\n")
    _assert_one_line_error(_skyradar("simulate", str(scenario), "-o", "run.zarr", cwd=tmp_path), "loop.yaml")


# --- nonsense in frames, recordings and scenarios ---------------------------------------------------


def _store(path: Path, *, nan_frame: int | None = None, times: list[float] | None = None) -> Path:
    """A tiny frames store (6 frames of 40 x 16 x 4) written the way the test suite writes runs."""
    from skyradar.config import RadarConfig
    from skyradar.io.frames import frames_dataset

    cfg = RadarConfig.prototype_2022(range_limit_m=600.0, n_doppler=16)
    rng = np.random.default_rng(0)
    shape = (6, cfg.n_range, cfg.n_doppler, cfg.n_rx)
    iq = (rng.normal(size=shape) + 1j * rng.normal(size=shape)).astype(np.complex64) * 1e-7
    if nan_frame is not None:
        iq[nan_frame, 3, 2, 1] = np.nan
    t = np.arange(6) * 0.1 if times is None else np.asarray(times, float)
    frames_dataset(iq, t, cfg).to_zarr(path, consolidated=False)
    return path


@pytest.mark.parametrize(
    "command",
    [
        ("process", "-o", "out.parquet"),
        ("state", "-o", "out.parquet"),
        ("spur-map", "-o", "out.parquet"),
        ("calibrate", "-o", "out.parquet", "--range-m", "300", "--azimuth-deg", "0", "--elevation-deg", "0"),
    ],
)
def test_nan_frame_is_refused_naming_file_and_frame(tmp_path, command, cli):
    run = _store(tmp_path / "run.zarr", nan_frame=4)
    result = cli(command[0], str(run), *command[1:], cwd=tmp_path)
    _assert_one_line_error(result, "run.zarr", "'iq'", "frame 4", "nan")
    assert not (tmp_path / "out.parquet").exists()


@pytest.mark.parametrize(
    ("command", "times"),
    [("process", [0, 0.1, 0.2, 0.2, 0.3, 0.4]), ("state", [0, 0.1, 0.2, 0.15, 0.3, 0.4])],
)
def test_repeated_or_backward_frame_times_are_refused(tmp_path, command, times, cli):
    run = _store(tmp_path / "run.zarr", times=times)
    result = cli(command, str(run), "-o", "out.parquet", cwd=tmp_path)
    _assert_one_line_error(result, "run.zarr", "'time'", "frame 3")


def test_state_on_store_with_zero_range_bins_names_the_file(tmp_path):
    import json

    import xarray as xr

    run = _store(tmp_path / "ok.zarr")
    ds = xr.open_zarr(run, consolidated=False).isel(range=slice(0, 0)).load()
    cfg = json.loads(ds.attrs["radar_config"])
    cfg["range_limit_m"] = 1.0
    ds.attrs["radar_config"] = json.dumps(cfg)
    ds.to_zarr(tmp_path / "empty.zarr", consolidated=False)
    result = _skyradar("state", str(tmp_path / "empty.zarr"), "-o", "s.parquet", cwd=tmp_path)
    _assert_one_line_error(result, "empty.zarr", "range_limit_m", "0 range bins")


def test_cfar_that_does_not_fit_names_the_run(tmp_path):
    from skyradar.config import RadarConfig
    from skyradar.io.frames import frames_dataset

    cfg = RadarConfig.prototype_2022(range_limit_m=90.0, n_doppler=16)  # 6 range bins
    iq = np.ones((2, cfg.n_range, cfg.n_doppler, cfg.n_rx), np.complex64)
    frames_dataset(iq, np.arange(2) * 0.1, cfg).to_zarr(tmp_path / "small.zarr", consolidated=False)
    result = _skyradar("process", "small.zarr", "-o", "d.parquet", cwd=tmp_path)
    _assert_one_line_error(result, "small.zarr", "cfar")


def _recording(path: Path, nan_frame: int | None = None) -> Path:
    from skyradar.config import RadarConfig

    cfg = RadarConfig.prototype_2022()
    adc = np.ones((3, cfg.n_rx, 8, cfg.samples_per_chirp), np.complex64)
    if nan_frame is not None:
        adc[nan_frame, 0, 0, 5] = np.inf
    np.save(path, adc)
    return path


def test_rd_refuses_non_finite_samples_before_writing(tmp_path):
    rec = _recording(tmp_path / "rec.npy", nan_frame=2)
    result = _skyradar("rd", str(rec), "-o", "rd.zarr", cwd=tmp_path)
    _assert_one_line_error(result, "rec.npy", "frame 2", "inf")
    assert not any(tmp_path.glob("rd.zarr*"))


def test_rd_refuses_repeated_frame_times(tmp_path):
    import json

    rec = _recording(tmp_path / "rec.npy")
    (tmp_path / "rec.json").write_text(json.dumps({"frame_times_s": [0.0, 0.1, 0.1]}))
    result = _skyradar("rd", str(rec), "-o", "rd.zarr", cwd=tmp_path)
    _assert_one_line_error(result, "rec.json", "frame_times_s", "frame 2")


def test_a_frame_time_of_1e308_is_refused(tmp_path):
    # Finite, so a recording's store and a run's frames took it; the filters' powers of dt overflow.
    import json

    from skyradar.errors import InputError
    from skyradar.io.checks import check_frame_times
    from skyradar.io.recordings import read_recording

    rec = _recording(tmp_path / "rec.npy")
    (tmp_path / "rec.json").write_text(json.dumps({"frame_times_s": [0.0, 0.1, 1e308]}))
    with pytest.raises(InputError, match=r"rec.json: field 'frame_times_s' is 1e\+308 s at frame 2"):
        read_recording(rec)
    with pytest.raises(InputError, match=r"run.zarr: field 'time' is 1e\+308 s at frame 2"):
        check_frame_times(np.array([0.0, 0.1, 1e308]), "run.zarr")


_OWN = {"type": "straight", "start_ned_m": [0, 0, -500], "heading_deg": 0, "speed_mps": 40}


@pytest.mark.parametrize(
    ("change", "needles"),
    [
        ({"radar": {"range_limit_m": 1}}, ["range_limit_m", "0 range bins"]),
        ({"duration_s": 1e12}, ["duration_s", "frame_rate_hz", "frames"]),  # refused, not a MemoryError
        ({"ownship": {**_OWN, "speed_mps": 1e9}}, ["ownship", "speed", "Mach 3"]),
        ({"ownship": {**_OWN, "start_ned_m": [0, 0, 1e7]}}, ["ownship", "altitude"]),
        # 1e308: numpy's "Maximum allowed dimension exceeded" (a traceback) and an overflow of 10**(NF/10)
        ({"terrain": {"type": "flat", "size_m": 1e308}}, ["'terrain.size_m'", "1e+12", "1e+308"]),
        ({"radar": {"noise_figure_db": 1e11}}, ["noise_figure_db", "+-300"]),
    ],
)
def test_nonsense_scenario_is_refused(tmp_path, change, needles, cli):
    import yaml

    scenario = {
        "name": "tiny",
        "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
        "mount": "forward",
        "terrain": {"type": "flat", "size_m": 3000, "spacing_m": 60},
        "ownship": _OWN,
        "frame_rate_hz": 5.0,
        "duration_s": 1.0,
    }
    (tmp_path / "s.yaml").write_text(yaml.safe_dump({**scenario, **change}))
    result = cli("simulate", "s.yaml", "-o", "run.zarr", cwd=tmp_path)
    _assert_one_line_error(result, "s.yaml", *needles)
    assert not any(tmp_path.glob("run.zarr*"))


@pytest.mark.parametrize(
    ("rows", "needles"),
    [
        # 104 deg of latitude in 1 s (a sign error in one ADS-B message)
        (["0,52,4,1000", "1,-52,4,1000", "2,-52,4,1000"], ["track.csv", "row 1", "latitude", "Mach 3"]),
        # -100000 ft
        (["0,52,4,1000", "10,52.001,4,-100000"], ["track.csv", "row 1", "'altitude'", "-30480 m"]),
    ],
)
def test_implausible_trajectory_file_is_refused(tmp_path, rows, needles, cli):
    import yaml

    (tmp_path / "track.csv").write_text("\n".join(["timestamp,latitude,longitude,altitude", *rows]) + "\n")
    scenario = {
        "name": "jump",
        "mount": "forward",
        "terrain": {"type": "flat", "size_m": 3000, "spacing_m": 60},
        "ownship": "track.csv",
        "frame_rate_hz": 1.0,
        "duration_s": 1.0,
    }
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(scenario))
    result = cli("simulate", "s.yaml", "-o", "run.zarr", cwd=tmp_path)
    _assert_one_line_error(result, *needles)
    assert not any(tmp_path.glob("run.zarr*"))


@pytest.mark.parametrize(
    ("args", "needles"),
    [
        (("process", "run.zarr", "-o", "d.parquet", "--method", "bogus"), ["--method", "bogus"]),
        (("process", "run.zarr", "-o", "d.parquet", "--spur-mode", "bogus"), ["--spur-mode", "bogus"]),
        (("spur-map", "run.zarr", "-o", "s.npz", "--pixels", "bogus"), ["--pixels", "bogus"]),
        (("state", "run.zarr", "-o", "s.parquet", "--method", "bogus"), ["--method", "bogus"]),
        (
            (
                "calibrate",
                "run.zarr",
                "-o",
                "c.json",
                "--range-m",
                "5000",
                "--azimuth-deg",
                "0",
                "--elevation-deg",
                "0",
            ),
            ["--range-m", "5000", "run.zarr"],
        ),
        (("experiment", "ch3", "--path", "bogus"), ["--path", "bogus"]),
    ],
)
def test_options_are_named_in_their_errors(tmp_path, args, needles, cli):
    _store(tmp_path / "run.zarr")
    _assert_one_line_error(cli(*args, cwd=tmp_path), *needles)


def test_rd_names_the_window_option(tmp_path):
    rec = _recording(tmp_path / "rec.npy")
    result = _skyradar("rd", str(rec), "-o", "rd.zarr", "--doppler-window", "bogus", cwd=tmp_path)
    _assert_one_line_error(result, "--doppler-window", "bogus")


@pytest.mark.parametrize(
    ("rows", "needles"),
    [([], ["own.csv", "no rows"]), (["0,0,0,nan,0,0,0", "1,0,0,0,0,0,0"], ["own.csv", "own_down_m", "nan"])],
)
def test_track_refuses_empty_or_nan_ownship(tmp_path, rows, needles, cli):
    source = _detections(tmp_path / "det.parquet", 3, False)
    header = "time_s,own_north_m,own_east_m,own_down_m,own_vn_mps,own_ve_mps,own_vd_mps"
    (tmp_path / "own.csv").write_text("\n".join([header, *rows]) + "\n")
    result = cli("track", str(source), "-o", "t.parquet", "--ownship", "own.csv", cwd=tmp_path)
    _assert_one_line_error(result, *needles)
    assert not (tmp_path / "t.parquet").exists()


def test_alert_refuses_a_nan_ownship_table(tmp_path):
    # alert interpolated its own-ship state through the NaN and alerted, exit 0.
    header = "time_s,own_north_m,own_east_m,own_down_m,own_vn_mps,own_ve_mps,own_vd_mps"
    rows = ["0,0,0,-800,50,0,0", "1,nan,0,-800,50,0,0", "2,100,0,-800,50,0,0"]
    (tmp_path / "own.csv").write_text("\n".join([header, *rows]) + "\n")
    cols = ["time_s", "track_id", "north_m", "east_m", "down_m", "vn_mps", "ve_mps", "vd_mps"]
    track = pd.DataFrame([[1.0, 1, 2000.0, 0.0, -800.0, -50.0, 0.0, 0.0]], columns=cols)
    track.to_parquet(tmp_path / "t.parquet")
    result = _skyradar("alert", "t.parquet", "--ownship", "own.csv", "-o", "a.parquet", cwd=tmp_path)
    _assert_one_line_error(result, "own.csv", "'own_north_m'", "row 1", "nan")
    assert not (tmp_path / "a.parquet").exists()


def test_a_1e308_ownship_state_is_refused_by_track():
    from skyradar.errors import InputError
    from skyradar.track.io import validate_ownship

    own = pd.DataFrame({"time_s": [0.0, 1.0], "own_north_m": [0.0, 1e308], "own_vn_mps": [50.0, 50.0]})
    with pytest.raises(InputError, match=r"own.csv: field 'own_north_m' is 1e\+308 m at row 1"):
        validate_ownship(own, ("time_s", "own_north_m", "own_vn_mps"), "own.csv")
