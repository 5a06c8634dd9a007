"""Terrain grids, DEM readers, synthetic terrain and roughness (skyradar.scene.terrain)."""

from __future__ import annotations

import numpy as np
import pymap3d
import pytest
import rasterio
from hypothesis import example, given, settings
from hypothesis import strategies as st
from rasterio.warp import transform as warp_transform

from skyradar.errors import InputError
from skyradar.geo import geodetic_to_ned
from skyradar.scene.dem_readers import jacksboro, read_dem
from skyradar.scene.synthetic_terrain import flat_terrain, fractal_terrain, local_height_sd, roughness_map
from skyradar.scene.terrain import Terrain

N = 1201
THESIS_SD_M = [19.2, 39.9, 63.6, 251.2, 345.0]


def _tile_values() -> np.ndarray:
    rows, cols = np.mgrid[0:N, 0:N]
    # 258 = bytes 01 02: endianness shows; 108-8658 m, inside the land surface's heights
    return (rows * 7 - cols // 8 + 258).astype(np.int16)


def _write_hgt(path, z) -> None:
    np.asarray(z, dtype=">i2").tofile(path)


def _horizontal_m(lat_a, lon_a, lat_b, lon_b) -> np.ndarray:
    ned = geodetic_to_ned(lat_b, lon_b, 0.0, lat_a, lon_a, 0.0)
    return np.hypot(ned[..., 0], ned[..., 1])


# ------------------------------------------------------------------ SRTM .hgt
def test_hgt_round_trip_values_corners_and_byte_order(tmp_path):
    z = _tile_values()
    path = tmp_path / "N52E004.hgt"
    _write_hgt(path, z)
    assert path.read_bytes()[:2] == b"\x01\x02"  # z[0, 0] = 258 stored big-endian
    t = read_dem(path)
    assert t.kind == "geographic" and t.shape == (N, N) and t.source == "N52E004.hgt"
    np.testing.assert_array_equal(t.elevation_m, z.astype(np.float32))
    assert t.bounds == (52.0, 4.0, 53.0, 5.0)
    assert t.lat_deg == 53.0 and t.lon_deg == 4.0  # row 0 is the north edge
    assert t.height_at(53.0, 4.0) == z[0, 0]
    assert t.height_at(52.0, 5.0) == z[-1, -1]
    assert t.height_at(52.0, 4.0) == z[-1, 0]
    assert t.spacing_m[0] == pytest.approx(92.6, abs=0.3)  # 3 arc-seconds of latitude
    shifted = read_dem(path, height_offset_m=45.0)  # e.g. the EGM96 geoid undulation in NL
    np.testing.assert_array_equal(shifted.elevation_m, z + np.float32(45.0))


def test_hgt_south_west_tile_name(tmp_path):
    path = tmp_path / "s34w071.hgt"
    _write_hgt(path, np.zeros((N, N)))
    assert read_dem(path).bounds == (-34.0, -71.0, -33.0, -70.0)


def test_hgt_wrong_size(tmp_path):
    path = tmp_path / "N52E004.hgt"
    path.write_bytes(b"\x00" * 100)
    with pytest.raises(
        InputError, match=r"^N52E004.hgt: size 100 bytes is not a 1201x1201 or 3601x3601 int16"
    ):
        read_dem(path)


@pytest.mark.parametrize("name", ["tile.hgt", "X52E004.hgt", "N95E004.hgt"])
def test_hgt_bad_name(tmp_path, name):
    path = tmp_path / name
    _write_hgt(path, np.zeros((N, N)))
    with pytest.raises(InputError, match=name):
        read_dem(path)


def test_void_fill_under_limit_restores_a_plane(tmp_path):
    rows, cols = np.mgrid[0:N, 0:N]
    plane = 2 * rows + 3 * cols + 100
    z = plane.copy()
    rng = np.random.default_rng(1)
    z[rng.integers(1, N - 1, 2000), rng.integers(1, N - 1, 2000)] = -32768  # scattered
    z[500:530, 600:640] = -32768  # one block
    z[0, 10:20] = -32768  # at the edge: nearest-neighbour fill
    assert (z == -32768).mean() < 0.01
    path = tmp_path / "N52E004.hgt"
    _write_hgt(path, z)
    t = read_dem(path)
    assert np.isfinite(t.elevation_m).all()
    inner = np.ones((N, N), bool)
    inner[0] = False
    np.testing.assert_allclose(t.elevation_m[inner], plane[inner], atol=1e-3)
    assert np.abs(t.elevation_m[0, 10:20] - plane[0, 10:20]).max() <= 3 * 5 + 1


def test_void_fill_above_limit_is_rejected(tmp_path):
    z = np.zeros(N * N, np.int16)
    z[: int(np.ceil(0.032 * N * N))] = -32768
    path = tmp_path / "N52E004.hgt"
    _write_hgt(path, z.reshape(N, N))
    expected = "N52E004.hgt: 3.2% of samples are voids, above the fill limit 1% (field elevation)"
    with pytest.raises(InputError) as err:
        read_dem(path)
    assert str(err.value) == expected
    assert read_dem(path, max_void_fraction=0.05).elevation_m.max() == 0.0


# ------------------------------------------------------------------ NaN / inf
def _npz(path, elevation, **extra):
    np.savez(path, elevation=elevation, dx=0.01, dy=0.01, xmin=4.0, ymax=53.0, **extra)
    return path


def test_nan_and_inf_are_filled_or_rejected(tmp_path):
    rows, cols = np.mgrid[0:50, 0:60]
    z = (rows + 2.0 * cols).astype(float)
    z[10, 10], z[20, 30] = np.nan, np.inf
    z[30, 40] = -np.inf
    path = _npz(tmp_path / "dem.npz", z)
    t = read_dem(path, max_void_fraction=0.01)
    assert np.isfinite(t.elevation_m).all()
    assert t.elevation_m[20, 30] == pytest.approx(20 + 60.0)
    with pytest.raises(InputError, match=r"^dem.npz: 0.1% of samples are voids, above the fill limit 0%"):
        read_dem(path, max_void_fraction=0.0)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_terrain_refuses_non_finite(bad):
    z = np.zeros((4, 4))
    z[2, 1] = bad
    with pytest.raises(
        InputError, match=r"my.dem: field 'elevation' has 1 non-finite value\(s\), first .* at \[2, 1\]"
    ):
        Terrain.geographic(z, 53.0, 4.0, 0.01, 0.01, source="my.dem")


def test_terrain_is_read_only():
    t = Terrain.geographic(np.zeros((3, 3)), 53.0, 4.0, 0.01, 0.01)
    with pytest.raises(ValueError):
        t.elevation_m[0, 0] = 1.0


def test_npz_errors(tmp_path):
    np.savez(tmp_path / "a.npz", height=np.zeros((3, 3)))
    with pytest.raises(InputError, match=r"a.npz: field 'elevation' is missing"):
        read_dem(tmp_path / "a.npz")
    np.savez(tmp_path / "b.npz", elevation=np.zeros((3, 3)), dx=0.1)
    with pytest.raises(InputError, match=r"b.npz: fields for the grid position are missing"):
        read_dem(tmp_path / "b.npz")
    (tmp_path / "c.dem").write_text("x")
    with pytest.raises(InputError, match=r"c.dem: DEM format '.dem' not supported"):
        read_dem(tmp_path / "c.dem")
    with pytest.raises(InputError, match="no such DEM file"):
        read_dem(tmp_path / "missing.hgt")


def test_npz_projected_keys(tmp_path):
    z = np.arange(12.0).reshape(3, 4)
    np.savez(tmp_path / "p.npz", elevation=z, dx_m=30.0, dy_m=20.0, lat0_deg=52.0, lon0_deg=4.0)
    t = read_dem(tmp_path / "p.npz")
    assert t.kind == "projected" and t.spacing_m == (20.0, 30.0)
    ned = t.points_ned(52.0, 4.0, 0.0)
    np.testing.assert_allclose(ned[2, 3], [-40.0, 90.0, -11.0], atol=1e-3)


# ------------------------------------------------------------------ Jacksboro
def test_jacksboro_loads():
    t = jacksboro()
    assert t.shape == (344, 403) and t.kind == "geographic"
    assert np.isfinite(t.elevation_m).all()
    assert (t.elevation_m.min(), t.elevation_m.max()) == (236.0, 1076.0)
    d = 1 / 1200  # pixel-edge bounds in the file: sample centres half a pixel inside
    south, west, north, east = t.bounds
    assert north == pytest.approx(36.73291666666667 - d / 2) and south == pytest.approx(36.44625 + d / 2)
    assert west == pytest.approx(-84.41375 + d / 2) and east == pytest.approx(-84.07791666666667 - d / 2)


# ------------------------------------------------------------------ GeoTIFF
def _write_tif(path, z, crs, tf, nodata=None):
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
        nodata=nodata,
    ) as ds:
        ds.write(z, 1)


