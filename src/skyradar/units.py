"""Bin <-> physical-unit conversions of a range-Doppler image: the one home of the rounding and the wrap.

A value maps to the bin whose centre is nearest, ties rounded up (``floor(x / step + 0.5)``, the
thesis convention, not numpy's round-half-to-even). A centred (FFT-shifted) axis of ``n`` bins has
bin ``j`` at ``(j - n // 2) * step``; a value outside ``[-n // 2, n - n // 2) * step`` wraps around.
:class:`skyradar.config.RadarConfig` exposes these for its range and Doppler axes
(:meth:`~skyradar.config.RadarConfig.range_bin`, :meth:`~skyradar.config.RadarConfig.doppler_bin`, ...).

Examples
--------
>>> nearest_bin([14.0, 22.5, -7.5], 15.0).tolist()
[1, 2, 0]
>>> centred_bin([0.0, 0.5, -62.5, 62.5], 0.5, 250).tolist()  # +62.5 wraps onto -62.5
[125, 126, 0, 0]
>>> float(centred_bin_value(126, 0.5, 250))
0.5
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["nearest_bin", "centred_bin", "centred_bin_value", "wrap", "wrap_angle"]


def nearest_bin(value: ArrayLike, step: float) -> np.ndarray:
    """Index of the bin (centres ``k * step``) nearest to ``value``, ties rounded up.

    Parameters
    ----------
    value : array_like
        Physical value(s), same unit as ``step``.
    step : float
        Bin width (> 0).

    Returns
    -------
    ndarray of int64
        Same shape as ``value`` (0-d for a scalar). Not clipped: out-of-axis values give out-of-axis bins.

    Examples
    --------
    >>> nearest_bin(7.5, 15.0).item(), nearest_bin(-7.6, 15.0).item()
    (1, -1)
    """
    return np.floor(np.asarray(value, float) / step + 0.5).astype(np.int64)


def centred_bin(value: ArrayLike, step: float, n_bins: int) -> np.ndarray:
    """Index on a centred axis of ``n_bins`` (bin ``j`` at ``(j - n_bins // 2) * step``), wrapped into range.

    Examples
    --------
    >>> centred_bin([0.0, 1.0, -2.0, 2.0], 1.0, 4).tolist()
    [2, 3, 0, 0]
    """
    return (nearest_bin(value, step) + n_bins // 2) % n_bins


def centred_bin_value(index: ArrayLike, step: float, n_bins: int) -> np.ndarray:
    """Centre ``(index - n_bins // 2) * step`` of (possibly fractional) bin ``index`` on a centred axis.

    Examples
    --------
    >>> centred_bin_value([0, 2, 3.5], 1.0, 4).tolist()
    [-2.0, 0.0, 1.5]
    """
    return (np.asarray(index, float) - n_bins // 2) * step


def wrap(values: ArrayLike, width: float | np.ndarray) -> np.ndarray:
    """Wrap ``values`` into ``[-width/2, width/2)``: ``mod(v + W/2, W) - W/2``.

    Examples
    --------
    >>> wrap(np.array([39.0, 40.0, -100.0]), 78.0).tolist()
    [-39.0, -38.0, -22.0]
    """
    values, width = np.asarray(values, float), np.asarray(width, float)
    # floor is faster than np.mod and gives the same result for finite inputs.
    out = values - width * np.floor((values + width / 2.0) / width)
    # Rounding can leave a value an ulp outside the interval (e.g. -0.6000000000000014 for W = 1.2):
    # it is moved by one width, and a value rounded onto W/2 is -W/2, so the interval stays half-open.
    out = np.where(out < -width / 2.0, out + width, out)
    return np.where(out >= width / 2.0, out - width, out)


def wrap_angle(angle_rad: ArrayLike) -> np.ndarray:
    """An angle (or a difference of angles) wrapped into ``[-pi, pi)``, rad.

    Examples
    --------
    >>> wrap_angle(np.radians([190.0, -190.0, 45.0])).round(4).tolist()
    [-2.9671, 2.9671, 0.7854]
    """
    return wrap(angle_rad, 2.0 * np.pi)
