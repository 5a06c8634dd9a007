"""Conflict geometry against closed forms, brute-force sampling and hand-worked numbers."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import minimize_scalar

from skyradar.daa.conflict import (
    FT,
    WellClearVolume,
    cpa,
    flarm_alarm_level,
    horizontal_violation,
    loss_of_well_clear_interval,
    traffic_indication,
    vertical_violation,
    widened_thresholds,
)

coord = st.floats(-5000, 5000, allow_nan=False)
# Speeds below 1 mm/s put the closest approach weeks away; keep the test in the physical range.
vel = st.floats(-120, 120, allow_nan=False).map(lambda x: 0.0 if abs(x) < 1e-3 else x)
vec_s = st.tuples(coord, coord, st.floats(-600, 600)).map(np.array)
vec_v = st.tuples(vel, vel, st.floats(-15, 15).map(lambda x: 0.0 if abs(x) < 1e-3 else x)).map(np.array)


@given(vec_s, vec_v)
@settings(max_examples=200, deadline=None)
def test_cpa_matches_numerical_minimum(s, v):
    tcpa, hmd, vmd = cpa(s, v)
    dist = lambda t: float(np.hypot(s[0] + t * v[0], s[1] + t * v[1]))  # noqa: E731
    # tcpa <= |s_h| / |v_h|, so the minimum lies in this bracket.
    t_max = 2 * np.hypot(s[0], s[1]) / max(np.hypot(v[0], v[1]), 1e-12) + 1.0
    res = minimize_scalar(dist, bounds=(0.0, t_max), method="bounded", options={"xatol": 1e-9})
    assert hmd == pytest.approx(min(res.fun, dist(0.0)), abs=1e-3)
    t = max(float(tcpa), 0.0)
    assert vmd == pytest.approx(abs(s[2] + t * v[2]), abs=1e-9)
    if np.hypot(v[0], v[1]) > 1e-3:
        # tcpa is the stationary point of the horizontal distance, so the gradient vanishes there.
        sh, vh = s[:2] + tcpa * v[:2], v[:2]
        assert abs(sh @ vh) <= 1e-6 * (1 + np.linalg.norm(sh) * np.linalg.norm(vh))


def test_cpa_known_answer_crossing():
    # Own-ship north at 50 m/s, intruder 2 km east flying west at 50 m/s, 1 km north of own-ship:
    # relative v = (-50, -50), s = (1000, 2000); tcpa = 30 s, miss vector (-500, 500).
    tcpa, hmd, vmd = cpa(np.array([1000.0, 2000.0, -100.0]), np.array([-50.0, -50.0, 2.0]))
    assert float(tcpa) == pytest.approx(30.0)
    assert float(hmd) == pytest.approx(500 * np.sqrt(2))
    assert float(vmd) == pytest.approx(40.0)


def test_do365_noncoop_volume_numbers():
    vol = WellClearVolume.do365_noncoop()
    assert vol.dthr_m == pytest.approx(670.56)
    assert vol.zthr_m == pytest.approx(137.16)
    assert vol.tthr_s == 0.0
    assert WellClearVolume.do365_cooperative().tthr_s == 35.0


def test_tau_volume_entry_time_by_hand():
    # DMOD 1000 m, TTHR 35 s, head-on closure 50 m/s from 3000 m: entry where
    # x^2 - 35*50 x = 1e6 with x the range, x = (1750 + sqrt(1750^2 + 4e6)) / 2.
    vol = WellClearVolume(1000.0, 100.0, 35.0)
    x = (1750 + np.sqrt(1750**2 + 4e6)) / 2
    t_in, t_out = loss_of_well_clear_interval(np.array([3000.0, 0, 0]), np.array([-50.0, 0, 0]), vol, 200.0)
    assert float(t_in) == pytest.approx((3000 - x) / 50)
    assert float(t_out) == pytest.approx(80.0)  # leaves the 1000 m disc behind the own-ship
    # The same encounter against the cylinder enters at the disc.
    t_in_c, _ = loss_of_well_clear_interval(
        np.array([3000.0, 0, 0]), np.array([-50.0, 0, 0]), WellClearVolume(1000.0, 100.0), 200.0
    )
    assert float(t_in_c) == pytest.approx(40.0)


def _sampled_first_violation(s, v, vol, lookahead, dt):
    t = np.arange(0.0, lookahead + dt / 2, dt)
    st_ = s[None, :] + t[:, None] * v[None, :]
    vv = np.broadcast_to(v, st_.shape)
    bad = horizontal_violation(st_, vv, vol.dthr_m, vol.tthr_s) & vertical_violation(
        st_, vv, vol.zthr_m, vol.tcoa_s
    )
    return t[np.argmax(bad)] if bad.any() else np.nan


volumes = st.sampled_from(
    [
        WellClearVolume.do365_noncoop(),
        WellClearVolume.do365_cooperative(),
        WellClearVolume(800.0, 150.0, 20.0, 10.0),
    ]
)


@given(vec_s, vec_v, volumes)
@settings(max_examples=200, deadline=None)
def test_interval_matches_sampled_predicate(s, v, vol):
    lookahead, dt = 60.0, 0.01
    t_in, t_out = loss_of_well_clear_interval(s, v, vol, lookahead)
    t_sample = _sampled_first_violation(s, v, vol, lookahead, dt)
    if np.isfinite(t_sample):
        assert np.isfinite(t_in)
        assert abs(float(t_in) - t_sample) <= dt + 1e-9
    elif np.isfinite(t_in):
        # Only a sliver shorter than the sampling step may be missed by the sampling.
        assert float(t_out) - float(t_in) <= dt
    if np.isfinite(t_in):
        # The predicate holds at the middle of the interval (independent check of both ends).
        mid = 0.5 * (float(t_in) + float(t_out))
        sm = s + mid * v
        assert horizontal_violation(sm, v, vol.dthr_m, vol.tthr_s) or float(t_out) - float(t_in) < 1e-6
        assert vertical_violation(sm, v, vol.zthr_m, vol.tcoa_s) or float(t_out) - float(t_in) < 1e-6


@given(vec_s, vec_v, st.floats(0, 1e5), st.floats(0, 100))
@settings(max_examples=100, deadline=None)
def test_uncertainty_only_widens(s, v, var_p, var_v):
    vol = WellClearVolume.do365_noncoop()
    t0, _ = loss_of_well_clear_interval(s, v, vol, 55.0)
    d, z = widened_thresholds(vol, np.eye(3) * var_p, np.eye(3) * var_v, 20.0)
    assert d >= vol.dthr_m and z >= vol.zthr_m
    t1, _ = loss_of_well_clear_interval(s, v, vol, 55.0, d, z)
    if np.isfinite(t0):
        assert np.isfinite(t1) and t1 <= t0 + 1e-9


def test_widened_thresholds_use_largest_horizontal_eigenvalue():
    cov = np.array([[400.0, 0, 0], [0, 2500.0, 0], [0, 0, 900.0]])  # sigma 20, 50 m, vertical 30 m
    d, z = widened_thresholds(WellClearVolume(600.0, 100.0), cov, None, 0.0, z_h_pos=2.0, z_v_pos=1.0)
    assert float(d) == pytest.approx(700.0)
    assert float(z) == pytest.approx(130.0)
    # Rotating the covariance does not change the widening.
    c, s_ = np.cos(0.7), np.sin(0.7)
    r = np.array([[c, -s_, 0], [s_, c, 0], [0, 0, 1]])
    d2, _ = widened_thresholds(WellClearVolume(600.0, 100.0), r @ cov @ r.T, None, 0.0, z_h_pos=2.0)
    assert float(d2) == pytest.approx(700.0)


def test_flarm_levels_at_thresholds():
    t = np.array([18.0, 18.01, 13.0, 8.0, 0.0, np.nan])
    assert flarm_alarm_level(t).tolist() == [1, 0, 2, 3, 3, 0]


def test_flarm_time_to_impact_head_on():
    # Closure 100 m/s from 2000 m: the 500 ft NMAC disc is entered at (2000 - 152.4) / 100 s.
    t_in, _ = loss_of_well_clear_interval(
        np.array([2000.0, 0, 0]), np.array([-100.0, 0, 0]), WellClearVolume.nmac(), 60.0
    )
    assert float(t_in) == pytest.approx((2000 - 500 * FT) / 100)


@given(st.floats(-np.pi, np.pi), st.floats(-np.pi, np.pi), st.floats(100, 5000), st.floats(-500, 500))
def test_sector_contains_bearing(heading, rel_bearing, dist, up):
    az = heading + rel_bearing
    s = np.array([dist * np.cos(az), dist * np.sin(az), -up])
    ind = traffic_indication(s, heading)
    centre = 30.0 * int(ind["sector"])
    diff = (np.degrees(rel_bearing) - centre + 180.0) % 360.0 - 180.0
    assert abs(diff) <= 15.0 + 1e-6
    assert float(ind["rel_alt_m"]) == pytest.approx(up)
    elev = np.degrees(np.arctan2(up, dist))
    expected_layer = 2 if elev >= 14 else 1 if elev >= 7 else 0 if elev > -7 else -1 if elev > -14 else -2
    assert int(ind["layer"]) == expected_layer
