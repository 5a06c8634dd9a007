"""Point-spread of the range and Doppler FFT windows for image-domain frames.

The raw ADC chain (:mod:`skyradar.sim.raw` then ``process.rangedoppler.range_doppler``) windows each
chirp and each slow-time row before its FFT, so a scatterer at fractional bin position ``x`` shows
in bin ``k`` with the window's response ``W(k - x)``: a main lobe two bins wide (Hann), sidelobes
(-31 dB for Hann) and a straddle loss up to 1.4 dB per axis for a scatterer half-way between bins.
Here ``W(u) = sum_n w[n] exp(-2j pi u (n - N/2) / N) / sum_n w[n]``: the zero-phase DTFT of the
periodic window, 1 at ``u = 0``, so pixel units stay "an on-bin scatterer's pixel power is its
received power" (the raw chain's pixel divided by the windows' coherent gain).

Two uses:

- point targets (few per frame) get ``W`` exactly at their fractional (range, Doppler) position
  (:func:`target_psf_taps`);
- terrain (millions of facets per frame) is accumulated at its nearest bin, then the whole frame
  (with its noise) is convolved with the *bin-averaged* kernel ``h[m]``, ``|h[m]|^2 =
  mean over d in [-1/2, 1/2) of |W(m + d)|^2`` (:func:`binned_kernel`, :func:`apply_psf`).
  With facets no coarser than half a bin their positions inside a bin are spread evenly, so the
  expected power of every cell (over speckle) is the raw chain's ``sum_i P_i |W(k - x_i)|^2`` up
  to that averaging (``tests/test_sim_psf.py`` measures the difference against the raw chain),
  at the cost of one separable convolution per frame instead of a kernel per facet. Noise
  convolved with ``h`` gets the windowed noise power ``sum |h|^2 = ENBW`` (1.5 per axis for Hann)
  as the raw chain's does.

The Doppler axis is circular (aliasing); the range axis ends at the cube's edges (clutter beyond
the last range bin, which the simulator does not accumulate, would leak in a few bins in the raw
chain).

Windows are scipy's periodic (``fftbins=True``) windows, the convention of
``skyradar.process.windows.get_window`` (tested equal there; ``sim`` may not import ``process``).
"""

from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

import numpy as np
from numba import njit, prange

from skyradar.errors import InputError

__all__ = [
    "PSF_WINDOW",
    "PSFKernels",
    "window_response",
    "binned_kernel",
    "psf_kernels",
    "enbw",
    "apply_psf",
    "target_psf_taps",
    "frame_options",
    "speckle_key",
]

PSF_WINDOW = "hann"  # the default range and Doppler windows of process/range_doppler
_TAIL = 1e-6  # kernel truncated where the power left out is below -60 dB of the whole
_K_MAX = 16
OVERSAMPLE = 2  # terrain lands on half-bins: the kernel then averages over half a bin, not a whole one
_SPECKLE_STREAM = 0x5D5EC1E5A1B2C3D4  # XORed into the frame's noise key: speckle's own stream


@lru_cache(maxsize=16)
def _window(name: str, n: int) -> np.ndarray:
    import scipy.signal  # here, not at import: see skyradar.process.windows.get_window

    try:
        return scipy.signal.get_window(name, int(n), fftbins=True).astype(float)
    except ValueError:
        raise InputError(f"simulation: unknown PSF window {name!r} (a scipy.signal window name)") from None


