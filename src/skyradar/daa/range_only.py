"""Alert levels of a track without a position, from its range and range rate alone.

A one-channel radar measures no direction of arrival: its tracks have a range and a range rate,
no north, east or height. Their recent rows still fit the straight relative path of the encounter
(:func:`skyradar.daa.range_miss.range_only_fit`): its 3-D miss distance ``m`` (standard deviation
``sigma``), its relative speed squared ``|u|^2`` and the time of its closest approach, so that the
range at any time ahead is ``r(t)^2 = m^2 + |u|^2 (t - t_c)^2``. That path has no direction: it
cannot say how much of the miss is horizontal and how much vertical.

The rule, level by level, with the levels, alerting times and hold times of the
:class:`~skyradar.daa.alerting.AlertConfig` the other tracks use:

- A level's cylinder (horizontal radius ``D``, half-height ``Z``) lies within its corner
  ``C = sqrt(D^2 + Z^2)`` of the intruder, so an intruder can lose that well clear only while its
  range is at most ``C``: the sphere of radius ``C`` stands for the cylinder. The path is taken
  with its miss lowered by three standard deviations (:data:`K_SIGMA`, the margin
  :func:`~skyradar.daa.range_miss.cannot_enter` clears a co-altitude track's level with), so
  noise in the fit makes the sphere's entry earlier, not later.
- The level is raised when that path enters the sphere within the level's alerting time, and an
  issued level holds while it enters within its hold time
  (:meth:`~skyradar.daa.alerting.AlertLevel.hold_time_s`): the timing test of the 3-D tracks, on
  the sphere. A path that enters the cylinder enters the sphere first, so on every row the fit
  gives, the raw level of an encounter that can lose well clear is raised at the latest its
  alerting time before the loss; the price is the intruders whose miss is inside the corner but
  outside the cylinder (300 m straight below, with the DO-365 volume's ``Z`` of 137 m), which
  alert too: no range can tell them apart.
- A volume with a modified tau (``tthr_s > 0``) adds DAIDALUS' horizontal tau test on the range:
  entry where ``r^2 + TTHR r rdot <= C^2`` and the miss is within ``C``. A time to co-altitude
  (``tcoa_s``) needs a vertical rate, which no range gives; the sphere holds the whole cylinder
  whatever the vertical rate.
- The FLARM-style time to impact is the entry into the collision volume's corner, the same way.
- Where the fit refuses (fewer rows or a shorter span than its window asks, a row without a range
  rate, the own-ship's velocity changed within the window as in a turn, no rising ``r rdot``),
  the row gives no evidence: it neither raises nor holds a level, and the alert filter leaves it
  out (:func:`range_only_levels` returns it as unknown). Range and range rate at one instant do not
  bound the miss: the range rate is ``-|u| cos(angle)`` and the relative speed is unknown without
  the fit's slope, so a 60 m/s head-on closure looks like a 90 m/s pass 1.5 km abeam at 2 km. Any
  rule on them alone (modified tau on the range, range over closing speed) must treat every
  closing aircraft as a collision course: it warns on each one whose range would close to the
  corner within 25 s at its present range rate, wherever it passes, and a fresh track would open
  with a warning on almost every approach a GA radar sees. The fit needs the first 4 s of a track
  (the default ``min_span_s``), and 10 s after a turn (its window): there the one-channel radar
  does not alert, and a level issued before a turn is lowered once its persistence and
  hysteresis have passed.

Without a bearing no resolution advice can be given: :func:`skyradar.daa.advice.advice_columns`
gives none on a frame where a range-only track alerts.
"""

from __future__ import annotations

import numpy as np

from skyradar.daa.alerting import AlertConfig
from skyradar.daa.conflict import WellClearVolume, flarm_alarm_level, loss_of_well_clear_interval

__all__ = ["K_SIGMA", "corner_m", "equivalent_encounter", "corner_entry_time", "range_only_levels"]

# Standard deviations by which the fitted miss is lowered: cannot_enter's margin.
K_SIGMA = 3.0


def corner_m(volume: WellClearVolume) -> float:
    """The corner of a well-clear cylinder, ``sqrt(dthr^2 + zthr^2)``, m: the farthest any point of
    it lies from the intruder.

    Examples
    --------
    >>> round(corner_m(WellClearVolume.do365_noncoop()), 1)
    684.4
    """
    return float(np.hypot(volume.dthr_m, volume.zthr_m))


