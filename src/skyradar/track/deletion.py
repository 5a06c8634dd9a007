"""Track deletion after missed detections.

A confirmed track is closed after ``max_misses`` consecutive frames without an assigned detection,
or after ``max_coast_s`` seconds without one, whichever comes first; a target that leaves the field
of view for longer becomes a new track when it comes back, as a count by hand would have it.
"""

from __future__ import annotations

import numpy as np

__all__ = ["MissDeleter"]


class MissDeleter:
    """Delete tracks after consecutive misses or a coasting time.

    Parameters
    ----------
    max_misses : int
        Consecutive missed frames before deletion.
    max_coast_s : float
        Time since the last update before deletion, s.

    Examples
    --------
    >>> MissDeleter(3, 1.0).delete(np.array([1, 3, 0]), np.array([0.1, 0.3, 2.0])).tolist()
    [False, True, True]
    """

    def __init__(self, max_misses: int = 20, max_coast_s: float = 2.0) -> None:
        if max_misses < 1 or not max_coast_s > 0:
            raise ValueError(f"need max_misses >= 1 and max_coast_s > 0, got {max_misses}, {max_coast_s}")
        self.max_misses, self.max_coast_s = int(max_misses), float(max_coast_s)

    def delete(self, misses: np.ndarray, time_since_update_s: np.ndarray) -> np.ndarray:
        """Boolean mask of tracks to close."""
        return (np.asarray(misses) >= self.max_misses) | (np.asarray(time_since_update_s) > self.max_coast_s)
