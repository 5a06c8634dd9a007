"""The ground under the encounter set: terrain names, own-ship height above it, intruders above it.

Terrains of ``skyradar experiment encounters --terrain``:

``none``
    Clear sky (no ground; every detection is the intruder or noise).
``flat-300``, ``flat-1000`` (alias ``flat``)
    Flat ground 300 m or 1000 m below own-ship, 16 km square around the origin.
``hills``
    Fractal terrain (:func:`skyradar.scene.synthetic_terrain.fractal_terrain`) with 60 m median local
    height SD, 16 km square, a new surface for every encounter (seeded by it).
``jacksboro``
    The real 3-arcsecond DEM shipped with matplotlib (``jacksboro_fault_dem.npz``, about 30 km square,
    250-720 m): own-ship passes a point within 3 km of its centre (seeded per encounter), so
    its track over the frame window and the 5 km range limit around it stay on the DEM.

Over ``hills`` and ``jacksboro`` own-ship flies level 400-700 m above the ground under its track in
the frame window (:func:`own_altitude_m`). Encounters are defined relative to own-ship; an intruder
that would pass closer than :data:`MIN_INTRUDER_AGL_M` to the ground flies the mirror encounter
(vertical miss and climb of opposite sign: the same horizontal geometry and the same vertical
miss distance) so that no aircraft flies underground (:func:`mirror_below_ground`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from skyradar.errors import InputError

__all__ = [
    "TERRAINS",
    "MIN_INTRUDER_AGL_M",
    "parse_terrains",
    "site",
    "own_altitude_m",
    "mirror_below_ground",
]

TERRAINS = ("none", "flat-300", "flat-1000", "hills", "jacksboro")
_ALIASES = {"flat": "flat-1000", "clear": "none"}
MIN_INTRUDER_AGL_M = 100.0
OWN_AGL_RANGE_M = (400.0, 700.0)  # over hills and jacksboro
_HILLS_SD_M = 60.0
_GRID_SIZE_M = 16_000.0  # the frame window's own-ship track (2 km) plus the 5 km range limit each side
_JACKSBORO_OFFSET_M = 3_000.0


def parse_terrains(value: str, terrains: tuple[str, ...] = TERRAINS, option: str = "--terrain") -> list[str]:
    """Terrain names from ``option`` (comma-separated names of ``terrains``; ``all`` = every one;
    ``flat`` = ``flat-1000``, ``clear`` = ``none``), in the given order, each once.

    Examples
    --------
    >>> parse_terrains("flat,hills")
    ['flat-1000', 'hills']
    >>> parse_terrains("all")
    ['none', 'flat-300', 'flat-1000', 'hills', 'jacksboro']
    """
    if value.strip() == "all":
        return list(terrains)
    names = [_ALIASES.get(v.strip(), v.strip()) for v in value.split(",")]
    for name in names:
        if name not in terrains:
            raise InputError(
                f"{option}: must be all or a comma-separated list of {', '.join(terrains)} (or flat), "
                f"got {value!r}"
            )
    return list(dict.fromkeys(names))


def site(terrain: str | None, seed: int) -> dict[str, Any]:
    """Scenario ``origin`` and ``terrain`` sections and own-ship's nominal altitude for a terrain name.

    ``seed`` (the encounter's) picks the hills surface and the point over Jacksboro.

    Examples
    --------
    >>> site("flat-300", 0)["own_altitude_m"]
    300.0
    """
    name = _ALIASES.get(terrain or "none", terrain or "none")
    origin = {"lat_deg": 52.0, "lon_deg": 5.0, "alt_m": 0.0}
    grid = {"size_m": _GRID_SIZE_M, "height_m": 0.0}
    if name == "none":
        return {"origin": origin, "terrain": None, "own_altitude_m": 1000.0}
    if name.startswith("flat-"):
        return {"origin": origin, "terrain": {"type": "flat", **grid}, "own_altitude_m": float(name[5:])}
    if name == "hills":
        hills = {"type": "fractal", "local_sd_m": _HILLS_SD_M, "seed": int(seed), **grid}
        return {"origin": origin, "terrain": hills, "own_altitude_m": 550.0}
    if name == "jacksboro":
        from skyradar.geo import ned_to_geodetic
        from skyradar.scene.dem_readers import jacksboro

        lat0, lon0 = jacksboro().center_latlon
        dn, de = np.random.default_rng(seed).uniform(-_JACKSBORO_OFFSET_M, _JACKSBORO_OFFSET_M, 2)
        lat, lon, _ = ned_to_geodetic(np.array([[dn, de, 0.0]]), lat0, lon0)
        origin = {"lat_deg": float(lat[0]), "lon_deg": float(lon[0]), "alt_m": 0.0}
        return {"origin": origin, "terrain": {"type": "jacksboro"}, "own_altitude_m": 1000.0}
    raise InputError(f"encounters: terrain must be one of {', '.join(TERRAINS)}, got {terrain!r}")


def own_altitude_m(ground_m: np.ndarray, agl_range_m: tuple[float, float] = OWN_AGL_RANGE_M) -> float:
    """Level flight altitude (m, same datum as ``ground_m``) over the ground heights under the track.

    The middle of ``agl_range_m`` above the mean ground, moved so that the lowest height above the
    ground is at least the range's minimum and, if the relief allows, the highest at most its
    maximum (the minimum wins: clearance first).

    Examples
    --------
    >>> own_altitude_m(np.array([100.0, 150.0, 200.0]))
    700.0
    >>> own_altitude_m(np.array([0.0, 500.0]))
    900.0
    """
    g = np.asarray(ground_m, float)
    g = g[np.isfinite(g)]
    if g.size == 0:
        raise InputError("encounters: own-ship's track in the frame window is outside the terrain grid")
    lo, hi = agl_range_m
    alt = min(float(g.mean()) + (lo + hi) / 2.0, float(g.min()) + hi)
    return max(alt, float(g.max()) + lo)


def mirror_below_ground(intruder_alt_m: np.ndarray, ground_m: np.ndarray, own_alt_m: float) -> bool:
    """True when the intruder (altitudes over the frame window, m) passes below
    :data:`MIN_INTRUDER_AGL_M` above ``ground_m`` under it and its mirror image in own-ship's
    altitude would not (the mirror then flies instead).

    Examples
    --------
    >>> mirror_below_ground(np.array([250.0, 280.0]), np.array([200.0, 200.0]), 300.0)
    True
    >>> mirror_below_ground(np.array([350.0]), np.array([200.0]), 300.0)
    False
    """
    alt, ground = np.asarray(intruder_alt_m, float), np.asarray(ground_m, float)
    ok = np.isfinite(ground)
    if not ok.any():
        return False
    low = float(np.min(alt[ok] - ground[ok]))
    mirrored = float(np.min(2.0 * own_alt_m - alt[ok] - ground[ok]))
    return low < MIN_INTRUDER_AGL_M and mirrored > low
