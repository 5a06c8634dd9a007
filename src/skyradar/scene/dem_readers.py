"""DEM readers: SRTM ``.hgt``, GeoTIFF, ``.npz``; void filling.

Every reader returns a :class:`~skyradar.scene.terrain.Terrain` with finite elevations. Voids
(SRTM's -32768, a GeoTIFF's nodata value, NaN) and infinities are filled from the surrounding
valid samples when they are at most ``max_void_fraction`` of the grid, and rejected with an
:class:`~skyradar.errors.InputError` otherwise. A height outside the land surface,
:data:`SURFACE_RANGE_M` (the Dead Sea shore to above Everest), is a void too: it is a no-data value
the file does not declare (downloads use -3.4e38, -9999 and 32767), and read as a height it would
put the radar thousands of kilometres above its ground and blind it.
"""

from __future__ import annotations

import logging
import re
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import spsolve

from skyradar.errors import InputError
from skyradar.extras import import_extra
from skyradar.geo import geodetic_to_ned
from skyradar.scene.terrain import Bounds, Terrain

__all__ = [
    "read_dem",
    "read_hgt",
    "read_geotiff",
    "read_npz",
    "jacksboro",
    "fill_voids",
    "SRTM_VOID",
    "SURFACE_RANGE_M",
]

SRTM_VOID = -32768
SURFACE_RANGE_M = (-500.0, 9000.0)  # every height of the Earth's land surface lies inside, m
_HGT_NAME = re.compile(r"^([NS])(\d{2})([EW])(\d{3})", re.IGNORECASE)
_log = logging.getLogger(__name__)


def fill_voids(
    elevation: np.ndarray,
    voids: np.ndarray,
    source: str,
    max_void_fraction: float = 0.01,
    undeclared: np.ndarray | None = None,
) -> np.ndarray:
    """Fill ``voids`` (bool mask) of ``elevation`` with the harmonic (Laplace) interpolant.

    Each void sample becomes the mean of its 4 in-grid neighbours, the valid ones fixed: one
    sparse linear solve over the void samples. Planes are reproduced exactly inside the grid;
    at the grid edge the fill has zero normal slope. Raises :class:`InputError` when the void
    fraction exceeds ``max_void_fraction``.

    Examples
    --------
    >>> z = np.arange(16.0).reshape(4, 4)
    >>> holes = np.zeros((4, 4), bool); holes[1, 2] = True
    >>> float(fill_voids(np.where(holes, np.nan, z), holes, "x.npz", 0.1)[1, 2])
    6.0
    """
    z = np.array(elevation, dtype=float)
    fraction = float(voids.mean())
    if fraction == 0.0:
        return z
    if voids.all():  # nothing to fill from: say so, not a void fraction
        first = z.flat[0]
        shown = "" if np.isnan(first) else f", first {first:.6g}"
        raise InputError(
            f"{source}: field 'elevation' holds no finite heights (every sample read is NaN, no-data or "
            f"outside the land surface{shown}); give a DEM with data"
        )
    if fraction > max_void_fraction:
        why = ""
        if undeclared is not None and undeclared.any():
            why = (
                f"; {int(undeclared.sum())} of them hold {z[undeclared][0]:.6g}, outside the land surface "
                f"[{SURFACE_RANGE_M[0]:g}, {SURFACE_RANGE_M[1]:g}] m: a no-data value the file does not "
                "declare (or sea-floor depths: the radar sees the sea surface, clip them to 0)"
            )
        raise InputError(
            f"{source}: {fraction * 100:.1f}% of samples are voids, above the fill limit "
            f"{max_void_fraction * 100:g}% (field elevation){why}"
        )
    ny, nx = z.shape
    rr, cc = np.nonzero(voids)
    index = np.full(z.shape, -1, np.intp)
    index[rr, cc] = np.arange(rr.size)
    diag, rhs = np.zeros(rr.size), np.zeros(rr.size)
    row_parts: list[np.ndarray] = []
    col_parts: list[np.ndarray] = []
    for dr, dc in ((-1, 0), (1, 0), (0, -1), (0, 1)):
        qr, qc = rr + dr, cc + dc
        ok = (qr >= 0) & (qr < ny) & (qc >= 0) & (qc < nx)
        diag += ok
        p, qr, qc = np.nonzero(ok)[0], qr[ok], qc[ok]
        q = index[qr, qc]
        known = q < 0
        np.add.at(rhs, p[known], z[qr[known], qc[known]])
        row_parts.append(p[~known])
        col_parts.append(q[~known])
    rows, cols = np.concatenate(row_parts), np.concatenate(col_parts)
    m = rr.size
    lap = sparse.csr_matrix((-np.ones(rows.size), (rows, cols)), shape=(m, m)) + sparse.diags(diag)
    z[rr, cc] = spsolve(lap.tocsc(), rhs)
    _log.info("%s: filled %d void samples (%.3f%%)", source, rr.size, fraction * 100)
    return z


