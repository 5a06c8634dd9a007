"""Time-division MIMO: the ADC cube's interleaved chirps to virtual channels, and their slot phase.

A radar with ``n_tx`` transmitters sends chirp ``n`` of a frame from transmitter ``t = n mod n_tx``
(:mod:`skyradar.config`). Sorting the chirps by transmitter gives each transmitter a slow time of
``nD = n_doppler / n_tx`` chirps spaced ``T = n_tx / PRF``; the range-Doppler transform of each,
channel by receiver, gives the virtual cube ``(n_range, nD, n_tx * n_rx)`` whose channel
``t * n_rx + r`` is the pair (transmitter ``t``, receiver ``r``) at ``tx_t + rx_r``
(:attr:`~skyradar.config.RadarConfig.virtual_positions_m`). Its axes are the MIMO config's
``range_axis_m`` and ``doppler_axis_mps`` (``nD`` bins of ``PRF * lambda / (2 n_doppler)``).

Slot phase. Transmitter ``t`` chirps ``t / PRF`` after transmitter 0, so a target of radial
velocity ``v`` has advanced its two-way phase by ``2 pi f_d t / PRF`` (``f_d = 2 v / lambda``) in
transmitter ``t``'s channels besides the direction's phase. Left in, it reads as a direction
shift along the transmitters' baseline (an angle bias that grows with ``|v|``). It is removed with
the Doppler bin's velocity ``v_hat`` (:func:`compensate_slot_phase`).

Ambiguity. The Doppler axis only spans ``[-VLim, VLim)`` with ``VLim = PRF * lambda / (4 n_tx)``:
the true velocity is ``v_hat + 2 m VLim`` for an integer ``m``, and the compensation then leaves
the phase ``2 pi m t / n_tx`` on slot ``t``, the same for every ``m`` of one residue mod ``n_tx``.
:func:`virtual_pixels` tries the ``n_tx`` residues and keeps the one whose pixels one plane wave
from inside the antenna's field of view (the cone within 6 dB of peak gain,
:func:`skyradar.process.doa.field_of_view_rad`) explains best: the beamformer peak
``max_u |z . conj(s(u))|^2`` over that cone. A wrong residue mimics a direction shifted by
``lambda m / (n_tx d)`` in direction cosine along a transmitter spacing ``d``; it loses where that
direction lies outside the cone (for ``mimo-2x4`` see :mod:`skyradar.rx_layouts`). The chosen
residue also extends the unambiguous velocity to ``[-n_tx VLim, n_tx VLim)``, the
one-transmitter ``PRF * lambda / 4``. The margin is small for arrays with a short transmitter
baseline: a wrong residue's best direction sits on the cone's edge, inside the broad beam of two
rows, so for ``mimo-2x4`` the winning peak beats the other by 1.5-18 % (``peak_ratio``
1.015-1.18 at 5-10 deg above or below the horizontal, azimuth within 20 deg); noise of comparable
size, a low SNR or a direction near the cone's edge makes the choice unreliable, and a ratio within
0.5 % of 1 means both residues fit. The track's range rate over several frames is then the other
witness: the runner-up residue's pixels are kept (``VirtualPixels.other_pixels``), the detections
table carries the position their direction gives (``other_*_m``), and the 3-D tracker takes it
where the track's de-aliased radial velocity ``v`` says that residue,
``round((v - v_hat) / 2 VLim) mod n_tx`` (:class:`skyradar.track.doa_feed.Measure3D`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.process.doa import direction_coherence, estimate_directions, field_of_view_rad
from skyradar.process.rangedoppler import range_doppler
from skyradar.process.windows import WindowSpec

__all__ = [
    "VirtualPixels",
    "split_chirps",
    "virtual_range_doppler",
    "slot_phase",
    "compensate_slot_phase",
    "virtual_pixels",
    "compensate_projector",
    "residue_shifts",
    "DetectionDirections",
    "plain_directions",
]


def _check_adc(adc: np.ndarray, config: RadarConfig) -> None:
    if np.ndim(adc) != 3 or np.shape(adc)[:2] != (config.n_rx, config.n_doppler):
        raise InputError(
            f"adc: expected a (rx, chirp, sample) cube of {config.n_rx} receivers and {config.n_doppler} "
            f"chirps, got shape {np.shape(adc)}"
        )


def split_chirps(adc: np.ndarray, config: RadarConfig) -> np.ndarray:
    """Interleaved ADC cube to one slow time per transmitter.

    Parameters
    ----------
    adc : ndarray, shape (n_rx, n_doppler, n_samples)
        One frame, chirp ``n`` from transmitter ``n mod n_tx``.
    config : RadarConfig
        The MIMO radar.

    Returns
    -------
    ndarray, shape (n_tx * n_rx, n_doppler_per_tx, n_samples)
        Channel ``t * n_rx + r``, slow index ``j`` = chirp ``t + j * n_tx`` of receiver ``r`` (a view
        when the input is contiguous).

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022(rx_positions_m="mimo-2x4", n_doppler=4)
    >>> adc = np.arange(4)[None, :, None] * np.ones((4, 4, 1))
    >>> split_chirps(adc, cfg)[[0, 4], :, 0].tolist()  # receiver 0 with transmitter 0, then 1
    [[0.0, 2.0], [1.0, 3.0]]
    """
    _check_adc(adc, config)
    a = np.asarray(adc)
    n_tx, n_rx, n_s = config.n_tx, config.n_rx, a.shape[2]
    per_tx = a.reshape(n_rx, config.n_doppler_per_tx, n_tx, n_s).transpose(2, 0, 1, 3)
    return per_tx.reshape(n_tx * n_rx, config.n_doppler_per_tx, n_s)


@lru_cache(maxsize=8)
def _slot_config(config: RadarConfig) -> RadarConfig:
    """One transmitter's radar: the receivers, calibration and range axis of ``config``, its slow time."""
    return config.replace(tx_positions_m=None, n_doppler=config.n_doppler_per_tx)


