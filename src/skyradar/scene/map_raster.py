"""A georeferenced raster map (GeoTIFF) as the reference image, resampled onto a ground grid.

Any CRS rasterio (GDAL/PROJ) knows works: the raster is warped onto the scenario's local frame with an
azimuthal equidistant projection centred on the geodetic origin. Within a few kilometres of the origin
that projection's (x, y) equals the local NED (east, north) to millimetres (the difference grows as
r^3 / R^2: 2 mm at 5 km), so a :class:`~skyradar.scene.ground_grid.GroundGrid` transform can serve as
the destination transform directly.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from skyradar.errors import InputError
from skyradar.extras import import_extra
from skyradar.geo import geodetic_to_ned
from skyradar.scene.ground_grid import GroundGrid

if TYPE_CHECKING:
    import rasterio
    from rasterio.crs import CRS

__all__ = ["MapRaster", "local_crs", "read_map_raster"]


@dataclass(frozen=True)
class MapRaster:
    """A reference image on a ground grid: ``image`` (float32, NaN where the file has no data).

    Attributes
    ----------
    image : ndarray of float32, shape ``grid.shape``
        The band's values on the grid's pixels.
    grid : GroundGrid
        The north/east pixel grid in the local frame of the origin.
    origin_lat_deg, origin_lon_deg : float
        Geodetic origin of the local frame, deg (WGS84).
    source : str
        The file, for messages.

    Examples
    --------
    >>> from skyradar.scene.ground_grid import GroundGrid
    >>> grid = GroundGrid.from_extent(-20.0, 20.0, -20.0, 20.0, pixel_m=10.0)
    >>> m = MapRaster(np.zeros(grid.shape, np.float32), grid, 52.0, 4.0, "map.tif")
    >>> m.image.shape == m.grid.shape, m.source
    (True, 'map.tif')
    """

    image: np.ndarray
    grid: GroundGrid
    origin_lat_deg: float
    origin_lon_deg: float
    source: str


def local_crs(origin_lat_deg: float, origin_lon_deg: float) -> CRS:
    """The CRS whose (x, y) in metres is the local (east, north) about a WGS84 origin.

    Parameters
    ----------
    origin_lat_deg, origin_lon_deg : float
        The origin, deg (WGS84).

    Returns
    -------
    rasterio.crs.CRS
        An azimuthal equidistant projection centred on the origin, in metres.

    Examples
    --------
    The origin is (0, 0), and 1000 m north is 1000 m of meridian arc, 0.008987 deg at 52 N:

    >>> from rasterio.warp import transform
    >>> lon, lat = transform(local_crs(52.0, 4.0), "EPSG:4326", [0.0, 0.0], [0.0, 1000.0])
    >>> [round(v, 6) for v in lon], [round(v, 6) for v in lat]
    ([4.0, 4.0], [52.0, 52.008987])
    """
    crs = import_extra("rasterio.crs", "geo", "reading a raster map")
    return crs.CRS.from_proj4(
        f"+proj=aeqd +lat_0={origin_lat_deg!r} +lon_0={origin_lon_deg!r} +datum=WGS84 +units=m"
    )


def _default_grid(src: rasterio.DatasetReader, lat0: float, lon0: float) -> GroundGrid:
    transform_bounds = import_extra("rasterio.warp", "geo", "reading a raster map").transform_bounds
    west, south, east, north = transform_bounds(src.crs, "EPSG:4326", *src.bounds, densify_pts=21)
    corners = geodetic_to_ned(np.array([south, north]), np.array([west, east]), 0.0, lat0, lon0)
    # Native resolution: the source pixel's ground size at the origin.
    width_m = corners[1, 1] - corners[0, 1]
    pixel_m = float(max(width_m / src.width, 0.01))
    return GroundGrid.from_extent(corners[0, 0], corners[1, 0], corners[0, 1], corners[1, 1], pixel_m)


def read_map_raster(
    path: str | Path,
    grid: GroundGrid | None = None,
    origin_lat_deg: float | None = None,
    origin_lon_deg: float | None = None,
    band: int = 1,
) -> MapRaster:
    """Read one band of a georeferenced raster and resample it (bilinear) onto a ground grid.

    Parameters
    ----------
    path : str or Path
        GeoTIFF (or any raster GDAL reads) with a CRS and a geotransform.
    grid : GroundGrid, optional
        The destination grid in the local frame; default the raster's extent at its native resolution.
    origin_lat_deg, origin_lon_deg : float, optional
        Geodetic origin of the local frame, deg; default the raster's centre.
    band : int
        1-based band number.

    Returns
    -------
    MapRaster
        The band on ``grid``, NaN where the raster has no data.

    Raises
    ------
    InputError
        One line naming the file: missing, unreadable, no georeference, no such band, or a band
        without one finite value.

    Examples
    --------
    A 3 x 4 raster of 0.01 deg pixels; at the origin, the centre of pixel [1, 1], the band's value
    comes back:

    >>> import tempfile, pathlib
    >>> import rasterio
    >>> z = np.arange(12.0, dtype="float32").reshape(3, 4)
    >>> grid = GroundGrid.from_extent(-150.0, 150.0, -150.0, 150.0, pixel_m=100.0)  # [1, 1] at (0, 0)
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = pathlib.Path(d) / "map.tif"
    ...     profile = {"driver": "GTiff", "height": 3, "width": 4, "count": 1, "dtype": "float32"}
    ...     transform = rasterio.Affine(0.01, 0.0, 4.0, 0.0, -0.01, 52.03)  # pixel edges
    ...     with rasterio.open(p, "w", crs="EPSG:4326", transform=transform, **profile) as dst:
    ...         dst.write(z, 1)
    ...     m = read_map_raster(p, grid, origin_lat_deg=52.015, origin_lon_deg=4.015)
    >>> m.image.shape, round(float(m.image[1, 1]), 3), (m.origin_lat_deg, m.origin_lon_deg)
    ((3, 3), 5.0, (52.015, 4.015))
    """
    path = Path(path)
    rasterio = import_extra("rasterio", "geo", f"reading {path}")
    warp = import_extra("rasterio.warp", "geo", f"reading {path}")
    if not path.is_file():
        raise InputError(f"{path}: map raster {'is not a file' if path.exists() else 'does not exist'}")
    try:
        with warnings.catch_warnings():
            # A raster without georeference is reported below as one InputError line, not a warning.
            warnings.simplefilter("ignore", rasterio.errors.NotGeoreferencedWarning)
            src = rasterio.open(path)
    except rasterio.errors.RasterioIOError as err:
        reason = " ".join(str(err).split())[:160]
        raise InputError(f"{path}: not a readable raster map ({reason})") from None
    with src:
        if src.crs is None or src.transform.is_identity:
            raise InputError(f"{path}: the raster map has no georeference (CRS and geotransform)")
        if not 1 <= band <= src.count:
            raise InputError(f"{path}: band {band} does not exist (the raster has {src.count})")
        if origin_lat_deg is None or origin_lon_deg is None:
            bounds = warp.transform_bounds(src.crs, "EPSG:4326", *src.bounds, densify_pts=21)
            west, south, east, north = bounds
            origin_lat_deg, origin_lon_deg = (south + north) / 2, (west + east) / 2
        grid = grid or _default_grid(src, origin_lat_deg, origin_lon_deg)
        image = np.full(grid.shape, np.nan, dtype=np.float32)
        warp.reproject(
            source=rasterio.band(src, band),
            destination=image,
            dst_transform=grid.transform,
            dst_crs=local_crs(origin_lat_deg, origin_lon_deg),
            dst_nodata=np.nan,
            resampling=warp.Resampling.bilinear,
        )
        if not np.isfinite(image).any() and not _has_finite_value(src, band):
            # Every pixel NaN or no-data: nothing to compare (each frame would be "too little structure").
            raise InputError(
                f"{path}: field 'band {band}' holds no finite heights or values (every pixel is NaN, "
                "infinite or no-data); give a map with data"
            )
    return MapRaster(image, grid, float(origin_lat_deg), float(origin_lon_deg), str(path))


def _has_finite_value(src: rasterio.DatasetReader, band: int) -> bool:
    """True when ``band`` holds a finite value that is not the no-data value; read block by block."""
    for _, window in src.block_windows(band):
        block = src.read(band, window=window, masked=True)
        values = block.compressed() if np.ma.isMaskedArray(block) else np.ravel(block)
        if np.isfinite(values).any():
            return True
    return False
