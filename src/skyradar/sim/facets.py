"""How finely the image simulator cuts each DEM cell into sub-facets.

Two rules:

- **uniform** (the default without the point-spread, and the rule of the ch2-ch6 results): every
  cell is cut into ``ceil(spacing / facet_size_m)`` sub-facets per axis, so no sub-facet edge is
  longer than ``facet_size_m`` on the ground;
- **adaptive** (the default with the point-spread): each cell is cut as finely as its
  own range and Doppler extent need. Along each cell axis, ``n`` is the smallest count for which
  one sub-facet edge spans at most ``facet_size_m`` of range and at most ``facet_size_m / dR``
  Doppler bins (half a bin each with the default ``facet_size_m = dR/2``). A cell seen from
  straight above spans little range; a cell far out spans little Doppler: both need fewer
  sub-facets than the ground-size rule gives (2.1x fewer over the benchmark tile), while a cell
  whose Doppler changes fast gets more.

The adaptive count per axis is

    n = ceil(max((dR_edge + H_R L^2 / 2) / facet_size_m, (dV_edge + H_V L^2 / 2) / target_V)),

with ``dR_edge``, ``dV_edge`` the largest range and radial-velocity change between the cell's
corners along that axis, ``L`` the axis' longest edge, ``H_R = 1 / R_min`` and
``H_V = sqrt(5) |v| / R_min^2`` bounds on the second derivative of range and of radial velocity
(``v . p / |p|``) along any line, and ``R_min`` a lower bound of the cell's distance. The
curvature terms make the count a bound on the sub-facet extent, not just a corner estimate: the
gradient along the edge is at most ``d_edge / L + H L / 2`` everywhere. ``tests/test_sim_facets.py``
measures the extents on a dense grid of each sub-facet against the targets.

Limits of the adaptive rule, each stated where it applies: at least ``min(uniform count, 2)``
per axis (occlusion and the antenna gain are still sampled at least 2 x 2 times per DEM cell, as
the horizon is), and at most ``max(4 x uniform count, 8)`` per axis (only cells right under a
radar a few hundred metres up reach it; their sub-facets are then still 4x finer on the ground
than the uniform rule's).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from numba import njit

from skyradar.config import RadarConfig

__all__ = ["FacetRule", "facet_rule", "cell_counts"]


class FacetRule(NamedTuple):
    """Sub-facet counts per cell axis (rows, columns) for the terrain kernel.

    Parameters
    ----------
    n_min : (int, int)
        The uniform counts, or the adaptive minimum.
    n_max : (int, int)
        The largest counts (equal to ``n_min`` for the uniform rule).
    adapt : (float, float, float, float)
        (range target, m; radial-velocity target, m/s; 0; 0), or all 0 for the uniform rule.

    Examples
    --------
    >>> rule = FacetRule((2, 2), (8, 12), (7.5, 0.157, 0.0, 0.0))
    >>> rule.counts, rule.per_cell_max  # 8 x 12 sub-facets at most
    ((2, 2, 8, 12), 96)
    """

    n_min: tuple[int, int]
    n_max: tuple[int, int]
    adapt: tuple[float, float, float, float]

    @property
    def counts(self) -> tuple[int, int, int, int]:
        """(n_min rows, n_min columns, n_max rows, n_max columns), the kernel's argument."""
        return (*self.n_min, *self.n_max)

    @property
    def per_cell_max(self) -> int:
        """Most sub-facets one cell can get."""
        return self.n_max[0] * self.n_max[1]


