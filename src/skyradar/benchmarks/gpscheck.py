"""Benchmark: one GPS-check frame, the 300-pose SSIM test and the continuous search, vs plain baselines.

The frame has ch6's size: the side-looking radar's 500 m footprint on 4 m pixels (250 x 125 body
pixels), a 2.4 x 2.4 km synthetic city map (random blocks and streets, 4 m pixels), the radar image
being the map at a known pose plus speckle. Both runs pre-process the radar the same way (timed
apart: ``preprocess_s``; ``frame_s`` = pre-processing + 300 poses + search).

- 300 poses: ours samples all poses in one compiled pass and scores them with the batched SSIM
  (:func:`skyradar.nav.gpscheck.compare.ssim_scores`); the baseline does what one would write first:
  per pose ``scipy.ndimage.map_coordinates`` and ``skimage.metrics.structural_similarity`` (full map,
  mean over the footprint).
- Search: ours is :func:`skyradar.nav.gpscheck.search.search_offset` (FFT masked NCC, shared template
  FFTs); the baseline runs scikit-image's masked ``phase_cross_correlation`` (the same masked NCC,
  Padfield 2012) at the same headings.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
from scipy.ndimage import map_coordinates
from skimage.metrics import structural_similarity
from skimage.registration import phase_cross_correlation

from skyradar.nav.gpscheck.compare import decoy_poses, score_poses
from skyradar.nav.gpscheck.preprocess import preprocess
from skyradar.nav.gpscheck.search import search_offset
from skyradar.scene.ground_grid import GroundGrid, PoseGrid, sample_at_pose

__all__ = ["synthetic_city", "baseline_scores", "baseline_search", "run"]


def synthetic_city(rng: np.random.Generator, size_px: int = 600, pixel_m: float = 4.0):
    """(map image, grid): blocks of random brightness cut by a street grid of random widths."""
    grid = GroundGrid(0.0, 0.0, pixel_m, (size_px, size_px))
    image = np.full(grid.shape, 0.6, np.float32)
    for _ in range(900):
        r, c = rng.integers(0, size_px, 2)
        h, w = rng.integers(3, 15, 2)
        image[r : r + h, c : c + w] = rng.uniform(0.0, 0.5)
    for axis in (0, 1):
        for pos in np.cumsum(rng.integers(15, 40, size_px // 15)):
            if pos < size_px:
                sl = (slice(pos, pos + rng.integers(1, 4)), slice(None))
                image[sl if axis == 0 else sl[::-1]] = 1.0
    return image, grid


def _sample_plain(image, grid, pose_grid, pose):
    north, east = pose_grid.world_points(*pose)
    rows, cols = grid.world_to_pixel(north, east)
    return map_coordinates(image, [rows, cols], order=1, cval=0.0)


def baseline_scores(radar, mask, map_image, grid, pose_grid, poses) -> np.ndarray:
    """Per pose: scipy sampling and skimage SSIM averaged over the footprint's whole windows."""
    from scipy.ndimage import binary_erosion

    inner = binary_erosion(mask, np.ones((7, 7), bool), border_value=0)
    out = np.empty(len(poses))
    for k, pose in enumerate(poses):
        candidate = _sample_plain(map_image, grid, pose_grid, pose)
        _, full = structural_similarity(radar, candidate, data_range=1.0, full=True)
        out[k] = full[inner].mean()
    return out


