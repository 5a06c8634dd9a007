"""Physical inputs outside their plausible range are refused in one line, through the entry point.

A radar head's lever arm is within 30 m of the aircraft's reference point and navigation errors are
those of working avionics; a value beyond is a slip of units or a failed sensor, and run silently it
blinds the chain (aircraft placed kilometres up, no detection, no warning).
"""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from cli_helpers import assert_one_line_error, skyradar, small_scenario

BASE = small_scenario("plausible")

REFUSED = [
    ({"mount": {"preset": "forward", "lever_arm_m": [1.0e9, 0.0, 0.0]}}, "mount.lever_arm_m.0", "<= 30"),
    ({"mount": {"preset": "forward", "position_m": [0.0, -45.0, 0.0]}}, "mount.position_m.1", ">= -30"),
    (
        {"radars": [{"name": "nose", "mount": {"preset": "forward", "lever_arm_m": [2.0, 0.0, 1000.0]}}]},
        "radars.0.mount.lever_arm_m.2",
        "<= 30",
    ),
    (
        {"navigation": {"model": "ga-typical", "heading_bias_deg": 1.0e6}},
        "navigation.heading_bias_deg",
        "<= 30",
    ),
    (
        {"navigation": {"model": "ga-typical", "gnss_horizontal_bias_m": 1.0e7}},
        "gnss_horizontal_bias_m",
        "<= 100",
    ),
    (
        {"navigation": {"model": "perfect", "gnss_velocity_noise_mps": 50.0}},
        "gnss_velocity_noise_mps",
        "<= 5",
    ),
]


@pytest.mark.parametrize(("change", "field", "bound"), REFUSED)
def test_implausible_physical_inputs_are_refused(tmp_path, change, field, bound, cli):
    (tmp_path / "s.yaml").write_text(yaml.safe_dump({**BASE, **change}))
    result = cli("simulate", "s.yaml", "-o", "run.zarr", cwd=tmp_path)
    assert_one_line_error(result, "s.yaml", field, bound)
    assert not (tmp_path / "run.zarr").exists()


def test_plausible_values_at_the_edge_are_accepted(tmp_path):
    from skyradar.scene.scenario import load_scenario

    change = {
        "mount": {"preset": "forward", "lever_arm_m": [29.0, -12.0, 1.5]},
        "navigation": {"model": "ga-typical", "heading_bias_deg": 30.0, "gnss_horizontal_bias_m": 100.0},
    }
    (tmp_path / "s.yaml").write_text(yaml.safe_dump({**BASE, **change}))
    built = load_scenario(tmp_path / "s.yaml").build()
    assert tuple(built.heads[0].config.mount.position_m) == (29.0, -12.0, 1.5)


def _tif(path, z):
    import rasterio

    with rasterio.open(
        path,
        "w",
        driver="GTiff",
        height=z.shape[0],
        width=z.shape[1],
        count=1,
        dtype=z.dtype,
        crs="EPSG:4326",
        transform=rasterio.Affine(0.001, 0.0, 4.33, 0.0, -0.001, 52.53),
    ) as ds:  # no nodata declared, as in many downloads
        ds.write(z, 1)


def test_an_undeclared_no_data_block_in_a_geotiff_is_not_read_as_terrain(tmp_path):
    rows, cols = np.mgrid[0:60, 0:80]
    z = (5.0 + 0.1 * rows + 0.05 * cols).astype(np.float32)
    z[10:30, 10:40] = -3.4e38  # 12.5 % of the tile: a no-data block the file does not declare
    _tif(tmp_path / "dem.tif", z)
    scenario = {**BASE, "terrain": {"type": "file", "path": "dem.tif"}}
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(scenario))
    result = skyradar("simulate", "s.yaml", "-o", "run.zarr", cwd=tmp_path)
    assert_one_line_error(result, "dem.tif", "-3.4e+38", "outside the land surface", "does not declare")
    assert not (tmp_path / "run.zarr").exists()


