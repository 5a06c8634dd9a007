"""Own-ship and intruder trajectories: time-tagged states in a scenario's NED frame.

A :class:`Trajectory` holds positions and velocities in the local NED frame of a geodetic
origin (see :mod:`skyradar.geo`), and attitude (yaw, pitch, roll) relative to the local
vertical *at the aircraft*, as :func:`skyradar.geo.ned_rotation_to` expects. Velocities are the
time derivatives of the NED positions, so positions interpolate as a cubic Hermite spline
through both.

Altitudes are heights above the WGS84 ellipsoid. Files that give altitude above mean sea
level (ADS-B geometric or barometric altitude) are taken as ellipsoidal heights: the geoid
undulation is the same for the terrain model and the aircraft over a few kilometres, so it
cancels in every relative quantity the radar sees.

This module holds the data type and attitude derivation; the builders live in
:mod:`skyradar.scene.flights` (parametric flights, encounters) and
:mod:`skyradar.scene.adsb` (CSV/Parquet/JSON readers), and are re-exported here.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np
from scipy.interpolate import CubicHermiteSpline

from skyradar.errors import InputError
from skyradar.geo import geodetic_to_ned, ned_rotation_to, ned_to_geodetic
from skyradar.units import wrap_angle

__all__ = [
    "GRAVITY_MPS2",
    "Trajectory",
    "TrajectorySample",
    "derive_attitude",
    "origin_to_local_rotation",
]

GRAVITY_MPS2 = 9.80665  # standard gravity, m/s^2
_TIME_TOLERANCE_S = 1e-6  # frame times computed as start + k / rate may overshoot the span by rounding
MIN_TRACK_SPEED_MPS = 0.5  # below this the track angle is noise; heading is held


@dataclass(frozen=True)
class TrajectorySample:
    """States of a trajectory at requested times (arrays of length n; vectors (n, 3)).

    Attributes
    ----------
    time_s : ndarray, shape (n,)
        The requested times, s.
    position_ned_m : ndarray, shape (n, 3)
        Positions (north, east, down) in the trajectory's NED frame, m.
    velocity_ned_mps : ndarray, shape (n, 3)
        Velocities in the same frame, m/s.
    attitude_rad : ndarray, shape (n, 3)
        (yaw, pitch, roll), rad.
    lat_deg, lon_deg : ndarray, shape (n,)
        Geodetic positions, deg.
    alt_m : ndarray, shape (n,)
        Heights above the WGS84 ellipsoid, m.

    Examples
    --------
    Made by :meth:`Trajectory.sample`; 30 m/s east from the origin is 300 m east after 10 s:

    >>> positions = [[0, 0, -1000], [0, 600, -1000]]
    >>> traj = Trajectory.from_states([0.0, 20.0], positions, origin=(52.0, 4.0, 0.0))
    >>> s = traj.sample([10.0, 20.0])
    >>> len(s), s.position_ned_m[0].tolist(), s.velocity_ned_mps[0].tolist()
    (2, [0.0, 300.0, -1000.0], [0.0, 30.0, 0.0])

    Heading east (yaw 90 deg), and 300 m east is 0.0044 deg of longitude at 52 N:

    >>> round(float(np.degrees(s.attitude_rad[0, 0])), 2)
    90.0
    >>> round(float(s.lat_deg[0]), 4), round(float(s.lon_deg[0]), 4), round(float(s.alt_m[0]), 1)
    (52.0, 4.0044, 1000.0)
    """

    time_s: np.ndarray
    position_ned_m: np.ndarray
    velocity_ned_mps: np.ndarray
    attitude_rad: np.ndarray
    lat_deg: np.ndarray
    lon_deg: np.ndarray
    alt_m: np.ndarray

    def __len__(self) -> int:
        return int(self.time_s.shape[0])


def _readonly(values: np.ndarray) -> np.ndarray:
    values = np.array(values, dtype=float)
    values.setflags(write=False)
    return values


@dataclass(frozen=True, eq=False)
class Trajectory:
    """Time-tagged aircraft states in the NED frame of ``origin``.

    Parameters
    ----------
    time_s : ndarray, shape (n,)
        Strictly increasing sample times, s.
    position_ned_m : ndarray, shape (n, 3)
        Positions (north, east, down) in the origin's NED frame, m.
    velocity_ned_mps : ndarray, shape (n, 3)
        Velocities in the same frame, m/s (time derivatives of the positions).
    attitude_rad : ndarray, shape (n, 3)
        (yaw, pitch, roll), radians, relative to the local NED frame at the aircraft.
    origin : tuple of float
        (lat_deg, lon_deg, alt_m) of the NED frame; alt above the WGS84 ellipsoid.
    name : str
        Used in messages and as the target name.
    epoch_s : float
        Unix time of ``time_s == 0`` when the source file had absolute timestamps, else NaN.

    Examples
    --------
    >>> t = np.array([0.0, 10.0])
    >>> traj = Trajectory.from_states(t, [[0, 0, -1000], [300, 0, -1000]], origin=(52.0, 4.0, 0.0))
    >>> s = traj.sample([5.0])
    >>> float(s.position_ned_m[0, 0]), float(s.velocity_ned_mps[0, 0])
    (150.0, 30.0)
    """

    time_s: np.ndarray
    position_ned_m: np.ndarray
    velocity_ned_mps: np.ndarray
    attitude_rad: np.ndarray
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    name: str = "trajectory"
    epoch_s: float = field(default=float("nan"))

    def __post_init__(self) -> None:
        t = _readonly(self.time_s)
        n = t.shape[0] if t.ndim == 1 else -1
        if n < 2:
            raise InputError(
                f"trajectory '{self.name}': field 'time_s' needs at least 2 samples, got shape {t.shape}"
            )
        for key in ("position_ned_m", "velocity_ned_mps", "attitude_rad"):
            values = _readonly(getattr(self, key))
            if values.shape != (n, 3):
                raise InputError(
                    f"trajectory '{self.name}': field '{key}' must have shape ({n}, 3), got {values.shape}"
                )
            if not np.all(np.isfinite(values)):
                row = int(np.nonzero(~np.all(np.isfinite(values), axis=1))[0][0])
                raise InputError(f"trajectory '{self.name}': field '{key}' is not finite at row {row}")
            object.__setattr__(self, key, values)
        if not np.all(np.isfinite(t)):
            raise InputError(f"trajectory '{self.name}': field 'time_s' is not finite")
        steps = np.diff(t)
        if np.any(steps <= 0):
            i = int(np.nonzero(steps <= 0)[0][0]) + 1
            raise InputError(
                f"trajectory '{self.name}': field 'time_s' is not strictly increasing "
                f"at row {i} ({t[i - 1]} -> {t[i]})"
            )
        origin = tuple(float(v) for v in self.origin)
        if len(origin) != 3 or not all(np.isfinite(origin)) or abs(origin[0]) > 90:
            raise InputError(
                f"trajectory '{self.name}': field 'origin' must be (lat_deg, lon_deg, alt_m), "
                f"got {self.origin!r}"
            )
        object.__setattr__(self, "time_s", t)
        object.__setattr__(self, "origin", origin)
        object.__setattr__(self, "epoch_s", float(self.epoch_s))

    @classmethod
    def from_states(
        cls,
        time_s: np.ndarray,
        position_ned_m: np.ndarray,
        velocity_ned_mps: np.ndarray | None = None,
        attitude_rad: np.ndarray | None = None,
        origin: tuple[float, float, float] = (0.0, 0.0, 0.0),
        name: str = "trajectory",
        epoch_s: float = float("nan"),
    ) -> Trajectory:
        """Build a trajectory, deriving what is missing.

        Missing velocities come from the positions (``np.gradient``, second order); missing
        attitude from the velocities through :func:`derive_attitude`, after rotating them into
        the local NED frame at each aircraft position.
        """
        t = np.asarray(time_s, dtype=float)
        pos = np.asarray(position_ned_m, dtype=float)
        if t.ndim != 1 or t.size < 2 or pos.shape != (t.size, 3):
            raise InputError(
                f"trajectory '{name}': need at least 2 times and (n, 3) positions, "
                f"got {t.shape} and {pos.shape}"
            )
        if np.any(np.diff(t) <= 0):
            i = int(np.nonzero(np.diff(t) <= 0)[0][0]) + 1
            raise InputError(f"trajectory '{name}': field 'time_s' is not strictly increasing at row {i}")
        vel = (
            np.gradient(pos, t, axis=0, edge_order=2 if t.size > 2 else 1)
            if velocity_ned_mps is None
            else velocity_ned_mps
        )
        vel = np.asarray(vel, dtype=float)
        if vel.shape != pos.shape:
            raise InputError(
                f"trajectory '{name}': field 'velocity_ned_mps' must have shape {pos.shape}, got {vel.shape}"
            )
        if attitude_rad is None:
            lat, lon, _ = ned_to_geodetic(pos, *origin)
            local = np.einsum("nij,nj->ni", origin_to_local_rotation(lat, lon, origin[0], origin[1]), vel)
            attitude_rad = derive_attitude(t, local)
        return cls(t, pos, vel, attitude_rad, origin, name, epoch_s)

    # ---- derived ------------------------------------------------------------------------
    @property
    def duration_s(self) -> float:
        """Time span covered, s."""
        return float(self.time_s[-1] - self.time_s[0])

    @property
    def start_s(self) -> float:
        return float(self.time_s[0])

    @property
    def end_s(self) -> float:
        return float(self.time_s[-1])

    def __len__(self) -> int:
        return int(self.time_s.shape[0])

    @cached_property
    def _spline(self) -> CubicHermiteSpline:
        return CubicHermiteSpline(self.time_s, self.position_ned_m, self.velocity_ned_mps, axis=0)

    @cached_property
    def _unwrapped_attitude(self) -> np.ndarray:
        # Yaw and roll may cross +-pi; interpolate them on the continuous branch.
        att = self.attitude_rad.copy()
        att[:, 0] = np.unwrap(att[:, 0])
        att[:, 2] = np.unwrap(att[:, 2])
        return att

    def covers(self, times_s: np.ndarray | float) -> np.ndarray:
        """Boolean mask of the times inside the trajectory's span (with a 1 us tolerance)."""
        t = np.atleast_1d(np.asarray(times_s, dtype=float))
        return (t >= self.time_s[0] - _TIME_TOLERANCE_S) & (t <= self.time_s[-1] + _TIME_TOLERANCE_S)

    def sample(self, times_s: np.ndarray | float) -> TrajectorySample:
        """States at ``times_s`` (s): Hermite position, its derivative as velocity, angle-aware attitude.

        The velocity is the derivative of the position spline, not an interpolation of the sampled
        velocities: between sparse samples (ADS-B gives a state every 5-12 s) a turning aircraft's
        interpolated velocity differs from the motion of its position by metres per second, and a
        simulated radar would then see a Doppler that disagrees with the range rate.

        Raises :class:`InputError` naming the trajectory when a time is outside its span.
        """
        t = np.atleast_1d(np.asarray(times_s, dtype=float))
        if t.ndim != 1:
            raise InputError(f"trajectory '{self.name}': sample times must be 1-D, got shape {t.shape}")
        inside = self.covers(t)
        if not np.all(inside):
            bad = float(t[~inside][0])
            raise InputError(
                f"trajectory '{self.name}': time {bad:.6g} s is outside its span "
                f"[{self.time_s[0]:.6g}, {self.time_s[-1]:.6g}] s"
            )
        t = np.clip(t, self.time_s[0], self.time_s[-1])
        pos = self._spline(t)
        vel = self._spline(t, 1)
        att = np.stack([np.interp(t, self.time_s, self._unwrapped_attitude[:, k]) for k in range(3)], axis=-1)
        att[:, [0, 2]] = wrap_angle(att[:, [0, 2]])
        lat, lon, alt = ned_to_geodetic(pos, *self.origin)
        return TrajectorySample(t, pos, vel, att, np.atleast_1d(lat), np.atleast_1d(lon), np.atleast_1d(alt))

    # ---- transforms ---------------------------------------------------------------------
    def shifted(self, dt_s: float) -> Trajectory:
        """The same flight ``dt_s`` seconds later."""
        return replace(self, time_s=self.time_s + float(dt_s), epoch_s=self.epoch_s - float(dt_s))

    def between(self, start_s: float, end_s: float) -> Trajectory:
        """The part of the flight from ``start_s`` to ``end_s`` (s), its samples there and both ends.

        Examples
        --------
        >>> t = np.arange(0.0, 101.0, 10.0)
        >>> traj = Trajectory.from_states(t, np.column_stack([50 * t, 0 * t, 0 * t - 500]))
        >>> part = traj.between(15.0, 42.0)
        >>> part.time_s.tolist(), float(part.sample([42.0]).position_ned_m[0, 0])
        ([15.0, 20.0, 30.0, 40.0, 42.0], 2100.0)
        """
        start, end = max(float(start_s), self.start_s), min(float(end_s), self.end_s)
        if not end > start:
            raise InputError(
                f"trajectory '{self.name}': [{start_s:g}, {end_s:g}] s is outside its span "
                f"[{self.start_s:g}, {self.end_s:g}] s"
            )
        inner = (self.time_s > start) & (self.time_s < end)
        times = np.concatenate([[start], self.time_s[inner], [end]])
        s = self.sample(times)
        att = np.vstack([s.attitude_rad[:1], self.attitude_rad[inner], s.attitude_rad[-1:]])
        return replace(
            self,
            time_s=times,
            position_ned_m=s.position_ned_m,
            velocity_ned_mps=s.velocity_ned_mps,
            attitude_rad=att,
        )

    def renamed(self, name: str) -> Trajectory:
        return replace(self, name=name)

    def reframed(self, new_origin: tuple[float, float, float]) -> Trajectory:
        """The same flight expressed in the NED frame of ``new_origin`` (exact, through geodetic).

        Attitude is relative to the local vertical at the aircraft, so it does not change.
        """
        lat0, lon0, alt0 = (float(v) for v in new_origin)
        lat, lon, alt = ned_to_geodetic(self.position_ned_m, *self.origin)
        pos = geodetic_to_ned(lat, lon, alt, lat0, lon0, alt0)
        # Both NED frames are fixed: one constant rotation takes vectors from the old to the new.
        rot = ned_rotation_to(self.origin[0], self.origin[1], lat0, lon0)
        vel = self.velocity_ned_mps @ rot.T
        return replace(self, position_ned_m=pos, velocity_ned_mps=vel, origin=(lat0, lon0, alt0))


