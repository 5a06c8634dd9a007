"""DAIDALUS' DO-365B non-cooperative alert lifecycle on perfect tracks, against hand-computed times.

The ``do365b`` settings: every level on the 2200 ft / 450 ft cylinder (670.56 m / 137.16 m, no tau),
alerting times 55, 55, 25 s and early alerting times 110, 110, 90 s, 2 of 4 one-second updates,
persistence 4 s, an issued level held while its volume is predicted lost within its early alerting
time, and the M-of-N memory reset after a data gap of more than 5 s (its first sample then counts
twice, DAIDALUS' ``MofN.reset``). Updates at 1 Hz, the rate DAIDALUS' 2 of 4 is meant for.
"""

from __future__ import annotations

import numpy as np

from skyradar.daa.alert_config import alert_config
from skyradar.daa.alerting import (
    DO365B_ALERT_CONFIG,
    RADAR_ALERT_CONFIG,
    filter_alert_levels,
    raw_alert_levels,
)

DTHR_M = 2200 * 0.3048  # 670.56 m


def _levels(t: np.ndarray, s: np.ndarray, v: np.ndarray, config=DO365B_ALERT_CONFIG) -> np.ndarray:
    raw = raw_alert_levels(s, v, config)
    return filter_alert_levels(t, raw["level"], config, raw["hold_level"])


def _onset(t: np.ndarray, levels: np.ndarray, level: int) -> float:
    return float(t[np.argmax(levels >= level)]) if (levels >= level).any() else np.nan


def _flickers(levels: np.ndarray, level: int = 3) -> int:
    """Times the level drops below ``level`` and comes back."""
    on = levels >= level
    starts = np.flatnonzero(on[1:] & ~on[:-1])
    return int(len(starts) - (0 if on[0] else 1)) if on.any() else 0


def test_the_named_settings_are_daidalus_do365b_noncooperative():
    cfg = alert_config("do365b")
    assert cfg is DO365B_ALERT_CONFIG
    assert [(lv.alerting_time_s, lv.early_alerting_time_s) for lv in cfg.levels] == [
        (55.0, 110.0),
        (55.0, 110.0),
        (25.0, 90.0),
    ]
    assert {round(lv.volume.dthr_m, 2) for lv in cfg.levels} == {670.56}
    assert {round(lv.volume.zthr_m, 2) for lv in cfg.levels} == {137.16}
    assert (cfg.m, cfg.n, cfg.persistence_s, cfg.gap_reset_s) == (2, 4, 4.0, 5.0)


def test_head_on_onsets():
    # 8 km apart, closing at 100 m/s, co-altitude: the volume's edge (670.56 m) is reached at
    # t_lowc = (8000 - 670.56) / 100 = 73.29 s. Raw corrective (entry within 55 s) from the first update
    # with 8000 - 100 t <= 670.56 + 5500, t >= 18.29: 19 s; issued on the second (2 of 4): 20 s.
    # Raw warning (within 25 s) from t >= 48.29: 49 s; issued at 50 s. Both held to the loss.
    t = np.arange(0.0, 74.0)
    s = np.column_stack([8000.0 - 100.0 * t, np.zeros_like(t), np.zeros_like(t)])
    v = np.tile([-100.0, 0.0, 0.0], (t.size, 1))
    levels = _levels(t, s, v)
    assert (_onset(t, levels, 2), _onset(t, levels, 3)) == (20.0, 50.0)
    assert (levels[t >= 50.0] == 3).all() and _flickers(levels) == 0


def test_a_decelerating_intruder_keeps_its_warning_within_the_early_alerting_time():
    # As the head-on, until the intruder slows at 55 s (2500 m apart): closing at 30 m/s the entry is
    # (2500 - 670.56) / 30 = 61.0 s away, past the warning's 25 s but within its early 90 s. DO-365B
    # holds the warning from 50 s to the loss of well clear at 55 + 61.0 = 116.0 s.
    t = np.arange(0.0, 116.0)
    fast, slow = t <= 55.0, t > 55.0
    north = np.where(fast, 8000.0 - 100.0 * t, 2500.0 - 30.0 * (t - 55.0))
    s = np.column_stack([north, np.zeros_like(t), np.zeros_like(t)])
    v = np.column_stack([np.where(slow, -30.0, -100.0), np.zeros_like(t), np.zeros_like(t)])
    raw = raw_alert_levels(s, v, DO365B_ALERT_CONFIG)
    assert (raw["level"][(t > 55.0) & (t < 80.0)] < 3).all()  # not raised again: held
    levels = _levels(t, s, v)
    assert _onset(t, levels, 3) == 50.0
    assert (levels[t >= 50.0] == 3).all() and _flickers(levels) == 0


def _entry_s(r: np.ndarray, v: np.ndarray) -> float:
    """First time the straight relative path r + v t is within DTHR_M horizontally (co-altitude)."""
    a, b, c = v @ v, 2.0 * r @ v, r @ r - DTHR_M**2
    return float((-b - np.sqrt(b * b - 4.0 * a * c)) / (2.0 * a))


