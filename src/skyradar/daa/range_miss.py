"""The smallest 3-D separation an encounter can reach, from range and range rate alone.

For straight relative motion ``p(t) = p_c + u (t - t_c)`` (both aircraft unaccelerated, ``p_c``
the miss vector, perpendicular to ``u``), ``r^2 = m^2 + |u|^2 (t - t_c)^2`` and
``r rdot = |u|^2 (t - t_c)``: the product of range and range rate is linear in time, its slope is
the relative speed squared, and every row then gives the 3-D miss distance
``m^2 = r^2 - (r rdot)^2 / |u|^2``. None of this needs a direction of arrival, so it holds where
the elevation is not measured (the nulls of clutter suppression took it, and the track's height is
the co-altitude prior): over flat ground 300 m below, an aircraft overtaken 347 m below with a
794 m miss is warned while its track is held co-altitude, but the fit over 10 s gives 792-795 m
from 8 s after the track is confirmed.

A cylinder of horizontal radius ``D`` and half-height ``Z`` lies within ``sqrt(D^2 + Z^2)`` of its
axis' centre, so an encounter whose miss distance is beyond that corner cannot lose that well-clear
volume, whatever the split between horizontal and vertical (:func:`cannot_enter`).

Inside the corner no kinematic fit can split the miss for a centrally symmetric array (the 2x2
square, :mod:`skyradar.rx_layouts`) whose elevation the nulls took: what is left per detection is
the range, the range rate and the direction cosine along the antenna's y axis, and all three are
unchanged when the whole relative path is rotated about that axis. A level aircraft passing 250 m
below and one ahead near the own-ship's level descending at 5.1 m/s give the same rows, and the
second loses well clear (the test
``test_range_and_horizontal_direction_cannot_split_below_from_descending_through``). An intruder
that passes well below over flat ground 300 m below, and must not alert, enters the warning
cylinder only with 4.5-5.9 m/s of vertical speed: a bound on the intruder's vertical rate below
that would be an assumption about traffic, not a measurement. The ``kite`` array measures those elevations.

The same path also bounds the miss from above. The horizontal miss of straight relative motion is
at most its 3-D miss (at the 3-D closest approach the horizontal distance is at most the 3-D one),
so a path whose miss, ``k`` sigmas high, is inside a cylinder's radius ``D`` passes inside it
horizontally whatever the track's velocity says, and its horizontal distance is inside ``D`` no
later than its range is (:func:`surely_inside_s`). A track whose horizontal velocity comes from
directions of arrival scattered by clutter nulls can drift to a horizontal miss the range and
range rate rule out: over hills, a fast closure 370 m from a collision course in 3-D had its
velocity's horizontal miss wander to 1000 m for seconds while the range path held the miss to a
few metres.

A track with no direction at all (one channel) is alerted on this miss alone, against the
cylinder's corner (:mod:`skyradar.daa.range_only`, from :func:`range_only_fit`).

The fit is per track over a sliding window; it refuses (NaN) where it has too few rows, where the
own-ship's velocity changed in the window (a turn bends the relative path), or where the rows do
not agree on one miss distance (a manoeuvring intruder, a range-rate alias): the spread of the
per-row miss distances and the fitted slope's error are the fit's uncertainty (:func:`miss_of_window`).
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = [
    "RANGE_FIT_WINDOW_S",
    "range_miss_distance",
    "range_only_fit",
    "miss_of_window",
    "cannot_enter",
    "surely_inside_s",
    "line_fit",
]

RANGE_FIT_WINDOW_S = 10.0  # the trailing window of a row's range fit, s


def range_miss_distance(
    track_id: np.ndarray,
    time_s: np.ndarray,
    range_m: np.ndarray,
    range_rate_mps: np.ndarray,
    own_velocity_mps: np.ndarray,
    window_s: float = RANGE_FIT_WINDOW_S,
    min_span_s: float = 4.0,
    min_rows: int = 20,
    own_accel_tol_mps: float = 1.0,
) -> tuple[np.ndarray, np.ndarray]:
    """3-D miss distance of each row's track and its uncertainty, from the last ``window_s`` of rows.

    Parameters
    ----------
    track_id, time_s : ndarray, shape (n,)
        Track of each row and its time, s (rows of one track in time order).
    range_m, range_rate_mps : ndarray, shape (n,)
        The track's range (m) and range rate (m/s, de-aliased).
    own_velocity_mps : ndarray, shape (n, 3)
        Own-ship velocity at each row, m/s (NED).
    window_s, min_span_s : float
        Fit window, s, and the least time it must span, s (with at least ``min_rows`` rows).
    own_accel_tol_mps : float
        Largest change of the own-ship's velocity within the window, m/s.

    Returns
    -------
    miss_m, sigma_m : ndarray, shape (n,)
        Miss distance, m, and its standard deviation (the rows' spread and the slope's error,
        :func:`miss_of_window`), m; NaN where the fit refuses or the rows' squared misses centre
        on zero or below.

    Examples
    --------
    >>> t = np.arange(0.0, 12.0, 0.1)
    >>> rel = np.column_stack([2000.0 - 60.0 * t, np.full_like(t, 300.0), np.full_like(t, 400.0)])
    >>> r = np.linalg.norm(rel, axis=1)
    >>> rdot = (rel @ np.array([-60.0, 0.0, 0.0])) / r
    >>> miss, sd = range_miss_distance(np.zeros(t.size, int), t, r, rdot, np.tile([50.0, 0, 0], (t.size, 1)))
    >>> round(float(miss[-1]), 3), bool(np.isnan(miss[0]))  # the first rows span too little
    (500.0, True)
    """
    fit = range_only_fit(
        track_id,
        time_s,
        range_m,
        range_rate_mps,
        own_velocity_mps,
        window_s,
        min_span_s,
        min_rows,
        own_accel_tol_mps,
    )
    positive = fit[0] > 0.0  # a miss of zero (a collision course within the noise) is no clearance
    return np.where(positive, fit[0], np.nan), np.where(positive, fit[1], np.nan)


def range_only_fit(
    track_id: np.ndarray,
    time_s: np.ndarray,
    range_m: np.ndarray,
    range_rate_mps: np.ndarray,
    own_velocity_mps: np.ndarray,
    window_s: float = RANGE_FIT_WINDOW_S,
    min_span_s: float = 4.0,
    min_rows: int = 20,
    own_accel_tol_mps: float = 1.0,
    wanted: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The straight relative path each row's window of range and range rate fits: its 3-D miss
    distance and uncertainty (:func:`range_miss_distance`), relative speed squared and time of the
    3-D closest approach.

    The fitted line ``r rdot = |u|^2 (t - t_c)`` gives ``|u|^2`` (its slope) and ``t_c`` (its zero);
    with the miss ``m`` the range follows at any time, ``r(t)^2 = m^2 + |u|^2 (t - t_c)^2``. All
    four are constants of straight relative motion, so a row's values also describe the path after
    it. Parameters as :func:`range_miss_distance`; ``wanted`` (bool per row, default all): the rows
    whose window is fitted, the others only feed those windows and are NaN (a stream fits the rows
    of its latest frame).

    Returns
    -------
    miss_m, sigma_m : ndarray, shape (n,)
        3-D miss distance and its standard deviation, m. Where the rows' squared misses
        ``r^2 - (r rdot)^2 / |u|^2`` centre on zero or below (a collision course, within the
        noise), the miss is 0 and its deviation the square root of their spread, m.
    speed2_m2ps2 : ndarray, shape (n,)
        Relative speed squared ``|u|^2``, m^2/s^2.
    t_cpa_s : ndarray, shape (n,)
        Time of the 3-D closest approach, s (on the clock of ``time_s``). All four are NaN where
        the fit refuses.

    Examples
    --------
    >>> t = np.arange(0.0, 12.0, 0.1)
    >>> rel = np.column_stack([2000.0 - 60.0 * t, np.full_like(t, 300.0), np.full_like(t, 400.0)])
    >>> r = np.linalg.norm(rel, axis=1)
    >>> rdot = (rel @ np.array([-60.0, 0.0, 0.0])) / r
    >>> m, sd, u2, tc = range_only_fit(np.zeros(t.size, int), t, r, rdot, np.tile([50.0, 0, 0], (t.size, 1)))
    >>> round(float(m[-1]), 3), round(float(u2[-1]), 3), round(float(tc[-1]), 3)
    (500.0, 3600.0, 33.333)
    """
    ids = np.asarray(track_id)
    n = ids.size
    out = np.full((4, n), np.nan)
    if n == 0:
        return out[0], out[1], out[2], out[3]
    t = np.asarray(time_s, float)
    r, rdot = np.asarray(range_m, float), np.asarray(range_rate_mps, float)
    own_v = np.asarray(own_velocity_mps, float).reshape(n, 3)
    want = np.ones(n, bool) if wanted is None else np.asarray(wanted, bool).reshape(n)
    order = np.argsort(ids, kind="stable")
    bounds = np.flatnonzero(np.diff(ids[order])) + 1
    for rows in np.split(order, bounds):
        if not want[rows].any():
            continue
        out[:, rows] = _fit_track(
            t[rows],
            r[rows],
            r[rows] * rdot[rows],
            own_v[rows],
            want[rows],
            window_s,
            min_span_s,
            min_rows,
            own_accel_tol_mps,
        )
    return out[0], out[1], out[2], out[3]


