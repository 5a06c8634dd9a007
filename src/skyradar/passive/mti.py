"""Clutter cancellation over pulses and coherent integration over the dwell.

The rows of a *profile matrix* are the matched-filter outputs of successive pulses, each starting at
its direct-path arrival and phase-referenced to it; the columns are bistatic delays. A static
reflector then gives the same complex value in every row (scaled only by the slowly changing beam
gain), a moving one a phase that turns by ``2 pi f_D t``. Cancellation removes what does not turn:

- ``"mti2"``/``"mti3"``/``"mti4"``: two-, three- and four-pulse cancellers. Given the pulse times they
  are divided differences (weights ``1 / prod_{i != j} (t_j - t_i)``, scaled to the binomial
  ``1, -2, 1`` for even spacing): they null any polynomial in time up to degree 0, 1, 2, so the beam's
  smooth sweep over a static reflector cancels even with PRF stagger (plain binomial weights on uneven
  pulses leave the beam slope times the stagger, which lands at PRF/4 and PRF/2);
- ``"eca"``: ECA over pulses, the least-squares projection out of a low-order polynomial in slow time
  (order 0 is the zero-Doppler subspace of ECA (Colone et al. 2009) with the pulses as the batch).

Coherent integration over the pulses that see one direction is a discrete Fourier transform at the
pulses' actual times (the PRF stagger makes them uneven), Hann-tapered.
"""

from __future__ import annotations

import numpy as np

from skyradar.errors import InputError

__all__ = ["cancel_static", "difference_weights", "doppler_spectrum", "dwell_pulses"]


_CANCELLERS = {"mti2": 1, "mti3": 2, "mti4": 3}


def difference_weights(times_s: np.ndarray, k: int) -> np.ndarray:
    """Divided-difference weights over ``k + 1`` consecutive pulses: (..., n - k, k + 1).

    Scaled by ``k! T^k`` (``T`` the mean spacing) so that even spacing gives the binomial canceller.

    Examples
    --------
    >>> np.round(difference_weights(np.arange(4) * 1e-3, 2), 6).tolist()
    [[1.0, -2.0, 1.0], [1.0, -2.0, 1.0]]
    >>> w = difference_weights(np.array([0.0, 1.0, 2.1, 3.0]), 2)
    >>> bool(np.allclose(w @ np.ones(3), 0) and np.allclose(w[0] @ [0.0, 1.0, 2.1], 0))
    True
    """
    t = np.asarray(times_s, dtype=float)
    n = t.shape[-1] - k
    win = np.stack([t[..., j : j + n] for j in range(k + 1)], axis=-1)  # (..., n, k + 1)
    diff = win[..., :, None] - win[..., None, :]
    diff = np.where(np.eye(k + 1, dtype=bool), 1.0, diff)
    spacing = (t[..., -1] - t[..., 0]) / (t.shape[-1] - 1)
    scale = float(np.prod(np.arange(1, k + 1))) * np.asarray(spacing)[..., None, None] ** k
    return scale / np.prod(diff, axis=-1)


def cancel_static(
    profiles: np.ndarray, method: str = "mti3", order: int = 1, times_s: np.ndarray | None = None
) -> np.ndarray:
    """Remove static returns from a (pulses, delays) profile matrix.

    ``"mti2"``, ``"mti3"``, ``"mti4"`` return 1, 2, 3 rows fewer (divided differences at
    ``times_s`` if given, binomial weights otherwise); ``"eca"`` keeps the shape.

    Examples
    --------
    >>> static = np.ones((6, 2), complex) * [3.0, 1j]
    >>> [float(abs(cancel_static(static, m)).max()) for m in ("mti2", "mti3", "eca")]
    [0.0, 0.0, 0.0]
    >>> moving = np.exp(1j * np.pi * np.arange(6))[:, None] * np.ones((1, 2))
    >>> cancel_static(moving, "mti3")[0].real.tolist()
    [4.0, 4.0]
    """
    p = np.asarray(profiles)
    if p.ndim != 2:
        raise InputError(f"MTI: profiles must be (pulses, delays), got shape {p.shape}")
    if method in _CANCELLERS:
        k = _CANCELLERS[method]
        t = np.arange(p.shape[0], dtype=float) if times_s is None else times_s
        w = difference_weights(t, k)
        return sum(w[:, j, None] * p[j : j + p.shape[0] - k] for j in range(k + 1))
    if method != "eca":
        raise InputError(f"MTI: method must be 'mti2', 'mti3', 'mti4' or 'eca', got {method!r}")
    n = p.shape[0]
    if n <= order + 1:
        raise InputError(f"MTI: ECA of order {order} needs more than {order + 1} pulses, got {n}")
    x = np.linspace(-1.0, 1.0, n)
    basis, _ = np.linalg.qr(np.vander(x, order + 1, increasing=True))
    return p - basis @ (basis.T @ p)


def doppler_spectrum(
    profiles: np.ndarray, times_s: np.ndarray, doppler_hz: np.ndarray, taper: str | None = "hann"
) -> np.ndarray:
    """Coherent sum ``sum_p w_p P[p, :] exp(-i 2 pi f t_p)`` for each ``f`` in ``doppler_hz``.

    Returns (Doppler, delays). Times are taken relative to their mean so the phase of a zero-Doppler
    sum does not depend on when the dwell happened. The taper ``w`` (Hann or none) sums to the number
    of pulses, so a static unit return integrates to ``n`` at 0 Hz with either taper.

    Examples
    --------
    >>> t = np.array([0.0, 1.0e-3, 2.1e-3, 3.0e-3])
    >>> p = np.exp(2j * np.pi * 250.0 * t)[:, None]
    >>> s = doppler_spectrum(p, t, np.array([0.0, 250.0]), taper=None)
    >>> np.round(abs(s[:, 0]), 6).tolist()[1]
    4.0
    """
    p = np.asarray(profiles, dtype=np.complex128)  # one dtype: the product then runs in BLAS
    t = np.asarray(times_s, dtype=float)
    if t.shape[0] != p.shape[0]:
        raise InputError(f"Doppler: {t.shape[0]} times for {p.shape[0]} pulses")
    n = t.size
    w = np.hanning(n + 2)[1:-1] if taper == "hann" else np.ones(n)
    w = w * (n / w.sum())
    steer = np.exp(-2j * np.pi * np.outer(np.asarray(doppler_hz, dtype=float), t - t.mean()))
    return (steer * w[None, :]) @ p


def dwell_pulses(beamwidth_rad: float, rotation_rate_rad_s: float, pri_s: float) -> int:
    """Pulses while the beam sweeps one beamwidth (at least 3).

    Examples
    --------
    >>> dwell_pulses(np.radians(1.4), 2 * np.pi * 13.5 / 60, 1.0125e-3)
    17
    """
    return max(3, int(round(beamwidth_rad / (abs(rotation_rate_rad_s) * pri_s))))