def window_response(name: str, n: int, offset_bins: np.ndarray) -> np.ndarray:
    """Zero-phase DTFT of the periodic window at ``offset_bins`` (bins), normalised to 1 at 0.

    Parameters
    ----------
    name : str
        scipy window name (``'hann'``, ``'hamming'``, ``'boxcar'``...).
    n : int
        Window length (samples per chirp for range, chirps per frame for Doppler).
    offset_bins : ndarray
        Bin offsets ``k - x`` between an output bin and the scatterer.

    Examples
    --------
    >>> w = window_response("hann", 256, np.array([0.0, 0.5, 1.0, 2.0]))
    >>> np.round(20 * np.log10(np.abs(w[:2])), 2).tolist(), np.round(w.real[2:], 3).tolist()
    ([0.0, -1.42], [0.5, 0.0])
    """
    u = np.asarray(offset_bins, float)
    if name in _COSINE_SUM:  # closed form: 25x faster than the sum, and called per target per frame
        a = _COSINE_SUM[name]
        total = a[0] * _dirichlet(u, n)
        for k, a_k in enumerate(a[1:], start=1):
            total = total + 0.5 * a_k * (_dirichlet(u - k, n) + _dirichlet(u + k, n))
        return np.exp(1j * np.pi * u) * total / (a[0] * n)
    w = _window(name, n)
    centred = np.arange(n) - n / 2.0
    phase = np.exp(-2j * np.pi * np.multiply.outer(u, centred) / n)
    return phase @ w / w.sum()


# Periodic cosine-sum windows, w[m] = sum_k a_k cos(2 pi k m / n), as scipy.signal.get_window makes them.
_COSINE_SUM = {
    "hann": (0.5, -0.5),
    "hamming": (0.54, -0.46),
    "blackman": (0.42, -0.5, 0.08),
    "boxcar": (1.0,),
}


def _dirichlet(v: np.ndarray, n: int) -> np.ndarray:
    """``sum_{m<n} exp(-2 pi i v m / n)`` in closed form (its limit where ``v`` is a multiple of ``n``)."""
    den = np.sin(np.pi * v / n)
    at_pole = np.abs(den) < 1e-12
    ratio = np.where(
        at_pole,
        n * np.cos(np.pi * v) / np.where(at_pole, np.cos(np.pi * v / n), 1.0),
        np.sin(np.pi * v) / np.where(at_pole, 1.0, den),
    )
    return np.exp(-1j * np.pi * v * (n - 1) / n) * ratio