def _void_mask(z: np.ndarray, nodata: float | None = None) -> np.ndarray:
    voids = ~np.isfinite(z) if np.issubdtype(z.dtype, np.floating) else np.zeros(z.shape, bool)
    if np.issubdtype(z.dtype, np.signedinteger) and z.dtype.itemsize >= 2:
        voids |= z == SRTM_VOID
    if nodata is not None and np.isfinite(nodata):
        voids |= z == nodata
    return voids


def _fill(z: np.ndarray, source: str, max_void_fraction: float, nodata: float | None = None) -> np.ndarray:
    declared = _void_mask(z, nodata)
    with np.errstate(invalid="ignore"):
        undeclared = ~declared & ((z < SURFACE_RANGE_M[0]) | (z > SURFACE_RANGE_M[1]))
    return fill_voids(z, declared | undeclared, source, max_void_fraction, undeclared)


def read_hgt(path: str | Path, max_void_fraction: float = 0.01, bounds: Bounds | None = None) -> Terrain:
    """Read an SRTM ``.hgt`` tile (1201x1201 or 3601x3601 big-endian int16).

    The file name gives the south-west corner (``N52E004.hgt``: 52 N, 4 E); row 0 is the
    north edge at lat + 1. Heights are taken as given (SRTM is relative to the EGM96 geoid).
    With ``bounds`` (south, west, north, east in degrees) only the samples inside them (plus one
    of margin) are read and void-filled; a box that misses the tile raises :class:`InputError`.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> folder = tempfile.TemporaryDirectory()
    >>> p = pathlib.Path(folder.name) / "N52E004.hgt"
    >>> np.full((1201, 1201), 7, ">i2").tofile(p)
    >>> read_hgt(p).bounds
    Bounds(south_deg=52.0, west_deg=4.0, north_deg=53.0, east_deg=5.0)
    >>> folder.cleanup()
    """
    path = Path(path)
    match = _HGT_NAME.match(path.name)
    if match is None:
        raise InputError(
            f"{path.name}: file name '{path.name}' does not give the tile corner (expected like N52E004.hgt)"
        )
    ns, lat, ew, lon = match.groups()
    lat_deg = int(lat) * (1 if ns.upper() == "N" else -1)
    lon_deg = int(lon) * (1 if ew.upper() == "E" else -1)
    if not (-90 <= lat_deg <= 89 and -180 <= lon_deg <= 179):
        raise InputError(
            f"{path.name}: tile corner lat {lat_deg}, lon {lon_deg} in the file name is out of range"
        )
    size = path.stat().st_size
    n = {1201 * 1201 * 2: 1201, 3601 * 3601 * 2: 3601}.get(size)
    if n is None:
        raise InputError(f"{path.name}: size {size} bytes is not a 1201x1201 or 3601x3601 int16 tile")
    step = 1.0 / (n - 1)
    north, west = lat_deg + 1.0, float(lon_deg)
    rows, cols = slice(0, n), slice(0, n)
    if bounds is not None:
        extent = Bounds(float(lat_deg), west, north, west + 1.0)
        rows = _index_span((north - bounds.north_deg) / step, (north - bounds.south_deg) / step, n)
        cols = _index_span((bounds.west_deg - west) / step, (bounds.east_deg - west) / step, n)
        _check_overlap(path.name, extent, bounds, rows, cols)
    raw = np.array(np.memmap(path, dtype=">i2", mode="r", shape=(n, n))[rows, cols])
    z = _fill(raw, path.name, max_void_fraction)
    lat0, lon0 = north - rows.start * step, west + cols.start * step
    return Terrain.geographic(z, lat0, lon0, step, step, source=path.name)


