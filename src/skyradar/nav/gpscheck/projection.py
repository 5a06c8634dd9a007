"""A side-looking radar frame projected onto the flat ground around the aircraft (Maas 2022, ch. 6).

The thesis put each range-Doppler pixel of a wingtip radar on the ground plane: the range bin gives
a sphere around the antenna, the Doppler bin a cone around the velocity vector (radial velocity
``v_r = -|v| cos(angle to the velocity)`` for static ground), and their intersection with the flat
ground gives two points, one either side of the track; the side the antenna looks at picks one.

Here the same geometry runs the other way, so every ground pixel gets a value and none is hit
twice: each pixel of a body-aligned :class:`~skyradar.scene.ground_grid.PoseGrid` (rows forward,
columns right of the aircraft, origin on the ground below the aircraft's reference point) is
a ground point at ``height_m`` below the aircraft; its slant range and radial velocity from the
antenna give its (fractional) range and Doppler bins through the same conversions the simulator
bins with (:meth:`RadarConfig.range_bin` conventions: sawtooth range-Doppler coupling, Doppler
wrapping), and the frame's power there is read bilinearly. Pixels behind the antenna or outside
its beam (the mirror side of the track) and beyond the processed range are NaN: the left/right
ambiguity is resolved by the antenna's side exactly as in the thesis.

The grid is aligned with the heading (``attitude_rad[0]``), not with the rolled and pitched body,
so a map rendered at a pose ``(north, east, heading)`` with
:func:`~skyradar.scene.ground_grid.sample_at_pose` lies on the same pixels.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.geo import direction_angles, rotation_matrix
from skyradar.process.power import power_image
from skyradar.scene.ground_grid import PoseGrid

__all__ = ["frame_power", "antenna_pose", "ground_image", "ground_in_view_fraction"]


def frame_power(iq: np.ndarray) -> np.ndarray:
    """Power per range-Doppler pixel, the mean of ``|iq|^2`` over receive antennas (W).

    Examples
    --------
    >>> frame_power(np.full((2, 3, 4), 1 + 1j, np.complex64)).tolist()[0]
    [2.0, 2.0, 2.0]
    """
    iq = np.asarray(iq)
    if iq.ndim == 2:
        return np.abs(iq) ** 2
    if iq.ndim != 3:
        raise InputError(f"gpscheck: a frame must be (range, doppler[, rx]), got shape {iq.shape}")
    return power_image(iq)  # the one channel-mean power image (skyradar.process.power)


def antenna_pose(
    config: RadarConfig, attitude_rad: Sequence[float] | np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Antenna phase centre relative to the aircraft (NED, m) and the NED-to-antenna rotation.

    Flat local frame: the attitude (yaw, pitch, roll) is relative to the local vertical.

    Examples
    --------
    >>> from skyradar.config import Mount
    >>> cfg = RadarConfig.prototype_2022(mount=Mount.preset("side-right"))
    >>> offset, rot = antenna_pose(cfg, (0.0, 0.0, 0.0))
    >>> np.round(offset, 3).tolist(), np.round(rot[0], 3).tolist()  # boresight right and down
    ([0.0, 5.0, 0.0], [0.0, 0.866, 0.5])
    """
    yaw, pitch, roll = (float(a) for a in attitude_rad)
    body_to_ned = rotation_matrix(yaw, pitch, roll)
    ant_to_ned = body_to_ned @ config.mount.rotation
    return body_to_ned @ np.asarray(config.mount.position_m, float), ant_to_ned.T


def _check_state(attitude_rad, velocity_ned_mps, height_m: float) -> tuple[np.ndarray, np.ndarray]:
    att = np.asarray(attitude_rad, float).reshape(-1)
    vel = np.asarray(velocity_ned_mps, float).reshape(-1)
    if att.size != 3 or not np.all(np.isfinite(att)):
        raise InputError(f"gpscheck: attitude_rad must be 3 finite angles (yaw, pitch, roll), got {att}")
    if vel.size != 3 or not np.all(np.isfinite(vel)):
        raise InputError(f"gpscheck: velocity_ned_mps must be 3 finite numbers, got {vel}")
    if not (np.isfinite(height_m) and height_m > 0):
        raise InputError(f"gpscheck: height_m (above ground) must be a positive number, got {height_m!r}")
    return att, vel


