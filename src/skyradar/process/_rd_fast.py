"""Drivers of the range-Doppler processing: thread pools, BLAS limiting and the 16 x Q frame path.

:class:`Split16` runs one frame of the compiled path of :mod:`skyradar.process._rd_kernel`
(complex64 end to end, no transposes): blocks of chirps (all channels) are windowed and
length-16 transformed, multiplied by the pruned length-Q DFT (one real matrix product), and
scattered with their Doppler weight into the (range, chirp, rx) output, where the Doppler FFT
then runs in place along the chirp axis. Blocks are spread over ``workers`` threads with BLAS
held to one thread meanwhile.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from functools import lru_cache
from typing import Any

import numpy as np
import scipy.fft as sfft

from skyradar.process._rd_kernel import padded_length, scatter_weighted, window_dft16_kernel

__all__ = ["BLOCK_ROWS", "Split16", "frame_pool", "one_blas_thread", "run_parallel"]

BLOCK_ROWS = 100  # 1.6 MB of complex64 ADC rows: the block stays in cache through all its stages


@lru_cache(maxsize=1)
def _blas_controller():
    from threadpoolctl import ThreadpoolController  # numpy's BLAS is loaded by now

    return ThreadpoolController()


_BLAS_LOCK = threading.Lock()
_BLAS_USERS: list[Any] = [0, None]  # callers inside, threadpoolctl limiter of the first one


@contextmanager
def one_blas_thread() -> Iterator[None]:
    """BLAS limited to one thread while any caller (from any thread) is inside."""
    with _BLAS_LOCK:
        if _BLAS_USERS[0] == 0:
            _BLAS_USERS[1] = _blas_controller().limit(limits=1, user_api="blas")
        _BLAS_USERS[0] += 1
    try:
        yield
    finally:
        with _BLAS_LOCK:
            _BLAS_USERS[0] -= 1
            if _BLAS_USERS[0] == 0:
                _BLAS_USERS[1].restore_original_limits()


@lru_cache(maxsize=4)
def _thread_pool(workers: int) -> ThreadPoolExecutor:
    return ThreadPoolExecutor(max_workers=workers, thread_name_prefix="skyradar-rd")


@lru_cache(maxsize=4)
def frame_pool(workers: int) -> ThreadPoolExecutor:
    """Pool for whole frames; separate from the block pool, which a frame job may use itself."""
    return ThreadPoolExecutor(max_workers=workers, thread_name_prefix="skyradar-rd-frame")


def run_parallel(job: Callable[[Any], None], items: Iterable, workers: int) -> None:
    """``job(item)`` for every item, spread over ``workers`` threads, BLAS at one thread each."""
    items = list(items)
    # BLAS threads spinning beside ours (or beside other processes) cost more than they
    # give on small machines: one BLAS thread per worker, parallel over blocks instead.
    with one_blas_thread():
        if workers > 1 and len(items) > 1:
            list(_thread_pool(workers).map(job, items))
        else:
            for item in items:
                job(item)


class Split16:
    """Tables and per-thread scratch of the compiled range transform for chirps of 16 x Q samples.

    Parameters
    ----------
    n_fft : int
        Range DFT length (a multiple of 16).
    n_range : int
        Range bins kept (the first ``n_range`` DFT bins).
    """

    def __init__(self, n_fft: int, n_range: int) -> None:
        q, k2 = n_fft // 16, -(-n_range // 16)
        qp = padded_length(q)
        self.n_range, self.k2, self.qp = n_range, k2, qp
        tw = np.zeros((16, qp), complex)
        tw[:, :q] = np.exp(-2j * np.pi * np.outer(np.arange(16), np.arange(q)) / n_fft)
        self.tr, self.ti = tw.real.astype(np.float32), tw.imag.astype(np.float32)
        w16 = np.exp(-2j * np.pi * np.outer(np.arange(4), np.arange(4)) / 16)
        self.cr, self.ci = w16.real.astype(np.float32), w16.imag.astype(np.float32)
        dft = np.zeros((qp, k2), complex)
        dft[:q] = np.exp(-2j * np.pi * np.outer(np.arange(q), np.arange(k2)) / q)
        # Planar rows [re(QP) | im(QP)] times this real matrix give interleaved complex columns;
        # zero columns up to a multiple of 16 make OpenBLAS's sgemm faster (measured: 48 columns
        # take 7 % less time than the 42 needed).
        m = np.zeros((2 * qp, padded_length(2 * k2)), np.float32)
        re, im = slice(0, 2 * k2, 2), slice(1, 2 * k2, 2)
        m[:qp, re], m[:qp, im] = dft.real, dft.imag
        m[qp:, re], m[qp:, im] = -dft.imag, dft.real
        self.dft_real = m
        self.kernel = window_dft16_kernel(q)
        self._local = threading.local()

    def _scratch(self, rows: int) -> tuple[np.ndarray, np.ndarray]:
        """Per-thread work arrays, reused: fresh megabyte arrays cost a page fault per page."""
        local = self._local.__dict__
        if local.get("rows") != rows:
            local.update(rows=rows, y=np.empty((rows, 16, 2 * self.qp), np.float32))
            local["z"] = np.empty((rows, 16, self.dft_real.shape[1]), np.float32)
        return local["y"], local["z"]

    def __call__(
        self, adc: np.ndarray, window: np.ndarray, remove_dc: bool, weight: np.ndarray, workers: int
    ) -> np.ndarray:
        """(rx, chirp, sample) complex64 -> (range, Doppler, rx) complex64 cube.

        ``window`` (16 Q,) float32 range window (zero past the valid samples); ``weight``
        (chirp * rx,) complex64, chirp-major: Doppler window, shift, normalisation, calibration.
        """
        n_rx, n_chirp = adc.shape[:2]
        out = np.empty((self.n_range, n_chirp, n_rx), np.complex64)
        flat = out.reshape(self.n_range, n_chirp * n_rx)
        step = max(1, BLOCK_ROWS // n_rx)

        def range_block(c0: int) -> None:
            c1 = min(c0 + step, n_chirp)
            y, z = self._scratch((c1 - c0) * n_rx)
            self.kernel(adc, c0, c1, window, remove_dc, self.cr, self.ci, self.tr, self.ti, y)
            np.matmul(y.reshape(-1, y.shape[2]), self.dft_real, out=z.reshape(-1, z.shape[2]))
            scatter_weighted(z.view(np.complex64), c0 * n_rx, weight, flat)

        def doppler_block(sl: slice) -> None:
            part = out[sl]  # contiguous, so pocketfft transforms it in place
            res = sfft.fft(part, axis=1, workers=1, overwrite_x=True)
            if not np.shares_memory(res, part):
                part[...] = res

        run_parallel(range_block, range(0, n_chirp, step), workers)
        edges = np.linspace(0, self.n_range, max(1, workers) + 1).astype(int)
        run_parallel(
            doppler_block, [slice(a, b) for a, b in zip(edges[:-1], edges[1:], strict=True)], workers
        )
        return out
