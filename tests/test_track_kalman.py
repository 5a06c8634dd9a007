"""Kalman filter, motion models, wrapped innovation and de-aliasing against closed forms."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyradar.track.dealias import dealias_velocity, push_history, range_rate_fit
from skyradar.track.kalman import innovation, predict, update
from skyradar.track.models import MEASUREMENT_MATRIX, radar_model, traditional_model
from skyradar.units import wrap

W = 78.32
finite = st.floats(-1e4, 1e4, allow_nan=False, allow_infinity=False)


@settings(max_examples=300, deadline=None)
@given(o=finite, p=finite, w=st.floats(0.5, 500.0))
def test_wrapped_innovation_in_half_open_interval_and_congruent(o, p, w):
    y = innovation(np.array([0.0, o]), np.array([0.0, p]), w)[1]
    assert -w / 2 <= y < w / 2
    k = (o - p - y) / w
    assert abs(k - round(k)) < 1e-6
    # It is the shortest way round: no other alias is closer to zero.
    assert abs(y) <= abs(y + w) + 1e-9 and abs(y) <= abs(y - w) + 1e-9


def test_wrap_matches_thesis_formula():
    v = np.linspace(-300, 300, 1001)
    np.testing.assert_allclose(wrap(v, W), np.mod(v + W / 2, W) - W / 2, atol=1e-9)


def test_single_observation_range_wrap_only_where_asked():
    z = np.array([[100.0, 0.0], [100.0, 0.0]])
    zp = np.array([[91.0, 0.0], [91.0, 0.0]])
    y = innovation(z, zp, W, np.array([8.0, np.nan]))
    assert y[0, 0] == pytest.approx(1.0)
    assert y[1, 0] == pytest.approx(9.0)


def test_kalman_update_equals_textbook_closed_form():
    rng = np.random.default_rng(3)
    A = rng.normal(size=(4, 4))
    P = A @ A.T + 4 * np.eye(4)
    x = rng.normal(size=4)
    R = np.diag([4.0, 0.01])
    y = np.array([3.0, -0.2])
    H = MEASUREMENT_MATRIX
    # Hand-written: K = P H^T (H P H^T + R)^-1 with the 2x2 inverse written out.
    S = P[:2, :2] + R
    det = S[0, 0] * S[1, 1] - S[0, 1] * S[1, 0]
    S_inv = np.array([[S[1, 1], -S[0, 1]], [-S[1, 0], S[0, 0]]]) / det
    K = P[:, :2] @ S_inv
    x_ref = x + K @ y
    P_ref = P - K @ S @ K.T
    x_new, P_new = update(x[None], P[None], y[None], H, R)
    np.testing.assert_allclose(x_new[0], x_ref, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(P_new[0], P_ref, rtol=1e-10, atol=1e-10)


def test_kalman_scalar_gain_for_diagonal_covariance():
    P = np.diag([9.0, 1.0, 5.0, 2.0])[None]
    x, Pn = update(np.zeros((1, 4)), P, np.array([[10.0, 2.0]]), MEASUREMENT_MATRIX, np.diag([1.0, 1.0]))
    # Independent axes: gain p / (p + r).
    np.testing.assert_allclose(x[0], [10.0 * 0.9, 2.0 * 0.5, 0.0, 0.0])
    np.testing.assert_allclose(np.diag(Pn[0]), [0.9, 0.5, 5.0, 2.0])


def test_batched_predict_and_update_equal_per_track_loop():
    rng = np.random.default_rng(0)
    n = 7
    m = radar_model(W)
    F, Q = m.transition(0.1), m.process_noise(0.1)
    A = rng.normal(size=(n, 4, 4))
    P = A @ np.swapaxes(A, 1, 2) + np.eye(4)
    x = rng.normal(size=(n, 4))
    y = rng.normal(size=(n, 2))
    xb, Pb = update(*predict(x, P, F, Q), y, MEASUREMENT_MATRIX, m.measurement_noise)
    for i in range(n):
        xi, Pi = F @ x[i], F @ P[i] @ F.T + Q
        K = Pi[:, :2] @ np.linalg.inv(Pi[:2, :2] + m.measurement_noise)
        np.testing.assert_allclose(xb[i], xi + K @ y[i], atol=1e-10)
        np.testing.assert_allclose(Pb[i], (np.eye(4) - K @ MEASUREMENT_MATRIX) @ Pi, atol=1e-8)


def test_radar_model_range_follows_radial_velocity():
    F = radar_model(W).transition(0.5)
    np.testing.assert_array_equal(F, [[1, 0.5, 0, 0], [0, 1, 0, 0.5], [0, 0, 1, 0], [0, 0, 0, 1]])
    x = np.array([1000.0, -20.0, 5.0, 2.0])
    assert (F @ x)[0] == 990.0  # range moved by V_R * dt, not by the range-rate state
    Ft = traditional_model(W).transition(0.5)
    assert (Ft @ x)[0] == 1002.5


@settings(max_examples=50, deadline=None)
@given(dt=st.floats(1e-3, 5.0))
def test_process_noise_symmetric_positive_semidefinite(dt):
    for m in (radar_model(W), traditional_model(W)):
        Q = m.process_noise(dt)
        np.testing.assert_allclose(Q, Q.T, atol=1e-12)
        assert np.linalg.eigvalsh(Q).min() > -1e-9 * max(1.0, np.abs(Q).max())


@settings(max_examples=200, deadline=None)
@given(v=st.floats(-39.0, 39.0), true=st.floats(-200.0, 200.0))
def test_dealias_congruent_and_closest_to_rate(v, true):
    out = dealias_velocity(np.array([v]), np.array([true]), W)[0]
    k = (out - v) / W
    assert abs(k - round(k)) < 1e-9
    assert abs(out - true) <= W / 2 + 1e-9


def test_range_rate_fit_exact_on_ring_buffer():
    buf_t = np.full((1, 4), np.nan)
    buf_r = np.full((1, 4), np.nan)
    for count, t in enumerate(np.arange(7) * 0.1):
        push_history(buf_t, np.array([0]), np.array([t]), np.array([count]))
        push_history(buf_r, np.array([0]), np.array([500.0 - 60.0 * t]), np.array([count]))
    assert range_rate_fit(buf_t, buf_r, np.array([7]))[0] == pytest.approx(-60.0)
    assert np.isnan(range_rate_fit(np.array([[0.0, np.nan]]), np.array([[1.0, np.nan]]), np.array([1])))[0]


def test_a_collision_course_track_never_reports_a_negative_range():
    # Head-on at 100 m/s (aliased), detected down to 5 m: the frame after, the filter's prediction
    # is 8.5 m past zero; the table reports the range projected onto range >= 0.
    import pandas as pd

    from skyradar.config import RadarConfig
    from skyradar.track.track_table import track_detections

    cfg = RadarConfig.prototype_2022()
    t = np.arange(60) / 9.4
    r = 600.0 - 100.0 * t
    alias = (-100.0 + cfg.v_lim_mps) % (2 * cfg.v_lim_mps) - cfg.v_lim_mps
    det = pd.DataFrame({"time_s": t[r > 5.0], "range_m": r[r > 5.0], "radial_velocity_mps": alias})
    out = track_detections(det, frame_times_s=t)
    assert out["range_m"].min() == 0.0 and out["range_rate_mps"].iloc[-1] < -90.0
