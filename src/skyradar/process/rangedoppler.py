"""ADC cube to range-Doppler cube: windowed range FFT, crop to RLim, windowed Doppler FFT.

The output has the same form as the image-domain simulator's frames, so every later stage takes
either: shape ``(n_range, n_doppler, n_rx)`` complex64, range bin ``k`` at ``k * dR``, Doppler bin
``j`` at ``(j - nV/2) * dV`` (FFT-shifted), channel ``k`` divided by its complex calibration gain.

Normalisation. Both FFTs are divided by their length, so a complex tone of amplitude ``a`` that
falls exactly on a range and a Doppler bin gives ``|pixel|^2 = a^2 * G`` with
``G = (mean(w_range) * mean(w_doppler))^2`` the windows' coherent power gain
(:func:`window_gain_db`; 0 dB for ``'none'``, -12.0 dB for Hann x Hann). With the ADC scaled so
that ``a^2`` is the received power in W (as :mod:`skyradar.sim.raw` does), an on-bin target has
the image-domain pixel value times ``G``, and white ADC noise of power ``noise_power_w * Ns * nV``
per sample gives ``noise_power_w`` per pixel without windows (times ``mean(w_r^2) * mean(w_d^2)``
with them, see :func:`window_noise_gain_db`).

Speed. The prototype's 2032 samples per chirp are 16 x 127; a full FFT of that length spends most
of its time in the prime factor 127, yet only the first ``n_range`` (333) of the 2032 bins are kept.
The range transform is therefore split (Cooley-Tukey, ``n = Q*n1 + n2``, ``k = k1 + P*k2`` with
``P`` the 5-smooth part of the length): a length-``P`` FFT, a twiddle, and a matrix product with
the length-``Q`` DFT restricted to the ``k2`` that are kept. It is exact (same numbers as the full
FFT to float32 rounding); ``method='fft'`` forces the plain FFT. For ``P = 16`` (the prototype's
16 x 127) the frame is done in complex64 end to end without transposes: blocks of chirps (all
channels) go through one compiled pass (window, length-16 DFT, twiddle;
:mod:`skyradar.process._rd_kernel`), one real matrix product with the pruned length-Q DFT, and a
compiled scatter that applies the Doppler weight while writing the kept bins straight into the
(range, chirp, rx) output; the Doppler FFT then runs in place along the chirp axis of that array,
which already is the output layout. Blocks stay in cache and are spread over ``workers`` threads
(BLAS held to one thread meanwhile); :meth:`RangeDopplerProcessor.many` instead keeps ``workers``
whole frames in flight. ``skyradar bench chain`` measures both.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable, Iterator, Sequence
from concurrent.futures import Future
from functools import lru_cache
from typing import Any

import numpy as np
import scipy.fft as sfft

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.io.frames import frames_dataset
from skyradar.process._rd_fast import BLOCK_ROWS, Split16, frame_pool, one_blas_thread, run_parallel
from skyradar.process.windows import (
    WINDOWS,
    WindowSpec,
    get_window,
    window_gain_db,
    window_noise_gain_db,
)

# fmt: off
__all__ = [
    "WINDOWS", "get_window", "window_gain_db", "window_noise_gain_db", "RangeDopplerProcessor",
    "range_doppler", "rd_frames_dataset",
]

def _smooth_part(n: int) -> int:
    """Largest divisor of ``n`` whose prime factors are 2, 3 and 5."""
    p = 1
    for f in (2, 3, 5):
        while n % (p * f) == 0:
            p *= f
    return p


class RangeDopplerProcessor:
    """Precomputed windows and DFT factors for one RadarConfig; call it on ADC cubes.

    Parameters
    ----------
    config : RadarConfig
        Axes, sizes and (by default) calibration gains.
    range_window, doppler_window : str, (str, float) or None
        See :func:`get_window`.
    method : {'auto', 'pruned', 'fft'}
        Range transform: split DFT that computes only the kept bins, or a full FFT. ``'auto'``
        uses the split form when the chirp length has a prime factor above 5 and few bins are kept.
    workers : int
        Threads. One frame (:meth:`__call__`): blocks of chirps are range-transformed in
        parallel, then the Doppler FFTs. Many frames (:meth:`many`): ``workers`` frames in
        flight, one thread each (higher sustained throughput).
    n_samples : int, optional
        Valid ADC samples per chirp when fewer than ``config.samples_per_chirp`` (the rest is
        zero-padded after windowing, so the range axis keeps its bin spacing).

    Examples
    --------
    A unit tone at the beat frequency of range bin 20 whose phase advances 5/250 of a turn per
    chirp lands in Doppler bin 125 + 5; Hann x Hann keeps ``(0.5 * 0.5)^2`` of its power, so
    the pixel's amplitude is 0.25:

    >>> cfg = RadarConfig.prototype_2022()
    >>> t, n = np.arange(cfg.samples_per_chirp) / cfg.fs_hz, np.arange(cfg.n_doppler)
    >>> adc = np.exp(2j * np.pi * (20 * cfg.prf_hz * t[None, :] + 5 * n[:, None] / cfg.n_doppler))
    >>> rd = RangeDopplerProcessor(cfg)(np.broadcast_to(adc, (cfg.n_rx, *adc.shape)))
    >>> rd.shape, [int(i) for i in np.unravel_index(np.abs(rd[..., 0]).argmax(), rd.shape[:2])]
    ((333, 250, 4), [20, 130])
    >>> round(float(abs(rd[20, 130, 0])), 4)
    0.25
    """

    def __init__(
        self,
        config: RadarConfig,
        range_window: WindowSpec = "hann",
        doppler_window: WindowSpec = "hann",
        method: str = "auto",
        workers: int = 2,
        n_samples: int | None = None,
    ) -> None:
        # Interleaved transmitters are one slow time each, not one of n_doppler chirps.
        config.require_one_transmitter(
            "the range-Doppler transform", "sort its chirps with skyradar.process.mimo.virtual_range_doppler"
        )
        self.config = config
        self.n_fft = config.samples_per_chirp
        self.n_samples = self.n_fft if n_samples is None else int(n_samples)
        if not 2 <= self.n_samples <= self.n_fft:
            raise InputError(
                f"adc: {self.n_samples} samples per chirp; need 2..{self.n_fft} for this radar config"
            )
        self.workers = int(workers)
        self.w_range = get_window(range_window, self.n_samples).astype(np.float32)
        self.w_doppler = get_window(doppler_window, config.n_doppler).astype(np.float32)
        self._w_full = np.zeros(self.n_fft, np.float32)
        self._w_full[: self.n_samples] = self.w_range
        self.scale = 1.0 / (self.n_samples * config.n_doppler)
        n = np.arange(config.n_doppler)
        shift = np.exp(2j * np.pi * (config.n_doppler // 2) * n / config.n_doppler)
        self._doppler_weight = self.w_doppler * shift
        p = _smooth_part(self.n_fft)
        q = self.n_fft // p
        k2 = -(-config.n_range // p)
        if method == "auto":
            method = "pruned" if q > 1 and k2 <= 32 else "fft"
        if method not in ("pruned", "fft"):
            raise InputError(f"range_doppler: method must be 'auto', 'pruned' or 'fft', got {method!r}")
        self.method = method
        self._split16: Split16 | None = None
        if method == "pruned":
            self._p, self._q, self._k2 = p, q, k2
            n2 = np.arange(q)
            twiddle = np.exp(-2j * np.pi * np.outer(np.arange(p), n2) / self.n_fft)
            self._twiddle = twiddle.astype(np.complex64).reshape(p, 1, q)
            self._dft = np.exp(-2j * np.pi * np.outer(n2, np.arange(k2)) / q).astype(np.complex64)
            if p == 16:
                self._split16 = Split16(self.n_fft, config.n_range)

    def _range_transform(self, x: np.ndarray, remove_dc: bool) -> np.ndarray:
        """Window and transform (C, n_samples) ADC rows -> first n_range DFT bins (C, n_range)."""
        c, n_range = x.shape[0], self.config.n_range
        if remove_dc:
            # ADC offset and LO leakage sit at zero beat frequency: remove each chirp's mean.
            x = x - x.mean(axis=-1, keepdims=True, dtype=np.complex64 if np.iscomplexobj(x) else np.float32)
        if self.n_samples < self.n_fft:  # short chirps: zero-pad (window covers the valid part)
            x = np.concatenate([x, np.zeros((c, self.n_fft - self.n_samples), x.dtype)], axis=1)
        if self.method == "fft":
            xw = np.empty((c, self.n_fft), np.complex64)
            np.multiply(x, self._w_full, out=xw, casting="unsafe")
            return sfft.fft(xw, axis=-1, workers=1, overwrite_x=True)[:, :n_range]
        p, q, k2 = self._p, self._q, self._k2
        y = np.empty((p, c, q), np.complex64)
        # Windowed samples as (n1, chirp, n2): the length-P FFT runs over the outer axis,
        # where pocketfft vectorises across the contiguous inner axes.
        np.multiply(
            x.reshape(c, p, q).transpose(1, 0, 2), self._w_full.reshape(p, 1, q), out=y, casting="unsafe"
        )
        y = sfft.fft(y, axis=0, workers=1, overwrite_x=True)
        y *= self._twiddle
        z = (y.reshape(p * c, q) @ self._dft).reshape(p, c, k2)
        # bin k = k1 + P*k2 lives at z[k1, :, k2]: (chirp, k2, k1) order gives increasing k.
        return z.transpose(1, 2, 0).reshape(c, k2 * p)[:, :n_range]

    def _range_stage(self, rows: np.ndarray, remove_dc: bool, workers: int) -> np.ndarray:
        """Range transform in cache-sized blocks of chirps spread over ``workers`` threads."""
        out = np.empty((rows.shape[0], self.config.n_range), np.complex64)

        def job(sl: slice) -> None:
            out[sl] = self._range_transform(rows[sl], remove_dc)

        run_parallel(job, [slice(s, s + BLOCK_ROWS) for s in range(0, rows.shape[0], BLOCK_ROWS)], workers)
        return out

    def __call__(
        self, adc: np.ndarray, remove_dc: bool = False, calibration: np.ndarray | None = None
    ) -> np.ndarray:
        """Range-Doppler cube (n_range, n_doppler, n_rx) complex64 of one ADC cube (rx, chirp, sample)."""
        with one_blas_thread():  # once per frame, not per stage: switching it costs time
            return self._frame(adc, remove_dc, self._gains(calibration), self.workers)

    def many(
        self, adc_frames: Iterable[np.ndarray], remove_dc: bool = False, calibration: np.ndarray | None = None
    ) -> Iterator[np.ndarray]:
        """Range-Doppler cubes of many ADC cubes, in order, ``workers`` frames in flight.

        Each frame runs on one thread, so the threads never wait for each other inside a frame:
        the sustained throughput for recordings and simulated flights (``skyradar bench chain``
        measures both this and the one-frame latency of :meth:`__call__`). BLAS stays at one
        thread, for the caller too, until the iteration ends.

        Examples
        --------
        >>> cfg = RadarConfig.prototype_2022()
        >>> adc = np.zeros((3, cfg.n_rx, cfg.n_doppler, cfg.samples_per_chirp), np.complex64)
        >>> [rd.shape for rd in RangeDopplerProcessor(cfg).many(adc)][-1]
        (333, 250, 4)
        """
        gains = self._gains(calibration)
        # One BLAS limit for the whole batch: switching OpenBLAS's thread count back and forth
        # between frames, while the other frame's thread is inside a matrix product, costs more
        # than the frames themselves.
        with one_blas_thread():
            if self.workers <= 1:
                yield from (self._frame(adc, remove_dc, gains, 1) for adc in adc_frames)
                return
            pool = frame_pool(self.workers)
            pending: deque[Future[np.ndarray]] = deque()
            for adc in adc_frames:
                pending.append(pool.submit(self._frame, adc, remove_dc, gains, 1))
                if len(pending) >= self.workers:
                    yield pending.popleft().result()
            while pending:
                yield pending.popleft().result()

    def _gains(self, calibration: np.ndarray | None) -> np.ndarray:
        n_rx = self.config.n_rx
        gains = self.config.rx_calibration if calibration is None else np.asarray(calibration, complex)
        if gains.shape != (n_rx,) or not np.all(np.isfinite(gains)) or np.any(gains == 0):
            raise InputError(f"range_doppler: calibration must be {n_rx} finite non-zero complex gains")
        return gains

    def _frame(self, adc: np.ndarray, remove_dc: bool, gains: np.ndarray, workers: int) -> np.ndarray:
        cfg, adc = self.config, np.asarray(adc)
        expected = (cfg.n_rx, cfg.n_doppler, self.n_samples)
        if adc.ndim != 3 or tuple(adc.shape) != expected:
            raise InputError(f"adc: shape {tuple(adc.shape)}, expected (rx, chirp, sample) = {expected}")
        if self._split16 is not None:
            # Doppler window, FFT shift (a frequency offset of nV//2 bins), normalisation and
            # calibration: one complex weight per (chirp, rx), applied while scattering.
            weight = (self._doppler_weight[:, None] * (self.scale / gains)[None, :]).astype(np.complex64)
            adc = np.ascontiguousarray(adc, np.complex64)
            return self._split16(adc, self._w_full, remove_dc, weight.ravel(), workers)
        rows = np.asarray(adc).reshape(cfg.n_rx * cfg.n_doppler, self.n_samples)
        rng = self._range_stage(rows, remove_dc, workers).reshape(cfg.n_rx, cfg.n_doppler, cfg.n_range)
        # Doppler window, FFT shift (a frequency offset of nV//2 bins), normalisation and
        # calibration are one complex weight per (rx, chirp): one pass over the data.
        weight = (self._doppler_weight[None, :] * (self.scale / gains)[:, None]).astype(np.complex64)
        rng *= weight[:, :, None]
        rd = sfft.fft(rng, axis=1, workers=workers, overwrite_x=True)
        return np.ascontiguousarray(rd.transpose(2, 1, 0))


@lru_cache(maxsize=8)
def _processor(
    config: RadarConfig, range_window: Any, doppler_window: Any, method: str, workers: int, n_samples: int
) -> RangeDopplerProcessor:
    return RangeDopplerProcessor(config, range_window, doppler_window, method, workers, n_samples)


def _hashable(spec: WindowSpec) -> Any:
    return tuple(spec) if isinstance(spec, list) else spec


def range_doppler(
    adc: np.ndarray,
    config: RadarConfig,
    range_window: WindowSpec = "hann",
    doppler_window: WindowSpec = "hann",
    remove_dc: bool = False,
    calibration: np.ndarray | None = None,
    method: str = "auto",
    workers: int = 2,
) -> np.ndarray:
    """Range-Doppler cube of one ADC cube.

    Parameters
    ----------
    adc : ndarray, shape (n_rx, n_doppler, n_samples)
        ADC samples (complex or real; any numeric dtype), one frame: rx, chirp, fast time.
        ``n_samples`` may be below ``config.samples_per_chirp`` (zero-padded after windowing).
    config : RadarConfig
        Sizes, axes and calibration.
    range_window, doppler_window : str, (str, float) or None
        ``'hann'`` (default), ``'hamming'``, ``'blackmanharris'``, ``'chebyshev[:dB]'``, ``'none'``.
    remove_dc : bool
        Subtract each chirp's mean before the range FFT (ADC offset, LO leakage at zero range).
    calibration : ndarray, shape (n_rx,), complex, optional
        Channel gains to divide by; default ``config.rx_calibration``.
    method : {'auto', 'pruned', 'fft'}
        See :class:`RangeDopplerProcessor`.
    workers : int
        FFT threads.

    Returns
    -------
    ndarray, shape (n_range, n_doppler, n_rx), complex64
        On-bin tone of amplitude ``a``: ``|pixel|^2 = a^2 * 10**(window_gain_db(...)/10)``.

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> t = np.arange(cfg.samples_per_chirp) / cfg.fs_hz
    >>> tone = np.exp(2j * np.pi * 10 * cfg.prf_hz * t)  # beat frequency of range bin 10
    >>> adc = np.broadcast_to(tone, (cfg.n_rx, cfg.n_doppler, t.size))
    >>> rd = range_doppler(adc, cfg, range_window='none', doppler_window='none')
    >>> np.unravel_index(np.abs(rd[..., 0]).argmax(), rd.shape[:2]), round(float(abs(rd[10, 125, 0])), 3)
    ((np.int64(10), np.int64(125)), 1.0)
    """
    if np.ndim(adc) != 3:
        raise InputError(f"adc: expected a (rx, chirp, sample) cube, got {np.ndim(adc)} dimensions")
    proc = _processor(
        config,
        _hashable(range_window),
        _hashable(doppler_window),
        method,
        int(workers),
        int(np.shape(adc)[2]),
    )
    return proc(adc, remove_dc=remove_dc, calibration=calibration)


def rd_frames_dataset(
    adc_frames: Sequence[np.ndarray] | np.ndarray,
    times_s: np.ndarray,
    config: RadarConfig,
    range_window: WindowSpec = "hann",
    doppler_window: WindowSpec = "hann",
    remove_dc: bool = False,
    calibration: np.ndarray | None = None,
    **truth: Any,
):
    """Process many ADC frames into the frames Dataset of :func:`skyradar.io.frames.frames_dataset`.

    Parameters
    ----------
    adc_frames : array_like, shape (n_time, n_rx, n_doppler, n_samples)
        ADC frames (an array, memmap or list of cubes).
    times_s : ndarray, shape (n_time,)
        Frame times, s.
    config, range_window, doppler_window, remove_dc, calibration
        As in :func:`range_doppler`.
    **truth
        ``ownship=``, ``targets=``, ``target_names=`` passed on to ``frames_dataset``.

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> adc = np.zeros((2, cfg.n_rx, cfg.n_doppler, cfg.samples_per_chirp), np.complex64)
    >>> rd_frames_dataset(adc, np.array([0.0, 0.1]), cfg).iq.shape
    (2, 333, 250, 4)
    """
    times_s = np.asarray(times_s, float)
    if len(adc_frames) != times_s.size:
        raise InputError(f"adc: {len(adc_frames)} frames but {times_s.size} frame times")
    iq = np.empty((times_s.size, config.n_range, config.n_doppler, config.n_rx), np.complex64)
    if times_s.size:
        rw, dw, n_samples = (
            _hashable(range_window),
            _hashable(doppler_window),
            int(np.shape(adc_frames[0])[-1]),
        )
        proc = _processor(config, rw, dw, "auto", 2, n_samples)
        for i, rd in enumerate(proc.many(adc_frames, remove_dc, calibration)):
            iq[i] = rd
    attrs = {"source": "adc", "range_window": str(range_window), "doppler_window": str(doppler_window)}
    return frames_dataset(iq, times_s, config, attrs=attrs, **truth)
