"""Benchmark: the adaptive nulls over relief, ours against a numpy version of the same algorithm.

Cubes: the image simulator over fractal hills (60 m local height SD, as the encounters'
``hills``) 550 m below the prototype radar, own-ship level at 50 m/s, a head-on intruder; the
prediction is flat ground at the height below the own-ship, as the pipeline's
(:func:`skyradar.process.clutter_frames.frame_subspace`), so the relief leaves clutter the
adaptive step (:mod:`skyradar.process.clutter_adaptive`) takes over. Ours: the compiled step
inside :func:`skyradar.process.clutter_suppress.suppress_clutter` (its CPU time is the
difference with ``adaptive=False``) and the whole :func:`skyradar.process.pipeline.process_cube`.
Baseline, measured in the same run on the same cubes: the same rule in numpy (cumulative-sum box
sums of the clipped image and of every cell's ``z z^H``, batched ``numpy.linalg.eigh`` of the
candidate cells' ring covariances, explicit projectors). ``relief_adaptive_same_nulls`` is the
fraction of cells where both chose the same null count, ``relief_adaptive_same_detections`` whether
CFAR finds the same cells on both images in every frame. The chain's CPU time per frame splits
into the predicted nulls, the adaptive step, and detection with the direction searches. The same
figures for the six- and eight-channel arrays (``relief_rx6_*``, ``relief_rx8_*``): what a larger
array's suppression costs over relief, at its default ceiling of nulls per cell. Both
versions stop at a tolerance (the compiled subspace iteration's residual, the baseline's exact
``eigh``), so a cell whose eigenvalue lies within it of the edge, or whose power lies that close to
its CFAR threshold, can take another null count or detection: the ``same_*`` figures say how often.
"""

from __future__ import annotations

import time

import numpy as np

from skyradar.config import RadarConfig
from skyradar.process.clutter import clutter_subspace
from skyradar.process.clutter_adaptive import ADAPTIVE_GATE, ADAPTIVE_WINDOW, EIGEN_EDGE, RING_CLIP
from skyradar.process.clutter_suppress import Suppressed, default_max_nulls, suppress_clutter
from skyradar.process.pipeline import process_cube
from skyradar.scene.synthetic_terrain import fractal_terrain
from skyradar.sim.image import ImageSimulator, PlatformState, PointTarget

__all__ = ["relief_cubes", "baseline_adaptive", "run_adaptive"]

HILLS_SD_M, AGL_M, SPEED_MPS = 60.0, 550.0, 50.0


def relief_cubes(config: RadarConfig, n_cubes: int, seed: int = 0) -> tuple[list[np.ndarray], float]:
    """Frames over fractal hills with a head-on intruder (3 km to 1.8 km); the height below, m."""
    terrain = fractal_terrain(52.0, 5.0, HILLS_SD_M, 12_000.0, 30.0, seed=seed)
    ground = float(terrain.height_at(52.0, 5.0))
    sim = ImageSimulator(config, terrain, origin=(52.0, 5.0, 0.0), seed=seed)
    alt = ground + AGL_M
    own = PlatformState(np.array([0.0, 0.0, -alt]), np.array([SPEED_MPS, 0.0, 0.0]), np.zeros(3))
    cubes = []
    for i, rng_m in enumerate(np.linspace(3000.0, 1800.0, n_cubes)):
        intruder = PointTarget(np.array([rng_m, 0.0, -alt]), np.array([-50.0, 0.0, 0.0]), rcs_m2=2.0)
        cubes.append(sim.frame(own, [intruder], i))
    return cubes, AGL_M


def _ring(x: np.ndarray, window: tuple[int, int, int, int]) -> np.ndarray:
    """Sums over each cell's ring (window minus guard): Doppler wraps, range truncated; x (n_r, n_d, ...)."""
    hr, hd, gr, gd = window

    def box(h_r: int, h_d: int) -> np.ndarray:
        n_r, n_d = x.shape[:2]
        c = np.concatenate([x[:, n_d - h_d :], x, x[:, :h_d]], axis=1) if h_d else x
        c = np.pad(c, ((1, 0), (1, 0)) + ((0, 0),) * (x.ndim - 2)).cumsum(0).cumsum(1)
        lo, hi = np.clip(np.arange(n_r) - h_r, 0, n_r), np.clip(np.arange(n_r) + h_r + 1, 0, n_r)
        return c[hi, 2 * h_d + 1 :] - c[lo, 2 * h_d + 1 :] - c[hi, :n_d] + c[lo, :n_d]

    return box(hr, hd) - box(gr, gd)


def baseline_adaptive(cube, inv_gain, cnr, floor_w, power, nulls, unsuppressed, max_nulls=2, gate=3.0):
    """:func:`skyradar.process.clutter_adaptive.adaptive_nulls` in numpy (in place; returns the mask)."""
    z = cube.astype(np.complex128) * inv_gain
    k = z.shape[-1]
    count = _ring(np.ones(power.shape), ADAPTIVE_WINDOW)
    clipped = _ring(np.minimum(power, RING_CLIP * floor_w).astype(float), ADAPTIVE_WINDOW)
    cand = (cnr > gate) & (clipped > ADAPTIVE_GATE * floor_w * count) & (count >= 16)
    mean = _ring(power.astype(float), ADAPTIVE_WINDOW)[cand] / count[cand]
    outer = z[..., :, None] * np.conj(z[..., None, :])
    cov = _ring(outer, ADAPTIVE_WINDOW)[cand] / (count[cand] * floor_w)[:, None, None]
    lam, e = np.linalg.eigh(cov)
    lam, e = lam[:, ::-1], e[:, :, ::-1]
    m = np.sum(lam[:, :max_nulls] > EIGEN_EDGE, axis=1)
    kept = lam.sum(axis=1) - np.sum(lam * (np.arange(k) < m[:, None]), axis=1)
    use = (m > 0) & (kept / (k - m) < mean / floor_w)
    e = e * (np.arange(k) < m[:, None])[:, None, :]
    y = z[cand] - np.einsum("nki,nli,nl->nk", e, np.conj(e), z[cand])
    mask = np.zeros(power.shape, bool)
    mask[cand] = use
    power[mask] = (np.sum(np.abs(y) ** 2, axis=1) / (k - m))[use]
    nulls[mask] = m[use]
    unsuppressed[mask] = ((kept - (k - m)) / k > 1.0)[use]
    return mask