def virtual_range_doppler(
    adc: np.ndarray,
    config: RadarConfig,
    range_window: WindowSpec = "hann",
    doppler_window: WindowSpec = "hann",
    remove_dc: bool = False,
    workers: int = 2,
) -> np.ndarray:
    """Virtual range-Doppler cube of one interleaved ADC cube (slot phase still in).

    Parameters
    ----------
    adc : ndarray, shape (n_rx, n_doppler, n_samples)
        One frame, chirp ``n`` from transmitter ``n mod n_tx``.
    config : RadarConfig
        The MIMO radar (one transmitter gives :func:`skyradar.process.rangedoppler.range_doppler`'s cube).
    range_window, doppler_window, remove_dc, workers
        As :func:`skyradar.process.rangedoppler.range_doppler`; the Doppler window spans one
        transmitter's ``n_doppler_per_tx`` chirps.

    Returns
    -------
    ndarray, shape (n_range, n_doppler_per_tx, n_tx * n_rx), complex64
        Channel ``t * n_rx + r``, each divided by receiver ``r``'s calibration gain; axes
        ``config.range_axis_m`` and ``config.doppler_axis_mps``.

    Examples
    --------
    A static target in range bin 10 whose transmitter-1 chirps arrive 1 rad later than
    transmitter 0's: zero Doppler is bin ``125 // 2 = 62`` of each transmitter's 125 chirps, and
    the virtual channels 4-7 carry the extra radian:

    >>> cfg = RadarConfig.prototype_2022(rx_positions_m="mimo-2x4")
    >>> t, n = np.arange(cfg.samples_per_chirp) / cfg.fs_hz, np.arange(cfg.n_doppler)
    >>> slot = np.array([1.0, np.exp(1j)])[n % 2]
    >>> adc = np.exp(2j * np.pi * 10 * cfg.prf_hz * t) * slot[:, None] * np.ones((cfg.n_rx, 1, 1))
    >>> rd = virtual_range_doppler(adc, cfg, range_window="none", doppler_window="none")
    >>> rd.shape, [int(i) for i in np.unravel_index(np.abs(rd[..., 0]).argmax(), rd.shape[:2])]
    ((333, 125, 8), [10, 62])
    >>> round(float(np.angle(rd[10, 62, 4] * np.conj(rd[10, 62, 0]))), 4)
    1.0
    """
    _check_adc(adc, config)
    if config.n_tx == 1:
        return range_doppler(adc, config, range_window, doppler_window, remove_dc, workers=workers)
    slot_cfg = _slot_config(config)
    n_tx, n_rx = config.n_tx, config.n_rx
    out = np.empty((config.n_range, config.n_doppler_per_tx, n_tx * n_rx), np.complex64)
    a = np.asarray(adc)
    for t in range(n_tx):
        out[..., t * n_rx : (t + 1) * n_rx] = range_doppler(
            a[:, t::n_tx, :], slot_cfg, range_window, doppler_window, remove_dc, workers=workers
        )
    return out


