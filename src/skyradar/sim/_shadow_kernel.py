"""Compiled line-of-sight test of ground facets against the buildings of a height raster.

A facet is in shadow when some raster pixel between it and the antenna rises above the straight line
from the facet to the antenna. The march goes from the facet towards the antenna in horizontal steps
of half a pixel and stops as soon as the line is above the tallest building: only the first few tens
of metres behind a building can be shadowed at the grazing angles of a side-looking radar.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

__all__ = ["shadowed", "shadow_mask"]


@njit(parallel=True, cache=True, error_model="numpy")
def shadowed(height, rows, cols, antenna_rc, antenna_up_m, pixel_m, out):
    """``out[n] = True`` where facet ``(rows[n], cols[n])`` cannot see the antenna over ``height``.

    Parameters
    ----------
    height : (ny, nx) float32
        Height of each pixel's top above the ground (0 for open ground), m.
    rows, cols : (n,) int64
        Facets to test; each sits on top of its own pixel (``height[row, col]``).
    antenna_rc : (2,) float64
        Antenna position in fractional pixel coordinates (row, column).
    antenna_up_m : float
        Antenna height above the ground, m.
    pixel_m : float
        Pixel size, m.
    out : (n,) bool
    """
    ny, nx = height.shape
    h_max = 0.0
    for i in range(ny):
        for j in range(nx):
            h_max = max(h_max, height[i, j])
    for n in prange(rows.shape[0]):
        r0, c0 = rows[n], cols[n]
        z0 = height[r0, c0]
        dr, dc = antenna_rc[0] - r0, antenna_rc[1] - c0
        dist_px = math.sqrt(dr * dr + dc * dc)
        hidden = False
        if dist_px > 1e-9 and antenna_up_m > z0:
            slope = (antenna_up_m - z0) / (dist_px * pixel_m)  # rise of the line per metre
            # Beyond this distance the line is above every building: nothing further can hide it.
            reach_px = min(dist_px, (h_max - z0) / slope / pixel_m) if h_max > z0 else 0.0
            step = 0.5
            n_steps = int(reach_px / step)
            ur, uc = dr / dist_px, dc / dist_px
            for s in range(1, n_steps + 1):
                t = s * step
                i = int(math.floor(r0 + ur * t + 0.5))
                j = int(math.floor(c0 + uc * t + 0.5))
                if i < 0 or j < 0 or i >= ny or j >= nx:
                    break
                if height[i, j] > z0 + slope * t * pixel_m:
                    hidden = True
                    break
        out[n] = hidden
    return out


def shadow_mask(
    height: np.ndarray, antenna_rc: np.ndarray, antenna_up_m: float, pixel_m: float
) -> np.ndarray:
    """Shadow of every pixel of ``height`` seen from an antenna (a convenience for tests and figures).

    Examples
    --------
    >>> height = np.zeros((1, 40), np.float32)
    >>> height[0, 10] = 10.0  # a 10 m wall 10 m from an antenna 20 m up at column 0...
    >>> mask = shadow_mask(height, np.array([0.0, 0.0]), 20.0, 1.0)
    >>> np.nonzero(mask[0])[0].tolist()  # ...hides the ground up to 20 m out (the grazing ray)
    [11, 12, 13, 14, 15, 16, 17, 18, 19]
    """
    grid_rows, grid_cols = np.indices(height.shape)
    out = np.empty(height.size, bool)
    rows, cols = grid_rows.ravel().astype(np.int64), grid_cols.ravel().astype(np.int64)
    height = np.ascontiguousarray(height, np.float32)
    shadowed(height, rows, cols, np.asarray(antenna_rc, float), float(antenna_up_m), float(pixel_m), out)
    return out.reshape(height.shape)
