"""From IQ samples to one range profile per direct-path pulse, chunk by chunk.

Each chunk is matched-filtered (FFT overlap-add); the direct-path pulses are the strongest peak per
PRI. The direct path is then fitted by least squares with the filter's response to the pulse delayed
by a fraction of a sample (a grid of 1/64 sample; for an operator-given pulse the shifted pulses are
sampled from its formula, as an ADC samples the real one) and subtracted, which takes its range
sidelobes with it. Every pulse's profile is the rest of the filter output from the direct-path
arrival on, shifted by that fraction (so static echoes line up from pulse to pulse whatever the PRF
stagger) and phase-referenced to the direct path (so an incoherent transmitter or a receiver frequency
offset does not smear static echoes).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass

import numpy as np
from scipy.signal.windows import hann

from skyradar.passive.matched_filter import filter_taps, matched_filter
from skyradar.passive.pulses import find_direct_pulses

__all__ = ["PulseProfiles", "ProfileExtractor", "read_chunks"]

_PAD = 8  # samples kept before each direct-path peak so the fractional shift has room
_FIT = 3  # the direct path is fitted over lags -_FIT .. _FIT around its peak
_N_FRAC = 64  # fractional-delay grid: 1/64 sample


@dataclass
class PulseProfiles:
    """Profiles of the direct-path pulses found in one chunk.

    Attributes
    ----------
    times_s : ndarray
        Direct-path arrival of each pulse, s from sample 0.
    amplitude : ndarray
        Complex matched-filter peak of each direct-path pulse.
    profiles : ndarray
        (pulses, lags), complex: lag ``k`` at ``k / fs`` after the direct path, the direct path
        removed, phase-referenced to it.

    Examples
    --------
    Four direct-path pulses 1 ms apart from 0.2 ms, no echo: the profiles hold only the residue of the
    removed direct path.

    >>> from skyradar.passive.matched_filter import lfm_pulse
    >>> fs = 5e6; pulse = lfm_pulse(fs, 20e-6, -5e5, 1e6 / 20e-6)
    >>> x = np.zeros(20_000, complex)
    >>> for start in range(1000, 19_000, 5000):
    ...     x[start : start + 100] += pulse
    >>> ex = ProfileExtractor(pulse, fs, n_lags=32, min_pri_s=8e-4, threshold=1.0)
    >>> out = ex.process(0, np.concatenate([np.zeros(ex.front), x]), x.size)
    >>> np.round(out.times_s * 1e3, 4).tolist(), out.profiles.shape
    ([0.2, 1.2, 2.2, 3.2], (4, 32))
    >>> bool(np.abs(out.profiles).max() < 1e-3 * np.abs(out.amplitude).min())
    True
    """

    times_s: np.ndarray
    amplitude: np.ndarray
    profiles: np.ndarray


class ProfileExtractor:
    """Streaming pulse-profile extraction with memory bounded by the chunk.

    Examples
    --------
    >>> from skyradar.passive.matched_filter import lfm_pulse
    >>> fs = 5e6; pulse = lfm_pulse(fs, 20e-6, -5e5, 1e6 / 20e-6)
    >>> x = np.zeros(50_000, complex)
    >>> for start in range(1000, 49_000, 5000):
    ...     x[start : start + 100] += pulse
    ...     x[start + 40 : start + 140] += 0.01 * pulse     # an echo 40 samples later
    >>> ex = ProfileExtractor(pulse, fs, n_lags=64, min_pri_s=8e-4, threshold=1.0)
    >>> out = ex.process(0, np.concatenate([np.zeros(ex.front), x]), x.size)  # x from sample -front
    >>> out.profiles.shape, int(np.argmax(abs(out.profiles[0])))
    ((10, 64), 40)
    """

    def __init__(
        self,
        pulse: np.ndarray,
        sample_rate_hz: float,
        n_lags: int,
        min_pri_s: float,
        threshold: float | None = None,
        window: str | None = "hann",
        threshold_db: float = 30.0,
        pulse_at: Callable[[np.ndarray], np.ndarray] | None = None,
        companion: tuple[float, float] | None = None,
    ) -> None:
        self.pulse = np.asarray(pulse, np.complex128)
        self.fs = float(sample_rate_hz)
        self.n_lags = int(n_lags)
        self.window = window
        self.min_separation = int(0.8 * min_pri_s * self.fs)
        self.threshold = threshold
        self.threshold_db = float(threshold_db)
        self.n_fft = 1 << int(np.ceil(np.log2(self.n_lags + 2 * _PAD)))
        self._k = np.fft.fftfreq(self.n_fft) * self.n_fft
        self.deltas = (np.arange(_N_FRAC) - _N_FRAC // 2) / _N_FRAC
        self.responses = self._responses(pulse_at)
        fit = self.responses[:, _PAD - _FIT : _PAD + _FIT + 1]
        self._fit_energy = np.sum(np.abs(fit) ** 2, axis=1)
        self._fit = np.conj(fit) / self._fit_energy[:, None]
        # The other pulse of the PRI (an ATC radar's short pulse, at a known delay after the long one)
        # leaks through the filter: its direct path is blanked, i.e. its few raw samples' contribution
        # to the filter output is subtracted (the filter is linear). Echoes lose those microseconds only.
        self.blank: tuple[int, int] | None = None  # (first raw sample, width) of the companion pulse
        if companion is not None:
            delay, width = companion
            first = int(np.floor(delay * self.fs)) - 2
            self.blank = (first, int(np.ceil(width * self.fs)) + 5)
        taps_len = self.pulse.size
        self._n_corr = 1 << int(np.ceil(np.log2(self.n_fft + 2 * taps_len)))
        q = self.pulse * (hann(taps_len, sym=False)[::-1] if window == "hann" else 1.0)  # h reversed
        self._q_spec = np.conj(np.fft.fft(q, self._n_corr))

    def _responses(
        self, pulse_at: Callable[[np.ndarray], np.ndarray] | None, extra: int | None = None
    ) -> np.ndarray:
        """Filter output (lags -_PAD .. n_fft - _PAD) for the pulse delayed by each grid fraction."""
        n = self.pulse.size
        m = n + 1
        out = np.empty((self.deltas.size, self.n_fft), np.complex128)
        spectrum = np.fft.fft(self.pulse, 2 * n)
        freq = np.fft.fftfreq(2 * n)
        for i, delta in enumerate(self.deltas):
            if pulse_at is not None:
                shifted = np.asarray(pulse_at((np.arange(m) - delta) / self.fs), np.complex128)
            else:
                shifted = np.fft.ifft(spectrum * np.exp(-2j * np.pi * freq * delta))[:m]
            x = np.zeros(_PAD + n + self.n_fft + m, np.complex128)
            x[_PAD : _PAD + m] = shifted
            out[i] = matched_filter(x, self.pulse, self.window, align="start")[: self.n_fft]
        return out

    def _blanked(self, x: np.ndarray, peaks: np.ndarray) -> np.ndarray:
        """Filter output (segment lags) of just the companion pulse's raw samples, per pulse."""
        assert self.blank is not None  # blanked only with a companion pulse
        first, width = self.blank
        at = peaks[:, None] + first + np.arange(width)[None, :]
        ok = (at >= 0) & (at < x.size)
        snippet = np.where(ok, x[np.clip(at, 0, x.size - 1)], 0)
        block = np.zeros((peaks.size, self._n_corr), np.complex128)
        offset = first + _PAD  # the snippet's first sample, counted from the segment's first lag
        block[:, offset : offset + width] = snippet
        corr = np.fft.ifft(np.fft.fft(block, axis=1) * self._q_spec[None, :], axis=1)
        return corr[:, : self.n_fft]

    @property
    def front(self) -> int:
        """Samples before each chunk given to :meth:`process` (a PRI's worth and the pulse)."""
        return self.min_separation + self.pulse.size + _PAD

    @property
    def overlap(self) -> int:
        """Samples after each chunk the filter and the last pulse's profile need."""
        return self.n_fft + self.pulse.size

    def process(self, start: int, x: np.ndarray, chunk: int | None = None) -> PulseProfiles:
        """Profiles of the pulses whose direct path arrives in ``x[front : front + chunk]``.

        ``x`` holds the recording from sample ``start - front`` (zeros before sample 0; ``front`` is
        :attr:`front`) and at least ``overlap`` samples beyond the chunk (fewer at the recording's end:
        pulses too close to the end are dropped). The front lets the pulse finder see the previous
        direct path, so a chunk never starts with that pulse's tail taken for a pulse.
        """
        chunk = x.size if chunk is None else int(chunk)
        y = matched_filter(x, self.pulse, self.window, align="start")
        mag = np.abs(y)
        threshold = self.threshold
        if threshold is None:
            threshold = float(np.median(mag)) * 10 ** (self.threshold_db / 20)
        peaks = find_direct_pulses(mag, self.min_separation, threshold)
        f = self.front
        peaks = peaks[(peaks >= f) & (peaks < f + chunk) & (peaks - _PAD + self.n_fft <= y.size)]
        if peaks.size == 0:
            empty = np.zeros((0, self.n_lags), np.complex64)
            return PulseProfiles(np.zeros(0), np.zeros(0, np.complex128), empty)
        segments = y[(peaks - _PAD)[:, None] + np.arange(self.n_fft)[None, :]]
        if self.blank is not None:
            segments = segments - self._blanked(x, peaks)
        near = segments[:, _PAD - _FIT : _PAD + _FIT + 1]
        coef = near @ self._fit.T  # least-squares amplitude for every fractional delay
        explained = np.abs(coef) ** 2 * self._fit_energy[None, :]
        best = np.clip(np.argmax(explained, axis=1), 1, self.deltas.size - 2)
        rows = np.arange(peaks.size)
        # Between grid points: a parabola through the explained energies, the response interpolated
        # quadratically (the residue then falls with the square of the grid step).
        e0, e1, e2 = (explained[rows, best + k] for k in (-1, 0, 1))
        den = e0 - 2 * e1 + e2
        u = np.clip(np.where(den < 0, 0.5 * (e0 - e2) / np.where(den < 0, den, -1.0), 0.0), -0.5, 0.5)
        r0, r1, r2 = (self.responses[best + k] for k in (-1, 0, 1))
        response = r1 + 0.5 * u[:, None] * (r2 - r0) + 0.5 * (u**2)[:, None] * (r2 - 2 * r1 + r0)
        fit = response[:, _PAD - _FIT : _PAD + _FIT + 1]
        amplitude = np.sum(np.conj(fit) * near, axis=1) / np.sum(np.abs(fit) ** 2, axis=1)
        frac = self.deltas[best] + u / _N_FRAC
        segments = segments - amplitude[:, None] * response
        # A shift by a fraction of a sample is a linear phase across the spectrum.
        ramp = np.exp(2j * np.pi * np.outer(frac, self._k) / self.n_fft)
        profiles = np.fft.ifft(np.fft.fft(segments, axis=1) * ramp, axis=1)[:, _PAD : _PAD + self.n_lags]
        profiles *= (np.conj(amplitude) / np.maximum(np.abs(amplitude), 1e-30))[:, None]
        times = (start - f + peaks + frac) / self.fs
        return PulseProfiles(times, amplitude, profiles.astype(np.complex64))

    def stream(self, chunks: Iterable[tuple[int, np.ndarray, int]]) -> Iterator[PulseProfiles]:
        """:meth:`process` over ``(start, samples, chunk_length)`` triples."""
        for start, x, chunk in chunks:
            yield self.process(start, x, chunk)

    def taps(self) -> np.ndarray:
        """The filter's impulse response (pulse conjugated, reversed, windowed)."""
        return filter_taps(self.pulse, self.window)


