"""An elevation clutter suppression left unobservable is carried as ``elevation_measured`` False, not
guessed from the value 0 (issue 12): the 3-D tracker takes such a detection's height as unknown, the
track-level ground test does not count it as a measured direction."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from skyradar.config import RadarConfig
from skyradar.io.frames import frames_dataset
from skyradar.process.pipeline import DETECTION_COLUMNS, process_frames
from skyradar.track.measure3d import UNMEASURED_ELEVATION_SIGMA_RAD, position_covariance
from skyradar.track.tracker3d import RadialObservation, Tracker3D

finite = st.floats(-3000.0, 3000.0, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(st.tuples(finite, finite, finite), st.floats(1e-3, 0.2), st.floats(1e-3, 0.5), st.floats(1.0, 50.0))
def test_vertical_sigma_sets_only_the_vertical_across_axis(point, sigma, vertical, range_sd):
    p = np.array([point]) + np.array([[4000.0, 0.0, 0.0]])  # keep the radar off the point
    r = float(np.linalg.norm(p))
    same = position_covariance(p, np.zeros(3), np.array([sigma]), range_sd, np.array([sigma]))
    np.testing.assert_allclose(
        same, position_covariance(p, np.zeros(3), np.array([sigma]), range_sd), atol=1e-6
    )
    cov = position_covariance(p, np.zeros(3), np.array([sigma]), range_sd, np.array([vertical]))[0]
    np.testing.assert_allclose(cov, cov.T, atol=1e-9)
    expected = sorted([range_sd**2, (r * sigma) ** 2, (r * vertical) ** 2])
    np.testing.assert_allclose(np.linalg.eigvalsh(cov), expected, rtol=1e-6, atol=1e-6)
    u = p[0] / r
    horizontal = np.cross([0.0, 0.0, 1.0], u)
    if np.linalg.norm(horizontal) > 1e-3:  # the horizontal across axis keeps the measured sd
        horizontal /= np.linalg.norm(horizontal)
        assert abs(horizontal @ cov @ horizontal - (r * sigma) ** 2) < 1e-6 * max(1.0, (r * sigma) ** 2)


def _height_rms(flag_unmeasured: bool, seed: int) -> float:
    """Height RMS error of a 3-D track whose every other detection has its elevation replaced by the
    prior 0 (placed at the own-ship's altitude), the rest measured to 0.01 rad, over its last 10 s, m."""
    rng = np.random.default_rng(seed)
    t3 = Tracker3D()
    own_v, v = np.array([50.0, 0.0, 0.0]), np.array([-40.0, -10.0, 0.0])
    err = []
    for k in range(200):
        t = 0.1 * k
        own, p = own_v * t, np.array([2500.0, 600.0, -200.0]) + v * t  # 200 m above the own-ship
        r = np.linalg.norm(p - own)
        u = (p - own) / r
        measured = k % 2 == 0
        if measured:
            meas = p + r * 0.01 * rng.standard_normal(3)
        else:
            flat = np.array([u[0], u[1], 0.0]) / np.hypot(u[0], u[1])
            meas = own + r * flat  # elevation 0: co-altitude
        vertical = None
        if flag_unmeasured:
            vertical = np.array([0.01 if measured else UNMEASURED_ELEVATION_SIGMA_RAD])
        cov = position_covariance(meas[None], own, np.array([0.01]), np.array([r * 0.01]), vertical)
        rr = np.array([u @ (v - own_v) + 0.2 * rng.standard_normal()])
        x, _ = t3.step(t, np.array([1]), meas[None], cov, RadialObservation(own, own_v, rr, 0.2))
        err.append(x[0, 2] - p[2])
    return float(np.sqrt(np.mean(np.square(err[100:]))))


def test_unmeasured_elevation_does_not_pull_the_track_to_co_altitude():
    for seed in range(3):
        guessed, flagged = _height_rms(False, seed), _height_rms(True, seed)
        assert guessed > 40.0  # half the detections say co-altitude, 200 m off
        assert flagged < 20.0


def test_clear_sky_detections_all_have_measured_elevations():
    cfg = RadarConfig.prototype_2022()
    rng = np.random.default_rng(1)
    shape = (2, cfg.n_range, cfg.n_doppler, cfg.n_rx)
    iq = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)) * np.sqrt(cfg.noise_power_w / 2)
    iq[:, 120, 60, :] += np.sqrt(1e4 * cfg.noise_power_w)
    table = process_frames(frames_dataset(iq.astype(np.complex64), np.array([0.0, 0.1]), cfg))
    assert "elevation_measured" in DETECTION_COLUMNS and table["elevation_measured"].dtype == bool
    assert len(table) >= 2 and table["elevation_measured"].all()
