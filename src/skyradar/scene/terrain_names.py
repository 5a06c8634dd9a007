"""Terrain for a recorded run by name or file: ``flat``, ``fractal``, ``jacksboro`` or a DEM path.

``skyradar process --terrain`` takes either a DEM file (SRTM ``.hgt``, GeoTIFF, ``.npz``) or one of
the built-in terrains of the scenario files, by name:

* ``jacksboro``: matplotlib's sample DEM (Jacksboro fault, Tennessee; 344 x 403 samples of
  3 arc-seconds, about 31.8 km north-south by 30 km east-west), read only where the run's
  own-ship can see and refused (one line) when the run is not over it;
* ``flat``: a flat ground under the run. Its height comes from the run's recorded scenario terrain
  (attribute ``terrain``, written by ``skyradar simulate``) when that is flat, else from the
  own-ship's altitude minus its height above ground at the first frame;
* ``fractal``: the scenario's fractal hills, rebuilt from the run's recorded terrain (size,
  spacing, local SD, seed); hills are random, so a run without that record is refused.

A run whose attribute ``terrain`` records a scenario terrain is also where :func:`recorded_terrain`
rebuilds it from, so ``process`` can use the run's own terrain when no ``--terrain`` is given.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from skyradar.errors import InputError
from skyradar.scene.terrain import Terrain

__all__ = ["BUILTIN_TERRAINS", "terrain_spec_attr", "recorded_terrain", "terrain_for_run"]

BUILTIN_TERRAINS = ("flat", "fractal", "jacksboro")
_OPTION = "option '--terrain'"


def terrain_spec_attr(model: Any) -> str | None:
    """JSON of a scenario's terrain model for the run's ``terrain`` attribute; None for a file DEM.

    Parameters
    ----------
    model : terrain model or None
        A scenario's ``terrain`` section (:mod:`skyradar.scene.scenario_models`).

    Returns
    -------
    str or None
        The section as JSON for ``flat``, ``fractal`` and ``jacksboro``; None for a file DEM or no
        terrain.

    Examples
    --------
    >>> from skyradar.scene.scenario_models import FileTerrainModel, FlatTerrainModel
    >>> terrain_spec_attr(FlatTerrainModel(type="flat", height_m=12.0, size_m=3000.0))
    '{"height_m": 12.0, "size_m": 3000.0, "spacing_m": 30.0, "type": "flat"}'
    >>> terrain_spec_attr(FileTerrainModel(type="file", path="N52E004.hgt")) is None
    True
    """
    if model is None or getattr(model, "type", None) not in BUILTIN_TERRAINS:
        return None
    return json.dumps(model.model_dump(mode="json"))


def _spec(ds: Any) -> dict | None:
    text = ds.attrs.get("terrain") if hasattr(ds, "attrs") else None
    if not text:
        return None
    try:
        spec = json.loads(text)
    except (TypeError, ValueError):
        return None
    return spec if isinstance(spec, dict) and spec.get("type") in BUILTIN_TERRAINS else None


def _origin(ds: Any, source: str) -> tuple[float, float, float]:
    from skyradar.io.run_origin import scenario_origin

    origin = scenario_origin(ds)
    if origin is None:
        raise InputError(
            f"{source}: {_OPTION} needs the run's origin (attributes origin_lat_deg, origin_lon_deg, "
            "origin_alt_m) to place a built-in terrain; this run has none"
        )
    lat, lon, alt = origin
    return float(lat), float(lon), float(alt)


def recorded_terrain(ds: Any, source: str = "frames") -> Terrain | None:
    """The scenario terrain a run records (attribute ``terrain``), rebuilt; None when it records none.

    Parameters
    ----------
    ds : xarray.Dataset
        The frames run (its attributes ``terrain`` and origin are read).
    source : str
        Name of the run, for messages.

    Returns
    -------
    Terrain or None

    Examples
    --------
    A run that records a flat terrain 12 m above the ellipsoid, 3 km square, about its origin:

    >>> import xarray as xr
    >>> spec = '{"type": "flat", "height_m": 12.0, "size_m": 3000.0, "spacing_m": 30.0}'
    >>> ds = xr.Dataset(attrs={"terrain": spec, "origin_lat_deg": 52.0, "origin_lon_deg": 4.0})
    >>> t = recorded_terrain(ds)
    >>> t.shape, [round(v, 6) for v in t.center_latlon], float(t.height_at(52.0, 4.0))
    ((101, 101), [52.0, 4.0], 12.0)
    >>> recorded_terrain(xr.Dataset()) is None
    True
    """
    spec = _spec(ds)
    if spec is None:
        return None
    return _built_in(spec["type"], spec, ds, source)


def _built_in(name: str, spec: dict | None, ds: Any, source: str) -> Terrain:
    from skyradar.scene.dem_readers import jacksboro
    from skyradar.scene.synthetic_terrain import flat_terrain, fractal_terrain

    if name == "jacksboro":
        return jacksboro()
    lat, lon, alt = _origin(ds, source)
    spec = spec or {}
    size, spacing = float(spec.get("size_m") or 12_000.0), float(spec.get("spacing_m") or 30.0)
    height = spec.get("height_m")
    height = alt if height is None else float(height)
    if name == "fractal":
        return fractal_terrain(
            lat,
            lon,
            float(spec["local_sd_m"]),
            size_m=size,
            spacing_m=spacing,
            seed=int(spec.get("seed", 0)),
            mean_height_m=height,
        )
    return flat_terrain(lat, lon, height, size, spacing)


def _flat_height(ds: Any, source: str) -> float | None:
    """Ground altitude under the own-ship at the first frame (navigation), or None."""
    from skyradar.io.navigation import navigation_state

    nav = navigation_state(ds, source)
    if nav is None or "own_height_agl_m" not in nav or "own_alt_m" not in nav:
        return None
    ground = nav["own_alt_m"].to_numpy(float) - nav["own_height_agl_m"].to_numpy(float)
    ground = ground[np.isfinite(ground)]
    return float(ground[0]) if ground.size else None


def terrain_for_run(value: str, ds: Any, range_limit_m: float, source: str) -> Terrain:
    """The terrain ``--terrain value`` names for the run ``ds``: a built-in name or a DEM file.

    Raises :class:`InputError` (one line) for an unknown name, a file that is not a DEM, a DEM or
    built-in terrain that does not lie under the own-ship, or a run without own-ship position.

    Parameters
    ----------
    value : str
        ``flat``, ``fractal``, ``jacksboro`` (any case) or a DEM file path.
    ds : xarray.Dataset
        The frames run (navigation variables, ``time`` and attributes are read).
    range_limit_m : float
        The radar's range limit, m: how far around the own-ship a DEM is read.
    source : str
        Name of the run, for messages.

    Returns
    -------
    Terrain

    Examples
    --------
    ``flat`` rebuilds the flat terrain the run records:

    >>> import xarray as xr
    >>> spec = '{"type": "flat", "height_m": 12.0, "size_m": 3000.0}'
    >>> ds = xr.Dataset({"nav_lat_deg": ("time", [52.0, 52.001]), "nav_lon_deg": ("time", [4.0, 4.0])},
    ...                 coords={"time": [0.0, 1.0]},
    ...                 attrs={"terrain": spec, "origin_lat_deg": 52.0, "origin_lon_deg": 4.0})
    >>> float(terrain_for_run("Flat", ds, 1000.0, "run.zarr").height_at(52.0, 4.0))
    12.0
    >>> terrain_for_run("hills", ds, 1000.0, "run.zarr")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: option '--terrain': 'hills' is neither a DEM file nor a built-in terrain \
