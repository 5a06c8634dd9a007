"""3-D tracks on direction-of-arrival positions, associated through the range-Doppler tracker.

DoA positions are too noisy to associate on their own (tens of metres at a few km, seed-brief.md
ch3), while range and radial velocity are measured to a pixel. So association is done once, in
range-Doppler, and every range-Doppler track owns one 3-D constant-velocity Kalman filter in the
scenario NED frame, state ``(north, east, down, vn, ve, vd)`` [m, m/s], updated with the position of
the detection its range-Doppler track was assigned. The filter carries its covariance.
"""

from __future__ import annotations

import numpy as np

from skyradar.track.kalman import predict, update

__all__ = ["Tracker3D", "cv3d_transition", "cv3d_process_noise"]

_H3 = np.hstack([np.eye(3), np.zeros((3, 3))])


def cv3d_transition(dt_s: float) -> np.ndarray:
    """Constant-velocity transition for ``(p, v)`` in 3-D, 6x6.

    Examples
    --------
    >>> float(cv3d_transition(2.0)[0, 3])
    2.0
    """
    F = np.eye(6)
    F[:3, 3:] = dt_s * np.eye(3)
    return F


def cv3d_process_noise(dt_s: float, sigma_accel_mps2: float) -> np.ndarray:
    """White-acceleration process noise for ``(p, v)`` in 3-D, 6x6."""
    q = sigma_accel_mps2**2
    block = np.array([[dt_s**3 / 3, dt_s**2 / 2], [dt_s**2 / 2, dt_s]]) * q
    return np.kron(block, np.eye(3))


class Tracker3D:
    """One 3-D constant-velocity Kalman filter per range-Doppler track id.

    Parameters
    ----------
    sigma_accel_mps2 : float
        Process noise (white acceleration), m/s^2.
    init_sigma_velocity_mps : float
        Prior standard deviation of each velocity component of a new filter, m/s.

    Examples
    --------
    >>> t3 = Tracker3D()
    >>> _ = t3.step(0.0, np.array([7]), np.array([[100.0, 0.0, -50.0]]), np.array([400.0]))
    >>> x, P = t3.step(1.0, np.array([7]), np.array([[110.0, 0.0, -50.0]]), np.array([400.0]))
    >>> bool(100.0 < x[0, 0] < 110.0), bool(x[0, 3] > 0)
    (True, True)
    """

    def __init__(self, sigma_accel_mps2: float = 3.0, init_sigma_velocity_mps: float = 60.0) -> None:
        self.sigma_accel_mps2 = float(sigma_accel_mps2)
        self.init_sigma_velocity_mps = float(init_sigma_velocity_mps)
        self.ids = np.zeros(0, np.int64)
        self.x = np.zeros((0, 6))
        self.P = np.zeros((0, 6, 6))
        self.time_s: float | None = None

    def step(
        self, time_s: float, ids: np.ndarray, positions_m: np.ndarray, variances_m2: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Move every filter to ``time_s`` and update those whose track has a 3-D position.

        Parameters
        ----------
        time_s : float
            Frame time, s.
        ids : ndarray of int, shape (k,)
            Range-Doppler track ids alive in this frame, increasing; ids not listed are dropped.
        positions_m : ndarray, shape (k, 3)
            NED position of the detection assigned to each track; NaN rows when none.
        variances_m2 : ndarray, shape (k,)
            Per-axis variance of each position, m^2.

        Returns
        -------
        x : ndarray, shape (k, 6)
            (north, east, down, vn, ve, vd); NaN for ids that never had a 3-D position.
        P : ndarray, shape (k, 6, 6)
        """
        ids = np.asarray(ids, np.int64)
        keep = np.isin(self.ids, ids)
        self.ids, self.x, self.P = self.ids[keep], self.x[keep], self.P[keep]
        if self.time_s is not None and self.ids.size and time_s > self.time_s:
            dt = time_s - self.time_s
            self.x, self.P = predict(
                self.x, self.P, cv3d_transition(dt), cv3d_process_noise(dt, self.sigma_accel_mps2)
            )
        self.time_s = float(time_s)
        has = np.all(np.isfinite(positions_m), axis=1)
        pos, known = _lookup(self.ids, ids)
        upd = has & known
        if np.any(upd):
            rows = pos[upd]
            R = variances_m2[upd][:, None, None] * np.eye(3)
            y = positions_m[upd] - self.x[rows, :3]
            self.x[rows], self.P[rows] = update(self.x[rows], self.P[rows], y, _H3, R)
        new = has & ~known
        if np.any(new):
            self._add(ids[new], positions_m[new], variances_m2[new])
        out_x = np.full((ids.size, 6), np.nan)
        out_P = np.full((ids.size, 6, 6), np.nan)
        pos, found = _lookup(self.ids, ids)
        out_x[found] = self.x[pos[found]]
        out_P[found] = self.P[pos[found]]
        return out_x, out_P

    def _add(self, ids: np.ndarray, positions_m: np.ndarray, variances_m2: np.ndarray) -> None:
        x = np.hstack([positions_m, np.zeros((ids.size, 3))])
        P = np.zeros((ids.size, 6, 6))
        P[:, [0, 1, 2], [0, 1, 2]] = variances_m2[:, None]
        P[:, [3, 4, 5], [3, 4, 5]] = self.init_sigma_velocity_mps**2
        order = np.argsort(np.concatenate([self.ids, ids]), kind="stable")
        self.ids = np.concatenate([self.ids, ids])[order]
        self.x = np.concatenate([self.x, x])[order]
        self.P = np.concatenate([self.P, P])[order]


def _lookup(stored: np.ndarray, ids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Row of each id in the sorted ``stored`` ids, and whether it is there."""
    if stored.size == 0:
        return np.zeros(ids.size, int), np.zeros(ids.size, bool)
    pos = np.searchsorted(stored, ids)
    found = stored[np.minimum(pos, stored.size - 1)] == ids
    return np.minimum(pos, stored.size - 1), found
