"""A DoA position's error sits on the array's axes: its bound per axis, with their correlation.

An array wider than it is tall measures the elevation worse than the azimuth. The 3-D track takes
each detection's covariance from :func:`skyradar.process.doa.direction_covariance` on the array's
axes (turned with the aircraft's bank), not one per-axis value for both, so that it does not trust
an elevation more than the array measures it. Peers: the phase-difference estimator itself on noisy
pixels (it reaches the bound at high SNR), and positions made by rotating the antenna frame.
"""

import numpy as np
import pytest

from skyradar.config import RadarConfig
from skyradar.process.doa import (
    angles_from_direction,
    direction_covariance,
    direction_from_angles,
    doa_crlb,
    estimate_directions,
    steering_vector,
)
from skyradar.track.measure3d import angle_covariance_rad2, angle_sigma_rad, position_covariance


@pytest.mark.parametrize(
    ("layout", "az_deg", "el_deg"),
    [("ura-2x4", -42.0, -10.0), ("ura-2x3", 25.0, 12.0), ("square", -35.0, 20.0)],
)
def test_bound_matches_the_estimator_off_boresight(layout, az_deg, el_deg):
    cfg = RadarConfig.prototype_2022(rx_positions_m=layout)
    snr_db, n = 25.0, 6000
    rng = np.random.default_rng(3)
    az, el = np.radians(az_deg), np.radians(el_deg)
    pixels = steering_vector(direction_from_angles(az, el), cfg)[None, :] + np.sqrt(
        10 ** (-snr_db / 10) / 2
    ) * (rng.standard_normal((n, cfg.n_rx)) + 1j * rng.standard_normal((n, cfg.n_rx)))
    got_az, got_el = angles_from_direction(estimate_directions(pixels, cfg, calibrated=True))
    # Rightward displacement is cos(el) d az, upward is d el.
    disp = np.column_stack([np.cos(el) * (got_az - az), got_el - el])
    empirical = np.cov(disp.T)
    bound = direction_covariance(snr_db, az, el, cfg)
    np.testing.assert_allclose(np.diag(empirical), np.diag(bound), rtol=0.1)
    corr = lambda c: c[0, 1] / np.sqrt(c[0, 0] * c[1, 1])  # noqa: E731
    assert abs(corr(empirical) - corr(bound)) < 0.05
    # doa_crlb is the same bound, azimuth in angle.
    sd_az, sd_el = doa_crlb(snr_db, az, el, cfg)
    assert np.isclose(sd_az * np.cos(el), np.sqrt(bound[0, 0])) and np.isclose(sd_el, np.sqrt(bound[1, 1]))


def test_wide_array_elevation_is_its_worse_axis():
    # A 2 x 4 array's rows have a fifth of its columns' second moment: the elevation's bound is
    # sqrt(5) times the azimuth's at boresight, and the old per-axis RMS understates it 1.3 times.
    cfg = RadarConfig.prototype_2022(rx_positions_m="ura-2x4")
    C = angle_covariance_rad2(np.array([12.0]), cfg, np.zeros(1), np.zeros(1))[0]
    assert np.isclose(np.sqrt(C[1, 1] / C[0, 0]), np.sqrt(5.0), rtol=1e-9)
    rms = angle_sigma_rad(np.array([12.0]), cfg)[0]
    assert np.isclose(np.sqrt(C[1, 1]) / rms, np.sqrt(5.0 / 3.0), rtol=1e-9)


def test_position_covariance_follows_a_banked_array():
    # Directions drawn with the bound's covariance on the antenna's (rightward, upward) axes, turned
    # into NED by the aircraft's 30 deg bank and 20 deg heading: their positions' covariance is
    # position_covariance of angle_covariance_rad2 with the detection's right axis.
    cfg = RadarConfig.prototype_2022(rx_positions_m="ura-2x4")
    rng = np.random.default_rng(0)
    az, el, r, snr_db = np.radians(-42.0), np.radians(-10.0), 2000.0, 15.0
    bound = direction_covariance(snr_db, az, el, cfg)
    disp = rng.multivariate_normal(np.zeros(2), bound, size=40000)
    u_ant = direction_from_angles(az + disp[:, 0] / np.cos(el), el + disp[:, 1])
    roll, yaw = np.radians(30.0), np.radians(20.0)
    R_roll = np.array([[1, 0, 0], [0, np.cos(roll), -np.sin(roll)], [0, np.sin(roll), np.cos(roll)]])
    R_yaw = np.array([[np.cos(yaw), -np.sin(yaw), 0], [np.sin(yaw), np.cos(yaw), 0], [0, 0, 1]])
    to_ned = R_yaw @ R_roll  # antenna axes (boresight, right, down) in NED
    own = np.array([10.0, -5.0, -1000.0])
    points = own + r * u_ant @ to_ned.T
    true_point = own + r * direction_from_angles(az, el) @ to_ned.T
    right_ned = to_ned @ np.array([0.0, 1.0, 0.0])
    C = angle_covariance_rad2(np.array([snr_db]), cfg, np.array([az]), np.array([el]))
    cov = position_covariance(true_point[None], own, C, 0.0, right_axis=right_ned[None])[0]
    scale = r**2 * bound[1, 1]
    np.testing.assert_allclose(np.cov(points.T), cov, atol=0.03 * scale)
    # Level (no right axis given) it is another covariance, by far more than the sampling error.
    level = position_covariance(true_point[None], own, C, 0.0)[0]
    assert np.abs(level - cov).max() > 0.2 * scale
