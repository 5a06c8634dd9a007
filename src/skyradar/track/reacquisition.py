"""Reacquisition of lost tracks: one track id per aircraft through detection gaps of several seconds.

The deleter (:class:`~skyradar.track.deletion.MissDeleter`) closes a confirmed track after a short
coasting time (2 s): coasting longer would let the track's gate, which grows with the model's white
jerk, take any detection within a large part of the image. An aircraft that fades for a few seconds
(beam edge, SNR dip, a turn) then comes back as a new track, a fragment. This role keeps the closed
confirmed tracks for ``max_age_s`` seconds instead of forgetting them, without reporting or gating
them. A track that was closing on the own-ship when it was lost is kept longer, up to the time its
range would take to reach zero at its range rate, at most ``closing_max_age_s``: that time bounds
its closest approach from above (a crossing's range falls slower than its relative speed), and a
closing aircraft is a threat until it has passed, however long a clutter ridge hides it. When a
new track is confirmed (M-of-N, so never on one clutter point), it is compared with
every lost track predicted to the same time with a gentler process noise (``q_jerk_mps3``, the
jerk an aircraft sustains over seconds rather than the frame-to-frame one); a pair within the
chi-square gate gives the new track the lost track's id (Hungarian assignment on the Mahalanobis
distance, each lost track used once). The comparison is done on the observed range and radial
velocity (``H x``, so an unresolved Doppler alias and the range-Doppler coupling of the new track do
not matter), with the Doppler difference wrapped the short way round the image; the new track then
takes the lost track's alias of the radial velocity when the prediction's velocity uncertainty is
small enough to choose it.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.optimize import linear_sum_assignment

from skyradar.track.association import pair_costs
from skyradar.track.kalman import predict
from skyradar.track.models import MotionModel
from skyradar.track.types import TrackArrays
from skyradar.units import wrap

__all__ = ["LostTracks", "manoeuvre_transition"]


class LostTracks:
    """Closed confirmed tracks kept for reacquisition by a newly confirmed track.

    Parameters
    ----------
    model : MotionModel
        The tracker's motion model (prediction, measurement matrix and noise).
    max_age_s : float
        A lost track is forgotten this long after it was closed, s (0 disables reacquisition).
    closing_max_age_s : float
        A lost track closing on the own-ship is forgotten at its range over its closing speed after
        it was closed, at most this long and never before ``max_age_s``, s (0: as the others).
    q_jerk_mps3 : float
        White jerk of the prediction across the gap, m/s^3.
    gate : float
        Chi-square gate (2 degrees of freedom) on the difference of the observed states.
    resolve_sd_mps : float
        The new track takes the lost track's alias when the predicted radial velocity's standard
        deviation is below this, m/s.
    tau_s, sigma_accel_mps2 : float
        Across the gap the radial acceleration is a manoeuvre that decays with time constant
        ``tau_s`` (Singer's model): a circling glider's radial acceleration changes sign within
        seconds, and extrapolating it unchanged over a gap misses the aircraft. Its uncertainty
        grows by ``sigma_accel_mps2`` (radar model only).

    Examples
    --------
    >>> from skyradar.track.models import radar_model
    >>> lost = LostTracks(radar_model(78.3))
    >>> x = np.array([[2000.0, -60.0, -60.0, 0.0]])
    >>> lost.add(np.array([4]), x, np.diag([16.0, 0.04, 1.0, 0.25])[None], np.array([True]), 10.0)
    >>> new = np.array([[1760.0, 18.3, 18.3, 0.0]])  # 4 s later, radial velocity aliased by +W
    >>> ids, alias = lost.match(new, np.diag([16.0, 0.04, 900.0, 1.0])[None], 14.0)
    >>> ids.tolist(), alias.tolist()
    ([4], [-1.0])
    """

    def __init__(
        self,
        model: MotionModel,
        max_age_s: float = 8.0,
        q_jerk_mps3: float = 1.5,
        gate: float = 16.0,
        resolve_sd_mps: float = 13.0,
        tau_s: float = 2.0,
        sigma_accel_mps2: float = 4.0,
        closing_max_age_s: float = 0.0,
    ) -> None:
        if max_age_s < 0 or not q_jerk_mps3 > 0 or not gate > 0 or not closing_max_age_s >= 0:
            raise ValueError(
                "need max_age_s >= 0, q_jerk_mps3 > 0, gate > 0, closing_max_age_s >= 0; got "
                f"{max_age_s}, {q_jerk_mps3}, {gate}, {closing_max_age_s}"
            )
        self.closing_max_age_s = float(closing_max_age_s)
        self.model = model
        self.tau_s, self.sigma_accel_mps2 = float(tau_s), float(sigma_accel_mps2)
        self._gentle = replace(model, q_velocity_mps3=float(q_jerk_mps3), q_range_mps2=float(q_jerk_mps3))
        self.max_age_s, self.gate, self.resolve_sd_mps = float(max_age_s), float(gate), float(resolve_sd_mps)
        self.ids = np.zeros(0, np.int64)
        self.x = np.zeros((0, 4))
        self.P = np.zeros((0, 4, 4))
        self.resolved = np.zeros(0, bool)
        self.time_s = np.zeros(0)
        self.memory_s = np.zeros(0)

    def __len__(self) -> int:
        return int(self.ids.size)

    def add(
        self, ids: np.ndarray, x: np.ndarray, P: np.ndarray, resolved: np.ndarray, time_s: np.ndarray | float
    ) -> None:
        """Keep closed tracks: states ``x`` (k, 4) and covariances ``P`` (k, 4, 4) at ``time_s``."""
        if self.max_age_s == 0 or len(ids) == 0:
            return
        resolved = np.asarray(resolved, bool)
        self.ids = np.concatenate([self.ids, np.asarray(ids, np.int64)])
        self.x = np.concatenate([self.x, x])
        self.P = np.concatenate([self.P, P])
        self.resolved = np.concatenate([self.resolved, resolved])
        self.time_s = np.concatenate([self.time_s, np.broadcast_to(np.asarray(time_s, float), (len(ids),))])
        self.memory_s = np.concatenate([self.memory_s, self.memory_of(x, resolved)])

    def memory_of(self, x: np.ndarray, resolved: np.ndarray) -> np.ndarray:
        """How long lost tracks of states ``x`` (k, 4) are kept, s: ``max_age_s``, or for a closing
        track its range over its closing speed when longer, at most ``closing_max_age_s``.

        The closing speed is the rate the range follows: the radial velocity once the alias is
        resolved (radar model), the range-rate state before it.

        Examples
        --------
        >>> from skyradar.track.models import radar_model
        >>> lost = LostTracks(radar_model(78.3), closing_max_age_s=25.0)
        >>> x = np.array([[2000.0, -100.0, -100.0, 0.0], [2000.0, 60.0, 60.0, 0.0]])
        >>> lost.memory_of(x, np.array([True, True])).tolist()  # closing, receding
        [20.0, 8.0]
        """
        x = np.asarray(x, float)
        follows_radial = (np.asarray(resolved, bool) | (not self.model.dealias)) & self.model.coupled
        rate = np.where(follows_radial, x[:, 1], x[:, 2])
        with np.errstate(divide="ignore", invalid="ignore"):
            to_zero = np.where(rate < 0.0, x[:, 0] / -rate, 0.0)
        to_zero = np.where(np.isfinite(to_zero), to_zero, 0.0)
        return np.maximum(self.max_age_s, np.minimum(to_zero, self.closing_max_age_s))

    def add_anchored(self, tracks: TrackArrays, mask: np.ndarray) -> None:
        """Keep the tracker's tracks ``mask`` at their anchors
        (:meth:`~skyradar.track.types.TrackArrays.set_anchor`)."""
        self.add(
            tracks.ids[mask],
            tracks.anchor_x[mask],
            tracks.anchor_P[mask],
            tracks.anchor_resolved[mask],
            tracks.anchor_t[mask],
        )

    def expire(self, time_s: float) -> None:
        """Forget lost tracks closed longer before ``time_s`` than their memory (:meth:`memory_of`)."""
        keep = time_s - self.time_s <= self.memory_s
        if not keep.all():
            self._take(keep)

    def match(self, x: np.ndarray, P: np.ndarray, time_s: float) -> tuple[np.ndarray, np.ndarray]:
        """Lost id for each newly confirmed track (-1: none), and the alias shift of its velocity.

        Parameters
        ----------
        x, P : ndarray, shapes (k, 4), (k, 4, 4)
            States of the newly confirmed tracks at ``time_s``.

        Returns
        -------
        ids : ndarray of int, shape (k,)
            Reacquired lost track id, -1 for a new aircraft. Matched lost tracks are removed.
        alias : ndarray of float, shape (k,)
            Whole Doppler widths to add to the new track's radial velocity, NaN when not matched or
            when the prediction cannot choose the alias (set only for lost tracks whose own alias
            was resolved).
        """
        self.expire(time_s)
        k = len(x)
        ids, alias = np.full(k, -1, np.int64), np.full(k, np.nan)
        if k == 0 or self.ids.size == 0:
            return ids, alias
        z_lost, S_lost = self._predicted_observation(time_s)
        H = self.model.measurement_matrix
        z_new = x @ H.T
        S_new = H @ P @ H.T
        # The two estimates are independent: the difference's covariance is the sum of theirs. Pairs
        # outside the gate's range extent are not scored.
        dr = z_new[:, None, 0] - z_lost[None, :, 0]
        a, b = np.nonzero(dr**2 < self.gate * (S_new[:, None, 0, 0] + S_lost[None, :, 0, 0]))
        y = np.column_stack([dr[a, b], z_new[a, 1] - z_lost[b, 1]])
        if self.model.wrap_doppler:
            y[:, 1] = wrap(y[:, 1], self.model.doppler_width_mps)
        cost = np.full((k, self.ids.size), 1e12)
        d2 = pair_costs(y, S_new[a] + S_lost[b], "mahalanobis", (1.0, 1.0))
        cost[a, b] = np.where(d2 < self.gate, d2, 1e12)
        r, c = linear_sum_assignment(cost)
        ok = cost[r, c] < self.gate
        r, c = r[ok], c[ok]
        ids[r] = self.ids[c]
        width = self.model.doppler_width_mps
        sure = self.resolved[c] & (np.sqrt(S_lost[c, 1, 1]) < self.resolve_sd_mps) & self.model.wrap_doppler
        alias[r] = np.where(sure, np.round((z_lost[c, 1] - x[r, 1]) / width), np.nan)
        drop = np.ones(self.ids.size, bool)
        drop[c] = False
        self._take(drop)
        return ids, alias

    def predict(
        self, x: np.ndarray, P: np.ndarray, resolved: np.ndarray, dt_s: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """States ``x`` (k, 4), ``P`` (k, 4, 4) carried ``dt_s`` (k,) seconds across a gap, as a lost
        track is: gentle jerk, and (radar model) a radial acceleration that decays as a manoeuvre.

        Examples
        --------
        >>> from skyradar.track.models import radar_model
        >>> lost = LostTracks(radar_model(78.3))
        >>> x, P = np.array([[2000.0, -60.0, -60.0, 1.0]]), np.diag([16.0, 0.04, 1.0, 0.25])[None]
        >>> xp, Pp = lost.predict(x, P, np.array([True]), np.array([2.0]))
        >>> round(float(xp[0, 0]), 1), bool(Pp[0, 0, 0] > 16.0)
        (1881.5, True)
        """
        m = self._gentle
        dt = np.asarray(dt_s, float)
        resolved = np.asarray(resolved, bool) | (not self.model.dealias)
        P = np.array(P, float)
        if self.model.coupled:
            F = manoeuvre_transition(dt, self.tau_s, resolved)
            P[:, 3, 3] += self.sigma_accel_mps2**2
        else:
            F = m.transition(dt)
        Q = np.where(resolved[:, None, None], m.process_noise(dt), m.process_noise_unresolved(dt))
        return predict(x, P, F, Q)

    def _predicted_observation(self, time_s: float) -> tuple[np.ndarray, np.ndarray]:
        """Observed (range, radial velocity) of every lost track at ``time_s`` and its covariance."""
        H = self.model.measurement_matrix
        xp, Pp = self.predict(self.x, self.P, self.resolved, time_s - self.time_s)
        return xp @ H.T, H @ Pp @ H.T

    def _take(self, keep: np.ndarray) -> None:
        self.ids, self.x, self.P = self.ids[keep], self.x[keep], self.P[keep]
        self.resolved, self.time_s = self.resolved[keep], self.time_s[keep]
        self.memory_s = self.memory_s[keep]


def manoeuvre_transition(
    dt_s: float | np.ndarray, tau_s: float, resolved: bool | np.ndarray = True
) -> np.ndarray:
    """Radar-model transition over ``dt_s`` with the radial acceleration decaying as ``exp(-t / tau)``.

    The acceleration adds ``g1 = tau (1 - exp(-dt / tau))`` to the velocities and
    ``g2 = tau (dt - g1)`` to the range; range follows ``V_R`` once the alias is resolved, the
    range-rate state before. Arrays of ``dt_s`` and ``resolved`` give ``dt_s.shape + (4, 4)``.

    Examples
    --------
    >>> F = manoeuvre_transition(2.0, 1e4)  # tau >> dt: constant acceleration
    >>> F[0].round(3).tolist(), F[1].round(3).tolist()
    ([1.0, 2.0, 0.0, 2.0], [0.0, 1.0, 0.0, 2.0])
    """
    dt = np.asarray(dt_s, float)
    x = dt / tau_s
    res = np.broadcast_to(np.asarray(resolved, bool), dt.shape)
    F = np.broadcast_to(np.eye(4), dt.shape + (4, 4)).copy()
    F[..., 0, 1] = np.where(res, dt, 0.0)
    F[..., 0, 2] = np.where(res, 0.0, dt)
    g1 = -tau_s * np.expm1(-x)
    F[..., 0, 3] = tau_s * tau_s * (x + np.expm1(-x))
    F[..., 1, 3] = F[..., 2, 3] = g1
    F[..., 3, 3] = np.exp(-x)
    return F
