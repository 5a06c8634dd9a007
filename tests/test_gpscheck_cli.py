"""`skyradar gpscheck` through the real entry point: bad input one line each, and a small end-to-end run.

The end-to-end run is a synthetic town (blocks of 12 m buildings, a street grid, grass) simulated by the
side-looking land-cover simulator; the map is the same town drawn as a map (buildings dark, streets
light) with a fifth of the blocks missing, written as a GeoTIFF in the run's local frame.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from cli_helpers import assert_one_line_error, skyradar
from skyradar.config import RadarConfig
from skyradar.io.frames import frames_dataset
from skyradar.scene.ground_grid import GroundGrid

ORIGIN = (60.17, 24.94)


def _ownship(n: int, north_m: float, east_m: float) -> dict[str, np.ndarray]:
    """Level flight north at 50 m/s, 200 m above flat ground."""
    state = {"own_north_m": north_m + 50.0 * np.arange(n), "own_east_m": np.full(n, east_m)}
    state |= {"own_down_m": np.full(n, -200.0), "own_height_agl_m": np.full(n, 200.0)}
    state |= {"own_vn_mps": np.full(n, 50.0), "own_ve_mps": np.zeros(n), "own_vd_mps": np.zeros(n)}
    state |= {f"own_{a}_rad": np.zeros(n) for a in ("yaw", "pitch", "roll")}
    return state


def _write_run(path, config: RadarConfig, iq: np.ndarray, north_m: float, east_m: float):
    n = iq.shape[0]
    attrs = {"origin_lat_deg": ORIGIN[0], "origin_lon_deg": ORIGIN[1], "origin_alt_m": 0.0}
    ds = frames_dataset(iq, np.arange(n, dtype=float), config, _ownship(n, north_m, east_m), attrs=attrs)
    ds.to_zarr(path, consolidated=False)
    return path


def _empty_run(path, config: RadarConfig, north_m: float = 0.0, east_m: float = 0.0, n: int = 2):
    iq = np.zeros((n, config.n_range, config.n_doppler, config.n_rx), np.complex64)
    return _write_run(path, config, iq, north_m, east_m)


def _town(grid: GroundGrid, rng: np.random.Generator):
    """(class code, building height, map image): blocks, streets 40-90 m apart (not periodic), grass."""
    code = np.full(grid.shape, 1, np.int8)  # grass
    height = np.zeros(grid.shape, np.float32)
    image = np.full(grid.shape, 0.78, np.float32)
    rows = np.cumsum(rng.integers(20, 45, grid.shape[0] // 20))
    cols = np.cumsum(rng.integers(20, 45, grid.shape[1] // 20))
    rows, cols = rows[rows < grid.shape[0]], cols[cols < grid.shape[1]]
    for r0 in rows:
        for c0 in cols:
            h, w = rng.integers(6, 20, 2)
            block = (slice(r0 + 5, r0 + 5 + h), slice(c0 + 5, c0 + 5 + w))
            code[block], height[block] = 6, 12.0
            if rng.random() > 0.2:  # the map misses a fifth of the buildings
                image[block] = 0.35
    for k in rows:
        code[k : k + 3, :], height[k : k + 3, :], image[k : k + 3, :] = 4, 0.0, 1.0
    for k in cols:
        code[:, k : k + 3], height[:, k : k + 3], image[:, k : k + 3] = 4, 0.0, 1.0
    return code, height, image


def _write_tif(path, grid: GroundGrid, image: np.ndarray):
    import rasterio

    from skyradar.scene.map_raster import local_crs

    profile = {
        "driver": "GTiff",
        "width": grid.shape[1],
        "height": grid.shape[0],
        "count": 1,
        "dtype": "float32",
        "crs": local_crs(*ORIGIN),
        "transform": grid.transform,
    }
    with rasterio.open(path, "w", **profile) as dst:
        dst.write(image, 1)
    return path


def test_forward_mount_is_one_line(tmp_path):
    run = _empty_run(tmp_path / "fwd.zarr", RadarConfig.prototype_2022())
    result = skyradar("gpscheck", str(run), "--map", "city.osm.pbf", "-o", "check.parquet", cwd=tmp_path)
    assert_one_line_error(result, "fwd.zarr", "looks forward", "side-looking")
    assert not (tmp_path / "check.parquet").exists()


def test_corrupt_osm_pbf_is_one_line(tmp_path):
    from skyradar.sim.land_cover_scene import ch6_radar_config

    run = _empty_run(tmp_path / "side.zarr", ch6_radar_config())
    (tmp_path / "bad.osm.pbf").write_bytes(b"\x00\x00\x00\x0dnot a protobuf block" * 20)
    result = skyradar("gpscheck", str(run), "--map", "bad.osm.pbf", "-o", "check.parquet", cwd=tmp_path)
    assert_one_line_error(result, "bad.osm.pbf")


def test_map_not_covering_the_footprint_is_one_line(tmp_path):
    from skyradar.sim.land_cover_scene import ch6_radar_config

    grid = GroundGrid.from_extent(-500.0, 500.0, -500.0, 500.0, pixel_m=10.0)
    _write_tif(tmp_path / "small.tif", grid, np.ones(grid.shape, np.float32))
    run = _empty_run(tmp_path / "far.zarr", ch6_radar_config(), north_m=5000.0)
    result = skyradar("gpscheck", str(run), "--map", "small.tif", "-o", "check.parquet", cwd=tmp_path)
    assert_one_line_error(result, "small.tif", "does not cover the radar footprint")


def test_map_without_finite_values_is_one_line(tmp_path):
    # An all-NaN map would leave every frame "no decision: too little structure"; the map is named.
    from skyradar.sim.land_cover_scene import ch6_radar_config

    grid = GroundGrid.from_extent(-1500.0, 1500.0, -1500.0, 1500.0, pixel_m=10.0)
    _write_tif(tmp_path / "empty.tif", grid, np.full(grid.shape, np.nan, np.float32))
    run = _empty_run(tmp_path / "side.zarr", ch6_radar_config())
    result = skyradar("gpscheck", str(run), "--map", "empty.tif", "-o", "check.parquet", cwd=tmp_path)
    assert_one_line_error(result, "empty.tif", "field 'band 1'", "no finite heights")
    assert not (tmp_path / "check.parquet").exists()


def test_map_without_data_under_the_flight_is_one_line(tmp_path):
    # Data in a corner, none under the flight: every frame was "no decision: too little structure".
    from skyradar.sim.land_cover_scene import ch6_radar_config

    grid = GroundGrid.from_extent(-1500.0, 1500.0, -1500.0, 1500.0, pixel_m=10.0)
    image = np.full(grid.shape, np.nan, np.float32)
    image[:40, :40] = np.random.default_rng(0).random((40, 40))
    _write_tif(tmp_path / "corner.tif", grid, image)
    run = _empty_run(tmp_path / "side.zarr", ch6_radar_config(), n=3)
    result = skyradar("gpscheck", str(run), "--map", "corner.tif", "-o", "check.parquet", cwd=tmp_path)
    assert_one_line_error(result, "corner.tif", "does not cover the flight", "all 3 frames", "its data lie")
    assert not (tmp_path / "check.parquet").exists()


@pytest.fixture(scope="module")
def town_run(tmp_path_factory):
    from skyradar.sim.geometry import PlatformState
    from skyradar.sim.land_cover_scene import LandCoverSimulator, ch6_radar_config

    folder = tmp_path_factory.mktemp("town")
    grid = GroundGrid.from_extent(-460.0, 360.0, 20.0, 480.0, pixel_m=2.0)  # the footprints, no more
    code, height, image = _town(grid, np.random.default_rng(0))
    config = ch6_radar_config()
    sim = LandCoverSimulator(config, code, height, grid, origin=(*ORIGIN, 0.0), seed=1)
    state = _ownship(2, -50.0, 0.0)
    iq = np.stack(
        [
            sim.frame(
                PlatformState(
                    np.array([state["own_north_m"][i], 0.0, -200.0]), np.array([50.0, 0, 0]), np.zeros(3)
                ),
                frame_index=i,
            )
            for i in range(2)
        ]
    )
    _write_tif(folder / "town.tif", grid, image)
    return _write_run(folder / "town.zarr", config, iq, -50.0, 0.0), folder / "town.tif"


@pytest.mark.slow  # about 22 CPU-seconds: two simulated frames and two gpscheck runs
def test_gpscheck_end_to_end_consistent_then_spoofed(town_run, tmp_path):
    run, tif = town_run
    common = ("gpscheck", str(run), "--map", str(tif), "--building-height-m", "12")
    result = skyradar(*common, "-o", "ok.parquet", "--json", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    table = pd.read_parquet(tmp_path / "ok.parquet")
    assert len(table) == 2 and set(table["verdict"]) == {"consistent"}, table.to_string()
    assert table["correction_m"].max() < 15.0 and not table["alert"].any()
    spoofed = skyradar(
        *common, "-o", "spoof.parquet", "--gps-offset-east-m", "80", "--alert-frames", "2", cwd=tmp_path
    )
    assert spoofed.returncode == 0, spoofed.stderr
    table = pd.read_parquet(tmp_path / "spoof.parquet")
    assert set(table["verdict"]) == {"inconsistent"}, table.to_string()
    # The correction undoes the spoof: about 80 m back west.
    assert np.all(np.abs(table["d_east_m"] + 80.0) < 15.0), table.to_string()
    assert table["alert"].tolist() == [False, True]
    assert "ALERT at frame 1 (t = 1.0 s): GPS inconsistent with the radar" in spoofed.stderr