def _index_span(first: float, last: float, n: int) -> slice:
    """Sample indices from ``first`` to ``last`` (fractional) plus one of margin, clipped to [0, n)."""
    lo = int(np.clip(np.floor(min(first, last)) - 1, 0, n))
    hi = int(np.clip(np.ceil(max(first, last)) + 2, 0, n))
    return slice(lo, max(lo, hi))


def _check_overlap(name: str, extent: Bounds, bounds: Bounds, rows: slice, cols: slice) -> None:
    if rows.stop - rows.start < 2 or cols.stop - cols.start < 2:
        from skyradar.scene.dem_coverage import DemCoverageError

        raise DemCoverageError(
            f"{name}: the DEM covers lat {extent.south_deg:.6g}..{extent.north_deg:.6g}, lon "
            f"{extent.west_deg:.6g}..{extent.east_deg:.6g}, outside the area the flight needs "
            f"(lat {bounds.south_deg:.6g}..{bounds.north_deg:.6g}, "
            f"lon {bounds.west_deg:.6g}..{bounds.east_deg:.6g})"
        )


def read_geotiff(path: str | Path, max_void_fraction: float = 0.01, bounds: Bounds | None = None) -> Terrain:
    """Read band 1 of a GeoTIFF DEM with rasterio.

    With ``bounds`` (south, west, north, east in degrees, WGS84) only the window covering them
    (plus one pixel of margin) is read: a country-size DEM costs the memory of the flight's area.
    A box that misses the raster raises :class:`InputError`.

    A geographic CRS gives a geographic grid; a projected CRS gives a projected grid anchored
    at pixel [0, 0] (its centre transformed to WGS84 lat/lon), with the spacing scaled to ground
    metres and the grid's rotation from true north (meridian convergence) measured at the anchor.
    The nodata value and NaN are voids.

    Parameters
    ----------
    path : str or Path
        The GeoTIFF (needs the ``geo`` extra, rasterio).
    max_void_fraction : float
        Largest share of void samples that is filled; more raise :class:`InputError`.
    bounds : Bounds, optional
        (south, west, north, east), deg: read only the window covering them.

    Returns
    -------
    Terrain
        Row 0 north and column 0 west, whichever way the file stores them.

    Examples
    --------
    A 3 x 4 grid of 0.01 deg pixels whose north-west pixel centre is at 52.025 N, 4.005 E:

    >>> import tempfile, pathlib
    >>> import rasterio
    >>> z = np.arange(12.0, dtype="float32").reshape(3, 4)
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = pathlib.Path(d) / "dem.tif"
    ...     profile = {"driver": "GTiff", "height": 3, "width": 4, "count": 1, "dtype": "float32"}
    ...     transform = rasterio.Affine(0.01, 0.0, 4.0, 0.0, -0.01, 52.03)  # pixel edges
    ...     with rasterio.open(p, "w", crs="EPSG:4326", transform=transform, **profile) as dst:
    ...         dst.write(z, 1)
    ...     t = read_geotiff(p)
    >>> t.kind, [round(v, 6) for v in t.bounds]
    ('geographic', [52.005, 4.005, 52.025, 4.035])
    >>> float(t.height_at(52.025, 4.005)), float(t.height_at(52.005, 4.035))  # z[0, 0], z[2, 3]
    (0.0, 11.0)
    """
    path = Path(path)
    # The later rasterio imports of this module run only after this one succeeded.
    rasterio = import_extra("rasterio", "geo", f"{path.name}: reading a GeoTIFF")
    from rasterio.errors import RasterioError

    try:
        with rasterio.open(path) as ds:
            nodata, tf, crs = ds.nodata, ds.transform, ds.crs
            if crs is None:
                raise InputError(f"{path.name}: field 'crs' is missing; cannot place the grid on the earth")
            if tf.b != 0 or tf.d != 0:
                raise InputError(
                    f"{path.name}: field 'transform' is rotated or sheared ({tuple(tf)[:6]}); not supported"
                )
            window = None if bounds is None else _geotiff_window(ds, bounds, path.name)
            z = ds.read(1, window=window)
            tf = tf if window is None else ds.window_transform(window)
    except RasterioError as exc:
        raise InputError(f"{path.name}: cannot read GeoTIFF ({exc})") from exc
    z = _fill(z, path.name, max_void_fraction, nodata)
    if tf.e > 0:  # rows run south to north
        z, tf = z[::-1], tf @ rasterio.Affine.translation(0, z.shape[0]) @ rasterio.Affine.scale(1, -1)
    if tf.a < 0:  # columns run east to west
        z, tf = z[:, ::-1], tf @ rasterio.Affine.translation(z.shape[1], 0) @ rasterio.Affine.scale(-1, 1)
    x0, y0 = tf @ (0.5, 0.5)
    lat0, lon0 = _to_wgs84(crs, [x0], [y0])
    if crs.is_geographic:
        return Terrain.geographic(z, lat0[0], lon0[0], -tf.e, tf.a, source=path.name)
    unit_m = float(crs.linear_units_factor[1])
    reach = 1000.0 / unit_m  # 1 km along each grid axis, in CRS units
    lat, lon = _to_wgs84(crs, [x0, x0 + reach], [y0 + reach, y0])
    ned = geodetic_to_ned(np.array(lat), np.array(lon), 0.0, lat0[0], lon0[0], 0.0)
    up_m, right_m = np.hypot(ned[0, 0], ned[0, 1]), np.hypot(ned[1, 0], ned[1, 1])
    rotation = float(np.degrees(np.arctan2(ned[0, 1], ned[0, 0])))
    dy_m, dx_m = -tf.e * unit_m * up_m / 1000.0, tf.a * unit_m * right_m / 1000.0
    return Terrain.projected(z, lat0[0], lon0[0], dy_m, dx_m, rotation_deg=rotation, source=path.name)


