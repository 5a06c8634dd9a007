"""Track initiation with M-of-N confirmation.

Every detection left unassigned starts a tentative track. A tentative track is confirmed once it
has been updated in at least ``m`` of its first ``n`` frames (the birth frame counts); a tentative
track that can no longer reach ``m`` hits within ``n`` frames is dropped. This keeps isolated
clutter from becoming tracks while a real target is confirmed after ``m`` frames.
"""

from __future__ import annotations

import numpy as np

__all__ = ["MOfN", "confirmation_status"]


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
