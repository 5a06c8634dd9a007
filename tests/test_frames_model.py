"""Frames data model: absolute UTC time + elapsed seconds, CF attributes, radar attributes, round trips."""

import numpy as np
import pytest
import xarray as xr
from tests.cli_helpers import assert_one_line_error, skyradar

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.io.frames import frame_times_s, frames_dataset, open_frames, radar_config_of
from skyradar.io.frames_model import DEFAULT_START_TIME, STANDARD_NAMES, parse_start_time
from skyradar.scene.scenario import Scenario

CFG = RadarConfig.prototype_2022(n_doppler=16, range_limit_m=150.0)
TIMES = np.array([0.0, 1 / 9.4, 2 / 9.4, 3 / 9.4])


def _dataset(start_time="2026-05-01T10:00:00Z"):
    rng = np.random.default_rng(0)
    shape = (TIMES.size, CFG.n_range, CFG.n_doppler, CFG.n_rx)
    iq = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)).astype(np.complex64)
    own = {"own_lat_deg": np.linspace(52, 52.001, 4), "own_height_agl_m": np.full(4, 300.0)}
    tgt = {"tgt_range_m": np.full((4, 2), 900.0), "tgt_visible": np.ones((4, 2), bool)}
    return frames_dataset(iq, TIMES, CFG, own, tgt, ["A", "B"], {"scenario": "t"}, start_time=start_time)


def _write(ds, path):
    ds.assign_attrs(skyradar_complete=True).to_zarr(path, mode="w", consolidated=False)
    return path


def test_absolute_utc_time_and_elapsed_seconds():
    ds = _dataset()
    assert ds["time"].dtype == np.dtype("datetime64[ns]") and ds["time_s"].dtype == np.float64
    expected = np.datetime64("2026-05-01T10:00:00", "ns") + np.round(TIMES * 1e9).astype("timedelta64[ns]")
    np.testing.assert_array_equal(ds["time"].values, expected)
    np.testing.assert_array_equal(frame_times_s(ds), TIMES)  # exactly the simulator's floats
    assert ds.attrs["start_time"] == "2026-05-01T10:00:00Z" and ds["time_s"].attrs["units"] == "s"


def test_cf_attributes_on_every_variable_and_coordinate():
    ds = _dataset()
    assert ds.attrs["Conventions"].startswith("CF-")
    for name, var in ds.variables.items():
        assert "long_name" in var.attrs, name
        if name not in ("time", "target"):  # datetime units live in the encoding; names have none
            assert "units" in var.attrs, name
        if name in STANDARD_NAMES:
            assert var.attrs["standard_name"] == STANDARD_NAMES[name], name
    assert ds["time"].attrs["standard_name"] == "time"


def test_radar_config_readable_as_attributes_and_json():
    ds = _dataset()
    assert ds.attrs["radar_fc_hz"] == CFG.fc_hz and ds.attrs["radar_n_doppler"] == 16
    assert ds.attrs["radar_range_resolution_m"] == CFG.range_resolution_m
    np.testing.assert_array_equal(np.reshape(ds.attrs["radar_rx_positions_m"], (-1, 3)), CFG.rx_positions_m)
    assert radar_config_of(ds) == CFG


def test_zarr_round_trip_identical_values_attrs_dtypes(tmp_path):
    ds = _dataset()
    back = open_frames(_write(ds, tmp_path / "run.zarr")).load()
    for name, var in ds.variables.items():
        np.testing.assert_array_equal(back[name].values, var.values, err_msg=name)
        if name != "target":  # names: object in memory, numpy StringDType from Zarr v3
            assert back[name].dtype == var.dtype, name
        assert back[name].attrs == var.attrs, name
    assert {k: v for k, v in back.attrs.items() if k != "skyradar_complete"} == ds.attrs
    assert radar_config_of(back) == CFG


def test_default_start_time_is_documented_epoch():
    ds = _dataset(start_time=None)
    assert ds.attrs["start_time"] == DEFAULT_START_TIME
    assert ds["time"].values[0] == np.datetime64("1970-01-01T00:00:00", "ns")


def test_old_store_with_float_time_still_opens_with_elapsed_seconds(tmp_path):
    ds = _dataset().drop_vars("time_s").assign_coords(time=TIMES)  # the frames/1 layout
    del ds.attrs["start_time"]
    back = open_frames(_write(ds, tmp_path / "old.zarr"))
    np.testing.assert_array_equal(frame_times_s(back), TIMES)


def test_netcdf_is_refused_with_one_line(tmp_path):
    path = tmp_path / "run.nc"
    xr.Dataset({"x": ("t", [1.0])}).to_netcdf(path)
    with pytest.raises(InputError, match="not a frames store"):
        open_frames(path)


def test_scenario_start_time_reaches_the_frames(tmp_path):
    spec = {
        "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
        "ownship": {"type": "straight", "speed_mps": 50, "start_ned_m": [0, 0, -300]},
        "duration_s": 1,
        "start_s": 5,
        "start_time": "2026-05-01T12:00:00+02:00",
    }
    built = Scenario.from_dict(spec).build()
    assert built.start_time == np.datetime64("2026-05-01T10:00:00", "ns")
    with pytest.raises(InputError, match="start_time"):
        Scenario.from_dict(spec | {"start_time": "noon"}).build()
    assert parse_start_time("2026-05-01T10:00:00") == built.start_time  # no offset: UTC


def test_cli_names_a_bad_scenario_start_time(tmp_path):
    path = tmp_path / "s.yaml"
    origin = "origin: {lat_deg: 52.0, lon_deg: 4.36, alt_m: 0.0}\n"
    path.write_text(origin + "ownship: {type: straight, speed_mps: 50}\nduration_s: 1\nstart_time: noon\n")
    result = skyradar("simulate", str(path), "-o", str(tmp_path / "run.zarr"), cwd=tmp_path)
    assert_one_line_error(result, "start_time")
