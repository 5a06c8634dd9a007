"""The simulator's counter-based Gaussian noise against scipy's normal distribution."""

from __future__ import annotations

import numba
import numpy as np
import pytest
from scipy import stats

from skyradar.sim._noise_kernel import finalize_frame, frame_key, gaussian_noise


@pytest.fixture(scope="module")
def samples() -> np.ndarray:
    x = gaussian_noise((1_000_000,), 2.0, frame_key(7, 11))
    return np.concatenate([x.real, x.imag]).astype(float)


def test_components_are_standard_normal(samples):
    assert samples.var() == pytest.approx(1.0, abs=0.005)
    assert abs(samples.mean()) < 0.005
    assert stats.kstest(samples, "norm").pvalue > 1e-3
    # Tails: the ziggurat's tail strip must be right, CFAR false alarms live there.
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
