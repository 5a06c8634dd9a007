"""Direct-path pulses of a rotating illuminator: find them, estimate the pulse, and the scan phase.

The receiver hears every transmitted pulse directly (through the radar's sidelobes most of the time,
through the main beam once per rotation). Their arrival times give the pulse timing (PRF stagger
included); the once-per-rotation maximum of their amplitude is the moment the main beam sweeps the
receiver, when the beam azimuth equals the bearing from the illuminator to the receiver. With the
rotation period that fixes the beam's azimuth at every pulse.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage, signal

from skyradar.errors import InputError

__all__ = ["find_direct_pulses", "refine_peaks", "estimate_pulse", "ScanPhase", "scan_phase"]


def find_direct_pulses(mf_abs: np.ndarray, min_separation: int, threshold: float) -> np.ndarray:
    """Indices of the direct-path pulses in a matched-filter magnitude: the strongest peak per PRI.

    A peak counts when it is the largest within ``min_separation`` samples (a bit less than the
    shortest PRI) and above ``threshold``. Echoes and short pulses are weaker than the direct path
    within a PRI, so they lose to it.

    Examples
    --------
    >>> y = np.zeros(100); y[[10, 14, 60]] = [5.0, 2.0, 4.0]
    >>> find_direct_pulses(y, 30, 1.0).tolist()
    [10, 60]
    """
    peaks, _ = signal.find_peaks(mf_abs, height=threshold, distance=max(1, int(min_separation)))
    return peaks


def refine_peaks(y: np.ndarray, peaks: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Fractional offset (samples, in [-0.5, 0.5]) and complex value of each peak of ``y``.

    The offset is the vertex of the parabola through the log-magnitudes of the peak and its two
    neighbours (exact for a Gaussian main lobe, close for a Hann-weighted compressed chirp); the
    complex value is ``y`` interpolated there with the same parabola.

    Examples
    --------
    >>> n = np.arange(20.0)
    >>> frac, value = refine_peaks(np.exp(-((n - 10.3) ** 2) / 4).astype(complex), np.array([10]))
    >>> round(float(frac[0]), 3), round(abs(complex(value[0])), 3)
    (0.3, 1.0)
    """
    peaks = np.asarray(peaks, dtype=np.int64)
    inner = np.clip(peaks, 1, max(1, len(y) - 2))
    a, b, c = (np.log(np.abs(y[inner + k]) + 1e-30) for k in (-1, 0, 1))
    den = a - 2 * b + c
    frac = np.where(den < 0, 0.5 * (a - c) / np.where(den < 0, den, -1.0), 0.0)
    frac = np.clip(frac, -0.5, 0.5)
    # Lagrange (parabolic) interpolation of the complex samples.
    ya, yb, yc = (y[inner + k] for k in (-1, 0, 1))
    value = yb + 0.5 * frac * (yc - ya) + 0.5 * frac**2 * (yc - 2 * yb + ya)
    mag = np.exp(b - 0.25 * (a - c) * frac)
    value = mag * np.exp(1j * np.angle(value))
    return frac, value


def estimate_pulse(x: np.ndarray, width_samples: int) -> np.ndarray:
    """The recording's strongest ``width_samples``-long burst, as a unit-energy template.

    Use a block that holds a main-beam pass (the direct path's signal-to-noise ratio is highest
    there). The window is the one with the largest energy, so a short pulse next to the long one
    does not shift it.

    Examples
    --------
    >>> x = np.full(300, 1e-3, complex); x[100:150] = np.exp(1j * np.arange(50) * 0.3)
    >>> p = estimate_pulse(x, 50)
    >>> p.size, round(float(np.vdot(p, p).real), 6), round(float(np.angle(p[1] / p[0])), 3)
    (50, 1.0, 0.3)
    """
    width_samples = int(width_samples)
    if width_samples < 2 or x.size < width_samples:
        raise InputError(f"pulse estimate: need at least {width_samples} samples of recording, got {x.size}")
    energy = np.convolve(np.abs(x) ** 2, np.ones(width_samples), mode="valid")
    start = int(np.argmax(energy))
    pulse = np.asarray(x[start : start + width_samples], np.complex128)
    return pulse / np.sqrt(np.vdot(pulse, pulse).real)


