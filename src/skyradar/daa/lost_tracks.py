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

A track that was closing on the own-ship when it was lost is held longer: up to its predicted time
of closest approach, at most ``closing_hold_s`` (:func:`lost_track_hold`). The threat of a closing
aircraft lasts until it has passed, whatever the time the radar needs to see it again; and the
fast closures that hide longest are those a terrain's clutter ridge covers for seconds on end, at
the ranges where a warning matters most. The prediction's own geometry still decides: it holds a
level only while it predicts that level's loss of well clear, so the hold ends once the predicted
closest approach is passed or the prediction no longer conflicts.

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

__all__ = ["lost_track_hold", "lost_track_rows", "SIGMA_ACCEL_MPS2"]

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


def lost_track_hold(
    relative_position_m: np.ndarray, relative_velocity_mps: np.ndarray, hold_s: float, closing_hold_s: float
) -> np.ndarray:
    """How long a prediction from each track row may stand in for the track once it is lost, s.

    ``hold_s`` for every row, and for a row closing on the own-ship (relative position and velocity
    with a negative dot product) its time to the closest approach, ``-s.v / |v|^2``, when that is
    longer, at most ``closing_hold_s``.

    Parameters
    ----------
    relative_position_m, relative_velocity_mps : ndarray, shape (n, 3)
        The intruder's position (m) and velocity (m/s) relative to the own-ship, NED.
    hold_s : float
        The hold of every lost track, s.
    closing_hold_s : float
        The longest hold of a closing track, s (at most ``hold_s``: closing tracks are held as the
        others are).

    Returns
    -------
    ndarray, shape (n,)
        The hold from each row, s (``hold_s`` where the state is not finite).

    Examples
    --------
    Head-on at 2 km closing at 100 m/s (closest approach in 20 s), and the same aircraft receding:

    >>> s = np.array([[2000.0, 0.0, 0.0], [2000.0, 0.0, 0.0]])
    >>> v = np.array([[-100.0, 0.0, 0.0], [100.0, 0.0, 0.0]])
    >>> lost_track_hold(s, v, hold_s=8.0, closing_hold_s=25.0).tolist()
    [20.0, 8.0]
    """
    s, v = np.asarray(relative_position_m, float), np.asarray(relative_velocity_mps, float)
    closing_rate = -np.einsum("ij,ij->i", s, v)  # -s.v, m^2/s
    speed_sq = np.einsum("ij,ij->i", v, v)
    with np.errstate(divide="ignore", invalid="ignore"):
        tcpa = np.where(closing_rate > 0.0, closing_rate / speed_sq, 0.0)
    tcpa = np.where(np.isfinite(tcpa), tcpa, 0.0)
    return np.maximum(float(hold_s), np.minimum(tcpa, float(closing_hold_s)))


def lost_track_rows(
    tracks: pd.DataFrame,
    frame_times_s: np.ndarray,
    hold_s: float | np.ndarray,
    only_at_s: float | None = None,
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
    hold_s : float or ndarray
        Longest prediction, s (0: no rows added); per row of ``tracks`` (:func:`lost_track_hold`),
        the hold of a gap is that of the row before it.
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
    holds = np.broadcast_to(np.asarray(hold_s, float), (len(tracks),))
    if len(tracks) == 0 or not (holds > 0.0).any() or frames.size < 2:
        return out
    half_frame = 0.5 * float(np.median(np.diff(frames)))
    if only_at_s is not None:
        added = _lost_at(tracks, float(only_at_s), frames, holds, half_frame)
    else:
        added = _lost_on_frames(tracks, frames, holds, half_frame)
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
    tracks: pd.DataFrame, at_s: float, frames: np.ndarray, holds: np.ndarray, half_frame: float
) -> list[pd.DataFrame]:
    """The predicted rows of the frame at ``at_s`` alone, every track at once (a stream's step):
    the rule of :func:`_lost_on_frames` on one frame."""
    if not np.any(frames == at_s):
        return []
    ids = tracks["track_id"].to_numpy()
    order = np.argsort(ids, kind="stable")  # each track's rows in their table order, as groupby keeps them
    t, ids, holds = tracks["time_s"].to_numpy(float)[order], ids[order], holds[order]
    first = np.flatnonzero(np.r_[True, ids[1:] != ids[:-1]])
    end = np.r_[first[1:], t.size] - 1  # each track's last row
    last = first + np.add.reduceat(t <= at_s, first) - 1  # the row at or before the frame
    after = np.minimum(last + 1, end)
    nearest = np.minimum(at_s - t[last], np.abs(t[after] - at_s))
    dt = at_s - t[last]
    gap = (t[first] < at_s) & (nearest > half_frame) & (dt <= holds[last])
    if not gap.any():
        return []
    start = tracks.iloc[order[last[gap]]].reset_index(drop=True)
    return [_predicted(start, np.full(int(gap.sum()), at_s), dt[gap])]


def _lost_on_frames(
    tracks: pd.DataFrame, frames: np.ndarray, holds: np.ndarray, half_frame: float
) -> list[pd.DataFrame]:
    """Each track's predicted rows on the frames it has no row within half a frame of, after its
    first row and up to the hold of the row before (``holds``, per row) after it."""
    added = []
    for _, index in tracks.groupby("track_id", sort=False).indices.items():
        rows, hold = tracks.iloc[index], holds[index]
        t = rows["time_s"].to_numpy(float)
        window = frames[(frames > t[0]) & (frames <= t[-1] + hold.max())]
        last = np.searchsorted(t, window, side="right") - 1  # the row at or before each frame
        after = np.minimum(last + 1, t.size - 1)
        nearest = np.minimum(window - t[last], np.abs(t[after] - window))
        gap_frames, last = window[nearest > half_frame], last[nearest > half_frame]
        if gap_frames.size == 0:
            continue
        dt = gap_frames - t[last]
        keep = dt <= hold[last]
        if not keep.any():
            continue
        start = rows.iloc[last[keep]].reset_index(drop=True)
        added.append(_predicted(start, gap_frames[keep], dt[keep]))
    return added
