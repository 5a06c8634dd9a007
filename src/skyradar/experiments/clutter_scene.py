"""The named scene of ``skyradar experiment clutter``: flat ground, prototype radar, fast head-on intruder.

Own-ship flies level at 50 m/s, ``height_m`` (1000 m or 300 m) above flat ground, radar facing
forward (the README's flat-ground case); a head-on intruder at the same altitude closes at
``closing_mps`` (100 m/s: its radial velocity -100 m/s aliases to -21.7 m/s, inside the band
of ground Doppler fed by the antenna's sidelobes) from ``start_range_m`` ahead. Frames come from
the image simulator (:mod:`skyradar.sim.scenario_frames`), with a clutter-only run (no noise, no
intruder) and a noise-free intruder-only run of the same geometry as truth for the figures.

Examples
--------
>>> data = scene_dict(1000.0, n_frames=2)
>>> data["ownship"]["start_ned_m"], data["intruders"][0]["kind"]
([0.0, 0.0, -1000.0], 'head-on')
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from skyradar.io.frames import frames_dataset
from skyradar.scene.scenario import Scenario
from skyradar.sim.scenario_frames import make_simulator, scenario_truth, simulate_frames

__all__ = ["scene_dict", "scene_frames", "OWN_SPEED_MPS"]

OWN_SPEED_MPS = 50.0


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
) -> dict[str, Any]:
    """Scenario dict (:meth:`Scenario.from_dict`) of the scene; ``ground=False`` is the clear-sky twin."""
    data: dict[str, Any] = {
        "name": f"clutter scene, flat ground {height_m:g} m below",
        "origin": {"lat_deg": 52.0, "lon_deg": 5.0, "alt_m": 0.0},
        "radar": {"antenna": {"beamwidth_deg": 70}},
        "mount": "forward",
        "ownship": {"type": "straight", "start_ned_m": [0.0, 0.0, -float(height_m)], "heading_deg": 0.0,
                    "speed_mps": OWN_SPEED_MPS},
        "intruders": [{"name": "head-on", "type": "encounter", "kind": "head-on",
                       "t_cpa_s": start_range_m / closing_mps,
                       "intruder_speed_mps": closing_mps - OWN_SPEED_MPS, "rcs_m2": float(rcs_m2)}],
        "frame_rate_hz": frame_rate_hz,
        "duration_s": n_frames / frame_rate_hz,
        "start_s": 0.0,
        "simulation": {"noise": bool(noise), "seed": int(seed), "facet_size_m": 7.5},
        "navigation": "perfect",
    }  # fmt: skip
    if ground:
        data["terrain"] = {"type": "flat", "size_m": float(size_m), "spacing_m": 30.0}
    if not intruder:
        data["intruders"] = []
    return data


def scene_frames(data: dict[str, Any]) -> xr.Dataset:
    """Frames Dataset (iq, own-ship and intruder truth, navigation) of a scene dict."""
    built = Scenario.from_dict(data, source="clutter scene").build()
    simulator = make_simulator(built)
    own, tgt, names = scenario_truth(built, simulator)
    iq = simulate_frames(built, np.arange(built.times_s.size), simulator)
    attrs = {"scenario": built.name, "origin_lat_deg": built.origin[0], "origin_lon_deg": built.origin[1],
             "origin_alt_m": built.origin[2]}  # fmt: skip
    return frames_dataset(iq, built.times_s, built.radar, own, tgt, names, attrs)
