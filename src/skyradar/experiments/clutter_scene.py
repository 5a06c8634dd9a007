"""The named scene of ``skyradar experiment clutter``: ground below, prototype radar, fast head-on intruder.

Own-ship flies level north at 50 m/s, radar facing forward; a head-on intruder at the same
altitude closes at ``closing_mps`` (100 m/s: its radial velocity -100 m/s aliases to -21.7 m/s,
inside the band of ground Doppler fed by the antenna's sidelobes) from ``start_range_m`` ahead.
The ground is flat, ``height_m`` (1000 m or 300 m) below (the README's flat-ground case), or a
relief of the encounter set (:func:`skyradar.experiments.encounter_terrain.site`: the ``hills``
fractal terrain or the ``jacksboro`` DEM, with its origin), over which :func:`relief_altitude_m`
picks the own-ship's altitude from the ground under its track. Frames come from the image
simulator (:mod:`skyradar.sim.scenario_frames`), with a clutter-only run (no noise, no intruder)
and a noise-free intruder-only run of the same geometry as truth for the figures.

Examples
--------
>>> data = scene_dict(1000.0, n_frames=2)
>>> data["ownship"]["start_ned_m"], data["intruders"][0]["kind"]
([0.0, 0.0, -1000.0], 'head-on')
>>> scene_dict(900.0, n_frames=2, terrain="hills")["terrain"]["type"]
'fractal'
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from skyradar.errors import InputError
from skyradar.experiments.encounter_terrain import MIN_INTRUDER_AGL_M, own_altitude_m, site
from skyradar.io.frames import frames_dataset
from skyradar.scene.scenario import Scenario
from skyradar.sim.scenario_frames import make_simulator, scenario_truth, simulate_frames

__all__ = ["scene_dict", "scene_frames", "relief_altitude_m", "OWN_SPEED_MPS", "RELIEFS"]

OWN_SPEED_MPS = 50.0
RELIEFS = ("hills", "jacksboro")  # the encounter set's terrains with relief


def scene_dict(
    height_m: float,
    n_frames: int = 40,
    frame_rate_hz: float = 9.4,
    closing_mps: float = 100.0,
    start_range_m: float = 5000.0,
    seed: int = 0,
    ground: bool = True,
    noise: bool = True,
    intruder: bool = True,
    size_m: float = 14_000.0,
    rcs_m2: float = 1.0,
    terrain: str = "flat",
    terrain_seed: int = 0,
) -> dict[str, Any]:
    """Scenario dict (:meth:`Scenario.from_dict`) of the scene; ``ground=False`` is the clear-sky twin.

    ``terrain="flat"``: flat ground ``height_m`` (m) below, ``size_m`` (m) square around the origin.
    A name of :data:`RELIEFS`: the origin and the ground of
    :func:`~skyradar.experiments.encounter_terrain.site` (``terrain_seed`` picks the hills surface
    and the point over Jacksboro), with the own-ship ``height_m`` (m) above the origin's datum.
    """
    if terrain != "flat" and terrain not in RELIEFS:
        raise InputError(f"clutter scene: terrain must be flat, {' or '.join(RELIEFS)}, got {terrain!r}")
    where = site(terrain, terrain_seed) if terrain in RELIEFS else None
    what = (
        f"flat ground {height_m:g} m below" if where is None else f"{terrain}, own-ship {height_m:.0f} m up"
    )
    data: dict[str, Any] = {
        "name": f"clutter scene, {what}",
        "origin": {"lat_deg": 52.0, "lon_deg": 5.0, "alt_m": 0.0} if where is None else where["origin"],
        "radar": {"antenna": {"beamwidth_deg": 70}},
        "mount": "forward",
        "ownship": {
            "type": "straight",
            "start_ned_m": [0.0, 0.0, -float(height_m)],
            "heading_deg": 0.0,
            "speed_mps": OWN_SPEED_MPS,
        },
        "intruders": [
            {
                "name": "head-on",
                "type": "encounter",
                "kind": "head-on",
                "t_cpa_s": start_range_m / closing_mps,
                "intruder_speed_mps": closing_mps - OWN_SPEED_MPS,
                "rcs_m2": float(rcs_m2),
            }
        ],
        "frame_rate_hz": frame_rate_hz,
        "duration_s": n_frames / frame_rate_hz,
        "start_s": 0.0,
        "simulation": {"noise": bool(noise), "seed": int(seed), "facet_size_m": 7.5},
        "navigation": "perfect",
    }
    if ground:
        flat = {"type": "flat", "size_m": float(size_m), "spacing_m": 30.0}
        data["terrain"] = flat if where is None else where["terrain"]
    if not intruder:
        data["intruders"] = []
    return data


def relief_altitude_m(terrain: str, agl_range_m: tuple[float, float], **scene: Any) -> float:
    """Own-ship's level altitude (m above the origin's datum) over the relief ``terrain``.

    The altitude of :func:`~skyradar.experiments.encounter_terrain.own_altitude_m` over the ground
    under the own-ship's track in the frames: ``agl_range_m`` (m) above it where the relief allows.
    The head-on intruder flies at the same altitude; where the ground under its track comes
    within :data:`~skyradar.experiments.encounter_terrain.MIN_INTRUDER_AGL_M` of it, both fly
    higher. ``scene`` holds the other :func:`scene_dict` arguments (``n_frames``,
    ``frame_rate_hz``, ``closing_mps``, ``start_range_m``, ``terrain_seed``).
    """
    built = Scenario.from_dict(scene_dict(0.0, terrain=terrain, **scene), source="clutter scene").build()
    times = np.linspace(float(built.times_s[0]), float(built.times_s[-1]), 64)
    own = built.ownship.sample(times)
    alt = own_altitude_m(built.terrain.height_at(own.lat_deg, own.lon_deg), agl_range_m)
    tgt = built.intruders[0].trajectory.sample(times)
    ground_tgt = built.terrain.height_at(tgt.lat_deg, tgt.lon_deg)
    return max(alt, float(np.nanmax(ground_tgt)) + MIN_INTRUDER_AGL_M)


def scene_frames(data: dict[str, Any]) -> xr.Dataset:
    """Frames Dataset (iq, own-ship and intruder truth, navigation) of a scene dict."""
    built = Scenario.from_dict(data, source="clutter scene").build()
    simulator = make_simulator(built)
    own, tgt, names = scenario_truth(built, simulator)
    iq = simulate_frames(built, np.arange(built.times_s.size), simulator)
    attrs = {
        "scenario": built.name,
        "origin_lat_deg": built.origin[0],
        "origin_lon_deg": built.origin[1],
        "origin_alt_m": built.origin[2],
    }
    return frames_dataset(iq, built.times_s, built.radar, own, tgt, names, attrs)
