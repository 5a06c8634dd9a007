"""Flight state from ground returns (ch5): closed-form inversion, robust fits, Kalman filter."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyradar.nav.inversion import (
    abc_from_state,
    fit_ransac,
    fit_robust,
    fit_thesis,
    ridge_velocity,
    state_from_abc,
)
from skyradar.nav.kalman_state import KalmanSettings, filter_states

speeds = st.floats(15.0, 90.0)
vertical = st.floats(-10.0, 10.0)  # climbing (negative, V_Z is positive down) and descending
heights = st.floats(100.0, 2000.0)


@given(speeds, vertical, heights)
@settings(max_examples=200, deadline=None)
def test_abc_round_trip(vx, vz, h):
    got = state_from_abc(*abc_from_state(vx, vz, h))
    np.testing.assert_allclose(got, (vx, vz, h), rtol=1e-9, atol=1e-9)


def _pairs(vx, vz, h, n=80, r_max=5000.0):
    r = np.linspace(1.02 * h, r_max, n)
    return r, ridge_velocity(r, vx, vz, h)


def test_ridge_velocity_is_the_fastest_closing_ground_point():
    # Brute force over the ground circle at one range: the minimum radial velocity is the formula.
    vx, vz, h, r = 47.0, -3.0, 650.0, 1400.0
    phi = np.linspace(-np.pi, np.pi, 200_001)
    rho = np.sqrt(r * r - h * h)
    u = np.stack([rho * np.cos(phi), rho * np.sin(phi), np.full_like(phi, h)]) / r
    v_r = -(np.array([vx, 0.0, vz]) @ u)  # ground moves at -V; positive receding
    assert v_r.min() == pytest.approx(float(ridge_velocity(np.array([r]), vx, vz, h)[0]), abs=1e-9)
    assert phi[v_r.argmin()] == pytest.approx(0.0, abs=1e-4)  # straight ahead on the track
    assert v_r.min() < 0


@given(speeds, vertical, heights)
@settings(max_examples=100, deadline=None)
def test_thesis_fit_exact_on_noiseless_pairs(vx, vz, h):
    fit = fit_thesis(*_pairs(vx, vz, h))
    assert fit.ok
    np.testing.assert_allclose([fit.vx_mps, fit.vz_mps, fit.h_m], [vx, vz, h], rtol=1e-6, atol=1e-5)


@given(speeds, vertical, heights)
@settings(max_examples=40, deadline=None)
def test_robust_fit_exact_on_noiseless_pairs(vx, vz, h):
    fit = fit_robust(*_pairs(vx, vz, h))
    assert fit.ok
    np.testing.assert_allclose([fit.vx_mps, fit.vz_mps, fit.h_m], [vx, vz, h], rtol=1e-5, atol=1e-3)


def test_robust_fits_survive_outliers_where_least_squares_does_not():
    rng = np.random.default_rng(3)
    r, v = _pairs(52.0, 1.5, 600.0, n=250)
    v = v + rng.uniform(-0.16, 0.16, r.size)  # Doppler bin quantisation
    bad = rng.random(r.size) < 0.15
    v[bad] += rng.uniform(-20.0, 20.0, bad.sum())  # intruders, faded ridge bins, spurs
    thesis = fit_thesis(r, v)
    # RANSAC (consensus + algebraic refit) is the starting point; Huber refinement is the estimate.
    for fit, tol in ((fit_ransac(r, v), (15.0, 1.0)), (fit_robust(r, v), (4.0, 0.2))):
        assert abs(fit.h_m - 600.0) < tol[0]
        assert abs(fit.vx_mps - 52.0) < tol[1] and abs(fit.vz_mps - 1.5) < tol[1]
        assert fit.inliers[bad].mean() < 0.1 and fit.inliers[~bad].mean() > 0.9
    assert not thesis.ok or abs(thesis.h_m - 600.0) > 20.0


def test_robust_fit_sd_matches_scatter():
    rng = np.random.default_rng(0)
    r, v0 = _pairs(50.0, 0.0, 500.0, n=300)
    h = []
    sds = []
    for _ in range(60):
        fit = fit_robust(r, v0 + rng.uniform(-0.156, 0.156, r.size))
        h.append(fit.h_m)
        sds.append(fit.h_sd_m)
    assert abs(np.mean(h) - 500.0) < 1.0
    # Reported SD within a factor of 2.5 of the observed scatter.
    assert 0.4 < np.std(h) / np.mean(sds) < 2.5


def test_fits_fail_cleanly_on_too_few_or_degenerate_pairs():
    for fit in (
        fit_thesis(np.array([600.0, 700.0]), np.array([-10.0, -20.0])),
        fit_robust(np.zeros(0), np.zeros(0)),
    ):
        assert not fit.ok and np.isnan(fit.h_m)
    assert np.isnan(state_from_abc(-1.0, 0.0, 1.0)[0])


def _truth(n=120, dt=1.0):
    t = np.arange(n) * dt
    vx = 50.0 + 2.0 * np.sin(t / 20.0)
    vz = np.where(t < n * dt / 2, 3.0, -2.0)  # descend, then climb
    h = 800.0 - np.concatenate([[0.0], np.cumsum(vz[:-1] * dt)])
    return t, np.column_stack([vx, vz, h])


def test_kalman_reduces_noise_and_tracks_climb_and_descent():
    rng = np.random.default_rng(1)
    t, truth = _truth()
    sd = np.array([1.0, 1.0, 8.0])
    z = truth + rng.normal(size=truth.shape) * sd
    out = filter_states(t, z, np.tile(sd, (t.size, 1)))
    err_raw = (z - truth)[20:].std(axis=0)
    err_f = (out.state - truth)[20:].std(axis=0)
    assert np.all(err_f < err_raw)
    assert abs((out.state - truth)[20:, 2].mean()) < 3.0


def test_kalman_rejects_outliers_without_gps_and_recovers_from_a_jump():
    rng = np.random.default_rng(2)
    t, truth = _truth()
    sd = np.array([0.5, 0.5, 5.0])
    z = truth + rng.normal(size=truth.shape) * sd
    z[[30, 31, 70], 2] += 300.0
    z[50] = np.nan  # frame without ground returns
    out = filter_states(t, z, np.tile(sd, (t.size, 1)))
    assert not out.accepted[[30, 31, 70, 50]].any()
    assert np.all(np.abs(out.state[[30, 31, 50, 70], 2] - truth[[30, 31, 50, 70], 2]) < 20.0)
    # A lasting step (e.g. a cliff) is accepted after max_rejections frames.
    z2 = z.copy()
    z2[80:, 2] += 200.0
    truth2 = truth.copy()
    truth2[80:, 2] += 200.0
    out2 = filter_states(t, z2, np.tile(sd, (t.size, 1)), KalmanSettings(max_rejections=4))
    assert np.all(np.abs(out2.state[90:, 2] - truth2[90:, 2]) < 20.0)


def test_gps_gated_mode_uses_reference_height():
    t, truth = _truth(40)
    z = truth.copy()
    z[10, 2] += 200.0
    out = filter_states(
        t,
        z,
        np.tile([0.5, 0.5, 5.0], (t.size, 1)),
        KalmanSettings(gps_gate_m=150.0),
        reference_h_m=truth[:, 2],
    )
    assert not out.accepted[10] and out.accepted[11]
