"""Track ids through reacquisition, on the tracks table: which reacquisitions an aircraft keeps.

The tracker (:class:`~skyradar.track.reacquisition.LostTracks`) gives a newly confirmed track the
id of a lost one when their predicted range and Doppler agree. It decides frame by frame, before
the track-level ground test (:mod:`skyradar.track.ground_tracks`) has seen either history. A lost
track that was ground clutter predicts badly (its alias is often unresolved, its range spread is
hundreds of metres after a few seconds), so its large gate can take an aircraft's new track; the
aircraft's rows then carry the ground track's id (over hills an intruder can reacquire a chain
of ground clutter tracks and be warned under their id). Here each
reacquisition is undone unless the track that was lost is, on its own rows, an object the ground
test confirms: an aircraft's track does not inherit a ground track's id, and a ground track's
reacquisition by more ground is not joined into one long clutter track either.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pandas as pd

__all__ = ["relabel_reacquired"]


def relabel_reacquired(
    tracks: pd.DataFrame,
    pairs: np.ndarray,
    times_s: np.ndarray,
    is_object: Callable[[pd.DataFrame], bool] | None = None,
    verdicts: dict[tuple[int, int, float], bool] | None = None,
) -> pd.DataFrame:
    """A tracks table with each kept reacquisition's track under the lost track's id.

    Parameters
    ----------
    tracks : DataFrame
        Tracker rows (``time_s, track_id, detection_row``): from a reacquisition on, the
        reacquiring track's rows already carry the lost id; its tentative rows before carry its
        own id.
    pairs : ndarray of int, shape (k, 2)
        ``(new id, lost id)`` of each reacquisition.
    times_s : ndarray, shape (k,)
        Time of each reacquisition, s.
    is_object : callable, optional
        Takes the rows of the lost track alone (from its start, or its own reacquisition, up to
        this one) and says whether it was a real object; a reacquisition of a track that was not
        is undone (the new track keeps its own id). Default: every reacquisition is kept.
    verdicts : dict, optional
        ``is_object``'s verdict on each reacquisition, by ``(new id, lost id, time)``, read where
        present and filled in place: a caller that relabels a growing table (a stream's) judges
        each reacquisition once, on the lost track's rows before it, which no later row changes.

    Returns
    -------
    DataFrame
        Rows relabelled; where two rows of one id share a time, the one with a detection is kept.

    Examples
    --------
    >>> df = pd.DataFrame({"time_s": [0.0, 1.0, 2.0, 3.0], "track_id": [4, 4, 9, 4],
    ...                    "detection_row": [0, 1, 2, 3]})
    >>> relabel_reacquired(df, np.array([[9, 4]]), np.array([3.0])).track_id.tolist()
    [4, 4, 4, 4]
    >>> relabel_reacquired(df, np.array([[9, 4]]), np.array([3.0]), lambda rows: False).track_id.tolist()
    [4, 4, 9, 9]
    """
    if len(pairs) == 0:
        return tracks
    reported = tracks["track_id"].to_numpy()
    t = tracks["time_s"].to_numpy(float)
    segment = reported.copy()  # the track a row belongs to, whatever id the tracker reported
    holder: dict[int, int] = {}  # reported id -> the track holding it now
    final: dict[int, int] = {}  # track -> the id it ends under
    for k in np.argsort(np.asarray(times_s, float), kind="stable"):
        new, lost, time = int(pairs[k, 0]), int(pairs[k, 1]), float(times_s[k])
        before = holder.get(lost, lost)
        lost_rows = (segment == before) & (t < time)  # its tentative rows too, under its own id
        segment[(reported == lost) & (t >= time)] = new
        holder[lost] = new
        key = (new, lost, time)
        if verdicts is not None and key in verdicts:
            kept_id = verdicts[key]
        else:
            kept_id = is_object is None or is_object(tracks[lost_rows])
            if verdicts is not None:
                verdicts[key] = kept_id
        if kept_id:
            final[new] = final.get(before, before)
    tracked, where = np.unique(segment, return_inverse=True)
    ids = np.array([final.get(s, s) for s in tracked.tolist()], np.int64)[where.reshape(-1)]
    # Of two rows of one id at one time, the one with a detection stays (else the first).
    by_detection = np.argsort(tracks["detection_row"].to_numpy() < 0, kind="stable")
    keys = pd.DataFrame({"time_s": t[by_detection], "track_id": ids[by_detection]})
    kept = np.sort(by_detection[~keys.duplicated().to_numpy()])
    return tracks.iloc[kept].assign(track_id=ids[kept]).reset_index(drop=True)
