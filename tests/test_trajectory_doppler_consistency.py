"""A trajectory's sampled velocity is the motion of its sampled position.

Sampled every 5-12 s, as ADS-B gives it, a thermalling glider's velocities interpolated on their own
can differ from the motion of its Hermite-interpolated positions by metres per second; the simulator
would then give it a Doppler that disagrees with its range rate, and the radar-aware tracker, whose
range follows the Doppler, would lag it by 10-15 m in range until it broke the track.
"""

from __future__ import annotations

import numpy as np

from skyradar.scene.trajectories import Trajectory


def test_sampled_velocity_is_the_derivative_of_the_sampled_position():
    ts = np.array([0.0, 7.0, 15.0, 21.0, 32.0, 40.0])  # sparse, irregular samples of a circle
    w = 25.0 / 120.0
    pos = np.column_stack([120 * np.cos(w * ts), 120 * np.sin(w * ts), np.full(ts.size, -1000.0)])
    vel = np.column_stack([-25 * np.sin(w * ts), 25 * np.cos(w * ts), np.zeros(ts.size)])
    t = np.arange(0.0, 40.0, 0.01)
    s = Trajectory.from_states(ts, pos, vel).sample(t)
    finite_difference = np.gradient(s.position_ned_m, t, axis=0)
    assert np.abs(finite_difference - s.velocity_ned_mps)[5:-5].max() < 0.05
    # The given velocities are kept at the samples.
    np.testing.assert_allclose(
        Trajectory.from_states(ts, pos, vel).sample(ts).velocity_ned_mps, vel, atol=1e-9
    )
