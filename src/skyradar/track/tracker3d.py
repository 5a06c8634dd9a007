"""3-D tracks on direction-of-arrival positions, associated through the range-Doppler tracker.

DoA positions are too noisy to associate on their own (tens of metres at a few km, Maas 2022,
ch. 3), while range and radial velocity are measured to a pixel. So association is done once, in
range-Doppler, and every range-Doppler track owns one 3-D constant-velocity Kalman filter in the
scenario NED frame, state ``(north, east, down, vn, ve, vd)`` [m, m/s], updated with the position of
the detection its range-Doppler track was assigned. The filter carries its covariance.

Each DoA position comes with its own covariance (range times the Cramer-Rao angle error at its
SNR, :mod:`skyradar.track.measure3d`). When the own-ship state is known, the de-aliased radial
velocity, the radar's most accurate measurement, updates the velocity too: ``h(x) = u . (v - v_own)``
with ``u`` the unit line of sight of the prediction (:func:`range_rate_update`). Without it the
radial velocity comes from differencing positions that are tens of metres apart. The range rate
measures the velocity along the line of sight and nothing else, so in the horizontal plane its gain
acts along the line of sight only; the horizontal velocity across it comes from the positions.
Positions that fall outside a chi-square gate of the prediction (DoA outliers at low SNR) are not
used.

The stated angle error is the bound at the detection's SNR; after clutter suppression a 2 x 2 array's
directions scatter far more (tens of degrees over terrain), and a filter that trusts the bound takes
its velocity from those directions (55-65 m/s off for 5 s on a converging aircraft 300 m above flat
ground). So each filter scales its position noise by what its own innovations show (covariance
matching): an exponential average of ``NIS / 3`` against the stated noise, never below 1 and up to
400 (directions 20 times worse than their bound).

A filter whose track is lost is kept for ``lost_memory_s``. When the range-Doppler tracker gives a
new track a lost one's id (:mod:`skyradar.track.reacquisition`), the lost filter, predicted across
the gap, is fused with the new one (:meth:`Tracker3D.rename`): the two rest on different detections,
before and after the gap, so their information adds. The new filter alone has a few frames of
directions and a velocity known to tens of m/s; with the lost one's history the reacquired track
keeps the velocity it had, and the alerts that rest on it are not silenced again as unconverged.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skyradar.track.kalman import predict, update

__all__ = ["Tracker3D", "RadialObservation", "cv3d_transition", "cv3d_process_noise", "range_rate_update"]

_H3 = np.hstack([np.eye(3), np.zeros((3, 3))])


@dataclass(frozen=True)
class RadialObservation:
    """Own-ship state and de-aliased radial velocities of one frame, for the 3-D update.

    Attributes
    ----------
    own_position_m, own_velocity_mps : ndarray, shape (3,)
        Own-ship NED position [m] and velocity [m/s] at the frame time.
    radial_velocity_mps : ndarray, shape (k,)
        De-aliased radial velocity (positive receding) per track; NaN where none.
    sigma_mps : float
        Its standard deviation, m/s.

    Examples
    --------
    A filter 1 km east of an own-ship flying east at 50 m/s, its velocity unknown (400 m^2/s^2):
    a range rate of -80 m/s puts the intruder's east velocity at ``50 - 80`` m/s.

    >>> obs = RadialObservation(np.zeros(3), np.array([0.0, 50.0, 0.0]), np.array([-80.0]))
    >>> x = np.array([[0.0, 1000.0, 0.0, 0.0, 0.0, 0.0]])
    >>> x1, _ = range_rate_update(x, np.eye(6)[None] * 400.0, obs.radial_velocity_mps, obs)
    >>> x1.round(1).tolist()
    [[0.0, 1000.0, 0.0, 0.0, -30.0, 0.0]]
    """

    own_position_m: np.ndarray
    own_velocity_mps: np.ndarray
    radial_velocity_mps: np.ndarray
    sigma_mps: float = 0.2


def range_rate_update(
    x: np.ndarray, P: np.ndarray, rr_mps: np.ndarray, obs: RadialObservation
) -> tuple[np.ndarray, np.ndarray]:
    """Update of a stack of (p, v) states with their range rates along the line of sight, Joseph form.

    ``h(x) = u . (v - v_own)`` with the line of sight ``u = (p - p_own) / r`` taken from the
    prediction and held fixed, so the update is linear in the velocity and does not drag the
    position across the line of sight (an extended update, with ``dh/dp = (w - (u.w) u) / r``,
    does, and with DoA positions tens of metres off it biased both position and velocity in the
    ch4 Free scenario). The error of ``u`` enters as measurement noise instead:
    ``|w_perp|^2 * var(angle)``, ``w = v - v_own``, the angle variance from the predicted position
    covariance across the line of sight.

    The gain leaves the position alone and, in the horizontal plane, acts along the horizontal
    line of sight only; the vertical speed takes the optimal gain ``(P h / S)_vd``. The optimal
    gain ``P h / S`` also acts across ``u`` through ``P_vv``, and there it reads the error of the
    filter's own line of sight as information: ``u`` is off by the angle error ``a`` of the
    prediction, the gain then carries ``P_vv a / S`` across the line of sight, and the innovation
    carries ``-a . w``. Their product pulls the velocity across the line of sight towards zero on
    every update, by ``P_vv var(a) w_perp / S``, which with a horizontal velocity sigma of tens of
    m/s and a range-rate sigma of 0.2 m/s exceeds the velocity itself: a track first seen at 3.5 km
    is held on a collision course for seconds, and a conflict-free aircraft 1 km abeam is warned.
    The vertical speed's sigma is a few m/s (its level-flight prior), so its optimal gain stays
    small; confined to the 3-D line of sight instead, the gain would put ``u_z`` of each horizontal
    correction into it (3.5 m/s of descent on a level aircraft 250 m above at 3.5 km, a false
    vertical conflict). Joseph form keeps the covariance right for this gain.

    Examples
    --------
    >>> obs = RadialObservation(np.zeros(3), np.zeros(3), np.array([-50.0]), 0.2)
    >>> x = np.array([[1000.0, 0.0, 0.0, 0.0, 0.0, 0.0]])
    >>> x1, _ = range_rate_update(x, np.eye(6)[None] * 400.0, np.array([-50.0]), obs)
    >>> round(float(x1[0, 3]), 1)
    -50.0
    """
    d = x[:, :3] - obs.own_position_m
    r = np.linalg.norm(d, axis=1)
    u = d / r[:, None]
    w = x[:, 3:] - obs.own_velocity_mps
    uw = np.sum(u * w, axis=1)
    w_perp2 = np.sum(w * w, axis=1) - uw**2
    P_pp = P[:, :3, :3]
    across = np.trace(P_pp, axis1=1, axis2=2) - np.einsum("ni,nij,nj->n", u, P_pp, u)
    noise = obs.sigma_mps**2 + w_perp2 * across / (2.0 * r**2)
    h = np.concatenate([np.zeros_like(u), u], axis=1)  # (n, 6)
    Ph = np.einsum("nij,nj->ni", P, h)
    S = np.einsum("ni,ni->n", h, Ph) + noise
    K = Ph / S[:, None]
    K[:, :3] = 0.0
    # The horizontal line of sight; straight above or below there is none, and the range rate says
    # nothing of the horizontal velocity (its gain there is 0, not NaN).
    horizontal = np.linalg.norm(u[:, :2], axis=1, keepdims=True)
    along_h = np.divide(u[:, :2], horizontal, out=np.zeros_like(u[:, :2]), where=horizontal > 0.0)
    K[:, 3:5] = np.sum(K[:, 3:5] * along_h, axis=1)[:, None] * along_h
    x_new = x + K * (rr_mps - uw)[:, None]
    I_KH = np.eye(6) - K[:, :, None] * h[:, None, :]
    P_new = I_KH @ P @ np.swapaxes(I_KH, -1, -2) + noise[:, None, None] * K[:, :, None] * K[:, None, :]
    return x_new, P_new


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


def cv3d_process_noise(dt_s: float, sigma_accel_mps2) -> np.ndarray:
    """White-acceleration process noise for ``(p, v)`` in 3-D, 6x6.

    ``sigma_accel_mps2`` is one value for all axes or three (north, east, down), m/s^2.

    Examples
    --------
    >>> Q = cv3d_process_noise(1.0, [3.0, 3.0, 1.0])
    >>> float(Q[3, 3]), float(Q[5, 5])
    (9.0, 1.0)
    """
    q = np.broadcast_to(np.asarray(sigma_accel_mps2, float) ** 2, (3,))
    block = np.array([[dt_s**3 / 3, dt_s**2 / 2], [dt_s**2 / 2, dt_s]])
    return np.kron(block, np.diag(q))


def _nis(y: np.ndarray, S: np.ndarray) -> np.ndarray:
    """Normalised innovation squared ``y^T S^-1 y`` of each row."""
    return np.einsum("ni,ni->n", y, np.linalg.solve(S, y[..., None])[..., 0])


class Tracker3D:
    """One 3-D constant-velocity Kalman filter per range-Doppler track id.

    Parameters
    ----------
    sigma_accel_mps2 : float
        Horizontal process noise (white acceleration), m/s^2.
    init_sigma_velocity_mps : float
        Prior standard deviation of each horizontal velocity component of a new filter, m/s.
    sigma_vertical_accel_mps2 : float
        Vertical process noise, m/s^2. Aircraft change their vertical speed gently (a 500 ft/min
        level-off takes several seconds), far more gently than their heading.
    init_sigma_vertical_mps : float
        Prior standard deviation of the vertical speed of a new filter (prior mean 0: level), m/s.
        Light aircraft climb and descend at a few m/s; without this prior the vertical speed is
        a difference of DoA elevations, metres of noise over a few seconds.
    gate : float
        Chi-square (3 degrees of freedom) gate on DoA positions; 16 keeps 99.9 % of good ones.
    max_rejects : int
        After this many consecutive gated-out positions the filter is restarted on the next one
        (the estimate, not the measurements, is then the likelier culprit).
    noise_memory : float
        Weight of each new position in a filter's average of ``NIS / 3`` (normalised innovation
        squared against the stated position noise); that average, clipped to
        ``[1, max_noise_scale]``, multiplies the position noise. A new filter's first
        ``1 / noise_memory`` positions enter as a running mean. 0: the stated noise, always.
    max_noise_scale : float
        Largest factor on the position noise (each NIS enters the average at most ``3 *`` this).
        400 covers directions 20 times worse than their bound (after clutter suppression a 2 x 2
        array's scatter by tens of degrees over terrain); the cap bounds what one wild position
        adds to the average.
    lost_memory_s : float
        A filter whose track is no longer alive is kept this long for a reacquisition, s (the
        longest the range-Doppler tracker keeps a lost track: ``reacquire_closing_s``); 0 forgets
        it at once.
    fusion_gate : float
        Chi-square (6 degrees of freedom) gate on the difference of a lost filter, predicted
        across the gap, and the reacquiring one; beyond it they are not one aircraft's, and the
        new filter is kept alone.

    Examples
    --------
    >>> t3 = Tracker3D()
    >>> _ = t3.step(0.0, np.array([7]), np.array([[100.0, 0.0, -50.0]]), np.array([400.0]))
    >>> x, P = t3.step(1.0, np.array([7]), np.array([[110.0, 0.0, -50.0]]), np.array([400.0]))
    >>> bool(100.0 < x[0, 0] < 110.0), bool(x[0, 3] > 0)
    (True, True)
    """

    def __init__(
        self,
        sigma_accel_mps2: float = 2.0,
        init_sigma_velocity_mps: float = 60.0,
        gate: float = 16.0,
        max_rejects: int = 5,
        sigma_vertical_accel_mps2: float = 0.3,
        init_sigma_vertical_mps: float = 3.0,
        noise_memory: float = 0.1,
        max_noise_scale: float = 400.0,
        lost_memory_s: float = 8.0,
        fusion_gate: float = 22.5,
    ) -> None:
        self.sigma_accel_mps2 = float(sigma_accel_mps2)
        self.init_sigma_velocity_mps = float(init_sigma_velocity_mps)
        self.sigma_vertical_accel_mps2 = float(sigma_vertical_accel_mps2)
        self.init_sigma_vertical_mps = float(init_sigma_vertical_mps)
        self.gate = float(gate)
        self.max_rejects = int(max_rejects)
        self.noise_memory = float(noise_memory)
        self.max_noise_scale = float(max_noise_scale)
        self.ids = np.zeros(0, np.int64)
        self.x = np.zeros((0, 6))
        self.P = np.zeros((0, 6, 6))
        self.rejects = np.zeros(0, np.int64)
        self.noise_scale = np.zeros(0)
        self.noise_samples = np.zeros(0, np.int64)
        self.time_s: float | None = None
        self.lost_memory_s = float(lost_memory_s)
        self.fusion_gate = float(fusion_gate)
        self._lost: dict[int, tuple[float, np.ndarray, np.ndarray]] = {}  # id: (time, x, P) when lost

    def step(
        self,
        time_s: float,
        ids: np.ndarray,
        positions_m: np.ndarray,
        variances_m2: np.ndarray,
        radial: RadialObservation | None = None,
        restart_ids: np.ndarray | None = None,
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
        variances_m2 : ndarray, shape (k,) or (k, 3, 3)
            Per-axis variance of each position, or its full covariance, m^2.
        radial : RadialObservation, optional
            Own-ship state and de-aliased radial velocity per track, for a range-rate update.
        restart_ids : ndarray of int, optional
            Tracks whose earlier positions the caller knows to be of mixed hypotheses (a MIMO
            radar's two velocity residues): a position of theirs that fails the gate at its stated
            noise restarts the filter at once, with the stated noise again, instead of being
            weighed with the noise scale those positions taught it.

        Returns
        -------
        x : ndarray, shape (k, 6)
            (north, east, down, vn, ve, vd); NaN for ids that never had a 3-D position.
        P : ndarray, shape (k, 6, 6)
        """
        ids = np.asarray(ids, np.int64)
        cov = np.asarray(variances_m2, float)
        if cov.ndim == 1:
            cov = cov[:, None, None] * np.eye(3)
        keep = np.isin(self.ids, ids)
        self._remember_lost(~keep)
        self._keep(keep)
        if self.time_s is not None and self.ids.size and time_s > self.time_s:
            dt = time_s - self.time_s
            self.x, self.P = predict(
                self.x, self.P, cv3d_transition(dt), cv3d_process_noise(dt, self._accel_sigmas())
            )
        self.time_s = float(time_s)
        # A position without a finite covariance (e.g. no SNR for its angle error) is not used.
        has = np.all(np.isfinite(positions_m), axis=1) & np.all(np.isfinite(cov), axis=(1, 2))
        pos, known = _lookup(self.ids, ids)
        fresh = np.isin(ids, np.asarray([] if restart_ids is None else restart_ids, np.int64))
        self._update_positions(np.flatnonzero(has & known), pos, positions_m, cov, fresh)
        new = has & ~known
        if np.any(new):
            self._add(ids[new], positions_m[new], cov[new])
        pos, found = _lookup(self.ids, ids)
        if radial is not None:
            ok = found & np.isfinite(radial.radial_velocity_mps)
            rows = pos[ok]
            self.x[rows], self.P[rows] = range_rate_update(
                self.x[rows], self.P[rows], radial.radial_velocity_mps[ok], radial
            )
        out_x = np.full((ids.size, 6), np.nan)
        out_P = np.full((ids.size, 6, 6), np.nan)
        out_x[found] = self.x[pos[found]]
        out_P[found] = self.P[pos[found]]
        return out_x, out_P

    def rename(self, old_ids: np.ndarray, new_ids: np.ndarray) -> None:
        """Give the filters of ``old_ids`` the ids ``new_ids`` (a track that reacquired a lost id).

        A filter still held under a new id is replaced: the renamed one follows the current
        detections.

        Examples
        --------
        >>> t3 = Tracker3D()
        >>> _ = t3.step(0.0, np.array([3, 9]), np.zeros((2, 3)), np.full(2, 400.0))
        >>> t3.rename(np.array([9]), np.array([1]))
        >>> t3.ids.tolist()
        [1, 3]
        """
        old_ids, new_ids = np.asarray(old_ids, np.int64), np.asarray(new_ids, np.int64)
        pos, found = _lookup(self.ids, old_ids)
        keep = ~np.isin(self.ids, new_ids[found])
        self.ids = self.ids.copy()
        self.ids[pos[found]] = new_ids[found]
        keep[pos[found]] = True
        order = np.flatnonzero(keep)[np.argsort(self.ids[keep], kind="stable")]
        self._keep(order)
        for new_id in new_ids[found]:
            self._fuse_lost(int(new_id))

    def _remember_lost(self, gone: np.ndarray) -> None:
        """Keep the filters ``gone`` (mask) for a reacquisition; forget those older than the memory."""
        if self.time_s is not None and self.lost_memory_s > 0.0:
            for row in np.flatnonzero(gone):
                self._lost[int(self.ids[row])] = (self.time_s, self.x[row].copy(), self.P[row].copy())
        if self.time_s is not None:
            now = self.time_s
            self._lost = {k: v for k, v in self._lost.items() if now - v[0] <= self.lost_memory_s}

    def _fuse_lost(self, track_id: int) -> None:
        """Fuse the lost filter of ``track_id``, predicted to now, into the live one of that id.

        The lost filter's information (before the gap) and the live one's (after it) are
        independent but for the process noise across the gap, which the prediction adds to the
        lost one: ``P = (P_lost^-1 + P_live^-1)^-1``, ``x = P (P_lost^-1 x_lost + P_live^-1 x_live)``.
        """
        lost = self.lost_prediction(track_id)
        self._lost.pop(track_id, None)
        pos, found = _lookup(self.ids, np.array([track_id], np.int64))
        if lost is None or not found[0]:
            return
        x_lost, P_lost = lost
        row = int(pos[0])
        x_live, P_live = self.x[row], self.P[row]
        if not (np.all(np.isfinite(x_lost)) and np.all(np.isfinite(x_live))):
            return
        d = x_lost - x_live
        if float(d @ np.linalg.solve(P_lost + P_live, d)) > self.fusion_gate:
            return  # not one aircraft's: the new filter alone
        info_lost, info_live = np.linalg.inv(P_lost), np.linalg.inv(P_live)
        P = np.linalg.inv(info_lost + info_live)
        self.x[row] = P @ (info_lost @ x_lost + info_live @ x_live)
        self.P[row] = 0.5 * (P + P.T)

    def lost_prediction(self, track_id: int) -> tuple[np.ndarray, np.ndarray] | None:
        """The filter of the lost track ``track_id`` predicted to the last step's time: state (6,)
        and covariance (6, 6); None when no such filter is kept.

        Examples
        --------
        >>> t3 = Tracker3D()
        >>> _ = t3.step(0.0, np.array([4]), np.array([[1000.0, 0.0, -300.0]]), np.array([400.0]))
        >>> t3.x[0, 3] = -50.0  # closing at 50 m/s
        >>> _ = t3.step(1.0, np.array([], np.int64), np.empty((0, 3)), np.empty(0))
        >>> x, P = t3.lost_prediction(4)
        >>> x[:3].round(1).tolist(), t3.lost_prediction(5)
        ([950.0, 0.0, -300.0], None)
        """
        lost = self._lost.get(int(track_id))
        if lost is None or self.time_s is None:
            return None
        t_lost, x_lost, P_lost = lost
        dt = self.time_s - t_lost
        if dt > 0.0:
            x, P = predict(
                x_lost[None], P_lost[None], cv3d_transition(dt), cv3d_process_noise(dt, self._accel_sigmas())
            )
            return x[0], P[0]
        return x_lost.copy(), P_lost.copy()

    def reset_height(
        self, ids: np.ndarray, own_state: np.ndarray, up_m: np.ndarray, sigma_m: np.ndarray
    ) -> None:
        """Restart the filters ``ids`` at ``up_m`` above the own-ship (m) with ``sigma_m`` (m; NaN
        keeps the filter's own vertical sigma).

        For a height learnt at once rather than reading by reading (a track whose elevations
        first agree, :mod:`skyradar.track.elevation_trust`): updated one scattered reading at a
        time, the first reading accepted sets the height and the gate then keeps out the rest.
        ``own_state`` is the own-ship's NED position and velocity (6,), m and m/s. The position
        moves on its range sphere (same range and bearing): the range is measured to a metre,
        and a height changed at a fixed horizontal position would contradict it. The horizontal
        speed along the bearing is rescaled to keep the range rate, which is measured to a few
        cm/s: left unchanged, the range-rate updates would turn the difference into a vertical speed
        (a level aircraft 250 m below would gain 4 m/s of climb, and a false warning).
        The vertical speed and its sigma are kept.

        Examples
        --------
        >>> t3 = Tracker3D()
        >>> _ = t3.step(0.0, np.array([7]), np.array([[1000.0, 0.0, 0.0]]), np.array([400.0]))
        >>> t3.x[0, 3] = -20.0  # closing at 20 m/s, level
        >>> t3.reset_height(np.array([7, 8]), np.zeros(6), np.array([500.0, 0.0]), np.array([50.0, 1.0]))
        >>> t3.x[0].round(1).tolist(), float(np.sqrt(t3.P[0, 2, 2]))
        ([866.0, 0.0, -500.0, -23.1, 0.0, 0.0], 50.0)
        """
        pos, found = _lookup(self.ids, np.asarray(ids, np.int64))
        rows, own = pos[found], np.asarray(own_state, float)
        d, v = self.x[rows, :3] - own[:3], self.x[rows, 3:] - own[3:]
        r = np.linalg.norm(d, axis=1)
        range_rate = np.einsum("ij,ij->i", d, v) / r
        up = np.clip(np.asarray(up_m, float)[found], -0.999 * r, 0.999 * r)
        bearing = np.arctan2(d[:, 1], d[:, 0])
        along = np.column_stack([np.cos(bearing), np.sin(bearing)])
        horizontal = np.sqrt(r**2 - up**2)
        # r * range rate = horizontal * along_speed - up * vd (NED: the point's down is -up), vd kept
        along_speed = (r * range_rate + up * v[:, 2]) / horizontal
        v_h = v[:, :2] + (along_speed - np.einsum("ij,ij->i", v[:, :2], along))[:, None] * along
        self.x[rows, :2] = own[:2] + along * horizontal[:, None]
        self.x[rows, 2] = own[2] - up
        self.x[rows, 3:5] = own[3:5] + v_h
        sigma = np.asarray(sigma_m, float)[found]
        variance = np.where(np.isfinite(sigma), sigma**2, self.P[rows, 2, 2])
        self.P[rows, 2, :], self.P[rows, :, 2] = 0.0, 0.0
        self.P[rows, 2, 2] = variance

    def _update_positions(
        self, sel: np.ndarray, pos: np.ndarray, positions_m: np.ndarray, cov: np.ndarray, fresh: np.ndarray
    ) -> None:
        """Gated linear update of the filters ``pos[sel]`` with ``positions_m[sel]``; a position of
        a ``fresh`` (mask over all rows) track outside the gate at its stated noise restarts its
        filter and forgets the noise scale."""
        if sel.size == 0:
            return
        rows = pos[sel]
        y = positions_m[sel] - self.x[rows, :3]
        stated = cov[sel]
        cov_sel = stated * self.noise_scale[rows, None, None]  # the noise this filter's innovations showed
        S = self.P[rows, :3, :3] + cov_sel
        nis, nis_stated = _nis(y, S), _nis(y, self.P[rows, :3, :3] + stated)
        self._match_noise(rows, nis_stated)
        ok = nis < self.gate
        renew = fresh[sel] & (nis_stated >= self.gate)
        restart = (~ok & (self.rejects[rows] >= self.max_rejects)) | renew
        self.rejects[rows] = np.where(ok, 0, self.rejects[rows] + 1)
        up = rows[ok]
        self.x[up], self.P[up] = update(self.x[up], self.P[up], y[ok], _H3, cov_sel[ok])
        if np.any(restart):
            self.noise_scale[rows[renew]], self.noise_samples[rows[renew]] = 1.0, 0
            cov_sel[renew] = stated[renew]
            x0, P0 = self._initial(positions_m[sel][restart], cov_sel[restart])
            r = rows[restart]
            self.x[r], self.P[r], self.rejects[r] = x0, P0, 0

    def _match_noise(self, rows: np.ndarray, nis: np.ndarray) -> None:
        """Average ``NIS / 3`` of the filters ``rows`` (``nis`` against the stated noise) into their
        noise scale."""
        top = self.max_noise_scale
        seen = np.minimum(np.nan_to_num(nis, nan=3.0 * top), 3.0 * top) / 3.0
        # A running mean until 1 / noise_memory innovations are in, then the exponential average:
        # a new filter learns its noise within a few positions instead of trusting the first ten.
        self.noise_samples[rows] += 1
        weight = np.maximum(self.noise_memory, 1.0 / self.noise_samples[rows])
        weight = np.where(self.noise_memory > 0.0, weight, 0.0)
        mixed = (1.0 - weight) * self.noise_scale[rows] + weight * seen
        self.noise_scale[rows] = np.clip(mixed, 1.0, top)

    def _keep(self, index: np.ndarray) -> None:
        """Keep (and order) the filters selected by ``index`` (boolean mask or rows)."""
        arrays = (self.ids, self.x, self.P, self.rejects, self.noise_scale, self.noise_samples)
        self.ids, self.x, self.P, self.rejects, self.noise_scale, self.noise_samples = (
            a[index] for a in arrays
        )

    def _initial(self, positions_m: np.ndarray, cov: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        x = np.hstack([positions_m, np.zeros((positions_m.shape[0], 3))])
        P = np.zeros((positions_m.shape[0], 6, 6))
        P[:, :3, :3] = cov
        P[:, [3, 4], [3, 4]] = self.init_sigma_velocity_mps**2
        P[:, 5, 5] = self.init_sigma_vertical_mps**2
        return x, P

    def _accel_sigmas(self) -> tuple[float, float, float]:
        return (self.sigma_accel_mps2, self.sigma_accel_mps2, self.sigma_vertical_accel_mps2)

    def _add(self, ids: np.ndarray, positions_m: np.ndarray, cov: np.ndarray) -> None:
        x, P = self._initial(positions_m, cov)
        order = np.argsort(np.concatenate([self.ids, ids]), kind="stable")
        self.ids = np.concatenate([self.ids, ids])[order]
        self.x = np.concatenate([self.x, x])[order]
        self.P = np.concatenate([self.P, P])[order]
        self.rejects = np.concatenate([self.rejects, np.zeros(ids.size, np.int64)])[order]
        self.noise_scale = np.concatenate([self.noise_scale, np.ones(ids.size)])[order]
        self.noise_samples = np.concatenate([self.noise_samples, np.zeros(ids.size, np.int64)])[order]


def _lookup(stored: np.ndarray, ids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Row of each id in the sorted ``stored`` ids, and whether it is there."""
    if stored.size == 0:
        return np.zeros(ids.size, int), np.zeros(ids.size, bool)
    pos = np.searchsorted(stored, ids)
    found = stored[np.minimum(pos, stored.size - 1)] == ids
    return np.minimum(pos, stored.size - 1), found