def test_a_few_undeclared_no_data_samples_are_filled_as_voids():
    from skyradar.scene.dem_readers import terrain_from_arrays

    rows, cols = np.mgrid[0:60, 0:80]
    z = 5.0 + 0.1 * rows + 0.05 * cols
    bad = z.copy()
    bad[20, 30] = 32767.0  # an integer tile's undeclared no-data value
    grid = {"dx_m": 30.0, "dy_m": 30.0, "lat0_deg": 52.5, "lon0_deg": 4.3}
    t = terrain_from_arrays({"elevation": bad, **grid}, "t.npz")
    assert float(t.elevation_m[20, 30]) == pytest.approx(z[20, 30], abs=1e-6)  # filled from a plane


def test_a_decompression_bomb_is_refused_quickly(tmp_path):
    """A 0.6 MB .json.gz that inflates to 600 MB: refused at the 256 MiB ceiling, in one line."""
    import gzip

    with gzip.open(tmp_path / "bomb.json.gz", "wb", compresslevel=9) as fh:
        for _ in range(600):
            fh.write(b" " * (1 << 20))
    result = skyradar("flight", "bomb.json.gz", "-o", "b.csv", cwd=tmp_path)
    assert_one_line_error(result, "bomb.json.gz", "inflates to more than 256 MiB")
    assert not (tmp_path / "b.csv").exists()


@pytest.mark.parametrize(
    "settings",
    [
        {"levels": [{"name": "only", "dthr_m": 670.56, "zthr_m": 137.16, "alerting_time_s": 25}]},
        {
            "levels": [
                {"name": n, "dthr_m": 0.0, "zthr_m": 0.0, "alerting_time_s": 25}
                for n in ("preventive", "corrective", "warning")
            ]
        },
        {"min_track_age_s": 1.0e5, "min_track_age_floor_s": 1.0e5},  # 1e9 s: beyond every setting's 1e6
        {"max_velocity_sigma_mps": 0.0},
    ],
)
def test_an_alert_config_that_never_warns_is_refused(tmp_path, settings):
    """Each of these once switched warnings off without a word; checked on a head-on course at load."""
    (tmp_path / "quiet.yaml").write_text(yaml.safe_dump(settings))
    from skyradar.daa.alert_config import alert_config
    from skyradar.errors import InputError

    with pytest.raises(
        InputError, match=r"quiet.yaml: these settings never warn on a head-on collision course"
    ):
        alert_config(tmp_path / "quiet.yaml")


def test_an_alert_config_that_alerts_on_everything_is_refused_through_the_entry_point(tmp_path):
    """A preventive volume of 100 km (1e308 m is out of range) alerts on every aircraft in sight. The
    config is named before the tracks are read: they need not exist. (The settings that never warn
    are refused by the same check, above; test_ownship_cli runs a bad config through the CLI.)"""
    levels = [
        {"name": "preventive", "dthr_m": 1.0e5, "zthr_m": 1.0e5, "alerting_time_s": 55},
        {"name": "corrective", "dthr_m": 670.56, "zthr_m": 137.16, "alerting_time_s": 55},
        {"name": "warning", "dthr_m": 670.56, "zthr_m": 137.16, "alerting_time_s": 25},
    ]
    (tmp_path / "c.yaml").write_text(yaml.safe_dump({"levels": levels}))
    args = ("alert", "t.parquet", "--ownship", "run.zarr", "-o", "a.parquet", "--config", "c.yaml")
    assert_one_line_error(
        skyradar(*args, cwd=tmp_path), "c.yaml", "alert on an aircraft 10 km abeam flying alongside"
    )


def test_an_alert_setting_beyond_1e6_is_refused(tmp_path):
    # z 1e308 overflowed the widened volumes (numpy warnings, then an alert on everything).
    from skyradar.daa.alert_config import alert_config
    from skyradar.errors import InputError

    (tmp_path / "z.yaml").write_text(yaml.safe_dump({"z_h_pos": 1.0e308}))
    message = r"z.yaml: field 'z_h_pos': must be a finite number from 0 to 1e\+06"
    with pytest.raises(InputError, match=message):
        alert_config(tmp_path / "z.yaml")


