"""The simulator's counter-based Gaussian noise against scipy's normal distribution."""

from __future__ import annotations

import numba
import numpy as np
import pytest
from numba import njit
from scipy import stats

from skyradar.sim._noise_kernel import _mix, cis_count_f32, finalize_frame, frame_key, gaussian_noise, log_f32


@pytest.fixture(scope="module")
def samples() -> np.ndarray:
    x = gaussian_noise((1_000_000,), 2.0, frame_key(7, 11))
    return np.concatenate([x.real, x.imag]).astype(float)


def test_components_are_standard_normal(samples):
    assert samples.var() == pytest.approx(1.0, abs=0.005)
    assert abs(samples.mean()) < 0.005
    assert stats.kstest(samples, "norm").pvalue > 1e-3
    # Tails: CFAR false alarms live there.
    for k in (3.0, 4.0):
        expected = 2 * stats.norm.sf(k) * samples.size
        observed = np.count_nonzero(np.abs(samples) > k)
        assert abs(observed - expected) < 5 * np.sqrt(expected)


def test_power_per_pixel_and_independence(samples):
    x = gaussian_noise((500_000,), 3.0, frame_key(1, 2))
    assert np.mean(np.abs(x) ** 2) == pytest.approx(3.0, rel=0.01)
    assert abs(np.corrcoef(x.real, x.imag)[0, 1]) < 0.01
    assert abs(np.corrcoef(samples[:-1], samples[1:])[0, 1]) < 0.005
    other = gaussian_noise((500_000,), 3.0, frame_key(1, 3))  # next frame
    assert abs(np.corrcoef(x.real, other.real)[0, 1]) < 0.01


def test_noise_does_not_depend_on_thread_count():
    blocks = np.zeros((1, 50, 40, 4), np.complex64)
    out = [np.empty((50, 40, 4), np.complex64) for _ in range(2)]
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        finalize_frame(blocks, 1.0, frame_key(0, 5), out[0])
        numba.set_num_threads(before)
        finalize_frame(blocks, 1.0, frame_key(0, 5), out[1])
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(out[0], out[1])


def test_finalize_sums_blocks_and_clears_them():
    rng = np.random.default_rng(0)
    blocks = (rng.standard_normal((3, 10, 8, 4)) + 1j * rng.standard_normal((3, 10, 8, 4))).astype(
        np.complex64
    )
    expected = blocks.sum(axis=0)
    out = np.empty((10, 8, 4), np.complex64)
    finalize_frame(blocks, 0.0, frame_key(0, 0), out)
    np.testing.assert_allclose(out, expected, rtol=1e-5, atol=1e-6)
    assert not blocks.any()


def test_higher_moments_and_rayleigh_radius(samples):
    assert abs(stats.skew(samples)) < 0.01
    assert abs(stats.kurtosis(samples)) < 0.02  # excess kurtosis, SE ~ 0.0035
    x = gaussian_noise((1_000_000,), 2.0, frame_key(3, 4))
    # |x|^2 of a unit-variance-per-component complex Gaussian is exponential with mean 2.
    assert stats.kstest(np.abs(x.astype(complex)) ** 2, "expon", args=(0, 2.0)).pvalue > 1e-3


@njit
def _logs(x, y):
    for i in range(x.size):
        y[i] = log_f32(x[i])


@njit
def _cis(counts, c, s):
    for i in range(counts.size):
        c[i], s[i] = cis_count_f32(counts[i])


