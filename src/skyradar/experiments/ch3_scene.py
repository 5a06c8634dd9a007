"""Scene of the ch3 experiment: radar on the ground near Delft, calibration building, clutter,
the aircraft's circuit or approach, and the 2x2 receive square of a chosen spacing.

See :mod:`skyradar.experiments.ch3` for the experiment and the spacing trade-off.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from skyradar.config import Mount, RadarConfig
from skyradar.errors import InputError
from skyradar.process.calibration import reflector_position
from skyradar.rx_layouts import square_m
from skyradar.sim.image import ImageSimulator, PlatformState, PointTarget
from skyradar.sim.impairments import ChannelErrorsConfig, NoiseConfig, channel_errors, thesis_flight_look

__all__ = ["square_array_m", "unambiguous_half_angle_deg", "build_scene", "aircraft_path"]

ORIGIN = (52.0, 4.37, 0.0)
BORESIGHT_BEARING_DEG = -37.7
BUILDING = (438.0, 5.0, -1.0, 1000.0)  # range m, az deg (right +), el deg (up +), RCS m^2
FRAME_RATE_HZ = 300 / 32.0
SPEED_MPS = {"circuit": 60.0, "approach": 70.0}
MAX_SPACING = 1.0  # wider squares wrap inside +-30 deg, within the 3 dB beam


def square_array_m(spacing_wavelengths: float, wavelength_m: float) -> np.ndarray:
    """Positions (4, 3), m, of a centred 2x2 square in the antenna y-z plane, side ``spacing * lambda``.

    ``spacing_wavelengths=0.5`` is :class:`~skyradar.config.RadarConfig`'s default layout. InputError
    outside (0, 1] wavelengths.

    Examples
    --------
    >>> np.round(square_array_m(0.5, 0.04) * 1000, 3)[:, 1:].tolist()  # (right, down) in mm
    [[-10.0, -10.0], [10.0, -10.0], [-10.0, 10.0], [10.0, 10.0]]
    """
    s = float(spacing_wavelengths)
    if not (np.isfinite(s) and 0.0 < s <= MAX_SPACING):
        raise InputError(
            f"ch3: field 'rx_spacing_wavelengths' must be in (0, {MAX_SPACING:g}] wavelengths, got {s!r}"
        )
    return square_m(s * wavelength_m)


def unambiguous_half_angle_deg(spacing_wavelengths: float) -> float:
    """Largest off-boresight angle (either axis) at which no pair of the square array wraps, deg."""
    return float(np.degrees(np.arcsin(min(1.0, 1.0 / (2.0 * spacing_wavelengths)))))


def build_scene(pitch_deg: float, seed: int, spacing: float) -> dict[str, Any]:
    """Radar (boresight ``pitch_deg`` above the horizon, 2x2 square of side ``spacing`` wavelengths),
    simulator, building and clutter, channel errors and impairments of one ch3 run.

    Everything random is drawn from ``seed`` alone, so two spacings see the same scene and noise.
    Returns a dict with ``config, platform, sim, geom, static, imp, true_gain, building_ant``.
    """
    config = RadarConfig.prototype_2022(mount=Mount(Mount.preset("sky").position_m, pitch_deg=pitch_deg))
    config = config.replace(rx_positions_m=square_array_m(spacing, config.wavelength_m))
    platform = PlatformState(
        np.array([0.0, 0.0, -2.0]), np.zeros(3), np.array([np.radians(BORESIGHT_BEARING_DEG), 0, 0])
    )
    sim = ImageSimulator(config, None, origin=ORIGIN, noise=False, seed=seed)
    geom = sim.geometry(platform)
    ant_to_ned = geom.rot_ned_to_ant.T
    rng = np.random.default_rng([seed, 3])
    building_ant = reflector_position(BUILDING[0], np.radians(BUILDING[1]), np.radians(BUILDING[2]))
    static = [PointTarget(geom.origin_ned_m + ant_to_ned @ building_ant, np.zeros(3), BUILDING[3])]
    for _ in range(6):  # trees, masts, roofs 1-7 deg above the horizon
        p = reflector_position(
            rng.uniform(150, 2000),
            np.radians(rng.uniform(-25, 25)),
            np.radians(rng.uniform(1, 7) - pitch_deg),
        )
        static.append(PointTarget(geom.origin_ned_m + ant_to_ned @ p, np.zeros(3), rng.uniform(10, 100)))
    phases = np.r_[0.0, rng.uniform(-180, 180, config.n_rx - 1)]
    gains = np.r_[0.0, rng.normal(0, 0.5, config.n_rx - 1)]
    imp = thesis_flight_look(seed).model_copy(
        update={
            "channel_errors": ChannelErrorsConfig(gain_db=gains.tolist(), phase_deg=phases.tolist()),
            "noise": NoiseConfig(),
        }
    )
    true_gain = channel_errors(config.n_rx, gains.tolist(), phases.tolist())
    return {
        "config": config,
        "platform": platform,
        "sim": sim,
        "geom": geom,
        "static": static,
        "imp": imp,
        "true_gain": true_gain,
        "building_ant": building_ant,
    }


def _racetrack(n: int = 6000) -> np.ndarray:
    """Dense circuit in (forward, right, down) from the radar: legs at +-300 m, turns reaching 500 and
    3000 m horizontal distance along boresight, 300 m above the radar."""
    near, far, half, down = 800.0, 2700.0, 300.0, -300.0
    leg = np.linspace(near, far, n)
    turn = np.linspace(0.0, np.pi, n)
    parts = [
        np.stack([leg, np.full(n, half)], axis=1),  # outbound, right of boresight
        np.stack([far + half * np.sin(turn), half * np.cos(turn)], axis=1),  # far turn through 3000 m
        np.stack([leg[::-1], np.full(n, -half)], axis=1),  # inbound
        np.stack([near - half * np.sin(turn), -half * np.cos(turn)], axis=1),  # near turn through 500 m
    ]
    fr = np.concatenate([part[1:] for part in parts])  # each part starts where the last ended
    return np.column_stack([fr, np.full(len(fr), down)])


def _approach(n: int = 4001) -> np.ndarray:
    """Dense curved, descending approach from 3000 m (quadratic Bezier) in (forward, right, down)."""
    ctrl = np.array([[2960.0, 450.0, -520.0], [1900.0, 900.0, -380.0], [700.0, -150.0, -160.0]])
    s = np.linspace(0.0, 1.0, n)[:, None]
    return (1 - s) ** 2 * ctrl[0] + 2 * s * (1 - s) * ctrl[1] + s**2 * ctrl[2]


def aircraft_path(n_frames: int, geom, path: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Frame times, NED positions and velocities of the aircraft at constant speed along ``path``."""
    if path not in ("circuit", "approach"):
        raise InputError(f"ch3: field 'path' must be 'circuit' or 'approach', got {path!r}")
    curve = _racetrack() if path == "circuit" else _approach()
    speed = SPEED_MPS[path]
    arc = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(curve, axis=0), axis=1))]
    # The circuit is flown once in n_frames; the approach at the field frame rate (thesis: 300 in 32 s).
    dt = arc[-1] / speed / n_frames if path == "circuit" else 1.0 / FRAME_RATE_HZ
    t = np.arange(n_frames) * dt
    dist = np.minimum(speed * t, arc[-1])
    tangent = np.gradient(curve, arc, axis=0)
    local = np.stack([np.interp(dist, arc, curve[:, k]) for k in range(3)], axis=1)
    local_v = speed * np.stack([np.interp(dist, arc, tangent[:, k]) for k in range(3)], axis=1)
    b = np.radians(BORESIGHT_BEARING_DEG)
    to_ned = np.array([[np.cos(b), -np.sin(b), 0.0], [np.sin(b), np.cos(b), 0.0], [0.0, 0.0, 1.0]])
    return t, geom.origin_ned_m + local @ to_ned.T, local_v @ to_ned.T
