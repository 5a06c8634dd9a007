"""Cell-averaging CFAR on power maps of any dimension (range, Doppler x range, ...).

The noise level at each cell is the mean power of a box of training cells around it, leaving out a
smaller guard box (the target's own spread). With ``n`` training cells of exponentially distributed
noise power, the threshold ``alpha * noise`` with ``alpha = n (pfa^(-1/n) - 1)`` gives the false-alarm
probability ``pfa`` (Richards, Fundamentals of Radar Signal Processing, eq. 6.17). Oversampled maps
(neighbouring cells correlated, as after a matched filter sampled faster than its bandwidth) have fewer
independent training cells than cells: ``cells_per_independent`` divides ``n`` in the threshold, else
the noise estimate is noisier than the design assumes and false alarms come orders of magnitude more
often.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from skyradar.errors import InputError

__all__ = ["ca_threshold_factor", "ca_cfar_noise", "ca_cfar", "local_peaks"]


def ca_threshold_factor(n_train: int, pfa: float) -> float:
    """Threshold multiplier for ``n_train`` averaged cells and false-alarm probability ``pfa``.

    Examples
    --------
    >>> round(ca_threshold_factor(16, 1e-6), 2)
    21.94
    """
    if not 0.0 < pfa < 1.0:
        raise InputError(f"CFAR: pfa must be in (0, 1), got {pfa}")
    return float(n_train * (pfa ** (-1.0 / n_train) - 1.0))


def _box(shape: int | tuple[int, ...], ndim: int) -> tuple[int, ...]:
    sizes = (shape,) * ndim if isinstance(shape, int | float | np.number) else tuple(shape)
    if len(sizes) != ndim:
        raise InputError(f"CFAR: window {shape} does not match a {ndim}-D map")
    return tuple(int(s) for s in sizes)


def ca_cfar_noise(
    power: np.ndarray,
    guard: int | tuple[int, ...],
    train: int | tuple[int, ...],
    mode: str | tuple[str, ...] = "reflect",
) -> tuple[np.ndarray, int]:
    """Mean power of the training cells around each cell and their number.

    Parameters
    ----------
    power : ndarray
        Power map (linear), any number of dimensions.
    guard, train : int or tuple of int
        Half-widths in cells, one for every axis or one per axis: the outer box spans
        ``guard + train`` cells on each side, the excluded inner box ``guard``.
    mode : str or tuple of str
        Edge handling (:func:`scipy.ndimage.uniform_filter`): mirrored by default (``"reflect"``);
        per axis, ``"wrap"`` for a circular axis such as Doppler.

    Returns
    -------
    noise : ndarray
        Mean training-cell power at each cell (the shape of ``power``).
    n_train : int
        Number of training cells per cell.

    Examples
    --------
    Guard 1 and train 2: 7 cells in the box, 3 left out, 4 training cells. A spike inside the guard
    box is left out; two cells away it is a training cell and raises the estimate to (3 + 101) / 4.

    >>> p = np.ones(11); p[5] = 101.0
    >>> noise, n_train = ca_cfar_noise(p, 1, 2)
    >>> n_train, noise[[5, 7]].tolist()
    (4, [1.0, 26.0])
    """
    power = np.asarray(power, dtype=float)
    g = _box(guard, power.ndim)
    t = _box(train, power.ndim)
    outer = tuple(2 * (gi + ti) + 1 for gi, ti in zip(g, t, strict=True))
    inner = tuple(2 * gi + 1 for gi in g)
    n_outer, n_inner = int(np.prod(outer)), int(np.prod(inner))
    n_train = n_outer - n_inner
    if n_train < 1:
        raise InputError(f"CFAR: no training cells with guard {guard} and train {train}")
    total = ndimage.uniform_filter(power, outer, mode=mode) * n_outer
    guard_sum = ndimage.uniform_filter(power, inner, mode=mode) * n_inner
    return np.maximum(total - guard_sum, 0.0) / n_train, n_train


def ca_cfar(
    power: np.ndarray,
    guard: int | tuple[int, ...],
    train: int | tuple[int, ...],
    pfa: float,
    mode: str | tuple[str, ...] = "reflect",
    cells_per_independent: float = 1.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Detections (boolean map) and signal-to-noise ratio (linear) of a CA-CFAR.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> p = rng.exponential(1.0, 2000); p[700] = 200.0
    >>> hits, snr = ca_cfar(p, 2, 16, 1e-6)
    >>> np.flatnonzero(hits).tolist()
    [700]
    """
    noise, n_train = ca_cfar_noise(power, guard, train, mode)
    snr = np.asarray(power, dtype=float) / np.maximum(noise, 1e-300)
    n_independent = max(1, int(n_train / max(cells_per_independent, 1.0)))
    return snr > ca_threshold_factor(n_independent, pfa), snr


def local_peaks(hits: np.ndarray, snr: np.ndarray, batch: bool = False) -> list[tuple[int, ...]]:
    """One cell per connected group of hits: where the SNR is largest (a target spread over cells).

    With ``batch`` the first axis indexes separate maps: groups never join across it.

    Examples
    --------
    >>> hits = np.array([0, 1, 1, 0, 1], bool); snr = np.array([0, 2.0, 3.0, 0, 1.0])
    >>> local_peaks(hits, snr)
    [(2,), (4,)]
    """
    if not hits.any():
        return []
    structure = ndimage.generate_binary_structure(hits.ndim, 1)
    if batch:
        structure[0] = structure[2] = False
    labels, _ = ndimage.label(hits, structure)
    out = []
    for i, box in enumerate(ndimage.find_objects(labels), start=1):
        masked = np.where(labels[box] == i, snr[box], -np.inf)
        local = np.unravel_index(int(np.argmax(masked)), masked.shape)
        out.append(tuple(int(sl.start + j) for sl, j in zip(box, local, strict=True)))
    return out