def equivalent_encounter(
    miss_m: np.ndarray, speed2_m2ps2: np.ndarray, tcpa_s: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """A co-altitude straight encounter with the same range at every time as the fitted path.

    The relative position ``(m, -|u| tcpa, 0)`` moving at ``(0, |u|, 0)`` (NED, m and m/s) has the
    range ``sqrt(m^2 + |u|^2 (t - tcpa)^2)`` and the range rate of the path; its directions are
    arbitrary and mean nothing. The conflict geometry of :mod:`skyradar.daa.conflict` run on it
    with a horizontal threshold of a volume's corner is the range-only test.

    Parameters
    ----------
    miss_m, speed2_m2ps2, tcpa_s : ndarray, shape (n,)
        3-D miss distance (m), relative speed squared (m^2/s^2) and time to the closest approach
        from now (s; negative: past).

    Returns
    -------
    s, v : ndarray, shape (n, 3)
        Relative position (m) and velocity (m/s).

    Examples
    --------
    >>> s, v = equivalent_encounter(np.array([300.0]), np.array([8100.0]), np.array([10.0]))
    >>> s.tolist(), v.tolist()
    ([[300.0, -900.0, 0.0]], [[0.0, 90.0, 0.0]])
    """
    m = np.asarray(miss_m, float)
    u = np.sqrt(np.asarray(speed2_m2ps2, float))
    zero = np.zeros_like(m)
    return np.stack([m, -u * np.asarray(tcpa_s, float), zero], -1), np.stack([zero, u, zero], -1)


def corner_entry_time(
    miss_m: np.ndarray,
    speed2_m2ps2: np.ndarray,
    tcpa_s: np.ndarray,
    volume: WellClearVolume,
    lookahead_s: float,
) -> np.ndarray:
    """Time from now at which the fitted path comes within the corner of ``volume``, s.

    The range reaches the corner ``C`` (:func:`corner_m`) at ``tcpa - sqrt((C^2 - m^2) / |u|^2)``
    (0 when it is within it now; with a modified tau ``volume.tthr_s``, earlier by DAIDALUS' tau
    test on the range). NaN where the miss is beyond the corner, the whole passage lies before now
    or after ``lookahead_s``, or an input is NaN.

    Examples
    --------
    >>> vol = WellClearVolume(600.0, 800.0)  # corner 1000 m
    >>> corner_entry_time(np.array([600.0, 1200.0]), np.array([1e4, 1e4]), np.array([20.0, 20.0]),
    ...                   vol, 60.0).tolist()
    [12.0, nan]
    """
    s, v = equivalent_encounter(miss_m, speed2_m2ps2, tcpa_s)
    sphere = WellClearVolume(corner_m(volume), volume.zthr_m, volume.tthr_s, 0.0)
    t_in, _ = loss_of_well_clear_interval(s, v, sphere, lookahead_s)
    return t_in


def range_only_levels(
    miss_m: np.ndarray,
    sigma_m: np.ndarray,
    speed2_m2ps2: np.ndarray,
    tcpa_s: np.ndarray,
    config: AlertConfig,
) -> dict[str, np.ndarray]:
    """Raw alert levels of rows without a position, from their range-only path (module docstring).

    Parameters
    ----------
    miss_m, sigma_m : ndarray, shape (n,)
        Fitted 3-D miss distance and its standard deviation, m (NaN: the fit refused).
    speed2_m2ps2 : ndarray, shape (n,)
        Fitted relative speed squared, m^2/s^2.
    tcpa_s : ndarray, shape (n,)
        Time to the 3-D closest approach from the row, s (negative: past).
    config : AlertConfig

    Returns
    -------
    dict of ndarray
        ``level`` (0..3), ``hold_level``, ``t_in_s`` (entry into the corner of the highest level
        raised; NaN if none), ``tcpa_s``, ``time_to_impact_s`` (entry into the collision volume's
        corner), ``flarm_level``, and ``known`` (False where the fit refused: no evidence either way).

    Examples
    --------
    >>> out = range_only_levels(np.array([10.0, 300.0, 1500.0, np.nan]), np.full(4, 5.0),
    ...                         np.full(4, 8100.0), np.full(4, 15.0), AlertConfig())
    >>> out["level"].tolist(), out["known"].tolist()
    ([3, 3, 0, 0], [True, True, True, False])
    """
    miss = np.asarray(miss_m, float)
    low = np.maximum(miss - K_SIGMA * np.asarray(sigma_m, float), 0.0)
    u2, tcpa = np.asarray(speed2_m2ps2, float), np.asarray(tcpa_s, float)
    level = np.zeros(miss.shape, int)
    hold = np.zeros(miss.shape, int)
    t_in_out = np.full(miss.shape, np.nan)
    for k, lv in enumerate(config.levels, start=1):
        t_in = corner_entry_time(low, u2, tcpa, lv.volume, lv.hold_time_s(config.hold_time_factor))
        hit = t_in <= lv.alerting_time_s
        level = np.where(hit, k, level)
        hold = np.where(np.isfinite(t_in), k, hold)
        t_in_out = np.where(hit, t_in, t_in_out)
    lookahead = config.flarm_thresholds_s[0]
    t_imp = corner_entry_time(low, u2, tcpa, config.collision_volume, lookahead)
    return {
        "level": level,
        "hold_level": np.maximum(hold, level),
        "t_in_s": t_in_out,
        "tcpa_s": tcpa,
        "time_to_impact_s": t_imp,
        "flarm_level": flarm_alarm_level(t_imp, config.flarm_thresholds_s),
        "known": np.isfinite(miss) & np.isfinite(u2) & np.isfinite(tcpa),
    }
