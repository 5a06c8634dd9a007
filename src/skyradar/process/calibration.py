"""Per-antenna phase and gain calibration from a reflector at a known position.

Cables, connectors and fabrication give every receive channel its own complex gain ``g_k``; the
measured pixel is ``true_k * g_k`` and processing divides by ``RadarConfig.rx_calibration``. A
reflector at a known antenna-frame position ``p`` gives the true pixel up to one complex factor:
``true_k = A exp(i 2 pi (|p - tx| + |p - rx_k|) / lambda)`` (exact two-way path, no far-field
approximation). So ``g_k / g_0`` is the ratio of measured to predicted pixel, averaged over frames
with weights ``|x_0|`` (a matched combiner). Only relative gains are observable: the result has
``c_0`` real and the RMS of ``|c_k|`` equal to one.

Examples
--------
>>> from skyradar.config import RadarConfig
>>> cfg = RadarConfig.prototype_2022()
>>> p = reflector_position(438.0, np.radians(5.0), np.radians(-1.0))
>>> offsets = np.exp(1j * np.radians([0.0, 40.0, -70.0, 120.0]))
>>> pixels = (expected_pixels(p, cfg) * offsets)[None, :]
>>> cal = estimate_rx_calibration(pixels, p, cfg)
>>> round(calibration_phase_error_deg(cal, offsets), 6)
0.0
"""

from __future__ import annotations

import numpy as np

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.process.detect import integrate_channels
from skyradar.process.doa import angles_from_direction, direction_from_angles

__all__ = [
    "reflector_position",
    "expected_pixels",
    "in_field_of_view",
    "estimate_rx_calibration",
    "calibrate_from_frames",
    "calibration_phase_error_deg",
]


def reflector_position(range_m: float, azimuth_rad: float, elevation_rad: float) -> np.ndarray:
    """Antenna-frame position (3,) of a point at range, azimuth (right +) and elevation (up +).

    Parameters
    ----------
    range_m : float
        Distance from the antenna, m.
    azimuth_rad : float
        Azimuth, rad, positive to the right.
    elevation_rad : float
        Elevation, rad, positive up.

    Returns
    -------
    ndarray, shape (3,)
        Position (x boresight, y right, z down), m.

    Examples
    --------
    >>> reflector_position(100.0, 0.0, np.radians(30.0)).round(3).tolist()  # 30 deg up: z is negative
    [86.603, 0.0, -50.0]
    """
    return float(range_m) * direction_from_angles(azimuth_rad, elevation_rad)


def expected_pixels(position_m: np.ndarray, config: RadarConfig) -> np.ndarray:
    """Unit-amplitude pixels ``exp(i 2 pi (|p - tx| + |p - rx_k|) / lambda)`` per receiver, (n_rx,).

    Parameters
    ----------
    position_m : ndarray, shape (3,)
        Scatterer position in the antenna frame, m.
    config : RadarConfig
        Transmit and receive antenna positions (m) and wavelength (m).

    Returns
    -------
    ndarray, shape (n_rx,), complex
        Predicted pixel of every receiver for an ideal (uncalibrated gain 1) radar.

    Examples
    --------
    On the boresight of the symmetric 2x2 square every receiver sees the same path:

    >>> from skyradar.config import RadarConfig
    >>> z = expected_pixels(np.array([100.0, 0.0, 0.0]), RadarConfig.prototype_2022())
    >>> np.round(np.abs(z), 6).tolist(), bool(np.allclose(z, z[0]))
    ([1.0, 1.0, 1.0, 1.0], True)
    """
    p = np.asarray(position_m, float)
    path = np.linalg.norm(p - config.tx_position_m) + np.linalg.norm(p - config.rx_positions_m, axis=1)
    return np.exp(1j * 2.0 * np.pi * np.mod(path / config.wavelength_m, 1.0))