def test_an_alert_config_that_warns_is_accepted(tmp_path):
    from skyradar.daa.alert_config import alert_config

    (tmp_path / "strict.yaml").write_text(yaml.safe_dump({"m": 3, "n": 5, "min_track_age_s": 3.0}))
    assert alert_config(tmp_path / "strict.yaml").m == 3


@pytest.mark.parametrize("address", ["garbage address", "tcp://::::bad"])
def test_a_malformed_scheduler_address_is_one_line(tmp_path, address, cli):
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(BASE))
    result = cli("simulate", "s.yaml", "-o", "run.zarr", "--scheduler", address, cwd=tmp_path)
    assert_one_line_error(result, "--scheduler", "not a Dask scheduler address")
    assert not list(tmp_path.glob("run.zarr*"))


def test_a_scheduler_address_without_a_valid_port_is_refused_before_the_output_folder(tmp_path):
    # tcp://HOST:99999 waited 10 s for an answer that cannot come, and left the experiment's folder.
    result = skyradar(
        "experiment", "encounters", "--scheduler", "tcp://127.0.0.1:99999", "--output", "x", cwd=tmp_path
    )
    assert_one_line_error(result, "--scheduler tcp://127.0.0.1:99999", "port 99999 is not 1..65535")
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize(
    "command",
    [("simulate-passive", "-o", "rec.sigmf-meta"), ("passive", "rec.sigmf-meta", "-o", "d.parquet")],
)
def test_a_tiny_iq_chunk_is_refused(tmp_path, command, cli):
    """One-sample chunks made a 1-s recording take hours: the option is bounded below."""
    result = cli(*command, "--chunk-samples", "1", cwd=tmp_path)
    assert result.returncode == 2 and "--chunk-samples" in result.stderr and ">= 4096" in result.stderr
    assert "Traceback" not in result.stderr


@pytest.mark.slow
def test_one_head_commands_on_a_run_of_several_heads_ask_which(tmp_path):
    """state, spur-map and calibrate use one head: on a two-head run they name the heads and ask."""
    heads = [{"name": "nose", "mount": "forward"}, {"name": "belly", "mount": "forward-down"}]
    two = {**BASE, "radars": heads, "simulation": {"noise": True, "psf": False, "speckle": False}}
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(two))
    made = skyradar("simulate", "s.yaml", "-o", "run.zarr", cwd=tmp_path)
    assert made.returncode == 0, made.stderr
    for args in (
        ("state", "run.zarr", "-o", "st.parquet"),
        ("spur-map", "run.zarr", "-o", "spurs.npz"),
        (
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
        ),
    ):
        result = skyradar(*args, cwd=tmp_path)
        assert_one_line_error(result, "run.zarr", "2 radar heads (nose, belly)", "give --head NAME")
    bad = skyradar("state", "run.zarr", "-o", "st.parquet", "--head", "tail", cwd=tmp_path)
    assert_one_line_error(bad, "--head", "'tail' is not a head of run.zarr")
    ok = skyradar("state", "run.zarr", "-o", "st.parquet", "--head", "belly", cwd=tmp_path)
    assert ok.returncode == 0, ok.stderr


def test_hostile_paths_give_one_line(tmp_path):
    """A symbolic link loop as input or output and a name longer than the file system allows."""
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(BASE))
    (tmp_path / "loop").symlink_to(tmp_path / "loop")
    cases = [
        (("simulate", "loop", "-o", "run.zarr"), "loop", "symbolic link loop"),
        (("flight", "loop", "-o", "x.csv"), "loop", "symbolic link loop"),
        (("process", "loop", "-o", "d.parquet"), "loop", "symbolic link"),
        (("simulate", "s.yaml", "-o", "a" * 300 + ".zarr"), "aaaa", "File name too long"),
        # 250 bytes fit, the temporary name written first does not: refused before the run, not after it
        (("simulate", "s.yaml", "-o", "b" * 245 + ".zarr"), "bbbb", "File name too long"),
    ]
    for args, path, reason in cases:
        result = skyradar(*args, cwd=tmp_path)
        assert_one_line_error(result, path, reason)
    assert not any(p.name.startswith(("aaa", "bbb", ".aaa", ".bbb")) for p in tmp_path.iterdir())


