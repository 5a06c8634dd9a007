"""Terrain: a regular elevation grid (DEM) placed on the WGS84 ellipsoid.

A :class:`Terrain` is either

* a **geographic** grid: constant spacing in degrees of latitude and longitude (SRTM ``.hgt``,
  geographic GeoTIFF, matplotlib's Jacksboro sample), or
* a **projected** grid: constant spacing in metres in the horizontal plane tangent to the
  ellipsoid at an anchor (the geodetic position of sample ``[0, 0]``), optionally rotated
  (projected GeoTIFFs, synthetic terrain).

Row 0 is the north edge and column 0 the west edge (for a rotated projected grid: the grid's
"up" and "left" edges). Elevations are metres above the WGS84 ellipsoid, float32.

A projected sample's horizontal position is the point of the tangent plane at
``(north, east)`` projected along the local vertical onto the ellipsoid; its elevation is then
measured along that local vertical, so a flat projected terrain is a curved earth surface, as
in reality (the tangent plane itself would rise 2.8 m above the ground 6 km from the anchor).

Readers (:func:`read_dem`, :func:`jacksboro`) live in :mod:`skyradar.scene.dem_readers` and
synthetic surfaces (:func:`flat_terrain`, :func:`fractal_terrain`, :func:`roughness_map`) in
:mod:`skyradar.scene.synthetic_terrain`; both import :class:`Terrain` from here, never the other way
round.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, NamedTuple

import numpy as np

from skyradar.errors import InputError
from skyradar.geo import geodetic_to_ned, ned_to_geodetic

_WGS84_A_M = 6_378_137.0
_WGS84_E2 = 6.69437999014e-3

__all__ = ["Terrain", "Bounds", "metres_per_degree"]

# Index distance (grid cells) within which a position counts as on the edge: float rounding only.
_EDGE_TOL = 1e-9


class Bounds(NamedTuple):
    """Latitude/longitude extent of the sample centres, degrees.

    Examples
    --------
    >>> b = Bounds(south_deg=52.0, west_deg=4.0, north_deg=53.0, east_deg=5.0)
    >>> b.north_deg - b.south_deg, tuple(b)
    (1.0, (52.0, 4.0, 53.0, 5.0))
    >>> Terrain.geographic(np.zeros((3, 3)), 53.0, 4.0, 0.5, 0.5).bounds == b
    True
    """

    south_deg: float
    west_deg: float
    north_deg: float
    east_deg: float


def metres_per_degree(lat_deg: float) -> tuple[float, float]:
    """WGS84 ground distance of one degree of latitude and of longitude at ``lat_deg``, metres.

    Parameters
    ----------
    lat_deg : float
        Geodetic latitude, deg.

    Returns
    -------
    (float, float)
        Metres per degree of latitude (along the meridian) and of longitude (along the parallel).

    Examples
    --------
    At the equator a degree of longitude is the semi-major axis times pi / 180; a degree of
    latitude is shorter there (the meridian is flattest at the poles) and none of longitude at a
    pole:

    >>> [round(v, 2) for v in metres_per_degree(0.0)]
    [110574.28, 111319.49]
    >>> round(6_378_137.0 * np.pi / 180.0, 2)
    111319.49
    >>> [round(v, 2) for v in metres_per_degree(90.0)]
    [111693.98, 0.0]
    """
    s = np.sin(np.radians(lat_deg))
    w = 1.0 - _WGS84_E2 * s * s
    meridian = _WGS84_A_M * (1.0 - _WGS84_E2) / w**1.5
    prime_vertical = _WGS84_A_M / np.sqrt(w)
    return float(np.radians(meridian)), float(np.radians(prime_vertical) * np.cos(np.radians(lat_deg)))


@dataclass(frozen=True, eq=False)
class Terrain:
    """A DEM grid on the WGS84 ellipsoid.

    Parameters
    ----------
    elevation_m : ndarray, shape (ny, nx)
        Heights above the ellipsoid, metres (stored as read-only float32). Must be finite.
    lat_deg, lon_deg : float
        Geodetic position of sample ``[0, 0]`` (north-west corner sample), degrees.
    dy, dx : float
        Row and column spacing: degrees for ``kind='geographic'``, metres for ``'projected'``.
    kind : {'geographic', 'projected'}
        Grid type (see the module docstring).
    rotation_deg : float
        Projected grids only: bearing of the grid's "up" direction (decreasing row), degrees
        clockwise from true north (0 for a north-up grid; GeoTIFFs in UTM have a small
        meridian convergence).
    source : str
        File name (or a description) used in error messages.

    Examples
    --------
    >>> t = Terrain.projected(np.zeros((3, 4)), 52.0, 4.0, dy_m=30.0, dx_m=30.0)
    >>> t.shape, t.spacing_m
    ((3, 4), (30.0, 30.0))
    """

    elevation_m: np.ndarray
    lat_deg: float
    lon_deg: float
    dy: float
    dx: float
    kind: Literal["geographic", "projected"] = "geographic"
    rotation_deg: float = 0.0
    source: str = "<terrain>"

    def __post_init__(self) -> None:
        z = np.array(self.elevation_m, dtype=np.float32)
        where = f"{self.source}: field 'elevation'"
        if z.ndim != 2 or min(z.shape) < 2:
            raise InputError(f"{where} must be a 2-D grid of at least 2x2 samples (shape {z.shape})")
        bad = ~np.isfinite(z)
        if bad.any():
            r, c = np.argwhere(bad)[0]
            raise InputError(
                f"{where} has {int(bad.sum())} non-finite value(s), first {z[r, c]} at [{r}, {c}]"
            )
        if self.kind not in ("geographic", "projected"):
            raise InputError(
                f"{self.source}: field 'kind' must be 'geographic' or 'projected' ({self.kind!r})"
            )
        for name in ("dy", "dx"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise InputError(f"{self.source}: field '{name}' must be a positive spacing ({value})")
        if not (np.isfinite(self.lat_deg) and abs(self.lat_deg) <= 90.0):
            raise InputError(f"{self.source}: field 'lat_deg' must be within [-90, 90] ({self.lat_deg})")
        if not np.isfinite(self.lon_deg):
            raise InputError(f"{self.source}: field 'lon_deg' must be finite ({self.lon_deg})")
        z.setflags(write=False)
        object.__setattr__(self, "elevation_m", z)
        for name in ("lat_deg", "lon_deg", "dy", "dx", "rotation_deg"):
            object.__setattr__(self, name, float(getattr(self, name)))

    @classmethod
    def geographic(
        cls,
        elevation_m: np.ndarray,
        lat_deg: float,
        lon_deg: float,
        dlat_deg: float,
        dlon_deg: float,
        source: str = "<terrain>",
    ) -> Terrain:
        """Grid with spacing ``dlat_deg`` x ``dlon_deg``; ``lat_deg``/``lon_deg`` of sample [0, 0]."""
        return cls(elevation_m, lat_deg, lon_deg, dlat_deg, dlon_deg, "geographic", 0.0, source)

    @classmethod
    def projected(
        cls,
        elevation_m: np.ndarray,
        lat_deg: float,
        lon_deg: float,
        dy_m: float,
        dx_m: float,
        rotation_deg: float = 0.0,
        source: str = "<terrain>",
    ) -> Terrain:
        """Tangent-plane grid with spacing ``dy_m`` x ``dx_m`` anchored at sample [0, 0]."""
        return cls(elevation_m, lat_deg, lon_deg, dy_m, dx_m, "projected", rotation_deg, source)

    # ----------------------------------------------------------------- geometry
    @property
    def shape(self) -> tuple[int, int]:
        """(ny, nx)."""
        return self.elevation_m.shape

    @property
    def is_geographic(self) -> bool:
        return self.kind == "geographic"

    @property
    def spacing_m(self) -> tuple[float, float]:
        """Approximate ground spacing (dy_m, dx_m) at the grid centre, metres."""
        if not self.is_geographic:
            return self.dy, self.dx
        m_lat, m_lon = metres_per_degree(self.center_latlon[0])
        return self.dy * m_lat, self.dx * m_lon

    def _plane_ne(self, rows: np.ndarray, cols: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Tangent-plane (north, east) of fractional indices of a projected grid, metres."""
        up, right = -np.asarray(rows, float) * self.dy, np.asarray(cols, float) * self.dx
        r = np.radians(self.rotation_deg)
        return up * np.cos(r) - right * np.sin(r), up * np.sin(r) + right * np.cos(r)

    def latlon_of(self, rows: np.ndarray | float, cols: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
        """Geodetic (lat_deg, lon_deg) of fractional (row, col) indices (broadcast)."""
        rows, cols = np.asarray(rows, float), np.asarray(cols, float)
        if self.is_geographic:
            return self.lat_deg - rows * self.dy, self.lon_deg + cols * self.dx
        north, east = self._plane_ne(rows, cols)
        ned = np.stack(np.broadcast_arrays(north, east, np.zeros_like(north)), axis=-1)
        lat, lon, _ = ned_to_geodetic(ned, self.lat_deg, self.lon_deg, 0.0)
        return lat, lon

    def index_of(
        self, lat_deg: np.ndarray | float, lon_deg: np.ndarray | float
    ) -> tuple[np.ndarray, np.ndarray]:
        """Fractional (row, col) of geodetic positions (degrees); may lie outside the grid.

        Examples
        --------
        >>> t = Terrain.geographic(np.zeros((1201, 1201)), 53.0, 4.0, 1 / 1200, 1 / 1200)
        >>> [round(float(v), 6) for v in t.index_of(52.5, 4.25)]
        [600.0, 300.0]
        """
        lat, lon = np.asarray(lat_deg, float), np.asarray(lon_deg, float)
        if self.is_geographic:
            dlon = (lon - self.lon_deg + 180.0) % 360.0 - 180.0  # across the antimeridian
            return (self.lat_deg - lat) / self.dy, dlon / self.dx
        ned = geodetic_to_ned(lat, lon, 0.0, self.lat_deg, self.lon_deg, 0.0)
        r = np.radians(self.rotation_deg)
        up = ned[..., 0] * np.cos(r) + ned[..., 1] * np.sin(r)
        right = -ned[..., 0] * np.sin(r) + ned[..., 1] * np.cos(r)
        return -up / self.dy, right / self.dx

    def height_at(self, lat_deg: np.ndarray | float, lon_deg: np.ndarray | float) -> np.ndarray:
        """Bilinear elevation (metres) at geodetic positions; NaN outside the grid."""
        row, col = self.index_of(lat_deg, lon_deg)
        return self.height_at_index(row, col)

    def height_at_index(self, row: np.ndarray | float, col: np.ndarray | float) -> np.ndarray:
        """Bilinear elevation (metres) at fractional indices; NaN outside ``[0, n-1]``."""
        ny, nx = self.shape
        row, col = np.broadcast_arrays(np.asarray(row, float), np.asarray(col, float))
        # A position on the grid's edge comes back from index_of a few ulps outside it
        # (120.0000000000017): snap such rounding onto the edge instead of calling it outside.
        row = np.where(np.abs(row - np.clip(row, 0, ny - 1)) < _EDGE_TOL, np.clip(row, 0, ny - 1), row)
        col = np.where(np.abs(col - np.clip(col, 0, nx - 1)) < _EDGE_TOL, np.clip(col, 0, nx - 1), col)
        inside = (row >= 0) & (row <= ny - 1) & (col >= 0) & (col <= nx - 1)
        r0 = np.clip(np.floor(np.where(inside, row, 0.0)), 0, ny - 2).astype(np.intp)
        c0 = np.clip(np.floor(np.where(inside, col, 0.0)), 0, nx - 2).astype(np.intp)
        fr, fc = np.where(inside, row - r0, 0.0), np.where(inside, col - c0, 0.0)
        z = self.elevation_m
        top = z[r0, c0] * (1 - fc) + z[r0, c0 + 1] * fc
        bottom = z[r0 + 1, c0] * (1 - fc) + z[r0 + 1, c0 + 1] * fc
        return np.where(inside, top * (1 - fr) + bottom * fr, np.nan)

    @property
    def center_latlon(self) -> tuple[float, float]:
        """Geodetic (lat_deg, lon_deg) of the grid centre."""
        ny, nx = self.shape
        lat, lon = self.latlon_of((ny - 1) / 2.0, (nx - 1) / 2.0)
        return float(lat), float(lon)

    @property
    def bounds(self) -> Bounds:
        """Extent of the sample centres (south, west, north, east), degrees."""
        ny, nx = self.shape
        lat, lon = self.latlon_of(np.array([0, 0, ny - 1, ny - 1]), np.array([0, nx - 1, 0, nx - 1]))
        return Bounds(float(lat.min()), float(lon.min()), float(lat.max()), float(lon.max()))

    def points_ned(
        self, lat0_deg: float, lon0_deg: float, alt0_m: float = 0.0, flat_earth: bool = False
    ) -> np.ndarray:
        """NED position of every sample in the scenario frame at (lat0, lon0, alt0), metres.

        Returns float64 of shape (ny, nx, 3). Exact (pymap3d, WGS84) unless ``flat_earth``,
        the thesis' spherical mapping: at 5 km it is off by 2 m in "down" (curvature) and by
        about 0.1% of the distance horizontally (mean radius instead of WGS84, 5 m at 52 N).
        About 0.4 s for a 1201 x 1201 geographic tile, 2 s for a projected grid of that size.

        Examples
        --------
        >>> t = Terrain.projected(np.full((3, 3), 10.0), 52.0, 4.0, dy_m=100.0, dx_m=100.0)
        >>> np.round(t.points_ned(52.0, 4.0, 0.0)[2, 1], 2).tolist()
        [-200.0, 100.0, -10.0]
        """
        ny, nx = self.shape
        rows, cols = np.arange(ny, dtype=float)[:, None], np.arange(nx, dtype=float)[None, :]
        lat, lon = self.latlon_of(rows, cols)
        return geodetic_to_ned(
            lat, lon, self.elevation_m.astype(float), lat0_deg, lon0_deg, alt0_m, flat_earth
        )

    def crop_window(self, lat_deg: float, lon_deg: float, radius_m: float) -> tuple[slice, slice]:
        """(row_slice, col_slice) covering every sample within ``radius_m`` horizontally.

        The window is a superset (a rectangle around the circle, one sample of margin);
        empty slices when the circle misses the grid.
        """
        ny, nx = self.shape
        row, col = (float(v) for v in self.index_of(lat_deg, lon_deg))
        dy_m, dx_m = self.spacing_m  # a circle spans radius/dy rows whatever the grid rotation
        if self.is_geographic:
            # columns are narrowest at the latitude furthest from the equator inside the window
            extreme_lat = min(89.9, abs(lat_deg) + np.degrees(radius_m / 6.3e6))
            dy_m = metres_per_degree(lat_deg)[0] * self.dy
            dx_m = metres_per_degree(extreme_lat)[1] * self.dx
        half_r, half_c = radius_m / dy_m + 1.0, radius_m / dx_m + 1.0
        r0, r1 = int(np.clip(np.floor(row - half_r), 0, ny)), int(np.clip(np.ceil(row + half_r) + 1, 0, ny))
        c0, c1 = int(np.clip(np.floor(col - half_c), 0, nx)), int(np.clip(np.ceil(col + half_c) + 1, 0, nx))
        return slice(r0, max(r0, r1)), slice(c0, max(c0, c1))

    def crop(self, rows: slice, cols: slice) -> Terrain:
        """Sub-grid of an index window (same kind, anchored at its first sample).

        A projected grid's rotation is re-expressed at the new anchor, whose north differs
        from the old anchor's by the meridian convergence.
        """
        z = self.elevation_m[rows, cols]
        r0, c0 = rows.start or 0, cols.start or 0
        lat, lon = (float(v) for v in self.latlon_of(r0, c0))
        rotation = self.rotation_deg
        if not self.is_geographic:
            ahead_lat, ahead_lon = self.latlon_of(r0 - 1000.0 / self.dy, c0)
            ned = geodetic_to_ned(ahead_lat, ahead_lon, 0.0, lat, lon, 0.0)
            rotation = float(np.degrees(np.arctan2(ned[1], ned[0])))
        return Terrain(z, lat, lon, self.dy, self.dx, self.kind, rotation, self.source)
