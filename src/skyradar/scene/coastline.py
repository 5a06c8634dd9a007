"""Sea polygons from OpenStreetMap coastline ways.

OpenStreetMap does not draw the sea as an area: it draws ``natural=coastline`` ways with the land on
their left and the water on their right, and leaves the sea outside every polygon. Inside an extract the
coastline ways cut the extract's box into faces; :func:`sea_polygons` polygonises them with shapely and
calls a face sea when more of the coastline has it on its right-hand side than on its left.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import shapely
from shapely.geometry import LineString, Polygon

__all__ = ["sea_polygons"]

_PROBE_M = 0.5  # how far beside the coastline the side probes sit
_SNAP_M = 50.0  # an open coastline end this close to the box edge is extended to it


def _extend_to_box(line: LineString, box: Polygon) -> LineString | None:
    """An open coastline clipped at the extract's edge, joined to the box boundary at both ends."""
    if line.is_closed:
        return line
    coords = list(line.coords)
    ring = box.exterior
    ends = []
    for end in (coords[0], coords[-1]):
        point = shapely.Point(end)
        if ring.distance(point) > _SNAP_M and box.contains(point):
            return None  # ends in the middle of the map: the data are incomplete, no side is known
        ends.append(ring.interpolate(ring.project(point)).coords[0])
    return LineString([ends[0], *coords, ends[1]])


def _side_probes(lines: list[LineString]) -> tuple[np.ndarray, np.ndarray]:
    """Points just right (water) and just left (land) of each coastline segment's midpoint."""
    rights, lefts = [], []
    for line in lines:
        xy = np.asarray(line.coords)
        d = np.diff(xy, axis=0)
        length = np.hypot(d[:, 0], d[:, 1])
        ok = length > 0
        mid = (xy[:-1] + xy[1:])[ok] / 2
        right = np.column_stack([d[ok, 1], -d[ok, 0]]) / length[ok, None]  # (x east, y north): turn clockwise
        rights.append(mid + _PROBE_M * right)
        lefts.append(mid - _PROBE_M * right)
    return np.concatenate(rights), np.concatenate(lefts)


def sea_polygons(coastlines: list[LineString] | np.ndarray, box: Polygon) -> list[Polygon]:
    """The sea inside ``box`` bounded by coastline ways (water on their right).

    Examples
    --------
    >>> from shapely.geometry import box
    >>> coast = LineString([(5.0, -1.0), (5.0, 11.0)])  # heading north: water to the east
    >>> [p.bounds for p in sea_polygons([coast], box(0.0, 0.0, 10.0, 10.0))]
    [(5.0, 0.0, 10.0, 10.0)]
    """
    lines = [shapely.intersection(line, box) for line in coastlines if line is not None and not line.is_empty]
    parts: list[Any] = []  # lines and the other geometries an intersection gives
    for line in lines:
        parts.extend(getattr(line, "geoms", [line]))
    parts = [p for p in parts if isinstance(p, LineString) and p.length > 0]
    extended = [e for e in (_extend_to_box(p, box) for p in parts) if e is not None]
    if not extended:
        return []
    noded = shapely.union_all([*extended, box.exterior])
    faces = list(shapely.polygonize(getattr(noded, "geoms", [noded])).geoms)
    rights, lefts = _side_probes(extended)
    sea = []
    for face in faces:
        water = shapely.contains_xy(face, rights[:, 0], rights[:, 1]).sum()
        land = shapely.contains_xy(face, lefts[:, 0], lefts[:, 1]).sum()
        if water > land:
            sea.append(face)
    return sea
