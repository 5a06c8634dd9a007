"""SSIM of a radar ground image against a map rendered at candidate poses, and the thesis' decoy test.

The thesis compared the pre-processed radar image with the map image at the GPS pose and at 300 false
poses (0-150 m away, +-15 deg heading) using SSIM, picked the best-scoring pose, and reported heading
error, position error and the share of false poses scoring above the true one (Maas 2022, ch. 6).

:func:`ssim_scores` is SSIM exactly as ``skimage.metrics.structural_similarity`` computes it (7 x 7
uniform window, sample covariance, K1 = 0.01, K2 = 0.03), averaged over the pixels whose whole window
lies inside the radar footprint, for hundreds of candidate images at once in one compiled pass (the
radar image's window statistics are computed once, each candidate needs three running box sums).
The tests check it against scikit-image.

Decoy positions are drawn uniformly over the 150 m disc (uniform in area, not in distance: a decoy
within 10 m of the truth is then as rare as that disc's share of the area, 0.4 %).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from skyradar.errors import InputError
from skyradar.scene.ground_grid import GroundGrid, PoseGrid, sample_at_poses
from skyradar.units import wrap_angle

__all__ = ["ssim_scores", "decoy_poses", "crop_to_mask", "score_poses", "DecoyResult", "decoy_test"]


@njit(cache=True)
def _integral(a):
    rows, cols = a.shape
    out = np.zeros((rows + 1, cols + 1))
    for i in range(rows):
        acc = 0.0
        for j in range(cols):
            acc += a[i, j]
            out[i + 1, j + 1] = out[i, j + 1] + acc
    return out


@njit(cache=True, inline="always")
def _box(s, i, j, h):
    return s[i + h + 1, j + h + 1] - s[i - h, j + h + 1] - s[i + h + 1, j - h] + s[i - h, j - h]


@njit(cache=True)
def _integrals(x, y, sy, syy, sxy):
    """Summed-area tables of y, y*y and x*y in one pass (no temporaries: this runs once per pose)."""
    rows, cols = x.shape
    for i in range(rows):
        ay = 0.0
        ayy = 0.0
        axy = 0.0
        for j in range(cols):
            v = np.float64(y[i, j])
            ay += v
            ayy += v * v
            axy += x[i, j] * v
            sy[i + 1, j + 1] = sy[i, j + 1] + ay
            syy[i + 1, j + 1] = syy[i, j + 1] + ayy
            sxy[i + 1, j + 1] = sxy[i, j + 1] + axy


@njit(cache=True, parallel=True)
def _ssim_kernel(x, centres, candidates, half, c1, c2, out):
    npix = (2 * half + 1) ** 2
    cov_norm = npix / (npix - 1.0)
    sx, sxx = _integral(x), _integral(x * x)
    n_c = centres.shape[0]
    ux = np.empty(n_c)
    vx = np.empty(n_c)
    for c in range(n_c):
        i, j = centres[c, 0], centres[c, 1]
        ux[c] = _box(sx, i, j, half) / npix
        vx[c] = cov_norm * (_box(sxx, i, j, half) / npix - ux[c] * ux[c])
    rows, cols = x.shape
    for k in prange(candidates.shape[0]):
        sy = np.zeros((rows + 1, cols + 1))
        syy = np.zeros((rows + 1, cols + 1))
        sxy = np.zeros((rows + 1, cols + 1))
        _integrals(x, candidates[k], sy, syy, sxy)
        total = 0.0
        for c in range(n_c):
            i, j = centres[c, 0], centres[c, 1]
            uy = _box(sy, i, j, half) / npix
            vy = cov_norm * (_box(syy, i, j, half) / npix - uy * uy)
            vxy = cov_norm * (_box(sxy, i, j, half) / npix - ux[c] * uy)
            num = (2.0 * ux[c] * uy + c1) * (2.0 * vxy + c2)
            den = (ux[c] * ux[c] + uy * uy + c1) * (vx[c] + vy + c2)
            total += num / den
        out[k] = total / max(n_c, 1)


def _window_centres(mask: np.ndarray, half: int) -> np.ndarray:
    """(row, col) of pixels whose whole window lies inside ``mask`` and inside the image."""
    from scipy.ndimage import binary_erosion

    inner = np.zeros_like(mask, dtype=bool)
    inner[half:-half, half:-half] = True
    full = binary_erosion(mask, np.ones((2 * half + 1, 2 * half + 1), bool), border_value=0) & inner
    return np.argwhere(full).astype(np.int64)


def ssim_scores(
    reference: np.ndarray,
    candidates: np.ndarray,
    mask: np.ndarray | None = None,
    *,
    win_size: int = 7,
    data_range: float = 1.0,
) -> float | np.ndarray:
    """Mean SSIM of ``reference`` against each candidate, over the windows inside ``mask``.

    Parameters
    ----------
    reference : (rows, cols) array
        Pre-processed radar image.
    candidates : (n, rows, cols) or (rows, cols) array
        Map images at candidate poses (NaN is read as 0).
    mask : (rows, cols) bool array, optional
        Radar footprint; only pixels whose ``win_size`` window lies wholly inside count.
    win_size, data_range : as ``skimage.metrics.structural_similarity``.

    Returns
    -------
    (n,) float array (a float for one candidate); NaN if no window fits in the mask.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> ref = rng.random((32, 32))
    >>> scores = ssim_scores(ref, np.stack([ref, rng.random((32, 32))]))
    >>> [round(float(s), 3) for s in scores]
    [1.0, -0.023]
    """
    if win_size < 3 or win_size % 2 == 0:
        raise InputError(f"ssim_scores: win_size must be an odd number >= 3, got {win_size!r}")
    reference = np.nan_to_num(np.asarray(reference, dtype=np.float64))
    stack = np.asarray(candidates, dtype=np.float32)
    single = stack.ndim == 2
    stack = np.nan_to_num(np.ascontiguousarray(stack[None] if single else stack))
    if stack.shape[1:] != reference.shape:
        raise InputError(
            f"ssim_scores: candidates {stack.shape[1:]} differ from the reference {reference.shape}"
        )
    mask = np.ones(reference.shape, bool) if mask is None else np.asarray(mask, bool)
    half = win_size // 2
    centres = _window_centres(mask, half)
    out = np.full(stack.shape[0], np.nan)
    if len(centres):
        c1, c2 = (0.01 * data_range) ** 2, (0.03 * data_range) ** 2
        _ssim_kernel(reference, centres, stack, half, c1, c2, out)
    return float(out[0]) if single else out


def decoy_poses(
    true_pose: np.ndarray,
    rng: np.random.Generator,
    n: int = 300,
    max_offset_m: float = 150.0,
    max_heading_deg: float = 15.0,
) -> np.ndarray:
    """``n`` false poses ``(north_m, east_m, heading_rad)`` around ``true_pose``: uniform over the disc
    of radius ``max_offset_m`` and uniform within ``+-max_heading_deg``.

    Examples
    --------
    >>> poses = decoy_poses(np.array([0.0, 0.0, 0.0]), np.random.default_rng(1), n=1000)
    >>> distance, heading = np.hypot(poses[:, 0], poses[:, 1]), np.degrees(np.abs(poses[:, 2]))
    >>> bool(distance.max() <= 150.0), bool(heading.max() <= 15.0)
    (True, True)
    """
    radius = max_offset_m * np.sqrt(rng.random(n))
    bearing = rng.uniform(0.0, 2 * np.pi, n)
    heading = np.radians(rng.uniform(-max_heading_deg, max_heading_deg, n))
    return np.column_stack(
        [
            true_pose[0] + radius * np.cos(bearing),
            true_pose[1] + radius * np.sin(bearing),
            true_pose[2] + heading,
        ]
    )


def crop_to_mask(radar: np.ndarray, mask: np.ndarray, *grids: PoseGrid | None):
    """Radar, mask and pose grids cut to the mask's bounding box: the work a footprint needs, no more.

    Examples
    --------
    >>> body = PoseGrid(0.0, 0.0, 1.0, (5, 5))
    >>> mask = np.zeros((5, 5), bool); mask[1:3, 2:4] = True
    >>> radar, mask, cut = crop_to_mask(np.ones((5, 5)), mask, body)
    >>> radar.shape, float(cut.forward0_m), float(cut.right0_m)
    ((2, 2), 1.0, 2.0)
    """
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    if not rows.size:
        return (radar, mask, *grids)
    r0, r1, c0, c1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
    cut = [
        None
        if g is None
        else PoseGrid(
            g.forward0_m + r0 * g.pixel_m,
            g.right0_m + c0 * g.pixel_m,
            g.pixel_m,
            (max(r1 - r0, 2), max(c1 - c0, 2)),
        )
        for g in grids
    ]
    r1, c1 = r0 + max(r1 - r0, 2), c0 + max(c1 - c0, 2)
    return (radar[r0:r1, c0:c1], mask[r0:r1, c0:c1], *cut)


def score_poses(
    radar: np.ndarray,
    radar_mask: np.ndarray,
    map_world: np.ndarray,
    grid: GroundGrid,
    pose_grid: PoseGrid,
    poses: np.ndarray,
    map_pose_grid: PoseGrid | None = None,
) -> np.ndarray:
    """SSIM of the pre-processed radar image against the pre-processed map sampled at each pose.

    Parameters
    ----------
    radar, radar_mask : 2-D arrays on ``pose_grid``
        The pre-processed radar image and its footprint.
    map_world : 2-D array on ``grid``
        The pre-processed map; outside it reads 0.
    grid : GroundGrid
    pose_grid : PoseGrid
    poses : ndarray, shape (n, 3) or (3,)
        ``(north_m, east_m, heading_rad)`` per candidate.
    map_pose_grid : PoseGrid, optional
        Where the map is sampled (default ``pose_grid``): ``pose_grid`` moved by the expected layover
        (:func:`skyradar.nav.gpscheck.check.layover_grid`).

    Returns
    -------
    ndarray, shape (n,)
        SSIM per pose; 1 for a map identical to the radar image.

    Examples
    --------
    >>> grid = GroundGrid(0.0, 0.0, 2.0, (200, 200))
    >>> world = np.random.default_rng(0).random(grid.shape).astype(np.float32)
    >>> body = PoseGrid.side_looking(range_m=60.0, pixel_m=2.0)
    >>> truth = np.array([200.0, 200.0, 0.3])
    >>> radar = sample_at_poses(world, grid, body, truth)
    >>> poses = truth + np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [0.0, 0.0, np.radians(5.0)]])
    >>> scores = score_poses(radar, np.ones(body.shape, bool), world, grid, body, poses)
    >>> round(float(scores[0]), 6), bool(scores[1:].max() < 0.1)
    (1.0, True)
    """
    where = pose_grid if map_pose_grid is None else map_pose_grid
    radar, radar_mask, where = crop_to_mask(radar, np.asarray(radar_mask, bool), where)
    candidates = sample_at_poses(map_world, grid, where, np.atleast_2d(poses), fill=0.0)
    scores = ssim_scores(radar, candidates, radar_mask)
    assert isinstance(scores, np.ndarray)  # candidates is a stack (n, rows, cols): an array of n
    return scores


@dataclass(frozen=True)
class DecoyResult:
    """One frame of the decoy test: the picked pose's errors and the false-positive share.

    Attributes
    ----------
    heading_error_deg : float
        Heading error of the picked pose, deg.
    position_error_m : float
        Position error of the picked pose, m.
    false_positive_fraction : float
        Share of the decoys scoring above the true pose, 0..1.
    true_score, best_score : float
        SSIM of the true pose and of the picked one.

    Examples
    --------
    >>> result = DecoyResult(1.5, 12.0, 0.02, 0.61, 0.64)
    >>> result.correct(), result.correct(max_position_m=10.0)
    (True, False)
    """

    heading_error_deg: float
    position_error_m: float
    false_positive_fraction: float
    true_score: float
    best_score: float

    def correct(self, max_heading_deg: float = 2.0, max_position_m: float = 15.0) -> bool:
        """The picked pose is within the bounds of the true one (acceptance: 2 deg, 15 m)."""
        return self.heading_error_deg <= max_heading_deg and self.position_error_m <= max_position_m


def decoy_test(
    radar: np.ndarray,
    radar_mask: np.ndarray,
    map_world: np.ndarray,
    grid: GroundGrid,
    pose_grid: PoseGrid,
    true_pose: np.ndarray,
    rng: np.random.Generator,
    n_decoys: int = 300,
    map_pose_grid: PoseGrid | None = None,
) -> DecoyResult:
    """The thesis' test: score the true pose and ``n_decoys`` false ones, pick the best.

    Examples
    --------
    >>> grid = GroundGrid(0.0, 0.0, 2.0, (300, 300))
    >>> world = np.random.default_rng(0).random(grid.shape).astype(np.float32)
    >>> body = PoseGrid.side_looking(range_m=60.0, pixel_m=2.0)
    >>> truth = np.array([300.0, 300.0, 0.3])
    >>> radar = sample_at_poses(world, grid, body, truth)
    >>> mask = np.ones(body.shape, bool)
    >>> result = decoy_test(radar, mask, world, grid, body, truth, np.random.default_rng(1))
    >>> result.correct(), result.false_positive_fraction
    (True, 0.0)
    """
    true_pose = np.asarray(true_pose, dtype=float)
    poses = np.vstack([true_pose[None], decoy_poses(true_pose, rng, n_decoys)])
    scores = score_poses(radar, radar_mask, map_world, grid, pose_grid, poses, map_pose_grid)
    best = int(np.nanargmax(scores))
    d_heading = wrap_angle(poses[best, 2] - true_pose[2])
    return DecoyResult(
        heading_error_deg=float(abs(np.degrees(d_heading))),
        position_error_m=float(np.hypot(*(poses[best, :2] - true_pose[:2]))),
        false_positive_fraction=float(np.mean(scores[1:] > scores[0])),
        true_score=float(scores[0]),
        best_score=float(scores[best]),
    )
