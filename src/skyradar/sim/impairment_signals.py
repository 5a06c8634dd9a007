"""The impairment effects themselves: plain functions on range-Doppler and ADC cubes.

See :mod:`skyradar.sim.impairments` for what each one models, the units, and how a scenario
switches them on.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from skyradar.config import BOLTZMANN, RadarConfig
from skyradar.errors import InputError

__all__ = [
    "dbm_to_w",
    "spur_cube",
    "spur_adc",
    "zero_doppler_line",
    "near_range_leakage",
    "channel_errors",
    "apply_channel_errors",
    "receiver_noise",
]


def dbm_to_w(power_dbm: float | np.ndarray) -> float | np.ndarray:
    """Power in dBm to W.

    Parameters
    ----------
    power_dbm : float or ndarray
        Power, dBm.

    Returns
    -------
    float or ndarray
        Power, W: ``10 ** ((P_dBm - 30) / 10)``.

    Examples
    --------
    >>> dbm_to_w(30.0), dbm_to_w(np.array([0.0, -120.0])).tolist()
    (np.float64(1.0), [0.001, 1e-15])
    """
    return 10.0 ** ((np.asarray(power_dbm, float) - 30.0) / 10.0)


def _phasors(rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    return np.exp(2j * np.pi * rng.random(shape))


# ---- spurs --------------------------------------------------------------------------------------
def _spur_pixels(config, spurs, spur_map, map_power_dbm) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rows, cols, power = [], [], []
    for r_m, v_mps, p_dbm in spurs:
        k = int(config.range_bin(r_m))
        if not 0 <= k < config.n_range:
            raise InputError(f"impairments.spurs: range_m {r_m} is outside 0..{config.range_limit_m} m")
        rows.append(k)
        cols.append(int(config.doppler_bin(v_mps)))
        power.append(dbm_to_w(p_dbm))
    if spur_map is not None:
        spur_map = np.asarray(spur_map, bool)
        if spur_map.shape != (config.n_range, config.n_doppler):
            expected = (config.n_range, config.n_doppler)
            raise InputError(f"impairments.spurs: spur map shape {spur_map.shape}, expected {expected}")
        map_k, map_j = np.nonzero(spur_map)
        rows += list(map_k)
        cols += list(map_j)
        power += [dbm_to_w(map_power_dbm)] * map_k.size
    return np.array(rows, int), np.array(cols, int), np.array(power, float)


def spur_cube(
    config: RadarConfig,
    spurs: Sequence[tuple[float, float, float]] = (),
    spur_map: np.ndarray | None = None,
    map_power_dbm: float = -130.0,
    leakage: bool = True,
    seed: int = 0,
) -> np.ndarray:
    """Fixed spurs as an additive (n_range, n_doppler, n_rx) complex64 cube, the same every frame.

    Parameters
    ----------
    config : RadarConfig
    spurs : list of (range_m, velocity_mps, power_dbm)
        Spur positions (nearest pixel; velocity wraps) and pixel powers.
    spur_map : ndarray of bool, shape (n_range, n_doppler), optional
        A measured spur map (e.g. from the ch3 spur learner); every True pixel is a spur.
    map_power_dbm : float
        Power of the spur-map pixels.
    leakage : bool
        Add the Hann main-lobe neighbours (amplitude -1/2 per bin step in each axis), exactly what
        an on-bin tone in the ADC shows after the default Hann windows.
    seed : int
        Fixes each spur's phase per channel.

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> cube = spur_cube(cfg, [(600.0, 10.0, -120.0)], leakage=False)
    >>> k, j, _ = np.unravel_index(np.abs(cube).argmax(), cube.shape)
    >>> round(float(cfg.range_axis_m[k])), round(float(cfg.doppler_axis_mps[j]), 1)
    (600, 10.0)
    """
    rows, cols, power = _spur_pixels(config, spurs, spur_map, map_power_dbm)
    cube = np.zeros((config.n_range, config.n_doppler, config.n_rx), np.complex128)
    if rows.size == 0:
        return cube.astype(np.complex64)
    values = np.sqrt(power)[:, None] * _phasors(np.random.default_rng([seed, 1]), (rows.size, config.n_rx))
    taps = [(0, 0, 1.0)]
    if leakage:
        taps += [
            (dk, dj, (-0.5) ** (abs(dk) + abs(dj))) for dk in (-1, 0, 1) for dj in (-1, 0, 1) if dk or dj
        ]
    for dk, dj, gain in taps:
        k = rows + dk
        ok = (k >= 0) & (k < config.n_range)
        np.add.at(cube, (k[ok], (cols[ok] + dj) % config.n_doppler), gain * values[ok])
    return cube.astype(np.complex64)


def spur_adc(config: RadarConfig, spurs: list[tuple[float, float, float]], seed: int = 0) -> np.ndarray:
    """Spurs as ADC tones, (n_rx, n_doppler, samples_per_chirp) complex64.

    Each spur is a tone on its pixel's beat and Doppler frequency with amplitude sqrt(P): after
    :func:`~skyradar.process.rangedoppler.range_doppler` its pixel power is ``P`` times the windows'
    coherent gain, like a target's.

    Parameters
    ----------
    config : RadarConfig
    spurs : list of (range_m, velocity_mps, power_dbm)
        Spur positions (m, m/s; nearest pixel, velocity wraps) and pixel powers (dBm).
    seed : int
        Fixes each spur's phase per channel, as in :func:`spur_cube` with the same seed.

    Returns
    -------
    ndarray, shape (n_rx, n_doppler, samples_per_chirp), complex64

    Examples
    --------
    A -120 dBm spur at 600 m and 10 m/s: every sample has amplitude sqrt(1e-15 W); the fast-time
    FFT peaks at the range bin (600 m / 15 m = 40) and the shifted slow-time FFT at the Doppler bin:

    >>> cfg = RadarConfig.prototype_2022()
    >>> adc = spur_adc(cfg, [(600.0, 10.0, -120.0)])
    >>> adc.shape, bool(np.allclose(np.abs(adc), np.sqrt(1e-15)))
    ((4, 250, 2032), True)
    >>> k = int(np.abs(np.fft.fft(adc[0, 0])).argmax())
    >>> j = int(np.abs(np.fft.fftshift(np.fft.fft(adc[0, :, 0]))).argmax())
    >>> k, j == int(cfg.doppler_bin(10.0))
    (40, True)
    """
    rows, cols, power = _spur_pixels(config, spurs, None, 0.0)
    values = np.sqrt(power)[:, None] * _phasors(np.random.default_rng([seed, 1]), (rows.size, config.n_rx))
    t = np.arange(config.samples_per_chirp) / config.fs_hz
    n = np.arange(config.n_doppler)
    adc = np.zeros((config.n_rx, config.n_doppler, t.size), np.complex128)
    bin_hz = config.fs_hz / config.samples_per_chirp
    for k, j, val in zip(rows, cols, values, strict=True):
        slow = np.exp(2j * np.pi * (j - config.n_doppler // 2) * n / config.n_doppler)
        fast = np.exp(2j * np.pi * k * bin_hz * t)
        adc += val[:, None, None] * (slow[:, None] * fast[None, :])[None]
    return adc.astype(np.complex64)


# ---- zero-Doppler line and near-range leakage ---------------------------------------------------
def zero_doppler_line(
    config: RadarConfig,
    power_dbm_at_100m: float = -115.0,
    falloff_db_per_decade: float = 20.0,
    width_bins: int = 1,
    seed: int = 0,
) -> np.ndarray:
    """Bright line at V = 0 over all ranges, power falling with range; fixed (n_range, n_doppler, n_rx).

    Pixel power ``P(R) = P_100 - falloff * log10(max(R, dR) / 100 m)`` dB on the zero-Doppler bin.

    Parameters
    ----------
    config : RadarConfig
    power_dbm_at_100m : float
        ``P_100``, the pixel power at 100 m, dBm.
    falloff_db_per_decade : float
        ``falloff``, dB per decade of range.
    width_bins : int
        Above 1, the line spreads over that many Doppler bins (each neighbour 6 dB down per bin).
    seed : int
        Fixes the pixels' phases.

    Returns
    -------
    ndarray, shape (n_range, n_doppler, n_rx), complex64

    Examples
    --------
    Bins 7 and 67 are 104.9 m and 1004.3 m out: -115 - 20 log10(R / 100 m) dBm.

    >>> cfg = RadarConfig.prototype_2022()
    >>> line = zero_doppler_line(cfg)
    >>> j0 = int(cfg.doppler_bin(0.0))
    >>> np.round(10 * np.log10(np.abs(line[[7, 67], j0, 0]) ** 2) + 30, 1).tolist()
    [-115.4, -135.0]
    >>> int(np.count_nonzero(np.abs(line).sum(axis=(0, 2))))  # one Doppler bin
    1
    """
    cube = np.zeros((config.n_range, config.n_doppler, config.n_rx), np.complex64)
    r = np.maximum(config.range_axis_m, config.range_resolution_m)
    p_dbm = power_dbm_at_100m - falloff_db_per_decade * np.log10(r / 100.0)
    amp = np.sqrt(dbm_to_w(p_dbm))
    rng = np.random.default_rng([seed, 2])
    centre = int(config.doppler_bin(0.0))
    for offset in range(-(int(width_bins) // 2), int(width_bins) // 2 + 1):
        phase = _phasors(rng, (config.n_range, config.n_rx))
        cube[:, (centre + offset) % config.n_doppler, :] = (0.5 ** abs(offset)) * amp[:, None] * phase
    return cube


def near_range_leakage(
    config: RadarConfig,
    power_dbm: float = -110.0,
    range_m: float = 100.0,
    rng: np.random.Generator | None = None,
) -> np.ndarray:
    """Returns at all velocities near the radar: (n_range, n_doppler, n_rx) complex64, new each frame.

    One random pattern per frame, coupled into every channel with a fixed phase (a single
    leakage source).

    Parameters
    ----------
    config : RadarConfig
    power_dbm : float
        Mean pixel power at zero range, dBm; complex Gaussian pixels, falling linearly in dB to
        30 dB down at ``range_m``.
    range_m : float
        Range of the leakage, m; absent beyond.
    rng : numpy.random.Generator, optional
        The frame's random stream (default: a fresh, unseeded one).

    Returns
    -------
    ndarray, shape (n_range, n_doppler, n_rx), complex64

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()  # 15 m range bins
    >>> cube = near_range_leakage(cfg, -110.0, 100.0, np.random.default_rng(0))
    >>> np.flatnonzero(np.abs(cube).sum(axis=(1, 2))).tolist()  # bins 0..6: up to 90 m
    [0, 1, 2, 3, 4, 5, 6]
    >>> round(float(10 * np.log10(np.mean(np.abs(cube[0]) ** 2)) + 30))  # mean power at 0 m, dBm
    -110
    """
    rng = rng or np.random.default_rng()
    r = config.range_axis_m
    inside = np.flatnonzero(r <= range_m)
    cube = np.zeros((config.n_range, config.n_doppler, config.n_rx), np.complex64)
    if inside.size == 0:
        return cube
    amp = np.sqrt(dbm_to_w(power_dbm - 30.0 * r[inside] / range_m))
    field = rng.standard_normal((inside.size, config.n_doppler)) + 1j * rng.standard_normal(
        (inside.size, config.n_doppler)
    )
    channel = _phasors(np.random.default_rng([0, 3]), (config.n_rx,))
    cube[inside] = (amp[:, None] * field / np.sqrt(2.0))[..., None] * channel
    return cube


# ---- channel errors and noise -------------------------------------------------------------------
def channel_errors(
    n_rx: int,
    gain_db: list[float] | None = None,
    phase_deg: list[float] | None = None,
    gain_sd_db: float = 0.0,
    phase_sd_deg: float = 0.0,
    seed: int = 0,
) -> np.ndarray:
    """Per-antenna complex gain errors ``10**(g/20) * exp(1j * phi)``, channel 0 the reference.

    Given values are used as they are; otherwise drawn from N(0, sd) with ``seed`` (channel 0 gets
    0 dB and 0 deg). A measured channel is ``true * errors[k]``; dividing by the same values (as
    ``RadarConfig.rx_calibration``) undoes it.

    Examples
    --------
    >>> g = channel_errors(4, phase_deg=[0, 10, -5, 30])
    >>> np.round(np.degrees(np.angle(g)), 6).tolist()
    [0.0, 10.0, -5.0, 30.0]
    """
    rng = np.random.default_rng([seed, 4])
    g = np.asarray(gain_db, float) if gain_db is not None else np.r_[0.0, rng.normal(0, gain_sd_db, n_rx - 1)]
    p = (
        np.asarray(phase_deg, float)
        if phase_deg is not None
        else np.r_[0.0, rng.normal(0, phase_sd_deg, n_rx - 1)]
    )
    if g.shape != (n_rx,) or p.shape != (n_rx,):
        raise InputError(
            f"impairments.channel_errors: need {n_rx} gains and phases, got {g.size} and {p.size}"
        )
    return 10.0 ** (g / 20.0) * np.exp(1j * np.radians(p))


def apply_channel_errors(data: np.ndarray, errors: np.ndarray, layout: str = "rd") -> np.ndarray:
    """Multiply each channel by its error: rx is the last axis (``'rd'``) or axis -3 (``'adc'``).

    Parameters
    ----------
    data : ndarray
        Range-Doppler (..., n_range, n_doppler, n_rx) or ADC (..., n_rx, n_chirp, n_sample) cube.
    errors : ndarray, shape (n_rx,)
        Complex gain per channel (:func:`channel_errors`).
    layout : {"rd", "adc"}
        Where the channel axis is.

    Returns
    -------
    ndarray
        The cube times the errors (a new array).

    Examples
    --------
    >>> e = channel_errors(4, gain_db=[0, 6, 0, 0], phase_deg=[0, 0, 90, 0])
    >>> rd = apply_channel_errors(np.ones((2, 3, 4), np.complex64), e)
    >>> np.round(np.abs(rd[0, 0]), 3).tolist(), np.round(np.degrees(np.angle(rd[0, 0]))).tolist()
    ([1.0, 1.995, 1.0, 1.0], [0.0, 0.0, 90.0, 0.0])
    >>> adc = apply_channel_errors(np.ones((4, 3, 5), np.complex64), e, layout="adc")
    >>> np.round(np.abs(adc[:, 0, 0]), 3).tolist()
    [1.0, 1.995, 1.0, 1.0]
    """
    e = np.asarray(errors, np.complex64)
    return data * (e if layout == "rd" else e[:, None, None])


def receiver_noise(
    config: RadarConfig, noise_figure_db: float | None = None, rng: np.random.Generator | None = None
) -> np.ndarray:
    """Thermal receiver noise per range-Doppler pixel, k T (PRF/nV) F; (n_range, n_doppler, n_rx).

    Parameters
    ----------
    config : RadarConfig
    noise_figure_db : float, optional
        Receiver noise figure F, dB (default: the radar's).
    rng : numpy.random.Generator, optional
        The frame's random stream (default: a fresh, unseeded one).

    Returns
    -------
    ndarray, shape (n_range, n_doppler, n_rx), complex64
        Circular complex Gaussian noise of mean power ``k T (PRF/nV) F`` per pixel, W.

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> noise = receiver_noise(cfg, rng=np.random.default_rng(0))
    >>> noise.shape, round(float(np.mean(np.abs(noise) ** 2) / cfg.noise_power_w), 2)
    ((333, 250, 4), 1.0)
    >>> louder = receiver_noise(cfg, cfg.noise_figure_db + 3.0, np.random.default_rng(0))
    >>> round(float(np.mean(np.abs(louder) ** 2) / np.mean(np.abs(noise) ** 2)), 2)  # 3 dB more
    2.0
    """
    nf = config.noise_figure_db if noise_figure_db is None else noise_figure_db
    power = BOLTZMANN * config.temperature_k * config.noise_bandwidth_hz * 10 ** (nf / 10.0)
    rng = rng or np.random.default_rng()
    shape = (config.n_range, config.n_doppler, config.n_rx, 2)
    return (rng.standard_normal(shape, dtype=np.float32) * np.float32(np.sqrt(power / 2))).view(np.complex64)[
        ..., 0
    ]