def test_polynomial_log_matches_numpy_down_to_the_smallest_uniform():
    # Every uniform Box-Muller can draw near 0 and 1 (the tails and the centre), and a random
    # sample between: error at float32 rounding, so the radius is exact to 5e-7 sigma up to
    # its largest value, 6.66 sigma.
    k = np.concatenate(
        [
            np.arange(100_000),
            np.random.default_rng(0).integers(0, 2**31, 1_000_000),
            2**31 - np.arange(1, 100_000),
        ]
    )
    u = (k.astype(np.float32) + np.float32(0.5)) * np.float32(2.0**-31)
    got = np.empty_like(u)
    _logs(u, got)
    want = np.log(u.astype(float))
    far = u < 0.99
    assert np.max(np.abs(got[far] - want[far]) / np.abs(want[far])) < 3e-7
    assert np.max(np.abs(got[~far] - want[~far])) < 1e-8
    radius = np.sqrt(np.maximum(-2.0 * got.astype(float), 0.0))
    assert np.max(np.abs(radius - np.sqrt(-2.0 * want))) < 5e-7
    assert np.sqrt(-2.0 * want.min()) > 6.6


def test_polynomial_cis_matches_numpy_in_every_quadrant():
    counts = np.concatenate(
        [
            np.arange(0, 2**32, 2**32 // 1_000_000, dtype=np.uint64),
            np.array([0, 2**29 - 1, 2**29, 2**30, 3 * 2**30 - 1, 2**31, 2**32 - 1], np.uint64),
        ]
    )
    c, s = np.empty(counts.size, np.float32), np.empty(counts.size, np.float32)
    _cis(counts, c, s)
    angle = 2 * np.pi * counts.astype(float) / 2.0**32
    assert np.max(np.abs(c - np.cos(angle))) < 2e-7
    assert np.max(np.abs(s - np.sin(angle))) < 2e-7


def test_neighbouring_pixels_and_frames_are_uncorrelated():
    n = 500_000
    a = gaussian_noise((n,), 2.0, frame_key(5, 0))
    b = gaussian_noise((n,), 2.0, frame_key(5, 1))
    c = gaussian_noise((n,), 2.0, frame_key(6, 0))  # other seed, same frame index
    limit = 5 / np.sqrt(n)  # 5 standard errors of a correlation of independent samples
    for x, y in (
        (a.real[:-1], a.real[1:]),
        (a.imag[:-1], a.imag[1:]),
        (a.real[:-1], a.imag[1:]),
        (a.real, b.real),
        (a.imag, b.imag),
        (a.real, c.real),
        (np.abs(a[:-1]), np.abs(a[1:])),  # the radius of neighbours too, not only the phase
    ):
        assert abs(np.corrcoef(x, y)[0, 1]) < limit


def test_pixel_noise_does_not_depend_on_chunking():
    # A pixel's value is a function of (key, index) only: a shorter frame cuts the chunks at
    # other places, so this also checks the vectorised and the scalar remainder loops agree.
    key = frame_key(2, 9)
    long = gaussian_noise((10_007,), 1.0, key)
    for n in (1, 63, 64, 65, 1000, 4099):
        np.testing.assert_array_equal(gaussian_noise((n,), 1.0, key), long[:n])


@pytest.mark.parametrize("threads", [1, 2])
def test_frame_noise_is_identical_for_any_thread_count(threads):
    if threads > numba.config.NUMBA_NUM_THREADS:
        pytest.skip("machine has fewer threads")
    before = numba.get_num_threads()
    out = np.empty((333, 250, 4), np.complex64)
    try:
        numba.set_num_threads(threads)
        finalize_frame(np.empty((0, 333, 250, 4), np.complex64), 1.0, frame_key(4, 2), out)
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(out.reshape(-1), gaussian_noise((333 * 250 * 4,), 2.0, frame_key(4, 2)))


def test_frame_key_is_splitmix_of_seed_and_index():
    for seed, index in ((0, 0), (1, 0), (0, 1), (2**32 - 1, 2**32 - 1), (12345, 678)):
        z = (((seed << 32) | index) * 0x9E3779B97F4A7C15 + 0x9E3779B97F4A7C15) % 2**64
        assert frame_key(seed, index) == _mix(np.uint64(z))
    assert len({int(frame_key(s, i)) for s in range(20) for i in range(500)}) == 10_000
