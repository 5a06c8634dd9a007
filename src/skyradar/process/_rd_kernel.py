"""Compiled stages of the split range DFT for chirp lengths 16 x Q (the prototype's 16 x 127).

A chirp row ``x[16*Q]`` is viewed as ``n = Q*n1 + n2``. :func:`window_dft16_kernel` applies the
range window (and optionally removes the row mean), the length-16 DFT over ``n1`` (radix 4 x 4)
and the twiddle ``exp(-2j pi k1 n2 / N)``, and writes ``y[row, k1, :]`` as planar float32
(``QP`` real parts, then ``QP`` imaginary parts; ``QP`` is ``Q`` rounded up to 16), ready for one
real matrix product with the pruned length-Q DFT. :func:`scatter_weighted` then puts the kept bins
``k = k1 + 16*k2`` of that product into the (range, chirp, rx) output, times one complex weight per
(chirp, rx) (Doppler window, FFT shift, normalisation, calibration).

Why it looks like this: LLVM vectorises a loop only when it can rule out overlap between the
arrays it stores to and loads from. Every butterfly loop therefore reads and writes one scratch
array at offsets that are compile-time constants (the kernel is specialised per ``Q``), and runs
over the padded length ``QP`` so no scalar remainder loop is left. The pad column carries finite
junk that the zero pad rows of the DFT matrix cancel exactly.
"""

from __future__ import annotations

from functools import lru_cache

import numba
import numpy as np

__all__ = ["padded_length", "window_dft16_kernel", "scatter_weighted"]


def padded_length(q: int) -> int:
    """Row length ``Q`` rounded up to a multiple of 16 (a whole number of SIMD vectors)."""
    return (int(q) + 15) // 16 * 16


@numba.njit(inline="always")
def _dft4(x0r, x0i, x1r, x1i, x2r, x2i, x3r, x3i):  # pragma: no cover - compiled
    # X0 = x0+x1+x2+x3, X1 = x0-jx1-x2+jx3, X2 = x0-x1+x2-x3, X3 = x0+jx1-x2-jx3
    s02r, s02i, d02r, d02i = x0r + x2r, x0i + x2i, x0r - x2r, x0i - x2i
    s13r, s13i, d13r, d13i = x1r + x3r, x1i + x3i, x1r - x3r, x1i - x3i
    return (
        s02r + s13r, s02i + s13i, d02r + d13i, d02i - d13r,
        s02r - s13r, s02i - s13i, d02r - d13i, d02i + d13r,
    )  # fmt: skip


@numba.njit(inline="always")
def _cmul(ar, ai, br, bi):  # pragma: no cover - compiled
    return ar * br - ai * bi, ar * bi + ai * br


@lru_cache(maxsize=4)
def window_dft16_kernel(q: int):
    """Compiled first stage for rows of ``16 * q`` samples (``q`` is baked in as a constant).

    The returned function is ``kernel(x, c0, c1, w, remove_dc, cr, ci, tr, ti, y)`` with ``x``
    (n_rx, n_chirp, n_samples <= 16 q) complex64, ``w`` (16 q,) float32 window, ``cr, ci`` (4, 4)
    the radix-4 twiddles ``exp(-2j pi p2 k / 16)``, ``tr, ti`` (16, QP) the outer twiddles (zero
    padded) and ``y`` (rows, 16, 2 QP) float32 output for chirps ``c0 <= c < c1``, row
    ``(c - c0) * n_rx + rx``.
    """
    qq = int(q)
    qp = padded_length(qq)
    n = 16 * qq
    im = 16 * qp  # offset of the imaginary plane in the butterfly scratch

    @numba.njit(fastmath=True, nogil=True, boundscheck=False, cache=True)  # cached per q
    def kernel(x, c0, c1, w, remove_dc, cr, ci, tr, ti, y):  # pragma: no cover - compiled
        n_rx, n_valid = x.shape[0], x.shape[2]
        a = np.zeros(2 * n + qp, np.float32)  # windowed samples, planar; zero past n_valid
        s = np.zeros(2 * im, np.float32)
        for c in range(c0, c1):
            for rx in range(n_rx):
                row = x[rx, c]
                sr = si = 0.0
                if remove_dc:  # ADC offset / LO leakage: the row mean, before the window
                    for j in range(n_valid):
                        sr += row[j].real
                        si += row[j].imag
                mr, mi = np.float32(sr / n_valid), np.float32(si / n_valid)
                for j in range(n_valid):
                    a[j] = (row[j].real - mr) * w[j]
                    a[n + j] = (row[j].imag - mi) * w[j]
                # Length-4 DFTs over p1 (n1 = 4*p1 + p2), then the inner twiddle W16^(p2*k).
                for p2 in range(4):
                    for t in range(qp):
                        o = _dft4(
                            a[p2 * qq + t], a[n + p2 * qq + t],
                            a[(4 + p2) * qq + t], a[n + (4 + p2) * qq + t],
                            a[(8 + p2) * qq + t], a[n + (8 + p2) * qq + t],
                            a[(12 + p2) * qq + t], a[n + (12 + p2) * qq + t],
                        )  # fmt: skip
                        s[4 * p2 * qp + t], s[im + 4 * p2 * qp + t] = o[0], o[1]
                        for j in range(1, 4):
                            re, ii = _cmul(o[2 * j], o[2 * j + 1], cr[p2, j], ci[p2, j])
                            s[(4 * p2 + j) * qp + t], s[im + (4 * p2 + j) * qp + t] = re, ii
                # Length-4 DFTs over p2 give k1 = m + 4*k2; then the outer twiddle.
                out = y[(c - c0) * n_rx + rx]
                for m in range(4):
                    for t in range(qp):
                        o = _dft4(
                            s[m * qp + t], s[im + m * qp + t],
                            s[(4 + m) * qp + t], s[im + (4 + m) * qp + t],
                            s[(8 + m) * qp + t], s[im + (8 + m) * qp + t],
                            s[(12 + m) * qp + t], s[im + (12 + m) * qp + t],
                        )  # fmt: skip
                        for k2 in range(4):
                            k = m + 4 * k2
                            re, ii = _cmul(o[2 * k2], o[2 * k2 + 1], tr[k, t], ti[k, t])
                            out[k, t], out[k, qp + t] = re, ii

    return kernel


@numba.njit(fastmath=True, nogil=True, boundscheck=False, cache=True)
def scatter_weighted(z, base, weight, out):  # pragma: no cover - compiled
    """``out[k1 + 16*k2, base + r] = z[r, k1, k2] * weight[base + r]`` for the kept bins.

    z (rows, 16, K2) complex64, weight (n_chirp * n_rx,) complex64 chirp-major,
    out (n_range, n_chirp * n_rx) complex64 (the (range, chirp, rx) cube, flattened).
    """
    # Bin-outer order: contiguous writes into the (mostly cold) output, strided reads of z
    # (which the matrix product just left in cache).
    n_range, n_rows = out.shape[0], z.shape[0]
    for k1 in range(16):
        for k2 in range(min(z.shape[2], (n_range - k1 + 15) // 16)):
            k = k1 + 16 * k2
            for r in range(n_rows):
                out[k, base + r] = z[r, k1, k2] * weight[base + r]
