"""Chirp-level simulation of the de-chirped (beat) signal: the ADC cube of one frame.

A sawtooth FMCW radar transmits chirps of slope ``S = B * PRF`` (one chirp per repetition
interval). Mixing the echo of a scatterer at two-way delay ``tau`` with the transmitted chirp
leaves, at fast time ``t`` within chirp ``n``,

    IF(t, n) = sum_i a_i exp(+1j * 2*pi * (fc*tau_i + S*tau_i*t - S*tau_i^2/2)),

with ``tau_i = (|p_i - tx| + |p_i - rx_k|) / c`` evaluated at the exact time of every sample
(chirp start ``n / PRF`` plus ``t = m / Fs``). Nothing else is modelled by hand: the beat
frequency ``2*S*R/c`` (range), the chirp-to-chirp phase step ``2v/lambda / PRF`` (Doppler, with its
aliasing), the intra-chirp Doppler that shifts the beat frequency by ``2v/lambda`` (range-Doppler
coupling, 0.19 m per m/s for the prototype), range migration within the frame and the per-antenna
phase all follow from the delays.

Time-division MIMO. With ``config.n_tx`` transmitters, chirp ``n`` is sent by transmitter
``n mod n_tx``: its delays use that transmitter's position at that chirp's sample times. The
scatterers keep moving between the slots, so a moving target's phase advances by
``2 pi (2 v / lambda) / PRF`` from one transmitter's chirp to the next one's on top of the
transmitters' geometric phase difference; :mod:`skyradar.process.mimo` removes that advance.

Units. ``|a_i|^2`` is the received power in W from the radar equation with the two-way gain of
``config.antenna`` (the image-domain simulator's equation), so after
:func:`skyradar.process.rangedoppler.range_doppler` an on-bin target has the image-domain pixel
value times the windows' coherent gain. Receiver noise is complex white Gaussian with power
``k T F * Fs_eff`` per sample, ``Fs_eff = Ns * nV * noise_bandwidth = Ns * PRF``, which gives
exactly ``config.noise_power_w`` per range-Doppler pixel without windows.

Time reference. Positions are given at ``t_ref_s`` after the first sample of the frame; by
default the frame centre, which is where a moving target's range bin lands after the FFTs.
"""

from __future__ import annotations

import numba
import numpy as np

from skyradar.config import SPEED_OF_LIGHT, RadarConfig
from skyradar.errors import InputError
from skyradar.geo import direction_angles

__all__ = ["received_power_w", "adc_noise", "simulate_adc"]


def received_power_w(config: RadarConfig, positions_m: np.ndarray, rcs_m2: np.ndarray | float) -> np.ndarray:
    """Received power of point scatterers from the radar equation, W.

    ``Pr = Pe * G(az, el)^2 * sigma * lambda^2 / ((4 pi)^3 R^4)`` with ``R`` half the mean two-way
    path over the receivers (and the transmitters, for MIMO) and ``G`` the one-way gain of
    ``config.antenna``; zero for scatterers on or behind the antenna plane (x <= 0 in the antenna
    frame).

    Parameters
    ----------
    config : RadarConfig
    positions_m : ndarray, shape (n, 3)
        Antenna-frame positions, m.
    rcs_m2 : float or ndarray, shape (n,)
        Radar cross-section (for terrain: facet area times reflectivity), m^2.

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> p = received_power_w(cfg, np.array([[1000.0, 0, 0]]), 1.0)
    >>> round(float(10 * np.log10(p[0] / cfg.noise_power_w)), 1)  # single-pixel SNR, dB
    30.6
    """
    p = np.asarray(positions_m, float).reshape(-1, 3)
    rcs = np.broadcast_to(np.asarray(rcs_m2, float), p.shape[:1])
    if config.n_tx == 1:
        r_tx = np.linalg.norm(p - config.tx_position_m, axis=1)
    else:
        r_tx = np.linalg.norm(p[:, None, :] - config.transmitters_m[None], axis=2).mean(axis=1)
    r_rx = np.linalg.norm(p[:, None, :] - config.rx_positions_m[None], axis=2).mean(axis=1)
    r = (r_tx + r_rx) / 2.0
    _, az, el = direction_angles(p)
    gain2 = 10.0 ** (config.antenna.gain_db(az, el) / 5.0)
    power = config.pe_w * gain2 * rcs * config.wavelength_m**2 / ((4 * np.pi) ** 3 * np.maximum(r, 1e-3) ** 4)
    return np.where(p[:, 0] > 0, power, 0.0)


