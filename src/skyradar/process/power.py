"""The receiver-integrated power image of a range-Doppler frame: one function, one normalisation.

``power_image(cube, c)[i, j] = (1 / L) * sum_k |cube[i, j, k] / c_k|^2`` (W) over the ``L`` receive
channels: the non-coherent MEAN, not the sum. Thermal noise therefore keeps its single-channel mean
``RadarConfig.noise_power_w`` per pixel and follows a Gamma(L, 1/L) law (the CFAR factors of
:mod:`skyradar.process.cfar` are exact for it); a point target of per-channel power ``S`` reads ``S``.
Callers that want the channel SUM (the flight-state ridge fits a Gamma(L, 1) noise floor) multiply by ``L``.

Examples
--------
>>> from skyradar.config import RadarConfig
>>> cfg = RadarConfig.prototype_2022()
>>> rng = np.random.default_rng(0)
>>> shape = (cfg.n_range, cfg.n_doppler, cfg.n_rx)
>>> noise = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)) * np.sqrt(cfg.noise_power_w / 2)
>>> round(float(power_image(noise).mean() / cfg.noise_power_w), 2)
1.0
"""

from __future__ import annotations

import numpy as np
from numba import njit

from skyradar.errors import InputError

__all__ = ["power_image"]


@njit(cache=True, fastmath=True)
def _weighted_square_sum(iq: np.ndarray, weight: np.ndarray, out: np.ndarray) -> np.ndarray:
    # iq: (n_range, n_doppler, 2 n_rx) real view of the complex cube (re, im interleaved);
    # the accumulator has the dtype of ``weight`` and ``out`` (float32 or float64).
    n_r, n_d, n_k = iq.shape
    zero = weight[0] - weight[0]  # a zero of weight's dtype (``* 0`` would promote float32 to float64)
    for i in range(n_r):
        for j in range(n_d):
            acc = zero
            for k in range(n_k):
                v = iq[i, j, k]
                acc += v * v * weight[k]
            out[i, j] = acc
    return out


def power_image(cube: np.ndarray, calibration: np.ndarray | None = None, dtype=np.float32) -> np.ndarray:
    """Mean over receive channels of ``|x_k / c_k|^2``, W, shape (n_range, n_doppler).

    Parameters
    ----------
    cube : ndarray, shape (n_range, n_doppler, n_rx), complex
        One range-Doppler frame.
    calibration : ndarray, shape (n_rx,), complex, optional
        Per-channel complex gains the signal is divided by (``RadarConfig.rx_calibration``).
    dtype : numpy float dtype
        float32 (default: the detection chain's precision) or float64; the sum is accumulated in it.

    Returns
    -------
    ndarray, shape (n_range, n_doppler)
        Noise-only pixels average ``noise_power_w`` (the per-channel noise power), whatever ``n_rx``.

    Examples
    --------
    >>> power_image(np.full((2, 3, 4), 1 + 1j, np.complex64)).tolist()[0]
    [2.0, 2.0, 2.0]
    """
    cube = np.asarray(cube)
    if cube.ndim != 3:
        raise InputError(f"frame: expected (range, doppler, rx) array, got shape {cube.shape}")
    n_rx = cube.shape[2]
    gain = np.ones(n_rx) if calibration is None else np.asarray(calibration)
    if gain.shape != (n_rx,):
        raise InputError(f"frame: field 'rx' has {n_rx} channels, calibration has {gain.shape[0]}")
    real = np.dtype(dtype)
    if real not in (np.float32, np.float64):
        raise ValueError(f"dtype must be float32 or float64, got {real}")
    weight = np.repeat(1.0 / (np.abs(gain) ** 2 * n_rx), 2).astype(real)
    iq = np.ascontiguousarray(cube, dtype=np.result_type(real, np.complex64)).view(real)
    return _weighted_square_sum(iq, weight, np.empty(cube.shape[:2], real))
