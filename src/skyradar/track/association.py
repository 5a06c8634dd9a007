"""Gating and global nearest-neighbour assignment of detections to predicted tracks.

Candidate pairs are found without forming the full track x detection matrix: detections are
sorted by range and each track only looks at the detections inside its range window (the range
marginal of its gate), found with ``np.searchsorted``. The surviving pairs are scored (squared
Mahalanobis distance of the possibly wrapped innovation, or its l2 norm in pixels, as in the
thesis) and the Hungarian algorithm (:func:`scipy.optimize.linear_sum_assignment`) picks the
assignment on the small dense matrix of tracks and detections that have any gated pair.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

from skyradar.track.kalman import innovation

__all__ = ["Association", "associate", "pair_costs"]

_FORBIDDEN = 1e12


@dataclass(frozen=True)
class Association:
    """Assigned (track, detection) pairs with their innovations.

    Attributes
    ----------
    track_index, detection_index : ndarray of int, shape (k,)
    innovation : ndarray, shape (k, 2)
        (range [m], radial velocity [m/s]) residual, wrapped as the model asks.
    cost : ndarray, shape (k,)
        Assignment cost of each pair (squared Mahalanobis distance or pixel l2 norm).

    Examples
    --------
    Two tracks and two detections listed in the other order; with range variance 25 m^2 and
    radial-velocity variance 0.04 m^2/s^2 the costs are ``5^2/25 + 0.2^2/0.04`` and ``10^2/25``:

    >>> S = np.tile(np.diag([25.0, 0.04]), (2, 1, 1))
    >>> z_pred, z = np.array([[1000.0, 0.0], [2000.0, 5.0]]), np.array([[2010.0, 5.0], [1005.0, 0.2]])
    >>> a = associate(z_pred, S, z, 16.0)
    >>> a.track_index.tolist(), a.detection_index.tolist(), a.innovation.tolist(), a.cost.tolist()
    ([0, 1], [1, 0], [[5.0, 0.2], [10.0, 0.0]], [2.0, 4.0])
    """

    track_index: np.ndarray
    detection_index: np.ndarray
    innovation: np.ndarray
    cost: np.ndarray


def pair_costs(y: np.ndarray, S: np.ndarray, metric: str, pixel_size: tuple[float, float]) -> np.ndarray:
    """Cost of innovations ``y`` (k, 2) with innovation covariances ``S`` (k, 2, 2).

    ``metric='mahalanobis'`` gives ``y^T S^-1 y``; ``metric='l2'`` gives the l2 norm of ``y`` in
    pixels (``pixel_size = (dR [m], dV [m/s])``).

    Examples
    --------
    >>> pair_costs(np.array([[3.0, 0.4]]), np.eye(2)[None], "l2", (1.5, 0.1)).round(3).tolist()
    [4.472]
    """
    if metric == "l2":
        return np.hypot(y[:, 0] / pixel_size[0], y[:, 1] / pixel_size[1])
    a, b, d = S[:, 0, 0], S[:, 0, 1], S[:, 1, 1]
    det = a * d - b * b
    return (d * y[:, 0] ** 2 - 2.0 * b * y[:, 0] * y[:, 1] + a * y[:, 1] ** 2) / det


def _solve(track_idx: np.ndarray, det_idx: np.ndarray, cost: np.ndarray) -> np.ndarray:
    """Indices into the pair arrays chosen by the Hungarian algorithm."""
    if cost.size == 0:
        return np.zeros(0, int)
    # A pair whose track and detection appear in no other pair is assigned as is; only the
    # contested pairs go to the Hungarian solver.
    per_track = np.bincount(track_idx)
    per_det = np.bincount(det_idx)
    alone = (per_track[track_idx] == 1) & (per_det[det_idx] == 1)
    contested = np.flatnonzero(~alone)
    if contested.size == 0:
        return np.flatnonzero(alone)
    rows, r_inv = np.unique(track_idx[contested], return_inverse=True)
    cols, c_inv = np.unique(det_idx[contested], return_inverse=True)
    matrix = np.full((rows.size, cols.size), _FORBIDDEN)
    pair_of = np.full((rows.size, cols.size), -1)
    matrix[r_inv, c_inv] = cost[contested]
    pair_of[r_inv, c_inv] = contested
    # Forbidden cells are costly but finite, so the solver maximises the number of gated
    # pairs first and then minimises their cost; forbidden picks are dropped afterwards.
    r, c = linear_sum_assignment(matrix)
    keep = matrix[r, c] < _FORBIDDEN
    return np.concatenate([np.flatnonzero(alone), pair_of[r[keep], c[keep]]])


def _pairs_in_range_window(
    r_pred: np.ndarray, r_det: np.ndarray, window: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(track, detection) index pairs with ``|r_det - r_pred| <= window`` of the track, by track.

    Sorting the detections by range makes this O((n + m) log m + pairs) instead of n x m.
    """
    order = np.argsort(r_det, kind="stable")
    r_sorted = r_det[order]
    lo = np.searchsorted(r_sorted, r_pred - window, "left")
    hi = np.searchsorted(r_sorted, r_pred + window, "right")
    counts = hi - lo
    t_idx = np.repeat(np.arange(r_pred.size), counts)
    offsets = np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)
    return t_idx, order[lo[t_idx] + offsets]


