"""The states the image-domain simulator works with: platform, point target, antenna, terrain view."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["PlatformState", "PointTarget", "TerrainView", "AntennaGeometry"]


@dataclass(frozen=True)
class PlatformState:
    """Own-ship state in the scenario NED frame: position (m), velocity (m/s), yaw/pitch/roll (rad)."""

    position_ned_m: np.ndarray
    velocity_ned_mps: np.ndarray
    attitude_rad: np.ndarray


@dataclass(frozen=True)
class PointTarget:
    """A point scatterer (e.g. an aircraft) in the scenario NED frame with its RCS in m^2."""

    position_ned_m: np.ndarray
    velocity_ned_mps: np.ndarray
    rcs_m2: float = 1.0


@dataclass(frozen=True)
class TerrainView:
    """Terrain cropped around the antenna for one frame, and its polar horizon."""

    p_ned: np.ndarray  # grid points relative to the antenna, NED, m
    horizon: np.ndarray  # (n_az, n_h) slope -down/horizontal to beat (1 x 1 of -inf: no occlusion)
    az_bin_rad: float
    h_bin_m: float


@dataclass(frozen=True)
class AntennaGeometry:
    """Where the antenna is and how it is turned in the scenario NED frame for one frame."""

    origin_ned_m: np.ndarray  # antenna phase-centre reference point
    rot_ned_to_ant: np.ndarray  # 3x3, NED vector -> antenna-frame vector
    velocity_ned_mps: np.ndarray
    lat_deg: float  # platform position (the antenna is metres away: same crop)
    lon_deg: float
