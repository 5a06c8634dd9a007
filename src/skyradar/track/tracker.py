"""The range-Doppler multi-target tracker, composed from swappable parts.

One frame is: predict every track (one batched Kalman step), gate and assign detections
(:func:`skyradar.track.association.associate`, Hungarian), update the assigned tracks with the
model's innovation, de-alias the radial velocity (radar model), start tentative tracks from
unassigned detections, confirm them M-of-N (sliding window), and close tracks after misses.
The parts are objects passed in, as in Stone Soup, each filling a role typed in
:mod:`skyradar.track.components`: the motion model (:mod:`skyradar.track.models`), the predictor,
the associator, the updater, the initiator, the deleter and the reacquirer.

Tracks live as one struct of arrays (:class:`~skyradar.track.types.TrackArrays`: states ``(n, 4)``,
covariances ``(n, 4, 4)``, counters), so the cost per frame is a fixed number of numpy calls, whatever
the number of tracks.
"""

from __future__ import annotations

import numpy as np

from skyradar.track.association import Association, associate
from skyradar.track.components import Associator, Deleter, Initiator, Predictor, Reacquirer, Updater
from skyradar.track.dealias import alias_count, dealias_velocity, push_history, range_rate_fit
from skyradar.track.deletion import MissDeleter
from skyradar.track.initiation import MOfN, push_hit
from skyradar.track.kalman import predict, update
from skyradar.track.models import MotionModel
from skyradar.track.range_walk import RangeWalks
from skyradar.track.reacquisition import LostTracks
from skyradar.track.types import FrameTracks, TrackArrays, TrackerConfig

__all__ = ["TrackerConfig", "FrameTracks", "RangeDopplerTracker"]