def slot_phase(radial_velocity_mps: np.ndarray | float, config: RadarConfig) -> np.ndarray:
    """Phase factor ``exp(i 2 pi (2 v / lambda) t / PRF)`` of each virtual channel, shape (..., n_virtual).

    Channel ``t * n_rx + r`` gets transmitter ``t``'s factor: the two-way phase a target of radial
    velocity ``v`` (m/s, positive receding) gains over the ``t / PRF`` s between transmitter 0's
    chirp and transmitter ``t``'s.

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022(rx_positions_m="mimo-2x4")
    >>> ph = slot_phase(cfg.v_lim_mps, cfg)  # at the limit: pi per transmitter chirp, pi / 2 per slot
    >>> np.round(np.angle(ph[[0, 4]]) / np.pi, 6).tolist()
    [0.0, 0.5]
    """
    v = np.asarray(radial_velocity_mps, float)[..., None]
    slots = np.repeat(np.arange(config.n_tx), config.n_rx)
    return np.exp(2j * np.pi * (2.0 * v / config.wavelength_m) * slots / config.prf_hz)


def compensate_slot_phase(rd: np.ndarray, config: RadarConfig) -> np.ndarray:
    """Virtual cube with each Doppler bin's slot phase removed (the bin's aliased velocity), complex64.

    Parameters
    ----------
    rd : ndarray, shape (n_range, n_doppler_per_tx, n_virtual)
        From :func:`virtual_range_doppler`.
    config : RadarConfig
        The MIMO radar.

    Returns
    -------
    ndarray, same shape
        ``rd * conj(slot_phase(doppler_axis_mps))``; exact for velocities on the axis
        ``[-VLim, VLim)``, the residue ``2 pi m t / n_tx`` beyond (module docstring).

    Examples
    --------
    A cube holding, in every Doppler bin, exactly that bin's slot phase comes out all ones:

    >>> cfg = RadarConfig.prototype_2022(rx_positions_m="mimo-2x4")
    >>> rd = slot_phase(cfg.doppler_axis_mps, cfg)[None] * np.ones((3, 1, 1))  # 3 range bins
    >>> out = compensate_slot_phase(rd, cfg)
    >>> out.shape, out.dtype, bool(np.allclose(out, 1.0, atol=1e-6))
    ((3, 125, 8), dtype('complex64'), True)
    """
    if np.shape(rd)[1:] != (config.n_doppler_per_tx, config.n_virtual):
        raise InputError(
            f"rd: expected (range, {config.n_doppler_per_tx} Doppler bins, {config.n_virtual} virtual "
            f"channels), got shape {np.shape(rd)}"
        )
    factor = np.conj(slot_phase(config.doppler_axis_mps, config)).astype(np.complex64)
    return (np.asarray(rd) * factor[None]).astype(np.complex64, copy=False)