def _check_power(power_rd: np.ndarray, config: RadarConfig) -> np.ndarray:
    power_rd = np.asarray(power_rd, float)
    if power_rd.shape != (config.n_range, config.n_doppler):
        raise InputError(
            f"gpscheck: frame power has shape {power_rd.shape}, expected (range, doppler) = "
            f"{(config.n_range, config.n_doppler)}"
        )
    return power_rd


def _bilinear_rd(power_rd: np.ndarray, k: np.ndarray, j: np.ndarray) -> np.ndarray:
    """Bilinear read at fractional (range bin k, Doppler bin j); Doppler wraps, range does not."""
    n_range, n_doppler = power_rd.shape
    k0 = np.floor(k).astype(np.int64)
    j0 = np.floor(j).astype(np.int64)
    tk, tj = k - k0, j - j0
    k1 = np.minimum(k0 + 1, n_range - 1)
    k0c = np.clip(k0, 0, n_range - 1)
    j0w, j1w = j0 % n_doppler, (j0 + 1) % n_doppler
    top = power_rd[k0c, j0w] * (1 - tj) + power_rd[k0c, j1w] * tj
    bottom = power_rd[k1, j0w] * (1 - tj) + power_rd[k1, j1w] * tj
    return top * (1 - tk) + bottom * tk


def ground_image(
    power_rd: np.ndarray,
    config: RadarConfig,
    pose_grid: PoseGrid,
    attitude_rad: Sequence[float] | np.ndarray,
    velocity_ned_mps: Sequence[float] | np.ndarray,
    height_m: float,
    beam_db: float = -10.0,
    compensate: bool = False,
) -> np.ndarray:
    """Project one frame's range-Doppler power onto the flat ground on a body-aligned grid.

    Parameters
    ----------
    power_rd : (n_range, n_doppler) array
        The frame's power (:func:`frame_power` of its ``iq``), any linear unit.
    config : RadarConfig
        The radar that made the frame, with its (side-looking) mount.
    pose_grid : PoseGrid
        Ground pixels in horizontal body axes (forward, right) around the point below the aircraft.
    attitude_rad : (yaw, pitch, roll)
        Aircraft attitude, rad; the grid turns with the yaw (heading).
    velocity_ned_mps, height_m : (3,) array, float
        Aircraft velocity over the ground (NED), m/s, and height above the flat ground, m.
    beam_db : float
        NaN where the one-way gain is below peak + ``beam_db`` (outside the beam: the mirror side).
    compensate : bool
        Divide by the flat-ground expectation ``G^2 (h / R)^4`` (the near-range brightening).

    Returns
    -------
    float32 array of ``pose_grid.shape``; NaN where the ground is not seen.

    Examples
    --------
    A point 300 m right of an aircraft at 200 m flying north lights the pixel it was put in:

    >>> from skyradar.config import Mount
    >>> cfg = RadarConfig.prototype_2022(
    ...     bandwidth_hz=50e6, fs_hz=40e6, prf_hz=10e3, range_limit_m=600.0,
    ...     mount=Mount(yaw_deg=90.0, pitch_deg=-30.0))
    >>> power = np.zeros((cfg.n_range, cfg.n_doppler))
    >>> power[int(cfg.range_bin(np.hypot(300.0, 200.0))), int(cfg.doppler_bin(0.0))] = 1.0
    >>> grid = PoseGrid(-50.0, 250.0, 5.0, (21, 21))
    >>> image = ground_image(power, cfg, grid, (0.0, 0.0, 0.0), (50.0, 0.0, 0.0), 200.0)
    >>> i, j = np.unravel_index(np.nanargmax(image), image.shape)
    >>> float(grid.forward_m[i]), float(grid.right_m[j])
    (0.0, 300.0)
    """
    att, vel = _check_state(attitude_rad, velocity_ned_mps, height_m)
    power_rd = _check_power(power_rd, config)
    k, j, gain_db, rng = _pixel_bins(config, pose_grid, att, vel, height_m)
    image = _bilinear_rd(power_rd, k, j)
    if compensate:
        expected = 10.0 ** (gain_db / 5.0) * (height_m / rng) ** 4
        image = image / np.maximum(expected, 1e-30)
    seen = np.isfinite(gain_db) & (gain_db >= beam_db) & (k <= config.n_range - 1)
    return np.where(seen, image, np.nan).astype(np.float32)