@numba.njit(cache=True)
def _fit_track(t, r, y, own_v, want, window_s, min_span_s, min_rows, own_tol):  # pragma: no cover
    # y = r * rdot, a straight line in time of slope |u|^2 and zero at the closest approach
    # (module docstring). Rows: miss, sigma, |u|^2, time of the closest approach; only the
    # ``want`` rows are fitted.
    n = t.size
    out = np.full((4, n), np.nan)
    i0 = 0
    for j in range(n):
        while t[i0] <= t[j] - window_s:
            i0 += 1
        if not want[j]:
            continue
        k = j + 1 - i0
        if k < min_rows or t[j] - t[i0] < min_span_s:
            continue
        tw, yw = t[i0 : j + 1], y[i0 : j + 1]
        if np.abs(own_v[i0 : j + 1] - own_v[j]).max() > own_tol or not np.isfinite(yw).all():
            continue  # the own-ship's velocity changed (a turn), or a row has no range rate
        u2, u2_sigma, t_mean, y_mean, inlier = line_fit(tw, yw)
        if not u2 > 0.0:
            continue
        rw, yw = r[i0 : j + 1][inlier], yw[inlier]
        m, s = miss_of_window(rw, yw, u2, u2_sigma)
        if m != m:  # NaN: the rows' squared misses centre on zero or below, a collision course
            m2 = rw**2 - yw**2 / u2
            spread_m2 = 1.4826 * np.median(np.abs(m2 - np.median(m2)))
            m, s = 0.0, np.sqrt(np.hypot(spread_m2, _slope_error_m2(yw, u2, u2_sigma)))
        out[0, j], out[1, j], out[2, j] = m, s, u2
        out[3, j] = t_mean - y_mean / u2
    return out