def test_a_run_or_own_ship_behind_a_link_that_leads_nowhere_is_named_so(tmp_path):
    from skyradar.errors import InputError
    from skyradar.io.frames import open_frames
    from skyradar.io.ownship_input import open_ownship

    (tmp_path / "loop").symlink_to(tmp_path / "loop")
    (tmp_path / "gone").symlink_to(tmp_path / "missing.zarr")
    for name in ("loop", "gone"):
        with pytest.raises(InputError, match="symbolic link that leads nowhere"):
            open_frames(tmp_path / name)
        with pytest.raises(InputError, match="symbolic link that leads nowhere"):
            open_ownship(tmp_path / name)


def test_sigmf_metadata_with_a_nan_rate_or_deep_nesting_is_one_line(tmp_path):
    import json
    import shutil

    made = skyradar("simulate-passive", "-o", "rec.sigmf-meta", "--duration-s", "0.05", cwd=tmp_path)
    assert made.returncode == 0, made.stderr
    meta = json.loads((tmp_path / "rec.sigmf-meta").read_text())
    meta["global"]["core:sample_rate"] = float("nan")
    (tmp_path / "nan.sigmf-meta").write_text(json.dumps(meta))
    meta["global"]["core:sample_rate"] = 5e6
    meta["global"]["skyradar:illuminator"]["pri_s"] = [1e308] * 4  # crashed the pulse profile
    meta["global"].pop("core:sha512", None)
    (tmp_path / "pri.sigmf-meta").write_text(json.dumps(meta))
    (tmp_path / "deep.sigmf-meta").write_text("[" * 100_000 + "]" * 100_000)
    for name in ("nan", "deep", "pri"):
        shutil.copy(tmp_path / "rec.sigmf-data", tmp_path / f"{name}.sigmf-data")
    assert_one_line_error(
        skyradar("passive", "nan.sigmf-meta", "-o", "a.parquet", cwd=tmp_path),
        "nan.sigmf-meta",
        "core:sample_rate",
        "finite rate",
    )
    assert_one_line_error(
        skyradar("passive", "deep.sigmf-meta", "-o", "b.parquet", cwd=tmp_path),
        "deep.sigmf-meta",
        "nested too deeply",
    )
    assert_one_line_error(
        skyradar("passive", "pri.sigmf-meta", "-o", "c.parquet", cwd=tmp_path),
        "pri.sigmf-meta",
        "'pri_s'",
        "1e+308",
    )


def test_a_negated_range_column_is_refused_by_track(tmp_path):
    import pandas as pd

    det = pd.DataFrame(
        {
            "time_s": [0.0, 0.1, 0.2],
            "frame": [0, 1, 2],
            "range_m": [-900.0, -895.0, -890.0],
            "radial_velocity_mps": [-50.0, -50.0, -50.0],
        }
    )
    det.to_parquet(tmp_path / "det.parquet")
    result = skyradar("track", "det.parquet", "-o", "trk.parquet", cwd=tmp_path)
    assert_one_line_error(result, "det.parquet", "range_m", "negative at row 0")
    assert not (tmp_path / "trk.parquet").exists()


