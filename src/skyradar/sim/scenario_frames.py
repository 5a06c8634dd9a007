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
    ``sim_options`` and impairments; frames and truth of that head come from it.

    Parameters
    ----------
    built : BuiltScenario
    head : int or str
        The radar head's index or name.

    Returns
    -------
    ImageSimulator or LandCoverSimulator
        The land-cover simulator when the scenario's ground is a map's land cover.

    Examples
    --------
    >>> from skyradar.scene.scenario import Scenario
    >>> spec = {"name": "pair", "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    ...     "radar": {"range_limit_m": 1500}, "simulation": {"noise": False},
    ...     "ownship": {"type": "straight", "start_ned_m": [0, 0, -2000], "speed_mps": 30},
    ...     "intruders": [{"name": "A", "type": "straight", "start_ned_m": [900, 0, -2000], "speed_mps": 30}],
    ...     "frame_rate_hz": 10, "duration_s": 0.2}
    >>> built = Scenario.from_dict(spec).build()  # two frames; A flies 900 m ahead at the same velocity
    >>> sim = make_simulator(built)
    >>> type(sim).__name__, sim.config.n_range, sim.noise  # 1500 m / 15 m range bins
    ('ImageSimulator', 100, False)
    """
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

    Parameters
    ----------
    built : BuiltScenario
    indices : ndarray of int
        Frame indices in the run.
    simulator : ImageSimulator, optional
        Default: :func:`make_simulator` of the first head.
    ownship : TrajectorySample, optional
        One state per frame of ``indices``; replaces the scenario's own-ship trajectory sampled
        at those frames.

    Returns
    -------
    ndarray, shape (n, n_range, n_doppler, n_channels), complex64
        Each frame ``config.frame_shape``; pixel units: ``|pixel|^2`` in W.

    Examples
    --------
    The intruder (1 m^2) 900 m ahead on boresight at zero radial velocity is one pixel of the
    radar equation's power ``Pe G^2 lambda^2 sigma / ((4 pi)^3 R^4)``:

    >>> from skyradar.scene.scenario import Scenario
    >>> spec = {"name": "pair", "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    ...     "radar": {"range_limit_m": 1500}, "simulation": {"noise": False},
    ...     "ownship": {"type": "straight", "start_ned_m": [0, 0, -2000], "speed_mps": 30},
    ...     "intruders": [{"name": "A", "type": "straight", "start_ned_m": [900, 0, -2000], "speed_mps": 30}],
    ...     "frame_rate_hz": 10, "duration_s": 0.2}
    >>> built = Scenario.from_dict(spec).build()  # two frames; A flies 900 m ahead at the same velocity
    >>> frames = simulate_frames(built, np.arange(2))
    >>> k, j, _ = np.unravel_index(np.abs(frames[1]).argmax(), frames[1].shape)
    >>> cfg = built.radar
    >>> frames.shape, round(float(cfg.range_axis_m[k]), 1), float(cfg.doppler_axis_mps[j])
    ((2, 100, 250, 4), 899.4, 0.0)
    >>> gain = 10 ** (float(cfg.antenna.gain_db(0.0, 0.0)) / 10)
    >>> expected = cfg.pe_w * gain**2 * cfg.wavelength_m**2 / ((4 * np.pi) ** 3 * 900.0**4)
    >>> power = np.abs(frames[1, k, j]) ** 2
    >>> f"{expected:.2e}", bool(np.allclose(power, expected, rtol=1e-5))
    ('5.51e-16', True)
    """
    simulator = simulator or make_simulator(built)
    indices = np.asarray(indices)
    own, intruders = _states(built, indices, ownship)
    cfg = simulator.config
    out = np.empty((indices.size, *cfg.frame_shape), np.complex64)
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

    Parameters
    ----------
    built : BuiltScenario
    indices : ndarray of int
        Frame indices in the run.
    simulator : ImageSimulator, optional
        Default: :func:`make_simulator` of the first head.
    ownship : TrajectorySample, optional
        Replaces the scenario's own-ship sample at those frames, as in :func:`simulate_frames`.

    Returns
    -------
    (dict, dict, list of str)
        Own-ship arrays on time, intruder arrays on (time, target) (``tgt_*``, NaN where an
        intruder is absent) and the intruders' names.

    Examples
    --------
    >>> from skyradar.scene.scenario import Scenario
    >>> spec = {"name": "pair", "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    ...     "radar": {"range_limit_m": 1500}, "simulation": {"noise": False},
    ...     "ownship": {"type": "straight", "start_ned_m": [0, 0, -2000], "speed_mps": 30},
    ...     "intruders": [{"name": "A", "type": "straight", "start_ned_m": [900, 0, -2000], "speed_mps": 30}],
    ...     "frame_rate_hz": 10, "duration_s": 0.2}
    >>> built = Scenario.from_dict(spec).build()  # two frames; A flies 900 m ahead at the same velocity
    >>> own, targets, names = frames_truth(built, np.array([1]))
    >>> names, own["own_north_m"].tolist()  # 30 m/s x 0.1 s
    (['A'], [3.0])
    >>> round(float(targets["tgt_range_m"][0, 0]), 3), float(targets["tgt_radial_velocity_mps"][0, 0])
    (900.0, 0.0)
    >>> bool(targets["tgt_visible"][0, 0])
    True
    """
    simulator = simulator or make_simulator(built)
    own, intruders = _states(built, np.asarray(indices), ownship)
    targets = _intruder_truth(built, own, intruders, simulator) if intruders else {}
    return _ownship_truth(built, own), targets, [i.name for i in built.intruders]


def scenario_truth(built, simulator: Simulator | None = None) -> tuple[dict, dict, list[str]]:
    """Own-ship truth on time and intruder truth on (time, target), named as in ``skyradar.io.frames``.

    The own-ship dict also holds the navigation solution (``nav_*``,
    :func:`~skyradar.sim.navigation.navigation_variables`) beside the truth (``own_*``).

    Parameters
    ----------
    built : BuiltScenario
    simulator : ImageSimulator, optional
        Default: :func:`make_simulator` of the first head.

    Returns
    -------
    (dict, dict, list of str)
        As :func:`frames_truth` over every frame, plus the ``nav_*`` arrays.

    Examples
    --------
    >>> from skyradar.scene.scenario import Scenario
    >>> spec = {"name": "pair", "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    ...     "radar": {"range_limit_m": 1500}, "simulation": {"noise": False},
    ...     "ownship": {"type": "straight", "start_ned_m": [0, 0, -2000], "speed_mps": 30},
    ...     "intruders": [{"name": "A", "type": "straight", "start_ned_m": [900, 0, -2000], "speed_mps": 30}],
    ...     "frame_rate_hz": 10, "duration_s": 0.2}
    >>> built = Scenario.from_dict(spec).build()  # two frames; A flies 900 m ahead at the same velocity
    >>> own, targets, names = scenario_truth(built)
    >>> own["own_north_m"].tolist(), targets["tgt_range_m"].shape, "nav_north_m" in own
    ([0.0, 3.0], (2, 1), True)
    """
    ownship, targets, names = frames_truth(built, np.arange(built.times_s.size), simulator)
    # The navigation solution (nav_*) beside the truth: the chain reads only nav_*, as an aircraft
    # knows only its navigation solution.
    return ownship | navigation_variables(built, ownship), targets, names


def simulate(built, progress: Callable[[int], None] | None = None, head: int | str = 0) -> xr.Dataset:
    """Whole scenario in memory (small runs, tests), one radar head.

    Parameters
    ----------
    built : BuiltScenario
    progress : callable, optional
        Called with 1 after each frame.
    head : int or str
        The radar head's index or name.

    Returns
    -------
    xarray.Dataset
        The frames dataset (:func:`skyradar.io.frames.frames_dataset`): ``iq``, truth and
        :func:`frames_attrs`.

    Examples
    --------
    >>> from skyradar.scene.scenario import Scenario
    >>> spec = {"name": "pair", "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    ...     "radar": {"range_limit_m": 1500}, "simulation": {"noise": False},
    ...     "ownship": {"type": "straight", "start_ned_m": [0, 0, -2000], "speed_mps": 30},
    ...     "intruders": [{"name": "A", "type": "straight", "start_ned_m": [900, 0, -2000], "speed_mps": 30}],
    ...     "frame_rate_hz": 10, "duration_s": 0.2}
    >>> built = Scenario.from_dict(spec).build()  # two frames; A flies 900 m ahead at the same velocity
    >>> ds = simulate(built)
    >>> dict(ds.sizes)
    {'time': 2, 'range': 100, 'doppler': 250, 'rx': 4, 'target': 1}
    >>> ds.attrs["scenario"], bool(np.array_equal(ds.iq.values, simulate_frames(built, np.arange(2))))
    ('pair', True)
    """
    simulator = make_simulator(built, head)
    n, cfg = built.times_s.size, simulator.config
    iq = np.empty((n, *cfg.frame_shape), np.complex64)
    for i in range(n):
        iq[i] = simulate_frames(built, np.array([i]), simulator)[0]
        if progress:
            progress(1)
    ownship, targets, names = scenario_truth(built, simulator)
    return frames_dataset(iq, built.times_s, cfg, ownship, targets, names, frames_attrs(built))


def frames_attrs(built) -> dict[str, Any]:
    """The scenario attributes a frames dataset carries (name, origin, simulator options, start time).

    Parameters
    ----------
    built : BuiltScenario

    Returns
    -------
    dict
        ``scenario``, ``origin_lat_deg``, ``origin_lon_deg``, ``origin_alt_m`` (m), ``sim_options``
        (JSON of the options as strings) and, when the scenario has them, ``terrain`` and
        ``start_time``.

    Examples
    --------
    >>> from skyradar.scene.scenario import Scenario
    >>> spec = {"name": "pair", "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    ...     "radar": {"range_limit_m": 1500}, "simulation": {"noise": False},
    ...     "ownship": {"type": "straight", "start_ned_m": [0, 0, -2000], "speed_mps": 30},
    ...     "intruders": [{"name": "A", "type": "straight", "start_ned_m": [900, 0, -2000], "speed_mps": 30}],
    ...     "frame_rate_hz": 10, "duration_s": 0.2}
    >>> built = Scenario.from_dict(spec).build()  # two frames; A flies 900 m ahead at the same velocity
    >>> attrs = frames_attrs(built)
    >>> attrs["scenario"], attrs["origin_lat_deg"], json.loads(attrs["sim_options"])["noise"]
    ('pair', 52.0, 'False')
    """
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
