"""skyradar.kalman: the one Kalman update (Joseph form) against the textbook form, and its users."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from skyradar.kalman import predict, update
from skyradar.nav.kalman_state import KalmanSettings, _transition, filter_states


def _textbook(x, P, y, H, R):
    K = P @ H.T @ np.linalg.inv(H @ P @ H.T + R)
    return x + K @ y, (np.eye(len(x)) - K @ H) @ P


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(2, 6), st.integers(1, 3))
def test_update_equals_textbook_on_random_spd(seed, d, k):
    rng = np.random.default_rng(seed)
    A, B = rng.normal(size=(d, d)), rng.normal(size=(k, k))
    P, R = A @ A.T + 0.5 * np.eye(d), B @ B.T + 0.5 * np.eye(k)
    H, x, y = rng.normal(size=(k, d)), rng.normal(size=d), rng.normal(size=k)
    x_ref, P_ref = _textbook(x, P, y, H, R)
    x1, P1 = update(x, P, y, H, R)
    np.testing.assert_allclose(x1, x_ref, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(P1, P_ref, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(P1, P1.T, rtol=1e-12, atol=1e-12)  # Joseph form keeps P symmetric
    # A stack of the same state gives the same answer per row (the trackers' batched use).
    xs, Ps = update(np.stack([x, x]), np.stack([P, P]), np.stack([y, y]), H, R)
    np.testing.assert_allclose(xs[1], x_ref, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(Ps[0], P_ref, rtol=1e-9, atol=1e-9)


def test_flight_state_filter_uses_the_same_update_as_a_textbook_loop():
    rng = np.random.default_rng(5)
    t = np.cumsum(rng.uniform(0.1, 0.4, 40))
    z = np.column_stack(
        [50 + rng.normal(0, 1, 40), 2 + rng.normal(0, 1, 40), 600 - 2 * t + rng.normal(0, 9, 40)]
    )
    sd = np.tile([1.0, 1.0, 10.0], (40, 1))
    s = KalmanSettings(gate_probability=1.0 - 1e-15)  # nothing gated: every frame updates
    out = filter_states(t, z, sd, s)
    x, P = z[0], np.diag(sd[0] ** 2)
    for i in range(1, 40):
        F, Q = _transition(t[i] - t[i - 1], s)
        x, P = predict(x, P, F, Q)
        x, P = _textbook(x, P, z[i] - x, np.eye(3), np.diag(sd[i] ** 2))
    assert out.accepted.all()
    np.testing.assert_allclose(out.state[-1], x, rtol=1e-10)
    np.testing.assert_allclose(out.sd[-1], np.sqrt(np.diag(P)), rtol=1e-10)
