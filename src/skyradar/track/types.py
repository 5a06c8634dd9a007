"""Settings, live tracks and per-frame output of the range-Doppler tracker."""

from __future__ import annotations

from dataclasses import dataclass, field, fields

import numpy as np

__all__ = ["TrackerConfig", "TrackArrays", "FrameTracks"]


@dataclass(frozen=True)
class TrackerConfig:
    """Tracker settings that are not part of the motion model.

    Parameters
    ----------
    gate : float
        Assignment gate: squared Mahalanobis distance (``metric='mahalanobis'``, 2 degrees of
        freedom; 16 keeps 99.97 % of true pairs) or l2 innovation in pixels (``metric='l2'``).
    metric : {'mahalanobis', 'l2'}
    confirm_m, confirm_n : int
        M-of-N confirmation.
    max_misses : int
        Consecutive missed frames before a track is closed.
    max_coast_s : float
        Time without an update before a track is closed, s.
    history : int
        Range observations kept per track for the range-rate fit used to de-alias.
    max_alias : int or None
        Largest alias (in image widths) a single-observation track may be off by; None: the
        image's :func:`~skyradar.track.dealias.alias_count` (radial speeds up to 195 m/s).
    confirmed_first : bool
        Assign detections to confirmed tracks before tentative ones.
    dealias : {'confident', 'thesis'}
        How the radar model resolves the alias of ``V_R``. ``'thesis'``: wrap the range innovation
        of single-observation tracks by ``W dt`` and apply the rounding rule at every update with
        the range rate fitted to the last ``history`` ranges. ``'confident'`` (default): until the
        alias is resolved, range follows the range-rate state (which moves with the radial
        acceleration like ``V_R``); the rounding rule is applied once, when the range-rate standard
        deviation falls below ``resolve_fraction * W``, and from then on range follows ``V_R``.
        With 15 m range bins at 10 frames/s the two-observation slope has about 60 m/s standard
        deviation against ``W/2 = 39`` m/s, which is why the second is the default.
    resolve_fraction : float
        Range-rate standard deviation, as a fraction of ``W``, below which the alias is resolved.
    reacquire_s : float
        A closed confirmed track can be taken up again, with its id, by a track confirmed up to
        this long after (:mod:`skyradar.track.reacquisition`), s; 0 turns reacquisition off.
    reacquire_closing_s : float
        A lost track closing on the own-ship can be taken up until its range over its closing speed
        (a bound on the time to its closest approach), at most this long, s (never less than
        ``reacquire_s``): 25 s, the time a warning looks ahead.
    reacquire_jerk_mps3 : float
        White jerk of a lost track's prediction across the gap, m/s^3.

    Examples
    --------
    A target seen in every frame is confirmed at the fourth frame by the default 4-of-5 rule, at
    the second by a 2-of-3 rule:

    >>> from skyradar.track.models import radar_model
    >>> from skyradar.track.tracker import RangeDopplerTracker
    >>> def confirmed_at(config):
    ...     trk = RangeDopplerTracker(radar_model(78.3), config)
    ...     for k in range(5):
    ...         if trk.step(0.1 * k, np.array([[1000.0 - 5.0 * k, -50.0]])).track_id.size:
    ...             return k + 1
    >>> confirmed_at(TrackerConfig()), confirmed_at(TrackerConfig(confirm_m=2, confirm_n=3))
    (4, 2)
    """

    gate: float = 16.0
    metric: str = "mahalanobis"
    confirm_m: int = 4
    confirm_n: int = 5
    max_misses: int = 20
    max_coast_s: float = 2.0
    history: int = 16
    max_alias: int | None = None
    confirmed_first: bool = True
    dealias: str = "confident"
    resolve_fraction: float = 1.0 / 6.0
    reacquire_s: float = 8.0
    reacquire_closing_s: float = 25.0
    reacquire_jerk_mps3: float = 1.5