def _pixel_bins(
    config: RadarConfig, pose_grid: PoseGrid, att: np.ndarray, vel: np.ndarray, height_m: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Fractional range and Doppler bins of every ground pixel, its one-way gain below the peak (dB;
    -inf behind the antenna) and its slant range (m)."""
    p_ant, rng = _ground_vectors(config, pose_grid, att, height_m)
    u = p_ant / np.maximum(rng, 1e-9)[..., None]
    _, rot = antenna_pose(config, att)
    v_r = -(u @ (rot @ vel))  # static ground moves at -v relative to the radar; receding positive
    k = (rng + v_r * config.range_doppler_coupling_s) / config.range_resolution_m
    j = v_r / config.doppler_resolution_mps + config.n_doppler // 2
    _, az, el = direction_angles(p_ant)
    gain_db = np.where(p_ant[..., 0] > 0, config.antenna.gain_db(az, el) - config.antenna.peak_db, -np.inf)
    return k, j, gain_db, rng


def _ground_vectors(
    config: RadarConfig, pose_grid: PoseGrid, attitude_rad: np.ndarray, height_m: float
) -> tuple[np.ndarray, np.ndarray]:
    """Antenna-frame vectors to every grid pixel on the ground, and their lengths (slant range)."""
    offset, rot = antenna_pose(config, attitude_rad)
    north, east = pose_grid.world_points(0.0, 0.0, float(attitude_rad[0]))
    down = np.full_like(north, height_m - offset[2])
    p_ned = np.stack([north - offset[0], east - offset[1], down], axis=-1)
    p_ant = p_ned @ rot.T
    return p_ant, np.linalg.norm(p_ant, axis=-1)


def ground_in_view_fraction(
    config: RadarConfig, attitude_rad: Sequence[float] | np.ndarray, height_m: float, n: int = 61
) -> float:
    """Share of the beam's two-way energy that falls on the ground within the processed range.

    Directions over the antenna's forward hemisphere are weighted by the two-way gain ``G^2``;
    a direction counts when it points below the horizon and meets flat ground ``height_m`` below
    at a slant range up to ``config.range_limit_m``. Level flight with a side mount pitched 30 deg
    down sees mostly ground; in a turn with that wing up the beam looks at the sky and the share
    drops towards 0: such a frame cannot be checked against a map.

    Examples
    --------
    >>> from skyradar.config import Mount
    >>> cfg = RadarConfig.prototype_2022(range_limit_m=1000.0, mount=Mount.preset("side-right"))
    >>> level = ground_in_view_fraction(cfg, (0.0, 0.0, 0.0), 200.0)
    >>> wing_up = ground_in_view_fraction(cfg, (0.0, 0.0, np.radians(-45.0)), 200.0)
    >>> level > 0.5, wing_up < 0.1
    (True, True)
    """
    att, _ = _check_state(attitude_rad, (0.0, 0.0, 0.0), height_m)
    offset, rot = antenna_pose(config, att)
    angles = np.linspace(-np.pi / 2, np.pi / 2, n)
    az, el = np.meshgrid(angles, angles, indexing="ij")
    u_ant = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)], axis=-1)
    weight = 10.0 ** (config.antenna.gain_db(az, el) / 5.0) * np.cos(el)  # G^2 dOmega
    down = (u_ant @ rot)[..., 2]  # NED down component of each direction
    antenna_height = height_m - offset[2]
    hits = (down > 0) & (antenna_height <= config.range_limit_m * down)
    return float(weight[hits].sum() / weight.sum())