def _ecef_from_ned(lat_deg: np.ndarray | float, lon_deg: np.ndarray | float) -> np.ndarray:
    # Columns are the N, E, D unit vectors in ECEF; shape (..., 3, 3).
    lat, lon = np.radians(lat_deg), np.radians(lon_deg)
    sl, cl, so, co = np.sin(lat), np.cos(lat), np.sin(lon), np.cos(lon)
    rows = [[-sl * co, -so, -cl * co], [-sl * so, co, -cl * so], [cl, np.zeros_like(lat), -sl]]
    return np.stack([np.stack(row, axis=-1) for row in rows], axis=-2)


def origin_to_local_rotation(
    lat_deg: np.ndarray, lon_deg: np.ndarray, lat0_deg: float, lon0_deg: float
) -> np.ndarray:
    """Rotations (n, 3, 3) taking origin-NED vectors to the local NED frame at each (lat, lon).

    Vectorised :func:`skyradar.geo.ned_rotation_to`; the transpose goes the other way.

    Examples
    --------
    >>> from skyradar.geo import ned_rotation_to
    >>> r = origin_to_local_rotation(np.array([52.1]), np.array([4.2]), 52.0, 4.0)[0]
    >>> bool(np.allclose(r, ned_rotation_to(52.0, 4.0, 52.1, 4.2)))
    True
    """
    local = _ecef_from_ned(
        np.atleast_1d(np.asarray(lat_deg, float)), np.atleast_1d(np.asarray(lon_deg, float))
    )
    return np.swapaxes(local, -1, -2) @ _ecef_from_ned(np.float64(lat0_deg), np.float64(lon0_deg))


