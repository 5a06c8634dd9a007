"""Settings and per-frame output of the range-Doppler tracker."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["TrackerConfig", "FrameTracks"]


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
    max_alias : int
        Largest alias (in image widths) a single-observation track may be off by.
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
    reacquire_jerk_mps3 : float
        White jerk of a lost track's prediction across the gap, m/s^3.
    """

    gate: float = 16.0
    metric: str = "mahalanobis"
    confirm_m: int = 4
    confirm_n: int = 5
    max_misses: int = 20
    max_coast_s: float = 2.0
    history: int = 16
    max_alias: int = 2
    confirmed_first: bool = True
    dealias: str = "confident"
    resolve_fraction: float = 1.0 / 6.0
    reacquire_s: float = 8.0
    reacquire_jerk_mps3: float = 1.5


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