@dataclass(frozen=True)
class VirtualPixels:
    """Pixels with the slot phase removed and the residue of the velocity ambiguity chosen.

    Attributes
    ----------
    pixels : ndarray, shape (n, n_virtual), complex
        Ready for :func:`skyradar.process.doa.estimate_directions` with the MIMO config.
    residue : ndarray, shape (n,), int
        The chosen ``m mod n_tx`` (0: the Doppler axis' velocity is the true one).
    radial_velocity_mps : ndarray, shape (n,)
        The velocity of the chosen residue within ``[-n_tx VLim, n_tx VLim)``, m/s.
    peak_ratio : ndarray, shape (n,)
        Beamformer peak of the chosen residue over the best other one (>= 1; inf for one
        transmitter): how clearly the field of view tells the residues apart.
    other_pixels : ndarray, shape (n, n_virtual), complex
        The pixels of that best other residue (the chosen ones again for one transmitter): where
        both fit, a track's range rate tells which was right.
    other_residue : ndarray, shape (n,), int
        Its residue (-1 for one transmitter).
    phasors, other_phasors : ndarray, shape (n, n_virtual), complex
        The unit phasors each residue multiplies the input pixels by (``pixels = phasors * z``):
        what turns a projector of the input pixels into one of the compensated pixels
        (:func:`compensate_projector`).

    Examples
    --------
    A target in Doppler bin 40 whose true velocity is one alias period ``2 VLim`` higher: the
    residue 1 is chosen, the velocity unfolded and the pixels are the plain steering vector:

    >>> from skyradar.process.doa import direction_from_angles, steering_vector
    >>> cfg = RadarConfig.prototype_2022(rx_positions_m="mimo-2x4")
    >>> v = float(cfg.radial_velocity_at_bin_mps(40)) + 2.0 * cfg.v_lim_mps
    >>> s = steering_vector(direction_from_angles(0.2, -0.1), cfg)
    >>> out = virtual_pixels((s * slot_phase(v, cfg))[None], 40, cfg)
    >>> out.residue.tolist(), round(float(out.radial_velocity_mps[0]), 3), round(v, 3)
    ([1], 32.245, 32.245)
    >>> bool(np.allclose(out.pixels[0], s)), bool(out.peak_ratio[0] > 1.0)
    (True, True)
    """

    pixels: np.ndarray
    residue: np.ndarray
    radial_velocity_mps: np.ndarray
    peak_ratio: np.ndarray
    other_pixels: np.ndarray
    other_residue: np.ndarray
    phasors: np.ndarray
    other_phasors: np.ndarray


@lru_cache(maxsize=8)
def _fov_match(config: RadarConfig, facing: tuple[float, float, float]) -> np.ndarray:
    """Conjugate virtual steering vectors (n_virtual, n_grid) of directions inside the field of view."""
    positions = config.virtual_positions_m - config.virtual_positions_m.mean(axis=0)
    aperture = max(float(np.linalg.norm(positions, axis=1).max()), 1e-12)
    # Step: the phase across the aperture moves by at most pi/8 between neighbours.
    step = min(0.05, config.wavelength_m / (16.0 * aperture))
    n = int(4.0 * np.pi / step**2)
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n  # Fibonacci sphere: near-uniform directions
    phi = np.pi * (1.0 + 5**0.5) * i
    u = np.stack([np.sqrt(1 - z * z) * np.cos(phi), np.sqrt(1 - z * z) * np.sin(phi), z], axis=1)
    u = u[u @ np.asarray(facing) >= np.cos(field_of_view_rad(config))]
    return np.ascontiguousarray(np.exp(1j * (2.0 * np.pi / config.wavelength_m) * (u @ positions.T)).T)


def _projected_peaks(z: np.ndarray, proj: np.ndarray, phasors: np.ndarray, match: np.ndarray) -> np.ndarray:
    """Peak over the field of view of the projected matched filter ``|s^H P_m z_m|^2 / (s^H P_m s)``
    per detection and residue (n, n_tx), ``z_m = d_m * z`` and ``P_m = D_m P D_m^H`` with ``D_m =
    diag(d_m)``: ``s^H P_m z_m = (d_m * P z) . conj(s)`` and ``s^H P_m s = a^H P a`` with
    ``a = conj(d_m) * s``. A direction the projector took (``a^H P a`` below 1e-9 of ``|a|^2``)
    scores 0; elsewhere the score is at most ``|P z|^2`` (Cauchy-Schwarz)."""
    peaks = np.zeros(phasors.shape[:2])
    if not match.shape[1]:
        return peaks
    n_channels = match.shape[0]
    for i in range(len(z)):
        b = phasors[i][:, :, None] * match[None]  # (n_tx, n_virtual, n_grid): conj(a) per residue
        y = proj[i] @ z[i]
        num = np.abs(np.einsum("tkg,k->tg", b, y)) ** 2
        den = np.einsum("tkg,tkg->tg", b, np.einsum("kl,tlg->tkg", proj[i], np.conj(b))).real
        seen = den > 1e-9 * n_channels
        peaks[i] = np.where(seen, num / np.where(seen, den, 1.0), 0.0).max(axis=1)
    return peaks