@dataclass(frozen=True)
class ScanPhase:
    """Beam azimuth over time from the main-beam crossings of the receiver.

    Attributes
    ----------
    crossings_s : ndarray
        Times the main beam points at the receiver (on the recording's clock, as seen by the direct
        path), s, increasing.
    period_s : float
        Rotation period, s.
    bearing_rad : float
        Azimuth of the receiver from the illuminator (clockwise from north), rad.
    direction : int
        +1 clockwise, -1 counter-clockwise.

    Examples
    --------
    Crossings at 1 s and 5 s: sweep 0 runs to 3 s, sweep 1 to 7 s.

    >>> ScanPhase(np.array([1.0, 5.0]), 4.0, 0.0).sweep([0.0, 2.9, 3.1, 7.1]).tolist()
    [0, 0, 1, 2]
    """

    crossings_s: np.ndarray
    period_s: float
    bearing_rad: float
    direction: int = 1

    def azimuth_rad(self, t_s: np.ndarray | float) -> np.ndarray:
        """Beam azimuth at times ``t_s`` (radians in [0, 2 pi)), phased on the nearest crossing.

        Examples
        --------
        >>> sp = ScanPhase(np.array([1.0, 5.0]), 4.0, 0.0)
        >>> np.round(np.degrees(sp.azimuth_rad([1.0, 2.0, 4.5])), 6).tolist()
        [0.0, 90.0, 315.0]
        """
        t = np.asarray(t_s, dtype=float)
        nearest = self.crossings_s[self._nearest(t)]
        rate = self.direction * 2 * np.pi / self.period_s
        return np.mod(self.bearing_rad + rate * (t - nearest), 2 * np.pi)

    def sweep(self, t_s: np.ndarray | float) -> np.ndarray:
        """Sweep number: 0 until half a period after the first crossing, then +1 per rotation.

        A sweep is one rotation centred on a main-beam crossing of the receiver, so the beam's
        whole circle around the receiver's bearing falls into one sweep.
        """
        t = np.asarray(t_s, dtype=float)
        return np.floor((t - self.crossings_s[0]) / self.period_s + 0.5).astype(np.int64)

    def _nearest(self, t: np.ndarray) -> np.ndarray:
        idx = np.searchsorted(self.crossings_s, t)
        lo = np.clip(idx - 1, 0, self.crossings_s.size - 1)
        hi = np.clip(idx, 0, self.crossings_s.size - 1)
        return np.where(np.abs(t - self.crossings_s[lo]) <= np.abs(t - self.crossings_s[hi]), lo, hi)


def scan_phase(
    times_s: np.ndarray,
    amplitudes: np.ndarray,
    period_hint_s: float,
    bearing_rad: float,
    direction: int = 1,
    source: str = "recording",
) -> ScanPhase:
    """Main-beam crossings from the direct-path amplitude of every pulse.

    The amplitude in dB is smoothed over a few pulses, the crossing is its maximum within each
    rotation (at least 10 dB above the median), refined by a parabola through the dB values (exact
    for a Gaussian main lobe). With two or more crossings the period is their median spacing,
    otherwise ``period_hint_s`` (the illuminator's nominal rotation).

    Parameters
    ----------
    times_s : ndarray
        Arrival time of each direct-path pulse, s (at least 3).
    amplitudes : ndarray
        Direct-path amplitude (or complex value) of each pulse.
    period_hint_s : float
        Nominal rotation period, s: spaces the search for maxima, and is the period with one crossing.
    bearing_rad : float
        Azimuth of the receiver from the illuminator (clockwise from north), rad.
    direction : int
        +1 clockwise, -1 counter-clockwise.
    source : str
        What the pulses come from, named in errors.

    Returns
    -------
    ScanPhase
        The crossings, period, bearing and direction.

    Examples
    --------
    A 4 s rotation whose 1.4 deg Gaussian beam sweeps the receiver at 2 s and 6 s, 1 kHz pulses:

    >>> from skyradar.units import wrap_angle
    >>> t = np.arange(0.0, 10.0, 1e-3)
    >>> off = wrap_angle(2 * np.pi * (t - 2.0) / 4.0)
    >>> amp = 0.01 + np.exp(-4 * np.log(2) * (off / np.radians(1.4)) ** 2)
    >>> sp = scan_phase(t, amp, 4.5, np.radians(250.0))
    >>> np.round(sp.crossings_s, 3).tolist(), round(sp.period_s, 3)
    ([2.0, 6.0], 4.0)
    """
    times_s = np.asarray(times_s, dtype=float)
    db = 20 * np.log10(np.abs(np.asarray(amplitudes)) + 1e-30)
    if times_s.size < 3:
        raise InputError(f"{source}: fewer than 3 direct-path pulses found ({times_s.size}); no scan phase")
    pri = float(np.median(np.diff(times_s)))
    smooth = ndimage.uniform_filter1d(db, 3)
    distance = max(1, int(0.6 * period_hint_s / pri))
    peaks, _ = signal.find_peaks(smooth, height=np.median(smooth) + 10.0, distance=distance)
    if peaks.size == 0:
        raise InputError(
            f"{source}: the main beam never sweeps the receiver (direct-path amplitude varies by "
            f"{float(np.ptp(smooth)):.1f} dB); no scan phase"
        )
    frac, _ = refine_peaks(10 ** (smooth / 20), peaks)
    crossings = np.interp(peaks + frac, np.arange(times_s.size), times_s)
    period = float(np.median(np.diff(crossings))) if crossings.size >= 2 else float(period_hint_s)
    return ScanPhase(crossings, period, float(bearing_rad), int(direction))
