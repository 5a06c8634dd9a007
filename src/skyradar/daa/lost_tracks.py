"""Alert continuity through a lost track: its prediction holds the alert it had.

A radar loses a closing intruder for a few seconds when it passes a clutter ridge, fades (Swerling),
or crosses into another head's beam; the tracker keeps the lost track for reacquisition
(:mod:`skyradar.track.reacquisition`) and gives the aircraft its id back when it is seen again. The
threat did not go away meanwhile, so the alert must not either: a warning that drops for three
seconds and comes back is two warnings to a pilot, and a pilot who turned away has nothing to
follow. On every frame a confirmed track has no confirmed row, up to ``lost_track_hold_s`` after
its last one, :func:`lost_track_rows` adds the track's constant-velocity prediction from that row,
its covariance grown by the white acceleration of the gap. The alerter lets such a row hold the
level the track has reached, never raise it: a prediction is no evidence of a new conflict.

Examples
--------
>>> tracks = pd.DataFrame({"time_s": [0.0, 0.5, 2.0], "track_id": 1, "north_m": [3000.0, 2950.0, 2800.0],
...                        "east_m": 0.0, "down_m": -500.0, "vn_mps": -100.0, "ve_mps": 0.0, "vd_mps": 0.0})
>>> out = lost_track_rows(tracks, np.arange(0.0, 2.6, 0.5), hold_s=8.0)
>>> out["north_m"].tolist(), out["extrapolated"].tolist()
([3000.0, 2950.0, 2900.0, 2850.0, 2800.0, 2750.0], [False, False, True, True, False, True])
"""

from __future__ import annotations

import numpy as np
import pandas as pd

__all__ = ["lost_track_rows", "SIGMA_ACCEL_MPS2"]

# White acceleration of a prediction across a gap, m/s^2 per axis: the tracker's 3-D filter's.
SIGMA_ACCEL_MPS2 = 2.0
_POS = ("north_m", "east_m", "down_m")
_VEL = ("vn_mps", "ve_mps", "vd_mps")


def _grown_covariances(rows: pd.DataFrame, dt: np.ndarray) -> dict[str, np.ndarray]:
    """The 3 x 3 covariance columns of ``rows`` predicted ``dt`` seconds on (constant velocity)."""
    names = {k: [f"cov_{k}_{i}{j}" for i in range(3) for j in range(3)] for k in ("pp", "vv", "pv")}
    if not all(c in rows for k in names for c in names[k]):
        return {}
    pp, vv, pv = (rows[names[k]].to_numpy(float).reshape(-1, 3, 3) for k in ("pp", "vv", "pv"))
    d = dt[:, None, None]
    q = SIGMA_ACCEL_MPS2**2 * np.eye(3)
    grown = {
        "pp": pp + d * (pv + np.swapaxes(pv, 1, 2)) + d**2 * vv + q * d**4 / 4.0,
        "vv": vv + q * d**2,
        "pv": pv + d * vv + q * d**3 / 2.0,
    }
    return {c: grown[k].reshape(-1, 9)[:, n] for k in names for n, c in enumerate(names[k])}


def lost_track_rows(
    tracks: pd.DataFrame, frame_times_s: np.ndarray, hold_s: float, only_at_s: float | None = None
) -> pd.DataFrame:
    """The tracks table with a predicted row on every frame a track has no row, up to ``hold_s`` s after
    its last row (and never before its first).

    Parameters
    ----------
    tracks : DataFrame
        Confirmed rows with a 3-D state (``time_s, track_id``, NED ``north_m, east_m, down_m`` in m,
        ``vn_mps, ve_mps, vd_mps`` in m/s; the ``cov_pp_ij, cov_vv_ij, cov_pv_ij`` covariances when
        present).
    frame_times_s : ndarray
        The frame times, s (the own-ship table's).
    hold_s : float
        Longest prediction, s (0: no rows added).
    only_at_s : float, optional
        Add predicted rows on the frame at this time only, s (a stream's latest frame).

    Returns
    -------
    DataFrame
        ``tracks`` and the predicted rows (other columns copied from the row they start from, the
        ``range_m`` and ``range_rate_mps`` measurements NaN), with a column ``extrapolated`` (True on
        predicted rows), sorted by time and track.

    Examples
    --------
    A track closing at 100 m/s, last seen at 1 s, held 2 s on frames 1 s apart:

    >>> tracks = pd.DataFrame({"time_s": [0.0, 1.0], "track_id": 1, "north_m": [3000.0, 2900.0],
    ...     "east_m": 0.0, "down_m": 0.0, "vn_mps": -100.0, "ve_mps": 0.0, "vd_mps": 0.0})
    >>> out = lost_track_rows(tracks, np.arange(5.0), hold_s=2.0)
    >>> out["time_s"].tolist(), out["north_m"].tolist(), out["extrapolated"].tolist()
    ([0.0, 1.0, 2.0, 3.0], [3000.0, 2900.0, 2800.0, 2700.0], [False, False, True, True])
    """
    out = tracks.assign(extrapolated=False)
    frames = np.unique(np.asarray(frame_times_s, float))
    if hold_s <= 0.0 or len(tracks) == 0 or frames.size < 2:
        return out
    half_frame = 0.5 * float(np.median(np.diff(frames)))
    if only_at_s is not None:
        added = _lost_at(tracks, float(only_at_s), frames, hold_s, half_frame)
    else:
        added = _lost_on_frames(tracks, frames, hold_s, half_frame)
    if not added:
        return out
    merged = pd.concat([out, *added], ignore_index=True)
    merged.attrs = dict(tracks.attrs)
    return merged.sort_values(["time_s", "track_id"], kind="stable").reset_index(drop=True)


