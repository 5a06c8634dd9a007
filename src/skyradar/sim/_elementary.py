"""Branch-free elementary functions for the numba kernels (no vector math library here).

``cis_cycles`` and ``fast_atan2`` replace libm calls that dominated the per-facet cost;
``wrap_index`` replaces an integer modulo (20-40 cycles) where the value is at most one period
out of range.
"""

from __future__ import annotations

import math

import numpy as np
from numba import float32, njit

__all__ = ["cis_cycles", "cis_cycles_f32", "fast_atan2", "wrap_index"]

_F1 = np.float32(1.0)
_SIN_F32 = tuple(np.float32(c) for c in (-1 / 6, 1 / 120, -1 / 5040, 1 / 362880))
_COS_F32 = tuple(np.float32(c) for c in (-1 / 2, 1 / 24, -1 / 720, 1 / 40320))


@njit(inline="always")
def _by_quadrant(c, s, n):
    """(cos, sin) of the angle ``n`` quarter turns past the one whose (cos, sin) is (c, s)."""
    # Selects, not branches: the quadrant of a path phase is random, and the mispredicted
    # branches cost more than the polynomials.
    quadrant = int(n) & 3
    odd = (quadrant & 1) != 0
    cos_q = s if odd else c
    sin_q = c if odd else s
    cos_q = -cos_q if quadrant == 1 or quadrant == 2 else cos_q
    sin_q = -sin_q if quadrant >= 2 else sin_q
    return cos_q, sin_q


@njit(inline="always")
def cis_cycles(x):
    """(cos, sin) of 2*pi*x for any real ``x`` (cycles), error below 1e-9.

    Reduce to the nearest quarter cycle, evaluate Taylor polynomials on [-pi/4, pi/4] and
    rotate by the quadrant: about four times cheaper than libm's fmod + cos + sin, which
    dominated the per-facet cost.
    """
    q = 4.0 * (x - math.floor(x))
    n = math.floor(q + 0.5)
    r = (q - n) * (0.5 * math.pi)
    r2 = r * r
    s = r * (1.0 - r2 / 6.0 * (1.0 - r2 / 20.0 * (1.0 - r2 / 42.0 * (1.0 - r2 / 72.0 * (1.0 - r2 / 110.0)))))
    c = 1.0 - r2 / 2.0 * (
        1.0 - r2 / 12.0 * (1.0 - r2 / 30.0 * (1.0 - r2 / 56.0 * (1.0 - r2 / 90.0 * (1.0 - r2 / 132.0))))
    )
    return _by_quadrant(c, s, n)


@njit(inline="always")
def cis_cycles_f32(x):
    """(cos, sin) of 2*pi*x for any real ``x`` (cycles) as float32, error below 2e-7.

    The reduction to a quarter cycle stays in float64 (a path of 10 km is 3e5 cycles); the
    polynomials run in float32, twice as many per SIMD register, at the precision of the
    complex64 pixels they end up in.
    """
    q = 4.0 * (x - math.floor(x))
    n = math.floor(q + 0.5)
    r = float32((q - n) * (0.5 * math.pi))
    r2 = r * r
    s = r * (_F1 + r2 * (_SIN_F32[0] + r2 * (_SIN_F32[1] + r2 * (_SIN_F32[2] + r2 * _SIN_F32[3]))))
    c = _F1 + r2 * (_COS_F32[0] + r2 * (_COS_F32[1] + r2 * (_COS_F32[2] + r2 * _COS_F32[3])))
    return _by_quadrant(c, s, n)


@njit(inline="always")
def wrap_index(i, n):
    """``i % n`` for n > 0; one period either way without an integer division (20-40 cycles)."""
    if i >= n:
        i -= n
    elif i < 0:
        i += n
    if i < 0 or i >= n:
        i %= n
    return i


@njit(inline="always")
def fast_atan2(y, x):
    """atan2 to within 1.15e-5 rad (minimax polynomial on [0, 1] plus octant fix-ups), branch-free.

    0 at the origin. Written with selects so that loops calling it vectorise.
    """
    ax, ay = abs(x), abs(y)
    z = min(ax, ay) / max(max(ax, ay), 1e-300)
    z2 = z * z
    a = z * (0.9998660 + z2 * (-0.3302995 + z2 * (0.1801410 + z2 * (-0.0851330 + z2 * 0.0208351))))
    a = 0.5 * math.pi - a if ay > ax else a
    a = math.pi - a if x < 0.0 else a
    return -a if y < 0.0 else a