def test_geotiff_geographic_round_trip(tmp_path):
    rows, cols = np.mgrid[0:40, 0:50]
    z = (rows * 10 + cols).astype(np.float32)
    z_voids = z.copy()
    z_voids[5, 5] = -9999.0
    path = tmp_path / "geo.tif"
    _write_tif(path, z_voids, "EPSG:4326", rasterio.Affine(0.01, 0.0, 4.0, 0.0, -0.02, 53.0), nodata=-9999.0)
    t = read_dem(path)
    assert t.kind == "geographic" and t.source == "geo.tif"
    np.testing.assert_allclose(t.elevation_m, z, atol=1e-3)  # nodata filled from a linear field
    assert (t.lat_deg, t.lon_deg, t.dy, t.dx) == pytest.approx((53.0 - 0.01, 4.0 + 0.005, 0.02, 0.01))
    # the same grid stored south-up must read identically
    flipped = tmp_path / "flipped.tif"
    tf = rasterio.Affine(0.01, 0.0, 4.0, 0.0, 0.02, 53.0 - 40 * 0.02)
    _write_tif(flipped, z[::-1].copy(), "EPSG:4326", tf)
    t2 = read_dem(flipped)
    np.testing.assert_array_equal(t2.elevation_m, z)
    assert (t2.lat_deg, t2.lon_deg) == pytest.approx((t.lat_deg, t.lon_deg))


