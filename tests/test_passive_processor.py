"""ch7 passive processor: each step against a closed form or an independent computation."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal

from skyradar.passive.bistatic import bistatic_range_m, ellipse_point, in_blind_zone, receiver_range_willis
from skyradar.passive.cfar import ca_cfar
from skyradar.passive.matched_filter import lfm_pulse, matched_filter, thesis_test_pulse
from skyradar.passive.mti import cancel_static, difference_weights, doppler_spectrum
from skyradar.passive.profiles import ProfileExtractor
from skyradar.passive.pulses import scan_phase

FS = 20e6


def _echo_is_visible(window: str | None, with_echo: bool = True) -> bool:
    """The thesis' test: is the strongest peak of the filter output in 0.16-0.18 ms the echo's (0.17 ms)?"""
    t, s = thesis_test_pulse(FS)
    if with_echo:
        d = int(round(2e-5 * FS))
        s[d:] += 0.01 * s[:-d].copy()
    y = np.abs(matched_filter(s, lfm_pulse(FS, 1e-4, 5.0e6, -7.0e9), window))
    lo, hi = int(1.6e-4 * FS), int(1.8e-4 * FS)
    peaks, _ = signal.find_peaks(y[lo:hi])
    strongest = lo + peaks[np.argmax(y[lo + peaks])]
    return abs(t[strongest] - 1.7e-4) <= 1e-6


def test_thesis_test_pulse_peaks_mid_pulse_with_and_without_hann():
    t, s = thesis_test_pulse(FS)
    pulse = lfm_pulse(FS, 1e-4, 5.0e6, -7.0e9)
    for window in (None, "hann"):
        y = matched_filter(s, pulse, window)
        assert t[np.argmax(np.abs(y))] == pytest.approx(1.5e-4, abs=1 / FS)


def test_weak_echo_visible_only_with_hann():
    assert _echo_is_visible("hann")
    assert not _echo_is_visible(None)
    assert not _echo_is_visible("hann", with_echo=False)  # the Hann peak there is the echo, not a sidelobe


def test_matched_filter_equals_direct_correlation():
    rng = np.random.default_rng(0)
    x = rng.normal(size=3000) + 1j * rng.normal(size=3000)
    p = lfm_pulse(5e6, 4e-5, -5e5, 2.5e10)
    taps = np.conj(p[::-1]) * signal.windows.hann(p.size, sym=False)
    direct = np.convolve(x, taps, mode="valid")  # numpy's time-domain sum, not an FFT
    np.testing.assert_allclose(matched_filter(x, p, "hann", align="start"), direct, rtol=1e-9, atol=1e-9)


@settings(max_examples=60, deadline=None)
@given(
    east=st.floats(-30e3, 30e3),
    north=st.floats(-30e3, 30e3),
    tx_e=st.floats(-15e3, 15e3),
    tx_n=st.floats(-15e3, 15e3),
)
def test_ellipse_point_inverts_the_bistatic_range_and_matches_willis(east, north, tx_e, tx_n):
    tx, rx, target = np.array([tx_e, tx_n]), np.zeros(2), np.array([east, north])
    baseline = np.hypot(tx_e, tx_n)
    r1, r2 = np.hypot(*(target - tx)), np.hypot(*target)
    if baseline < 1e3 or r1 < 200 or r2 < 200 or r1 + r2 - baseline < 50:
        return  # degenerate: on the baseline (the blind zone) or at a site
    az = np.arctan2(target[0] - tx[0], target[1] - tx[1])
    s = bistatic_range_m(target, tx, rx)
    point, got_r1, got_r2 = ellipse_point(s, az, tx, rx)
    np.testing.assert_allclose(point, target, atol=1e-6 * (r1 + r2))
    # The thesis' receiver-angle form: sin(theta_R) = -unit(target - rx) . unit(tx - rx).
    sin_theta = np.clip(-np.dot(target / r2, tx / baseline), -1.0, 1.0)
    assert receiver_range_willis(s, baseline, np.arcsin(sin_theta)) == pytest.approx(r2, rel=1e-6)
    assert got_r1 == pytest.approx(r1, rel=1e-6) and got_r2 == pytest.approx(r2, rel=1e-6)


def test_blind_zone_is_the_thin_ellipse_and_the_receiver_direction():
    blind = in_blind_zone(
        [100.0, 3000.0, 3000.0], [1.0, 1.0, np.radians(71)], np.radians(70), 500.0, np.radians(4)
    )
    assert blind.tolist() == [True, False, True]


def test_cfar_false_alarm_rate_matches_its_design():
    rng = np.random.default_rng(1)
    power = rng.exponential(1.0, size=(200, 5000))  # square-law detected complex Gaussian noise
    hits, _ = ca_cfar(power, (0, 2), (0, 16), 1e-3)
    rate = hits.mean()
    assert 0.8e-3 < rate < 1.25e-3  # 1e6 cells: 1000 +- 3 sigma (~100) false alarms


def test_divided_difference_cancels_a_beam_swept_reflector_under_stagger():
    """A static echo scaled by the sweeping beam: binomial weights on staggered pulses leak the beam's
    slope times the stagger to PRF/4 and PRF/2; divided differences leave only the curvature near 0 Hz."""
    pri = np.tile([1.000e-3, 1.075e-3, 0.950e-3, 1.025e-3], 5)
    t = np.concatenate([[0.0], np.cumsum(pri)])
    gain = np.exp(-4 * np.log(2) * ((t - t.mean()) / 0.017) ** 2)  # 17 ms beam dwell
    profiles = (gain * np.exp(0.3j))[:, None]
    grid = np.linspace(-490, 490, 99)
    far = np.abs(grid) > 150

    def leak(times):
        cancelled = cancel_static(profiles, "mti3", times_s=times)
        return np.abs(doppler_spectrum(cancelled, t[1:-1], grid)[far, 0]).max()

    assert leak(t) < 0.3 * leak(None)
    w = difference_weights(t, 2)  # nulls constant and linear in time exactly
    np.testing.assert_allclose(w @ np.ones(3), 0, atol=1e-9)
    np.testing.assert_allclose((w * np.stack([t[:-2], t[1:-1], t[2:]], axis=1)).sum(axis=1), 0, atol=1e-9)


def test_doppler_spectrum_peaks_at_the_target_doppler_on_staggered_pulses():
    t = np.cumsum(np.tile([1.000e-3, 1.075e-3, 0.950e-3, 1.025e-3], 5))
    profiles = np.exp(2j * np.pi * 230.0 * t)[:, None]
    grid = np.linspace(-480, 480, 193)
    spec = np.abs(doppler_spectrum(profiles, t, grid)[:, 0])
    assert grid[np.argmax(spec)] == pytest.approx(230.0, abs=5.0)


def test_scan_phase_finds_the_main_beam_crossings():
    pri = np.tile([1.000e-3, 1.075e-3, 0.950e-3, 1.025e-3], 3000)
    t = np.cumsum(pri)
    period, first = 4.4444, 1.2345
    off = np.angle(np.exp(2j * np.pi * (t - first) / period))  # beam angle from the receiver, rad
    amp = np.maximum(np.exp(-4 * np.log(2) * (off / np.radians(1.4)) ** 2), 10 ** (-30 / 20))
    sp = scan_phase(t, amp, 4.0, bearing_rad=1.0)
    assert sp.crossings_s[0] == pytest.approx(first, abs=2e-3)
    assert sp.period_s == pytest.approx(period, rel=1e-3)
    assert float(sp.azimuth_rad(first + period / 4)) == pytest.approx(1.0 + np.pi / 2, abs=2e-3)


def test_profiles_remove_the_direct_path_and_keep_a_weak_echo_at_fractional_delays():
    """Pulses at fractional-sample times (PRF stagger): the direct path is gone to -60 dB, the echo stays."""
    fs, width, bw = 5e6, 40e-6, 1.5e6

    def pulse_at(t):
        inside = (t >= 0) & (t < width)
        return np.where(inside, np.exp(2j * np.pi * (-bw / 2 * t + 0.5 * bw / width * t * t)), 0)

    n = int(width * fs)
    x = np.zeros(60_000, complex)
    n_samples = np.arange(x.size)
    t0s = 1e-3 + np.cumsum(np.tile([1.000e-3, 1.075e-3, 0.950e-3, 1.025e-3], 3))[:10]
    t0s = (np.round(t0s * fs) + np.random.default_rng(2).uniform(0.05, 0.95, t0s.size)) / fs  # off the grid
    echo_delay = 37.3 / fs
    for t0 in t0s:
        x += pulse_at(n_samples / fs - t0) + 1e-3 * pulse_at(n_samples / fs - t0 - echo_delay)
    ex = ProfileExtractor(pulse_at(np.arange(n) / fs), fs, 128, 0.9e-3, pulse_at=pulse_at)
    out = ex.process(0, np.concatenate([np.zeros(ex.front, complex), x]), x.size)
    assert out.profiles.shape[0] == 10
    np.testing.assert_allclose(out.times_s, t0s, atol=1 / fs / 50)
    peak = np.abs(out.profiles).max(axis=0)
    assert np.argmax(peak) == 37  # the echo, 37.3 samples after the direct path
    dp = np.abs(out.amplitude).mean() * np.abs(ex.responses[0]).max()
    residue = peak[:20].max() / dp
    assert residue < 1e-3  # -60 dB; the echo itself is at -60 dB of the direct path + its own lag
