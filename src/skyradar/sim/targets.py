"""Point targets (aircraft) in the image domain: geometry, line of sight over terrain, pixels.

A target's truth (range, radial velocity, antenna-frame angles, expected SNR) and its
contribution to a frame use the same geometry, so the truth written with a run describes exactly
what was simulated.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from skyradar.config import RadarConfig
from skyradar.geo import direction_angles
from skyradar.sim.geometry import AntennaGeometry, PointTarget, TerrainView
from skyradar.units import nearest_bin

__all__ = ["line_of_sight", "target_geometry", "add_targets"]


def line_of_sight(
    view: TerrainView | None, geom: AntennaGeometry, targets: Sequence[PointTarget]
) -> np.ndarray:
    """True for targets not hidden behind terrain (the same horizon test as terrain facets)."""
    rel = np.array([t.position_ned_m for t in targets], float).reshape(-1, 3) - geom.origin_ned_m
    if view is None:
        return np.ones(len(rel), bool)
    n_az, n_h = view.horizon.shape
    h = np.hypot(rel[:, 0], rel[:, 1])
    a = ((np.arctan2(rel[:, 1], rel[:, 0]) + np.pi) / view.az_bin_rad).astype(int) % n_az
    k = np.minimum((h / view.h_bin_m).astype(int), n_h - 1)
    return -rel[:, 2] / np.maximum(h, 1e-9) >= view.horizon[a, k]


def target_geometry(
    cfg: RadarConfig,
    geom: AntennaGeometry,
    targets: Sequence[PointTarget],
    coupling_s: float,
    clear: np.ndarray,
):
    pos = np.array([t.position_ned_m for t in targets], float).reshape(-1, 3)
    vel = np.array([t.velocity_ned_mps for t in targets], float).reshape(-1, 3)
    rcs = np.array([t.rcs_m2 for t in targets], float)
    p_ant = (pos - geom.origin_ned_m) @ geom.rot_ned_to_ant.T
    v_ant = (vel - geom.velocity_ned_mps) @ geom.rot_ned_to_ant.T
    r_tx = np.linalg.norm(p_ant - cfg.tx_position_m, axis=1)
    r_rx = np.linalg.norm(p_ant[:, None, :] - cfg.rx_positions_m[None], axis=2)
    path = r_tx[:, None] + r_rx
    rng, az, el = direction_angles(p_ant)
    u = p_ant / np.maximum(rng, 1e-9)[:, None]
    v_r = np.einsum("ij,ij->i", v_ant, u)
    half_path = path.mean(axis=1) / 2.0
    gain_db = cfg.antenna.gain_db(az, el)
    power_w = cfg.pe_w * 10 ** (gain_db / 5.0) * cfg.wavelength_m**2 * rcs / ((4 * np.pi) ** 3 * half_path**4)
    k = nearest_bin(half_path + coupling_s * v_r, cfg.range_resolution_m)  # coupling_s may differ from cfg's
    j = cfg.doppler_bin(v_r)
    in_view = (p_ant[:, 0] > 0) & (k >= 0) & (k < cfg.n_range) & clear
    return {
        "range_m": half_path,
        "radial_velocity_mps": v_r,
        "azimuth_rad": az,
        "elevation_rad": el,
        "power_w": power_w,
        "snr_db": 10 * np.log10(np.maximum(power_w, 1e-300) / cfg.noise_power_w),
        "range_bin": k,
        "doppler_bin": j,
        "visible": in_view,
        "path_m": path,
    }


def add_targets(
    cube: np.ndarray, cfg: RadarConfig, geom, targets, coupling_s: float, clear: np.ndarray
) -> None:
    g = target_geometry(cfg, geom, targets, coupling_s, clear)
    keep = g["visible"]
    if not np.any(keep):
        return
    amp = np.sqrt(g["power_w"][keep])[:, None]
    phase = 2 * np.pi * np.mod(g["path_m"][keep] / cfg.wavelength_m, 1.0)
    values = amp * np.exp(1j * phase)
    for q in range(cfg.n_rx):
        np.add.at(
            cube[..., q], (g["range_bin"][keep], g["doppler_bin"][keep]), values[:, q].astype(cube.dtype)
        )
