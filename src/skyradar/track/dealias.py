"""De-aliasing of the radial velocity from the range history (Maas 2022, ch. 4, change 3).

The Doppler axis only measures the radial velocity modulo ``W = 2 VLim``; the range does not alias.
Once a track has two or more range observations, the slope of range against time gives the
unaliased range rate, and the radial velocity is moved by the whole number of image widths that
brings it closest: ``V_R := V_R + round((dR/dt - V_R) / W) * W``.

With 15 m range bins and about 10 frames/s the slope of two observations is too noisy to choose
the alias reliably (about 60 m/s standard deviation against ``W/2 = 39`` m/s), so the slope here
is a least-squares fit over the last few observations; the rule is applied at every update and
settles as the history grows.

How many aliases a track may be off by follows from the fastest radial speed a light aircraft's
radar sees, not from one radar's image: two light aircraft head-on at 190 kt each close at
195 m/s (:data:`MAX_RADIAL_SPEED_MPS`). :func:`alias_count` turns that into the alias bound of
an image of any width, so a time-division MIMO radar, whose image is narrower by its number of
transmitters, keeps the same span of radial speeds.
"""

from __future__ import annotations

import numpy as np

__all__ = ["MAX_RADIAL_SPEED_MPS", "alias_count", "dealias_velocity", "range_rate_fit", "push_history"]

MAX_RADIAL_SPEED_MPS = 195.0  # two light aircraft head-on at 190 kt each, m/s


def alias_count(width_mps: float, max_radial_speed_mps: float = MAX_RADIAL_SPEED_MPS) -> int:
    """Largest alias ``|k|`` of a radial velocity up to ``max_radial_speed_mps`` in an image ``W`` wide.

    A measured velocity lies within ``W/2`` of zero, so the true one, ``v + k W``, can reach the
    speed only for ``|k| W - W/2 <= max_radial_speed_mps``: ``|k| <= floor(v_max / W + 1/2)``.

    Parameters
    ----------
    width_mps : float
        Doppler image width ``2 VLim``, m/s.
    max_radial_speed_mps : float
        Fastest radial speed to cover, m/s.

    Returns
    -------
    int

    Examples
    --------
    The prototype's 78.3 m/s image needs two aliases either side for +-195 m/s; a 2 TX x 4 RX
    time-division MIMO radar at the same PRF (39.15 m/s image) needs five:

    >>> alias_count(78.3), alias_count(39.15)
    (2, 5)
    """
    if not (np.isfinite(width_mps) and width_mps > 0.0):
        raise ValueError(f"width_mps must be a positive number of m/s, got {width_mps!r}")
    return int(np.floor(max_radial_speed_mps / width_mps + 0.5))


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
