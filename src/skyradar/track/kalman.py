"""The range-Doppler innovation of the trackers; predict/update are :mod:`skyradar.kalman`'s.

The innovation is computed outside the update (:func:`innovation`) so the tracker can wrap it: the
Doppler axis of a range-Doppler image is circular, and the shortest way round the image is the right
residual (Maas 2022, ch. 4; the wrap is :func:`skyradar.units.wrap`). ``predict``, ``update`` and
``innovation_covariance`` are re-exported from :mod:`skyradar.kalman`, their one home.
"""

from __future__ import annotations

import numpy as np

from skyradar.kalman import innovation_covariance, predict, update
from skyradar.units import wrap

__all__ = ["predict", "innovation", "innovation_covariance", "update"]


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
