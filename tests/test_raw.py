"""Raw FMCW chain (chirp-level simulator + range-Doppler FFT) against the config axes, the
image-domain simulator and scipy's window spectra."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal
from hypothesis import given, settings
from hypothesis import strategies as st

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.process.rangedoppler import range_doppler, window_gain_db
from skyradar.sim import image
from skyradar.sim.raw import adc_noise, received_power_w, simulate_adc

CFG = RadarConfig.prototype_2022()
NV = CFG.n_doppler


def predicted_bins(range_m: float, v_mps: float, cfg: RadarConfig = CFG) -> tuple[float, int]:
    """Range bin (fractional, with range-Doppler coupling) and wrapped Doppler bin (shifted index)."""
    k = (range_m + cfg.range_doppler_coupling_s * v_mps) / cfg.range_resolution_m
    j = (int(np.floor(v_mps / cfg.doppler_resolution_mps + 0.5)) + cfg.n_doppler // 2) % cfg.n_doppler
    return k, j


def peak(rd: np.ndarray) -> tuple[int, int]:
    power = (np.abs(rd) ** 2).sum(axis=2)
    k, j = np.unravel_index(power.argmax(), power.shape)
    return int(k), int(j)


def circular_distance(a: int, b: int, n: int) -> int:
    d = abs(a - b) % n
    return min(d, n - d)


@settings(max_examples=12, deadline=None)
@given(
    range_m=st.floats(100.0, 4800.0),
    v_mps=st.floats(-3.0 * 39.16, 3.0 * 39.16),  # includes velocities aliased once and twice
    az_deg=st.floats(-20, 20),
    el_deg=st.floats(-20, 20),
)
def test_peak_lands_in_the_bin_of_the_config_axes(range_m, v_mps, az_deg, el_deg):
    az, el = np.radians(az_deg), np.radians(el_deg)
    u = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)])
    adc = simulate_adc(CFG, range_m * u[None], v_mps * u[None], noise=False)
    k_pred, j_pred = predicted_bins(range_m, v_mps)
    k, j = peak(range_doppler(adc, CFG))
    assert abs(k - k_pred) <= 1.0
    assert circular_distance(j, j_pred, NV) <= 1


@settings(max_examples=10, deadline=None)
@given(
    k=st.integers(5, 325),
    j=st.integers(-NV // 2, NV // 2 - 1),
    alias=st.integers(-1, 1),
    window=st.sampled_from(["hann", "none", "blackmanharris", "chebyshev:80"]),
)
def test_on_bin_power_equals_radar_equation_after_window_gain(k, j, alias, window):
    v = (j + alias * NV) * CFG.doppler_resolution_mps
    r = k * CFG.range_resolution_m - CFG.range_doppler_coupling_s * v  # on-bin after coupling
    pos = np.array([[r, 0.0, 0.0]])
    adc = simulate_adc(CFG, pos, [[v, 0.0, 0.0]], rcs_m2=2.0, noise=False)
    rd = range_doppler(adc, CFG, window, window)
    assert peak(rd) == (k, j + NV // 2)
    power_db = 10 * np.log10(np.abs(rd[k, j + NV // 2]) ** 2) - window_gain_db(window, window)
    expected_db = 10 * np.log10(received_power_w(CFG, pos, 2.0)[0])
    # A fast target migrates up to a third of a range bin over the frame: a scalloping loss of up
    # to about half a dB at short range with the rectangular window (physics, not error).
    assert np.all(np.abs(power_db - expected_db) < 1.0)


@settings(max_examples=10, deadline=None)
@given(
    k=st.integers(10, 320),
    j=st.integers(-NV // 2, NV // 2 - 1),
    alias=st.integers(-1, 1),
    az_deg=st.floats(-25, 25),
    el_deg=st.floats(-25, 25),
    frac_k=st.floats(-0.3, 0.3),
    frac_j=st.floats(-0.3, 0.3),
)
def test_raw_chain_agrees_with_image_domain_simulator(k, j, alias, az_deg, el_deg, frac_k, frac_j):
    # Antenna frame = NED here: platform at the origin, level, facing north, default mount.
    v = (j + frac_j + alias * NV) * CFG.doppler_resolution_mps
    r = (k + frac_k) * CFG.range_resolution_m - CFG.range_doppler_coupling_s * v
    az, el = np.radians(az_deg), np.radians(el_deg)
    u = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)])
    sim = image.ImageSimulator(CFG, noise=False)
    own = image.PlatformState(np.zeros(3), np.zeros(3), np.zeros(3))
    img = sim.frame(own, [image.PointTarget(r * u, v * u, 1.0)])
    window = "hann"
    rd = range_doppler(simulate_adc(CFG, (r * u)[None], (v * u)[None], noise=False), CFG, window, window)
    k_img, j_img = peak(img)
    k_raw, j_raw = peak(rd)
    assert abs(k_raw - k_img) <= 1 and circular_distance(j_raw, j_img, NV) <= 1
    p_img = np.abs(img[k_img, j_img]) ** 2
    # Off-bin targets spread over neighbouring pixels (scalloping); their summed power is the
    # target's power times the windows' noise gain (Parseval). On-bin the peak alone matches.
    block = rd[k_raw - 4 : k_raw + 5].take(np.arange(j_raw - 4, j_raw + 5) % NV, axis=1)
    from skyradar.process.rangedoppler import window_noise_gain_db

    summed_db = 10 * np.log10((np.abs(block) ** 2).sum(axis=(0, 1))) - window_noise_gain_db(window, window)
    assert np.all(np.abs(summed_db - 10 * np.log10(p_img)) < 1.0)
    if abs(frac_k) < 0.02 and abs(frac_j) < 0.02:
        peak_db = 10 * np.log10(np.abs(rd[k_raw, j_raw]) ** 2) - window_gain_db(window, window)
        assert np.all(np.abs(peak_db - 10 * np.log10(p_img)) < 1.0)


def test_raw_chain_matches_image_domain_on_bin_peak_power_and_phase_differences():
    v = 37 * CFG.doppler_resolution_mps
    r = 120 * CFG.range_resolution_m - CFG.range_doppler_coupling_s * v
    az, el = np.radians(12.0), np.radians(-7.0)
    u = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)])
    sim = image.ImageSimulator(CFG, noise=False)
    img = sim.frame(
        image.PlatformState(np.zeros(3), np.zeros(3), np.zeros(3)), [image.PointTarget(r * u, v * u)]
    )
    rd = range_doppler(simulate_adc(CFG, (r * u)[None], (v * u)[None], noise=False), CFG)
    k, j = peak(img)
    assert peak(rd) == (k, j) == (120, 37 + NV // 2)
    ratio_db = 10 * np.log10(np.abs(rd[k, j]) ** 2 / np.abs(img[k, j]) ** 2) - window_gain_db()
    assert np.all(np.abs(ratio_db) < 0.1)
    # DoA information: channel phase differences agree with the image-domain convention.
    d_raw = np.angle(rd[k, j, 1:] * np.conj(rd[k, j, 0]))
    d_img = np.angle(img[k, j, 1:] * np.conj(img[k, j, 0]))
    assert np.allclose(np.angle(np.exp(1j * (d_raw - d_img))), 0.0, atol=np.radians(1.0))


@pytest.mark.parametrize("window", ["hann", "hamming", "blackmanharris", "chebyshev:70"])
def test_off_bin_target_leakage_matches_scipy_window_spectrum(window):
    # A stationary scatterer 0.37 bins off a range bin centre: the range profile through its
    # Doppler bin is the window's spectrum sampled at the bin offsets.
    frac = 0.37
    r = (150 + frac) * CFG.range_resolution_m * (CFG.fs_hz / CFG.samples_per_chirp) / CFG.prf_hz
    rd = range_doppler(simulate_adc(CFG, [[r, 0.0, 0.0]], noise=False), CFG, window, "hann")
    prof = np.abs(rd[:, NV // 2, 0]) ** 2
    m = np.arange(-10, 11)
    name, _, param = window.partition(":")
    spec = ("chebwin", float(param)) if name == "chebyshev" else name
    w = scipy.signal.get_window(spec, CFG.samples_per_chirp)
    n = np.arange(w.size)
    dtft = np.abs(np.exp(-2j * np.pi * np.outer(m - frac, n) / w.size) @ w) ** 2
    got = 10 * np.log10(prof[150 + m] / prof[150])
    expected = 10 * np.log10(dtft / dtft[10])
    assert np.all(np.abs(got - expected) < 1.0), np.c_[got, expected]


def test_receiver_noise_gives_noise_power_per_pixel():
    rd = range_doppler(adc_noise(CFG, seed=5), CFG, "none", "none")
    assert np.mean(np.abs(rd) ** 2) == pytest.approx(CFG.noise_power_w, rel=0.01)
    with_target = simulate_adc(CFG, [[1000.0, 0, 0]], seed=5)
    assert with_target.dtype == np.complex64 and with_target.shape == (CFG.n_rx, NV, CFG.samples_per_chirp)


def test_scatterers_behind_the_antenna_are_silent_and_sum_linearly():
    a = simulate_adc(CFG, [[800.0, 50, 0]], noise=False)
    b = simulate_adc(CFG, [[-800.0, 0, 0]], noise=False)
    both = simulate_adc(CFG, [[800.0, 50, 0], [-800.0, 0, 0], [1600.0, 0, 10]], noise=False)
    c = simulate_adc(CFG, [[1600.0, 0, 10]], noise=False)
    assert not np.any(b)
    assert np.allclose(both, a + c, atol=1e-6 * np.abs(a).max())


def test_bad_input_raises_input_error():
    with pytest.raises(InputError, match="positions_m"):
        simulate_adc(CFG, np.zeros((2, 2)))
    with pytest.raises(InputError, match="velocities_mps"):
        simulate_adc(CFG, np.ones((2, 3)), np.zeros((3, 3)))
    with pytest.raises(InputError, match="non-finite"):
        simulate_adc(CFG, [[np.nan, 0, 0]])
    with pytest.raises(InputError, match="power"):
        simulate_adc(CFG, [[100.0, 0, 0]], power_w=[-1.0])