@dataclass
class TrackArrays:
    """The tracker's live tracks, tentative and confirmed, as a struct of arrays (one row a track).

    A frame's work is a fixed number of numpy calls over these arrays, whatever the number of
    tracks. Rows are kept sorted by ``ids``. :meth:`keep` and :meth:`extend` change the rows in
    place, so every holder of the object sees the same tracks.

    Attributes
    ----------
    x : ndarray, shape (n, 4)
        State (range [m], radial velocity [m/s], range rate [m/s], radial acceleration [m/s^2]).
    P : ndarray, shape (n, 4, 4)
        State covariance.
    ids : ndarray of int
        Track ids.
    t_update : ndarray
        Time of the last update, s.
    hits, frames, n_updates : ndarray of int
        Updates and frames since birth, and updates (hits) counted for the range history.
    window : ndarray of int
        Hit bits of the last N frames, newest lowest (:func:`~skyradar.track.initiation.push_hit`).
    misses : ndarray of int
        Consecutive frames without an update.
    confirmed : ndarray of bool
        Confirmed now (M of N).
    hist_t, hist_r : ndarray, shape (n, history)
        Times (s) and ranges (m) of the last updates, for the range-rate fit that de-aliases.
    resolved : ndarray of bool
        The radial velocity's alias is resolved (range follows ``V_R``).
    anchor_x, anchor_P, anchor_t, anchor_resolved : ndarray
        The anchor: state, covariance, time (s) and alias flag just after the last solid update (an
        update while confirmed and not after a long coast, when the gate was small). A track lost
        after taking a clutter point in a grown gate is remembered there, not where the clutter
        took it.
    was_confirmed : ndarray of bool
        Confirmed at some frame.

    Examples
    --------
    >>> tracks = TrackArrays.empty(history=16)
    >>> tracks.extend(TrackArrays.born(np.array([[1000.0, -20.0, -20.0, 0.0]]), np.eye(4), np.array([7]),
    ...                                1.0, np.array([1000.0]), history=16, confirmed=False))
    >>> tracks.size, tracks.ids.tolist(), tracks.anchor_t.tolist()
    (1, [7], [1.0])
    >>> tracks.keep(np.zeros(0, int)); tracks.size
    0
    """

    x: np.ndarray
    P: np.ndarray
    ids: np.ndarray
    t_update: np.ndarray
    hits: np.ndarray
    frames: np.ndarray
    window: np.ndarray
    misses: np.ndarray
    confirmed: np.ndarray
    n_updates: np.ndarray
    hist_t: np.ndarray
    hist_r: np.ndarray
    resolved: np.ndarray
    anchor_x: np.ndarray
    anchor_P: np.ndarray
    anchor_t: np.ndarray
    anchor_resolved: np.ndarray
    was_confirmed: np.ndarray

    @classmethod
    def empty(cls, history: int) -> TrackArrays:
        """No tracks, with range histories of ``history`` entries."""
        return cls.born(np.zeros((0, 4)), np.eye(4), np.zeros(0, np.int64), 0.0, np.zeros(0), history, False)

    @classmethod
    def born(
        cls,
        x: np.ndarray,
        P0: np.ndarray,
        ids: np.ndarray,
        time_s: float,
        range_m: np.ndarray,
        history: int,
        confirmed: bool,
    ) -> TrackArrays:
        """Tracks started at ``time_s`` from one detection each: states ``x`` (n, 4), covariance
        ``P0`` (4, 4) for all, observed ranges ``range_m`` (m) as their first history entry;
        ``confirmed`` when one hit confirms (M = 1). Each is its own anchor."""
        n = len(x)
        hist_t = np.full((n, history), np.nan)
        hist_r = np.full((n, history), np.nan)
        hist_t[:, 0] = time_s
        hist_r[:, 0] = range_m
        P = np.broadcast_to(np.asarray(P0, float), (n, 4, 4))
        return cls(
            x=np.array(x, float),
            P=P.copy(),
            ids=np.asarray(ids, np.int64),
            t_update=np.full(n, float(time_s)),
            hits=np.ones(n, np.int64),
            frames=np.ones(n, np.int64),
            window=np.ones(n, np.int64),
            misses=np.zeros(n, np.int64),
            confirmed=np.full(n, bool(confirmed)),
            n_updates=np.ones(n, np.int64),
            hist_t=hist_t,
            hist_r=hist_r,
            resolved=np.zeros(n, bool),
            anchor_x=np.array(x, float),
            anchor_P=P.copy(),
            anchor_t=np.full(n, float(time_s)),
            anchor_resolved=np.zeros(n, bool),
            was_confirmed=np.zeros(n, bool),
        )

    @property
    def size(self) -> int:
        """Number of tracks."""
        return int(self.ids.size)

    def keep(self, rows: np.ndarray) -> None:
        """Keep only ``rows`` (indices or a boolean mask), in their order, in place."""
        for f in fields(self):
            setattr(self, f.name, getattr(self, f.name)[rows])

    def extend(self, other: TrackArrays) -> None:
        """Append ``other``'s tracks after these, in place."""
        for f in fields(self):
            setattr(self, f.name, np.concatenate([getattr(self, f.name), getattr(other, f.name)]))

    def set_anchor(self, rows: np.ndarray, time_s: float) -> None:
        """Anchor tracks ``rows`` at their current state, at ``time_s``."""
        self.anchor_x[rows] = self.x[rows]
        self.anchor_P[rows] = self.P[rows]
        self.anchor_t[rows] = time_s
        self.anchor_resolved[rows] = self.resolved[rows]


