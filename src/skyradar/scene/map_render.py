"""The reference map a GPS check compares the radar with: drawn like a map, and out of date like one.

The radar's ground image is simulated from the land cover (:mod:`skyradar.scene.land_cover`); the map it
is compared with must not be that same input. :func:`render_reference_map` draws the layers the way a
printed map does, in grey levels (:data:`MAP_STYLE`): filled water, forest, grass and buildings, roads as
cased lines whose width grows with the class, railways as thin dark lines. :func:`outdated_map` first
drops and moves a share of the objects, as a real map differs from the ground a radar sees (buildings
built or demolished since the survey, digitising offsets of a few metres).

:func:`check_map_covers` is the one-line error when a radar footprint falls outside the map.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from skyradar.errors import InputError
from skyradar.extras import import_extra
from skyradar.scene.ground_grid import GroundGrid
from skyradar.scene.osm_map import ROAD_CLASSES, MapLayers

if TYPE_CHECKING:
    import geopandas as gpd

__all__ = ["MAP_STYLE", "MapStyle", "render_reference_map", "outdated_map", "check_map_covers"]


@dataclass(frozen=True)
class MapStyle:
    """Grey levels (0 black .. 1 white) and line widths of the cartographic rendering.

    Widths (``*_m``) are in m on the ground; every other field is a grey level.

    Examples
    --------
    A darker road fill and a 3 m casing either side of a 12 m road; 8 m off its centre line the
    casing shows, 10 m off the background:

    >>> import geopandas as gpd
    >>> from shapely.geometry import LineString
    >>> empty = gpd.GeoDataFrame(geometry=[])
    >>> road = gpd.GeoDataFrame({"road_class": ["primary"], "width_m": [12.0]},
    ...                         geometry=[LineString([(-50, 0), (50, 0)])])
    >>> layers = MapLayers(gpd.GeoDataFrame({"height_m": []}, geometry=[]), road, empty, empty, empty,
    ...                    empty, empty, 60.0, 25.0)
    >>> style = MapStyle(road_fill=0.8, road_casing_m=3.0)
    >>> image = render_reference_map(layers, GroundGrid.from_extent(-20, 20, -20, 20, pixel_m=1.0), style)
    >>> [round(float(v), 2) for v in image[[20, 28, 30], 20]]  # north 0.5, 8.5 and 10.5 m
    [0.8, 0.55, 0.93]
    """

    background: float = 0.93
    open_land: float = 0.88
    grass: float = 0.78
    forest: float = 0.62
    water: float = 0.45
    building: float = 0.35
    railway: float = 0.15
    railway_width_m: float = 2.0
    road_casing: float = 0.55
    road_casing_m: float = 1.0  # casing shows this much either side of the road fill
    road_fill: float = 1.0
    footway: float = 0.70


MAP_STYLE = MapStyle()


def _paint(image: np.ndarray, geometries: np.ndarray, value: float, grid: GroundGrid) -> None:
    shapes = [g for g in geometries if g is not None and not g.is_empty]
    if not shapes:
        return
    rasterize = import_extra("rasterio.features", "geo", "drawing a map").rasterize
    mask = rasterize(
        [(g, 1) for g in shapes], out_shape=grid.shape, transform=grid.transform, fill=0, dtype="uint8"
    )
    image[mask.astype(bool)] = value


def render_reference_map(
    layers: MapLayers, grid: GroundGrid, style: MapStyle = MAP_STYLE, supersample: int = 1
) -> np.ndarray:
    """A cartographic grey-level image of the map on a ground grid (float32, 0..1).

    ``supersample=n`` draws at ``pixel_m / n`` and averages n x n blocks: anti-aliased edges, and roads
    narrower than a pixel still show (as a paler line) instead of vanishing between pixel centres.
    Painting order: areas (open land, grass, forest, water), railways, road casings from the smallest
    class up, road fills, buildings on top.

    Examples
    --------
    >>> from skyradar.scene.ground_grid import GroundGrid
    >>> import geopandas as gpd
    >>> from shapely.geometry import LineString
    >>> empty = gpd.GeoDataFrame(geometry=[])
    >>> road = gpd.GeoDataFrame({"road_class": ["primary"], "width_m": [12.0]},
    ...                         geometry=[LineString([(-50, 0), (50, 0)])])
    >>> layers = MapLayers(gpd.GeoDataFrame({"height_m": []}, geometry=[]), road, empty, empty, empty,
    ...                    empty, empty, 60.0, 25.0)
    >>> image = render_reference_map(layers, GroundGrid.from_extent(-20, 20, -20, 20, pixel_m=1.0))
    >>> [float(v) for v in image[[20, 26, 35], 20]]  # road centre, its casing, the background
    [1.0, 0.55, 0.93]
    """
    if supersample > 1:
        n = int(supersample)
        fine = GroundGrid(
            grid.north0_m - grid.pixel_m / 2 + grid.pixel_m / (2 * n),
            grid.east0_m - grid.pixel_m / 2 + grid.pixel_m / (2 * n),
            grid.pixel_m / n,
            (n * grid.shape[0], n * grid.shape[1]),
        )
        image = render_reference_map(layers, fine, style)
        return image.reshape(grid.shape[0], n, grid.shape[1], n).mean(axis=(1, 3), dtype=np.float32)
    shapely = import_extra("shapely", "geo", "drawing a map")
    image = np.full(grid.shape, style.background, dtype=np.float32)
    for name in ("open_land", "grass", "forest", "water"):
        _paint(image, getattr(layers, name).geometry.to_numpy(), getattr(style, name), grid)
    rails = layers.railways.geometry.to_numpy()
    _paint(image, shapely.buffer(rails, style.railway_width_m / 2), style.railway, grid)
    roads = layers.roads
    lines, widths = roads.geometry.to_numpy(), roads["width_m"].to_numpy(dtype=float)
    classes = roads["road_class"].to_numpy(dtype=str)
    for stage in ("casing", "fill"):
        for name in reversed(ROAD_CLASSES):  # small roads first, so main roads are drawn over them
            pick = classes == name
            if name == "footway":
                if stage == "fill":
                    _paint(image, shapely.buffer(lines[pick], widths[pick] / 2), style.footway, grid)
                continue
            half = widths[pick] / 2 + (style.road_casing_m if stage == "casing" else 0.0)
            value = style.road_casing if stage == "casing" else style.road_fill
            _paint(image, shapely.buffer(lines[pick], half, cap_style="flat"), value, grid)
    _paint(image, layers.buildings.geometry.to_numpy(), style.building, grid)
    return image


def _drop(layer: gpd.GeoDataFrame, fraction: float, rng: np.random.Generator, what: str) -> gpd.GeoDataFrame:
    if not 0.0 <= fraction <= 1.0:
        raise InputError(f"outdated_map: {what} must be between 0 and 1, got {fraction!r}")
    n_drop = int(round(fraction * len(layer)))
    keep = np.ones(len(layer), dtype=bool)
    keep[rng.choice(len(layer), size=n_drop, replace=False)] = False
    return layer[keep].reset_index(drop=True)


def _jitter(layer: gpd.GeoDataFrame, jitter_m: float, rng: np.random.Generator) -> gpd.GeoDataFrame:
    if jitter_m == 0 or not len(layer):
        return layer
    gpd = import_extra("geopandas", "geo", "outdated_map")
    translate = import_extra("shapely.affinity", "geo", "outdated_map").translate
    shift = rng.normal(0.0, jitter_m, size=(len(layer), 2))
    moved = [translate(g, dx, dy) for g, (dx, dy) in zip(layer.geometry.to_numpy(), shift, strict=True)]
    out = layer.copy()
    out.geometry = gpd.GeoSeries(moved, index=layer.index)
    return out


def outdated_map(
    layers: MapLayers,
    rng: np.random.Generator,
    missing_building_fraction: float = 0.2,
    jitter_m: float = 3.0,
    missing_road_fraction: float = 0.0,
    missing_forest_fraction: float = 0.3,
) -> MapLayers:
    """The map as a survey some years old would draw it: objects missing, objects moved.

    Drops exactly ``round(fraction * n)`` buildings, road segments and forest features (lone trees
    are forest features and the most often missing ones), then moves every remaining building, road,
    railway and area by its own random offset, normal with ``jitter_m`` standard deviation per axis.

    Examples
    --------
    >>> import geopandas as gpd
    >>> from shapely.geometry import box
    >>> empty = gpd.GeoDataFrame(geometry=[])
    >>> houses = gpd.GeoDataFrame({"height_m": np.full(10, 9.0)},
    ...                           geometry=[box(10 * i, 0, 10 * i + 5, 5) for i in range(10)])
    >>> roads = gpd.GeoDataFrame({"road_class": [], "width_m": []}, geometry=[])
    >>> layers = MapLayers(houses, roads, empty, empty, empty, empty, empty, 60.0, 25.0)
    >>> len(outdated_map(layers, np.random.default_rng(0)).buildings)
    8
    """
    if not (np.isfinite(jitter_m) and jitter_m >= 0):
        raise InputError(f"outdated_map: jitter_m must be a non-negative distance, got {jitter_m!r}")
    buildings = _drop(layers.buildings, missing_building_fraction, rng, "missing_building_fraction")
    roads = _drop(layers.roads, missing_road_fraction, rng, "missing_road_fraction")
    forest = _drop(layers.forest, missing_forest_fraction, rng, "missing_forest_fraction")
    changed = {"buildings": buildings, "roads": roads, "forest": forest}
    for name in ("railways", "water", "grass", "open_land"):
        changed[name] = getattr(layers, name)
    return layers.with_layers(**{name: _jitter(layer, jitter_m, rng) for name, layer in changed.items()})


def check_map_covers(
    map_extent: MapLayers | GroundGrid,
    footprint_north_m: np.ndarray,
    footprint_east_m: np.ndarray,
    source: str | None = None,
    min_covered_fraction: float = 0.9,
) -> None:
    """Raise a one-line :class:`InputError` when the map does not cover the radar footprint.

    ``footprint_north_m``/``footprint_east_m`` are world points of the footprint (its corners, or
    every pixel of a pose grid); at least ``min_covered_fraction`` of them must lie on the map.

    Examples
    --------
    >>> grid = GroundGrid.from_extent(0.0, 1000.0, 0.0, 1000.0, pixel_m=10.0)
    >>> check_map_covers(grid, np.array([100.0, 900.0]), np.array([100.0, 900.0]), source="city.osm.pbf")
    >>> check_map_covers(grid, np.array([1500.0, 2500.0]), np.array([100.0, 900.0]), source="city.osm.pbf")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: city.osm.pbf: the map (north 0..1000 m, east 0..1000 m) does not cover the \