def adc_noise(config: RadarConfig, seed: int | np.random.SeedSequence | None = None) -> np.ndarray:
    """Receiver noise at the ADC, (n_rx, n_doppler, samples_per_chirp) complex64.

    Power per sample ``noise_power_w * Ns * nV / n_tx`` (``k T F`` times ``Ns * PRF``), so an
    unwindowed range-Doppler pixel (of one transmitter's ``nV / n_tx`` chirps) carries
    ``config.noise_power_w``.

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> n = adc_noise(cfg, seed=1)
    >>> n.shape, bool(abs(np.mean(abs(n) ** 2) / (cfg.noise_power_w * n.shape[1] * n.shape[2]) - 1) < 0.01)
    ((4, 250, 2032), True)
    """
    shape = (config.n_rx, config.n_doppler, config.samples_per_chirp)
    sigma = np.sqrt(config.noise_power_w * config.n_doppler_per_tx * shape[2] / 2.0)
    rng = np.random.default_rng(seed)
    pair = rng.standard_normal((*shape, 2), dtype=np.float32) * np.float32(sigma)
    return pair.view(np.complex64)[..., 0]


@numba.njit(parallel=True, cache=True)
def _beat_kernel(out, pos, vel, amp, tx, rx, fc, slope, fs, prf, t_ref, c):  # pragma: no cover - compiled
    n_rx, n_chirp, n_s = out.shape
    n_scat = pos.shape[0]
    two_pi = 2.0 * np.pi
    n_tx = tx.shape[0]
    for n in numba.prange(n_chirp):
        t_n = n / prf - t_ref
        slot = n % n_tx  # time-division MIMO: chirp n is sent by transmitter n mod n_tx
        tx0, tx1, tx2 = tx[slot, 0], tx[slot, 1], tx[slot, 2]
        for i in range(n_scat):
            vx, vy, vz = vel[i, 0], vel[i, 1], vel[i, 2]
            px, py, pz = pos[i, 0] + vx * t_n, pos[i, 1] + vy * t_n, pos[i, 2] + vz * t_n
            v2 = vx * vx + vy * vy + vz * vz
            # |p(t) - a|^2 = d.d + 2 d.v t + v.v t^2 for constant velocity: exact per sample.
            dx, dy, dz = px - tx0, py - tx1, pz - tx2
            a_tx, b_tx = dx * dx + dy * dy + dz * dz, 2.0 * (dx * vx + dy * vy + dz * vz)
            for k in range(n_rx):
                ex, ey, ez = px - rx[k, 0], py - rx[k, 1], pz - rx[k, 2]
                a_rx, b_rx = ex * ex + ey * ey + ez * ez, 2.0 * (ex * vx + ey * vy + ez * vz)
                for m in range(n_s):
                    t = m / fs
                    tau = (np.sqrt(a_tx + (b_tx + v2 * t) * t) + np.sqrt(a_rx + (b_rx + v2 * t) * t)) / c
                    cyc = fc * tau + slope * tau * (t - 0.5 * tau)
                    ph = two_pi * (cyc - np.floor(cyc))
                    out[k, n, m] += amp[i] * complex(np.cos(ph), np.sin(ph))


def _as_points(name: str, values: np.ndarray | None, n: int | None) -> np.ndarray:
    arr = np.zeros((n or 0, 3)) if values is None else np.asarray(values, float)
    arr = arr.reshape(-1, 3) if arr.ndim == 1 and arr.size == 3 else arr
    if arr.ndim != 2 or arr.shape[1] != 3 or (n is not None and arr.shape[0] != n):
        got = arr.shape if values is None else np.shape(values)
        raise InputError(f"raw simulation: {name} must have shape (n, 3), got {got}")
    if not np.all(np.isfinite(arr)):
        raise InputError(f"raw simulation: {name} has non-finite values")
    return arr