def _geotiff_window(ds, bounds: Bounds, name: str):
    """Pixel window of ``ds`` covering the WGS84 box ``bounds`` (plus one pixel of margin)."""
    from rasterio.warp import transform_bounds
    from rasterio.windows import Window

    left, bottom, right, top = transform_bounds(
        "EPSG:4326",
        ds.crs,
        bounds.west_deg,
        bounds.south_deg,
        bounds.east_deg,
        bounds.north_deg,
        densify_pts=21,
    )
    inverse = ~ds.transform
    cols, rows = zip(*(inverse @ (x, y) for x in (left, right) for y in (bottom, top)), strict=True)
    rs = _index_span(min(rows) - 0.5, max(rows) - 0.5, ds.height)  # pixel centres at +0.5
    cs = _index_span(min(cols) - 0.5, max(cols) - 0.5, ds.width)
    full = ds.bounds
    lat, lon = _to_wgs84(ds.crs, [full.left, full.right], [full.bottom, full.top])
    _check_overlap(name, Bounds(min(lat), min(lon), max(lat), max(lon)), bounds, rs, cs)
    return Window(cs.start, rs.start, cs.stop - cs.start, rs.stop - rs.start)


def _to_wgs84(crs, xs: list[float], ys: list[float]) -> tuple[list[float], list[float]]:
    from rasterio.warp import transform

    lon, lat = transform(crs, "EPSG:4326", xs, ys)
    return list(lat), list(lon)


def _scalar(data: Mapping, key: str, source: str) -> float:
    try:
        value = float(np.asarray(data[key]))
    except (TypeError, ValueError) as exc:
        raise InputError(f"{source}: field '{key}' is not a number ({data[key]!r})") from exc
    if not np.isfinite(value):
        raise InputError(f"{source}: field '{key}' is not finite ({value})")
    return value