def test_geotiff_projected_round_trip(tmp_path):
    # UTM 31N east of its central meridian: 2.3 deg meridian convergence that the reader must absorb
    rows, cols = np.mgrid[0:200, 0:300]
    z = (rows * 0.5 + cols * 0.25).astype(np.float32)
    tf = rasterio.Affine(20.0, 0.0, 700_000.0, 0.0, -25.0, 5_770_000.0)
    path = tmp_path / "utm.tif"
    _write_tif(path, z, "EPSG:32631", tf, nodata=-9999.0)
    t = read_dem(path)
    assert t.kind == "projected"
    np.testing.assert_array_equal(t.elevation_m, z)
    assert t.rotation_deg == pytest.approx(2.30, abs=0.05)
    r = np.array([0, 0, 199, 199, 100])
    c = np.array([0, 299, 0, 299, 150])
    xs, ys = tf @ (c + 0.5, r + 0.5)
    lon, lat = warp_transform("EPSG:32631", "EPSG:4326", list(xs), list(ys))
    lat_t, lon_t = t.latlon_of(r, c)
    assert _horizontal_m(np.array(lat), np.array(lon), lat_t, lon_t).max() < 0.5  # over 7.5 km x 5 km


# ------------------------------------------------------------------ geometry
def _geo_plane() -> Terrain:
    rows, cols = np.mgrid[0:121, 0:121]
    return Terrain.geographic(5.0 * rows - 2.0 * cols + 300.0, 52.05, 3.95, 1 / 1200, 1 / 1200)


def test_points_ned_matches_pymap3d_and_flat_earth_offset():
    t = _geo_plane()
    lat0, lon0, alt0 = 52.0, 4.0, 1000.0
    ned = t.points_ned(lat0, lon0, alt0)
    assert ned.shape == (121, 121, 3) and ned.dtype == np.float64
    for r, c in [(0, 0), (60, 60), (120, 7), (33, 120)]:
        lat, lon = t.lat_deg - r * t.dy, t.lon_deg + c * t.dx
        expected = pymap3d.geodetic2ned(lat, lon, t.elevation_m[r, c], lat0, lon0, alt0)
        np.testing.assert_allclose(ned[r, c], expected, atol=1e-6)
    flat = t.points_ned(lat0, lon0, alt0, flat_earth=True)
    dist = np.hypot(ned[..., 0], ned[..., 1])
    r, c = np.unravel_index(np.argmin(np.abs(dist - 5000.0)), dist.shape)
    curvature = dist[r, c] ** 2 / (2 * 6.371e6)  # the sphere drops 1.96 m below the plane at 5 km
    assert flat[r, c, 2] - ned[r, c, 2] == pytest.approx(-curvature, rel=0.05)
    # horizontally the sphere of mean radius is off by ~0.1% of the distance on WGS84 at 52 N (5 m at 5 km)
    assert np.linalg.norm(flat[r, c, :2] - ned[r, c, :2]) < 0.0015 * dist[r, c]


