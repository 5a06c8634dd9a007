"""DoA: exact on noise-free data for any layout, efficient against the Cramer-Rao bound, calibration."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyradar.benchmarks.process import synthetic_frame
from skyradar.config import Mount, RadarConfig
from skyradar.errors import InputError
from skyradar.experiments.ch3_scene import square_array_m, unambiguous_half_angle_deg
from skyradar.geo import rotation_matrix
from skyradar.process.calibration import (
    calibrate_from_frames,
    calibration_phase_error_deg,
    estimate_rx_calibration,
    expected_pixels,
    in_field_of_view,
    reflector_position,
)
from skyradar.process.doa import (
    angles_from_direction,
    antenna_to_body,
    direction_from_angles,
    doa_crlb,
    estimate_directions,
    steering_vector,
)

CFG = RadarConfig.prototype_2022()
LAM = CFG.wavelength_m
LAYOUTS = {
    "square": CFG,
    # Non-coplanar: a tetrahedron-like array with lambda/2 edges along y, z and a depth offset.
    "3d": CFG.replace(
        rx_positions_m=np.array([[0, 0, 0], [0, LAM / 2, 0], [0, 0, LAM / 2], [LAM / 2, 0, 0]])
    ),
    # ch3's default: 0.6 lambda square, every baseline ambiguous (grid search path); grating lobes
    # 1/0.6 apart in direction cosine stay outside the field of view.
    "square_0.6": CFG.replace(rx_positions_m=square_array_m(0.6, LAM)),
    "sparse3d": CFG.replace(
        rx_positions_m=np.array(
            [[0, 0, 0], [0, 0.6 * LAM, 0], [0, 0, 0.6 * LAM], [0.6 * LAM, 0.3 * LAM, 0.3 * LAM]]
        )
    ),
    # Three antennas in a tilted plane, unequal baselines (one over lambda/2).
    "tilted": CFG.replace(
        rx_positions_m=np.array([[0.002, 0, 0], [-0.001, 0.45 * LAM, 0], [0.0, 0.2 * LAM, 0.48 * LAM]]),
        rx_calibration=None,
    ),
}


def noisy_pixels(u, snr_db, config, rng, gains=None):
    n = len(u)
    amp = np.sqrt(10 ** (np.asarray(snr_db) / 10.0))
    z = (
        np.atleast_1d(amp)[:, None]
        * steering_vector(u, config)
        * np.exp(1j * rng.uniform(0, 2 * np.pi, (n, 1)))
    )
    z = z + (rng.standard_normal(z.shape) + 1j * rng.standard_normal(z.shape)) / np.sqrt(2)
    return z if gains is None else z * gains


@settings(max_examples=60, deadline=None)
@given(
    layout=st.sampled_from(sorted(LAYOUTS)),
    az=st.floats(-np.radians(45), np.radians(45)),
    el=st.floats(-np.radians(45), np.radians(45)),
)
def test_noise_free_directions_are_exact_for_every_layout(layout, az, el):
    cfg = LAYOUTS[layout]
    u = direction_from_angles(az, el)[None]
    # Exact two-way phases at 5 km (near-field terms included) instead of the far-field model.
    pixels = expected_pixels(5000.0 * u[0], cfg)[None] * np.exp(0.7j)
    est_az, est_el = angles_from_direction(estimate_directions(pixels, cfg))
    assert np.degrees(abs(est_az[0] - az)) < 1e-3 and np.degrees(abs(est_el[0] - el)) < 1e-3


def test_wrapped_diagonal_baseline_is_unwrapped():
    # az = el = 38 deg: u_y + u_z > 1, so the lambda/sqrt(2) diagonal of the square array wraps.
    az = el = np.radians(38.0)
    u = direction_from_angles(az, el)
    assert u[1] - u[2] > 1.0
    est = estimate_directions(steering_vector(u, CFG)[None], CFG)[0]
    np.testing.assert_allclose(est, u, atol=1e-9)


def test_crlb_matches_numerical_fisher_information():
    # Independent check: FIM = (2 / sigma^2) Re(J^H J) of the complex model with unknown
    # amplitude, common phase, az, el, differentiated numerically.
    rng = np.random.default_rng(0)
    for cfg in (LAYOUTS["square"], LAYOUTS["3d"], LAYOUTS["tilted"], LAYOUTS["square_0.6"]):
        az, el, snr_db = rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5), 20.0
        theta = np.array([np.sqrt(10 ** (snr_db / 10)), 0.3, az, el])

        def model(t, cfg=cfg):
            return t[0] * np.exp(1j * t[1]) * steering_vector(direction_from_angles(t[2], t[3]), cfg)

        jac = np.stack([(model(theta + h) - model(theta - h)) / 2e-7 for h in np.eye(4) * 1e-7], axis=1)
        crlb = np.linalg.inv(2.0 * np.real(jac.conj().T @ jac))
        sd_az, sd_el = doa_crlb(snr_db, az, el, cfg)
        assert sd_az == pytest.approx(np.sqrt(crlb[2, 2]), rel=1e-4)
        assert sd_el == pytest.approx(np.sqrt(crlb[3, 3]), rel=1e-4)


@pytest.mark.parametrize("layout", ["square", "tilted", "3d", "square_0.6"])
def test_error_sd_within_1_25_crlb_in_every_snr_band(layout):
    cfg = LAYOUTS[layout]
    rng = np.random.default_rng(1)
    n = 3000
    for snr_db in (15.0, 20.0, 25.0, 30.0, 35.0, 40.0):
        az = rng.uniform(-np.radians(35), np.radians(35), n)
        el = rng.uniform(-np.radians(35), np.radians(35), n)
        z = noisy_pixels(direction_from_angles(az, el), np.full(n, snr_db), cfg, rng)
        est_az, est_el = angles_from_direction(estimate_directions(z, cfg))
        sd_az, sd_el = doa_crlb(snr_db, az, el, cfg)
        # Normalised errors: the bound varies with direction, so compare error / bound per trial.
        assert np.std((est_az - az) / sd_az) <= 1.25, snr_db
        assert np.std((est_el - el) / sd_el) <= 1.25, snr_db


@pytest.mark.parametrize("layout", ["square", "square_0.6"])
def test_bias_below_0_1_deg_after_calibration(layout):
    cfg = LAYOUTS[layout]
    rng = np.random.default_rng(2)
    offsets = np.array([1.0, 0.9, 1.1, 1.05]) * np.exp(1j * rng.uniform(-np.pi, np.pi, 4))
    reflector = reflector_position(438.0, np.radians(5.0), np.radians(-1.0))
    # A building at 438 m is a strong reflector (50 dB SNR); 10 frames.
    frames = [
        synthetic_frame(cfg, [(438.0, 0.0, np.radians(5.0), np.radians(-1.0), 50.0)], rng, rx_gain=offsets)[0]
        for _ in range(10)
    ]
    cal = calibrate_from_frames(np.stack(frames), reflector, cfg)
    assert calibration_phase_error_deg(cal.rx_calibration, offsets) <= 0.1
    n = 20000
    az = rng.uniform(-np.radians(30), np.radians(30), n)
    el = rng.uniform(-np.radians(30), np.radians(30), n)
    z = noisy_pixels(direction_from_angles(az, el), np.full(n, 35.0), cal, rng, gains=offsets)
    est_az, est_el = angles_from_direction(estimate_directions(z, cal))
    assert abs(np.degrees(np.mean(est_az - az))) < 0.1
    assert abs(np.degrees(np.mean(est_el - el))) < 0.1
    # Without calibration the same data are badly biased: the test can fail.
    raw_az, _ = angles_from_direction(estimate_directions(z, cfg))
    assert abs(np.degrees(np.mean(raw_az - az))) > 1.0


@given(phases=st.lists(st.floats(-np.pi, np.pi), min_size=3, max_size=3), gain=st.floats(0.5, 2.0))
def test_calibration_recovers_offsets_exactly_without_noise(phases, gain):
    offsets = np.array([1.0, gain, 1.0, 1.0 / gain]) * np.exp(1j * np.array([0.0, *phases]))
    p = reflector_position(438.0, np.radians(5.0), np.radians(-1.0))
    cal = estimate_rx_calibration(expected_pixels(p, CFG) * offsets * 3.0, p, CFG)
    assert calibration_phase_error_deg(cal, offsets) < 1e-6
    np.testing.assert_allclose(np.abs(cal) / np.abs(cal[0]), np.abs(offsets), rtol=1e-9)


def test_bad_layouts_and_reflectors_are_input_errors():
    line = CFG.replace(rx_positions_m=np.array([[0, 0, 0], [0, LAM / 2, 0], [0, LAM, 0], [0, 1.5 * LAM, 0]]))
    with pytest.raises(InputError, match="one line"):
        estimate_directions(np.ones((1, 4)), line)
    with pytest.raises(InputError, match="coincide"):  # a channel counted twice is refused up front
        CFG.replace(rx_positions_m=np.array([[0, 0, 0], [0, LAM / 2, 0], [0, 0, 0], [0, LAM / 2, 0]]))
    two = CFG.replace(rx_positions_m=np.array([[0, 0, 0], [0, LAM / 2, 0]]), rx_calibration=None)
    with pytest.raises(InputError, match="distinct"):
        estimate_directions(np.ones((1, 2)), two)
    with pytest.raises(InputError, match="channels"):
        estimate_directions(np.ones((1, 3)), CFG)
    behind = reflector_position(438.0, np.radians(120.0), 0.0)
    with pytest.raises(InputError, match="field of view"):
        estimate_rx_calibration(expected_pixels(behind, CFG), behind, CFG)
    wide = reflector_position(438.0, np.radians(60.0), np.radians(-1.0))
    with pytest.raises(InputError, match="field of view"):
        calibrate_from_frames(np.zeros((CFG.n_range, CFG.n_doppler, 4), np.complex64), wide, CFG)
    assert bool(in_field_of_view(np.radians(5.0), np.radians(-1.0), CFG))


def test_body_frame_uses_the_mount_rotation():
    cfg = CFG.replace(mount=Mount(position_m=(1.0, 0.0, -0.5), yaw_deg=0.0, pitch_deg=15.0, roll_deg=0.0))
    p_ant = np.array([[1000.0, 0.0, 0.0]])
    body = antenna_to_body(p_ant, cfg)
    expected = rotation_matrix(0.0, np.radians(15.0), 0.0) @ p_ant[0] + np.array([1.0, 0.0, -0.5])
    np.testing.assert_allclose(body[0], expected)
    assert body[0, 2] < -250  # pitched up: boresight points above the body x axis (down is +z)


def test_square_06_unambiguous_to_56_deg_then_aliases_to_the_grating_lobe():
    # Phase differences of a 0.6 lambda pair wrap where |u| > 1 / (2 * 0.6), i.e. beyond 56.4 deg
    # on either axis; a target further out is indistinguishable from its grating lobe
    # u - 1 / 0.6 and is reported there (the price of the wider aperture).
    cfg = LAYOUTS["square_0.6"]
    limit = unambiguous_half_angle_deg(0.6)
    assert limit == pytest.approx(np.degrees(np.arcsin(1 / 1.2)))
    for axis in (0, 1):
        for deg in (*np.linspace(-limit + 0.05, limit - 0.05, 41), 60.0, 70.0, -80.0):
            angles = [np.radians(deg), 0.0] if axis == 0 else [0.0, np.radians(deg)]
            u = direction_from_angles(*angles)
            est = np.degrees(angles_from_direction(estimate_directions(steering_vector(u, cfg)[None], cfg)))
            s = np.sin(np.radians(deg))
            expected = deg if abs(deg) < limit else np.degrees(np.arcsin(s - np.sign(s) / 0.6))
            assert est[axis][0] == pytest.approx(expected, abs=1e-6), (axis, deg)
            assert est[1 - axis][0] == pytest.approx(0.0, abs=1e-6)


@settings(max_examples=30, deadline=None)
@given(az=st.floats(-1.0, 1.0), el=st.floats(-1.0, 1.0), spacing=st.floats(0.1, 1.0))
def test_crlb_uses_the_actual_layout_and_scales_with_one_over_spacing(az, el, spacing):
    # Phase per radian of direction is proportional to the baseline, so the bound is too (inverse).
    sparse = CFG.replace(rx_positions_m=square_array_m(spacing, LAM))
    for half, wide in zip(doa_crlb(25.0, az, el, CFG), doa_crlb(25.0, az, el, sparse), strict=True):
        assert wide == pytest.approx(half * 0.5 / spacing, rel=1e-9)
