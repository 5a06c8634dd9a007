"""Batched Kalman predict/update over stacks of tracks, with a pluggable innovation.

All functions work on stacks: states ``x`` of shape ``(n, d)`` and covariances ``P`` of shape
``(n, d, d)``, so one call moves every track. The innovation is computed outside the update
(:func:`innovation`) so the tracker can wrap it: the Doppler axis of a range-Doppler image is
circular, and the shortest way round the image is the right residual (seed-brief.md ch4).
"""

from __future__ import annotations

import numpy as np

__all__ = ["wrap", "predict", "innovation", "innovation_covariance", "update"]


def wrap(values: np.ndarray, width: float | np.ndarray) -> np.ndarray:
    """Wrap ``values`` into ``[-width/2, width/2)``: ``mod(v + W/2, W) - W/2``.

    Examples
    --------
    >>> wrap(np.array([39.0, 40.0, -100.0]), 78.0).tolist()
    [-39.0, -38.0, -22.0]
    """
    width = np.asarray(width, float)
    # floor is faster than np.mod and gives the same result for finite inputs.
    return values - width * np.floor((values + width / 2.0) / width)


def predict(x: np.ndarray, P: np.ndarray, F: np.ndarray, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Kalman prediction ``x <- F x``, ``P <- F P F^T + Q`` for a stack of tracks.

    ``F`` and ``Q`` are ``(d, d)`` or per-track ``(n, d, d)``.

    Examples
    --------
    >>> F = np.array([[1.0, 1.0], [0.0, 1.0]])
    >>> predict(np.array([[0.0, 2.0]]), np.eye(2)[None], F, np.zeros((2, 2)))[0].tolist()
    [[2.0, 2.0]]
    """
    x_new = x @ F.T if F.ndim == 2 else (F @ x[..., None])[..., 0]
    P_new = F @ P @ np.swapaxes(F, -1, -2) + Q
    return x_new, P_new


def innovation(
    z: np.ndarray,
    z_pred: np.ndarray,
    doppler_width_mps: float | None = None,
    range_wrap_m: np.ndarray | None = None,
) -> np.ndarray:
    """Innovation ``z - z_pred`` of ``(range_m, radial_velocity_mps)`` observations.

    Parameters
    ----------
    z, z_pred : ndarray, shape (..., 2)
        Observed and predicted (range [m], radial velocity [m/s]).
    doppler_width_mps : float, optional
        Doppler image width ``W``; when given the Doppler residual is wrapped into ``[-W/2, W/2)``.
    range_wrap_m : ndarray, optional
        Per-row wrap width for the range residual (``W * dt`` for single-observation tracks, whose
        radial velocity may be aliased); ``NaN`` or 0 leaves that row unwrapped.

    Examples
    --------
    >>> innovation(np.array([100.0, -38.0]), np.array([90.0, 38.0]), 78.0).tolist()
    [10.0, 2.0]
    """
    y = np.asarray(z, float) - np.asarray(z_pred, float)
    if doppler_width_mps is not None:
        y[..., 1] = wrap(y[..., 1], doppler_width_mps)
    if range_wrap_m is not None:
        rw = np.broadcast_to(np.asarray(range_wrap_m, float), y.shape[:-1])
        use = np.isfinite(rw) & (rw > 0)
        if np.any(use):
            y[..., 0] = np.where(use, wrap(y[..., 0], np.where(use, rw, 1.0)), y[..., 0])
    return y


def innovation_covariance(P: np.ndarray, H: np.ndarray, R: np.ndarray) -> np.ndarray:
    """``S = H P H^T + R`` for a stack of covariances."""
    return H @ P @ H.T + R


def update(
    x: np.ndarray, P: np.ndarray, y: np.ndarray, H: np.ndarray, R: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Kalman update of a stack of tracks with given innovations ``y`` (Joseph form).

    Parameters
    ----------
    x : ndarray, shape (n, d)
    P : ndarray, shape (n, d, d)
    y : ndarray, shape (n, k)
        Innovations, already wrapped where the measurement space is circular.
    H : ndarray, shape (k, d)
    R : ndarray, shape (k, k) or (n, k, k)

    Returns
    -------
    x, P : updated state and covariance.

    Examples
    --------
    >>> H = np.array([[1.0, 0.0]])
    >>> x, P = update(np.zeros((1, 2)), np.eye(2)[None], np.array([[2.0]]), H, np.eye(1))
    >>> x.tolist(), float(P[0, 0, 0])
    ([[1.0, 0.0]], 0.5)
    """
    S = innovation_covariance(P, H, R)
    K = P @ H.T @ _inverse(S)
    x_new = x + (K @ y[..., None])[..., 0]
    I_KH = np.eye(x.shape[-1]) - K @ H
    P_new = I_KH @ P @ np.swapaxes(I_KH, -1, -2) + K @ R @ np.swapaxes(K, -1, -2)
    return x_new, P_new


def _inverse(S: np.ndarray) -> np.ndarray:
    """Inverse of a stack of symmetric matrices; closed form for 2x2 (the range-Doppler case)."""
    if S.shape[-1] != 2:
        return np.linalg.inv(S)
    a, b, d = S[..., 0, 0], S[..., 0, 1], S[..., 1, 1]
    det = a * d - b * b
    out = np.empty_like(S)
    out[..., 0, 0] = d / det
    out[..., 1, 1] = a / det
    out[..., 0, 1] = out[..., 1, 0] = -b / det
    return out