def test_projected_flat_terrain_curves_with_the_earth():
    t = flat_terrain(52.0, 4.0, height_m=10.0, size_m=12_000.0, spacing_m=30.0)
    assert t.center_latlon == pytest.approx((52.0, 4.0), abs=1e-7)
    ned = t.points_ned(52.0, 4.0, 500.0)
    np.testing.assert_allclose(ned[200, 200], [0.0, 0.0, 490.0], atol=0.01)
    dist = np.hypot(ned[..., 0], ned[..., 1])
    np.testing.assert_allclose(ned[..., 2], 490.0 + dist**2 / (2 * 6.38e6), atol=0.02)
    # grid columns run true north at the centre, spacing 30 m
    np.testing.assert_allclose(ned[199, 200, :2] - ned[200, 200, :2], [30.0, 0.0], atol=1e-3)
    np.testing.assert_allclose(ned[200, 201, :2] - ned[200, 200, :2], [0.0, 30.0], atol=1e-3)


@settings(max_examples=50, deadline=None)
@given(st.floats(0, 120), st.floats(0, 120))
@example(120.0, 0.0)  # index_of gives 120.0000000000017 here: the edge must not read as outside
def test_height_at_is_exact_on_a_plane(row, col):
    t = _geo_plane()
    lat, lon = t.lat_deg - row * t.dy, t.lon_deg + col * t.dx
    assert t.index_of(lat, lon) == pytest.approx((row, col), abs=1e-6)
    assert t.height_at(lat, lon) == pytest.approx(5.0 * row - 2.0 * col + 300.0, abs=1e-3)


def test_height_at_outside_is_nan():
    t = _geo_plane()
    h = t.height_at(np.array([53.0, 51.9, 52.0]), np.array([4.0, 4.0, 3.9]))
    assert np.isnan(h).all()


@settings(max_examples=30, deadline=None)
@given(st.floats(-3000, 3000), st.floats(-3000, 3000), st.floats(-20, 20))
def test_projected_index_round_trip(north_m, east_m, rotation_deg):
    t = Terrain.projected(np.zeros((5, 5)), 45.0, 7.0, dy_m=20.0, dx_m=30.0, rotation_deg=rotation_deg)
    r = np.radians(rotation_deg)
    row = -(north_m * np.cos(r) + east_m * np.sin(r)) / 20.0
    col = (-north_m * np.sin(r) + east_m * np.cos(r)) / 30.0
    lat, lon = t.latlon_of(row, col)
    ned = geodetic_to_ned(lat, lon, 0.0, 45.0, 7.0, 0.0)
    assert ned[:2] == pytest.approx([north_m, east_m], abs=0.01)
    assert t.index_of(lat, lon) == pytest.approx((row, col), abs=1e-4)  # tangent plane vs ellipsoid: mm


@pytest.mark.parametrize("terrain", [_geo_plane(), flat_terrain(52.0, 4.0, size_m=8000.0, spacing_m=40.0)])
def test_crop_window_covers_the_radius_and_crop_keeps_positions(terrain):
    lat, lon = terrain.latlon_of(70.0, 40.0)
    origin = (float(lat), float(lon), 0.0)
    ned = terrain.points_ned(*origin)
    within = np.hypot(ned[..., 0], ned[..., 1]) <= 2000.0
    rs, cs = terrain.crop_window(float(lat), float(lon), 2000.0)
    inside = np.zeros_like(within)
    inside[rs, cs] = True
    assert within.any() and not (within & ~inside).any()
    assert inside.sum() < 1.6 * within.sum()  # a tight rectangle around the circle, not the whole grid
    cropped = terrain.crop(rs, cs)
    np.testing.assert_allclose(cropped.points_ned(*origin), ned[rs, cs], atol=0.01)
    far_rows, far_cols = terrain.crop_window(0.0, 0.0, 2000.0)  # the circle misses the grid
    assert terrain.elevation_m[far_rows, far_cols].size == 0