def in_field_of_view(
    azimuth_rad: np.ndarray | float,
    elevation_rad: np.ndarray | float,
    config: RadarConfig,
    max_loss_db: float = 6.0,
) -> np.ndarray:
    """True where the one-way antenna gain is within ``max_loss_db`` of its peak (and in front).

    Parameters
    ----------
    azimuth_rad, elevation_rad : array_like
        Direction in the antenna frame, rad (azimuth right +, elevation up +).
    config : RadarConfig
        Its ``antenna`` pattern gives the gain.
    max_loss_db : float
        Largest one-way loss from the peak gain still inside the field of view, dB.

    Returns
    -------
    ndarray of bool
        Broadcast shape of the two angles.

    Examples
    --------
    The prototype's field of view reaches 49.5 deg off boresight:

    >>> from skyradar.config import RadarConfig
    >>> in_field_of_view(np.radians([0.0, 30.0, 60.0]), 0.0, RadarConfig.prototype_2022()).tolist()
    [True, True, False]
    """
    az, el = np.asarray(azimuth_rad, float), np.asarray(elevation_rad, float)
    loss = config.antenna.peak_db - config.antenna.gain_db(az, el)
    return (np.abs(az) < np.pi / 2) & (np.abs(el) < np.pi / 2) & (loss <= max_loss_db)


def _check_fov(position_m: np.ndarray, config: RadarConfig, max_loss_db: float) -> None:
    az, el = angles_from_direction(np.asarray(position_m, float))
    if not bool(in_field_of_view(az, el, config, max_loss_db)):
        raise InputError(
            f"calibration: field 'reflector' at azimuth {np.degrees(az):.1f} deg, elevation "
            f"{np.degrees(el):.1f} deg is outside the field of view "
            f"(gain more than {max_loss_db:g} dB below peak)"
        )


def estimate_rx_calibration(
    pixels: np.ndarray,
    position_m: np.ndarray,
    config: RadarConfig,
    gain: bool = True,
    max_loss_db: float = 6.0,
) -> np.ndarray:
    """Relative complex gain of every receive channel from raw reflector pixels.

    Parameters
    ----------
    pixels : ndarray, shape (n_frames, n_rx) or (n_rx,), complex
        Raw (uncalibrated) peak pixel of the reflector in each frame.
    position_m : ndarray, shape (3,)
        Reflector position in the antenna frame, m.
    config : RadarConfig
        Antenna positions (m), wavelength (m) and antenna pattern (the reflector must be in the field
        of view).
    gain : bool
        Estimate amplitudes too; False gives unit-magnitude (phase-only) factors.
    max_loss_db : float
        Largest one-way antenna loss from peak, dB, at the reflector direction; beyond it InputError.

    Returns
    -------
    ndarray, shape (n_rx,), complex
        Value for ``config.replace(rx_calibration=...)``: ``c_0`` real, RMS of ``|c_k|`` one.

    Examples
    --------
    >>> from skyradar.config import RadarConfig
    >>> cfg = RadarConfig.prototype_2022()
    >>> p = reflector_position(438.0, np.radians(5.0), np.radians(-1.0))
    >>> offsets = np.array([1.0, 2.0j, -1.0, 1.0])  # gains 1, 2, 1, 1 and phases 0, 90, 180, 0 deg
    >>> cal = estimate_rx_calibration(expected_pixels(p, cfg) * offsets, p, cfg)
    >>> np.round(cal * np.sqrt(7.0 / 4.0), 6).tolist()  # offsets scaled to unit RMS magnitude
    [(1+0j), 2j, (-1+0j), (1+0j)]
    """
    x = np.atleast_2d(np.asarray(pixels, complex))
    if x.shape[1] != config.n_rx:
        raise InputError(f"calibration: field 'rx' has {x.shape[1]} channels, radar_config has {config.n_rx}")
    if x.shape[0] == 0 or not np.all(np.isfinite(x)) or np.any(np.abs(x) == 0):
        raise InputError("calibration: field 'pixels' is empty, zero or not finite")
    _check_fov(position_m, config, max_loss_db)
    ratio = x / expected_pixels(position_m, config)  # g_k * A_m (common per frame)
    ref = ratio[:, :1]
    rel = np.sum(ratio * np.conj(ref), axis=0) / np.sum(np.abs(ref) ** 2)  # g_k / g_0
    if not gain:
        return np.exp(1j * np.angle(rel))
    return rel / np.sqrt(np.mean(np.abs(rel) ** 2))


