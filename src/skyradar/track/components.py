"""The roles a tracker is composed of, as typed interfaces (Stone Soup's components).

:class:`~skyradar.track.tracker.RangeDopplerTracker` is put together from parts passed in: a
predictor that carries every track's state to the frame's time, an associator that gates and
assigns detections to tracks, an updater that corrects the assigned tracks with their innovations,
an initiator that confirms tentative tracks, a deleter that closes tracks, and a reacquirer that
gives a lost track's id back to the aircraft when it is found again. Each role is a
:class:`typing.Protocol`: any object with the methods (and the attributes the tracker reads) fits,
without inheriting from anything, and a type checker or ``isinstance`` (the protocols are
runtime-checkable) says whether it does. The motion model (the transition, process-noise and
measurement matrices the predictor and updater are given) is the
:class:`~skyradar.track.models.MotionModel` value the tracker is built with.

The shipped parts: :func:`~skyradar.track.kalman.predict` and :func:`~skyradar.track.kalman.update`
(the batched Kalman step, Joseph-form covariance),
:func:`~skyradar.track.association.associate` (Hungarian assignment in a Mahalanobis or pixel gate,
Doppler-alias aware), :class:`~skyradar.track.initiation.MOfN`,
:class:`~skyradar.track.deletion.MissDeleter` and :class:`~skyradar.track.reacquisition.LostTracks`.

Examples
--------
>>> from skyradar.track.deletion import MissDeleter
>>> from skyradar.track.initiation import MOfN
>>> from skyradar.track.kalman import predict, update
>>> isinstance(MissDeleter(), Deleter), isinstance(MOfN(3, 4), Initiator)
(True, True)
>>> isinstance(predict, Predictor), isinstance(update, Updater)
(True, True)
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from skyradar.track.association import Association
from skyradar.track.types import TrackArrays

__all__ = ["Predictor", "Associator", "Updater", "Initiator", "Deleter", "Reacquirer"]


@runtime_checkable
class Predictor(Protocol):
    """Carries a stack of track states forward by one time step."""

    def __call__(
        self, x: np.ndarray, P: np.ndarray, F: np.ndarray, Q: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """States ``x`` (n, d) and covariances ``P`` (n, d, d) one step later, from the step's
        transition ``F`` and process noise ``Q`` (each (d, d), or (n, d, d) per track), in the
        states' units (m, m/s, ...)."""
        ...


@runtime_checkable
class Associator(Protocol):
    """Gates and assigns one frame's detections to the predicted tracks."""

    def __call__(
        self,
        z_pred: np.ndarray,
        S: np.ndarray,
        z: np.ndarray,
        gate: float,
        doppler_width_mps: float | None = None,
        range_wrap_m: np.ndarray | None = None,
        metric: str = "mahalanobis",
        pixel_size: tuple[float, float] = (1.0, 1.0),
        max_alias: int = 2,
    ) -> Association:
        """Pairs of (track row of ``z_pred``, detection row of ``z``) with their innovations.

        ``z_pred`` (n, 2) and ``z`` (m, 2) are (range [m], radial velocity [m/s]); ``S`` (n, 2, 2)
        the innovation covariances; ``gate`` the largest assignment cost kept.
        """
        ...


@runtime_checkable
class Updater(Protocol):
    """Corrects the assigned tracks' states with their measurements' innovations."""

    def __call__(
        self,
        x: np.ndarray,
        P: np.ndarray,
        y: np.ndarray,
        H: np.ndarray,
        R: np.ndarray,
        S: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """States ``x`` (n, d) and covariances ``P`` (n, d, d) after the update with innovations
        ``y`` (n, k) (wrapped by the tracker where the measurement space is circular), the
        measurement matrix ``H`` (k, d), the measurement noise ``R`` (k, k) and, when the caller
        has it, the innovation covariance ``S`` (n, k, k)."""
        ...


@runtime_checkable
class Initiator(Protocol):
    """Confirms tentative tracks on a sliding window of hits (``m`` of the last ``n`` frames)."""

    m: int
    n: int

    def window_status(self, window: np.ndarray, misses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Which tracks are confirmed and which failed, from each track's hit window (a bit per
        frame, newest lowest) and its consecutive misses."""
        ...


@runtime_checkable
class Deleter(Protocol):
    """Closes tracks that went unobserved."""

    max_coast_s: float

    def delete(self, misses: np.ndarray, time_since_update_s: np.ndarray) -> np.ndarray:
        """Boolean mask of tracks to close, from their consecutive misses and time without an update, s."""
        ...


@runtime_checkable
class Reacquirer(Protocol):
    """Keeps closed confirmed tracks and gives their id to a new track on the same aircraft."""

    def __len__(self) -> int:
        """Lost tracks kept."""
        ...

    def add_anchored(self, tracks: TrackArrays, mask: np.ndarray) -> None:
        """Keep the tracker's tracks ``mask``, at their anchor states."""
        ...

    def match(self, x: np.ndarray, P: np.ndarray, time_s: float) -> tuple[np.ndarray, np.ndarray]:
        """Lost id (-1: none) and velocity alias shift for each newly confirmed state ``x``, ``P``."""
        ...

    def predict(
        self, x: np.ndarray, P: np.ndarray, resolved: np.ndarray, dt_s: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """States ``x``, ``P`` (alias ``resolved``) carried ``dt_s`` seconds across a gap, as a lost
        track is carried to be matched."""
        ...
