"""A built scenario through the image-domain simulator, in memory: frames, truth, whole runs.

Each frame is a pure function of the scenario and its index (noise is seeded per frame), so any
split of the frames into blocks or chunks gives the same bytes. Writing a run to a Zarr store
chunk by chunk is :mod:`skyradar.sim.simulate_store`; the hash that identifies a run is
:mod:`skyradar.sim.fingerprint`.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr

from skyradar.io.frames import frames_dataset
from skyradar.scene.radar_heads import head_of
from skyradar.scene.trajectories import TrajectorySample
from skyradar.sim.image import ImageSimulator, PlatformState, PointTarget
from skyradar.sim.impairments import apply_impairments
from skyradar.sim.navigation import navigation_variables

if TYPE_CHECKING:
    from skyradar.sim.land_cover_scene import LandCoverSimulator

    # What make_simulator gives: the terrain simulator, or the land-cover one (a map's ground).
    Simulator = ImageSimulator | LandCoverSimulator

__all__ = [
    "make_simulator",
    "frames_truth",
    "scenario_truth",
    "simulate_frames",
    "simulate",
    "frames_attrs",
]

_SIM_KEYS = (
    "facet_size_m",
    "reflectivity",
    "occlusion",
    "noise",
    "flat_earth",
    "range_doppler_coupling",
    "seed",
    "psf",
    "speckle",
    "swerling",
)


def make_simulator(built, head: int | str = 0) -> Simulator:
    """An :class:`ImageSimulator` of one radar head (index or name) of a BuiltScenario, with its
    ``sim_options`` and impairments; frames and truth of that head come from it."""
    radar = head_of(built.heads, head, "make_simulator").config
    options = {k: v for k, v in built.sim_options.items() if k in _SIM_KEYS and v is not None}
    impairments = getattr(built, "impairments", None)
    if impairments is not None:
        options["ground_reflectivity_db"] = impairments.ground_reflectivity_db
        if impairments.noise is not None and impairments.noise.enabled:
            options["noise"] = False  # the impairment's receiver noise replaces the simulator's
    land_cover = getattr(built, "land_cover", None)
    if land_cover is not None:  # the ground is a map's land cover (ch6), flat at the origin's altitude
        from skyradar.sim.land_cover_scene import LandCoverSimulator

        cover, seed, noise = land_cover, options.get("seed", 0), options.get("noise", True)
        code, height = cover.class_code, cover.height_m
        return LandCoverSimulator(radar, code, height, cover.grid, built.origin, seed, noise)
    return ImageSimulator(radar, built.terrain, built.origin, **options)


def _states(built, indices: np.ndarray, ownship: TrajectorySample | None = None):
    """Own-ship and intruder states of frames ``indices``; ``ownship`` replaces the scenario's own-ship
    sample at those frames (a closed loop's states, known only at run time)."""
    times = built.times_s[indices]
    own = built.ownship.sample(times) if ownship is None else ownship
    intruders = []
    for intruder in built.intruders:
        present = intruder.trajectory.covers(times)
        sample = intruder.trajectory.sample(times[present]) if present.any() else None
        intruders.append((intruder, present, sample))
    return own, intruders


def _frame_inputs(own, intruders, i: int) -> tuple[PlatformState, list[PointTarget], list[int]]:
    platform = PlatformState(own.position_ned_m[i], own.velocity_ned_mps[i], own.attitude_rad[i])
    targets, which = [], []
    for t, (intruder, present, sample) in enumerate(intruders):
        if present[i]:
            k = int(present[: i + 1].sum()) - 1
            targets.append(PointTarget(sample.position_ned_m[k], sample.velocity_ned_mps[k], intruder.rcs_m2))
            which.append(t)
    return platform, targets, which


def simulate_frames(
    built,
    indices: np.ndarray,
    simulator: Simulator | None = None,
    ownship: TrajectorySample | None = None,
) -> np.ndarray:
    """Frames ``indices`` of the simulator's head as an (n, range, doppler, rx) complex64 array.

    ``ownship`` (one state per frame of ``indices``) replaces the scenario's own-ship trajectory
    sampled at those frames.
    """
    simulator = simulator or make_simulator(built)
    indices = np.asarray(indices)
    own, intruders = _states(built, indices, ownship)
    cfg = simulator.config
    out = np.empty((indices.size, cfg.n_range, cfg.n_doppler, cfg.n_rx), np.complex64)
    impairments = getattr(built, "impairments", None)
    for i, frame_index in enumerate(indices):
        platform, targets, _ = _frame_inputs(own, intruders, i)
        simulator.frame(platform, targets, frame_index=int(frame_index), out=out[i])
        if impairments is not None:
            # Seeded per frame like the thermal noise: any chunking gives the same bytes.
            out[i] = apply_impairments(out[i], cfg, impairments, int(frame_index))
    return out


_TRUTH_FROM_GEOMETRY = {  # frames variable -> ImageSimulator.target_truth key
    "tgt_range_m": "range_m",
    "tgt_radial_velocity_mps": "radial_velocity_mps",
    "tgt_azimuth_rad": "azimuth_rad",
    "tgt_elevation_rad": "elevation_rad",
    "tgt_snr_db": "snr_db",
    "tgt_visible": "visible",
}
_XYZ = ("north", "east", "down")
_VXYZ = ("vn", "ve", "vd")


def _ownship_truth(built, own) -> dict[str, np.ndarray]:
    agl = np.full(own.time_s.size, np.nan)
    if built.terrain is not None:
        agl = own.alt_m - built.terrain.height_at(own.lat_deg, own.lon_deg)
    elif getattr(built, "land_cover", None) is not None:
        agl = -own.position_ned_m[:, 2]  # flat map ground at the origin
    truth = {f"own_{a}_m": own.position_ned_m[:, c] for c, a in enumerate(_XYZ)}
    truth |= {f"own_{a}_mps": own.velocity_ned_mps[:, c] for c, a in enumerate(_VXYZ)}
    truth |= {f"own_{a}_rad": own.attitude_rad[:, c] for c, a in enumerate(("yaw", "pitch", "roll"))}
    truth |= {"own_lat_deg": own.lat_deg, "own_lon_deg": own.lon_deg, "own_alt_m": own.alt_m}
    return truth | {"own_height_agl_m": agl}


def _intruder_truth(built, own, intruders, simulator: Simulator) -> dict[str, np.ndarray]:
    n, n_t = own.time_s.size, len(intruders)
    keys = [f"tgt_{a}_m" for a in _XYZ] + [f"tgt_{a}_mps" for a in _VXYZ]
    keys += ["tgt_lat_deg", "tgt_lon_deg", "tgt_alt_m", "tgt_rcs_m2", *list(_TRUTH_FROM_GEOMETRY)[:-1]]
    truth = {k: np.full((n, n_t), np.nan) for k in keys} | {"tgt_visible": np.zeros((n, n_t), bool)}
    for t, (intruder, present, sample) in enumerate(intruders):
        if sample is None:
            continue
        rows = np.nonzero(present)[0]
        for c in range(3):
            truth[f"tgt_{_XYZ[c]}_m"][rows, t] = sample.position_ned_m[:, c]
            truth[f"tgt_{_VXYZ[c]}_mps"][rows, t] = sample.velocity_ned_mps[:, c]
        truth["tgt_lat_deg"][rows, t], truth["tgt_lon_deg"][rows, t] = sample.lat_deg, sample.lon_deg
        truth["tgt_alt_m"][rows, t] = sample.alt_m
        truth["tgt_rcs_m2"][rows, t] = intruder.rcs_m2
    for i in range(n):
        platform, point_targets, which = _frame_inputs(own, intruders, i)
        if point_targets:
            geometry = simulator.target_truth(platform, point_targets)
            for key, src in _TRUTH_FROM_GEOMETRY.items():
                truth[key][i, which] = geometry[src]
    return truth


def frames_truth(
    built,
    indices: np.ndarray,
    simulator: Simulator | None = None,
    ownship: TrajectorySample | None = None,
) -> tuple[dict, dict, list[str]]:
    """Own-ship truth (``own_*``, no navigation solution) and intruder truth of frames ``indices``.

    ``ownship`` replaces the scenario's own-ship sample at those frames, as in :func:`simulate_frames`.
    """
    simulator = simulator or make_simulator(built)
    own, intruders = _states(built, np.asarray(indices), ownship)
    targets = _intruder_truth(built, own, intruders, simulator) if intruders else {}
    return _ownship_truth(built, own), targets, [i.name for i in built.intruders]


def scenario_truth(built, simulator: Simulator | None = None) -> tuple[dict, dict, list[str]]:
    """Own-ship truth on time and intruder truth on (time, target), named as in ``skyradar.io.frames``."""
    ownship, targets, names = frames_truth(built, np.arange(built.times_s.size), simulator)
    # The navigation solution (nav_*) beside the truth: the chain reads only nav_*, as an aircraft
    # knows only its navigation solution.
    return ownship | navigation_variables(built, ownship), targets, names


def simulate(built, progress: Callable[[int], None] | None = None, head: int | str = 0) -> xr.Dataset:
    """Whole scenario in memory (small runs, tests), one radar head."""
    simulator = make_simulator(built, head)
    n, cfg = built.times_s.size, simulator.config
    iq = np.empty((n, cfg.n_range, cfg.n_doppler, cfg.n_rx), np.complex64)
    for i in range(n):
        iq[i] = simulate_frames(built, np.array([i]), simulator)[0]
        if progress:
            progress(1)
    ownship, targets, names = scenario_truth(built, simulator)
    return frames_dataset(iq, built.times_s, cfg, ownship, targets, names, frames_attrs(built))


def frames_attrs(built) -> dict[str, Any]:
    """The scenario attributes a frames dataset carries (name, origin, simulator options, start time)."""
    attrs = {
        "scenario": built.name,
        "origin_lat_deg": built.origin[0],
        "origin_lon_deg": built.origin[1],
        "origin_alt_m": built.origin[2],
        "sim_options": json.dumps({k: str(v) for k, v in built.sim_options.items()}),
    }
    if getattr(built, "terrain_spec", None):  # `process` rebuilds the run's built-in terrain from it
        attrs["terrain"] = built.terrain_spec
    if getattr(built, "start_time", None) is not None:  # else frames_dataset's documented default
        attrs["start_time"] = built.start_time
    return attrs