def calibrate_from_frames(
    frames: np.ndarray,
    position_m: np.ndarray,
    config: RadarConfig,
    radial_velocity_mps: float = 0.0,
    search_bins: tuple[int, int] = (2, 2),
    gain: bool = True,
) -> RadarConfig:
    """Calibrate on a reflector seen in one or more raw frames; returns the calibrated config.

    The reflector's pixel is the brightest one within ``search_bins`` (range, Doppler) of the bin
    its position and radial velocity predict, found on the channel-integrated image.

    Parameters
    ----------
    frames : ndarray, shape (n_frames, n_range, n_doppler, n_rx) or (n_range, n_doppler, n_rx)
        Raw frames.
    position_m : ndarray, shape (3,)
        Reflector position in the antenna frame, m.
    config : RadarConfig
        Radar the frames come from; its axes give the predicted bin.
    radial_velocity_mps : float
        Reflector radial velocity, m/s (positive receding); 0 for a fixed reflector.
    search_bins : (int, int)
        Half-width of the search window in (range, Doppler) bins.
    gain : bool
        Estimate amplitudes too; False gives unit-magnitude (phase-only) factors.

    Returns
    -------
    RadarConfig
        ``config`` with ``rx_calibration`` from :func:`estimate_rx_calibration`.

    Examples
    --------
    One frame with the reflector in its predicted pixel and per-channel phase offsets:

    >>> from skyradar.config import RadarConfig
    >>> cfg = RadarConfig.prototype_2022()
    >>> p = reflector_position(438.0, np.radians(5.0), np.radians(-1.0))
    >>> offsets = np.exp(1j * np.radians([0.0, 40.0, -70.0, 120.0]))
    >>> frame = np.zeros((cfg.n_range, cfg.n_doppler, cfg.n_rx), complex)
    >>> frame[cfg.range_bin(438.0), cfg.doppler_bin(0.0)] = 10.0 * expected_pixels(p, cfg) * offsets
    >>> calibrated = calibrate_from_frames(frame, p, cfg)
    >>> np.round(np.degrees(np.angle(calibrated.rx_calibration)), 3).tolist()
    [0.0, 40.0, -70.0, 120.0]
    """
    cube = np.asarray(frames)
    cube = cube[None] if cube.ndim == 3 else cube
    if cube.ndim != 4 or cube.shape[0] == 0:
        raise InputError(
            f"calibration: field 'frames' must be (time, range, doppler, rx), got shape {cube.shape}"
        )
    if cube.shape[1:] != (config.n_range, config.n_doppler, config.n_rx):
        raise InputError(
            f"calibration: frame shape {cube.shape[1:]} does not match radar_config "
            f"{(config.n_range, config.n_doppler, config.n_rx)}"
        )
    _check_fov(position_m, config, 6.0)
    rng_m = float(np.linalg.norm(position_m)) + radial_velocity_mps * config.range_doppler_coupling_s
    r0 = int(config.range_bin(rng_m))
    if not 0 <= r0 < config.n_range:
        raise InputError(f"calibration: field 'reflector' range {rng_m:.0f} m is beyond the processed range")
    d0 = int(config.doppler_bin(radial_velocity_mps))
    rows = np.arange(max(r0 - search_bins[0], 0), min(r0 + search_bins[0] + 1, config.n_range))
    cols = np.arange(d0 - search_bins[1], d0 + search_bins[1] + 1) % config.n_doppler
    pixels = np.empty((cube.shape[0], config.n_rx), complex)
    for i, frame in enumerate(cube):
        window = frame[np.ix_(rows, cols)]
        power = integrate_channels(window)
        r, d = np.unravel_index(int(np.argmax(power)), power.shape)
        pixels[i] = window[r, d]
    return config.replace(rx_calibration=estimate_rx_calibration(pixels, position_m, config, gain=gain))


def calibration_phase_error_deg(estimated: np.ndarray, true: np.ndarray) -> float:
    """RMS phase error over channels between two calibrations after removing their common phase, deg.

    Parameters
    ----------
    estimated, true : ndarray, shape (n_rx,), complex
        The two calibrations; their magnitudes do not matter.

    Returns
    -------
    float
        RMS phase difference, deg, after the best common phase rotation.

    Examples
    --------
    Phase errors of 0, 10, 0 and -10 deg give ``sqrt(200 / 4)``; a common phase is free:

    >>> round(calibration_phase_error_deg(np.exp(1j * np.radians([0.0, 10.0, 0.0, -10.0])), np.ones(4)), 4)
    7.0711
    >>> round(calibration_phase_error_deg(np.full(4, 1j), np.ones(4)), 6)
    0.0
    """
    diff = np.asarray(estimated, complex) * np.conj(np.asarray(true, complex))
    common = np.angle(np.sum(diff / np.abs(diff)))
    return float(np.degrees(np.sqrt(np.mean(np.angle(diff * np.exp(-1j * common)) ** 2))))