def test_a_range_of_1e308_is_refused_by_track(tmp_path):
    # Finite, so it passed the checks, and the tracker dropped the detection without a word.
    import pandas as pd

    det = pd.DataFrame(
        {
            "time_s": [0.0, 0.1, 0.2],
            "frame": [0, 1, 2],
            "range_m": [900.0, 1e308, 890.0],
            "radial_velocity_mps": [-50.0, -50.0, -50.0],
        }
    )
    det.to_parquet(tmp_path / "det.parquet")
    result = skyradar("track", "det.parquet", "-o", "trk.parquet", cwd=tmp_path)
    assert_one_line_error(result, "det.parquet", "'range_m'", "1e+308", "row 1")
    assert not (tmp_path / "trk.parquet").exists()


@pytest.mark.parametrize(
    ("row", "needles"),
    [
        ("10,52.001,4.36,1000,1e308,0,0", ["'groundspeed'", "row 1", "1e+308 kt"]),  # was a traceback
        ("10,52.001,4.36,FL350,100,0,0", ["'altitude'", "row 1", "'FL350'"]),  # was dropped as empty
    ],
)
def test_a_flight_file_with_a_corrupt_number_is_one_line(tmp_path, row, needles, cli):
    rows = ["0,52,4.36,1000,100,0,0", row, "20,52.002,4.36,1000,100,0,0", "30,52.003,4.36,1000,100,0,0"]
    head = "timestamp,latitude,longitude,altitude,groundspeed,track,vertical_rate"
    (tmp_path / "f.csv").write_text("\n".join([head, *rows]) + "\n")
    assert_one_line_error(cli("flight", "f.csv", "-o", "p.csv", cwd=tmp_path), "f.csv", *needles)
    assert not (tmp_path / "p.csv").exists()


def test_a_refused_intruder_file_is_the_one_line_after_a_good_own_ship_file(tmp_path):
    # The own-ship file's repair note came first: two lines for one refusal.
    head = "timestamp,latitude,longitude,altitude\n"
    (tmp_path / "own.csv").write_text(head + "0,52,4.36,1000\n60,52.03,4.36,1000\n")
    (tmp_path / "int.csv").write_text(head + "0,52.06,4.37,1000\n60,52.03,4.37,high\n")
    result = skyradar("make-encounter", "own.csv", "int.csv", "-o", "e.yaml", cwd=tmp_path)
    assert_one_line_error(result, "int.csv", "'altitude'", "'high'")


@pytest.mark.parametrize("name", ["../x", ".", "zarr.json", ".zattrs", "a/b", "nose head"])
def test_a_radar_head_name_that_is_not_a_plain_name_is_refused(tmp_path, name, cli):
    # A head's frames are a group named after it: a path or a Zarr metadata key would write outside it
    # (and crashed half-way, leaving a .partial store).
    heads = [{"name": name, "mount": "nose"}, {"name": "left", "mount": "left-wingtip"}]
    (tmp_path / "s.yaml").write_text(yaml.safe_dump({**BASE, "duration_s": 0.4, "radars": heads}))
    done = cli("simulate", "s.yaml", "-o", "run.zarr", cwd=tmp_path)
    assert_one_line_error(done, "radars.0.name")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.yaml"]


@pytest.mark.parametrize(
    "radar",
    [
        {"rx_positions_m": [[0, 0, 0], [0, 1.0e6, 0], [0, 0, 1.0e6], [0, 1.0e6, 1.0e6]]},  # km for m
        {"rx_positions_m": [[0, 0, 0], [0, 3.0, 0], [0, 0, 0.0156], [0, 3.0, 0.0156]]},
        {"tx_position_m": [0.0, 500.0, 0.0]},
    ],
)
def test_an_antenna_array_larger_than_one_aircraft_is_refused(tmp_path, radar, cli):
    # One radar's antennas sit on one aircraft, within 2 m of each other; farther is a unit mistake.
    (tmp_path / "s.yaml").write_text(yaml.safe_dump({**BASE, "duration_s": 0.4, "radar": radar}))
    done = cli("simulate", "s.yaml", "-o", "run.zarr", cwd=tmp_path)
    assert_one_line_error(done, "radar.", "2 m")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.yaml"]
