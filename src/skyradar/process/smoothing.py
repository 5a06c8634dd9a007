"""Hann-window low-pass smoothing of 3-D positions along a track (the thesis' comparison).

Phase noise makes single-frame DoA positions jitter; a short Hann window along the track
averages it out at the cost of lag in turns. Missing frames (NaN) get zero weight and the
window is renormalised by the weights it actually covers, so track ends and gaps are not
pulled towards zero (a zeroth-order fit: on a curving or accelerating track the ends lag).

Examples
--------
>>> x = np.array([1.0, 3.0, 1.0, np.nan, 1.0, 3.0, 1.0])
>>> np.round(hann_smooth(x, 3), 3).tolist()  # the gap is filled from its neighbours
[1.667, 2.0, 1.667, 1.0, 1.667, 2.0, 1.667]
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage
from scipy.signal.windows import hann

from skyradar.errors import InputError

__all__ = ["hann_window", "hann_smooth"]


def hann_window(length: int) -> np.ndarray:
    """Hann window of ``length`` non-zero taps summing to one.

    Parameters
    ----------
    length : int
        Taps, at least 1 (frames when used along a track).

    Returns
    -------
    ndarray (length,)
        The Hann window of ``length + 2`` points without its zero end taps, normalised.

    Examples
    --------
    >>> hann_window(3).tolist(), hann_window(1).tolist()
    ([0.25, 0.5, 0.25], [1.0])
    """
    if int(length) != length or length < 1:
        raise InputError(f"smoothing: field 'window' must be a positive integer, got {length!r}")
    w = hann(int(length) + 2)[1:-1]  # drop the zero end taps
    return w / w.sum()


def hann_smooth(values: np.ndarray, window: int, axis: int = 0) -> np.ndarray:
    """Smooth ``values`` along ``axis`` with a normalised Hann window, ignoring NaNs.

    Parameters
    ----------
    values : ndarray
        E.g. positions (n_frames, 3) in metres, one row per frame (NaN where no detection).
    window : int
        Window length in frames (odd lengths keep the filter centred).
    axis : int
        Time axis.

    Returns
    -------
    ndarray
        Same shape; NaN only where the window covers no valid sample.

    Examples
    --------
    A ramp keeps its inner samples (the window is symmetric); its ends lag towards the inside,
    the renormalised window seeing only one side of them:

    >>> hann_smooth(np.arange(7.0), 5).round(3).tolist()
    [0.625, 1.182, 2.0, 3.0, 4.0, 4.818, 5.375]
    """
    x = np.asarray(values, float)
    w = hann_window(window)
    valid = np.isfinite(x)
    num = ndimage.convolve1d(np.where(valid, x, 0.0), w, axis=axis, mode="constant")
    den = ndimage.convolve1d(valid.astype(float), w, axis=axis, mode="constant")
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 1e-12, num / den, np.nan)