def _predicted(start: pd.DataFrame, at_s: np.ndarray, dt: np.ndarray) -> pd.DataFrame:
    """The rows ``start`` predicted ``dt`` s on to the times ``at_s`` (constant velocity), flagged."""
    moved = {
        p: start[p].to_numpy(float) + start[v].to_numpy(float) * dt for p, v in zip(_POS, _VEL, strict=True)
    }
    unmeasured = {c: np.nan for c in ("range_m", "range_rate_mps") if c in start}
    return start.assign(time_s=at_s, extrapolated=True, **moved, **unmeasured).assign(
        **_grown_covariances(start, dt)
    )


def _lost_at(
    tracks: pd.DataFrame, at_s: float, frames: np.ndarray, hold_s: float, half_frame: float
) -> list[pd.DataFrame]:
    """The predicted rows of the frame at ``at_s`` alone, every track at once (a stream's step):
    the rule of :func:`_lost_on_frames` on one frame."""
    if not np.any(frames == at_s):
        return []
    ids = tracks["track_id"].to_numpy()
    order = np.argsort(ids, kind="stable")  # each track's rows in their table order, as groupby keeps them
    t, ids = tracks["time_s"].to_numpy(float)[order], ids[order]
    first = np.flatnonzero(np.r_[True, ids[1:] != ids[:-1]])
    end = np.r_[first[1:], t.size] - 1  # each track's last row
    inside = (t[first] < at_s) & (at_s <= t[end] + hold_s)
    last = first + np.add.reduceat(t <= at_s, first) - 1  # the row at or before the frame
    after = np.minimum(last + 1, end)
    nearest = np.minimum(at_s - t[last], np.abs(t[after] - at_s))
    dt = at_s - t[last]
    gap = inside & (nearest > half_frame) & (dt <= hold_s)
    if not gap.any():
        return []
    start = tracks.iloc[order[last[gap]]].reset_index(drop=True)
    return [_predicted(start, np.full(int(gap.sum()), at_s), dt[gap])]


def _lost_on_frames(
    tracks: pd.DataFrame, frames: np.ndarray, hold_s: float, half_frame: float
) -> list[pd.DataFrame]:
    """Each track's predicted rows on the frames it has no row within half a frame of, after its
    first row and up to ``hold_s`` after the row before."""
    added = []
    for _, rows in tracks.groupby("track_id", sort=False):
        t = rows["time_s"].to_numpy(float)
        window = frames[(frames > t[0]) & (frames <= t[-1] + hold_s)]
        last = np.searchsorted(t, window, side="right") - 1  # the row at or before each frame
        after = np.minimum(last + 1, t.size - 1)
        nearest = np.minimum(window - t[last], np.abs(t[after] - window))
        gap_frames, last = window[nearest > half_frame], last[nearest > half_frame]
        if gap_frames.size == 0:
            continue
        dt = gap_frames - t[last]
        keep = dt <= hold_s
        if not keep.any():
            continue
        start = rows.iloc[last[keep]].reset_index(drop=True)
        added.append(_predicted(start, gap_frames[keep], dt[keep]))
    return added