@lru_cache(maxsize=16)
def binned_kernel(name: str, n: int, oversample: int = 1) -> np.ndarray:
    """Window kernel averaged over sub-bins of ``1 / oversample`` bin, float32.

    Entry ``s`` (s = -S..S, S = oversample * K + oversample - 1) is the root of the mean of
    ``|W(s / oversample + d)|^2`` over ``d`` in one sub-bin, with the sign of its mean real part.
    ``K`` is the smallest reach in bins whose left-out power is below -60 dB of the total (at
    most 16, and less than half the window length). ``sum(h^2) / oversample`` is the window's
    ENBW.

    Examples
    --------
    >>> h = binned_kernel("hann", 250)
    >>> len(h) // 2, round(float(np.sum(h.astype(float) ** 2)), 3)  # reach, ENBW of Hann
    (7, 1.5)
    >>> h2 = binned_kernel("hann", 250, 2)
    >>> len(h2) // 2, round(float(np.sum(h2.astype(float) ** 2)) / 2, 2)
    (13, 1.5)
    """
    d = ((np.arange(64) + 0.5) / 64 - 0.5) / oversample
    # The response repeats every n bins: the kernel stays within half a period.
    half = max(0, min(_K_MAX + 4, (n - 1) // 2 - 1))
    m = np.arange(-half * oversample, half * oversample + 1) / oversample
    resp = window_response(name, n, (m[:, None] + d[None, :]).ravel()).reshape(m.size, d.size)
    power = np.mean(np.abs(resp) ** 2, axis=1)
    total = power.sum()
    reach = min(_K_MAX, half - 1)
    for k in range(reach + 1):
        if power[np.abs(m) > k + 0.5].sum() <= _TAIL * total:
            reach = k
            break
    keep = np.abs(m) <= reach + 1 - 1.0 / oversample + 1e-9
    sign = np.where(resp.real.mean(axis=1) < 0.0, -1.0, 1.0)
    return (sign * np.sqrt(power))[keep].astype(np.float32)


@njit(inline="always")
def _set4(dst, g0, s0, g1, s1, g2, s2, g3, s3):
    for x in range(dst.shape[0]):
        dst[x] = g0 * s0[x] + g1 * s1[x] + g2 * s2[x] + g3 * s3[x]


@njit(inline="always")
def _add4(dst, g0, s0, g1, s1, g2, s2, g3, s3):
    # Four taps per pass: one load and store of ``dst`` per four multiply-adds, not per one (the
    # passes were bound by those loads and stores). A plain range(n) index: no wrap-around
    # check, and LLVM vectorises the loop.
    for x in range(dst.shape[0]):
        dst[x] += g0 * s0[x] + g1 * s1[x] + g2 * s2[x] + g3 * s3[x]


@njit(inline="always")
def _taps_into(dst, gains, rows, n):
    """``dst = sum(gains[t] * rows[t] for t < n)``; ``n`` a multiple of 4 (padding has gain 0)."""
    _set4(dst, gains[0], rows[0], gains[1], rows[1], gains[2], rows[2], gains[3], rows[3])
    for t in range(4, n, 4):
        _add4(
            dst,
            gains[t],
            rows[t],
            gains[t + 1],
            rows[t + 1],
            gains[t + 2],
            rows[t + 2],
            gains[t + 3],
            rows[t + 3],
        )


@njit(inline="always")
def _row_filled(fine, m):
    for b in range(fine.shape[0]):
        src = fine[b, m]
        for x in range(src.shape[0]):
            if src[x] != 0.0:
                return True
    return False


@njit(inline="always")
def _phase_rows(fine, m, ext, n_d, step, pad, clear):
    # Fine bin L j + p of row m (summed over the blocks, which are cleared on the way when
    # ``clear``) into ext[p, (pad + j) step ...], then ``pad`` bins copied circularly either side:
    # every Doppler tap then reads one contiguous run. Whole-row 2-D and 3-D views indexed by
    # plain range() counters: a slice per bin cost more than the copying (3.8 of 8 ms a frame).
    os = ext.shape[0]
    for b in range(fine.shape[0]):
        src = fine[b, m].reshape((n_d, os, step))
        for p in range(os):
            dst = ext[p].reshape((n_d + 2 * pad, step))[pad : pad + n_d]
            if b == 0:
                for j in range(n_d):
                    for c in range(step):
                        dst[j, c] = src[j, p, c]
            else:
                for j in range(n_d):
                    for c in range(step):
                        dst[j, c] += src[j, p, c]
        if clear:
            fine[b, m, :] = 0
    for p in range(os):
        e = ext[p]
        e[: pad * step] = e[n_d * step : (n_d + pad) * step]
        e[(pad + n_d) * step :] = e[pad * step : 2 * pad * step]


@njit(parallel=True, cache=True, error_model="numpy", fastmath=True)
def _psf_kernel(fine, tmp, out, h_range, h_doppler, step, clear):  # pragma: no cover - compiled
    # Float32 views: fine (n_blocks, L n_r, L n_d * w), summed over its blocks (the simulator's
    # per-thread accumulation cubes, cleared on the way when ``clear``: no separate pass over
    # them), tmp (L n_r, n_d * w), out (n_r, n_d * w) with w = 2 n_rx floats per bin.
    # out[k, j] = sum over fine (m, l) of fine[m, l] h_range[L k - m] h_doppler[L j - l]: a real
    # kernel acts on the real and imaginary parts alike, so the inner loops are plain vector
    # multiply-adds over whole rows, four taps at a time.
    n_fine_r, n_d = fine.shape[1], tmp.shape[1] // step
    os = fine.shape[2] // step // n_d
    sr, sd = h_range.shape[0] // 2, h_doppler.shape[0] // 2
    width, pad = n_d * step, (sd + os - 1) // os + 1
    filled = np.zeros(n_fine_r, np.bool_)  # rows with any return (ground below is empty)
    for m in prange(n_fine_r):  # Doppler: circular
        filled[m] = _row_filled(fine, m)
        if not filled[m]:
            continue
        ext = np.empty((os, (n_d + 2 * pad) * step), np.float32)
        _phase_rows(fine, m, ext, n_d, step, pad, clear)
        # Fine bin L j - s is phase p = (-s) mod L of bin j - t, t = (s + p) / L.
        gains, rows = np.zeros((2 * sd + 4) // 4 * 4, np.float32), [ext[0, :width]] * ((2 * sd + 4) // 4 * 4)
        for i in range(2 * sd + 1):
            p = (sd - i) % os
            t = (i - sd + p) // os
            gains[i], rows[i] = h_doppler[i], ext[p, (pad - t) * step : (pad - t) * step + width]
        _taps_into(tmp[m], gains, rows, gains.shape[0])
    n_taps = (2 * sr + 4) // 4 * 4
    for k in prange(out.shape[0]):  # range: zero beyond the cube
        gains, rows, n = np.zeros(n_taps, np.float32), [tmp[0]] * n_taps, 0
        for s in range(-sr, sr + 1):
            m = os * k - s
            if 0 <= m < n_fine_r and filled[m]:
                gains[n], rows[n], n = h_range[s + sr], tmp[m], n + 1
        if n == 0:
            out[k, :] = 0
            continue
        for t in range(n, n_taps):  # padding taps (gain 0) read a written row: 0 * garbage may be NaN
            rows[t] = rows[0]
        _taps_into(out[k], gains, rows, (n + 3) // 4 * 4)


def apply_psf(
    fine: np.ndarray, kernels: PSFKernels, out: np.ndarray, scratch: np.ndarray, clear: bool = False
) -> None:
    """``out`` (n_range, n_doppler, n_rx) from the oversampled grid ``fine`` and the kernels.

    ``fine`` is (L n_range, L n_doppler, n_rx) complex64 with ``L = kernels.oversample``: each
    scatterer added at its nearest sub-bin; or (n_blocks, L n_range, L n_doppler, n_rx): blocks
    summed first (and set to 0 when ``clear``). ``scratch`` is complex64 with at least
    ``L n_range * n_doppler * n_rx`` elements (overwritten).

    Examples
    --------
    >>> k = PSFKernels(binned_kernel("hann", 64, 2), binned_kernel("hann", 64, 2), 2)
    >>> fine, out = np.zeros((40, 128, 1), np.complex64), np.zeros((20, 64, 1), np.complex64)
    >>> fine[20, 0, 0] = 1.0  # on bin (10, 0)
    >>> apply_psf(fine, k, out, np.empty(40 * 64, np.complex64))
    >>> round(float(np.sum(np.abs(out) ** 2)), 2), bool(abs(out[10, 63, 0]) > 0)  # ~ENBW^2; wraps
    (2.25, True)
    """
    n_r, n_d, n_rx = out.shape
    step = 2 * n_rx
    blocks = fine if fine.ndim == 4 else fine[None]
    n_fine_r = blocks.shape[1]
    tmp = scratch.reshape(-1)[: n_fine_r * n_d * n_rx].view(np.float32)
    tmp = tmp.reshape(n_fine_r, n_d * step)
    _psf_kernel(
        blocks.view(np.float32).reshape(blocks.shape[0], n_fine_r, -1),
        tmp,
        out.view(np.float32).reshape(n_r, n_d * step),
        kernels.h_range,
        kernels.h_doppler,
        step,
        bool(clear),
    )


def target_psf_taps(
    name: str, n: int, position_bins: float, reach: int, n_bins: int, circular: bool
) -> tuple[np.ndarray, np.ndarray]:
    """Bins and exact window responses of a point at fractional ``position_bins`` on one axis.

    Bins ``round(position) - reach .. + reach``, wrapped when ``circular`` (Doppler), else
    those inside ``[0, n_bins)`` (range).

    Examples
    --------
    >>> bins, w = target_psf_taps("hann", 250, 249.5, 2, 250, True)
    >>> bins.tolist(), np.round(np.abs(w), 2).tolist()
    ([248, 249, 0, 1, 2], [0.17, 0.85, 0.85, 0.17, 0.02])
    """
    centre = int(np.floor(position_bins + 0.5))
    bins = np.arange(centre - reach, centre + reach + 1)
    response = window_response(name, n, bins - position_bins)
    if circular:
        return bins % n_bins, response
    inside = (bins >= 0) & (bins < n_bins)
    return bins[inside], response[inside]


class PSFKernels(NamedTuple):
    """The sub-bin averaged range and Doppler kernels of one radar's frames (float32, odd lengths).

    Parameters
    ----------
    h_range, h_doppler : ndarray of float32
        Range and Doppler kernels (:func:`binned_kernel`), odd lengths.
    oversample : int
        Sub-bins per bin the kernels are sampled at.

    Examples
    --------
    >>> k = PSFKernels(binned_kernel("hann", 64, 2), binned_kernel("hann", 64, 2), 2)
    >>> len(k.h_range), k.reach  # 27 half-bin taps: 6 whole bins either side
    (27, (6, 6))
    """

    h_range: np.ndarray
    h_doppler: np.ndarray
    oversample: int = 1

    @property
    def reach(self) -> tuple[int, int]:
        """Half-widths (range, Doppler), whole bins."""
        return len(self.h_range) // 2 // self.oversample, len(self.h_doppler) // 2 // self.oversample


def psf_kernels(config, window: str = PSF_WINDOW, oversample: int = OVERSAMPLE) -> PSFKernels:
    """Kernels for ``config``: range over ``samples_per_chirp``, Doppler over one transmitter's chirps
    (``n_doppler_per_tx``).

    Examples
    --------
    >>> from skyradar.config import RadarConfig
    >>> psf_kernels(RadarConfig.prototype_2022()).reach
    (6, 6)
    """
    return PSFKernels(
        binned_kernel(window, config.samples_per_chirp, oversample),
        binned_kernel(window, config.n_doppler_per_tx, oversample),
        oversample,
    )


def enbw(kernels: PSFKernels | None) -> float:
    """Noise power gain of the two kernels (the windows' ENBW product; 1 for none).

    Examples
    --------
    >>> round(enbw(PSFKernels(binned_kernel("hann", 64), binned_kernel("hann", 64))), 2)
    2.25
    """
    if kernels is None:
        return 1.0
    h_r, h_d = kernels.h_range.astype(float), kernels.h_doppler.astype(float)
    return float(np.sum(h_r**2) * np.sum(h_d**2)) / kernels.oversample**2


def frame_options(psf, speckle, swerling) -> tuple[bool, bool, int]:
    """Checked ``psf``, ``speckle`` and ``swerling`` simulation options.

    Parameters
    ----------
    psf, speckle : bool-like
        Window point-spread and terrain speckle on or off.
    swerling : int
        Target fluctuation model: 0 (constant) or 1 (Swerling 1); a bool is refused.

    Returns
    -------
    (bool, bool, int)

    Raises
    ------
    InputError
        For any other ``swerling``.

    Examples
    --------
    >>> frame_options(1, 0, 1)
    (True, False, 1)
    >>> frame_options(True, False, 2)
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: simulation.swerling must be 0 or 1, got 2
    """
    if swerling not in (0, 1) or isinstance(swerling, bool):
        raise InputError(f"simulation.swerling must be 0 or 1, got {swerling!r}")
    return bool(psf), bool(speckle), int(swerling)


def speckle_key(noise_key: np.uint64) -> np.uint64:
    """The frame's speckle stream key, derived from its noise key (never 0: 0 means no speckle).

    Parameters
    ----------
    noise_key : numpy.uint64
        The frame's noise key.

    Returns
    -------
    numpy.uint64
        ``noise_key`` XOR a fixed stream constant, or 1 where that is 0.

    Examples
    --------
    >>> hex(int(speckle_key(np.uint64(0))))  # the stream constant itself
    '0x5d5ec1e5a1b2c3d4'
    >>> speckle_key(np.uint64(0x5D5EC1E5A1B2C3D4))
    np.uint64(1)
    """
    return np.uint64(int(noise_key) ^ _SPECKLE_STREAM) or np.uint64(1)