def facet_rule(
    config: RadarConfig, spacing_m: tuple[float, float], facet_size_m: float, adaptive: bool
) -> FacetRule:
    """The sub-facet rule for a DEM of ``spacing_m`` (rows, columns) and the facet size.

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> facet_rule(cfg, (92.6, 65.5), 7.5, adaptive=False).n_max
    (13, 9)
    >>> rule = facet_rule(cfg, (92.6, 65.5), 7.5, adaptive=True)
    >>> rule.n_min, rule.n_max, round(rule.adapt[1], 3)  # half a Doppler bin, m/s
    ((2, 2), (52, 36), 0.157)
    """
    finite = math.isfinite(facet_size_m)
    n_rows, n_cols = (max(1, math.ceil(s / facet_size_m)) if finite else 1 for s in spacing_m)
    uniform = (n_rows, n_cols)
    if not adaptive or not finite:
        return FacetRule(uniform, uniform, (0.0, 0.0, 0.0, 0.0))
    target_v = facet_size_m / config.range_resolution_m * config.doppler_resolution_mps
    n_min = (min(n_rows, 2), min(n_cols, 2))
    n_max = (max(4 * n_rows, 8), max(4 * n_cols, 8))
    return FacetRule(n_min, n_max, (float(facet_size_m), float(target_v), 0.0, 0.0))


@njit(inline="always")
def cell_counts(p_ant, i, j, vg, n_min_r, n_min_c, n_max_r, n_max_c, adapt):
    """Sub-facets per axis of cell (i, j): the adaptive rule of :mod:`skyradar.sim.facets`."""
    target_r, target_v = adapt[0], adapt[1]
    if target_r <= 0.0:
        return n_min_r, n_min_c
    # Corner ranges and radial velocities as scalars: a small array here would be a heap
    # allocation per cell.
    r00, v00 = _range_velocity(p_ant, i, j, vg)
    r01, v01 = _range_velocity(p_ant, i, j + 1, vg)
    r10, v10 = _range_velocity(p_ant, i + 1, j, vg)
    r11, v11 = _range_velocity(p_ant, i + 1, j + 1, vg)
    l_u = max(_dist(p_ant, i, j, i + 1, j), _dist(p_ant, i, j + 1, i + 1, j + 1))
    l_w = max(_dist(p_ant, i, j, i, j + 1), _dist(p_ant, i + 1, j, i + 1, j + 1))
    r_min = max(min(min(r00, r01), min(r10, r11)) - (l_u + l_w), 1e-3)
    h_r = 1.0 / r_min
    h_v = math.sqrt(5.0) * math.sqrt(vg[0] * vg[0] + vg[1] * vg[1] + vg[2] * vg[2]) / (r_min * r_min)
    dr_u, dv_u = max(abs(r10 - r00), abs(r11 - r01)), max(abs(v10 - v00), abs(v11 - v01))
    dr_w, dv_w = max(abs(r01 - r00), abs(r11 - r10)), max(abs(v01 - v00), abs(v11 - v10))
    n_u = _axis_count(dr_u, dv_u, l_u, h_r, h_v, target_r, target_v)
    n_w = _axis_count(dr_w, dv_w, l_w, h_r, h_v, target_r, target_v)
    return min(max(n_u, n_min_r), n_max_r), min(max(n_w, n_min_c), n_max_c)


@njit(inline="always")
def _range_velocity(p, i, j, vg):
    x, y, z = p[i, j, 0], p[i, j, 1], p[i, j, 2]
    r = math.sqrt(x * x + y * y + z * z)
    return r, (vg[0] * x + vg[1] * y + vg[2] * z) / max(r, 1e-9)


@njit(inline="always")
def _dist(p, i0, j0, i1, j1):
    dx, dy, dz = p[i1, j1, 0] - p[i0, j0, 0], p[i1, j1, 1] - p[i0, j0, 1], p[i1, j1, 2] - p[i0, j0, 2]
    return math.sqrt(dx * dx + dy * dy + dz * dz)


@njit(inline="always")
def _axis_count(d_r, d_v, length, h_r, h_v, target_r, target_v):
    # Largest change along the axis: corner change plus the curvature bound (facets.py).
    n_r = (d_r + 0.5 * h_r * length * length) / target_r
    n_v = (d_v + 0.5 * h_v * length * length) / target_v if target_v > 0.0 else 0.0
    return int(min(math.ceil(max(n_r, n_v)), 1e6))
