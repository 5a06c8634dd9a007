"""Track quality: innovation statistics, track counts, fragmentation, identity switches, GOSPA.

Tracks and truth are compared in the range-Doppler image in pixels, with the Doppler distance
taken the shortest way round the image (an aliased track is on its target). Per frame the
confirmed tracks are matched to the visible truths by the Hungarian algorithm on that distance,
with a match threshold; the counts below follow from that matching:

* ``truth_tracks``: visible segments of the intruders (runs of visibility, gaps shorter than
  ``gap_s`` bridged), i.e. what a count by hand would give;
* ``tracks``: distinct confirmed track ids; ``false_tracks``: of those, never matched to a truth;
* ``fragmentation``: sum over truth segments of (distinct tracks matched to it - 1);
* ``id_switches``: frames in which a truth segment is matched to a different track than the last
  one it was matched to (CLEAR-MOT style);
* ``completeness``: share of visible truth frames (in counted segments) matched by a track;
* ``missed_truth_tracks``: counted truth segments that no confirmed track was ever matched to;
* GOSPA (García-Fernández et al., alpha = 2) per frame, on the same distance, averaged over frames.

Only confirmed rows (``confirmed`` column, when present) are matched and counted. Innovation
statistics cover every update of those tracks, including the ones before confirmation (a track's
first updates are part of tracking it); ``*_confirmed`` repeats them over confirmed rows only.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd
from scipy.optimize import linear_sum_assignment

from skyradar.track.io import Truth
from skyradar.units import wrap

__all__ = [
    "innovation_stats",
    "gospa",
    "pixel_distance",
    "truth_segments",
    "detected_truth",
    "match_tracks",
    "existing_rows",
    "track_metrics",
]


def innovation_stats(innovation: np.ndarray, pixel_size: tuple[float, float]) -> dict[str, float]:
    """Mean and 95th percentile of the l2 innovation in pixels, and per axis in SI units.

    Parameters
    ----------
    innovation : ndarray, shape (n, 2)
        (range [m], radial velocity [m/s]) innovations; rows with NaN are ignored.
    pixel_size : (float, float)
        (dR [m], dV [m/s]).

    Examples
    --------
    >>> innovation_stats(np.array([[3.0, 0.4], [0.0, 0.0]]), (1.5, 0.1))["innov_mean_px"]
    2.23606797749979
    """
    y = np.asarray(innovation, float).reshape(-1, 2)
    y = y[np.all(np.isfinite(y), axis=1)]
    if y.shape[0] == 0:
        nan = float("nan")
        keys = ("innov_mean_px", "innov_p95_px", "innov_range_mean_m", "innov_range_p95_m")
        return {
            **dict.fromkeys(keys, nan),
            "innov_doppler_mean_mps": nan,
            "innov_doppler_p95_mps": nan,
            "n_innov": 0,
        }
    px = np.hypot(y[:, 0] / pixel_size[0], y[:, 1] / pixel_size[1])
    ar, ad = np.abs(y[:, 0]), np.abs(y[:, 1])
    return {
        "innov_mean_px": float(px.mean()),
        "innov_p95_px": float(np.percentile(px, 95)),
        "innov_range_mean_m": float(ar.mean()),
        "innov_range_p95_m": float(np.percentile(ar, 95)),
        "innov_doppler_mean_mps": float(ad.mean()),
        "innov_doppler_p95_mps": float(np.percentile(ad, 95)),
        "n_innov": int(y.shape[0]),
    }


def gospa(distances: np.ndarray, c: float, p: float = 2.0) -> dict[str, float]:
    """GOSPA (alpha = 2) between m estimates and n truths from their distance matrix.

    ``GOSPA^p = min over assignments of sum min(d, c)^p + c^p / 2 * (unassigned estimates +
    unassigned truths)``; only pairs closer than ``c`` count as assigned.

    Parameters
    ----------
    distances : ndarray, shape (m, n)
        Distance from each estimate (row) to each truth (column).
    c : float
        Cut-off distance.
    p : float
        Order, ``p >= 1``.

    Returns
    -------
    dict with ``distance``, ``localisation``, ``missed``, ``false`` (the last three in the p-th power,
    as Stone Soup reports them).

    Examples
    --------
    >>> round(gospa(np.array([[1.0, 20.0]]), c=10.0)["distance"] ** 2, 9)
    51.0
    """
    d = np.asarray(distances, float)
    m, n = d.shape
    half = c**p / 2.0
    if m == 0 or n == 0:
        missed, false = n * half, m * half
        return {
            "distance": float((missed + false) ** (1 / p)),
            "localisation": 0.0,
            "missed": missed,
            "false": false,
        }
    capped = np.minimum(d, c) ** p
    rows, cols = linear_sum_assignment(capped)
    real = d[rows, cols] < c
    loc = float(capped[rows[real], cols[real]].sum())
    k = int(real.sum())
    missed, false = (n - k) * half, (m - k) * half
    return {
        "distance": float((loc + missed + false) ** (1 / p)),
        "localisation": loc,
        "missed": missed,
        "false": false,
    }


def pixel_distance(
    a_rd: np.ndarray, b_rd: np.ndarray, pixel_size: tuple[float, float], doppler_width_mps: float | None
) -> np.ndarray:
    """Pairwise range-Doppler distance in pixels, Doppler wrapped when a width is given; (m, n).

    Examples
    --------
    >>> pixel_distance(np.array([[0.0, 39.0]]), np.array([[0.0, -39.0]]), (15.0, 0.5), 78.0).tolist()
    [[0.0]]
    """
    a = np.asarray(a_rd, float).reshape(-1, 2)
    b = np.asarray(b_rd, float).reshape(-1, 2)
    dr = (a[:, None, 0] - b[None, :, 0]) / pixel_size[0]
    dv = a[:, None, 1] - b[None, :, 1]
    if doppler_width_mps is not None:
        dv = wrap(dv, doppler_width_mps)
    return np.hypot(dr, dv / pixel_size[1])


def truth_segments(
    truth: Truth, gap_s: float = 1.0, min_duration_s: float = 0.0, confirm: tuple[int, int] = (1, 1)
) -> np.ndarray:
    """Label each (time, target) with its visible segment id, -1 where invisible or not counted.

    Runs of visibility separated by less than ``gap_s`` are one segment; segments shorter than
    ``min_duration_s``, or with no ``confirm = (m, n)`` window (m visible frames among n
    consecutive frames, the tracker's M-of-N), are not counted.

    Examples
    --------
    >>> t = np.arange(6.0)
    >>> vis = np.array([[1, 1, 0, 0, 1, 1]], bool).T
    >>> truth_segments(Truth(t, np.zeros((6, 1)), np.zeros((6, 1)), vis), gap_s=1.5)[:, 0].tolist()
    [0, 0, -1, -1, 1, 1]
    """
    t = truth.time_s
    labels = np.full(truth.visible.shape, -1, np.int64)
    next_id = 0
    for j in range(truth.visible.shape[1]):
        idx = np.flatnonzero(truth.visible[:, j])
        if idx.size == 0:
            continue
        breaks = np.flatnonzero(np.diff(t[idx]) > gap_s) + 1
        for run in np.split(idx, breaks):
            m, n = confirm
            in_window = np.searchsorted(run, run + n - 1, "right") - np.arange(run.size)
            if t[run[-1]] - t[run[0]] < min_duration_s or in_window.max() < m:
                continue
            labels[run, j] = next_id
            next_id += 1
    return labels


def detected_truth(
    truth: Truth,
    detections: pd.DataFrame,
    pixel_size: tuple[float, float],
    doppler_width_mps: float | None,
    threshold_px: float = 2.0,
    coupling_s: float = 0.0,
) -> np.ndarray:
    """Which truths were detected in which frame: a detection within ``threshold_px`` pixels.

    This is the oracle's view of the image sequence (what a count by hand sees): with
    :func:`truth_segments` it gives the number of aircraft visits a tracker could follow.
    ``coupling_s`` adds the range-Doppler coupling to the truth range before comparing.

    Parameters
    ----------
    truth : Truth
        Intruder truth on the frame grid.
    detections : DataFrame
        ``time_s`` (s), ``range_m`` (m) and ``radial_velocity_mps`` (m/s).
    pixel_size : (float, float)
        Range bin (m) and Doppler bin (m/s) of one pixel.
    doppler_width_mps : float or None
        Width of the Doppler image, m/s: the Doppler difference is wrapped into it (None: not).
    threshold_px : float
        Largest distance of a detection from the truth, pixels.
    coupling_s : float
        Range-Doppler coupling, s (m of apparent range per m/s).

    Returns
    -------
    ndarray of bool, shape (n_time, n_target)

    Examples
    --------
    A target closing at 50 m/s: at 1 s the detection is 2 pixels of range off, at 3 s its Doppler
    has aliased by the image width of 78.3 m/s:

    >>> t = np.arange(4.0)
    >>> truth = Truth(t, (1000.0 - 50.0 * t)[:, None], np.full((4, 1), -50.0), np.ones((4, 1), bool))
    >>> det = pd.DataFrame({"time_s": [0.0, 1.0, 3.0], "range_m": [1001.0, 980.0, 850.0],
    ...                     "radial_velocity_mps": [-50.0, -50.0, -50.0 + 78.3]})
    >>> detected_truth(truth, det, (15.0, 0.3), 78.3)[:, 0].tolist()
    [True, False, False, True]
    """
    n_time, n_tgt = truth.visible.shape
    out = np.zeros((n_time, n_tgt), bool)
    t_det = detections["time_s"].to_numpy(float)
    k = np.clip(np.searchsorted(truth.time_s, t_det - 1e-9), 0, n_time - 1)
    r = truth.range_m[k] + coupling_s * truth.radial_velocity_mps[k]
    dr = (detections["range_m"].to_numpy(float)[:, None] - r) / pixel_size[0]
    dv = detections["radial_velocity_mps"].to_numpy(float)[:, None] - truth.radial_velocity_mps[k]
    if doppler_width_mps is not None:
        dv = wrap(dv, doppler_width_mps)
    d = np.hypot(dr, dv / pixel_size[1])
    hit = np.nan_to_num(d, nan=np.inf) < threshold_px
    rows, cols = np.nonzero(hit)
    out[k[rows], cols] = True
    return out & truth.visible


def match_tracks(
    tracks: pd.DataFrame,
    truth: Truth,
    pixel_size: tuple[float, float],
    doppler_width_mps: float | None,
    threshold_px: float = 5.0,
    gospa_c_px: float = 10.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Per truth frame: matched track id per target (-1 when none) and the GOSPA distance.

    Tracks are taken at the truth frame nearest in time (within half a frame interval).

    Parameters
    ----------
    tracks : DataFrame
        ``time_s`` (s), ``track_id``, ``range_m`` (m) and ``radial_velocity_mps`` (m/s).
    truth : Truth
        Intruder truth on the frame grid.
    pixel_size : (float, float)
        Range bin (m) and Doppler bin (m/s) of one pixel.
    doppler_width_mps : float or None
        Width of the Doppler image, m/s (None: the Doppler difference is not wrapped).
    threshold_px : float
        Largest track-to-truth distance of a match, pixels.
    gospa_c_px : float
        GOSPA cut-off distance, pixels.

    Returns
    -------
    matched : ndarray of int, shape (n_time, n_target)
        Matched track id, -1 when none.
    gospa : ndarray, shape (n_time,)
        GOSPA distance per frame, pixels.

    Examples
    --------
    One track on the target and one far from it: the far one costs ``sqrt(c^2 / 2)`` of GOSPA.

    >>> t = np.arange(3.0)
    >>> truth = Truth(t, (1000.0 - 50.0 * t)[:, None], np.full((3, 1), -50.0), np.ones((3, 1), bool))
    >>> tracks = pd.DataFrame({"time_s": np.r_[t, t], "track_id": np.repeat([7, 8], 3),
    ...     "range_m": np.r_[1000.0 - 50.0 * t, 3000.0 + 0 * t], "radial_velocity_mps": -50.0})
    >>> matched, d = match_tracks(tracks, truth, (15.0, 0.3), 78.3)
    >>> matched[:, 0].tolist(), bool(np.allclose(d, np.sqrt(10.0**2 / 2)))
    ([7, 7, 7], True)
    """
    n_time, n_tgt = truth.visible.shape
    matched = np.full((n_time, n_tgt), -1, np.int64)
    gospa_d = np.zeros(n_time)
    t_trk = tracks["time_s"].to_numpy(float)
    half = 0.5 * float(np.median(np.diff(truth.time_s))) if n_time > 1 else np.inf
    nearest = (
        np.clip(np.searchsorted(truth.time_s, t_trk), 1, max(n_time - 1, 1))
        if n_time > 1
        else np.zeros(len(t_trk), int)
    )
    if n_time > 1:
        left = truth.time_s[nearest - 1]
        nearest = np.where(
            np.abs(t_trk - left) <= np.abs(truth.time_s[nearest] - t_trk), nearest - 1, nearest
        )
    ok = np.abs(truth.time_s[nearest] - t_trk) <= half if len(t_trk) else np.zeros(0, bool)
    frame_of = np.where(ok, nearest, -1)
    order = np.argsort(frame_of, kind="stable")
    bounds = np.searchsorted(frame_of[order], np.arange(n_time + 1))
    rd = tracks[["range_m", "radial_velocity_mps"]].to_numpy(float)
    ids = tracks["track_id"].to_numpy(np.int64)
    last = np.full(n_tgt, -1, np.int64)
    for k in range(n_time):
        rows = order[bounds[k] : bounds[k + 1]]
        vis = np.flatnonzero(truth.visible[k])
        truth_rd = np.column_stack([truth.range_m[k, vis], truth.radial_velocity_mps[k, vis]])
        d = pixel_distance(rd[rows], truth_rd, pixel_size, doppler_width_mps)
        gospa_d[k] = gospa(d, gospa_c_px)["distance"]
        if rows.size and vis.size:
            matched[k, vis] = _match_frame(d, ids[rows], last[vis], threshold_px)
            last[vis] = np.where(matched[k, vis] >= 0, matched[k, vis], last[vis])
    return matched, gospa_d


def _match_frame(
    d: np.ndarray, track_ids: np.ndarray, previous: np.ndarray, threshold_px: float
) -> np.ndarray:
    """Track id per truth column of ``d`` (tracks x truths), -1 when none.

    As in CLEAR-MOT, a truth keeps the track it had in the previous frame while that track is
    still within the threshold, so two truths that pass through one pixel do not count as an
    identity switch of the evaluation itself; the rest are matched by the Hungarian algorithm.
    """
    out = np.full(d.shape[1], -1, np.int64)
    free_r = np.ones(d.shape[0], bool)
    for j in np.flatnonzero(previous >= 0):
        i = np.flatnonzero((track_ids == previous[j]) & free_r)
        if i.size and d[i[0], j] < threshold_px:
            out[j] = previous[j]
            free_r[i[0]] = False
    free_c = out < 0
    sub = d[np.ix_(free_r, free_c)]
    if sub.size:
        r, c = linear_sum_assignment(np.minimum(sub, 1e6))
        good = sub[r, c] < threshold_px
        out[np.flatnonzero(free_c)[c[good]]] = track_ids[np.flatnonzero(free_r)[r[good]]]
    return out


def existing_rows(tracks: pd.DataFrame) -> np.ndarray:
    """Rows at or after each track's first ``confirmed`` row (in time order): where the track exists.

    Examples
    --------
    >>> df = pd.DataFrame({"time_s": [0, 1, 2, 3], "track_id": [1, 1, 1, 1], "confirmed": [0, 1, 0, 1]})
    >>> existing_rows(df).tolist()
    [False, True, True, True]
    """
    order = np.argsort(tracks["time_s"].to_numpy(float), kind="stable")
    conf = pd.Series(tracks["confirmed"].to_numpy(bool)[order].astype(np.int8))
    seen = conf.groupby(tracks["track_id"].to_numpy()[order]).cummax().to_numpy(bool)
    out = np.zeros(len(tracks), bool)
    out[order] = seen
    return out


def _scored_rows(tracks: pd.DataFrame, coasting: bool) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(rows to match, confirmed rows): all rows without a ``confirmed`` column."""
    if "confirmed" not in tracks.columns:
        return tracks, tracks
    confirmed_rows = tracks[tracks["confirmed"].to_numpy(bool)]
    return (tracks[existing_rows(tracks)] if coasting else confirmed_rows), confirmed_rows


def _segment_counts(matched: np.ndarray, labels: np.ndarray) -> tuple[int, int, float, int]:
    """Fragmentation, identity switches, completeness and missed segments from per-frame matches."""
    frag = switches = missed = 0
    counted = labels >= 0
    hit = counted & (matched >= 0)
    completeness = float(hit.sum() / counted.sum()) if counted.any() else float("nan")
    for seg in np.unique(labels[counted]):
        seq = matched[labels == seg]  # time order: boolean masks keep row-major order per target
        seq = seq[seq >= 0]
        if seq.size == 0:
            missed += 1
            continue
        frag += np.unique(seq).size - 1
        switches += int(np.count_nonzero(seq[1:] != seq[:-1]))
    return frag, switches, completeness, missed


def track_metrics(
    tracks: pd.DataFrame,
    truth: Truth,
    pixel_size: tuple[float, float],
    doppler_width_mps: float | None,
    threshold_px: float = 5.0,
    gospa_c_px: float = 10.0,
    gap_s: float = 2.0,
    min_duration_s: float = 2.0,
    confirm: tuple[int, int] = (1, 1),
    counted: np.ndarray | None = None,
    coasting: bool = False,
) -> dict[str, Any]:
    """All track metrics of this module in one dict (see the module docstring).

    The defaults bridge truth gaps shorter than the tracker's coasting time (2 s) and do not count
    truth segments shorter than 2 s (a count by hand would not see them as tracks either).
    ``counted`` (bool, shape of ``truth.visible``, within it) selects the frames that make up the
    counted truth segments, e.g. those with enough expected SNR; tracks are still matched against
    every visible truth, so a track on an aircraft too faint to be counted is not a false track;
    GOSPA is taken against the counted truths only (one too faint is not a missed target).
    With ``coasting`` a track is matched on every row from its first confirmed one on (coasted
    predictions included: the track exists there, as in Stone Soup's SIAP completeness), not only
    on ``confirmed`` rows (``completeness_confirmed``). ``tracks_per_target``: distinct tracks
    matched to each target over the run.

    Parameters
    ----------
    tracks : DataFrame
        ``time_s`` (s), ``track_id``, ``range_m`` (m), ``radial_velocity_mps`` (m/s),
        ``innovation_range_m`` (m), ``innovation_radial_velocity_mps`` (m/s) and ``confirmed``.
    truth : Truth
        Intruder truth on the frame grid.
    pixel_size : (float, float)
        Range bin (m) and Doppler bin (m/s) of one pixel.
    doppler_width_mps : float or None
        Width of the Doppler image, m/s (None: the Doppler difference is not wrapped).
    threshold_px, gospa_c_px : float
        Largest distance of a match and GOSPA cut-off, pixels.
    gap_s, min_duration_s : float
        Truth gaps bridged and shortest truth segment counted, s.
    confirm : (int, int)
        M-of-N visible frames that start a truth segment.
    counted : ndarray of bool, optional
        Frames of the counted truth segments (default ``truth.visible``).
    coasting : bool
        Match a track's rows from its first confirmed one on.

    Returns
    -------
    dict
        Counts (``truth_tracks``, ``tracks``, ``false_tracks``, ``fragmentation``, ``id_switches``,
        ``missed_truth_tracks``), ``completeness`` fractions, ``gospa_mean`` (pixels) and the
        innovation statistics of :func:`innovation_stats`.

    Examples
    --------
    One track following the target over the run and one false track:

    >>> t = np.arange(4.0)
    >>> truth = Truth(t, (1000.0 - 50.0 * t)[:, None], np.full((4, 1), -50.0), np.ones((4, 1), bool))
    >>> tracks = pd.DataFrame({"time_s": np.r_[t, t], "track_id": np.repeat([7, 8], 4),
    ...     "range_m": np.r_[1000.0 - 50.0 * t, 3000.0 + 0 * t], "radial_velocity_mps": -50.0,
    ...     "innovation_range_m": 0.0, "innovation_radial_velocity_mps": 0.0, "confirmed": True})
    >>> m = track_metrics(tracks, truth, (15.0, 0.3), 78.3, min_duration_s=1.0)
    >>> m["truth_tracks"], m["false_tracks"], m["completeness"], round(m["gospa_mean"] ** 2, 9)
    (1, 1, 1.0, 50.0)
    """
    if counted is None:
        counted = truth.visible
    counted = np.asarray(counted, bool) & truth.visible
    counted_truth = Truth(truth.time_s, truth.range_m, truth.radial_velocity_mps, counted)
    labels = truth_segments(counted_truth, gap_s, min_duration_s, confirm)
    all_rows, (tracks, confirmed_rows) = tracks, _scored_rows(tracks, coasting)
    args = (pixel_size, doppler_width_mps, threshold_px, gospa_c_px)
    matched, gospa_d = match_tracks(tracks, truth, *args)
    if not np.array_equal(counted, truth.visible):
        gospa_d = match_tracks(tracks, counted_truth, *args)[1]
    frag, switches, completeness, missed = _segment_counts(matched, labels)
    completeness_confirmed = completeness
    if coasting and len(confirmed_rows) != len(tracks):
        completeness_confirmed = _segment_counts(match_tracks(confirmed_rows, truth, *args)[0], labels)[2]
    ids = np.unique(tracks["track_id"].to_numpy(np.int64))
    true_ids = np.unique(matched[matched >= 0])
    innov_cols = ["innovation_range_m", "innovation_radial_velocity_mps"]
    innov = all_rows[innov_cols].to_numpy(float)
    confirmed_only = innovation_stats(tracks[innov_cols].to_numpy(float), pixel_size)
    return {
        "truth_tracks": int(np.unique(labels[labels >= 0]).size),
        "tracks": int(ids.size),
        "false_tracks": int(np.setdiff1d(ids, true_ids).size),
        "fragmentation": int(frag),
        "id_switches": int(switches),
        "completeness": completeness,
        "missed_truth_tracks": int(missed),
        "completeness_confirmed": completeness_confirmed,
        "tracks_per_target": [int(np.unique(m[m >= 0]).size) for m in matched.T],
        "gospa_mean": float(gospa_d.mean()) if gospa_d.size else float("nan"),
        **innovation_stats(innov, pixel_size),
        "innov_mean_px_confirmed": confirmed_only["innov_mean_px"],
        "innov_p95_px_confirmed": confirmed_only["innov_p95_px"],
    }
