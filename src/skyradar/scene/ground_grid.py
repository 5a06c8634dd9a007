"""Rasters on the ground plane: a north/east world grid and a body-aligned grid attached to a pose.

A :class:`GroundGrid` is a regular raster in the scenario's local NED frame: row ``i`` is at
``north_m = north0_m + i * pixel_m`` and column ``j`` at ``east_m = east0_m + j * pixel_m`` (both
ascending, pixel centres), so ``imshow(image, origin="lower", extent=grid.extent_m)`` draws north up.

A :class:`PoseGrid` is the same kind of raster in the aircraft's horizontal body axes: rows step
``forward_m``, columns step ``right_m``. Attached to a pose ``(north_m, east_m, heading_rad)`` (heading
clockwise from north) a body point maps to the world by the closed-form rotation::

    north = north_m + forward * cos(heading) - right * sin(heading)
    east  = east_m  + forward * sin(heading) + right * cos(heading)

:func:`sample_at_poses` samples a world raster on a pose grid for many poses at once (bilinear, one
compiled pass): a GPS check scores hundreds of candidate poses per frame, so this is its inner loop.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numba import njit, prange

from skyradar.errors import InputError
from skyradar.extras import import_extra

if TYPE_CHECKING:
    from affine import Affine

__all__ = ["GroundGrid", "PoseGrid", "sample_at_pose", "sample_at_poses"]


def _check_grid(pixel_m: float, shape: tuple[int, int], what: str) -> None:
    if not (np.isfinite(pixel_m) and pixel_m > 0):
        raise InputError(f"{what}: pixel_m must be a positive finite size, got {pixel_m!r}")
    if len(shape) != 2 or min(shape) < 2:
        raise InputError(f"{what}: shape must be two sizes of at least 2 pixels, got {tuple(shape)!r}")


@dataclass(frozen=True)
class GroundGrid:
    """A north/east raster in the local NED world frame (pixel centres, ascending axes).

    Parameters
    ----------
    north0_m, east0_m : float
        World position of the centre of pixel (row 0, column 0).
    pixel_m : float
        Pixel size in metres (square pixels).
    shape : tuple of int
        ``(rows, columns)``: rows step north, columns step east.

    Examples
    --------
    >>> grid = GroundGrid.from_extent(-100.0, 100.0, -50.0, 50.0, pixel_m=10.0)
    >>> grid.shape, float(grid.north_m[0]), float(grid.east_m[-1])
    ((20, 10), -95.0, 45.0)
    >>> row, col = grid.world_to_pixel(-95.0, 45.0)
    >>> float(row), float(col)
    (0.0, 9.0)
    """

    north0_m: float
    east0_m: float
    pixel_m: float
    shape: tuple[int, int]

    def __post_init__(self) -> None:
        _check_grid(self.pixel_m, self.shape, "GroundGrid")
        object.__setattr__(self, "shape", (int(self.shape[0]), int(self.shape[1])))

    @classmethod
    def from_extent(
        cls, north_min_m: float, north_max_m: float, east_min_m: float, east_max_m: float, pixel_m: float
    ) -> GroundGrid:
        """The grid whose pixels tile the rectangle ``[north_min, north_max] x [east_min, east_max]``.

        The number of pixels is rounded up, so the grid covers at least the rectangle.
        """
        _check_grid(pixel_m, (2, 2), "GroundGrid")
        rows = max(2, int(np.ceil((north_max_m - north_min_m) / pixel_m - 1e-9)))
        cols = max(2, int(np.ceil((east_max_m - east_min_m) / pixel_m - 1e-9)))
        return cls(north_min_m + pixel_m / 2, east_min_m + pixel_m / 2, float(pixel_m), (rows, cols))

    @property
    def north_m(self) -> np.ndarray:
        """Row centres, metres north of the origin (ascending)."""
        return self.north0_m + self.pixel_m * np.arange(self.shape[0])

    @property
    def east_m(self) -> np.ndarray:
        """Column centres, metres east of the origin (ascending)."""
        return self.east0_m + self.pixel_m * np.arange(self.shape[1])

    @property
    def extent_m(self) -> tuple[float, float, float, float]:
        """Pixel-edge extent ``(east_min, east_max, north_min, north_max)`` for ``imshow(origin="lower")``."""
        half = self.pixel_m / 2
        return (
            self.east0_m - half,
            self.east0_m + (self.shape[1] - 0.5) * self.pixel_m,
            self.north0_m - half,
            self.north0_m + (self.shape[0] - 0.5) * self.pixel_m,
        )

    @property
    def transform(self) -> Affine:
        """Affine map (column, row) -> (east_m, north_m) of pixel corners, as rasterio expects."""
        east_min, _, north_min, _ = self.extent_m
        affine = import_extra("affine", "geo", "GroundGrid.transform")  # comes with rasterio
        return affine.Affine(self.pixel_m, 0.0, east_min, 0.0, self.pixel_m, north_min)

    def world_to_pixel(
        self, north_m: np.ndarray | float, east_m: np.ndarray | float
    ) -> tuple[np.ndarray, np.ndarray]:
        """Fractional (row, column) of world points; integer values are pixel centres."""
        row = (np.asarray(north_m, dtype=float) - self.north0_m) / self.pixel_m
        col = (np.asarray(east_m, dtype=float) - self.east0_m) / self.pixel_m
        return row, col

    def pixel_to_world(
        self, row: np.ndarray | float, col: np.ndarray | float
    ) -> tuple[np.ndarray, np.ndarray]:
        """World (north_m, east_m) of fractional pixel positions."""
        north = self.north0_m + np.asarray(row, dtype=float) * self.pixel_m
        east = self.east0_m + np.asarray(col, dtype=float) * self.pixel_m
        return north, east

    def contains(self, north_m: np.ndarray | float, east_m: np.ndarray | float) -> np.ndarray:
        """True where a world point lies inside the grid's pixel-edge extent."""
        east_min, east_max, north_min, north_max = self.extent_m
        north, east = np.asarray(north_m, dtype=float), np.asarray(east_m, dtype=float)
        return (north >= north_min) & (north <= north_max) & (east >= east_min) & (east <= east_max)


