"""Does a DEM cover the flight? The area a run needs, and a clear refusal when the DEM misses it.

A valid DEM tile far from the scenario would otherwise give frames with no terrain at all and no
word about it. :func:`footprint_bounds` is the latitude/longitude box the radar can see from a
track (own-ship positions plus the range limit), which the DEM readers use to read only that
window; :func:`check_dem_covers` refuses a DEM that does not lie under every own-ship position.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from skyradar.errors import InputError
from skyradar.io.frames_model import frame_times_s
from skyradar.scene.terrain import Bounds, Terrain, metres_per_degree

__all__ = ["DemCoverageError", "footprint_bounds", "check_dem_covers", "dem_for_run"]

# The simulator and the ground filter look this far beyond the range limit (a few facets).
_MARGIN_M = 1000.0


class DemCoverageError(InputError):
    """The DEM does not cover the area a flight needs.

    An :class:`~skyradar.errors.InputError`, so the command line reports it in one line; callers
    catch it alone to add where the flight is.

    Examples
    --------
    A tile at 52 N, 4 E read for a flight near 10 N, 10 E:

    >>> import tempfile, pathlib
    >>> from skyradar.scene.dem_readers import read_hgt
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = pathlib.Path(d) / "N52E004.hgt"
    ...     np.full((1201, 1201), 7, ">i2").tofile(p)
    ...     try:
    ...         read_hgt(p, bounds=Bounds(10.0, 10.0, 10.1, 10.1))
    ...     except DemCoverageError as exc:
    ...         print(isinstance(exc, InputError), exc)
    True N52E004.hgt: the DEM covers lat 52..53, lon 4..5, outside the area the flight needs (lat 10..10.1, \
lon 10..10.1)
    """


def footprint_bounds(lat_deg: np.ndarray, lon_deg: np.ndarray, margin_m: float) -> Bounds:
    """Box around the positions ``(lat_deg, lon_deg)`` widened by ``margin_m`` on every side.

    Parameters
    ----------
    lat_deg, lon_deg : array_like
        Geodetic positions, degrees.
    margin_m : float
        Ground distance added on each side, metres (the radar's range limit, say).

    Returns
    -------
    Bounds
        (south, west, north, east), degrees; longitudes may pass +-180 near the antimeridian.

    Examples
    --------
    >>> b = footprint_bounds([52.0, 52.01], [4.0, 4.0], 1000.0)
    >>> [round(v, 4) for v in b]
    [51.991, 3.9854, 52.019, 4.0146]
    """
    lat, lon = np.asarray(lat_deg, float), np.asarray(lon_deg, float)
    south, north = float(lat.min()), float(lat.max())
    m_lat = metres_per_degree(0.5 * (south + north))[0]
    # A degree of longitude is shortest at the latitude furthest from the equator.
    extreme = min(89.9, max(abs(south), abs(north)) + margin_m / m_lat)
    m_lon = metres_per_degree(extreme)[1]
    return Bounds(
        max(-90.0, south - margin_m / m_lat),
        float(lon.min()) - margin_m / m_lon,
        min(90.0, north + margin_m / m_lat),
        float(lon.max()) + margin_m / m_lon,
    )


def check_dem_covers(
    terrain: Terrain,
    lat_deg: np.ndarray,
    lon_deg: np.ndarray,
    times_s: np.ndarray,
    origin: tuple[float, ...] | None,
    what: str = "own-ship",
) -> None:
    """Raise :class:`InputError` unless every position ``(lat_deg, lon_deg)`` lies over ``terrain``.

    The message names the DEM, its extent, the first position outside it (with its time) and
    the scenario origin.

    Examples
    --------
    >>> t = Terrain.geographic(np.zeros((11, 11)), 53.0, 4.0, 0.1, 0.1, source="N52E004.hgt")
    >>> check_dem_covers(t, [52.5], [4.5], [0.0], (52.5, 4.5, 0.0))  # inside: no error
    >>> check_dem_covers(t, [52.5, 7.0], [4.5, 60.0], [0.0, 1.0], (7.0, 60.0, 0.0))
    Traceback (most recent call last):
    ...
    skyradar.scene.dem_coverage.DemCoverageError: N52E004.hgt: the DEM covers lat 52..53, lon 4..5 but ...
    """
    lat, lon = np.atleast_1d(np.asarray(lat_deg, float)), np.atleast_1d(np.asarray(lon_deg, float))
    row, col = terrain.index_of(lat, lon)
    ny, nx = terrain.shape
    outside = ~((row >= 0) & (row <= ny - 1) & (col >= 0) & (col <= nx - 1))
    if not outside.any():
        return
    i = int(np.flatnonzero(outside)[0])
    b = terrain.bounds
    c_lat, c_lon = terrain.center_latlon
    away_km = _great_circle_m(lat[i], lon[i], c_lat, c_lon) / 1000.0
    where = "" if origin is None else f"; scenario origin lat {origin[0]:.6g}, lon {origin[1]:.6g}"
    raise DemCoverageError(
        f"{terrain.source}: the DEM covers lat {b.south_deg:.6g}..{b.north_deg:.6g}, lon "
        f"{b.west_deg:.6g}..{b.east_deg:.6g} but the {what} is at lat {lat[i]:.6g}, lon {lon[i]:.6g} "
        f"at t = {float(np.atleast_1d(times_s)[i]):.6g} s ({away_km:.0f} km away{where}): "
        "it does not cover the flight"
    )


def dem_for_run(path: str | Path, ds: Any, range_limit_m: float, source: str) -> Terrain:
    """Read the DEM ``path`` for a frames run ``ds``: the window its own-ship can see, checked to cover it.

    The own-ship positions come from the run's navigation (``nav_lat_deg``/``nav_lon_deg``, or
    its NED track and stored origin; ``own_*`` in runs without ``nav_*``). A run without
    either cannot place a DEM: :class:`InputError` naming ``source``.

    Parameters
    ----------
    path : str or Path
        DEM file (SRTM ``.hgt``, GeoTIFF or ``.npz``).
    ds : xarray.Dataset
        The frames run (only its navigation variables, ``time`` and origin attributes are read).
    range_limit_m : float
        The radar's range limit, m; the window reaches this plus 1 km beyond every position.
    source : str
        Name of the run, for messages.

    Returns
    -------
    Terrain
        The window of the DEM under the run.

    Raises
    ------
    DemCoverageError
        When the DEM does not lie under every own-ship position.

    Examples
    --------
    A run over 52.5 N, 4.5 E with a 2 km range limit reads the tile's samples within 3 km of the
    track (range limit plus 1 km), not the whole tile:

    >>> import tempfile, pathlib
    >>> import xarray as xr
    >>> ds = xr.Dataset({"nav_lat_deg": ("time", [52.5, 52.51]), "nav_lon_deg": ("time", [4.5, 4.5])},
    ...                 coords={"time": [0.0, 1.0]})
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = pathlib.Path(d) / "N52E004.hgt"
    ...     np.full((1201, 1201), 7, ">i2").tofile(p)
    ...     terrain = dem_for_run(p, ds, 2000.0, "run.zarr")
    >>> terrain.shape, float(terrain.height_at(52.5, 4.5))
    ((81, 111), 7.0)
    """
    from skyradar.scene.dem_readers import read_dem

    lat, lon, origin = run_track(ds, source)
    times = frame_times_s(ds)
    try:
        terrain = read_dem(path, bounds=footprint_bounds(lat, lon, range_limit_m + _MARGIN_M))
    except DemCoverageError as exc:
        where = "" if origin is None else f", origin lat {origin[0]:.6g}, lon {origin[1]:.6g}"
        raise DemCoverageError(f"{exc} by the own-ship of {source}{where}") from None
    check_dem_covers(terrain, lat, lon, times, origin, what=f"own-ship of {source}")
    return terrain


def run_track(ds: Any, source: str) -> tuple[np.ndarray, np.ndarray, tuple[float, ...] | None]:
    """Own-ship latitude/longitude per frame as the aircraft knows them (navigation), and the origin."""
    from skyradar.geo import ned_to_geodetic
    from skyradar.io.navigation import navigation_state
    from skyradar.io.run_origin import scenario_origin

    origin = scenario_origin(ds)
    nav = navigation_state(ds, source)
    if nav is not None and "own_lat_deg" in nav and "own_lon_deg" in nav:
        return nav["own_lat_deg"].to_numpy(float), nav["own_lon_deg"].to_numpy(float), origin
    names = ("own_north_m", "own_east_m", "own_down_m")
    if origin is None or nav is None or not all(n in nav for n in names):
        raise InputError(
            f"{source}: option '--terrain' needs the run's own-ship position (navigation variables "
            "nav_lat_deg, nav_lon_deg, or nav_north_m.. and an origin; own_* in older runs) to place "
            "the terrain and judge ground; this run has none"
        )
    ned = np.stack([nav[n].to_numpy(float) for n in names], axis=-1)
    lat, lon, _ = ned_to_geodetic(ned, *origin)
    return np.atleast_1d(lat), np.atleast_1d(lon), origin


def _great_circle_m(lat1: float, lon1: float, lat2: float, lon2: float) -> float:
    """Haversine distance on the mean earth sphere, metres (for messages only)."""
    p1, p2 = np.radians(lat1), np.radians(lat2)
    dp, dl = p2 - p1, np.radians(lon2 - lon1)
    h = np.sin(dp / 2) ** 2 + np.cos(p1) * np.cos(p2) * np.sin(dl / 2) ** 2
    return float(2 * 6_371_008.8 * np.arcsin(np.sqrt(min(1.0, h))))