def baseline_search(radar, mask, map_image, grid, pose_grid, pose, margin_m=250.0) -> tuple[float, float]:
    """skimage's masked phase correlation at the search's headings; best (shift m, heading deg)."""
    m = int(np.ceil(margin_m / pose_grid.pixel_m))
    h, w = pose_grid.shape
    big = PoseGrid(
        pose_grid.forward0_m - m * pose_grid.pixel_m,
        pose_grid.right0_m - m * pose_grid.pixel_m,
        pose_grid.pixel_m,
        (h + 2 * m, w + 2 * m),
    )
    padded, padded_mask = np.zeros(big.shape), np.zeros(big.shape, bool)
    padded[m : m + h, m : m + w], padded_mask[m : m + h, m : m + w] = radar, mask
    best = (-np.inf, 0.0, 0.0)
    headings = np.concatenate([np.arange(-15.0, 15.01, 1.5), np.arange(-1.5, 1.51, 0.25)])
    for d_heading in headings:
        patch = sample_at_pose(
            map_image, grid, big, pose[0], pose[1], pose[2] + np.radians(d_heading), fill=0.0
        )
        shift = phase_cross_correlation(
            patch, padded, reference_mask=np.ones(big.shape, bool), moving_mask=padded_mask
        )[0]
        moved = np.roll(padded, tuple(int(s) for s in shift), axis=(0, 1))
        score = float(np.sum(moved * patch))
        if score > best[0]:
            best = (score, float(np.hypot(*shift)) * pose_grid.pixel_m, float(d_heading))
    return best[1], best[2]


def _seconds(fn, min_time_s: float) -> float:
    """Median seconds per call over at least ``min_time_s`` (one warm-up call first)."""
    fn()
    times: list[float] = []
    start = time.perf_counter()
    while time.perf_counter() - start < min_time_s or len(times) < 3:
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return float(np.median(times))


def run(min_time_s: float = 2.0, seed: int = 0) -> dict[str, Any]:
    """Seconds per frame for the 300-pose test and the search, ours and baseline, and their ratios."""
    rng = np.random.default_rng(seed)
    map_image, grid = synthetic_city(rng)
    pose_grid = PoseGrid.side_looking(500.0, 4.0)
    truth = np.array([1200.0, 700.0, 0.3])
    north_m, east_m, heading_rad = truth
    clean = sample_at_pose(map_image, grid, pose_grid, north_m, east_m, heading_rad, fill=0.0)
    right = np.broadcast_to(pose_grid.right_m, pose_grid.shape)
    forward = np.broadcast_to(pose_grid.forward_m[:, None], pose_grid.shape)
    mask = (np.hypot(forward, right) < 460.0) & (np.abs(np.arctan2(forward, right)) < np.radians(30))
    power = np.where(mask, (0.05 + clean) * rng.exponential(1.0, clean.shape), np.nan)
    radar = preprocess(power, "clahe_ridge", mask, log_power=True, despeckle_px=3)
    processed = preprocess(map_image, "clahe_ridge")
    poses = np.vstack([truth, decoy_poses(truth, rng)])
    gps = truth + np.array([30.0, -20.0, np.radians(3.0)])
    prep = _seconds(
        lambda: preprocess(power, "clahe_ridge", mask, log_power=True, despeckle_px=3), min_time_s
    )
    ours_poses = _seconds(lambda: score_poses(radar, mask, processed, grid, pose_grid, poses), min_time_s)
    ours_search = _seconds(lambda: search_offset(radar, mask, processed, grid, pose_grid, gps), min_time_s)
    base_poses = _seconds(lambda: baseline_scores(radar, mask, processed, grid, pose_grid, poses), min_time_s)
    base_search = _seconds(lambda: baseline_search(radar, mask, processed, grid, pose_grid, gps), min_time_s)
    off = search_offset(radar, mask, processed, grid, pose_grid, gps)
    ours = score_poses(radar, mask, processed, grid, pose_grid, poses[:20])
    agree = np.corrcoef(ours, baseline_scores(radar, mask, processed, grid, pose_grid, poses[:20]))[0, 1]
    corrected = gps[:2] + np.array([off.d_north_m, off.d_east_m])
    return {
        "footprint_px": list(pose_grid.shape),
        "poses": len(poses),
        "poses_s": ours_poses,
        "poses_baseline_s": base_poses,
        "poses_speedup": base_poses / ours_poses,
        "search_s": ours_search,
        "search_baseline_s": base_search,
        "search_speedup": base_search / ours_search,
        "preprocess_s": prep,
        "frame_s": prep + ours_poses + ours_search,
        "search_error_m": float(np.hypot(*(corrected - truth[:2]))),
        "ssim_vs_skimage_correlation": float(agree),
    }
