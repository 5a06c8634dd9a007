"""De-aliasing of the radial velocity from the range history (Maas 2022, ch. 4, change 3).

The Doppler axis only measures the radial velocity modulo ``W = 2 VLim``; the range does not alias.
Once a track has two or more range observations, the slope of range against time gives the
unaliased range rate, and the radial velocity is moved by the whole number of image widths that
brings it closest: ``V_R := V_R + round((dR/dt - V_R) / W) * W``.

With 15 m range bins and about 10 frames/s the slope of two observations is too noisy to choose
the alias reliably (about 60 m/s standard deviation against ``W/2 = 39`` m/s), so the slope here
is a least-squares fit over the last few observations; the rule is applied at every update and
settles as the history grows.
"""

from __future__ import annotations

import numpy as np

__all__ = ["dealias_velocity", "range_rate_fit", "push_history"]


def dealias_velocity(velocity_mps: np.ndarray, range_rate_mps: np.ndarray, width_mps: float) -> np.ndarray:
    """``V_R + round((dR/dt - V_R) / W) * W``, elementwise.

    Examples
    --------
    >>> dealias_velocity(np.array([18.3]), np.array([-55.0]), 78.3).tolist()
    [-60.0]
    """
    v = np.asarray(velocity_mps, float)
    k = np.round((np.asarray(range_rate_mps, float) - v) / width_mps)
    return v + k * width_mps


def range_rate_fit(times_s: np.ndarray, ranges_m: np.ndarray, count: np.ndarray) -> np.ndarray:
    """Least-squares slope of range against time for each row of a history buffer.

    Parameters
    ----------
    times_s, ranges_m : ndarray, shape (n, k)
        Ring buffers; only the ``count[i]`` most recent entries of row ``i`` are valid and the
        unused entries must hold NaN.
    count : ndarray, shape (n,)
        Number of valid entries per row.

    Returns
    -------
    ndarray, shape (n,)
        Range rate, m/s; NaN for rows with fewer than two observations or zero time spread.

    Examples
    --------
    >>> t = np.array([[0.0, 1.0, 2.0, np.nan]])
    >>> r = np.array([[100.0, 90.0, 80.0, np.nan]])
    >>> range_rate_fit(t, r, np.array([3])).tolist()
    [-10.0]
    """
    valid = np.isfinite(times_s) & np.isfinite(ranges_m)
    n = valid.sum(axis=1)
    t = np.where(valid, times_s, 0.0)
    r = np.where(valid, ranges_m, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        tm = t.sum(axis=1) / n
        rm = r.sum(axis=1) / n
        dt = np.where(valid, t - tm[:, None], 0.0)
        num = (dt * np.where(valid, r - rm[:, None], 0.0)).sum(axis=1)
        den = (dt * dt).sum(axis=1)
        slope = num / den
    return np.where((np.asarray(count) >= 2) & (den > 0), slope, np.nan)


def push_history(buffer: np.ndarray, rows: np.ndarray, values: np.ndarray, count: np.ndarray) -> None:
    """Append ``values`` to ring-buffer rows ``rows`` in place (oldest entry overwritten).

    Examples
    --------
    >>> b = np.full((1, 2), np.nan)
    >>> push_history(b, np.array([0]), np.array([5.0]), np.array([0]))
    >>> b.tolist()
    [[5.0, nan]]
    """
    buffer[rows, np.asarray(count) % buffer.shape[1]] = values