class RangeDopplerTracker:
    """Multi-target tracker in the range-Doppler image.

    Parameters
    ----------
    model : MotionModel
        :func:`~skyradar.track.models.radar_model` or :func:`~skyradar.track.models.traditional_model`.
    config : TrackerConfig, optional
    pixel_size : (float, float)
        (dR [m], dV [m/s]) of the image, for the l2 metric.
    associator : Associator, optional
        :class:`~skyradar.track.components.Associator`; default
        :func:`~skyradar.track.association.associate`.
    initiator : Initiator, optional
        :class:`~skyradar.track.components.Initiator`; default :class:`MOfN` of the config's
        ``confirm_m`` of ``confirm_n``.
    deleter : Deleter, optional
        :class:`~skyradar.track.components.Deleter`; default :class:`MissDeleter` of the config's
        ``max_misses`` and ``max_coast_s``.
    reacquirer : Reacquirer, optional
        :class:`~skyradar.track.components.Reacquirer`: keeps closed confirmed tracks and gives
        their id to a newly confirmed track on the same aircraft (default
        :class:`~skyradar.track.reacquisition.LostTracks` from ``config.reacquire_s``;
        ``reacquire_s=0`` turns it off).
    report_tentative : bool
        Also report tentative tracks (tracks born in this frame are reported from the next one).
    predictor : Predictor, optional
        :class:`~skyradar.track.components.Predictor`: carries the tracks to each frame's time
        with the model's transition and process noise; default :func:`~skyradar.track.kalman.predict`.
    updater : Updater, optional
        :class:`~skyradar.track.components.Updater`: corrects the assigned tracks with their
        innovations; default :func:`~skyradar.track.kalman.update`.
    range_walks : RangeWalks or False, optional
        Confirms a track whose detections walk in range faster than any static point can
        (:mod:`skyradar.track.range_walk`), on the frames where :meth:`step` is given the
        own-ship's speed; default :class:`~skyradar.track.range_walk.RangeWalks` for models that
        wrap the Doppler, False: off.

    Examples
    --------
    >>> from skyradar.track.models import radar_model
    >>> trk = RangeDopplerTracker(radar_model(78.3))
    >>> for k in range(15):
    ...     out = trk.step(0.1 * k, np.array([[1000.0 - 5.0 * k, -50.0 + 78.3]]))
    >>> out.track_id.tolist(), round(float(out.state[0, 1]), 1)
    ([0], -50.0)
    """

    def __init__(
        self,
        model: MotionModel,
        config: TrackerConfig | None = None,
        pixel_size: tuple[float, float] = (14.99, 0.313),
        associator: Associator = associate,
        initiator: Initiator | None = None,
        deleter: Deleter | None = None,
        report_tentative: bool = False,
        reacquirer: Reacquirer | None = None,
        predictor: Predictor = predict,
        updater: Updater = update,
        range_walks: RangeWalks | bool | None = None,
    ) -> None:
        self.model = model
        self.report_tentative = bool(report_tentative)
        self.config = config or TrackerConfig()
        self.pixel_size = pixel_size
        self.predictor = predictor
        self.associator = associator
        self.updater = updater
        self.initiator = initiator or MOfN(self.config.confirm_m, self.config.confirm_n)
        self.deleter = deleter or MissDeleter(self.config.max_misses, self.config.max_coast_s)
        c = self.config
        self.reacquirer = reacquirer or LostTracks(
            model,
            c.reacquire_s,
            c.reacquire_jerk_mps3,
            c.gate,
            c.resolve_fraction * model.doppler_width_mps,
            closing_max_age_s=c.reacquire_closing_s,
        )
        self._reacquired = np.zeros((0, 2), np.int64)
        self.max_alias = alias_count(model.doppler_width_mps) if c.max_alias is None else c.max_alias
        if range_walks is None:
            range_walks = RangeWalks(model.doppler_width_mps) if model.wrap_doppler else False
        self.range_walks: RangeWalks | None = range_walks if isinstance(range_walks, RangeWalks) else None
        self._walked: set[int] = set()  # ids of the tracks a range walk confirmed
        self._walk_pending: set[int] = set()  # ... in the last frame, not yet offered a lost track's id
        self.time_s: float | None = None  # the last frame's time; None before the first
        self._now = 0.0  # the frame being processed, for the stages of step
        self._next_id = 0
        self._range_wrap: np.ndarray | None = None
        self._cache: dict[float, tuple[np.ndarray, ...]] = {}
        self.tracks = TrackArrays.empty(self.config.history)
        if self.config.dealias not in ("confident", "thesis"):
            raise ValueError(f"dealias must be 'confident' or 'thesis', got {self.config.dealias!r}")
        self._R = model.measurement_noise
        self._H = model.measurement_matrix
        self._P0 = model.initial_covariance()
        self._hybrid = model.dealias and self.config.dealias == "confident"
        self._thesis = model.dealias and self.config.dealias == "thesis"

    @property
    def n_tracks(self) -> int:
        """Live tracks, tentative and confirmed."""
        return self.tracks.size

    def step(
        self,
        time_s: float,
        z: np.ndarray,
        secondary: np.ndarray | None = None,
        static_speed_mps: float = float("nan"),
    ) -> FrameTracks:
        """Process one frame of detections ``z`` (m, 2) = (range [m], radial velocity [m/s]).

        ``secondary`` (bool, one per detection) marks detections that passed only a secondary,
        lower threshold (:func:`skyradar.process.detect.detect`'s ``pfa_secondary``): they may
        update a confirmed track that no primary detection updates, inside its gate, and never
        start or confirm a track by M-of-N. A confirmed track's gate spans a few cells, where the
        lower threshold's false alarms are rare; over the whole image they are not. They do count
        in a range walk (:mod:`skyradar.track.range_walk`), whose line is a gate of one range bin
        and a fraction of a m/s. ``static_speed_mps`` is the fastest a static point's range
        changes this frame (the own-ship's speed, m/s); NaN (unknown) starts no walk.
        ``time_s`` must not decrease between calls.
        """
        if self.time_s is not None and time_s < self.time_s:
            raise ValueError(f"time goes backwards ({self.time_s} -> {time_s})")
        z = np.asarray(z, float).reshape(-1, 2)
        secondary = np.zeros(len(z), bool) if secondary is None else np.asarray(secondary, bool).reshape(-1)
        if secondary.size != len(z):
            raise ValueError(f"secondary has {secondary.size} flags for {len(z)} detections")
        tr = self.tracks
        if self.time_s is not None and tr.ids.size and time_s > self.time_s:
            dt = time_s - self.time_s
            F, Q, F_u, Q_u = self._matrices(dt)
            if self._hybrid and not tr.resolved.all():
                # Two groups with one F each: cheaper than stacking a per-track F.
                for rows, FF, QQ in (
                    (np.flatnonzero(tr.resolved), F, Q),
                    (np.flatnonzero(~tr.resolved), F_u, Q_u),
                ):
                    tr.x[rows], tr.P[rows] = self.predictor(tr.x[rows], tr.P[rows], FF, QQ)
            else:
                tr.x, tr.P = self.predictor(tr.x, tr.P, F, Q)
        self.time_s = self._now = float(time_s)
        self._close_stale()
        assoc = self._associate(z, secondary)
        walk_free = np.ones(len(z), bool)  # not taken by a confirmed track: may start or support a walk
        walk_free[assoc.detection_index[tr.confirmed[assoc.track_index]]] = False
        assigned = np.full(tr.ids.size, -1)
        assigned[assoc.track_index] = assoc.detection_index
        innov = np.full((tr.ids.size, 2), np.nan)
        innov[assoc.track_index] = assoc.innovation
        self._update(assoc, z)
        self._bookkeep(assigned >= 0, tr.misses >= self.initiator.n)
        alive = self._manage()
        assigned, innov = assigned[alive], innov[alive]
        used = np.zeros(len(z), bool)
        used[assoc.detection_index] = True
        new_det = np.flatnonzero(~used & ~secondary)
        self._start(z[new_det])
        alive_det = np.concatenate([assigned, new_det])
        if self.range_walks is not None:
            walk_rows, walk_v = self.range_walks.step(self._now, z, walk_free, static_speed_mps)
            alive_det = self._confirm_walks(walk_rows, walk_v, z, alive_det)
        alive_ids = tr.ids
        confirmed = tr.confirmed[: assigned.size]
        out = np.ones(assigned.size, bool) if self.report_tentative else confirmed
        return FrameTracks(
            self._now,
            tr.ids[: assigned.size][out],
            tr.x[: assigned.size][out],
            tr.P[: assigned.size][out],
            tr.n_updates[: assigned.size][out],
            assigned[out],
            innov[out],
            alive_ids,
            alive_det,
            confirmed[out],
            self._reacquired,
        )

    def _confirm_walks(
        self, rows: np.ndarray, velocity_mps: np.ndarray, z: np.ndarray, alive_det: np.ndarray
    ) -> np.ndarray:
        """Confirm the tracks of the detections ``rows`` that complete a range walk, at its true
        radial velocity (the alias resolved); a detection no track took (a secondary one) starts
        one. Returns ``alive_det`` with the started tracks' detections appended."""
        if rows.size == 0:
            return alive_det
        tr, width = self.tracks, self.model.doppler_width_mps
        missing = rows[~np.isin(rows, alive_det)]
        if missing.size:
            self._start(z[missing])
            alive_det = np.concatenate([alive_det, missing])
        track_rows = np.array([int(np.flatnonzero(alive_det == j)[0]) for j in rows])
        fresh = track_rows[~tr.confirmed[track_rows]]
        shift = np.round((velocity_mps - tr.x[track_rows, 1]) / width) * width
        self._shift_velocity(track_rows, shift)
        tr.resolved[track_rows] = True
        tr.x[track_rows, 2] = tr.x[track_rows, 1]
        tr.confirmed[track_rows] = True
        tr.set_anchor(track_rows, self._now)
        # Newly confirmed: the next frame's management gives them a lost track's id if one matches
        # (ids change there, where the rows are sorted by id again).
        fresh_ids = tr.ids[fresh[~tr.was_confirmed[fresh]]]
        self._walk_pending.update(int(i) for i in fresh_ids)
        self._walked.update(int(i) for i in tr.ids[track_rows])
        return alive_det

    def _matrices(self, dt: float) -> tuple[np.ndarray, ...]:
        """F, Q (and their unresolved-alias versions) for a time step, cached by step."""
        key = round(dt, 9)
        if key not in self._cache:
            if len(self._cache) > 64:
                self._cache.clear()
            m = self.model
            self._cache[key] = (
                m.transition(dt),
                m.process_noise(dt),
                m.transition_unresolved(dt),
                m.process_noise_unresolved(dt),
            )
        return self._cache[key]

    def _associate(self, z: np.ndarray, secondary: np.ndarray) -> Association:
        tr, m = self.tracks, self.model
        # H = [[1, c, 0, 0], [0, 1, 0, 0]] written out: S = H P H^T + R without batched matmuls.
        c, P, x = m.coupling_s, tr.P, tr.x
        z_pred = np.column_stack([x[:, 0] + c * x[:, 1], x[:, 1]])
        S = np.empty((x.shape[0], 2, 2))
        S[:, 0, 0] = P[:, 0, 0] + 2 * c * P[:, 0, 1] + c * c * P[:, 1, 1] + self._R[0, 0]
        S[:, 0, 1] = S[:, 1, 0] = P[:, 0, 1] + c * P[:, 1, 1] + self._R[0, 1]
        S[:, 1, 1] = P[:, 1, 1] + self._R[1, 1]
        range_wrap = None
        if self._thesis:
            range_wrap = np.where(tr.n_updates == 1, m.doppler_width_mps * (self._now - tr.t_update), np.nan)
        self._range_wrap = range_wrap
        # Confirmed tracks choose first; tentative tracks share what is left. Otherwise the
        # solver's preference for more pairs lets a new track take a confirmed track's detection
        # while the confirmed track is handed a clutter point.
        # Secondary detections come last, to the confirmed tracks no primary detection updated.
        confirmed = tr.confirmed
        if self.config.confirmed_first:
            stages = [(np.flatnonzero(confirmed), False), (np.flatnonzero(~confirmed), False)]
        else:
            stages = [(np.arange(tr.ids.size), False)]
        if secondary.any():
            stages.append((np.flatnonzero(confirmed), True))
        free = np.ones(len(z), bool)
        taken = np.zeros(tr.ids.size, bool)
        parts = []
        for rows, lower in stages:
            rows = rows[~taken[rows]]
            dets = np.flatnonzero(free & (secondary == lower))
            if rows.size == 0 or dets.size == 0:
                continue
            a = self.associator(
                z_pred[rows],
                S[rows],
                z[dets],
                self.config.gate,
                m.doppler_width_mps if m.wrap_doppler else None,
                None if range_wrap is None else range_wrap[rows],
                self.config.metric,
                self.pixel_size,
                self.max_alias,
            )
            parts.append(Association(rows[a.track_index], dets[a.detection_index], a.innovation, a.cost))
            free[dets[a.detection_index]] = False
            taken[rows[a.track_index]] = True
        if not parts:
            return Association(np.zeros(0, int), np.zeros(0, int), np.zeros((0, 2)), np.zeros(0))
        return Association(
            *(np.concatenate([getattr(p, f) for p in parts]) for f in Association.__dataclass_fields__)
        )

    def _update(self, assoc: Association, z: np.ndarray) -> None:
        tr, m = self.tracks, self.model
        rows = assoc.track_index
        if rows.size == 0:
            return
        if self._range_wrap is not None:
            self._shift_alias(rows, z[assoc.detection_index, 0], assoc.innovation[:, 0], self._range_wrap)
        x, P = tr.x[rows], tr.P[rows]
        tr.x[rows], tr.P[rows] = self.updater(x, P, assoc.innovation, self._H, self._R)
        if self._hybrid:
            self._resolve(rows)
        if self._thesis:
            push_history(tr.hist_t, rows, np.full(rows.size, self._now), tr.n_updates[rows])
            push_history(tr.hist_r, rows, z[assoc.detection_index, 0], tr.n_updates[rows])
            rate = range_rate_fit(tr.hist_t[rows], tr.hist_r[rows], tr.n_updates[rows] + 1)
            ok = np.isfinite(rate)
            r_ok = rows[ok]
            tr.x[r_ok, 2] = rate[ok]
            self._shift_velocity(
                r_ok, dealias_velocity(tr.x[r_ok, 1], rate[ok], m.doppler_width_mps) - tr.x[r_ok, 1]
            )

    def _resolve(self, rows: np.ndarray) -> None:
        """Resolve the alias of tracks whose range rate is now known well enough (confident mode)."""
        tr, width = self.tracks, self.model.doppler_width_mps
        sd = np.sqrt(tr.P[rows, 2, 2])
        now = ~tr.resolved[rows] & (sd < self.config.resolve_fraction * width)
        r = rows[now]
        self._shift_velocity(r, dealias_velocity(tr.x[r, 1], tr.x[r, 2], width) - tr.x[r, 1])
        tr.resolved[r] = True
        done = rows[tr.resolved[rows]]
        # Once resolved, range follows V_R; the range-rate state simply reports it.
        tr.x[done, 2] = tr.x[done, 1]

    def _shift_velocity(self, rows: np.ndarray, delta_mps: np.ndarray) -> None:
        """Move V_R by whole image widths, keeping the predicted observed range unchanged.

        The observed range is ``R + c V_R`` (range-Doppler coupling), so R moves by ``-c dV``.
        """
        self.tracks.x[rows, 1] += delta_mps
        self.tracks.x[rows, 0] -= self.model.coupling_s * delta_mps

    def _shift_alias(
        self, rows: np.ndarray, range_m: np.ndarray, wrapped_m: np.ndarray, range_wrap: np.ndarray
    ) -> None:
        """Move single-observation tracks to the alias their wrapped range innovation chose.

        The wrapped residual differs from the raw one by ``k * W * dt``; that ``k`` is the thesis'
        de-aliasing rule with the range rate of the first two observations, so the prediction is
        shifted by ``k`` image widths (range by ``k W dt``) before the ordinary update.
        """
        tr, width = self.tracks, self.model.doppler_width_mps
        span = range_wrap[rows]
        use = np.isfinite(span) & (span > 0)
        if not np.any(use):
            return
        r = rows[use]
        k = np.round((range_m[use] - tr.x[r, 0] - wrapped_m[use]) / span[use])
        tr.x[r, 0] += k * span[use]
        self._shift_velocity(r, k * width)

    def _bookkeep(self, hit: np.ndarray, long_gap: np.ndarray) -> None:
        tr = self.tracks
        # A confirmed track updated after coasting initiator.n frames or more may have taken clutter in
        # its grown gate: it must be confirmed again (M-of-N) and keeps its anchor meanwhile.
        # A track a range walk confirmed keeps its confirmation through its gaps (its detections come
        # in bursts: that is why its walk, not M-of-N, confirmed it); the deleter still closes it.
        again = hit & long_gap & tr.confirmed & ~np.isin(tr.ids, list(self._walked))
        tr.confirmed &= ~again
        tr.window = np.where(again, 0, tr.window)
        # The anchor moves only with updates right after another (a gate that had no time to grow).
        solid = hit & (tr.misses <= 1) & tr.confirmed
        tr.set_anchor(np.flatnonzero(solid), self._now)
        tr.frames += 1
        tr.hits += hit
        tr.window = push_hit(tr.window, hit, self.initiator.n)
        tr.n_updates += hit
        tr.misses = np.where(hit, 0, tr.misses + 1)
        tr.t_update = np.where(hit, self._now, tr.t_update)

    def _manage(self) -> np.ndarray:
        """Confirm, delete and reacquire; returns the surviving tracks' pre-deletion rows, by id."""
        tr = self.tracks
        tentative = ~tr.confirmed
        confirmed_now, failed = self.initiator.window_status(tr.window, tr.misses)
        tr.confirmed = tr.confirmed | (tentative & confirmed_now)
        tr.set_anchor(np.flatnonzero(tentative & tr.confirmed), self._now)
        # A track that was confirmed and must be confirmed again after a gap lives until the
        # deleter's coasting limits close it, as a confirmed track does: a patchy return (an aircraft
        # in clutter, a fade) fails an M-of-N window without the aircraft being gone, and a new track
        # on the same returns would need a full window of its own. When its window fails, the
        # updates since the gap did not confirm the aircraft (they may be clutter its grown gate
        # took), so it goes back to its anchor, its last solid state, carried to now as a lost
        # track is. Only tracks never confirmed are dropped when their window fails.
        known = tr.confirmed | tr.was_confirmed
        dead = (tentative & failed & ~known) | (
            known & self.deleter.delete(tr.misses, self._now - tr.t_update)
        )
        back = np.flatnonzero(tentative & failed & known & ~tr.confirmed & ~dead)
        if back.size:
            tr.x[back], tr.P[back] = self.reacquirer.predict(
                tr.anchor_x[back],
                tr.anchor_P[back],
                tr.anchor_resolved[back],
                self._now - tr.anchor_t[back],
            )
            tr.resolved[back] = tr.anchor_resolved[back]
        # Closed tracks that were ever confirmed are kept as lost, at their last solid update.
        self.reacquirer.add_anchored(tr, dead & tr.was_confirmed)
        walked = np.isin(tr.ids, list(self._walk_pending))
        self._walk_pending = set()
        self._reacquire(np.flatnonzero((tentative | walked) & tr.confirmed & ~tr.was_confirmed & ~dead))
        for new_id, lost_id in self._reacquired.tolist():  # a walk's standing follows its track's id
            if new_id in self._walked:
                self._walked.add(int(lost_id))
        tr.was_confirmed |= tr.confirmed
        alive = np.flatnonzero(~dead)
        # A reacquired track has an older id: keep the rows sorted by id, as callers look ids up.
        alive = alive[np.argsort(tr.ids[alive], kind="stable")]
        if alive.size != tr.ids.size or np.any(np.diff(alive) < 0):
            tr.keep(alive)
        return alive

    def _close_stale(self) -> None:
        """Close tracks not updated for longer than the coasting time before they gate: without
        frames between detections (``skyradar track`` steps on detection times) such a track meets
        the next frame with a gate over much of the image and takes whatever is there."""
        tr = self.tracks
        stale = self._now - tr.t_update > self.deleter.max_coast_s
        if not np.any(stale):
            return
        self.reacquirer.add_anchored(tr, stale & tr.was_confirmed)
        tr.keep(~stale)

    def _reacquire(self, rows: np.ndarray) -> None:
        """Give newly confirmed tracks ``rows`` the id (and the resolved alias) of a lost track."""
        tr = self.tracks
        self._reacquired = np.zeros((0, 2), np.int64)
        if rows.size == 0 or len(self.reacquirer) == 0:
            return
        lost_ids, alias = self.reacquirer.match(tr.x[rows], tr.P[rows], self._now)
        hit = lost_ids >= 0
        self._reacquired = np.column_stack([tr.ids[rows[hit]], lost_ids[hit]])
        tr.ids[rows[hit]] = lost_ids[hit]
        sure = hit & np.isfinite(alias)
        r = rows[sure]
        self._shift_velocity(r, alias[sure] * self.model.doppler_width_mps)
        tr.resolved[r] = True
        tr.x[r, 2] = tr.x[r, 1]

    def _start(self, z_new: np.ndarray) -> None:
        n = len(z_new)
        if n == 0:
            return
        tr, m = self.tracks, self.model
        x = np.zeros((n, 4))
        x[:, :2] = z_new
        x[:, 0] -= m.coupling_s * z_new[:, 1]
        # The radar model's range rate starts at the (possibly aliased) radial velocity.
        x[:, 2] = z_new[:, 1] if m.coupled else 0.0
        ids = np.arange(self._next_id, self._next_id + n)
        self._next_id += n
        born = TrackArrays.born(
            x, self._P0, ids, self._now, z_new[:, 0], self.config.history, self.initiator.m <= 1
        )
        tr.extend(born)