(flat, fractal, jacksboro)
    """
    from skyradar.io.frames_model import frame_times_s
    from skyradar.scene.dem_coverage import check_dem_covers, dem_for_run, run_track

    name = str(value).strip().lower()
    if name not in BUILTIN_TERRAINS:
        path = Path(value)
        if not path.exists() and not path.suffix:
            raise InputError(
                f"{_OPTION}: '{value}' is neither a DEM file nor a built-in terrain "
                f"({', '.join(BUILTIN_TERRAINS)})"
            )
        return dem_for_run(path, ds, range_limit_m, source)
    lat, lon, origin = run_track(ds, source)
    spec = _spec(ds)
    if name == "fractal" and (spec is None or spec.get("type") != "fractal"):
        raise InputError(
            f"{source}: {_OPTION} 'fractal': the run does not record its fractal terrain (attribute "
            "'terrain': local_sd_m, seed); fractal hills are random, give the DEM file instead"
        )
    if name == "flat" and (spec is None or spec.get("type") != "flat"):
        height = _flat_height(ds, source)
        spec = None if height is None else {"height_m": height, "size_m": 2.0 * range_limit_m + 14_000.0}
    terrain = _built_in(name, spec if spec is None or spec.get("type", name) == name else None, ds, source)
    check_dem_covers(terrain, lat, lon, frame_times_s(ds), origin, what=f"own-ship of {source}")
    return terrain