@dataclass(frozen=True)
class FrameTracks:
    """Confirmed tracks after one frame.

    Attributes
    ----------
    time_s : float
    track_id : ndarray of int, shape (k,)
    state : ndarray, shape (k, 4)
        (range [m], radial velocity [m/s], range rate [m/s], radial acceleration [m/s^2]).
    covariance : ndarray, shape (k, 4, 4)
    n_updates : ndarray of int, shape (k,)
    detection_index : ndarray of int, shape (k,)
        Row of the frame's detections assigned to the track, -1 when it coasted.
    innovation : ndarray, shape (k, 2)
        Innovation of the assigned detection (range [m], radial velocity [m/s]); NaN when coasting.
    alive_ids, alive_detection : ndarray of int
        All live tracks (tentative too) and their assigned detection rows, for the 3-D tracker.
    confirmed : ndarray of bool, shape (k,)
        Whether each reported track is confirmed (all True unless ``report_tentative``).
    reacquired : ndarray of int, shape (r, 2)
        (id at birth, lost id it took) of the tracks that reacquired a lost track in this frame.

    Examples
    --------
    What :meth:`~skyradar.track.tracker.RangeDopplerTracker.step` returns: the tentative track is
    live but not reported until the fourth frame confirms it.

    >>> from skyradar.track.models import radar_model
    >>> from skyradar.track.tracker import RangeDopplerTracker
    >>> trk = RangeDopplerTracker(radar_model(78.3))
    >>> frames = [trk.step(0.1 * k, np.array([[1000.0 - 5.0 * k, -50.0]])) for k in range(4)]
    >>> frames[2].track_id.tolist(), frames[2].alive_ids.tolist()
    ([], [0])
    >>> out = frames[3]
    >>> out.track_id.tolist(), out.n_updates.tolist(), out.detection_index.tolist(), out.state.shape
    ([0], [4], [0], (1, 4))
    """

    time_s: float
    track_id: np.ndarray
    state: np.ndarray
    covariance: np.ndarray
    n_updates: np.ndarray
    detection_index: np.ndarray
    innovation: np.ndarray
    alive_ids: np.ndarray
    alive_detection: np.ndarray
    confirmed: np.ndarray
    reacquired: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int64))
