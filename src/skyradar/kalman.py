"""The one Kalman predict/update (Joseph form), for a single state or a stack of states.

A single state is ``x`` of shape ``(d,)`` with ``P`` ``(d, d)``; a stack is ``(n, d)`` with ``(n, d, d)``,
so one call moves every track. The innovation ``y`` is computed by the caller, which knows whether its
measurement space is circular (the range-Doppler tracker wraps the Doppler residual,
:func:`skyradar.track.kalman.innovation`). Used by the range-Doppler and 3-D trackers (``track``) and the
flight-state filter (``nav.kalman_state``).
"""

from __future__ import annotations

import numpy as np

__all__ = ["predict", "innovation_covariance", "update"]


def predict(x: np.ndarray, P: np.ndarray, F: np.ndarray, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Kalman prediction ``x <- F x``, ``P <- F P F^T + Q``.

    ``F`` and ``Q`` are ``(d, d)`` or per-state ``(n, d, d)``.

    Examples
    --------
    >>> F = np.array([[1.0, 1.0], [0.0, 1.0]])
    >>> predict(np.array([[0.0, 2.0]]), np.eye(2)[None], F, np.zeros((2, 2)))[0].tolist()
    [[2.0, 2.0]]
    """
    x_new = x @ F.T if F.ndim == 2 else (F @ x[..., None])[..., 0]
    P_new = F @ P @ np.swapaxes(F, -1, -2) + Q
    return x_new, P_new


def innovation_covariance(P: np.ndarray, H: np.ndarray, R: np.ndarray) -> np.ndarray:
    """``S = H P H^T + R`` for one covariance or a stack.

    Parameters
    ----------
    P : ndarray, shape (d, d) or (n, d, d)
        State covariance, in the squared units of the state (m^2, m^2/s^2, ...).
    H : ndarray, shape (k, d)
        Measurement matrix.
    R : ndarray, shape (k, k)
        Measurement noise covariance, in the squared units of the measurement.

    Returns
    -------
    ndarray, shape (k, k) or (n, k, k)
        Innovation covariance.

    Examples
    --------
    Measuring the sum of two independent states with variances 4 and 1 m^2, noise 0.5 m^2:

    >>> innovation_covariance(np.diag([4.0, 1.0]), np.array([[1.0, 1.0]]), np.array([[0.5]])).tolist()
    [[5.5]]
    """
    return H @ P @ H.T + R


def update(
    x: np.ndarray, P: np.ndarray, y: np.ndarray, H: np.ndarray, R: np.ndarray, S: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Kalman update with given innovations ``y``, covariance in Joseph form.

    ``K = P H^T S^-1``, ``x <- x + K y``, ``P <- (I - K H) P (I - K H)^T + K R K^T``. For the optimal
    gain this equals the textbook ``(I - K H) P``, but stays symmetric and positive definite under
    rounding.

    Parameters
    ----------
    x : ndarray, shape (d,) or (n, d)
    P : ndarray, shape (d, d) or (n, d, d)
    y : ndarray, shape (k,) or (n, k)
        Innovations, already wrapped where the measurement space is circular.
    H : ndarray, shape (k, d)
    R : ndarray, shape (k, k) or (n, k, k)
    S : ndarray, optional
        ``H P H^T + R`` when the caller already has it (for gating); computed otherwise.

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
    S = innovation_covariance(P, H, R) if S is None else S
    K = P @ H.T @ _inverse(S)
    x_new = x + (K @ y[..., None])[..., 0]
    I_KH = np.eye(x.shape[-1]) - K @ H
    P_new = I_KH @ P @ np.swapaxes(I_KH, -1, -2) + K @ R @ np.swapaxes(K, -1, -2)
    return x_new, P_new


def _inverse(S: np.ndarray) -> np.ndarray:
    """Inverse of symmetric matrices; closed form for 2x2 (the range-Doppler case)."""
    if S.shape[-1] != 2:
        return np.linalg.inv(S)
    a, b, d = S[..., 0, 0], S[..., 0, 1], S[..., 1, 1]
    det = a * d - b * b
    out = np.empty_like(S)
    out[..., 0, 0] = d / det
    out[..., 1, 1] = a / det
    out[..., 0, 1] = out[..., 1, 0] = -b / det
    return out