def test_a_turning_intruder_keeps_its_warning_within_the_early_alerting_time():
    # Head-on at 100 m/s closing, passing 600 m aside (inside the 670.56 m cylinder): the entry is
    # where the north distance is sqrt(670.56^2 - 600^2) = 299.4 m, so the raw warning (entry within
    # 25 s) starts at 8000 - 100 t <= 2799.4, t >= 52.0: 53 s; issued on the second update, 54 s.
    # At 55 s (2500 m ahead) the intruder turns across the own-ship's path, east at 25 m/s: relative
    # velocity (-50, 25) m/s and its entry 38.8 s away, past 25 s but within the early 90 s: DO-365B
    # holds the warning through the turn to the loss of well clear at 55 + 38.8 = 93.8 s.
    t = np.arange(0.0, 94.0)
    tau = np.maximum(t - 55.0, 0.0)
    before = t <= 55.0
    north = np.where(before, 8000.0 - 100.0 * t, 2500.0 - 50.0 * tau)
    east = np.where(before, -600.0, -600.0 + 25.0 * tau)
    s = np.column_stack([north, east, np.zeros_like(t)])
    v = np.column_stack([np.where(t < 55.0, -100.0, -50.0), np.where(t < 55.0, 0.0, 25.0), np.zeros_like(t)])
    assert round(_entry_s(np.array([2500.0, -600.0]), np.array([-50.0, 25.0])), 1) == 38.8
    raw = raw_alert_levels(s, v, DO365B_ALERT_CONFIG)
    assert (raw["level"][(t > 55.0) & (t < 68.0)] < 3).all()  # the turn takes the raw warning away
    levels = _levels(t, s, v)
    assert _onset(t, levels, 3) == 54.0
    assert (levels[t >= 54.0] == 3).all() and _flickers(levels) == 0


def test_an_intruder_that_turns_away_is_lowered_once_its_entry_is_beyond_the_early_alerting_time():
    # The head-on warned at 50 s; at 55 s the intruder stops closing (relative velocity 0.5 m/s):
    # the entry (2500 - 670.56) / 0.5 = 3659 s away is past every early alerting time, so the warning
    # goes after its 4 s persistence (raised at 50 s: kept to 54 s) and the M-of-N of the held level
    # falls: 2 of 4 updates of 56-59 s do not hold it: lowered at 57 s (56 and 57 without).
    t = np.arange(0.0, 70.0)
    north = np.where(t <= 55.0, 8000.0 - 100.0 * t, 2500.0 - 0.5 * (t - 55.0))
    s = np.column_stack([north, np.zeros_like(t), np.zeros_like(t)])
    v = np.column_stack([np.where(t < 55.0, -100.0, -0.5), np.zeros_like(t), np.zeros_like(t)])
    levels = _levels(t, s, v)
    assert _onset(t, levels, 3) == 50.0
    assert levels[t == 56.0][0] == 3 and (levels[t >= 57.0] == 0).all()


def test_a_data_gap_longer_than_5_s_restarts_the_filter_and_its_first_update_counts_twice():
    # Updates at 1 Hz to 30 s, none until 40 s (a 10 s gap), then 1 Hz: at 40 s the memory restarts
    # with the first update counted twice (2 of 4 at once): a warning raw at 40 s is issued at 40 s.
    t = np.concatenate([np.arange(0.0, 31.0), np.arange(40.0, 60.0)])
    s = np.column_stack([8000.0 - 100.0 * t, np.zeros_like(t), np.zeros_like(t)])
    s[t >= 40.0, 0] = DTHR_M + 100.0 * 20.0 - 100.0 * (t[t >= 40.0] - 40.0)  # entry 20 s away at 40 s
    v = np.tile([-100.0, 0.0, 0.0], (t.size, 1))
    levels = _levels(t, s, v)
    assert levels[t == 40.0][0] == 3
    # without the gap the first warning update waits for its second: the same track at 1 Hz throughout
    t2 = np.arange(0.0, 60.0)
    s2 = np.column_stack([DTHR_M + 100.0 * 20.0 - 100.0 * (t2 - 40.0), np.zeros_like(t2), np.zeros_like(t2)])
    levels2 = _levels(t2, s2, np.tile([-100.0, 0.0, 0.0], (t2.size, 1)))
    assert _onset(t2, levels2, 3) == 36.0  # raw from 35 s (entry 25 s away), issued on the second


def test_the_radar_settings_hold_a_decelerating_intruders_warning_too():
    # The radar's settings share DO-365B's early alerting times: the decelerating intruder's warning
    # holds with them as well (its onset differs: 2 of 4 one-second periods from 9.4 Hz-like updates).
    t = np.arange(0.0, 116.0)
    north = np.where(t <= 55.0, 8000.0 - 100.0 * t, 2500.0 - 30.0 * (t - 55.0))
    s = np.column_stack([north, np.zeros_like(t), np.zeros_like(t)])
    v = np.column_stack([np.where(t > 55.0, -30.0, -100.0), np.zeros_like(t), np.zeros_like(t)])
    levels = _levels(t, s, v, RADAR_ALERT_CONFIG)
    first = _onset(t, levels, 3)
    assert first <= 50.0 and (levels[t >= first] == 3).all() and _flickers(levels) == 0
