"""Counter-based complex Gaussian noise, fused with the last pass over a frame.

Each pixel's noise is a pure function of (key, pixel index): SplitMix64 of the counter gives
two 53-bit uniforms, Box-Muller turns them into one complex Gaussian sample (tails to 8.6
sigma). So the noise of a frame does not depend on how many threads draw it, any frame can be
regenerated alone, and drawing it costs one parallel pass that also sums the per-thread
accumulation blocks, casts to complex64 and clears the blocks for the next frame.
"""

from __future__ import annotations

import math

import numpy as np
from numba import int64, njit, prange, uint64

from skyradar.sim._terrain_kernel import cis_cycles

__all__ = ["frame_key", "finalize_frame", "gaussian_noise"]

_GAMMA = np.uint64(0x9E3779B97F4A7C15)
_INV_2_53 = 1.0 / 9007199254740992.0


@njit(inline="always")
def _mix(z):
    z = (z ^ (z >> uint64(30))) * uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> uint64(27))) * uint64(0x94D049BB133111EB)
    return z ^ (z >> uint64(31))


@njit(inline="always")
def _complex_normal(key, index, sigma):
    """Complex Gaussian sample ``index`` of stream ``key`` (SD ``sigma`` per component)."""
    return _complex_normal_at(key + uint64(2) * uint64(index) * _GAMMA, sigma)


@njit(inline="always")
def _complex_normal_at(base, sigma):
    # SplitMix64 outputs at counters base + gamma and base + 2 gamma, then Box-Muller.
    # Through int64: the unsigned-to-float conversion is slow on x86.
    u1 = (float(int64(_mix(base + _GAMMA) >> uint64(11))) + 1.0) * _INV_2_53  # (0, 1]
    u2 = float(int64(_mix(base + uint64(2) * _GAMMA) >> uint64(11))) * _INV_2_53  # [0, 1)
    r = sigma * math.sqrt(-2.0 * math.log(u1))
    c, s = cis_cycles(u2)
    return r * c, r * s


def _ziggurat_tables(layers: int = 256) -> tuple[np.ndarray, np.ndarray]:
    # Doornik's ZIGNOR tables for the standard normal: layer edges x and ratios x[i+1]/x[i].
    r, v = 3.6541528853610088, 0.00492867323399
    x = np.empty(layers + 1)
    x[0] = v / math.exp(-0.5 * r * r)
    x[1] = r
    for i in range(1, layers - 1):
        x[i + 1] = math.sqrt(-2.0 * math.log(v / x[i] + math.exp(-0.5 * x[i] * x[i])))
    x[layers] = 0.0
    return x, x[1:] / x[:-1]


_ZIG_X, _ZIG_RATIO = _ziggurat_tables()
_ZIG_R = 3.6541528853610088


@njit(inline="always")
def _uniform(z):
    return float(int64(z >> uint64(11))) * _INV_2_53  # [0, 1)


@njit(inline="always")
def _ziggurat_normal(counter, zx, zratio):
    """Standard normal from the SplitMix64 stream at ``counter`` (ZIGNOR; about 1% rejections).

    Each attempt uses a fresh output of the stream (counter + k * 2^40 gamma), so the sample is
    a pure function of ``counter``.
    """
    attempt = uint64(0)
    while True:
        z = _mix(counter + attempt * uint64(0x9E3779B97F4A7C15) * uint64(1099511627776))
        attempt += uint64(1)
        i = int64(z & uint64(255))
        u = 2.0 * _uniform(z) - 1.0
        if abs(u) < zratio[i]:
            return u * zx[i]
        if i == 0:  # the base strip's tail beyond R (Marsaglia's method)
            while True:
                z1 = _mix(counter + attempt * uint64(0x9E3779B97F4A7C15) * uint64(1099511627776))
                z2 = _mix(
                    counter + (attempt + uint64(1)) * uint64(0x9E3779B97F4A7C15) * uint64(1099511627776)
                )
                attempt += uint64(2)
                x = -math.log(1.0 - _uniform(z1)) / _ZIG_R
                y = -math.log(1.0 - _uniform(z2))
                if 2.0 * y > x * x:
                    return -(_ZIG_R + x) if u < 0.0 else _ZIG_R + x
        x = u * zx[i]
        f0 = math.exp(-0.5 * (zx[i] * zx[i] - x * x))
        f1 = math.exp(-0.5 * (zx[i + 1] * zx[i + 1] - x * x))
        z3 = _mix(counter + attempt * uint64(0x9E3779B97F4A7C15) * uint64(1099511627776))
        attempt += uint64(1)
        if f1 + _uniform(z3) * (f0 - f1) < 1.0:
            return x


