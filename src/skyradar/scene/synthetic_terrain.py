"""Synthetic terrain (flat, fractal) and the local-roughness measure of ch5.

Roughness is the standard deviation of height over cells of about 1 km (north-south, along
the grid's rows) by 0.6 km (east-west, along its columns), the measure the thesis used to rank
its terrains (local height SD 19.2, 39.9, 63.6, 251.2 and 345.0 m). :func:`fractal_terrain`
makes a seeded power-law (fractional Brownian) surface whose *median* cell SD equals the
requested value.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from skyradar.errors import InputError
from skyradar.geo import geodetic_to_ned, ned_to_geodetic
from skyradar.scene.terrain import Terrain

__all__ = ["flat_terrain", "fractal_terrain", "roughness_map", "local_height_sd", "centred_grid"]

DEFAULT_CELL_M = (1000.0, 600.0)


def centred_grid(
    elevation_m: np.ndarray, lat0_deg: float, lon0_deg: float, spacing_m: float, source: str
) -> Terrain:
    """Projected terrain with its centre sample at (lat0, lon0) and its columns along true north there.

    The anchor (sample [0, 0]) sits north-west of the centre; its grid rotation absorbs the
    meridian convergence between anchor and centre, so the grid is north-up at the centre.

    Parameters
    ----------
    elevation_m : ndarray, shape (ny, nx)
        Heights above the WGS84 ellipsoid, m; row 0 north.
    lat0_deg, lon0_deg : float
        Geodetic position of the centre, deg.
    spacing_m : float
        Sample spacing along both axes, m.
    source : str
        Names the terrain in messages.

    Returns
    -------
    Terrain
        A projected grid.

    Examples
    --------
    5 x 7 samples 100 m apart: the anchor is 200 m north and 300 m west of the centre, and the
    centre sample [2, 3] lies on (lat0, lon0):

    >>> t = centred_grid(np.zeros((5, 7)), 60.0, 10.0, 100.0, "flat")
    >>> t.kind, t.shape, [round(v, 9) for v in t.center_latlon]
    ('projected', (5, 7), [60.0, 10.0])
    >>> ned = t.points_ned(60.0, 10.0, 0.0)
    >>> np.round(ned[0, 0, :2], 2).tolist(), bool(np.allclose(ned[2, 3], 0.0, atol=1e-6))
    ([200.0, -300.0], True)
    """
    ny, nx = np.shape(elevation_m)
    half_n, half_e = (ny - 1) / 2.0 * spacing_m, (nx - 1) / 2.0 * spacing_m
    ned = np.array([[half_n, -half_e, 0.0], [half_n + 1000.0, -half_e, 0.0]])
    lat, lon, _ = ned_to_geodetic(ned, lat0_deg, lon0_deg, 0.0)
    ahead = geodetic_to_ned(lat[1], lon[1], 0.0, lat[0], lon[0], 0.0)
    rotation = float(np.degrees(np.arctan2(ahead[1], ahead[0])))
    return Terrain.projected(
        elevation_m, float(lat[0]), float(lon[0]), spacing_m, spacing_m, rotation_deg=rotation, source=source
    )


def _grid_size(size_m: float, spacing_m: float) -> int:
    if not (spacing_m > 0 and size_m >= 2 * spacing_m):
        raise InputError(
            f"synthetic terrain: field 'size_m' ({size_m}) must be >= 2 x 'spacing_m' ({spacing_m}) > 0"
        )
    return int(round(size_m / spacing_m)) + 1


def flat_terrain(
    lat0_deg: float, lon0_deg: float, height_m: float = 0.0, size_m: float = 12_000.0, spacing_m: float = 30.0
) -> Terrain:
    """Flat terrain at ``height_m`` (metres above the ellipsoid), ``size_m`` square, centred on lat0/lon0.

    Examples
    --------
    >>> t = flat_terrain(52.0, 4.0, height_m=5.0, size_m=600.0, spacing_m=30.0)
    >>> t.shape, [round(v, 6) for v in t.center_latlon]
    ((21, 21), [52.0, 4.0])
    """
    n = _grid_size(size_m, spacing_m)
    return centred_grid(np.full((n, n), height_m, np.float32), lat0_deg, lon0_deg, spacing_m, "flat terrain")


def fractal_terrain(
    lat0_deg: float,
    lon0_deg: float,
    local_sd_m: float,
    size_m: float = 12_000.0,
    spacing_m: float = 30.0,
    seed: int = 0,
    mean_height_m: float = 0.0,
    hurst: float = 0.8,
    cell_m: tuple[float, float] = DEFAULT_CELL_M,
) -> Terrain:
    """Seeded fractal (fBm) terrain whose median local height SD is ``local_sd_m``.

    White Gaussian noise is shaped in the 2-D Fourier domain by amplitude ``k**-(hurst + 1)``
    (power spectrum ``k**-(2 hurst + 2)``, fractal dimension ``3 - hurst``; natural terrain has
    hurst about 0.7-0.9), then scaled so that the **median** over cells of
    :func:`roughness_map` equals ``local_sd_m`` (exactly, up to float32 rounding), and shifted to
    mean ``mean_height_m``. The surface is periodic across its edges. Same seed, same terrain.

    Examples
    --------
    >>> t = fractal_terrain(52.0, 4.0, local_sd_m=40.0, size_m=6000.0, seed=1)
    >>> round(local_height_sd(t), 1)
    40.0
    """
    if not (np.isfinite(local_sd_m) and local_sd_m >= 0):
        raise InputError(f"fractal terrain: field 'local_sd_m' must be >= 0 ({local_sd_m})")
    if not 0.0 < hurst <= 1.0:
        raise InputError(f"fractal terrain: field 'hurst' must be within (0, 1] ({hurst})")
    n = _grid_size(size_m, spacing_m)
    rng = np.random.default_rng(seed)
    spectrum = np.fft.fft2(rng.standard_normal((n, n)))
    k = np.hypot(*np.meshgrid(np.fft.fftfreq(n, spacing_m), np.fft.fftfreq(n, spacing_m), indexing="ij"))
    k[0, 0] = np.inf  # no mean component
    surface = np.fft.ifft2(spectrum * k ** -(hurst + 1.0)).real
    unit = centred_grid(surface.astype(np.float32), lat0_deg, lon0_deg, spacing_m, "fractal terrain")
    scale = local_sd_m / local_height_sd(unit, cell_m)
    z = surface * scale
    z += mean_height_m - z.mean()
    return centred_grid(z.astype(np.float32), lat0_deg, lon0_deg, spacing_m, f"fractal terrain (seed {seed})")


def _cell_shape(terrain: Terrain, cell_m: tuple[float, float]) -> tuple[int, int]:
    dy_m, dx_m = terrain.spacing_m
    cy, cx = max(2, int(round(cell_m[0] / dy_m))), max(2, int(round(cell_m[1] / dx_m)))
    ny, nx = terrain.shape
    if cy > ny or cx > nx:
        raise InputError(
            f"{terrain.source}: field 'elevation' grid {ny}x{nx} is smaller than one roughness cell "
            f"({cy}x{cx} samples for {cell_m[0]:g} m x {cell_m[1]:g} m)"
        )
    return cy, cx


def roughness_map(terrain: Terrain, cell_m: tuple[float, float] = DEFAULT_CELL_M) -> xr.DataArray:
    """Standard deviation of height (metres, population SD) over non-overlapping cells.

    Each cell spans ``cell_m[0]`` metres along the grid's rows (north-south) by ``cell_m[1]``
    along its columns (east-west), rounded to whole samples at the metric spacing of the grid
    centre (``terrain.spacing_m``; for geographic grids that is the centre latitude's spacing).
    Samples left over at the south and east edges are not used.

    Returns a DataArray with dims ``(cell_row, cell_col)``, coords ``row``/``col`` (fractional
    sample index of each cell centre) and ``lat_deg``/``lon_deg`` (2-D, cell centres), and
    attrs ``cell_rows``, ``cell_cols``, ``cell_dy_m``, ``cell_dx_m`` (actual cell size).

    Examples
    --------
    >>> roughness_map(flat_terrain(52.0, 4.0, size_m=3000.0)).values.max()
    np.float64(0.0)
    """
    cy, cx = _cell_shape(terrain, cell_m)
    ny, nx = terrain.shape
    nby, nbx = ny // cy, nx // cx
    blocks = terrain.elevation_m[: nby * cy, : nbx * cx].astype(float).reshape(nby, cy, nbx, cx)
    sd = blocks.std(axis=(1, 3))
    rows = np.arange(nby) * cy + (cy - 1) / 2.0
    cols = np.arange(nbx) * cx + (cx - 1) / 2.0
    lat, lon = terrain.latlon_of(rows[:, None], cols[None, :])
    lat, lon = np.broadcast_arrays(lat, lon)
    dy_m, dx_m = terrain.spacing_m
    return xr.DataArray(
        sd,
        dims=("cell_row", "cell_col"),
        coords={
            "row": ("cell_row", rows),
            "col": ("cell_col", cols),
            "lat_deg": (("cell_row", "cell_col"), np.array(lat)),
            "lon_deg": (("cell_row", "cell_col"), np.array(lon)),
        },
        name="local_height_sd_m",
        attrs={
            "units": "m",
            "long_name": "standard deviation of height per cell",
            "cell_rows": cy,
            "cell_cols": cx,
            "cell_dy_m": cy * dy_m,
            "cell_dx_m": cx * dx_m,
            "source": terrain.source,
        },
    )


def local_height_sd(terrain: Terrain, cell_m: tuple[float, float] = DEFAULT_CELL_M) -> float:
    """Median over cells of :func:`roughness_map`, metres: one roughness number per terrain.

    Examples
    --------
    >>> local_height_sd(flat_terrain(52.0, 4.0, size_m=3000.0))
    0.0
    """
    return float(np.median(roughness_map(terrain, cell_m).values))