def terrain_from_arrays(
    data: Mapping, source: str, max_void_fraction: float = 0.01, bounds: Bounds | None = None
) -> Terrain:
    """Build a Terrain from an ``.npz``-style mapping (see :func:`read_npz` for the keys).

    With ``bounds`` only the samples covering them (plus one of margin) are kept, and the void limit
    applies to those: a no-data block under the flight is not diluted by the rest of a large grid.
    """
    keys = set(data.keys())
    if "elevation" not in keys:
        raise InputError(f"{source}: field 'elevation' is missing (have {sorted(keys)})")
    raw = np.asarray(data["elevation"])
    if raw.ndim != 2:
        raise InputError(f"{source}: field 'elevation' must be 2-D (shape {raw.shape})")
    nodata = _scalar(data, "nodata", source) if "nodata" in keys else None
    if bounds is None:
        return _npz_grid(data, keys, _fill(raw, source, max_void_fraction, nodata), source)
    # The grid's placement first (heights zero), to find the window; then the window's voids are filled.
    whole = _npz_grid(data, keys, np.zeros(raw.shape, np.float32), source)
    rows, cols = (
        np.asarray(v, float)
        for v in whole.index_of(
            np.array([bounds.south_deg, bounds.south_deg, bounds.north_deg, bounds.north_deg]),
            np.array([bounds.west_deg, bounds.east_deg, bounds.west_deg, bounds.east_deg]),
        )
    )
    rs = _index_span(rows.min(), rows.max(), raw.shape[0])
    cs = _index_span(cols.min(), cols.max(), raw.shape[1])
    _check_overlap(source, whole.bounds, bounds, rs, cs)
    window = whole.crop(rs, cs)
    return replace(window, elevation_m=_fill(raw[rs, cs], source, max_void_fraction, nodata))


def _npz_grid(data: Mapping, keys: set, z: np.ndarray, source: str) -> Terrain:
    """The Terrain of heights ``z`` placed as the ``.npz`` fields say."""
    if {"dx_m", "dy_m", "lat0_deg", "lon0_deg"} <= keys:
        rot = _scalar(data, "rotation_deg", source) if "rotation_deg" in keys else 0.0
        lat0, lon0, dy, dx = (_scalar(data, k, source) for k in ("lat0_deg", "lon0_deg", "dy_m", "dx_m"))
        return Terrain.projected(z, lat0, lon0, dy, dx, rotation_deg=rot, source=source)
    if {"dx", "dy", "xmin", "ymax"} <= keys:
        dx, dy = abs(_scalar(data, "dx", source)), abs(_scalar(data, "dy", source))
        west, north = _scalar(data, "xmin", source), _scalar(data, "ymax", source)
        ny, nx = z.shape
        if "ymin" in keys:  # the two y bounds may be swapped: north is the larger
            north = max(north, _scalar(data, "ymin", source))
            if abs(abs(_scalar(data, "ymin", source) - _scalar(data, "ymax", source)) - ny * dy) < 0.01 * dy:
                north -= dy / 2.0  # bounds are pixel edges (n * d wide): move to the sample centre
        if "xmax" in keys:
            west = min(west, _scalar(data, "xmax", source))
            if abs(abs(_scalar(data, "xmax", source) - _scalar(data, "xmin", source)) - nx * dx) < 0.01 * dx:
                west += dx / 2.0
        return Terrain.geographic(z, north, west, dy, dx, source=source)
    raise InputError(
        f"{source}: fields for the grid position are missing: need dx, dy, xmin, ymax (degrees) "
        f"or dx_m, dy_m, lat0_deg, lon0_deg (have {sorted(keys)})"
    )