def frame_key(seed: int, frame_index: int) -> np.uint64:
    """64-bit stream key of one frame, mixed so that neighbouring frames share nothing."""
    z = ((seed & 0xFFFFFFFF) << 32) | (frame_index & 0xFFFFFFFF)
    return np.uint64(_mix(np.uint64((z * 0x9E3779B97F4A7C15 + 0x9E3779B97F4A7C15) & 0xFFFFFFFFFFFFFFFF)))


@njit(fastmath=True, cache=True)
def _finalize_chunk(blocks, sigma, key, out, lo, hi, zx, zratio):
    # Index slices with a plain range(n): an index like lo + t may be negative as far as numba
    # knows, and its wrap-around check made these loops three times slower. Two simple loops,
    # not one fused one, for the same reason.
    part, dst = blocks[:, lo:hi], out[lo:hi]
    has_blocks = part.shape[0] > 0
    if not has_blocks and sigma <= 0.0:
        dst[:] = 0
    for t in range(hi - lo if has_blocks else 0):
        acc = part[0, t]
        for b in range(1, part.shape[0]):
            acc += part[b, t]
        dst[t] = acc
    if sigma > 0.0:
        base = key + uint64(2) * uint64(lo) * _GAMMA
        step = uint64(2) * _GAMMA
        for t in range(hi - lo):
            nre = sigma * _ziggurat_normal(base + _GAMMA, zx, zratio)
            nim = sigma * _ziggurat_normal(base + uint64(2) * _GAMMA, zx, zratio)
            if has_blocks:
                dst[t] += complex(nre, nim)
            else:
                dst[t] = complex(nre, nim)
            base += step
    part[:, :] = 0


@njit(parallel=True, cache=True)
def _finalize_flat(blocks, sigma, key, out, zx, zratio):
    n = blocks.shape[1]
    n_chunks = 64
    step = (n + n_chunks - 1) // n_chunks
    for c in prange(n_chunks):
        _finalize_chunk(blocks, sigma, key, out, c * step, min((c + 1) * step, n), zx, zratio)


def finalize_frame(blocks: np.ndarray, sigma: float, key: np.uint64, out: np.ndarray) -> None:
    """``out = sum(blocks) + noise`` (complex64), and ``blocks`` cleared, in one parallel pass.

    ``blocks`` has shape (n_blocks, *out.shape), n_blocks may be 0 (noise only); ``sigma`` is
    the SD of each of the real and imaginary parts of the noise (0 for none).
    """
    _finalize_flat(
        blocks.reshape(blocks.shape[0], out.size),
        float(sigma),
        np.uint64(key),
        out.reshape(-1),
        _ZIG_X,
        _ZIG_RATIO,
    )


def gaussian_noise(shape: tuple[int, ...], power_w: float, key: np.uint64) -> np.ndarray:
    """Complex64 noise of ``power_w`` per sample (``power_w / 2`` per real component)."""
    blocks = np.zeros((1, 1, 1, int(np.prod(shape))), np.complex64)
    out = np.empty(blocks.shape[1:], np.complex64)
    finalize_frame(blocks, np.sqrt(power_w / 2.0), key, out)
    return out.reshape(shape)
