"""Track initiation with M-of-N confirmation.

Every detection left unassigned starts a tentative track. A tentative track is confirmed once it
has been updated in at least ``m`` of the last ``n`` frames (a sliding window, the usual M-of-N
logic); it is dropped after more than ``n - m`` consecutive misses, since no window of ``n`` frames
with ``m`` hits contains that many. So any run of ``m`` detections within ``n`` consecutive frames
that the tracker associates confirms a track, wherever the run starts, while isolated clutter
never does. (A window anchored at the birth frame instead drops a tentative track whose first
window misses and throws its detections away: a brief, patchy re-detection is then never tracked.)
"""

from __future__ import annotations

import numpy as np

__all__ = ["MOfN", "confirmation_status", "window_status", "push_hit"]


class MOfN:
    """M-of-N confirmation rule.

    Parameters
    ----------
    m : int
        Hits needed.
    n : int
        Frames (from birth) within which the hits must come; ``n >= m >= 1``.

    Examples
    --------
    >>> rule = MOfN(3, 4)
    >>> rule.status(np.array([3, 1, 2]), np.array([3, 3, 4]))
    (array([ True, False, False]), array([False,  True,  True]))
    """

    def __init__(self, m: int = 3, n: int = 4) -> None:
        if not (1 <= m <= n):
            raise ValueError(f"M-of-N needs 1 <= m <= n, got m={m}, n={n}")
        self.m, self.n = int(m), int(n)

    def status(self, hits: np.ndarray, frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Which tentative tracks are confirmed and which failed.

        Parameters
        ----------
        hits : ndarray of int
            Updates so far (including the birth detection).
        frames : ndarray of int
            Frames since birth, counting the birth frame.

        Returns
        -------
        confirmed, failed : ndarray of bool
        """
        return confirmation_status(hits, frames, self.m, self.n)

    def window_status(self, window: np.ndarray, misses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Sliding-window rule used by the tracker (see :func:`window_status`)."""
        return window_status(window, misses, self.m, self.n)


def confirmation_status(
    hits: np.ndarray, frames: np.ndarray, m: int, n: int
) -> tuple[np.ndarray, np.ndarray]:
    """``confirmed = hits >= m and frames <= n``; ``failed`` when the remaining frames cannot reach m.

    Examples
    --------
    >>> confirmation_status(np.array([2]), np.array([2]), 2, 3)
    (array([ True]), array([False]))
    """
    hits = np.asarray(hits)
    frames = np.asarray(frames)
    confirmed = (hits >= m) & (frames <= n)
    remaining = n - frames
    failed = ~confirmed & (hits + remaining < m)
    return confirmed, failed


def push_hit(window: np.ndarray, hit: np.ndarray, n: int) -> np.ndarray:
    """Shift one frame into hit windows: bit 0 is the newest frame, ``n`` bits are kept.

    Examples
    --------
    >>> push_hit(np.array([0b1011]), np.array([False]), 4).tolist()
    [6]
    """
    return ((np.asarray(window, np.int64) << 1) | np.asarray(hit, np.int64)) & ((1 << n) - 1)


def window_status(window: np.ndarray, misses: np.ndarray, m: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """``confirmed`` = at least ``m`` hits among the last ``n`` frames; ``failed`` = more than
    ``n - m`` consecutive misses (and not confirmed).

    Parameters
    ----------
    window : ndarray of int
        Hit bits of the last ``n`` frames (:func:`push_hit`).
    misses : ndarray of int
        Consecutive misses up to now.

    Examples
    --------
    >>> window_status(np.array([0b11011, 0b00101, 0b11000]), np.array([0, 0, 3]), 4, 5)
    (array([ True, False, False]), array([False, False,  True]))
    """
    confirmed = np.bitwise_count(np.asarray(window, np.int64)) >= m
    failed = ~confirmed & (np.asarray(misses) > n - m)
    return confirmed, failed
