"""Checks on frames as they are read: frame times that move forward, samples that are numbers.

A NaN or inf sample spreads through every FFT, CFAR window and estimate it touches and comes
out as silently wrong detections or states; a repeated or backward frame time breaks every
tracker and filter that divides by the frame interval. Readers call these per chunk, so the
error names the file and the first bad frame without holding the whole run in memory.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from skyradar.errors import InputError

__all__ = ["MAX_TIME_S", "check_frame_times", "check_finite_frames"]

# Frame and table times stay within +-1e10 s (elapsed seconds, or unix seconds for 300 years): beyond,
# they are no clock's reading, and the steps between frames overflow in the filters' powers of dt.
MAX_TIME_S = 1.0e10


def check_frame_times(
    times_s: np.ndarray, source: str | Path, field: str = "time", index_name: str = "frame"
) -> np.ndarray:
    """``times_s`` as floats if finite and strictly increasing, else :class:`InputError`.

    The message names the first bad element as ``index_name`` (a frame, or a table's row).

    Examples
    --------
    >>> check_frame_times(np.array([0.0, 0.1, 0.2]), "run.zarr")
    array([0. , 0.1, 0.2])
    >>> check_frame_times(np.array([0.0, 0.1, 0.1]), "run.zarr")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: run.zarr: field 'time' does not increase at frame 2 (0.1 -> 0.1 s)
    """
    t = np.asarray(times_s, dtype=float).ravel()
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise InputError(
            f"{source}: field '{field}' is not a finite number at {index_name} {bad[0]} (got {t[bad[0]]})"
        )
    far = np.flatnonzero(np.abs(t) > MAX_TIME_S)
    if far.size:  # 1e308 is finite, and no clock's reading: the frame steps would overflow
        raise InputError(
            f"{source}: field '{field}' is {t[far[0]]:g} s at {index_name} {far[0]}, "
            f"beyond +-{MAX_TIME_S:g} s"
        )
    back = np.flatnonzero(np.diff(t) <= 0.0)
    if back.size:
        i = int(back[0]) + 1
        raise InputError(
            f"{source}: field '{field}' does not increase at {index_name} {i} ({t[i - 1]:g} -> {t[i]:g} s)"
        )
    return t


def check_finite_frames(block: np.ndarray, first_frame: int, source: str | Path, field: str = "iq") -> None:
    """Raise :class:`InputError` naming the first frame of ``block`` holding a NaN or inf.

    ``block`` holds frames ``first_frame, first_frame + 1, ...`` along its first axis.

    Examples
    --------
    >>> block = np.zeros((3, 4, 2), np.complex64)
    >>> check_finite_frames(block, 10, "run.zarr")
    >>> block[1, 2, 0] = np.nan
    >>> check_finite_frames(block, 10, "run.zarr")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: run.zarr: field 'iq' has a non-finite value (nan) in frame 11
    """
    finite = np.isfinite(block)
    if finite.all():
        return
    per_frame = finite.reshape(finite.shape[0], -1).all(axis=1)
    k = int(np.flatnonzero(~per_frame)[0])
    value = np.asarray(block[k]).ravel()[np.flatnonzero(~finite[k].ravel())[0]]
    kind = "nan" if np.isnan(value) else "inf"
    raise InputError(f"{source}: field '{field}' has a non-finite value ({kind}) in frame {first_frame + k}")
