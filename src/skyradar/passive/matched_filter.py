"""Matched filter for a pulsed illuminator: FFT convolution with the conjugate, time-reversed pulse.

The thesis (Maas 2022, ch. 7) writes the filter as ``y[n] = sum_m s[n-m] h[m]`` with ``h`` the complex
conjugate of the (time-reversed) pulse, optionally tapered by a Hann window ``w[m] = sin^2(pi m / N)``
that narrows the peak's skirts and lowers the range sidelobes. Its test pulse is a 0.1 ms linear FM,
``f(t) = 5.0 MHz - 7.0 GHz/s * t``, present from 0.1 to 0.2 ms; the filter output peaks mid-pulse at
0.15 ms, and a 0.01-amplitude copy 0.02 ms later stands out only with the Hann window.
"""

from __future__ import annotations

import numpy as np
from scipy import signal

from skyradar.errors import InputError

__all__ = ["lfm_pulse", "thesis_test_pulse", "filter_taps", "matched_filter", "autocorrelation"]


def lfm_pulse(
    sample_rate_hz: float, width_s: float, start_hz: float, chirp_rate_hz_per_s: float
) -> np.ndarray:
    """Complex linear-FM pulse ``exp(i 2 pi (f0 t + k t^2 / 2))`` sampled at ``t = n / fs``.

    Examples
    --------
    >>> p = lfm_pulse(20e6, 1e-4, 5.0e6, -7.0e9)
    >>> p.shape, p.dtype, float(abs(p).max())
    ((2000,), dtype('complex128'), 1.0)
    """
    n = int(round(width_s * sample_rate_hz))
    if n < 1:
        raise InputError(f"pulse: width {width_s} s is shorter than one sample at {sample_rate_hz} Hz")
    t = np.arange(n) / sample_rate_hz
    return np.exp(2j * np.pi * (start_hz * t + 0.5 * chirp_rate_hz_per_s * t**2))


def thesis_test_pulse(sample_rate_hz: float = 20e6) -> tuple[np.ndarray, np.ndarray]:
    """The thesis' test signal: times (s, 0-0.3 ms) and the 0.1 ms LFM present from 0.1 to 0.2 ms.

    Examples
    --------
    >>> t, s = thesis_test_pulse(20e6)
    >>> len(t), round(float(t[np.flatnonzero(s)[0]]) * 1e3, 3)
    (6000, 0.1)
    """
    t = np.arange(int(round(3e-4 * sample_rate_hz))) / sample_rate_hz
    s = np.zeros(t.size, complex)
    start = int(round(1e-4 * sample_rate_hz))
    pulse = lfm_pulse(sample_rate_hz, 1e-4, 5.0e6, -7.0e9)
    s[start : start + pulse.size] = pulse
    return t, s


def filter_taps(pulse: np.ndarray, window: str | None = None) -> np.ndarray:
    """Impulse response ``h[m] = w[m] conj(p[N-1-m])``; ``window`` None or ``"hann"`` (sin^2(pi m/N)).

    Parameters
    ----------
    pulse : ndarray
        The transmitted pulse's samples (1-D, complex).
    window : str, optional
        ``None`` (or ``"none"``) for no taper, ``"hann"`` for ``w[m] = sin^2(pi m / N)``.

    Returns
    -------
    ndarray
        The ``N`` filter taps (complex128).

    Examples
    --------
    >>> np.round(filter_taps(np.array([1, 2j, 3])), 3).tolist()
    [(3-0j), -2j, (1-0j)]
    >>> np.round(filter_taps(np.array([1, 2j, 3]), "hann"), 3).tolist()  # w = [0, 0.75, 0.75]
    [0j, -1.5j, (0.75+0j)]
    """
    pulse = np.asarray(pulse)
    if pulse.ndim != 1 or pulse.size == 0:
        raise InputError(f"matched filter: pulse must be a non-empty 1-D array, got shape {pulse.shape}")
    taps = np.conj(pulse[::-1]).astype(np.complex128)
    if window is None or window == "none":
        return taps
    if window != "hann":
        raise InputError(f"matched filter: window must be 'hann' or none, got {window!r}")
    return taps * signal.windows.hann(pulse.size, sym=False)


def matched_filter(
    x: np.ndarray, pulse: np.ndarray, window: str | None = None, align: str = "centre"
) -> np.ndarray:
    """Matched-filter ``x`` with ``pulse`` (FFT overlap-add, :func:`scipy.signal.oaconvolve`).

    ``align="centre"`` returns ``len(x)`` samples with the peak of a pulse at the pulse's middle
    (the thesis' convention: 0.15 ms for a pulse from 0.1 to 0.2 ms); ``align="start"`` returns the
    correlation ``z[n] = sum_m x[n+m] w[m'] conj(p[m])`` for every ``n`` where the pulse fits
    (``len(x) - len(pulse) + 1`` samples), peaking at the sample where a pulse starts.

    Examples
    --------
    >>> t, s = thesis_test_pulse(20e6)
    >>> y = matched_filter(s, lfm_pulse(20e6, 1e-4, 5.0e6, -7.0e9))
    >>> round(float(t[np.argmax(abs(y))]) * 1e3, 3)
    0.15
    """
    taps = filter_taps(pulse, window)
    x = np.asarray(x)
    if align == "start":
        if x.size < taps.size:
            return np.zeros(0, np.complex128)
        return signal.oaconvolve(x, taps, mode="valid")
    if align != "centre":
        raise InputError(f"matched filter: align must be 'centre' or 'start', got {align!r}")
    return signal.oaconvolve(x, taps, mode="same")


def autocorrelation(pulse: np.ndarray, window: str | None = None, lags: int | None = None) -> np.ndarray:
    """Filter output for the pulse itself at lags ``0 .. lags-1`` after its start, normalised to 1 at 0.

    This is the shape a direct-path pulse leaves in the ``align="start"`` output; subtracting it scaled
    by the direct path's complex amplitude removes the direct path's range sidelobes.

    Examples
    --------
    >>> acf = autocorrelation(lfm_pulse(5e6, 1e-5, 0.0, 1e11), lags=3)
    >>> complex(acf[0])
    (1+0j)
    """
    pulse = np.asarray(pulse, np.complex128)
    lags = pulse.size if lags is None else int(lags)
    padded = np.concatenate([pulse, np.zeros(lags, np.complex128)])
    full = matched_filter(padded, pulse, window, align="start")
    out = np.zeros(lags, np.complex128)
    take = min(lags, full.size)
    out[:take] = full[:take]
    return out / out[0]
