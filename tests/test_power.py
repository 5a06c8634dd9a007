"""The one receiver-integrated power image (process.power) and its normalisation."""

import numpy as np
import pytest

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.nav.ridge import summed_power_image
from skyradar.process.detect import integrate_channels
from skyradar.process.power import power_image

CFG = RadarConfig.prototype_2022()


def _noise(n_rx, rng, shape=(200, 250)):
    s = (*shape, n_rx)
    return (rng.standard_normal(s) + 1j * rng.standard_normal(s)) * np.sqrt(CFG.noise_power_w / 2)


@pytest.mark.parametrize("n_rx", [1, 4, 7])
def test_noise_only_frame_averages_noise_power_w_whatever_n_rx(n_rx):
    p = power_image(_noise(n_rx, np.random.default_rng(n_rx)), dtype=np.float64)
    # 50 000 pixels, each a mean of n_rx exponentials: the mean is within ~5 standard errors.
    assert abs(p.mean() / CFG.noise_power_w - 1.0) < 5 / np.sqrt(p.size * n_rx)
    assert abs(p.var() / CFG.noise_power_w**2 - 1.0 / n_rx) < 0.05 / n_rx  # Gamma(L, 1/L) variance 1/L


def test_equals_numpy_channel_mean_with_calibration():
    rng = np.random.default_rng(2)
    cube = _noise(4, rng).astype(np.complex64)
    gains = np.exp(1j * rng.uniform(0, 2 * np.pi, 4)) * rng.uniform(0.5, 2.0, 4)
    ref = np.mean(np.abs(cube.astype(np.complex128) / gains) ** 2, axis=-1)
    np.testing.assert_allclose(power_image(cube, gains), ref, rtol=2e-6)
    np.testing.assert_allclose(power_image(cube, gains, dtype=np.float64), ref, rtol=1e-12)
    assert power_image(cube).dtype == np.float32 and integrate_channels is power_image


def test_ridge_sum_is_n_rx_times_the_mean():
    cube = _noise(4, np.random.default_rng(3))
    ref = np.sum(cube.real**2 + cube.imag**2, axis=-1)
    np.testing.assert_allclose(summed_power_image(cube), ref, rtol=1e-14)


def test_bad_shapes_are_input_errors():
    with pytest.raises(InputError, match="calibration has 3"):
        power_image(np.zeros((2, 2, 4), np.complex64), np.ones(3))
    with pytest.raises(InputError, match="expected"):
        power_image(np.zeros((2, 2), np.complex64))