def read_chunks(
    recording, chunk_samples: int, overlap: int, front: int
) -> Iterator[tuple[int, np.ndarray, int]]:
    """``(start, samples from start - front, chunk length)`` over a recording with ``read(start, count)``.

    Parameters
    ----------
    recording : object
        Has ``n_samples`` and ``read(start, count)`` (fewer samples at the end), as
        :class:`~skyradar.io.sigmf_io.IqRecording`.
    chunk_samples : int
        Samples per chunk.
    overlap : int
        Samples read past each chunk's end.
    front : int
        Samples read before each chunk's start; zeros before sample 0.

    Yields
    ------
    (int, ndarray, int)
        The chunk's first sample, the samples from ``start - front`` to ``start + chunk + overlap``
        (fewer at the end) and the chunk's length.

    Examples
    --------
    >>> class Ramp:
    ...     n_samples = 10
    ...     def read(self, start, count):
    ...         return np.arange(start, min(start + count, self.n_samples), dtype=np.float32)
    >>> for start, x, n in read_chunks(Ramp(), 4, 2, 1):
    ...     print(start, x.tolist(), n)
    0 [0.0, 0.0, 1.0, 2.0, 3.0, 4.0, 5.0] 4
    4 [3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0] 4
    8 [7.0, 8.0, 9.0] 2
    """
    n = int(recording.n_samples)
    for start in range(0, n, chunk_samples):
        lo = start - front
        x = recording.read(max(lo, 0), chunk_samples + overlap + min(lo, 0) + front)
        if lo < 0:
            x = np.concatenate([np.zeros(-lo, x.dtype), x])
        yield start, x, min(chunk_samples, n - start)