@numba.njit(cache=True)
def line_fit(t: np.ndarray, y: np.ndarray, k: float = 3.5) -> tuple:  # pragma: no cover - numba
    """The straight line ``y = y_mean + slope (t - t_mean)`` through a window's rows, robust to rows
    off it: a range rate of the ground's taken into a track's window (a clutter hit) puts its
    ``r rdot`` far off the line, and a least-squares slope follows it.

    The first line is Theil-Sen's (the median of the slopes between the rows of the window's first
    half and those of its second, every ``half // 16``-th of each, and the median intercept),
    which a quarter of the rows off the line does not move far. The rows more than ``k`` spreads
    (1.4826 median absolute deviation of the residuals) off it are set aside, and the kept rows
    are fitted by least squares, whose slope's standard error they give. Returns the slope, its
    standard error, ``t_mean`` and ``y_mean`` of the kept rows and which rows are kept (NaN slope
    where fewer than 3 are).

    Examples
    --------
    >>> t = np.arange(20.0)
    >>> y = 3.0 * t - 5.0
    >>> y[[4, 9, 15]] = 500.0  # three rows off the line
    >>> slope, sd, t_mean, y_mean, kept = line_fit(t, y)
    >>> round(float(slope), 6), round(float(sd), 6), int(kept.sum())
    (3.0, 0.0, 17)
    """
    n = t.size
    half = n // 2
    keep = np.zeros(n, np.bool_)
    if half < 2:
        return np.nan, np.nan, np.nan, np.nan, keep
    stride = max(half // 16, 1)  # at most about 16 x 16 pairs: the median needs no more
    slopes = np.empty(((half + stride - 1) // stride) * ((n - half + stride - 1) // stride))
    m = 0
    for i in range(0, half, stride):
        for j in range(half, n, stride):
            if t[j] > t[i]:
                slopes[m] = (y[j] - y[i]) / (t[j] - t[i])
                m += 1
    if m == 0:
        return np.nan, np.nan, np.nan, np.nan, keep
    slope = np.median(slopes[:m])
    residual = y - slope * t
    residual -= np.median(residual)
    spread = 1.4826 * np.median(np.abs(residual))
    keep = np.abs(residual) <= k * spread + 1e-9 * (np.abs(y).max() + 1.0)
    tk, yk = t[keep], y[keep]
    if tk.size < 3:
        return np.nan, np.nan, np.nan, np.nan, keep
    t_mean, y_mean = tk.mean(), yk.mean()
    tc = tk - t_mean
    slope = (tc * (yk - y_mean)).sum() / (tc * tc).sum()
    fit_residual = yk - y_mean - slope * tc
    sd = np.sqrt((fit_residual * fit_residual).sum() / (tk.size - 2) / (tc * tc).sum())
    return slope, sd, t_mean, y_mean, keep


@numba.njit(cache=True)
def miss_of_window(
    r: np.ndarray, y: np.ndarray, u2: float, u2_sigma: float = 0.0
) -> tuple[float, float]:  # pragma: no cover
    """Miss distance and its sigma, m, from one window's ranges ``r`` (m), ``y = r rdot`` (m^2/s)
    and the relative speed squared ``u2`` (m^2/s^2) fitted to them, with that slope's standard
    error ``u2_sigma`` (m^2/s^2); NaN where the miss squared is not positive.

    The miss is the square root of the median of the rows' ``r^2 - y^2 / u2``. Its sigma has two
    parts: the rows' spread (1.4826 median absolute deviation), and the slope's error, which moves
    every row's ``r^2 - y^2 / u2`` the same way, by ``y^2 / u2^2`` per unit of ``u2``, so no spread
    shows it. A window whose ``r rdot`` carries a few clutter hits (a range rate of the ground at the
    target's range) can fit a slope far off with rows that still agree on a miss: the slope's
    error then says so. The second part is taken on the miss squared and converted with
    ``sqrt(m^2 + e) - m``, which stays finite near a collision course.

    Examples
    --------
    >>> r = np.array([500.0, 1000.0])
    >>> [round(float(x), 3) for x in miss_of_window(r, -60.0 * np.sqrt(r**2 - 400.0**2), 3600.0)]
    [400.0, 0.0]
    >>> [round(float(x), 1) for x in miss_of_window(r, -60.0 * np.sqrt(r**2 - 400.0**2), 3600.0, 36.0)]
    [400.0, 5.8]
    """
    m2 = r**2 - y**2 / u2
    centre = np.median(m2)
    if not centre > 0.0:
        return np.nan, np.nan
    miss = np.sqrt(centre)
    spread = 1.4826 * np.median(np.abs(m2 - centre)) / (2.0 * miss)
    slope = np.sqrt(centre + _slope_error_m2(y, u2, u2_sigma)) - miss
    return miss, np.hypot(spread, slope)


@numba.njit(cache=True)
def _slope_error_m2(y: np.ndarray, u2: float, u2_sigma: float) -> float:  # pragma: no cover - numba
    # How far the slope's error moves the rows' r^2 - y^2 / u2 together: y^2 / u2^2 per unit of u2.
    return np.median(y**2) / u2**2 * u2_sigma


def cannot_enter(
    miss_m: np.ndarray, sigma_m: np.ndarray, dthr_m: float, zthr_m: float, k: float = 3.0
) -> np.ndarray:
    """Whether a miss distance ``k`` sigmas low still passes the cylinder's corner (bool per row).

    Examples
    --------
    >>> cannot_enter(np.array([800.0, 700.0, np.nan]), np.array([10.0, 10.0, 1.0]), 670.56, 137.16).tolist()
    [True, False, False]
    """
    low = np.asarray(miss_m, float) - k * np.asarray(sigma_m, float)
    return np.nan_to_num(low, nan=-np.inf) > np.hypot(dthr_m, zthr_m)


def surely_inside_s(
    miss_m: np.ndarray,
    sigma_m: np.ndarray,
    speed2_m2ps2: np.ndarray,
    tcpa_s: np.ndarray,
    radius_m: float,
    k: float = 3.0,
) -> np.ndarray:
    """Time from now by which a fitted straight path is surely within ``radius_m`` of the own-ship, s.

    The path (:func:`range_only_fit`) is taken with its miss ``k`` sigmas high, so that noise in
    the fit makes the entry later, not earlier: its range is ``r(t)^2 = m^2 + |u|^2 (t - t_c)^2``,
    inside the radius from ``t_c - h`` to ``t_c + h``, ``h = sqrt((R^2 - m^2) / |u|^2)``. Its
    horizontal distance is inside the radius at the latest then (the module docstring).

    Parameters
    ----------
    miss_m, sigma_m : ndarray
        3-D miss distance and its standard deviation, m.
    speed2_m2ps2 : ndarray
        Relative speed squared, m^2/s^2.
    tcpa_s : ndarray
        Time from now to the path's 3-D closest approach, s (negative: past it).
    radius_m : float
        Radius of the sphere (a cylinder's horizontal radius), m.
    k : float
        Standard deviations added to the miss.

    Returns
    -------
    ndarray
        Time of entry from now, s: 0 where the path is inside now, NaN where its miss ``k`` sigmas
        high is not inside the radius, the path has left the sphere, or the fit refused.

    Examples
    --------
    >>> miss, sigma = np.array([300.0, 300.0, 700.0]), np.full(3, 10.0)
    >>> speed2, tcpa = np.full(3, 100.0**2), np.array([20.0, -1.0, 20.0])
    >>> surely_inside_s(miss, sigma, speed2, tcpa, 670.56).round(2).tolist()  # h = 5.84 s
    [14.16, 0.0, nan]
    """
    high = np.asarray(miss_m, float) + k * np.asarray(sigma_m, float)
    with np.errstate(invalid="ignore"):
        half_s = np.sqrt((radius_m**2 - high**2) / np.asarray(speed2_m2ps2, float))
    tcpa = np.asarray(tcpa_s, float)
    entry = np.maximum(tcpa - half_s, 0.0)
    return np.where(tcpa + half_s >= 0.0, entry, np.nan)  # NaN stays NaN through every step