radar footprint (north 1500..2500 m, east 100..900 m): 0% of it is on the map, need 90%
    """
    if isinstance(map_extent, GroundGrid):
        east_min, east_max, north_min, north_max = map_extent.extent_m
    else:
        north_min, north_max, east_min, east_max = map_extent.bounds_m
        source = source or map_extent.source
    north = np.asarray(footprint_north_m, dtype=float).ravel()
    east = np.asarray(footprint_east_m, dtype=float).ravel()
    finite = np.isfinite(north) & np.isfinite(east)
    source = source or "map"
    if not finite.any():
        raise InputError(f"{source}: the radar footprint has no finite point to check against the map")
    north, east = north[finite], east[finite]
    inside = (north >= north_min) & (north <= north_max) & (east >= east_min) & (east <= east_max)
    if inside.mean() < min_covered_fraction:
        raise InputError(
            f"{source}: the map (north {north_min:.0f}..{north_max:.0f} m, east {east_min:.0f}.."
            f"{east_max:.0f} m) does not cover the radar footprint (north {north.min():.0f}.."
            f"{north.max():.0f} m, east {east.min():.0f}..{east.max():.0f} m):"
            f" {100 * inside.mean():.0f}% of it is on the map, need {100 * min_covered_fraction:.0f}%"
        )
