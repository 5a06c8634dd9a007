"""The geodetic origin of a run's local NED frame, read from its attributes.

Readers in several layers need it (scene's DEM coverage check, process, daa provenance), so it
lives in :mod:`skyradar.io`, below all of them.
"""

from __future__ import annotations

import json

import xarray as xr

__all__ = ["scenario_origin"]


def scenario_origin(ds: xr.Dataset) -> tuple[float, float, float] | None:
    """Geodetic origin (lat_deg, lon_deg, alt_m) of the run's NED frame from its attributes, if stored.

    Examples
    --------
    >>> scenario_origin(xr.Dataset(attrs={"origin_lat_deg": 52.5, "origin_lon_deg": 13.4}))
    (52.5, 13.4, 0.0)
    >>> scenario_origin(xr.Dataset(attrs={"origin": "[48.1, 11.6, 500]"}))
    (48.1, 11.6, 500.0)
    >>> scenario_origin(xr.Dataset()) is None
    True
    """
    attrs = ds.attrs
    if all(k in attrs for k in ("origin_lat_deg", "origin_lon_deg")):
        return (
            float(attrs["origin_lat_deg"]),
            float(attrs["origin_lon_deg"]),
            float(attrs.get("origin_alt_m", 0.0)),
        )
    origin = attrs.get("origin")
    if origin is not None:
        values = json.loads(origin) if isinstance(origin, str) else list(origin)
        if len(values) >= 2:
            return float(values[0]), float(values[1]), float(values[2]) if len(values) > 2 else 0.0
    return None
