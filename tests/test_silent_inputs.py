"""Inputs that must not give a silently wrong run: a DEM far from the flight, tracks alerted against
another run's own-ship; and the DEM window the scenario reads."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import rasterio
import yaml

from cli_helpers import assert_one_line_error as _assert_one_line_error
from cli_helpers import skyradar as _skyradar
from skyradar.errors import InputError
from skyradar.io.frames import open_frames
from skyradar.scene.dem_coverage import dem_for_run
from skyradar.scene.dem_readers import read_dem, read_geotiff
from skyradar.scene.scenario import Scenario, load_scenario
from skyradar.scene.terrain import Bounds
from skyradar.sim.simulate_store import simulate_to_zarr

BASE = {
    "name": "tiny",
    "origin": {"lat_deg": 52.5, "lon_deg": 4.36, "alt_m": 0.0},
    "mount": "forward",
    "radar": {"range_limit_m": 600.0},
    "ownship": {"type": "straight", "start_ned_m": [0, 0, -300], "heading_deg": 0, "speed_mps": 40},
    "frame_rate_hz": 5.0,
    "duration_s": 1.0,
    "simulation": {"facet_size_m": 30.0},
}


def _hgt(directory: Path, name: str) -> Path:
    """A valid SRTM-3 tile: a plane rising 1 m per row southwards and 2 m per column eastwards."""
    rows, cols = np.mgrid[0:1201, 0:1201]
    path = directory / name
    (100 + rows + 2 * cols).astype(">i2").tofile(path)
    return path


def _scenario(tmp_path: Path, name: str = "s.yaml", **changes) -> Path:
    path = tmp_path / name
    path.write_text(yaml.safe_dump({**BASE, **changes}))
    return path


# ------------------------------------------------------------------ DEM far from the flight
def test_simulate_refuses_a_dem_tile_far_from_the_origin(tmp_path):
    _hgt(tmp_path, "N07E060.hgt")  # valid, but 5000 km from the origin: no terrain at all
    scenario = _scenario(tmp_path, terrain={"type": "file", "path": "N07E060.hgt"})
    result = _skyradar("simulate", str(scenario), "-o", "run.zarr", cwd=tmp_path)
    needles = ("s.yaml", "terrain", "N07E060.hgt", "lat 7..8, lon 60..61", "origin lat 52.5")
    _assert_one_line_error(result, *needles)
    assert not (tmp_path / "run.zarr").exists() and not (tmp_path / "run.zarr.partial").exists()


def test_scenario_refuses_a_dem_the_flight_leaves(tmp_path):
    # A small DEM whose north edge is 22 m north of the origin; own-ship flies north at 40 m/s.
    z = np.full((41, 41), 10.0)
    np.savez(tmp_path / "small.npz", elevation=z, dx=0.0005, dy=0.0005, xmin=4.35, ymax=52.5002)
    path = _scenario(tmp_path, terrain={"type": "file", "path": "small.npz"})
    message = r"s.yaml: field 'terrain': small.npz: the DEM covers .* at t = 0.6 s"
    with pytest.raises(InputError, match=message):
        load_scenario(path).build()


def test_scenario_reads_only_the_dem_window_it_needs(tmp_path):
    tile = _hgt(tmp_path, "N52E004.hgt")
    built = load_scenario(_scenario(tmp_path, terrain={"type": "file", "path": "N52E004.hgt"})).build()
    full = read_dem(tile)
    assert built.terrain.shape[0] * built.terrain.shape[1] < full.shape[0] * full.shape[1] / 100
    own = built.ownship.sample(built.times_s)
    lat = np.concatenate([own.lat_deg, own.lat_deg + 0.005, own.lat_deg - 0.005])  # 550 m either side
    lon = np.concatenate([own.lon_deg, own.lon_deg - 0.008, own.lon_deg + 0.008])
    np.testing.assert_allclose(built.terrain.height_at(lat, lon), full.height_at(lat, lon), atol=1e-3)


def test_an_undeclared_no_data_block_under_the_flight_of_a_large_npz_is_refused(tmp_path):
    # 0.03 % of the whole grid, under the fill limit, so it was filled as terrain without a word; it is
    # a large part of the window the flight sees, and the limit now applies to that window (as for
    # .hgt and .tif files).
    step, z = 0.0005, np.full((600, 600), 10.0)
    z[295:305, 295:305] = -9999.0  # 550 x 340 m under the origin
    corner = {"xmin": 4.36 - 300 * step, "ymax": 52.5 + 300 * step}
    np.savez(tmp_path / "big.npz", elevation=z, dx=step, dy=step, **corner)
    scenario = _scenario(tmp_path, terrain={"type": "file", "path": "big.npz"})
    result = _skyradar("simulate", str(scenario), "-o", "run.zarr", cwd=tmp_path)
    _assert_one_line_error(result, "s.yaml", "big.npz", "-9999", "above the fill limit", "does not declare")
    assert not any(tmp_path.glob("run.zarr*"))


def test_process_refuses_a_dem_far_from_the_runs_own_ship(tmp_path):
    built = Scenario.from_dict(BASE, source=tmp_path / "s.yaml").build()
    simulate_to_zarr(built, tmp_path / "run.zarr", chunk_frames=5)
    _hgt(tmp_path, "N07E060.hgt")
    args = ["process", "run.zarr", "-o", "det.parquet", "--terrain"]
    result = _skyradar(*args, "N07E060.hgt", cwd=tmp_path)
    _assert_one_line_error(result, "N07E060.hgt", "lat 7..8, lon 60..61", "run.zarr")
    assert not (tmp_path / "det.parquet").exists()
    # A tile under the flight is read only around it (in process, to keep the test fast).
    dem = dem_for_run(_hgt(tmp_path, "N52E004.hgt"), open_frames(tmp_path / "run.zarr"), 600.0, "run.zarr")
    assert dem.shape[0] < 100 and dem.shape[1] < 100


# ------------------------------------------------------------------ GeoTIFF window
def _write_tif(path: Path, z: np.ndarray, crs: str, tf: rasterio.Affine) -> None:
    with rasterio.open(
        path,
        "w",
        driver="GTiff",
        height=z.shape[0],
        width=z.shape[1],
        count=1,
        dtype=z.dtype,
        crs=crs,
        transform=tf,
        nodata=-9999.0,
    ) as ds:
        ds.write(z, 1)


@pytest.mark.parametrize("south_up", [False, True])
def test_geotiff_window_matches_the_whole_raster(tmp_path, south_up):
    rows, cols = np.mgrid[0:400, 0:500]
    z = (3.0 * rows + 0.5 * cols).astype(np.float32)  # row 0 north
    path = tmp_path / "big.tif"
    if south_up:
        _write_tif(path, z[::-1].copy(), "EPSG:4326", rasterio.Affine(0.01, 0, 4.0, 0, 0.01, 49.0))
    else:
        _write_tif(path, z, "EPSG:4326", rasterio.Affine(0.01, 0, 4.0, 0, -0.01, 53.0))
    full = read_geotiff(path)
    box = Bounds(51.0, 5.0, 51.2, 5.3)
    part = read_geotiff(path, bounds=box)
    assert part.shape[0] < 30 and part.shape[1] < 40  # of 400 x 500
    lat0, lon0 = part.lat_deg, part.lon_deg
    r0, c0 = (int(round(float(v))) for v in full.index_of(lat0, lon0))
    ny, nx = part.shape
    np.testing.assert_array_equal(part.elevation_m, full.elevation_m[r0 : r0 + ny, c0 : c0 + nx])
    b = part.bounds
    assert b.south_deg <= box.south_deg and b.north_deg >= box.north_deg
    assert b.west_deg <= box.west_deg and b.east_deg >= box.east_deg


def test_projected_geotiff_window_gives_the_same_heights(tmp_path):
    rows, cols = np.mgrid[0:300, 0:300]
    z = (rows * 0.5 + cols * 0.25).astype(np.float32)
    path = tmp_path / "utm.tif"
    _write_tif(path, z, "EPSG:32631", rasterio.Affine(20.0, 0, 700_000.0, 0, -20.0, 5_770_000.0))
    full = read_geotiff(path)
    c_lat, c_lon = full.center_latlon
    box = Bounds(c_lat - 0.004, c_lon - 0.004, c_lat + 0.004, c_lon + 0.004)
    part = read_geotiff(path, bounds=box)
    assert part.shape[0] * part.shape[1] < full.shape[0] * full.shape[1] / 10
    lat = np.linspace(box.south_deg, box.north_deg, 7)
    lon = np.linspace(box.west_deg, box.east_deg, 7)
    np.testing.assert_allclose(part.height_at(lat, lon), full.height_at(lat, lon), atol=0.01)


def test_geotiff_window_outside_the_raster_is_refused(tmp_path):
    path = tmp_path / "geo.tif"
    tf = rasterio.Affine(0.01, 0, 4.0, 0, -0.01, 53.0)
    _write_tif(path, np.zeros((20, 20), np.float32), "EPSG:4326", tf)
    with pytest.raises(InputError, match=r"geo.tif: the DEM covers lat 52.8.*outside the area"):
        read_geotiff(path, bounds=Bounds(7.0, 60.0, 7.1, 60.1))


# ------------------------------------------------------------------ tracks vs another run
@pytest.fixture(scope="module")
def two_runs(tmp_path_factory) -> Path:
    """run_a.zarr and run_b.zarr: the same frame times, own-ship flights 3.3 km apart (another origin)."""
    folder = tmp_path_factory.mktemp("runs")
    intruder = {"name": "A", "type": "encounter", "kind": "head-on", "t_cpa_s": 10, "rcs_m2": 10.0}
    for name, lat in (("run_a.zarr", 52.5), ("run_b.zarr", 52.53)):
        data = {**BASE, "origin": {**BASE["origin"], "lat_deg": lat}, "intruders": [intruder]}
        built = Scenario.from_dict(data, source=folder / "s.yaml").build()
        simulate_to_zarr(built, folder / name, chunk_frames=5)
    return folder


def _with_runs(tmp_path: Path, runs: Path) -> None:
    for name in ("run_a.zarr", "run_b.zarr"):
        (tmp_path / name).symlink_to(runs / name, target_is_directory=True)


@pytest.mark.slow
def test_alert_refuses_an_ownship_run_the_tracks_did_not_come_from(tmp_path, two_runs):
    _with_runs(tmp_path, two_runs)
    for args in (
        ["process", "run_a.zarr", "-o", "det.parquet"],
        ["track", "det.parquet", "-o", "trk.parquet"],
    ):
        result = _skyradar(*args, cwd=tmp_path)
        assert result.returncode == 0, result.stderr
    # Another run with the same frame times passes a check of the times alone; its origin differs.
    result = _skyradar("alert", "trk.parquet", "--ownship", "run_b.zarr", "-o", "al.parquet", cwd=tmp_path)
    _assert_one_line_error(result, "trk.parquet", "run_a.zarr", "run_b.zarr", "0..0.8 s", "origins differ")
    assert not (tmp_path / "al.parquet").exists()
    # evaluate's check names its run as the argument it is (evaluate has no --ownship).
    from skyradar.cli.commands_track import _check_tracks_of_run

    tracks = pd.read_parquet(tmp_path / "trk.parquet")
    with pytest.raises(InputError, match="but the run .*run_b.zarr is another run .* origins differ"):
        _check_tracks_of_run(tracks, tmp_path / "trk.parquet", tmp_path / "run_b.zarr")
    result = _skyradar("alert", "trk.parquet", "--ownship", "run_a.zarr", "-o", "al.parquet", cwd=tmp_path)
    assert result.returncode == 0, result.stderr


def test_alert_traces_tables_without_a_signature_back_to_their_run(tmp_path, two_runs):
    # Tables without a signature: tracks -> detections -> run through 'source'.
    _with_runs(tmp_path, two_runs)
    det = pd.DataFrame({"time_s": [0.0]})
    det.attrs["source"] = "run_a.zarr"
    det.to_parquet(tmp_path / "det.parquet")
    cols = ["time_s", "track_id", "north_m", "east_m", "down_m", "vn_mps", "ve_mps", "vd_mps"]
    trk = pd.DataFrame([[0.2, 1, 1000.0, 0.0, -300.0, -30.0, 0.0, 0.0]], columns=cols)
    trk.attrs["source"] = "det.parquet"
    trk.to_parquet(tmp_path / "trk.parquet")
    result = _skyradar("alert", "trk.parquet", "--ownship", "run_b.zarr", "-o", "al.parquet", cwd=tmp_path)
    _assert_one_line_error(result, "trk.parquet", "run_a.zarr", "run_b.zarr")
    result = _skyradar("alert", "trk.parquet", "--ownship", "run_a.zarr", "-o", "al.parquet", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