def _cpu_per_frame(fn, cubes: list[np.ndarray], repeats: int = 3) -> float:
    """Best pass's process-CPU seconds per frame (one warm-up pass first)."""
    for cube in cubes:
        fn(cube)
    best = np.inf
    for _ in range(repeats):
        c0 = time.process_time()
        for cube in cubes:
            fn(cube)
        best = min(best, time.process_time() - c0)
    return best / len(cubes)


def run_adaptive(n_cubes: int = 4, seed: int = 0) -> dict:
    """CPU ms per frame of the adaptive step, ours and the numpy baseline; the whole chain's frames/s.

    The prototype's square under ``relief_*``; the six- and eight-channel arrays of
    ``skyradar bench process`` (``ura-2x3``, ``ura-2x4``, at their default ceiling on nulls,
    :func:`skyradar.process.clutter_suppress.default_max_nulls`) on fewer frames of the same hills
    under ``relief_rx6_*`` and ``relief_rx8_*``.
    """
    out = _adaptive_figures(RadarConfig.prototype_2022(), n_cubes, seed, "relief_")
    for n_rx, layout in ((6, "ura-2x3"), (8, "ura-2x4")):
        config = RadarConfig.prototype_2022(rx_positions_m=layout)
        out |= _adaptive_figures(config, max(n_cubes // 2, 1), seed, f"relief_rx{n_rx}_")
    return out


def _adaptive_figures(config: RadarConfig, n_cubes: int, seed: int, prefix: str) -> dict:
    """:func:`run_adaptive`'s figures of one array, keys starting with ``prefix``."""
    cubes, agl = relief_cubes(config, n_cubes, seed)
    sub = clutter_subspace(config, np.array([SPEED_MPS, 0.0, 0.0]), config.mount.rotation, agl, n_azimuth=720)
    inv_gain = (1.0 / np.asarray(config.rx_calibration)).astype(np.complex64)
    max_nulls = default_max_nulls(config.n_virtual, config.n_tx)  # as suppress_clutter takes it

    def baseline(cube: np.ndarray) -> Suppressed:
        """The predicted pass, its cells rewritten in place by the numpy adaptive step."""
        s = suppress_clutter(cube, sub, config, adaptive=False)
        args = (s.clutter_to_noise, s.noise_floor_w, s.power, s.nulls, s.unsuppressed)
        baseline_adaptive(cube, inv_gain, *args, max_nulls=max_nulls)
        return s

    predicted = _cpu_per_frame(lambda c: suppress_clutter(c, sub, config, adaptive=False), cubes)
    ours = _cpu_per_frame(lambda c: suppress_clutter(c, sub, config), cubes) - predicted
    base = _cpu_per_frame(baseline, cubes, repeats=1) - predicted
    chain = _cpu_per_frame(lambda c: process_cube(c, config, clutter=sub), cubes)
    same, same_hits, cells = [], [], []
    for cube in cubes:
        s, b = suppress_clutter(cube, sub, config), baseline(cube)
        same.append(float(np.mean(s.nulls == b.nulls)))
        same_hits.append(_hit_cells(s, config) == _hit_cells(b, config))
        assert s.adaptive is not None  # suppress_clutter's adaptive pass (its default) sets it
        cells.append(int(s.adaptive.sum()))
    return {
        f"{prefix}adaptive_cells_per_frame": float(np.mean(cells)),
        f"{prefix}adaptive_cpu_ms_per_frame": 1e3 * ours,
        f"{prefix}adaptive_baseline_cpu_ms_per_frame": 1e3 * base,
        f"{prefix}adaptive_speedup_cpu": float(base / max(ours, 1e-9)),
        f"{prefix}adaptive_same_nulls": float(np.mean(same)),
        f"{prefix}adaptive_same_detections": bool(all(same_hits)),
        f"{prefix}predicted_cpu_ms_per_frame": 1e3 * predicted,
        # The rest of the chain: CFAR, peaks and every detection's direction search.
        f"{prefix}detect_and_directions_cpu_ms_per_frame": 1e3 * max(chain - predicted - ours, 0.0),
        f"{prefix}suppressed_cpu_ms_per_frame": 1e3 * chain,
        f"{prefix}suppressed_cpu_frames_per_s": float(1.0 / chain),
    }


def _hit_cells(suppressed, config: RadarConfig) -> set[tuple[int, int]]:
    """The (range, Doppler) cells CFAR detects on a suppressed image (the baseline rewrites its null
    counts in place; :meth:`~skyradar.process.clutter_suppress.Suppressed.detections` reads them)."""
    det = suppressed.detections(config)
    return set(zip(det.range_index.tolist(), det.doppler_index.tolist(), strict=True))
