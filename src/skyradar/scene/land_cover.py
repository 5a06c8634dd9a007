"""Land-cover classes on a ground grid and their X-band backscatter.

Class codes (int8) used by the rasteriser, the radar ground-image simulator and the map renderer:

====  ===========  ======================================================
code  name         from the map layers
====  ===========  ======================================================
0     open         background and ``open_land`` (bare ground, yards, plazas)
1     grass        ``grass`` (lawns, parks, scrub, heath)
2     forest       ``forest`` (woods and lone tree crowns)
3     water        ``water``
4     road         ``roads``, buffered to their class width
5     rail         ``railways``, buffered to :data:`RAIL_WIDTH_M`
6     building     ``buildings``, with their height in the height raster
====  ===========  ======================================================

Backscatter model
-----------------
The normalised radar cross-section follows the constant-gamma model of the plateau region,
``sigma0 = gamma * sin(grazing)`` (Long 2001, eq. for land clutter; Richards, *Fundamentals of Radar
Signal Processing*, 2nd ed., sec. 2.7), with one ``gamma`` per class at X-band (9-10 GHz),
:data:`GAMMA_DB`. The values are rounded, representative figures from the published tables, not a fit:

- open ground -20 dB and grass/farmland -15 dB: Nathanson, Reilly & Cohen, *Radar Design Principles*,
  2nd ed. 1999 ("flatland" and "farmland" at 10 GHz); Barton, "Land clutter models for radar design and
  analysis", Proc. IEEE 73(2), 1985.
- forest -10 dB: Nathanson's "wooded hills" at 10 GHz; Ulaby & Dobson, *Handbook of Radar Scattering
  Statistics for Terrain*, 1989, tree canopies at X-band lie several dB above grass at mid incidence.
- water -40 dB: calm inland water, below Long's sea state 3 (*Radar Reflectivity of Land and Sea*, 3rd ed.
  2001); away from the specular direction water is the darkest surface in a radar image.
- road -25 dB: smooth asphalt, darker than grass at X-band (Ulaby & Dobson 1989, road surfaces).
- rail -10 dB: ballast plus steel rails and their corner reflections, bright lines in radar images.
- building -5 dB: above Long's "metropolitan" average (-10 dB at 10 GHz), which also averages the streets
  and shadows between buildings; wall-ground dihedrals make buildings the brightest returns (Billingsley,
  *Low-Angle Radar Land Clutter*, 2002, urban clutter is the strongest land class).

Shadow behind buildings, speckle and the antenna pattern are the image simulator's business, not this
table's. The model does not hold at near-normal incidence (grazing above about 70 deg) where specular
returns rise, nor at the lowest grazing angles (below about 1 deg) where Billingsley's data fall faster.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from skyradar.extras import import_extra
from skyradar.scene.ground_grid import GroundGrid
from skyradar.scene.osm_map import MapLayers

__all__ = [
    "CLASS_NAMES",
    "GAMMA_DB",
    "OPEN",
    "GRASS",
    "FOREST",
    "WATER",
    "ROAD",
    "RAIL",
    "BUILDING",
    "RAIL_WIDTH_M",
    "sigma0",
    "rasterise_land_cover",
]

OPEN, GRASS, FOREST, WATER, ROAD, RAIL, BUILDING = range(7)
CLASS_NAMES = ("open", "grass", "forest", "water", "road", "rail", "building")
# X-band constant-gamma reflectivity per class (dB), indexed by class code; sources in the module docstring.
GAMMA_DB = np.array([-20.0, -15.0, -10.0, -40.0, -25.0, -10.0, -5.0])
RAIL_WIDTH_M = 3.0  # one standard-gauge track with its ballast bed


def sigma0(class_code: np.ndarray | int, grazing_rad: np.ndarray | float) -> np.ndarray:
    """X-band normalised radar cross-section (m^2/m^2, linear) per class and grazing angle.

    Constant-gamma model ``gamma * sin(grazing)``; grazing angles at or below zero (shadow, or looking
    from below) give 0.

    Examples
    --------
    >>> round(float(10 * np.log10(sigma0(GRASS, np.pi / 2))), 1)
    -15.0
    >>> np.round(10 * np.log10(sigma0(np.array([BUILDING, WATER]), np.radians(30.0))), 1).tolist()
    [-8.0, -43.0]
    """
    gamma = 10.0 ** (GAMMA_DB[np.asarray(class_code, dtype=int)] / 10.0)
    return gamma * np.maximum(np.sin(grazing_rad), 0.0)


def _valid(geometry: Any) -> bool:
    return geometry is not None and not geometry.is_empty


def _shapes(geometries: np.ndarray, value: int) -> list[tuple[object, int]]:
    return [(g, value) for g in geometries if _valid(g)]


def land_cover_shapes(layers: MapLayers) -> list[tuple[object, int]]:
    """(geometry, class code) pairs in painting order: later shapes cover earlier ones."""
    shapely = import_extra("shapely", "geo", "rasterising a map")
    roads = shapely.buffer(layers.roads.geometry.to_numpy(), layers.roads["width_m"].to_numpy() / 2)
    rails = shapely.buffer(layers.railways.geometry.to_numpy(), RAIL_WIDTH_M / 2)
    return [
        *_shapes(layers.open_land.geometry.to_numpy(), OPEN),
        *_shapes(layers.grass.geometry.to_numpy(), GRASS),
        *_shapes(layers.forest.geometry.to_numpy(), FOREST),
        *_shapes(layers.water.geometry.to_numpy(), WATER),
        *_shapes(rails, RAIL),
        *_shapes(roads, ROAD),
        *_shapes(layers.buildings.geometry.to_numpy(), BUILDING),
    ]


def rasterise_land_cover(layers: MapLayers, grid: GroundGrid) -> tuple[np.ndarray, np.ndarray]:
    """Class codes and building heights on a ground grid.

    A pixel takes the class of the last shape covering its centre, in the order open land, grass,
    forest, water, railways, roads, buildings (so a building stands on whatever is below it and a road
    crosses a park). Roads are their lines buffered to half their class width each side, railways to
    :data:`RAIL_WIDTH_M`. Painting is rasterio's (GDAL) rasteriser, pixel-centre rule.

    Returns
    -------
    class_code : (rows, cols) int8
    height_m : (rows, cols) float32, building height where a building is, else 0.

    Examples
    --------
    >>> import geopandas as gpd
    >>> import geopandas as gpd
    >>> from shapely.geometry import box
    >>> empty = gpd.GeoDataFrame(geometry=[])
    >>> houses = gpd.GeoDataFrame({"height_m": [12.0]}, geometry=[box(0.0, 0.0, 4.0, 2.0)])
    >>> roads = gpd.GeoDataFrame({"road_class": [], "width_m": []}, geometry=[])
    >>> layers = MapLayers(houses, roads, empty, empty, empty, empty, empty, 60.0, 25.0)
    >>> code, height = rasterise_land_cover(layers, GroundGrid.from_extent(-2, 4, -2, 6, pixel_m=1.0))
    >>> int((code == BUILDING).sum()), float(height.max())
    (8, 12.0)
    """
    rasterize = import_extra("rasterio.features", "geo", "rasterising a map").rasterize
    kwargs = {"out_shape": grid.shape, "transform": grid.transform, "all_touched": False}
    shapes = land_cover_shapes(layers)
    code = np.zeros(grid.shape, dtype=np.uint8)
    if shapes:
        code = rasterize(shapes, fill=OPEN, dtype="uint8", **kwargs)
    height = np.zeros(grid.shape, dtype=np.float32)
    buildings = layers.buildings
    if len(buildings):
        heights = buildings["height_m"].to_numpy(dtype=float)
        pairs = [(g, h) for g, h in zip(buildings.geometry.to_numpy(), heights, strict=True) if _valid(g)]
        height = rasterize(pairs, fill=0.0, dtype="float32", **kwargs)
        # A building partly covered by a later, lower one keeps only the pixels the class raster gives it.
        height[code != BUILDING] = 0.0
    return code.astype(np.int8), height