@dataclass(frozen=True)
class PoseGrid:
    """A raster in horizontal body axes: rows step forward, columns step right (pixel centres).

    Examples
    --------
    >>> body = PoseGrid.side_looking(range_m=100.0, pixel_m=10.0)
    >>> body.shape, float(body.forward_m[0]), float(body.right_m[0])
    ((20, 10), -95.0, 5.0)
    >>> north, east = body.world_points(0.0, 0.0, np.pi / 2)  # heading east: right points south
    >>> float(north[0, 0]), float(east[0, 0])
    (-5.0, -95.0)
    """

    forward0_m: float
    right0_m: float
    pixel_m: float
    shape: tuple[int, int]

    def __post_init__(self) -> None:
        _check_grid(self.pixel_m, self.shape, "PoseGrid")
        object.__setattr__(self, "shape", (int(self.shape[0]), int(self.shape[1])))

    @classmethod
    def side_looking(cls, range_m: float, pixel_m: float, side: str = "right") -> PoseGrid:
        """The half-disc footprint of a sideways radar: forward ``-range..range``, side ``0..range``.

        ``side="left"`` covers right ``-range..0`` instead.
        """
        if side not in ("right", "left"):
            raise InputError(f"PoseGrid: side must be 'right' or 'left', got {side!r}")
        n_side = max(2, int(np.ceil(range_m / pixel_m - 1e-9)))
        right0 = pixel_m / 2 if side == "right" else -n_side * pixel_m + pixel_m / 2
        return cls(-n_side * pixel_m + pixel_m / 2, right0, float(pixel_m), (2 * n_side, n_side))

    @property
    def forward_m(self) -> np.ndarray:
        """Row centres, metres ahead of the aircraft."""
        return self.forward0_m + self.pixel_m * np.arange(self.shape[0])

    @property
    def right_m(self) -> np.ndarray:
        """Column centres, metres to the right of the aircraft."""
        return self.right0_m + self.pixel_m * np.arange(self.shape[1])

    def world_points(
        self, north_m: float, east_m: float, heading_rad: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """World (north_m, east_m) of every pixel centre, each of ``shape``, for one pose."""
        forward, right = np.meshgrid(self.forward_m, self.right_m, indexing="ij")
        c, s = np.cos(heading_rad), np.sin(heading_rad)
        return north_m + forward * c - right * s, east_m + forward * s + right * c


# Fast math without "no NaNs": maps carry NaN for no data, and the bounds test must stay exact.
@njit(cache=True, nogil=True, boundscheck=False, fastmath={"nsz", "arcp", "contract", "afn", "reassoc"})
def _sample_one(image, n0, e0, pix, pose, f0, r0, bpix, fill, out):
    nr, nc = image.shape
    rows, cols = out.shape
    c, s = np.cos(pose[2]), np.sin(pose[2])
    # Pixel coordinates are affine in (i, j): step them instead of recomputing the rotation.
    row_base = (pose[0] + f0 * c - r0 * s - n0) / pix
    col_base = (pose[1] + f0 * s + r0 * c - e0) / pix
    drow_i, dcol_i = bpix * c / pix, bpix * s / pix
    drow_j, dcol_j = -bpix * s / pix, bpix * c / pix
    # A hair of tolerance so a pixel exactly on the raster's edge is not lost to rounding.
    low, row_high, col_high = -1e-6, nr - 1 + 1e-6, nc - 1 + 1e-6
    for i in range(rows):
        row_i = row_base + i * drow_i
        col_i = col_base + i * dcol_i
        for j in range(cols):
            r = row_i + j * drow_j
            q = col_i + j * dcol_j
            if r > low and q > low and r < row_high and q < col_high:
                ri = min(max(int(r), 0), nr - 2)
                qi = min(max(int(q), 0), nc - 2)
                fr, fq = np.float32(r - ri), np.float32(q - qi)
                top = image[ri, qi] + (image[ri, qi + 1] - image[ri, qi]) * fq
                bottom = image[ri + 1, qi] + (image[ri + 1, qi + 1] - image[ri + 1, qi]) * fq
                out[i, j] = top + (bottom - top) * fr
            else:
                out[i, j] = fill


@njit(cache=True, nogil=True)
def _sample_serial(image, n0, e0, pix, poses, f0, r0, bpix, fill, out):
    for k in range(poses.shape[0]):
        _sample_one(image, n0, e0, pix, poses[k], f0, r0, bpix, fill, out[k])


@njit(cache=True, nogil=True, parallel=True)
def _sample_parallel(image, n0, e0, pix, poses, f0, r0, bpix, fill, out):
    for k in prange(poses.shape[0]):
        _sample_one(image, n0, e0, pix, poses[k], f0, r0, bpix, fill, out[k])


def sample_at_poses(
    image: np.ndarray, grid: GroundGrid, pose_grid: PoseGrid, poses: np.ndarray, fill: float = np.nan
) -> np.ndarray:
    """Bilinear samples of a world raster on a body-aligned grid, for many poses at once.

    Parameters
    ----------
    image : (rows, cols) array
        World raster on ``grid`` (any real dtype; sampled in float32).
    grid : GroundGrid
        Where ``image`` lies.
    pose_grid : PoseGrid
        The body-aligned grid to fill.
    poses : (n, 3) array
        ``(north_m, east_m, heading_rad)`` per pose; one pose of shape (3,) is accepted too.
    fill : float
        Value where a body pixel falls outside ``image``. NaN (no data) in ``image`` spreads to every
        sample whose 2 x 2 bilinear stencil touches it.

    Returns
    -------
    (n, rows, cols) float32 array (or (rows, cols) for one pose).

    Examples
    --------
    >>> grid = GroundGrid(0.0, 0.0, 1.0, (4, 4))
    >>> image = np.add.outer(10.0 * np.arange(4), np.arange(4))  # 10 * north + east
    >>> body = PoseGrid(0.0, 0.0, 1.0, (2, 2))
    >>> sample_at_poses(image, grid, body, np.array([1.5, 0.5, 0.0])).tolist()
    [[15.5, 16.5], [25.5, 26.5]]
    """
    image = np.ascontiguousarray(image, dtype=np.float32)
    if image.shape != grid.shape:
        raise InputError(f"sample_at_poses: image shape {image.shape} differs from the grid's {grid.shape}")
    poses = np.asarray(poses, dtype=float)
    single = poses.ndim == 1
    poses = np.ascontiguousarray(np.atleast_2d(poses))
    if poses.shape[1] != 3:
        raise InputError(f"sample_at_poses: poses must be (n, 3) north, east, heading; got {poses.shape}")
    if not np.isfinite(poses).all():
        raise InputError("sample_at_poses: every pose must be finite (north_m, east_m, heading_rad)")
    rows, cols = pose_grid.shape
    out = np.empty((poses.shape[0], rows, cols), dtype=np.float32)
    # Poses in parallel from the main thread only: numba's default (workqueue) threading layer must not
    # be entered from two threads at once, as Dask worker threads would.
    many = poses.shape[0] >= 8 and threading.current_thread() is threading.main_thread()
    kernel = _sample_parallel if many else _sample_serial
    kernel(
        image,
        grid.north0_m,
        grid.east0_m,
        grid.pixel_m,
        poses,
        pose_grid.forward0_m,
        pose_grid.right0_m,
        pose_grid.pixel_m,
        np.float32(fill),
        out,
    )
    return out[0] if single else out


def sample_at_pose(
    image: np.ndarray,
    grid: GroundGrid,
    pose_grid: PoseGrid,
    north_m: float,
    east_m: float,
    heading_rad: float,
    fill: float = np.nan,
) -> np.ndarray:
    """Bilinear samples of a world raster on a body-aligned grid at one pose; shape ``pose_grid.shape``.

    Examples
    --------
    >>> grid = GroundGrid(0.0, 0.0, 1.0, (3, 3))
    >>> image = np.arange(9.0).reshape(3, 3)
    >>> sample_at_pose(image, grid, PoseGrid(0.0, 0.0, 1.0, (2, 2)), 1.0, 1.0, np.pi).tolist()
    [[4.0, 3.0], [1.0, 0.0]]
    """
    return sample_at_poses(image, grid, pose_grid, np.array([north_m, east_m, heading_rad]), fill)