def _moving_mean(time_s: np.ndarray, values: np.ndarray, window_s: float) -> np.ndarray:
    """Centred mean over +-window_s/2 (time-based, so uneven sampling is fine)."""
    if window_s <= 0 or values.size < 3:
        return values
    lo = np.searchsorted(time_s, time_s - window_s / 2.0, side="left")
    hi = np.searchsorted(time_s, time_s + window_s / 2.0, side="right")
    csum = np.concatenate([[0.0], np.cumsum(values)])
    return (csum[hi] - csum[lo]) / (hi - lo)


def derive_attitude(
    time_s: np.ndarray, velocity_ned_mps: np.ndarray, smooth_s: float = 2.0, g_mps2: float = GRAVITY_MPS2
) -> np.ndarray:
    """Attitude (yaw, pitch, roll) in radians of an aircraft flying coordinated along its velocity.

    Heading is the track ``atan2(ve, vn)``, pitch the flight-path angle ``atan2(-vd, ground
    speed)`` and bank that of a coordinated turn, ``roll = atan(V * turn_rate / g)``, with the
    turn rate the derivative of the unwrapped track, smoothed by a centred ``smooth_s`` mean.
    ``V`` is the full (3-D) speed: for a steady climbing turn at flight-path angle gamma the
    lift balances ``g cos(gamma)`` and the horizontal ``V cos(gamma) * turn_rate``, so
    ``tan(roll) = V * turn_rate / g`` holds exactly.
    No wind: heading equals track, angle of attack and sideslip are zero. Where the ground
    speed is below 0.5 m/s the last heading is held.

    Parameters
    ----------
    time_s : ndarray, shape (n,)
        Strictly increasing times, s.
    velocity_ned_mps : ndarray, shape (n, 3)
        Velocities in the local NED frame, m/s.

    Examples
    --------
    >>> t = np.linspace(0.0, 60.0, 601)
    >>> w = 0.1  # rad/s: a 50 m/s circle of 500 m radius, clockwise
    >>> v = np.stack([-50 * np.sin(w * t), 50 * np.cos(w * t), 0 * t], axis=1)
    >>> roll = derive_attitude(t, v)[300, 2]
    >>> bool(abs(roll - np.arctan(50.0**2 / (GRAVITY_MPS2 * 500.0))) < 1e-6)
    True
    """
    t = np.asarray(time_s, dtype=float)
    v = np.asarray(velocity_ned_mps, dtype=float)
    if t.ndim != 1 or v.shape != (t.size, 3):
        raise InputError(
            f"derive_attitude: need times (n,) and velocities (n, 3), got {t.shape} and {v.shape}"
        )
    ground = np.hypot(v[:, 0], v[:, 1])
    track = np.arctan2(v[:, 1], v[:, 0])
    moving = ground >= MIN_TRACK_SPEED_MPS
    if np.any(moving) and not np.all(moving):
        # Hold the last valid track (first valid one before any motion).
        idx = np.where(moving, np.arange(t.size), -1)
        idx = np.maximum.accumulate(idx)
        idx[idx < 0] = int(np.argmax(moving))
        track = track[idx]
    yaw_unwrapped = np.unwrap(track)
    turn_rate = np.gradient(yaw_unwrapped, t) if t.size > 1 else np.zeros_like(t)
    turn_rate = _moving_mean(t, turn_rate, smooth_s)
    speed = np.linalg.norm(v, axis=1)
    roll = np.arctan(speed * turn_rate / g_mps2)
    pitch = np.arctan2(-v[:, 2], ground)
    return np.stack([wrap_angle(track), pitch, roll], axis=-1)


_REEXPORTS = {
    "read_trajectory": "skyradar.scene.adsb",
    "read_trajectories": "skyradar.scene.adsb",
    "straight": "skyradar.scene.flights",
    "circle": "skyradar.scene.flights",
    "circuit": "skyradar.scene.flights",
    "encounter": "skyradar.scene.flights",
}


def __getattr__(name: str):
    # Builders and readers live in their own modules (which import this one); re-export lazily
    # so that ``skyradar.scene.trajectories`` is the one entry point without an import cycle.
    if name in _REEXPORTS:
        import importlib

        return getattr(importlib.import_module(_REEXPORTS[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
