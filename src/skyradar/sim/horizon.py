"""The polar horizon around the antenna for the occlusion test: its grid, its map, targets' line of sight.

Terrain facets and point targets are hidden by the same rule: a point is hidden when its slope
(-down / horizontal distance, seen from the antenna) is below the steepest slope of any terrain
sample strictly closer along its azimuth bin (:mod:`skyradar.sim._horizon_kernel`). A frame
needs the whole map (every facet is tested); a target's truth needs one entry of it per target,
which :func:`target_clear` computes from the cells near that azimuth only, equal to the map's.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from skyradar.sim._horizon_kernel import horizon_at, horizon_map

__all__ = ["HorizonGrid", "horizon_grid", "needs_horizon", "terrain_horizon", "target_bins", "target_clear"]

LEVEL_CLEAR_M = 50.0  # antenna height above level terrain from which nothing in range is hidden


class HorizonGrid(NamedTuple):
    """Bins of the polar horizon of one simulator (radar and DEM spacing fix them).

    Parameters
    ----------
    nsub : (int, int)
        Horizon samples per DEM cell, per axis.
    r_lim_m : float
        Samples beyond this horizontal distance are left out, m.
    az_bin_rad : float
        Azimuth bin width, rad.
    h_bin_m : float
        Horizontal-distance bin width, m.
    n_az, n_h : int
        Azimuth and horizontal-distance bins.
    sample_m : float
        The patch one sample stands for, m (see ``horizon_map``).

    Examples
    --------
    >>> from skyradar.config import RadarConfig
    >>> g = horizon_grid(RadarConfig.prototype_2022(range_limit_m=300.0), (10.0, 10.0), (4, 4), 7.5)
    >>> g.nsub, g.h_bin_m, g.n_az, g.n_h, g.sample_m  # n_az: ceil(pi r_lim / h_bin)
    ((2, 2), 7.5, 132, 43, 5.0)
    >>> round(g.az_bin_rad * g.n_az, 6) == round(2 * np.pi, 6)
    True
    """

    nsub: tuple[int, int]  # horizon samples per DEM cell, per axis
    r_lim_m: float  # samples beyond this horizontal distance are left out
    az_bin_rad: float
    h_bin_m: float
    n_az: int
    n_h: int
    sample_m: float  # the patch one sample stands for (see horizon_map)


def horizon_grid(
    config, spacing_m: tuple[float, float], nsub: tuple[int, int], facet_m: float
) -> HorizonGrid:
    """The horizon's bins for ``config`` over a DEM of ``spacing_m`` cut into ``nsub`` sub-facets.

    The horizon follows the terrain's shape, which the DEM resolves at its own spacing: 2 x 2
    samples per DEM cell and bins of half the spacing, not every sub-facet.

    Examples
    --------
    >>> from skyradar.config import RadarConfig
    >>> g = horizon_grid(RadarConfig.prototype_2022(), (30.0, 30.0), (4, 4), 7.5)
    >>> g.nsub, g.h_bin_m, g.n_h
    ((2, 2), 15.0, 336)
    """
    r_lim = config.range_limit_m + config.range_resolution_m
    h_nsub = (min(nsub[0], 2), min(nsub[1], 2))
    h_bin = max(facet_m, min(spacing_m) / 2.0)
    n_az = int(np.ceil(2 * np.pi * (r_lim / 2.0) / h_bin))
    n_h = int(np.ceil(r_lim / h_bin)) + 1
    sample_m = max(spacing_m[0] / h_nsub[0], spacing_m[1] / h_nsub[1])
    return HorizonGrid(h_nsub, r_lim, 2 * np.pi / n_az, h_bin, n_az, n_h, sample_m)


def needs_horizon(grid: HorizonGrid, p_ned: np.ndarray, level: bool, occlusion: bool) -> bool:
    """False when nothing in range can be hidden: no occlusion, or level terrain well below.

    Level terrain (one height everywhere) is a convex surface: it hides nothing closer than its
    geometric horizon, sqrt(2 R_earth h), 25 km at h = 50 m. With the antenna more than
    ``LEVEL_CLEAR_M`` above every point of the crop (a lower bound of its height) and the range
    limit below that, the horizon is skipped: the same frames, without its cost.

    Parameters
    ----------
    grid : HorizonGrid
        The simulator's horizon bins.
    p_ned : ndarray, shape (..., 3)
        The terrain crop relative to the antenna, NED, m.
    level : bool
        The terrain has one height everywhere.
    occlusion : bool
        The simulator's occlusion option.

    Returns
    -------
    bool
        True when the frame needs the horizon map.

    Examples
    --------
    >>> from skyradar.config import RadarConfig
    >>> grid = horizon_grid(RadarConfig.prototype_2022(), (30.0, 30.0), (2, 2), 7.5)
    >>> below_60 = np.array([[[0.0, 0.0, 60.0], [30.0, 0.0, 60.0]]])  # level ground 60 m down
    >>> needs_horizon(grid, below_60, True, True), needs_horizon(grid, below_60 - [0, 0, 20], True, True)
    (False, True)
    >>> needs_horizon(grid, below_60, False, True), needs_horizon(grid, below_60, False, False)
    (True, False)
    """
    clear = level and grid.r_lim_m < 20e3 and float(p_ned[..., 2].min()) > LEVEL_CLEAR_M
    return bool(occlusion) and not clear


def terrain_horizon(
    grid: HorizonGrid, p_ned: np.ndarray, rot_ned_to_ant: np.ndarray, n_blocks: int
) -> np.ndarray:
    """The whole (n_az, n_h) horizon map of the crop ``p_ned`` (NED, relative to the antenna).

    Parameters
    ----------
    grid : HorizonGrid
        The horizon bins.
    p_ned : ndarray, shape (rows, cols, 3)
        DEM grid points relative to the antenna, NED, m.
    rot_ned_to_ant : ndarray, shape (3, 3)
        NED to antenna-frame rotation.
    n_blocks : int
        Parallel blocks of the map's computation.

    Returns
    -------
    ndarray, shape (n_az, n_h)
        Per bin, the steepest slope (-down / horizontal distance) of the terrain strictly closer
        along its azimuth; -inf where nothing is closer.

    Examples
    --------
    Beyond a ridge whose top is 10 m below the antenna, 100 to 110 m north, a point must be above
    the ridge's slope, about -10 m over 100 m:

    >>> from skyradar.config import RadarConfig
    >>> grid = horizon_grid(RadarConfig.prototype_2022(range_limit_m=300.0), (10.0, 10.0), (2, 2), 7.5)
    >>> n, e = np.meshgrid(np.arange(-300.0, 301.0, 10.0), np.arange(-300.0, 301.0, 10.0), indexing="ij")
    >>> down = np.where((n >= 100) & (n <= 110), 10.0, 50.0)  # ground 50 m below, a ridge 100 m north
    >>> p_ned = np.stack([n, e, down], -1)
    >>> horizon = terrain_horizon(grid, p_ned, np.eye(3), 1)
    >>> bins = (grid.az_bin_rad, grid.h_bin_m, grid.n_az, grid.n_h)
    >>> a, k, _ = target_bins(np.array([[200.0, 0.0, 0.0]]), *bins)  # 200 m north
    >>> horizon.shape, round(float(horizon[a[0], k[0]]), 3)
    ((132, 43), -0.093)
    """
    return horizon_map(
        p_ned,
        rot_ned_to_ant,
        *grid.nsub,
        grid.r_lim_m,
        grid.az_bin_rad,
        grid.h_bin_m,
        grid.n_az,
        grid.n_h,
        n_blocks,
        grid.sample_m,
    )


def target_bins(
    rel_ned: np.ndarray, az_bin_rad: float, h_bin_m: float, n_az: int, n_h: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Azimuth bin, horizontal-range bin and slope of points ``rel_ned`` (m, relative to the antenna).

    Parameters
    ----------
    rel_ned : ndarray, shape (n, 3)
        Points relative to the antenna, NED, m.
    az_bin_rad : float
        Azimuth bin width, rad; bin 0 starts at -pi (south).
    h_bin_m : float
        Horizontal-distance bin width, m.
    n_az, n_h : int
        Azimuth and horizontal-distance bins (the last distance bin takes everything beyond).

    Returns
    -------
    (ndarray, ndarray, ndarray)
        Azimuth bins, distance bins and slopes (-down / horizontal distance) of the points.

    Examples
    --------
    >>> rel = np.array([[100.0, 0.0, 50.0], [0.0, 100.0, -10.0], [0.0, 900.0, 0.0]])
    >>> a, k, slope = target_bins(rel, np.pi / 2, 30.0, 4, 10)
    >>> a.tolist(), k.tolist(), slope.tolist()  # north, east; 100 m is bin 3; 900 m the last bin
    ([2, 3, 3], [3, 3, 9], [-0.5, 0.1, -0.0])
    """
    h = np.hypot(rel_ned[:, 0], rel_ned[:, 1])
    a = ((np.arctan2(rel_ned[:, 1], rel_ned[:, 0]) + np.pi) / az_bin_rad).astype(int) % n_az
    k = np.minimum((h / h_bin_m).astype(int), n_h - 1)
    return a, k, -rel_ned[:, 2] / np.maximum(h, 1e-9)