def _mahalanobis_costs(y: np.ndarray, S: np.ndarray, t_idx: np.ndarray) -> np.ndarray:
    """``y^T S^-1 y`` per pair for 2x2 ``S`` of track ``t_idx``."""
    # Inverse terms once per track, then gathered per pair (cheaper than S[t_idx]).
    det = S[:, 0, 0] * S[:, 1, 1] - S[:, 0, 1] ** 2
    ia, ib, id_ = S[:, 1, 1] / det, -S[:, 0, 1] / det, S[:, 0, 0] / det
    return ia[t_idx] * y[:, 0] ** 2 + 2.0 * ib[t_idx] * y[:, 0] * y[:, 1] + id_[t_idx] * y[:, 1] ** 2


def associate(
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
    """Gate and assign detections ``z`` to predicted observations ``z_pred``.

    Parameters
    ----------
    z_pred : ndarray, shape (n, 2)
        Predicted (range [m], radial velocity [m/s]) of each track.
    S : ndarray, shape (n, 2, 2)
        Innovation covariances.
    z : ndarray, shape (m, 2)
        Detections (range [m], radial velocity [m/s]).
    gate : float
        Pairs with cost >= gate are never assigned.
    doppler_width_mps : float, optional
        Wrap the Doppler residual into ``[-W/2, W/2)``.
    range_wrap_m : ndarray, shape (n,), optional
        Wrap width of the range residual per track (``W * dt`` for single-observation tracks).
    metric : {'mahalanobis', 'l2'}
    pixel_size : (float, float)
        (dR [m], dV [m/s]) for the l2 metric.
    max_alias : int
        A wrapped range residual stands for a true one up to ``max_alias`` wrap widths away; this
        bounds the range window searched for such tracks.

    Examples
    --------
    >>> zp = np.array([[1000.0, 38.0]])
    >>> a = associate(zp, np.diag([25.0, 0.04])[None], np.array([[1003.0, -39.9]]), 16.0, 78.0)
    >>> a.detection_index.tolist(), a.innovation.round(2).tolist()
    ([0], [[3.0, 0.1]])
    """
    n, m = len(z_pred), len(z)
    if n == 0 or m == 0:
        return Association(np.zeros(0, int), np.zeros(0, int), np.zeros((0, 2)), np.zeros(0))
    window = np.full(n, gate * pixel_size[0]) if metric == "l2" else np.sqrt(gate * S[:, 0, 0])
    if range_wrap_m is not None:
        window = window + max_alias * np.nan_to_num(np.asarray(range_wrap_m, float))
    t_idx, d_idx = _pairs_in_range_window(z_pred[:, 0], z[:, 0], window)
    rw = None if range_wrap_m is None else np.asarray(range_wrap_m, float)[t_idx]
    y = innovation(z[d_idx], z_pred[t_idx], doppler_width_mps, rw)
    cost = pair_costs(y, S[t_idx], metric, pixel_size) if metric == "l2" else _mahalanobis_costs(y, S, t_idx)
    ok = cost < gate
    t_idx, d_idx, y, cost = t_idx[ok], d_idx[ok], y[ok], cost[ok]
    pick = _solve(t_idx, d_idx, cost)
    return Association(t_idx[pick], d_idx[pick], y[pick], cost[pick])