def read_npz(path: str | Path, max_void_fraction: float = 0.01, bounds: Bounds | None = None) -> Terrain:
    """Read a DEM from ``.npz``.

    Keys: ``elevation`` (2-D, row 0 north) and either ``dx, dy, xmin, ymax`` in degrees
    (matplotlib's ``jacksboro_fault_dem.npz`` convention; with ``xmax``/``ymin`` also present
    and spanning n*d, the bounds are pixel edges; the larger of ``ymin``/``ymax`` is north) or
    ``dx_m, dy_m, lat0_deg, lon0_deg`` (+ optional ``rotation_deg``) for a projected grid
    anchored at sample [0, 0]. Optional ``nodata``. With ``bounds`` only the window covering them is
    kept (and void-filled), as :func:`read_hgt` and :func:`read_geotiff` read theirs.

    Parameters
    ----------
    path : str or Path
        The ``.npz`` file (no pickled objects).
    max_void_fraction : float
        Largest share of void samples that is filled; more raise :class:`InputError`.
    bounds : Bounds, optional
        (south, west, north, east), deg: keep only the window covering them.

    Returns
    -------
    Terrain

    Examples
    --------
    Sample centres 0.01 deg apart from 52.02 N, 4.0 E (north-west) to 52.0 N, 4.03 E (south-east);
    between samples the height is bilinear:

    >>> import tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = pathlib.Path(d) / "dem.npz"
    ...     np.savez(p, elevation=np.arange(12.0).reshape(3, 4), dx=0.01, dy=0.01, xmin=4.0, ymax=52.02)
    ...     t = read_npz(p)
    >>> t.bounds
    Bounds(south_deg=52.0, west_deg=4.0, north_deg=52.02, east_deg=4.03)
    >>> float(t.height_at(52.02, 4.0)), float(t.height_at(52.0, 4.03))  # corner samples
    (0.0, 11.0)
    >>> round(float(t.height_at(52.01, 4.015)), 6)  # halfway between z[1, 1] and z[1, 2]
    5.5
    """
    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {k: data[k] for k in data.files}
    except (OSError, ValueError) as exc:
        raise InputError(f"{path.name}: cannot read .npz ({exc})") from exc
    return terrain_from_arrays(arrays, path.name, max_void_fraction, bounds)


def jacksboro(max_void_fraction: float = 0.01) -> Terrain:
    """Matplotlib's sample DEM of the Jacksboro fault (Tennessee): 344 x 403, 3 arc-second.

    Examples
    --------
    >>> jacksboro().shape
    (344, 403)
    """
    from matplotlib import cbook

    data = cbook.get_sample_data("jacksboro_fault_dem.npz")
    assert isinstance(data, np.lib.npyio.NpzFile)  # an .npz sample loads as one
    arrays = {k: data[k] for k in data.files}
    return terrain_from_arrays(arrays, "jacksboro_fault_dem.npz", max_void_fraction)


_READERS = {".hgt": read_hgt, ".tif": read_geotiff, ".tiff": read_geotiff, ".npz": read_npz}


def read_dem(
    path: str | Path,
    max_void_fraction: float = 0.01,
    height_offset_m: float = 0.0,
    bounds: Bounds | None = None,
) -> Terrain:
    """Read a DEM by suffix: ``.hgt`` (SRTM), ``.tif``/``.tiff`` (GeoTIFF), ``.npz``.

    ``bounds`` (south, west, north, east, degrees): read only that area (an ``.npz`` file is
    loaded whole, then cut to it); see :func:`skyradar.scene.dem_coverage.footprint_bounds`.

    Voids up to ``max_void_fraction`` of the samples are filled; more raise InputError.
    ``height_offset_m`` is added to every elevation: Terrain heights are above the WGS84
    ellipsoid, while SRTM heights are above the EGM96 geoid, so pass the local geoid
    undulation there (about +45 m in the Netherlands) to match GPS altitudes.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> folder = tempfile.TemporaryDirectory()
    >>> p = pathlib.Path(folder.name) / "N52E005.hgt"
    >>> np.full((1201, 1201), 10, ">i2").tofile(p)
    >>> float(read_dem(p, height_offset_m=45.0).height_at(52.5, 5.5))
    55.0
    >>> folder.cleanup()
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such DEM file")
    reader = _READERS.get(path.suffix.lower())
    if reader is None:
        raise InputError(f"{path.name}: DEM format '{path.suffix}' not supported (use {', '.join(_READERS)})")
    if not 0.0 <= max_void_fraction <= 1.0:
        raise InputError(
            f"{path.name}: field 'max_void_fraction' must be within [0, 1] ({max_void_fraction})"
        )
    terrain = reader(path, max_void_fraction, bounds)
    if height_offset_m:
        terrain = replace(terrain, elevation_m=terrain.elevation_m + np.float32(height_offset_m))
    return terrain