# ------------------------------------------------------------------ roughness
@pytest.mark.parametrize(("a", "b"), [(0.0, 0.0), (0.1, 0.0), (0.0, -0.05), (0.2, 0.3)])
def test_roughness_of_a_plane_is_closed_form(a, b):
    dy, dx = 25.0, 20.0
    rows, cols = np.mgrid[0:130, 0:95]
    z = a * (-rows * dy) + b * (cols * dx)  # height = a * north + b * east
    t = Terrain.projected(z, 52.0, 4.0, dy_m=dy, dx_m=dx)
    rough = roughness_map(t)
    cy, cx = rough.attrs["cell_rows"], rough.attrs["cell_cols"]
    assert (cy, cx) == (40, 30) and rough.shape == (130 // 40, 95 // 30)
    expected = np.sqrt(a**2 * dy**2 * (cy**2 - 1) / 12 + b**2 * dx**2 * (cx**2 - 1) / 12)
    np.testing.assert_allclose(rough.values, expected, atol=1e-3)
    assert local_height_sd(t) == pytest.approx(expected, abs=1e-3)
    np.testing.assert_allclose(rough["row"].values, [19.5, 59.5, 99.5])


def test_roughness_geographic_uses_metric_cells():
    t = jacksboro()  # 92.5 m x 74.6 m spacing -> 11 x 8 samples per 1 km x 0.6 km cell
    rough = roughness_map(t)
    assert (rough.attrs["cell_rows"], rough.attrs["cell_cols"]) == (11, 8)
    assert rough.shape == (344 // 11, 403 // 8)
    z = t.elevation_m.astype(float)
    assert rough.values[3, 5] == pytest.approx(z[33:44, 40:48].std(), rel=1e-9)
    assert float(rough["lat_deg"][0, 0]) == pytest.approx(t.lat_deg - 5 * t.dy)


def test_roughness_of_flat_is_zero():
    assert local_height_sd(flat_terrain(52.0, 4.0, height_m=123.0)) == 0.0


def _independent_median_cell_sd(t: Terrain, cell_m=(1000.0, 600.0)) -> float:
    dy, dx = t.spacing_m
    cy, cx = round(cell_m[0] / dy), round(cell_m[1] / dx)
    z = t.elevation_m.astype(float)
    sds = [
        np.std(z[i : i + cy, j : j + cx])
        for i in range(0, z.shape[0] - cy + 1, cy)
        for j in range(0, z.shape[1] - cx + 1, cx)
    ]
    return float(np.median(sds))


@pytest.mark.parametrize("sd_m", THESIS_SD_M)
def test_fractal_terrain_hits_requested_roughness(sd_m):
    t = fractal_terrain(46.5, 6.0, local_sd_m=sd_m, seed=7, mean_height_m=800.0)
    assert _independent_median_cell_sd(t) == pytest.approx(sd_m, rel=0.05)
    assert t.elevation_m.mean() == pytest.approx(800.0, abs=0.5)
    assert t.center_latlon == pytest.approx((46.5, 6.0), abs=1e-7)


@settings(max_examples=10, deadline=None)
@given(st.floats(1.0, 500.0), st.integers(0, 2**31), st.floats(0.5, 1.0))
def test_fractal_roughness_property(sd_m, seed, hurst):
    t = fractal_terrain(52.0, 4.0, local_sd_m=sd_m, size_m=4000.0, spacing_m=40.0, seed=seed, hurst=hurst)
    assert _independent_median_cell_sd(t) == pytest.approx(sd_m, rel=0.05)


def test_fractal_terrain_is_reproducible_per_seed():
    a = fractal_terrain(52.0, 4.0, 40.0, size_m=6000.0, seed=3)
    b = fractal_terrain(52.0, 4.0, 40.0, size_m=6000.0, seed=3)
    c = fractal_terrain(52.0, 4.0, 40.0, size_m=6000.0, seed=4)
    np.testing.assert_array_equal(a.elevation_m, b.elevation_m)
    assert np.abs(a.elevation_m - c.elevation_m).max() > 10.0


def test_fractal_terrain_bad_input():
    with pytest.raises(InputError, match="local_sd_m"):
        fractal_terrain(52.0, 4.0, -1.0)
    with pytest.raises(InputError, match="hurst"):
        fractal_terrain(52.0, 4.0, 10.0, hurst=1.5)
    with pytest.raises(InputError, match="smaller than one roughness cell"):
        fractal_terrain(52.0, 4.0, 10.0, size_m=300.0)
