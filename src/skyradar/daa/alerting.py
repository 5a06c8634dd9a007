"""Alert levels: DAIDALUS-style thresholds and the stateful persistence/hysteresis filter.

A raw level is the highest level ``k`` whose well-clear volume is predicted to be lost within its
alerting time. The filter turns the per-frame raw levels of one track into a steady indication:
level ``k`` is issued when at least ``M`` of the last ``N`` raw levels reach ``k``; a level, once
issued, is held at least ``persistence_s``, and it is lowered only after the M-of-N level has stayed
below it for ``hysteresis_s``. The threshold has hysteresis too: an issued level counts as still
reached while its volume is predicted lost within ``hold_time_factor`` times its alerting time, so a
prediction that sits near the edge of the alerting time does not make the alert chatter; and, with
``hold_volume_factor`` above 1, while that volume enlarged by the factor is, so a prediction whose
miss sits near the volume's edge does not either. The
defaults follow DAIDALUS' DO-365B configuration (``alerting_m = 2``, ``alerting_n = 4``,
``persistence_time = 4 s``, ``hysteresis_time = 5 s``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from skyradar.daa.conflict import (
    FT,
    WellClearVolume,
    cpa,
    flarm_alarm_level,
    loss_of_well_clear_interval,
    widened_thresholds,
)
from skyradar.daa.range_miss import cannot_enter, surely_inside_s

__all__ = [
    "LEVEL_NAMES",
    "AlertLevel",
    "AlertConfig",
    "RADAR_ALERT_CONFIG",
    "DO365B_ALERT_CONFIG",
    "do365b_noncoop_levels",
    "raw_alert_levels",
    "AlertFilter",
    "filter_alert_levels",
    "velocity_unconverged",
    "required_track_age",
    "alerting_rows",
]

LEVEL_NAMES = ("none", "preventive", "corrective", "warning")


@dataclass(frozen=True)
class AlertLevel:
    """One alert level: its volume, alerting time (s) and early alerting time (s).

    Parameters
    ----------
    name : str
        Name of the level (``'preventive'``, ``'corrective'``, ``'warning'``).
    volume : WellClearVolume
        The well-clear volume whose predicted loss raises the level (thresholds in m and s).
    alerting_time_s : float
        The level is reached when its volume is predicted lost within this time, s.
    early_alerting_time_s : float, optional
        DAIDALUS' ``early_alerting_time``, s (at least the alerting time): once the level is
        issued, it stays reached while its volume is predicted lost within this time. None:
        :attr:`AlertConfig.hold_time_factor` times the alerting time.

    Examples
    --------
    >>> warning = AlertLevel("warning", WellClearVolume(670.56, 137.16), 25.0)
    >>> warning.hold_time_s(1.5)
    37.5
    >>> AlertLevel("warning", WellClearVolume(670.56, 137.16), 25.0, 90.0).hold_time_s(1.5)
    90.0
    """

    name: str
    volume: WellClearVolume
    alerting_time_s: float
    early_alerting_time_s: float | None = None

    def hold_time_s(self, hold_time_factor: float) -> float:
        """The time within which a predicted loss holds this level once issued, s."""
        if self.early_alerting_time_s is not None:
            return max(self.early_alerting_time_s, self.alerting_time_s)
        return hold_time_factor * self.alerting_time_s


def do365b_noncoop_levels() -> tuple[AlertLevel, ...]:
    """DAIDALUS' DO-365B non-cooperative alerter (``DWC_Non_Coop`` of its ``DO_365B_no_SUM``
    configuration): all three levels on the 2200 ft / 450 ft volume without tau, alerting times
    55, 55 and 25 s, early alerting times 110, 110 and 90 s. Its first level shows no guidance.

    Examples
    --------
    >>> [(lv.alerting_time_s, lv.early_alerting_time_s) for lv in do365b_noncoop_levels()]
    [(55.0, 110.0), (55.0, 110.0), (25.0, 90.0)]
    """
    nc = WellClearVolume.do365_noncoop()
    return (
        AlertLevel("preventive", nc, 55.0, 110.0),
        AlertLevel("corrective", nc, 55.0, 110.0),
        AlertLevel("warning", nc, 25.0, 90.0),
    )


def _noncoop_levels() -> tuple[AlertLevel, ...]:
    # DAIDALUS DO-365B "DWC_Non_Coop" alerter (2200 ft / 450 ft, no tau; alerting times 55, 55, 25 s,
    # early alerting times 110, 110, 90 s: an issued level holds while lost within those). Its preventive
    # level differs from the corrective one only by guidance region; we give it the 700 ft vertical
    # threshold of the DO-365 Phase I preventive alert so that it warns earlier for vertical encounters.
    nc = WellClearVolume.do365_noncoop()
    return (
        AlertLevel("preventive", WellClearVolume(nc.dthr_m, 700 * FT), 55.0, 110.0),
        AlertLevel("corrective", nc, 55.0, 110.0),
        AlertLevel("warning", nc, 25.0, 90.0),
    )


@dataclass(frozen=True)
class AlertConfig:
    """Alerting configuration.

    Parameters
    ----------
    levels : tuple of AlertLevel
        Preventive, corrective, warning (index + 1 is the level number).
    m, n : int
        M-of-N persistence on the raw level.
    period_s : float, optional
        Length of one M-of-N sample, s. None: a frame (M of the last N frames). With a period the
        window is the last ``n * period_s`` seconds and level k needs raw levels >= k on at least
        ``m / n`` of the window's frames (and on ``m`` frames). DAIDALUS' DO-365B 2 of 4 is meant
        for 1 Hz surveillance: ``m=2, n=4, period_s=1`` keeps its meaning for a radar at several
        frames per second, where 2 of 4 frames would be half a second of agreement.
    persistence_s : float
        Minimum time an issued level is held, s.
    hysteresis_s : float
        Time the M-of-N level must stay below the issued one before it is lowered, s (0: lowered
        as soon as it falls, once ``persistence_s`` has passed, as DAIDALUS does).
    gap_reset_s : float, optional
        DAIDALUS' ``hysteresis_time``: an update more than this after the previous one (a data gap)
        starts the filter afresh, its M-of-N memory reset with the new raw level counted M times, so
        that level is issued at once (DAIDALUS' ``MofN.reset(value)``); so does the first update.
        None (default): no reset, and a fresh filter needs M updates.
    z_h_pos, z_h_vel, z_v_pos, z_v_vel : float
        Sensor-uncertainty z-scores (see :func:`skyradar.daa.conflict.widened_thresholds`).
    collision_volume : WellClearVolume
        Volume whose entry time is the FLARM "time to impact" (default: NMAC cylinder).
    flarm_thresholds_s : tuple of float
        Times to impact of FLARM alarm levels 1, 2, 3, s.
    min_track_age_s : float
        A track raises no alert before it is this old, s: a fresh track's velocity has not
        converged, and its covariance would widen the volumes to anything. The wait scales with
        the urgency (:func:`required_track_age`): it is at most ``age_fraction_of_time_left``
        of the predicted time to the loss of well clear and at least ``min_track_age_floor_s``.
    age_fraction_of_time_left : float
        The largest share of the time left before the loss of well clear a fresh track waits
        before it may alert. DO-365 judges alerts by the time they leave the pilot; a track
        first confirmed 8 s before the loss cannot spend 2 s of it proving itself, while the
        velocity gate (``max_velocity_sigma_mps``) and the M-of-N filter still ask for a
        converged, repeated prediction.
    min_track_age_floor_s : float
        The shortest wait of a fresh track however urgent, s: a few frames of range rate and
        direction at the prototype's frame rate.
    hold_time_factor : float
        An issued level is held while its (widened) volume is predicted lost within this multiple
        of its alerting time (threshold hysteresis, >= 1): a raw level that hovers at the edge of
        the alerting time, as a track's prediction does when the widened volume's edge crosses
        the alerting time, raises the alert once and does not drop and raise it again.
    hold_volume_factor : float
        An issued level is also held while its (widened) volume, its horizontal and vertical
        thresholds multiplied by this factor (>= 1), is predicted lost within its hold time
        (threshold hysteresis in space). A track's predicted miss scatters from frame to frame by
        its position and velocity errors (a radar's height by 30-35 m at 2-3 km, a quarter of
        the 450 ft threshold); where the true miss lies near the volume's edge the prediction
        crosses it back and forth, and the alert would drop and come back. 1: no spatial hold
        (DAIDALUS').
    lost_track_hold_s : float
        A confirmed track that has no row on a frame is predicted there from its last row for this
        long, s (the tracker's reacquisition memory), and the prediction may hold the level the
        track reached, never raise it (:mod:`skyradar.daa.lost_tracks`); 0 turns it off.
    closing_track_hold_s : float
        A lost track that was closing on the own-ship is predicted up to its time of closest
        approach instead, at most this long, s (:func:`~skyradar.daa.lost_tracks.lost_track_hold`;
        at most ``lost_track_hold_s``: held as the others). A closing aircraft stays a
        threat until it has passed, however long the radar takes to see it again. 25 s is the
        warning's alerting time: beyond it a prediction says nothing the warning needs, and a
        constant-velocity prediction has grown by hundreds of metres.
    max_velocity_sigma_mps : float, optional
        Track-quality gate: a track row whose horizontal velocity standard deviation
        ``sqrt(cov_vv_00 + cov_vv_11)`` exceeds this raises no alert, m/s (default off), while its
        time to CPA is the warning's alerting time or more; closer, the gate is on the miss
        distance that error makes by the CPA (:func:`velocity_unconverged`). A track seen at long
        range with noisy DoA can stay unconverged far longer than ``min_track_age_s``.

    Examples
    --------
    >>> AlertConfig().levels[2].alerting_time_s
    25.0
    """

    levels: tuple[AlertLevel, ...] = field(default_factory=_noncoop_levels)
    m: int = 2
    n: int = 4
    period_s: float | None = None
    persistence_s: float = 4.0
    hysteresis_s: float = 5.0
    gap_reset_s: float | None = None
    z_h_pos: float = 1.5
    z_h_vel: float = 1.0
    z_v_pos: float = 0.75
    z_v_vel: float = 1.5
    collision_volume: WellClearVolume = field(default_factory=WellClearVolume.nmac)
    flarm_thresholds_s: tuple[float, float, float] = (18.0, 13.0, 8.0)
    min_track_age_s: float = 2.0
    age_fraction_of_time_left: float = 0.1
    min_track_age_floor_s: float = 0.5
    hold_time_factor: float = 1.5
    hold_volume_factor: float = 1.0
    lost_track_hold_s: float = 8.0
    closing_track_hold_s: float = 25.0
    max_velocity_sigma_mps: float | None = None

    def __post_init__(self) -> None:
        if not 1 <= self.m <= self.n:
            raise ValueError(f"alert config: need 1 <= m <= n, got m={self.m}, n={self.n}")
        if self.period_s is not None and not self.period_s > 0:
            raise ValueError(f"alert config: period_s must be > 0, got {self.period_s}")
        if not self.hold_time_factor >= 1.0:
            raise ValueError(f"alert config: hold_time_factor must be >= 1, got {self.hold_time_factor}")
        if not self.hold_volume_factor >= 1.0:
            raise ValueError(f"alert config: hold_volume_factor must be >= 1, got {self.hold_volume_factor}")
        if self.gap_reset_s is not None and not self.gap_reset_s > 0:
            raise ValueError(f"alert config: gap_reset_s must be > 0, got {self.gap_reset_s}")
        if not self.lost_track_hold_s >= 0.0:
            raise ValueError(f"alert config: lost_track_hold_s must be >= 0, got {self.lost_track_hold_s}")
        if not self.closing_track_hold_s >= 0.0:
            raise ValueError(
                f"alert config: closing_track_hold_s must be >= 0, got {self.closing_track_hold_s}"
            )
        if not self.min_track_age_floor_s >= 0.0:
            raise ValueError(
                f"alert config: min_track_age_floor_s must be >= 0, got {self.min_track_age_floor_s}"
            )
        if not 0.0 <= self.age_fraction_of_time_left <= 1.0:
            fraction = self.age_fraction_of_time_left
            raise ValueError(f"alert config: age_fraction_of_time_left must be in [0, 1], got {fraction}")

    @property
    def longest_lost_track_hold_s(self) -> float:
        """The longest a lost track's prediction is held, s."""
        return max(self.lost_track_hold_s, self.closing_track_hold_s)

    @property
    def lookahead_s(self) -> float:
        """The longest alerting time, s."""
        return max(lv.alerting_time_s for lv in self.levels)


# For tracks from an onboard radar at several frames per second: DAIDALUS' 2 of 4 at 1 Hz, no alert
# from a track whose horizontal velocity is known worse than 6 m/s (1 sigma; the gate scales with
# the time to CPA, velocity_unconverged), and no widening by the vertical-speed sigma (z_v_vel = 0).
# Sensor-uncertainty mitigation widens a volume by the error of what the sensor measured. DoA
# elevation does not measure a light aircraft's vertical speed at the 2-4 km where a 25 s warning is
# decided (a few m/s are a fraction of a degree over the track's life), so the tracker's vertical-
# speed sigma there is its level-flight prior (3 m/s). Widened by that prior, the warning volume of
# every level intruder reaches ZTHR + 3 m/s x 25 s = 212 m whatever the radar measures: past 1.5
# times ZTHR (206 m), where a near miss must not be warned. The vertical speed the tracker estimates
# still moves the prediction, and the measured height's sigma still widens ZTHR.
# An issued level also holds while its volume enlarged 1.5 times is predicted lost: a radar track's
# predicted miss scatters from frame to frame (its height by 30-35 m at 2-3 km), so where the true miss
# lies near the volume's edge the prediction crosses it back and forth; inside 1.5 times the volume an
# encounter may be warned (a sensor cannot tell it from a conflict), and a warning there is held
# rather than dropped and raised again.
RADAR_ALERT_CONFIG = AlertConfig(
    period_s=1.0, max_velocity_sigma_mps=6.0, z_v_vel=0.0, hold_volume_factor=1.5
)


# DAIDALUS' DO-365B non-cooperative alerting as its DO_365B_no_SUM configuration sets it: the
# DWC_Non_Coop levels with their early alerting times, 2 of 4 updates, persistence 4 s, a level lowered
# as soon as its M-of-N falls after that, the filter reset after a 5 s gap (hysteresis_time), the
# sensor-uncertainty z-scores (h_vel_z_score at its 1.0 maximum), no track-age wait, no velocity gate,
# no lost-track prediction. DAIDALUS takes 2 of 4 at its 1 Hz update: period_s = 1 keeps that meaning
# at a radar's frame rate and is the same at 1 Hz.
DO365B_ALERT_CONFIG = AlertConfig(
    levels=do365b_noncoop_levels(),
    m=2,
    n=4,
    period_s=1.0,
    persistence_s=4.0,
    hysteresis_s=0.0,
    gap_reset_s=5.0,
    z_h_pos=1.5,
    z_h_vel=1.0,
    z_v_pos=0.75,
    z_v_vel=1.5,
    min_track_age_s=0.0,
    min_track_age_floor_s=0.0,
    lost_track_hold_s=0.0,
    closing_track_hold_s=0.0,
)


def velocity_unconverged(sigma_hv_mps: np.ndarray, tcpa_s: np.ndarray, config: AlertConfig) -> np.ndarray:
    """Rows whose horizontal velocity is too uncertain to alert on (``max_velocity_sigma_mps``).

    The error a velocity standard deviation ``sigma`` makes in the predicted miss distance grows
    as ``sigma * tcpa``; the gate bounds that product by ``max_velocity_sigma_mps`` times the
    warning's alerting time, so it is the plain velocity gate for a CPA that far or farther, and
    lets a track closing fast from short range (first seen late over clutter, its cross-range
    velocity still converging) warn: at 8 s to CPA a 10 m/s velocity error moves the miss by
    80 m, an eighth of the 670 m volume. The time to CPA is floored at 8 s (a diverging track's,
    negative, counts as 8 s), so no track warns with a velocity sigma above about three times
    ``max_velocity_sigma_mps``, however close its CPA: such a velocity says nothing about the miss.

    Examples
    --------
    >>> cfg = AlertConfig(max_velocity_sigma_mps=6.0)
    >>> velocity_unconverged(np.array([7.0, 7.0, 18.0, 40.0]), np.array([40.0, 8.0, 8.0, 2.0]), cfg)
    array([ True, False, False,  True])
    """
    if config.max_velocity_sigma_mps is None:
        return np.zeros(np.shape(sigma_hv_mps), bool)
    warning_s = config.levels[-1].alerting_time_s
    t = np.clip(np.nan_to_num(np.asarray(tcpa_s, float), nan=warning_s), 8.0, warning_s)
    return (
        np.nan_to_num(np.asarray(sigma_hv_mps, float), nan=np.inf, posinf=np.inf) * t
        > config.max_velocity_sigma_mps * warning_s
    )


def required_track_age(s: np.ndarray, v: np.ndarray, config: AlertConfig) -> np.ndarray:
    """Age a track needs before this row may alert, s, from the urgency of its prediction.

    The time left is the predicted entry into the warning level's plain volume (not widened by
    the track's covariance: a fresh track's wide covariance would make every track urgent). A
    track predicted to lose well clear in ``t`` seconds waits ``age_fraction_of_time_left * t``,
    bounded by ``min_track_age_floor_s`` (or ``min_track_age_s`` when that is shorter) and
    ``min_track_age_s``; one predicted to stay clear
    over the warning's alerting time waits ``min_track_age_s``.

    Parameters
    ----------
    s, v : ndarray, shape (n, 3)
        Relative position (m) and velocity (m/s), intruder minus own-ship, NED.
    config : AlertConfig

    Returns
    -------
    ndarray, shape (n,)
        Required track age, s.

    Examples
    --------
    >>> s = np.array([[2000.0, 0, 0], [900.0, 0, 0], [9000.0, 0, 0]])
    >>> v = np.array([[-100.0, 0, 0], [-100.0, 0, 0], [-100.0, 0, 0]])
    >>> required_track_age(s, v, AlertConfig()).round(2).tolist()
    [1.33, 0.5, 2.0]
    """
    warning = config.levels[-1]
    t_in, _ = loss_of_well_clear_interval(
        np.atleast_2d(np.asarray(s, float)),
        np.atleast_2d(np.asarray(v, float)),
        warning.volume,
        warning.alerting_time_s,
    )
    longest = config.min_track_age_s
    wait = np.clip(
        config.age_fraction_of_time_left * t_in, min(config.min_track_age_floor_s, longest), longest
    )
    return np.where(np.isfinite(t_in), wait, config.min_track_age_s)


def alerting_rows(times_s: np.ndarray, required_age_s: np.ndarray) -> np.ndarray:
    """Rows of one track (increasing ``times_s``) from the first one old enough to alert onward.

    A track is old enough from its first row whose age (time since its first row) reaches that
    row's :func:`required_track_age`, and stays so: age only grows.

    Examples
    --------
    >>> alerting_rows(np.arange(5) * 0.5, np.array([2.0, 2.0, 0.9, 2.0, 2.0])).tolist()
    [False, False, True, True, True]
    """
    t = np.asarray(times_s, float)
    ready = t - t[0] >= np.asarray(required_age_s, float) - 1e-9 if t.size else np.zeros(0, bool)
    return np.cumsum(ready) > 0


def _volume_levels(s, v, tcpa, hmd, config: AlertConfig, cov_pos_m2, cov_vel_m2ps2, miss=None):
    """Highest level whose (widened) volume is lost within its alerting time, its entry time,
    the widened thresholds ``{level: (dthr_m, zthr_m)}`` of every level, and the highest level
    lost within its hold time (:meth:`AlertLevel.hold_time_s`), or whose volume enlarged by
    ``hold_volume_factor`` is. ``miss`` (miss distance and sigma,
    m) clears the levels whose plain cylinder it passes outside; with the path's relative speed
    squared and time to its closest approach it also raises those its path surely enters while the
    track's height is inside, and holds them while the vertical miss the path leaves beside the
    track's horizontal miss ``hmd`` (m) is inside (:func:`raw_alert_levels`)."""
    level = np.zeros(len(s), int)
    hold = np.zeros(len(s), int)
    t_in_out = np.full(len(s), np.nan)
    widened = {}
    z = (config.z_h_pos, config.z_h_vel, config.z_v_pos, config.z_v_vel)
    if miss is not None and len(miss) == 4:
        with np.errstate(invalid="ignore"):  # the vertical miss the path leaves beside hmd
            left_vertical_m = np.sqrt(np.maximum(miss[0] ** 2 - hmd**2, 0.0))
    for k, lv in enumerate(config.levels, start=1):
        t_ref = np.clip(tcpa, 0.0, lv.alerting_time_s)
        dthr, zthr = widened_thresholds(lv.volume, cov_pos_m2, cov_vel_m2ps2, t_ref, *z)
        widened[k] = (dthr, zthr)
        held_s = lv.hold_time_s(config.hold_time_factor)
        t_in, _ = loss_of_well_clear_interval(s, v, lv.volume, held_s, dthr, zthr)
        t_hold = t_in
        if config.hold_volume_factor > 1.0:
            f = config.hold_volume_factor
            t_hold, _ = loss_of_well_clear_interval(s, v, lv.volume, held_s, f * dthr, f * zthr)
        possible = np.ones(len(s), bool)
        path_holds = np.zeros(len(s), bool)
        if miss is not None and lv.volume.tthr_s == 0.0 and lv.volume.tcoa_s == 0.0:
            possible = ~cannot_enter(miss[0], miss[1], lv.volume.dthr_m, lv.volume.zthr_m)
            if len(miss) == 4:
                sure_s = surely_inside_s(miss[0], miss[1], miss[2], miss[3], lv.volume.dthr_m)
                sure_s = np.where(sure_s <= held_s, sure_s, np.nan)
                with np.errstate(invalid="ignore"):
                    height_in = np.abs(s[:, 2] + v[:, 2] * sure_s) < zthr  # False where NaN
                t_in = np.fmin(t_in, np.where(height_in, sure_s, np.nan))
                path_holds = np.isfinite(sure_s) & (left_vertical_m < zthr)
        hit = possible & (t_in <= lv.alerting_time_s)
        level = np.where(hit, k, level)
        hold = np.where(possible & (np.isfinite(t_in) | np.isfinite(t_hold) | path_holds), k, hold)
        t_in_out = np.where(hit, t_in, t_in_out)
    return level, t_in_out, widened, hold


def raw_alert_levels(
    s: np.ndarray,
    v: np.ndarray,
    config: AlertConfig | None = None,
    cov_pos_m2: np.ndarray | None = None,
    cov_vel_m2ps2: np.ndarray | None = None,
    miss: tuple[np.ndarray, ...] | None = None,
) -> dict[str, np.ndarray]:
    """Per-encounter raw alert level and conflict geometry (no persistence).

    Parameters
    ----------
    s, v : ndarray, shape (n, 3)
        Relative position (m) and velocity (m/s), intruder minus own-ship, NED.
    config : AlertConfig, optional
    cov_pos_m2, cov_vel_m2ps2 : ndarray, shape (n, 3, 3), optional
        Relative position / velocity covariance; widens the volumes.
    miss : tuple of ndarray, optional
        3-D miss distance and its sigma per row, m (:func:`skyradar.daa.range_miss.range_miss_distance`,
        NaN: unknown): a level whose volume (a cylinder without tau) the miss passes outside by 3
        sigmas is not raised, whatever ``s`` and ``v`` predict. With two more arrays, the path's
        relative speed squared (m^2/s^2) and time to its 3-D closest approach from the row (s),
        as :func:`skyradar.daa.range_miss.range_only_fit` gives them: a level is also lost where
        the path, its miss 3 sigmas high, is inside the cylinder's radius within the lookahead
        (:func:`skyradar.daa.range_miss.surely_inside_s`, a bound on the horizontal distance
        whatever ``v`` predicts) and the height ``s`` and ``v`` predict then is inside the
        cylinder's (widened) half-height. An issued level is also held while the path surely
        enters within the hold time and the vertical miss it leaves beside the predicted
        horizontal one, ``sqrt(miss^2 - hmd^2)``, is inside the half-height: range and range rate
        are measured to a pixel where the ground's band pulls a track's elevations towards the
        ground, so a height that makes the predicted 3-D miss larger than the measured one is
        the estimate to doubt. It holds and never raises: where the predicted horizontal miss
        is itself off, the vertical it leaves is too.

    Returns
    -------
    dict of ndarray
        ``level`` (0..3), ``hold_level`` (the highest level an issued alert is held at: its
        volume lost within its early alerting time, :meth:`AlertLevel.hold_time_s`), ``t_in_s``
        (entry time into the highest-level volume lost, or the corrective one; NaN if none),
        ``tcpa_s``, ``hmd_m``, ``vmd_m``, ``time_to_impact_s``, ``flarm_level``, ``dthr_m``,
        ``zthr_m`` (widened corrective thresholds).

    Examples
    --------
    >>> out = raw_alert_levels(np.array([[3000.0, 0, 0]]), np.array([[-100.0, 0, 0]]))
    >>> int(out["level"][0])
    3
    """
    config = config or AlertConfig()
    s = np.atleast_2d(np.asarray(s, float))
    v = np.atleast_2d(np.asarray(v, float))
    tcpa, hmd, vmd = cpa(s, v)
    level, t_in_out, widened, hold = _volume_levels(s, v, tcpa, hmd, config, cov_pos_m2, cov_vel_m2ps2, miss)
    t_imp, _ = loss_of_well_clear_interval(s, v, config.collision_volume, config.flarm_thresholds_s[0])
    corrective = widened[min(2, len(config.levels))]
    return {
        "level": level,
        "hold_level": np.maximum(hold, level),
        "t_in_s": t_in_out,
        "tcpa_s": tcpa,
        "hmd_m": hmd,
        "vmd_m": vmd,
        "time_to_impact_s": t_imp,
        "flarm_level": flarm_alarm_level(t_imp, config.flarm_thresholds_s),
        "dthr_m": np.broadcast_to(corrective[0], level.shape).copy(),
        "zthr_m": np.broadcast_to(corrective[1], level.shape).copy(),
    }


class AlertFilter:
    """M-of-N persistence and hysteresis for the alert level of one track.

    Parameters
    ----------
    config : AlertConfig, optional

    Examples
    --------
    >>> f = AlertFilter(AlertConfig(m=2, n=3, persistence_s=0.0, hysteresis_s=2.0))
    >>> [f.update(t, raw) for t, raw in enumerate([3, 0, 3, 0, 0, 0, 0, 0])]
    [0, 0, 3, 3, 3, 0, 0, 0]
    """

    def __init__(self, config: AlertConfig | None = None) -> None:
        self.config = config or AlertConfig()
        self._raw: list[int] = []
        self._hold: list[int] = []
        self._times: list[float] = []
        self.level = 0
        self._raised_at = -np.inf
        self._below_since: float | None = None
        self._seeded, self._seed = 0, (0, 0)  # a gap reset's copies of its first sample still counted

    def update(self, time_s: float, raw_level: int, hold_level: int | None = None) -> int:
        """Feed the raw level of the frame at ``time_s`` (s); return the issued level.

        ``hold_level`` (default ``raw_level``) is the highest level the frame would hold an issued
        alert at (:attr:`AlertConfig.hold_time_factor`): the issued level is not lowered while
        the M-of-N of these reaches it. A negative ``raw_level`` says the frame has no evidence
        to raise a level (a lost track's prediction): it is left out of the raising M-of-N, whose
        share is taken over the frames with evidence, and counts only towards holding.
        """
        cfg = self.config
        hold = max(int(raw_level), 0) if hold_level is None else max(int(hold_level), int(raw_level))
        self._seeded = max(self._seeded - 1, 0)
        if cfg.gap_reset_s is not None and (not self._times or time_s - self._times[-1] > cfg.gap_reset_s):
            # DAIDALUS' reset (MofN.reset(value)): a fresh memory holding M copies of this sample,
            # one of which each later update pushes out, and no alert.
            self._raw, self._hold, self._times = [], [], []
            self.level, self._raised_at, self._below_since = 0, -np.inf, None
            self._seeded, self._seed = cfg.m - 1, (int(raw_level), hold)
        candidate, held = self._m_of_n_level(time_s, int(raw_level), hold)
        if candidate > self.level:
            self.level, self._raised_at, self._below_since = candidate, time_s, None
        elif candidate == self.level or held >= self.level:
            self._below_since = None
        else:
            if self._below_since is None:
                self._below_since = time_s
            held = time_s - self._raised_at < cfg.persistence_s
            if not held and time_s - self._below_since >= cfg.hysteresis_s:
                self.level, self._below_since = candidate, None
        return self.level

    def _m_of_n_level(self, time_s: float, raw_level: int, hold_level: int) -> tuple[int, int]:
        """Highest level reached by M of the last N samples (frames, or periods of ``period_s``),
        of the raw levels and of the hold levels; a reset's remaining copies of its first sample
        (``gap_reset_s``) count with them."""
        cfg = self.config
        self._raw.append(raw_level)
        self._hold.append(hold_level)
        self._times.append(float(time_s))
        if cfg.period_s is None:
            start = max(len(self._raw) - cfg.n, 0)
        else:
            # Frames strictly inside the window (a tolerance keeps exactly n periods of frames).
            start = next(i for i, t in enumerate(self._times) if t > time_s - cfg.n * cfg.period_s + 1e-9)
        self._raw, self._hold, self._times = self._raw[start:], self._hold[start:], self._times[start:]

        def reached(levels: list[int]) -> int:
            known = [r for r in levels if r >= 0]
            need = float(cfg.m) if cfg.period_s is None else max(float(cfg.m), cfg.m / cfg.n * len(known))
            counts = [sum(r >= k for r in known) for k in range(1, len(cfg.levels) + 1)]
            return max([k for k, c in enumerate(counts, start=1) if c >= need], default=0)

        seeded_raw, seeded_hold = ([self._seed[0]], [self._seed[1]]) if self._seeded else ([], [])
        return reached(seeded_raw * self._seeded + self._raw), reached(
            seeded_hold * self._seeded + self._hold
        )


def filter_alert_levels(
    times_s: np.ndarray,
    raw_levels: np.ndarray,
    config: AlertConfig | None = None,
    hold_levels: np.ndarray | None = None,
) -> np.ndarray:
    """Issued levels of one track from its raw levels at increasing ``times_s`` (see :class:`AlertFilter`).

    ``hold_levels`` (default the raw levels) are the levels each frame holds an issued alert at.

    Examples
    --------
    >>> filter_alert_levels(np.arange(4.0), np.array([1, 1, 1, 1])).tolist()
    [0, 1, 1, 1]
    """
    filt = AlertFilter(config)
    hold = raw_levels if hold_levels is None else hold_levels
    return np.array(
        [filt.update(float(t), int(r), int(h)) for t, r, h in zip(times_s, raw_levels, hold, strict=True)],
        int,
    )