def _beat_signal(config: RadarConfig, pos, vel, power, t_ref: float, chunk: int) -> np.ndarray:
    """Sum of the scatterers' beat signals (complex128, noise-free), ``chunk`` scatterers per call."""
    shape = (config.n_rx, config.n_doppler, config.samples_per_chirp)
    acc = np.zeros(shape, np.complex128)
    keep = np.flatnonzero(power > 0)
    amp = np.sqrt(power)
    for start in range(0, keep.size, max(1, int(chunk))):
        sel = keep[start : start + chunk]
        _beat_kernel(
            acc,
            np.ascontiguousarray(pos[sel]),
            np.ascontiguousarray(vel[sel]),
            amp[sel],
            np.ascontiguousarray(config.transmitters_m),
            config.rx_positions_m,
            config.fc_hz,
            config.chirp_slope_hz_per_s,
            config.fs_hz,
            config.prf_hz,
            t_ref,
            SPEED_OF_LIGHT,
        )
    return acc


def simulate_adc(
    config: RadarConfig,
    positions_m: np.ndarray,
    velocities_mps: np.ndarray | None = None,
    rcs_m2: np.ndarray | float = 1.0,
    *,
    power_w: np.ndarray | None = None,
    noise: bool = True,
    seed: int | np.random.SeedSequence | None = None,
    t_ref_s: float | None = None,
    chunk: int = 256,
) -> np.ndarray:
    """ADC cube of one frame, (n_rx, n_doppler, samples_per_chirp) complex64.

    For a time-division MIMO radar chirp ``n`` comes from transmitter ``n mod n_tx`` (module
    docstring); :func:`skyradar.process.mimo.virtual_range_doppler` sorts the chirps into virtual
    channels.

    Parameters
    ----------
    config : RadarConfig
        Carrier, sweep, sampling, antennas, noise figure.
    positions_m : ndarray, shape (n, 3)
        Scatterer positions in the antenna frame at time ``t_ref_s``, m.
    velocities_mps : ndarray, shape (n, 3), optional
        Scatterer velocities relative to the radar, in the antenna frame, m/s (default 0).
    rcs_m2 : float or ndarray, shape (n,)
        Radar cross-section, m^2 (terrain facets: area times reflectivity).
    power_w : ndarray, shape (n,), optional
        Received power per scatterer, W, instead of the radar equation (e.g. with occlusion or
        reflectivity computed elsewhere).
    noise : bool
        Add receiver noise (:func:`adc_noise`).
    seed : int, optional
        Noise seed.
    t_ref_s : float, optional
        Time of ``positions_m`` after the frame's first sample, s; default the frame centre.
    chunk : int
        Scatterers per compiled call (bounds the time between interrupt checks; memory is the
        output cube only).

    Examples
    --------
    >>> from skyradar.process.rangedoppler import range_doppler
    >>> cfg = RadarConfig.prototype_2022()
    >>> adc = simulate_adc(cfg, [[1500.0, 0, 0]], [[-20.0, 0, 0]], noise=False)
    >>> rd = range_doppler(adc, cfg)
    >>> k, j = np.unravel_index(np.abs(rd[..., 0]).argmax(), rd.shape[:2])
    >>> round(float(cfg.range_axis_m[k])), round(float(cfg.doppler_axis_mps[j]), 1)
    (1499, -20.0)
    """
    pos = _as_points("positions_m", positions_m, None)
    vel = _as_points("velocities_mps", velocities_mps, pos.shape[0])
    if power_w is None:
        power = received_power_w(config, pos, rcs_m2)
    else:
        power = np.broadcast_to(np.asarray(power_w, float), pos.shape[:1])
    if not np.all(np.isfinite(power)) or np.any(power < 0):
        raise InputError("raw simulation: received power must be finite and >= 0")
    t_ref = config.frame_duration_s / 2.0 if t_ref_s is None else float(t_ref_s)
    adc = _beat_signal(config, pos, vel, power, t_ref, chunk).astype(np.complex64)
    if noise:
        adc += adc_noise(config, seed)
    return adc
