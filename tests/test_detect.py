"""Detection: CFAR factors against closed forms and Monte Carlo, one detection per object, sub-pixel, SNR."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyradar.benchmarks.process import synthetic_frame
from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.process.detect import blob_peaks, cfar_2d, cfar_factor, detect, integrate_channels, refine_peaks

CFG = RadarConfig.prototype_2022()


def noise_power(shape, n_int, rng):
    """Mean of n_int unit exponentials per pixel (Gamma(L, 1/L))."""
    return rng.gamma(n_int, 1.0 / n_int, size=shape).astype(np.float32)


def test_ca_factor_matches_classic_formula_for_one_channel():
    for n, pfa in [(16, 1e-6), (400, 1e-7), (50, 1e-3)]:
        assert cfar_factor(pfa, n) == pytest.approx(n * (pfa ** (-1 / n) - 1), rel=1e-6)


def test_os_factor_matches_closed_form_for_one_channel():
    # Rohling: Pfa = prod_{i=0}^{k-1} (N - i) / (N - i + alpha) for exponential noise.
    n, k, pfa = 24, 18, 1e-4
    alpha = cfar_factor(pfa, n, 1, "os", k)
    closed = np.prod([(n - i) / (n - i + alpha) for i in range(k)])
    assert closed == pytest.approx(pfa, rel=1e-3)


@pytest.mark.parametrize("kind", ["ca", "os"])
def test_cfar_false_alarm_rate_matches_pfa(kind):
    rng = np.random.default_rng(1)
    pfa = 2e-3
    shape = (120, 100) if kind == "ca" else (64, 64)
    frames = 12 if kind == "ca" else 4
    hits = 0
    for _ in range(frames):
        h, _ = cfar_2d(noise_power(shape, 4, rng), (1, 1), (3, 4), pfa, kind, n_integrated=4)
        hits += int(h[8:-8].sum())  # away from the reflected range edges
    n = frames * (shape[0] - 16) * shape[1]
    assert abs(hits - n * pfa) < 5 * np.sqrt(n * pfa)


def test_noise_only_frames_give_almost_no_false_alarms():
    rng = np.random.default_rng(2)
    count = 0
    for _ in range(20):
        cube, _ = synthetic_frame(CFG, rng=rng)
        count += len(detect(integrate_channels(cube), CFG))
    assert count <= 1  # expected 0.002 per frame at pfa 2e-8


def leaky_blob(shape, r0, d0, peak_db, rng):
    """A Hann-windowed point response (main lobe +-2 bins) on top of unit noise."""
    image = noise_power(shape, 4, rng)
    w = np.array([0.25, 0.75, 1.0, 0.75, 0.25])  # |Hann kernel| around the peak
    blob = np.outer(w, w) ** 2 * 10 ** (peak_db / 10)
    for i in range(5):
        for j in range(5):
            image[min(max(r0 + i - 2, 0), shape[0] - 1), (d0 + j - 2) % shape[1]] += blob[i, j]
    return image


@settings(max_examples=40, deadline=None)
@given(
    r0=st.integers(0, CFG.n_range - 1),
    d0=st.integers(0, CFG.n_doppler - 1),
    peak_db=st.floats(20.0, 60.0),
    seed=st.integers(0, 2**16),
)
def test_one_detection_per_object_anywhere_including_the_doppler_edge(r0, d0, peak_db, seed):
    rng = np.random.default_rng(seed)
    image = leaky_blob((CFG.n_range, CFG.n_doppler), r0, d0, peak_db, rng) * np.float32(CFG.noise_power_w)
    for method in ("cfar", "shi-tomasi"):
        det = detect(image, CFG, method=method)
        near = (np.abs(det.range_index - r0) <= 3) & (
            np.abs((det.doppler_index - d0 + CFG.n_doppler // 2) % CFG.n_doppler - CFG.n_doppler // 2) <= 3
        )
        assert near.sum() == 1, (method, det)
        assert det.range_index[near][0] == r0 and det.doppler_index[near][0] == d0


def test_two_separated_objects_give_two_detections():
    rng = np.random.default_rng(3)
    cube, pixels = synthetic_frame(CFG, [(1500.0, 5.0, 0.1, 0.0, 30.0), (1500.0, 15.0, -0.1, 0.0, 20.0)], rng)
    det = detect(integrate_channels(cube), CFG)
    assert sorted(zip(det.range_index.tolist(), det.doppler_index.tolist(), strict=True)) == sorted(pixels)


def test_blob_peaks_join_across_doppler_edge():
    mask = np.zeros((10, 20), bool)
    power = np.ones((10, 20), np.float32)
    mask[4, [0, 1, 19]] = True
    mask[5, 18] = True
    power[4, 19] = 5.0
    r, d = blob_peaks(mask, power)
    assert r.tolist() == [4] and d.tolist() == [19]


@given(dr=st.floats(-0.45, 0.45), dd=st.floats(-0.45, 0.45), width=st.floats(0.7, 2.0))
def test_parabolic_refinement_is_exact_on_gaussian_peaks(dr, dd, width):
    rr, dd_grid = np.meshgrid(np.arange(30), np.arange(40), indexing="ij")
    # Peak placed across the Doppler edge to exercise the wrap.
    ddw = (dd_grid - (0 + dd) + 20) % 40 - 20
    power = np.exp(-((rr - (15 + dr)) ** 2 + ddw**2) / (2 * width**2)).astype(np.float64)
    rb, db = refine_peaks(power, np.array([15]), np.array([0]))
    assert rb[0] == pytest.approx(15 + dr, abs=1e-6)
    assert (db[0] - dd + 20) % 40 - 20 == pytest.approx(0.0, abs=1e-6)


def test_snr_and_axes_of_a_detection():
    rng = np.random.default_rng(4)
    snrs, ranges, vels = [], [], []
    for _ in range(20):
        cube, _ = synthetic_frame(CFG, [(2000.0, -12.0, 0.2, -0.1, 30.0)], rng)
        det = detect(integrate_channels(cube), CFG)
        assert len(det) == 1
        snrs.append(det.snr_db[0])
        ranges.append(det.range_m(CFG)[0])
        vels.append(det.radial_velocity_mps(CFG)[0])
    assert np.mean(snrs) == pytest.approx(30.0, abs=0.5)
    assert np.all(np.abs(np.array(ranges) - 2000.0) <= CFG.range_resolution_m / 2 + 0.5)
    assert np.all(np.abs(np.array(vels) + 12.0) <= CFG.doppler_resolution_mps / 2 + 0.5)


def test_calibration_gains_are_divided_out_of_the_power():
    rng = np.random.default_rng(5)
    cube, _ = synthetic_frame(CFG, [(1000.0, 0.0, 0.0, 0.0, 40.0)], rng)
    gains = np.array([1.0, 2.0, 0.5, 1.5]) * np.exp(1j * np.array([0.0, 1.0, 2.0, 3.0]))
    p1 = integrate_channels(cube)
    p2 = integrate_channels(cube * gains.astype(np.complex64), gains)
    np.testing.assert_allclose(p1, p2, rtol=1e-5)


def test_bad_input():
    with pytest.raises(InputError, match="shape"):
        detect(np.zeros((10, 10), np.float32), CFG)
    with pytest.raises(InputError, match="method"):
        detect(np.ones((CFG.n_range, CFG.n_doppler), np.float32), CFG, method="threshold")
    with pytest.raises(InputError, match="rx"):
        integrate_channels(np.zeros((5, 5, 3), np.complex64), np.ones(4))
    with pytest.raises(InputError, match="pfa"):
        cfar_factor(1.5, 10)
