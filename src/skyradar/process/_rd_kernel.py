"""Compiled first stage of the split range DFT for chirp lengths 16 x Q (the prototype's 16 x 127).

For every chirp row ``x[c, 16*Q]`` (viewed as ``n = Q*n1 + n2``) it applies the range window,
the length-16 DFT over ``n1`` (radix 4 x 4) and the twiddle ``exp(-2j pi k1 n2 / N)``, and writes
``y[k1, c, n2]`` ready for the matrix product with the pruned length-Q DFT. One pass over the
samples instead of four numpy passes; the inner loop runs along ``n2`` so it vectorises.
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = ["window_dft16_twiddle"]


@numba.njit(inline="always")
def _dft4(x0r, x0i, x1r, x1i, x2r, x2i, x3r, x3i):  # pragma: no cover - compiled
    # X0 = x0+x1+x2+x3, X1 = x0-jx1-x2+jx3, X2 = x0-x1+x2-x3, X3 = x0+jx1-x2-jx3
    s02r, s02i, d02r, d02i = x0r + x2r, x0i + x2i, x0r - x2r, x0i - x2i
    s13r, s13i, d13r, d13i = x1r + x3r, x1i + x3i, x1r - x3r, x1i - x3i
    return (
        s02r + s13r, s02i + s13i, d02r + d13i, d02i - d13r,
        s02r - s13r, s02i - s13i, d02r - d13i, d02i + d13r,
    )  # fmt: skip


@numba.njit(fastmath=True, nogil=True, cache=True)
def window_dft16_twiddle(x, w, w16r, w16i, tr, ti, y):  # pragma: no cover - compiled
    """x (C, 16*Q) complex64, w (16*Q,) float32, w16 (4, 4) = exp(-2j pi p2 k1 / 16),
    t (16, Q) twiddles, y (16, C, Q) complex64 output."""
    n_chirp = x.shape[0]
    q_len = tr.shape[1]
    ar = np.empty((16, q_len), np.float32)
    ai = np.empty((16, q_len), np.float32)
    br = np.empty((16, q_len), np.float32)
    bi = np.empty((16, q_len), np.float32)
    for c in range(n_chirp):
        for p in range(16):
            for q in range(q_len):
                v = x[c, p * q_len + q]
                g = w[p * q_len + q]
                ar[p, q] = v.real * g
                ai[p, q] = v.imag * g
        # n1 = 4*p1 + p2: length-4 DFTs over p1, then the inner twiddle W16^(p2*k1).
        for p2 in range(4):
            for q in range(q_len):
                r0, i0, r1, i1, r2, i2, r3, i3 = _dft4(
                    ar[p2, q], ai[p2, q], ar[4 + p2, q], ai[4 + p2, q],
                    ar[8 + p2, q], ai[8 + p2, q], ar[12 + p2, q], ai[12 + p2, q],
                )  # fmt: skip
                br[4 * p2, q] = r0
                bi[4 * p2, q] = i0
                br[4 * p2 + 1, q] = r1 * w16r[p2, 1] - i1 * w16i[p2, 1]
                bi[4 * p2 + 1, q] = r1 * w16i[p2, 1] + i1 * w16r[p2, 1]
                br[4 * p2 + 2, q] = r2 * w16r[p2, 2] - i2 * w16i[p2, 2]
                bi[4 * p2 + 2, q] = r2 * w16i[p2, 2] + i2 * w16r[p2, 2]
                br[4 * p2 + 3, q] = r3 * w16r[p2, 3] - i3 * w16i[p2, 3]
                bi[4 * p2 + 3, q] = r3 * w16i[p2, 3] + i3 * w16r[p2, 3]
        # length-4 DFTs over p2 give k1 = m + 4*k2; then the outer twiddle.
        for m in range(4):
            for q in range(q_len):
                out = _dft4(
                    br[m, q], bi[m, q], br[4 + m, q], bi[4 + m, q],
                    br[8 + m, q], bi[8 + m, q], br[12 + m, q], bi[12 + m, q],
                )  # fmt: skip
                for k2 in range(4):
                    k = m + 4 * k2
                    rr, ii = out[2 * k2], out[2 * k2 + 1]
                    y[k, c, q] = complex(rr * tr[k, q] - ii * ti[k, q], rr * ti[k, q] + ii * tr[k, q])
