"""Hardware impairments that make simulated frames look like real ones (Maas 2022, ch. 2 and 3).

Real flight data differ from the clean simulation by fixed bright spurs (self-interference) in
every frame, a bright line at zero Doppler over all ranges, returns at all velocities near the
radar (up to about 100 m), per-antenna phase and gain errors and receiver noise; the ground return
is also weaker. Each effect is a plain function on a range-Doppler cube (``(..., n_range,
n_doppler, n_rx)``, pixel units: ``|pixel|^2`` in W); spurs, channel errors and noise also exist for
ADC cubes ``(n_rx, n_chirp, n_sample)``. :class:`ImpairmentConfig` switches them on and sets their
parameters (the ``impairments:`` section of a scenario file, defined in
:mod:`skyradar.scene.impairment_config` and re-exported here); :func:`thesis_flight_look` is the
preset that reproduces the look of the thesis' flight data.

Levels are pixel powers in dBm (the prototype's thermal noise is -155 dBm per pixel, a 1 m^2
aircraft at 1 km about -118 dBm). Fixed patterns (spurs, the zero-Doppler line, channel errors)
depend only on ``seed``; frame-varying ones (near-range leakage, noise) on ``(seed, frame)``.
The weaker ground return is a simulator setting (``ImageSimulator(ground_reflectivity_db=...)``),
carried here as ``ground_reflectivity_db`` for the scenario runner.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.scene.impairment_config import (
    ChannelErrorsConfig,
    ImpairmentConfig,
    NearRangeConfig,
    NoiseConfig,
    Spur,
    SpursConfig,
    ZeroDopplerConfig,
    thesis_flight_look,
)
from skyradar.sim.impairment_signals import (
    apply_channel_errors,
    channel_errors,
    dbm_to_w,
    near_range_leakage,
    receiver_noise,
    spur_adc,
    spur_cube,
    zero_doppler_line,
)

# fmt: off
__all__ = [
    "Spur", "SpursConfig", "ZeroDopplerConfig", "NearRangeConfig", "ChannelErrorsConfig",
    "NoiseConfig", "ImpairmentConfig", "dbm_to_w", "spur_cube", "spur_adc", "zero_doppler_line",
    "near_range_leakage", "channel_errors", "apply_channel_errors", "receiver_noise",
    "apply_impairments", "apply_impairments_frames", "apply_impairments_adc", "thesis_flight_look",
]
# fmt: on


def _channel_gains(imp: ImpairmentConfig, n_rx: int) -> np.ndarray:
    """The per-antenna complex errors of the ``channel_errors`` section (ones when off)."""
    ce = imp.enabled("channel_errors")
    if ce is None:
        return np.ones(n_rx, complex)
    return channel_errors(n_rx, ce.gain_db, ce.phase_deg, ce.gain_sd_db, ce.phase_sd_deg, imp.seed)


def _spur_map(imp: ImpairmentConfig) -> np.ndarray | None:
    s = imp.enabled("spurs")
    if s is None or s.map_file is None:
        return None
    path = Path(s.map_file)
    try:
        return np.load(path, allow_pickle=False).astype(bool)
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: cannot read spur map ({exc})") from None


def _spur_list(s: SpursConfig) -> list[tuple[float, float, float]]:
    return [(p.range_m, p.velocity_mps, p.power_dbm) for p in s.spurs]


def apply_impairments(
    cube: np.ndarray, config: RadarConfig, imp: ImpairmentConfig, frame_index: int = 0
) -> np.ndarray:
    """Apply the enabled impairments to one range-Doppler cube (n_range, n_doppler, n_rx).

    Order: channel errors on the scene, then spurs, zero-Doppler line, near-range leakage (their
    own fixed channel phases), then receiver noise.

    Parameters
    ----------
    cube : ndarray, shape (n_range, n_doppler, n_rx)
        The simulated frame; pixel units ``|pixel|^2`` in W.
    config : RadarConfig
    imp : ImpairmentConfig
        Which impairments, and their parameters.
    frame_index : int
        The frame's index in the run: seeds the frame-varying effects with ``(imp.seed, frame_index)``.

    Returns
    -------
    ndarray, shape (n_range, n_doppler, n_rx), complex64
        A new cube.

    Examples
    --------
    A -120 dBm spur at 600 m and 10 m/s lands on the nearest pixel (599.6 m, 10.0 m/s) with
    that power:

    >>> cfg = RadarConfig.prototype_2022()
    >>> spur = {"range_m": 600, "velocity_mps": 10, "power_dbm": -120}
    >>> imp = ImpairmentConfig.from_dict({"spurs": {"spurs": [spur], "leakage": False}})
    >>> out = apply_impairments(np.zeros((cfg.n_range, cfg.n_doppler, cfg.n_rx)), cfg, imp)
    >>> k, j, _ = np.unravel_index(np.abs(out).argmax(), out.shape)
    >>> round(float(cfg.range_axis_m[k]), 1), round(float(cfg.doppler_axis_mps[j]), 1)
    (599.6, 10.0)
    >>> round(float(10 * np.log10(np.abs(out[k, j, 0]) ** 2) + 30), 3), out.dtype.name
    (-120.0, 'complex64')
    """
    out = np.array(cube, np.complex64)
    if imp.enabled("channel_errors") is not None:
        out = apply_channel_errors(out, _channel_gains(imp, config.n_rx))
    if (s := imp.enabled("spurs")) is not None:
        out += spur_cube(config, _spur_list(s), _spur_map(imp), s.map_power_dbm, s.leakage, imp.seed)
    if (z := imp.enabled("zero_doppler")) is not None:
        out += zero_doppler_line(config, z.power_dbm_at_100m, z.falloff_db_per_decade, z.width_bins, imp.seed)
    rng = np.random.default_rng([imp.seed, 5, int(frame_index)])
    if (nr := imp.enabled("near_range")) is not None:
        out += near_range_leakage(config, nr.power_dbm, nr.range_m, rng)
    if (n := imp.enabled("noise")) is not None:
        out += receiver_noise(config, n.noise_figure_db, rng)
    return out


def apply_impairments_frames(
    iq: np.ndarray, config: RadarConfig, imp: ImpairmentConfig, frame_indices: np.ndarray | None = None
) -> np.ndarray:
    """:func:`apply_impairments` over a (time, n_range, n_doppler, n_rx) block of frames.

    Parameters
    ----------
    iq : ndarray, shape (time, n_range, n_doppler, n_rx)
        The frames; pixel units ``|pixel|^2`` in W.
    config : RadarConfig
    imp : ImpairmentConfig
    frame_indices : ndarray of int, shape (time,), optional
        The frames' indices in the whole run (default 0..n-1), so a chunked run gives the same
        bytes as a single pass.

    Returns
    -------
    ndarray, shape (time, n_range, n_doppler, n_rx), complex64

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> imp = ImpairmentConfig.from_dict({"noise": {}})
    >>> zeros = np.zeros((cfg.n_range, cfg.n_doppler, cfg.n_rx), np.complex64)
    >>> block = apply_impairments_frames(np.stack([zeros, zeros]), cfg, imp, np.array([6, 7]))
    >>> bool(np.array_equal(block[0], apply_impairments(zeros, cfg, imp, 6)))  # frame 6 alone
    True
    >>> bool(np.array_equal(block[0], block[1]))  # new noise each frame
    False
    """
    indices = np.arange(len(iq)) if frame_indices is None else np.asarray(frame_indices)
    return np.stack(
        [apply_impairments(frame, config, imp, int(i)) for frame, i in zip(iq, indices, strict=True)]
    )


def apply_impairments_adc(
    adc: np.ndarray, config: RadarConfig, imp: ImpairmentConfig, frame_index: int = 0
) -> np.ndarray:
    """Apply the ADC-level impairments (channel errors, listed spurs, noise) to one ADC cube.

    The zero-Doppler line, near-range leakage and spur maps are image-level models; apply them
    to the range-Doppler cube with :func:`apply_impairments` (the other sections switched off).

    Parameters
    ----------
    adc : ndarray, shape (n_rx, n_chirp, n_sample)
        The ADC cube.
    config : RadarConfig
    imp : ImpairmentConfig
    frame_index : int
        The frame's index in the run: seeds the noise with ``(imp.seed, frame_index)``.

    Returns
    -------
    ndarray, shape (n_rx, n_chirp, n_sample), complex64
        A new cube.

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> imp = ImpairmentConfig.from_dict({"channel_errors": {"phase_deg": [0, 90, 180, -90]}})
    >>> out = apply_impairments_adc(np.ones((cfg.n_rx, 2, 8), np.complex64), cfg, imp)
    >>> np.round(np.degrees(np.angle(out[:, 0, 0]))).tolist(), out.shape
    ([0.0, 90.0, 180.0, -90.0], (4, 2, 8))
    """
    from skyradar.sim.raw import adc_noise

    out = np.array(adc, np.complex64)
    if imp.enabled("channel_errors") is not None:
        out = apply_channel_errors(out, _channel_gains(imp, config.n_rx), layout="adc")
    if (s := imp.enabled("spurs")) is not None and s.spurs:
        out += spur_adc(config, _spur_list(s), imp.seed)
    if (n := imp.enabled("noise")) is not None:
        noisy = config if n.noise_figure_db is None else config.replace(noise_figure_db=n.noise_figure_db)
        out += adc_noise(noisy, np.random.SeedSequence([imp.seed, 5, int(frame_index)]))
    return out