def target_clear(
    grid: HorizonGrid, p_ned: np.ndarray, rot_ned_to_ant: np.ndarray, rel_ned: np.ndarray
) -> np.ndarray:
    """True for points ``rel_ned`` not hidden by the crop ``p_ned``: the frame's test, without its map.

    Parameters
    ----------
    grid : HorizonGrid
        The horizon bins.
    p_ned : ndarray, shape (rows, cols, 3)
        DEM grid points relative to the antenna, NED, m.
    rot_ned_to_ant : ndarray, shape (3, 3)
        NED to antenna-frame rotation.
    rel_ned : ndarray, shape (n, 3)
        Points relative to the antenna, NED, m.

    Returns
    -------
    ndarray of bool, shape (n,)
        Equal to testing the points against :func:`terrain_horizon`'s map.

    Examples
    --------
    A ridge 10 m below the antenna, 100 m north, hides a point 200 m north and 40 m below the
    antenna (slope -0.2), not one 20 m above it; nothing hides a point to the south:

    >>> from skyradar.config import RadarConfig
    >>> grid = horizon_grid(RadarConfig.prototype_2022(range_limit_m=300.0), (10.0, 10.0), (2, 2), 7.5)
    >>> n, e = np.meshgrid(np.arange(-300.0, 301.0, 10.0), np.arange(-300.0, 301.0, 10.0), indexing="ij")
    >>> down = np.where((n >= 100) & (n <= 110), 10.0, 50.0)  # ground 50 m below, a ridge 100 m north
    >>> p_ned = np.stack([n, e, down], -1)
    >>> rel = np.array([[200.0, 0.0, 40.0], [200.0, 0.0, -20.0], [-200.0, 0.0, 40.0]])
    >>> target_clear(grid, p_ned, np.eye(3), rel).tolist()
    [False, True, True]
    """
    a, k, slope = target_bins(rel_ned, grid.az_bin_rad, grid.h_bin_m, grid.n_az, grid.n_h)
    entries = horizon_at(
        p_ned,
        rot_ned_to_ant,
        *grid.nsub,
        grid.r_lim_m,
        grid.az_bin_rad,
        grid.h_bin_m,
        grid.n_az,
        grid.n_h,
        grid.sample_m,
        a.astype(np.int64),
        k.astype(np.int64),
    )
    return slope >= entries