def virtual_pixels(
    pixels: np.ndarray,
    doppler_bin: np.ndarray | int,
    config: RadarConfig,
    facing: tuple[float, float, float] = (1.0, 0.0, 0.0),
    proj: np.ndarray | None = None,
) -> VirtualPixels:
    """Slot phase removed and velocity ambiguity resolved for detections of the virtual cube.

    Parameters
    ----------
    pixels : ndarray, shape (n, n_virtual), complex
        Detections' pixels of :func:`virtual_range_doppler` (calibrated, slot phase still in).
    doppler_bin : int or ndarray, shape (n,)
        Their Doppler bins (``config.doppler_axis_mps``; fractional bins are allowed).
    config : RadarConfig
        The MIMO radar.
    facing : (float, float, float)
        Centre of the field of view in the antenna frame (the boresight by default).
    proj : ndarray, shape (n, n_virtual, n_virtual), complex, optional
        Each pixel's clutter projector or whitening (Hermitian, of the input pixels, slot phase
        in; :func:`skyradar.process.clutter_frames.detect_suppressed`): the residues are then
        told apart by the projected matched filter's peak in the field of view instead of the
        beamformer's, so that the clutter a cell's nulls take out does not choose for the target.

    Returns
    -------
    VirtualPixels
        Compensated pixels, residue, unambiguous velocity (m/s) and peak ratio (module docstring).

    Examples
    --------
    >>> from skyradar.process.doa import direction_from_angles, steering_vector
    >>> cfg = RadarConfig.prototype_2022(rx_positions_m="mimo-2x4")
    >>> v = 1.5 * cfg.v_lim_mps  # aliased onto -0.5 VLim
    >>> z = steering_vector(direction_from_angles(0.2, -0.1), cfg) * slot_phase(v, cfg)
    >>> out = virtual_pixels(z[None], cfg.doppler_bin(v), cfg)
    >>> out.residue.tolist(), round(float(out.radial_velocity_mps[0] / cfg.v_lim_mps), 3)
    ([1], 1.5)

    Through a projector that leaves the channels alone the choice is the same:

    >>> virtual_pixels(z[None], cfg.doppler_bin(v), cfg, proj=np.eye(8)[None]).residue.tolist()
    [1]
    """
    z = np.atleast_2d(np.asarray(pixels))
    if z.ndim != 2 or z.shape[1] != config.n_virtual:
        raise InputError(
            f"mimo: pixels have {z.shape[-1]} channels, the radar has {config.n_virtual} virtual"
        )
    if proj is not None and np.shape(proj) != (z.shape[0], config.n_virtual, config.n_virtual):
        raise InputError(f"mimo: proj has shape {np.shape(proj)}, expected one square matrix per pixel")
    bins = np.broadcast_to(np.asarray(doppler_bin, float), z.shape[:1])
    v_hat = np.asarray(config.radial_velocity_at_bin_mps(bins), float)
    base = np.conj(slot_phase(v_hat, config))
    n_tx = config.n_tx
    if n_tx == 1:
        n = z.shape[0]
        return VirtualPixels(
            base * z, np.zeros(n, int), v_hat, np.full(n, np.inf), base * z, np.full(n, -1), base, base
        )
    fx, fy, fz = (float(f) for f in np.asarray(facing, float) / np.linalg.norm(facing))
    match = _fov_match(config, (fx, fy, fz))
    slots = np.repeat(np.arange(n_tx), config.n_rx)
    residues = np.exp(-2j * np.pi * np.outer(np.arange(n_tx), slots) / n_tx)  # (n_tx, n_virtual)
    phasors = base[:, None, :] * residues[None]  # (n, n_tx, n_virtual)
    candidates = z[:, None, :] * phasors
    if proj is not None:
        peak = _projected_peaks(z, np.asarray(proj), phasors, match)
    elif match.shape[1]:
        peak = np.abs(candidates @ match).max(axis=2) ** 2
    else:
        peak = np.zeros(candidates.shape[:2])
    rows = np.arange(z.shape[0])
    best = np.argmax(peak, axis=1)
    other = np.argmax(np.where(np.arange(n_tx) == best[:, None], -np.inf, peak), axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = peak[rows, best] / peak[rows, other]
    span = 2.0 * n_tx * config.v_lim_mps  # the one-transmitter Doppler span, 4 * VLim_1 / 2
    v = v_hat + best * 2.0 * config.v_lim_mps
    v = (v + span / 2.0) % span - span / 2.0
    return VirtualPixels(
        candidates[rows, best],
        best,
        v,
        ratio,
        candidates[rows, other],
        other,
        phasors[rows, best],
        phasors[rows, other],
    )


def compensate_projector(proj: np.ndarray, phasors: np.ndarray) -> np.ndarray:
    """A projector (or whitening) of pixels ``z`` as one of the compensated pixels ``d * z``.

    ``D P D^H`` with ``D = diag(d)`` (``d`` unit phasors, :attr:`VirtualPixels.phasors`): the
    compensated pixel's projection is the compensated projection, ``(D P D^H)(D z) = D (P z)``.

    Parameters
    ----------
    proj : ndarray, shape (n, k, k), complex
    phasors : ndarray, shape (n, k), complex

    Returns
    -------
    ndarray, shape (n, k, k), complex

    Examples
    --------
    >>> d = np.exp(1j * np.array([[0.0, 0.5]]))
    >>> p = np.array([[[0.5, 0.5], [0.5, 0.5]]], complex)
    >>> z = np.array([[1.0, 2.0]], complex)
    >>> bool(np.allclose(compensate_projector(p, d)[0] @ (d[0] * z[0]), d[0] * (p[0] @ z[0])))
    True
    """
    d = np.asarray(phasors)
    return np.asarray(proj) * d[:, :, None] * np.conj(d)[:, None, :]


def residue_shifts(config: RadarConfig) -> np.ndarray:
    """Direction-cosine shifts (n, 3) in the antenna frame that a wrong residue mimics, both signs.

    Compensating a target's slot phase with residue ``m`` off the true one leaves the phase
    ``2 pi m t / n_tx`` on transmitter ``t``'s channels (module docstring): the pixels of a plane
    wave from ``u + d`` with ``(tx_t - tx_0) . d = -m t lambda / n_tx`` on every transmitter.
    Where that shift leaves every receiver's phase unchanged (``(rx_r - rx_0) . d`` a whole number
    of wavelengths) the wrong residue reads the direction ``u`` as ``u + d`` exactly, whatever
    ``u``: the ground straight below, read through the other residue, sits near the boresight.
    Shifts without that exact form (transmitters off one uniform line) are left out: no single
    direction mimics them. Each ``d`` is given with ``-d`` (the residues ``m`` and ``n_tx - m``).

    Parameters
    ----------
    config : RadarConfig
        The radar; one transmitter has no shifts.

    Returns
    -------
    ndarray, shape (n, 3)
        Shifts ``d`` of the unit direction's components (forward, right, down), dimensionless.

    Examples
    --------
    Two transmitters half a wavelength apart in height: the other residue moves the vertical
    direction cosine by one, so the nadir (``0, 0, 1``) reads as the boresight:

    >>> (residue_shifts(RadarConfig.prototype_2022(rx_positions_m="mimo-2x4")).round(6) + 0.0).tolist()
    [[0.0, 0.0, -1.0], [0.0, 0.0, 1.0]]
    >>> residue_shifts(RadarConfig.prototype_2022()).shape
    (0, 3)
    """
    n_tx = config.n_tx
    if n_tx == 1:
        return np.zeros((0, 3))
    tx = np.asarray(config.transmitters_m, float)
    rx = np.asarray(config.rx_positions_m, float)
    lam = config.wavelength_m
    shifts = []
    for m in range(1, n_tx):
        target = -m * np.arange(n_tx) * lam / n_tx
        d_yz = np.linalg.lstsq((tx - tx[0])[:, 1:], target, rcond=None)[0]
        d = np.array([0.0, *d_yz])
        tx_err = ((tx - tx[0]) @ d - target) / lam
        rx_cycles = (rx - rx[0]) @ d / lam
        if np.allclose(tx_err, 0.0, atol=1e-6) and np.allclose(rx_cycles, np.round(rx_cycles), atol=1e-6):
            shifts += [d, -d]
    return np.array(shifts).reshape(-1, 3)


@dataclass(frozen=True)
class DetectionDirections:
    """Directions of one frame's detections, as the pipeline reads them from their pixels.

    Attributes
    ----------
    u_ant : ndarray, shape (n, 3)
        Antenna-frame unit vectors (:func:`skyradar.process.doa.estimate_directions`, or through a
        cell's clutter nulls).
    coherence : ndarray, shape (n,)
        One plane wave's fit to each pixel (:func:`skyradar.process.doa.direction_coherence`; through
        the nulls where the direction was searched there).
    elevation_measured : ndarray, shape (n,), bool
        False where the nulls left the elevation unobservable and ``u_ant`` holds elevation 0 (a prior).
    residue, other_residue : ndarray, shape (n,), int
        A time-division MIMO radar's chosen and runner-up residue (:func:`virtual_pixels`); 0 and
        -1 with one transmitter.
    other_u_ant : ndarray, shape (n, 3)
        The runner-up residue's direction (NaN with one transmitter).

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> plain_directions(np.ones((1, 4), complex), 0, cfg).u_ant.round(6).tolist()
    [[1.0, 0.0, 0.0]]
    """

    u_ant: np.ndarray
    coherence: np.ndarray
    elevation_measured: np.ndarray
    residue: np.ndarray
    other_residue: np.ndarray
    other_u_ant: np.ndarray


def plain_directions(
    pixels: np.ndarray, doppler_bin: np.ndarray | int, config: RadarConfig
) -> DetectionDirections:
    """Directions of calibrated detection pixels read as they are (no clutter nulls; every elevation
    measured): a MIMO radar's after :func:`virtual_pixels` (slot phase out, residue chosen by the
    field of view), with the runner-up residue's direction too.

    Parameters
    ----------
    pixels : ndarray, shape (n, n_virtual), complex
        Calibrated pixels (slot phase still in for a MIMO radar).
    doppler_bin : int or ndarray, shape (n,)
        Their Doppler bins.
    config : RadarConfig
        The radar.

    Returns
    -------
    DetectionDirections

    Examples
    --------
    >>> from skyradar.process.doa import angles_from_direction, direction_from_angles, steering_vector
    >>> cfg = RadarConfig.prototype_2022(rx_positions_m="mimo-2x4")
    >>> v = 1.5 * cfg.v_lim_mps
    >>> z = steering_vector(direction_from_angles(0.2, -0.1), cfg) * slot_phase(v, cfg)
    >>> out = plain_directions(z[None], cfg.doppler_bin(v), cfg)
    >>> out.residue.tolist(), np.round(angles_from_direction(out.u_ant), 3).ravel().tolist()
    ([1], [0.2, -0.1])
    """
    z = np.atleast_2d(np.asarray(pixels))
    n = z.shape[0]
    residue, other_residue, u_other = np.zeros(n, np.int64), np.full(n, -1, np.int64), np.full((n, 3), np.nan)
    if config.n_tx > 1:  # each transmitter slot's Doppler phase out, its ambiguity resolved
        virtual = virtual_pixels(z, doppler_bin, config)
        z = virtual.pixels
        u_other = estimate_directions(virtual.other_pixels, config, calibrated=True)
        residue, other_residue = virtual.residue.astype(np.int64), virtual.other_residue.astype(np.int64)
    u = estimate_directions(z, config, calibrated=True)
    coherence = direction_coherence(z, u, config, calibrated=True)
    return DetectionDirections(u, coherence, np.ones(n, bool), residue, other_residue, u_other)
