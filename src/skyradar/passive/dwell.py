"""Detection in one dwell: the pulses while the beam crosses one direction.

Two channels over the same (pulses, lags) profile matrix:

- *static*: the coherent mean over the dwell (zero Doppler), CFAR along the lags: buildings, masts,
  clutter (the thesis' urban clusters);
- *moving*: static returns cancelled over pulses (:func:`~skyradar.passive.mti.cancel_static`), then
  integrated coherently at a grid of Doppler shifts, CFAR along the lags of each Doppler row (the
  canceller's gain varies with Doppler, so the noise level is estimated per row); cells within
  ``zero_doppler_guard_hz`` of 0 (the residue of beam-modulated clutter) are not detections.

Each channel yields one candidate per connected group of CFAR hits, at the group's SNR peak with the
lag refined by a parabola through the neighbouring powers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skyradar.passive.cfar import ca_cfar, local_peaks
from skyradar.passive.mti import cancel_static, difference_weights

__all__ = ["DwellSettings", "detect_dwell", "detect_dwells"]


@dataclass(frozen=True)
class DwellSettings:
    """CFAR and cancellation settings (lags and Doppler bins are cells).

    Attributes
    ----------
    min_lag : int
        First lag searched (shorter lags hold the direct path's residue).
    pfa_static, pfa_moving : float
        CFAR false-alarm probability per cell of the static and the moving channel.
    guard_lags, train_lags : int
        CFAR guard and training half-widths along the lags.
    lags_per_independent : float
        Lags per independent noise sample (``cells_per_independent`` of
        :func:`~skyradar.passive.cfar.ca_cfar`).
    cancel : str
        Static-return canceller of the moving channel (``"mti2"``, ``"mti3"``, ``"mti4"``, or another
        method of :func:`~skyradar.passive.mti.cancel_static`).
    doppler_oversample : int
        Doppler grid points per pulse of the dwell.
    zero_doppler_guard_hz : float
        Moving-channel cells within this Doppler shift of 0 are not detections, Hz.

    Examples
    --------
    >>> s = DwellSettings(zero_doppler_guard_hz=100.0)
    >>> s.cancel, s.train_lags, s.zero_doppler_guard_hz
    ('mti3', 40, 100.0)
    """

    min_lag: int = 4
    pfa_static: float = 1e-6
    pfa_moving: float = 1e-10  # 1e-8 left 1-3 false moving detections a sweep on seeds 1 and 2 (of 0-3)
    guard_lags: int = 3
    train_lags: int = 40
    lags_per_independent: float = 1.0
    cancel: str = "mti3"
    doppler_oversample: int = 2
    zero_doppler_guard_hz: float = 0.0


def _refine_lag(power_row: np.ndarray, k: int) -> float:
    if 0 < k < power_row.size - 1:
        a, b, c = np.log(power_row[k - 1 : k + 2] + 1e-300)
        den = a - 2 * b + c
        if den < 0:
            return k + float(np.clip(0.5 * (a - c) / den, -0.5, 0.5))
    return float(k)


def detect_dwell(
    profiles: np.ndarray, times_s: np.ndarray, prf_hz: float, settings: DwellSettings
) -> list[dict]:
    """Candidates (channel, lag, doppler_hz, snr_db, time_s, power_db) in one dwell's profile matrix.

    ``snr_db`` is against the CFAR's local noise estimate, ``power_db`` the cell's power (filter units).

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> t = np.arange(16) * 1e-3
    >>> p = (rng.normal(size=(16, 200)) + 1j * rng.normal(size=(16, 200))) / np.sqrt(2)
    >>> p[:, 50] += 3.0                                        # static
    >>> p[:, 120] += 3.0 * np.exp(2j * np.pi * 300.0 * t)      # moving at 300 Hz
    >>> found = detect_dwell(p, t, 1000.0, DwellSettings(zero_doppler_guard_hz=100.0))
    >>> sorted((c["channel"], round(c["lag"]), round(c["doppler_hz"], -2)) for c in found)
    [('moving', 120, 300.0), ('static', 50, 0.0)]
    """
    return detect_dwells(profiles[None], times_s[None], prf_hz, settings)


def detect_dwells(
    profiles: np.ndarray, times_s: np.ndarray, prf_hz: float, settings: DwellSettings
) -> list[dict]:
    """:func:`detect_dwell` over a batch: ``profiles`` (dwells, pulses, lags), ``times_s`` (dwells, pulses).

    One vectorised pass over all dwells of a chunk (the per-dwell work is small, so Python overhead
    would otherwise dominate).

    Parameters
    ----------
    profiles : ndarray
        Complex pulse profiles, (dwells, pulses, lags).
    times_s : ndarray
        Time of each pulse, s, (dwells, pulses).
    prf_hz : float
        Mean pulse repetition frequency, Hz (sets the Doppler grid's span).
    settings : DwellSettings
        CFAR and cancellation settings.

    Returns
    -------
    list of dict
        The candidates of every dwell, as :func:`detect_dwell`'s; ``time_s`` is the mean pulse time of
        the candidate's dwell, s (moving candidates also carry ``static_db``, the zero-Doppler power
        at their lag).

    Examples
    --------
    Two dwells of 16 pulses; a mover at lag 120 and 300 Hz in the second only:

    >>> rng = np.random.default_rng(1)
    >>> t = np.arange(16) * 1e-3
    >>> p = (rng.normal(size=(2, 16, 200)) + 1j * rng.normal(size=(2, 16, 200))) / np.sqrt(2)
    >>> p[1, :, 120] += 3.0 * np.exp(2j * np.pi * 300.0 * t)
    >>> found = detect_dwells(p, np.stack([t, t + 0.1]), 1000.0, DwellSettings(zero_doppler_guard_hz=100.0))
    >>> (c,) = found
    >>> c["channel"], round(c["lag"]), round(c["doppler_hz"], -2), round(float(c["time_s"]), 4)
    ('moving', 120, 300.0, 0.1075)
    """
    s = settings
    lo = s.min_lag
    t_mid = times_s.mean(axis=1)
    out: list[dict] = []
    static_power = np.abs(profiles[:, :, lo:].mean(axis=1)) ** 2  # (dwells, lags)
    hits, snr = ca_cfar(
        static_power,
        (0, s.guard_lags),
        (0, s.train_lags),
        s.pfa_static,
        cells_per_independent=s.lags_per_independent,
    )
    last = static_power.shape[1] - 1
    for w, k in local_peaks(hits, snr, batch=True):
        if k in (0, last):
            continue  # the group rises towards the blind lags (or beyond the last): its peak lies there
        lag = lo + _refine_lag(static_power[w], k)
        out.append(_candidate("static", lag, 0.0, snr[w, k], t_mid[w], static_power[w, k]))

    n_cut = {"mti2": 1, "mti3": 2, "mti4": 3}.get(s.cancel, 0)
    n = profiles.shape[1] - n_cut
    cancelled = _cancel_batch(profiles[:, :, lo:], times_s, s.cancel)
    t_kept = times_s[:, n_cut // 2 : n_cut // 2 + n]
    n_dop = max(4, s.doppler_oversample * n)
    doppler = (np.arange(n_dop) - n_dop // 2) * (prf_hz / n_dop)
    power = np.abs(_spectra(cancelled, t_kept, doppler)) ** 2  # (dwells, Doppler, lags)
    hits, snr = ca_cfar(
        power,
        (0, 0, s.guard_lags),
        (0, 0, s.train_lags),
        s.pfa_moving,
        cells_per_independent=s.lags_per_independent,
    )
    hits &= (np.abs(doppler) >= s.zero_doppler_guard_hz)[None, :, None]
    static_sum = static_power * profiles.shape[1] ** 2  # the zero-Doppler sum, on the moving power's scale
    for w, d, k in local_peaks(hits, snr, batch=True):
        if k in (0, last):
            continue
        lag = lo + _refine_lag(power[w, d], k)
        cand = _candidate("moving", lag, float(doppler[d]), snr[w, d, k], t_mid[w], power[w, d, k])
        cand["static_db"] = 10 * np.log10(static_sum[w, k] + 1e-300)
        out.append(cand)
    return out


def _cancel_batch(profiles: np.ndarray, times_s: np.ndarray, method: str) -> np.ndarray:
    k = {"mti2": 1, "mti3": 2, "mti4": 3}.get(method)
    if k is None:
        return np.stack([cancel_static(p, method) for p in profiles])
    w = difference_weights(times_s, k).astype(np.float32)  # (dwells, n - k, k + 1)
    n = profiles.shape[1] - k
    return sum(w[:, :, j, None] * profiles[:, j : j + n] for j in range(k + 1))


def _spectra(profiles: np.ndarray, times_s: np.ndarray, doppler_hz: np.ndarray) -> np.ndarray:
    """Batched :func:`~skyradar.passive.mti.doppler_spectrum` (Hann taper)."""
    n = times_s.shape[1]
    w = np.hanning(n + 2)[1:-1]
    w *= n / w.sum()
    rel = times_s - times_s.mean(axis=1, keepdims=True)
    steer = np.exp(-2j * np.pi * doppler_hz[None, :, None] * rel[:, None, :]) * w[None, None, :]
    return np.matmul(steer, profiles.astype(np.complex128))


def _candidate(channel: str, lag: float, doppler_hz: float, snr: float, t: float, power: float) -> dict:
    return {
        "channel": channel,
        "lag": lag,
        "doppler_hz": doppler_hz,
        "snr_db": 10 * np.log10(snr),
        "time_s": t,
        "power_db": 10 * np.log10(power + 1e-300),
    }
