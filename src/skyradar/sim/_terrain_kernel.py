"""Compiled inner loop of the image-domain simulator: terrain facets into the range-Doppler cube.

Per sub-facet: bilinear position, exact surface area and normal, behind-the-antenna and range
culling, line-of-sight test against a polar horizon, two-way antenna gain, incidence-angle
reflectivity, radar equation, exact two-way path phase per receive antenna, and the
scatter-add into the pixel. Whole grid cells are culled first. The sub-facets then go through
the vectorised batches of ``_terrain_batch`` (a cell at a time, or a row's worth of small
cells), or, as the reference, through the scalar loop here one at a time. Row blocks run in
parallel, each into its own cube, so no two threads add into one pixel.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange, uint64

from skyradar.sim._elementary import cis_cycles, fast_atan2, wrap_index
from skyradar.sim._terrain_batch import (
    CELL_FIELDS,
    cell_geometry,
    cell_geometry_scalar,
    item_returns,
    number_items,
    scatter_items,
)
from skyradar.sim.facets import cell_counts

_CULL_SLACK_M = 1e-6  # m: the cull bound's margin over the rounding of the patch formula (1e-9 m at 10 km)

__all__ = [
    "add_sparse",
    "cell_count_grid",
    "cis_cycles",
    "fast_atan2",
    "relative_points",
    "rotate_points",
    "terrain_returns",
]


@njit(inline="always")
def _polar_bin(n, e, d, az_bin_rad, h_bin_m, n_az, n_h):
    # Azimuth bin, horizontal-range bin, and the slope -d/h (tan of the elevation angle: the
    # same order as the angle, without an atan2).
    h = math.sqrt(n * n + e * e)
    a = wrap_index(int((fast_atan2(e, n) + math.pi) / az_bin_rad), n_az)
    k = min(int(h / h_bin_m), n_h - 1)
    return a, k, -d / max(h, 1e-9)


@njit(inline="always")
def _table(x, x0, dx, table):
    f = (x - x0) / dx
    if f <= 0.0:
        return table[0]
    n = table.shape[0]
    if f >= n - 1:
        return table[n - 1]
    i = int(f)
    t = f - i
    return table[uint64(i)] * (1.0 - t) + table[uint64(i + 1)] * t


@njit(inline="always")
def _table2(uy, uz, step, table):
    # Bilinear lookup on a grid of direction cosines spanning [-1, 1] in both axes.
    fy = (uy + 1.0) / step
    fz = (uz + 1.0) / step
    n = table.shape[0] - 1
    iy = min(max(int(fy), 0), n - 1)
    iz = min(max(int(fz), 0), n - 1)
    ty = min(max(fy - iy, 0.0), 1.0)
    tz = min(max(fz - iz, 0.0), 1.0)
    # Unsigned indices: numba then skips its negative-index wrap-around check.
    row0, row1 = table[uint64(iy)], table[uint64(iy + 1)]
    uz0, uz1 = uint64(iz), uint64(iz + 1)
    return (1 - ty) * ((1 - tz) * row0[uz0] + tz * row0[uz1]) + ty * ((1 - tz) * row1[uz0] + tz * row1[uz1])


@njit(inline="always")
def _corner_terms(g, i, j, out):
    # Bilinear patch p(u, w) = p00 + u*e1 + w*e2 + u*w*e3 over one grid cell.
    for c in range(3):
        out[0, c] = g[i, j, c]
        out[1, c] = g[i + 1, j, c] - g[i, j, c]
        out[2, c] = g[i, j + 1, c] - g[i, j, c]
        out[3, c] = g[i + 1, j + 1, c] - g[i + 1, j, c] - g[i, j + 1, c] + g[i, j, c]


@njit(inline="always")
def _patch_point(t, u, w, c):
    return t[0, c] + u * t[1, c] + w * t[2, c] + u * w * t[3, c]


@njit(inline="always")
def _patch_normal(t, u, w, up):
    """Upward normal of the bilinear patch at (u, w); its length is the area per unit (u, w)."""
    dux, duy, duz = t[1, 0] + w * t[3, 0], t[1, 1] + w * t[3, 1], t[1, 2] + w * t[3, 2]
    dwx, dwy, dwz = t[2, 0] + u * t[3, 0], t[2, 1] + u * t[3, 1], t[2, 2] + u * t[3, 2]
    nx = duy * dwz - duz * dwy
    ny = duz * dwx - dux * dwz
    nz = dux * dwy - duy * dwx
    if nx * up[0] + ny * up[1] + nz * up[2] < 0.0:
        return -nx, -ny, -nz, math.sqrt(nx * nx + ny * ny + nz * nz)
    return nx, ny, nz, math.sqrt(nx * nx + ny * ny + nz * nz)


@njit(inline="always")
def _cell_behind(p_ant, i, j):
    return (
        p_ant[i, j, 0] <= 0.0
        and p_ant[i + 1, j, 0] <= 0.0
        and p_ant[i, j + 1, 0] <= 0.0
        and p_ant[i + 1, j + 1, 0] <= 0.0
    )


@njit(inline="always")
def _cell_nearest(p_ant, i, j):
    """A lower bound (m) of the distance from the antenna to any point of cell (i, j).

    A point of the bilinear patch is a convex combination of the four corners, so its
    component along any unit vector ``n`` is at least the smallest corner component, and its
    distance at least that component: with ``n`` towards the corners' centroid this is within
    about half the cell's diagonal of the true nearest distance. The nearest corner's distance
    minus the cell's extent (a sum of absolute coordinate differences) bounds it too; the
    larger of the two holds. ``_CULL_SLACK_M`` covers the rounding of the patch formula.
    """
    cx, cy, cz, nearest2, extent = 0.0, 0.0, 0.0, 1e300, 0.0
    for ci in range(2):
        for cj in range(2):
            x, y, z = p_ant[i + ci, j + cj, 0], p_ant[i + ci, j + cj, 1], p_ant[i + ci, j + cj, 2]
            nearest2 = min(nearest2, x * x + y * y + z * z)
            cx, cy, cz = cx + x, cy + y, cz + z
    for c in range(3):
        extent += abs(p_ant[i + 1, j + 1, c] - p_ant[i, j, c]) + abs(p_ant[i + 1, j, c] - p_ant[i, j + 1, c])
    bound = math.sqrt(nearest2) - extent
    norm = math.sqrt(cx * cx + cy * cy + cz * cz)
    if norm > 0.0:
        along = 1e300
        for ci in range(2):
            for cj in range(2):
                x, y, z = p_ant[i + ci, j + cj, 0], p_ant[i + ci, j + cj, 1], p_ant[i + ci, j + cj, 2]
                along = min(along, cx * x + cy * y + cz * z)
        bound = max(bound, along / norm)
    return max(bound - _CULL_SLACK_M, 0.0)


@njit(inline="always")
def _cell_beyond(p_ant, i, j, r_max):
    # No point of the cell can be within r_max when a lower bound of its distance exceeds it
    # (its sub-facets would all fail the per-sub-facet test r0 <= r_max).
    return _cell_nearest(p_ant, i, j) > r_max


@njit(inline="always")
def _hidden(tn, u, w, horizon, az_bin_rad, h_bin_m):
    pn, pe, pd = _patch_point(tn, u, w, 0), _patch_point(tn, u, w, 1), _patch_point(tn, u, w, 2)
    ia, k, slope = _polar_bin(pn, pe, pd, az_bin_rad, h_bin_m, horizon.shape[0], horizon.shape[1])
    return slope < horizon[uint64(ia), uint64(k)]


@njit(inline="always")
def _two_way_paths(x, y, z, tx, rx, r_rx):
    """Transmitter range (returned) and each receiver's range (into ``r_rx``), m."""
    dx, dy, dz = x - tx[0], y - tx[1], z - tx[2]
    r_tx = math.sqrt(dx * dx + dy * dy + dz * dz)
    for q in range(rx.shape[0]):
        dx, dy, dz = x - rx[q, 0], y - rx[q, 1], z - rx[q, 2]
        r_rx[q] = math.sqrt(dx * dx + dy * dy + dz * dz)
    return r_tx


@njit(inline="always")
def _accumulate(out, sparse, blk, kr, kd, amp, r_tx, r_rx, inv_wavelength):
    # Exact two-way path phase per receiver; into the dense block, or appended to the sparse
    # list (pixel, value per receiver) when the frame has fewer facets than pixels.
    idx, val, count = sparse
    if idx.shape[1] > 0:
        n = count[blk]
        idx[blk, n] = kr * out.shape[2] + kd
        count[blk] = n + 1
        for q in range(r_rx.shape[0]):
            cos_p, sin_p = cis_cycles((r_tx + r_rx[q]) * inv_wavelength)
            val[blk, n, q] = complex(amp * cos_p, amp * sin_p)
    else:
        # Unsigned pixel indices (kr, kd >= 0 here): numba then skips its wrap-around check,
        # which cost 16% of the whole kernel.
        pixel = out[blk, uint64(kr), uint64(kd)]
        for q in range(r_rx.shape[0]):
            cos_p, sin_p = cis_cycles((r_tx + r_rx[q]) * inv_wavelength)
            pixel[q] += complex(amp * cos_p, amp * sin_p)


@njit(cache=True, error_model="numpy")
def relative_points(grid, row0, row1, col0, col1, origin, out):
    """``out[:] = grid[row0:row1, col0:col1] - origin``; ``out`` is (rows, cols, 3), C order.

    numpy's broadcast subtract runs its inner loop over the last axis, three elements long,
    and took 0.17 ms for a 5 km crop; this takes a tenth of that.
    """
    block = grid[row0:row1, col0:col1]
    o0, o1, o2 = origin[0], origin[1], origin[2]
    for i in range(block.shape[0]):
        src, dst = block[i], out[i]
        for j in range(dst.shape[0]):
            dst[j, 0] = src[j, 0] - o0
            dst[j, 1] = src[j, 1] - o1
            dst[j, 2] = src[j, 2] - o2
    return out


@njit(parallel=True, cache=True, error_model="numpy")
def add_sparse(frame, idx, val, count):
    """Add recorded contributions into ``frame`` of shape (n_range * n_doppler, n_rx).

    One share of the pixels per list (the lists are per thread): each thread takes a
    contiguous share (the share its noise pass just wrote, still in its cache) and scans every
    list for it. Per pixel the additions keep the order of the lists.
    """
    n_parts = count.shape[0]
    n_pix = frame.shape[0]
    for part in prange(n_parts):
        lo, hi = part * n_pix // n_parts, (part + 1) * n_pix // n_parts
        for blk in range(count.shape[0]):
            pixels, values = idx[blk], val[blk]
            for n in range(count[blk]):
                p = pixels[n]
                if p < lo or p >= hi:
                    continue
                # Unsigned pixel index (>= 0 by construction): no wrap-around check.
                dst, src = frame[uint64(p)], values[n]
                for q in range(dst.shape[0]):
                    dst[q] += src[q]


@njit(cache=True, error_model="numpy")
def rotate_points(points, rot, out):
    """``out[:] = points @ rot.T`` for (ny, nx, 3) points and a 3 x 3 rotation (C order)."""
    r00, r01, r02, r10, r11, r12 = rot[0, 0], rot[0, 1], rot[0, 2], rot[1, 0], rot[1, 1], rot[1, 2]
    r20, r21, r22 = rot[2, 0], rot[2, 1], rot[2, 2]
    for i in range(points.shape[0]):
        src, dst = points[i], out[i]
        for j in range(src.shape[0]):
            x, y, z = src[j, 0], src[j, 1], src[j, 2]
            dst[j, 0] = r00 * x + r01 * y + r02 * z
            dst[j, 1] = r10 * x + r11 * y + r12 * z
            dst[j, 2] = r20 * x + r21 * y + r22 * z
    return out


@njit(cache=True, error_model="numpy")
def cell_count_grid(p_ant, v_ground_ant, counts, adapt, r_max):
    """Sub-facets per axis (ny - 1, nx - 1, 2) that ``terrain_returns`` cuts each cell into (0: culled)."""
    out = np.zeros((p_ant.shape[0] - 1, p_ant.shape[1] - 1, 2), np.int64)
    n0, n1, n2, n3 = counts[0], counts[1], counts[2], counts[3]
    for i in range(p_ant.shape[0] - 1):
        for j in range(p_ant.shape[1] - 1):
            if not (_cell_behind(p_ant, i, j) or _cell_beyond(p_ant, i, j, r_max)):
                out[i, j] = cell_counts(p_ant, i, j, v_ground_ant, n0, n1, n2, n3, adapt)
    return out


@njit(inline="always")
def _sub_centres(us, ws, nu, nw):
    # Nested loops, not m // nw and m % nw: integer divisions per sub-facet cost more here.
    m = 0
    for a in range(nu):
        u = (a + 0.5) / nu
        for b in range(nw):
            us[m], ws[m] = u, (b + 0.5) / nw
            m += 1


@njit(parallel=True, cache=True, fastmath=True, error_model="numpy")
def terrain_returns(
    p_ned,
    p_ant,
    up_ant,
    tx,
    rx,
    v_ground_ant,
    counts,
    adapt,
    wavelength,
    d_range,
    d_vel,
    coupling,
    power_const,
    gain2,
    gain2_step,
    refl_table,
    horizon,
    az_bin_rad,
    h_bin_m,
    use_horizon,
    n_blocks,
    out,
    sparse,
    mode,
    speckle_key,
):
    """Accumulate terrain returns into ``out`` of shape (n_blocks, n_range, n_doppler, n_rx).

    Parameters are in SI units. ``p_ned`` and ``p_ant`` are the cropped grid relative to the
    antenna phase centre in NED and in the antenna frame (m); ``up_ant`` is the local up
    direction in the antenna frame; ``tx``/``rx`` are antenna positions in the antenna frame;
    ``v_ground_ant`` is the velocity of the static ground relative to the radar in the antenna
    frame. ``counts`` (n_min_r, n_min_c, n_max_r, n_max_c) and ``adapt`` are the sub-facet rule
    (:class:`skyradar.sim.facets.FacetRule`). ``power_const`` is Pe * lambda^2 / (4 pi)^3.
    ``gain2`` is the two-way linear gain G^2 on a regular grid of antenna-frame direction
    cosines (u_y, u_z) over [-1, 1]^2 with spacing ``gain2_step``. ``sparse`` is (idx, val,
    count): with ``idx`` of shape (n_blocks, cap) and cap > 0 contributions are recorded there
    instead of added to ``out`` (see :func:`add_sparse`). ``mode`` 1 runs the vectorised
    batches of ``_terrain_batch``, 0 the scalar loop below, one sub-facet at a time (the same
    physics term for term: the reference the batches are tested against). ``speckle_key`` not
    0 multiplies every sub-facet by its own unit-power complex Gaussian drawn from that key and
    its number (batched mode only). ``fastmath`` is safe here: every input is finite.
    """
    ny, nx = p_ned.shape[0], p_ned.shape[1]
    n_range, n_dopp = out.shape[1], out.shape[2]
    r_max = d_range * (n_range + 2)
    n_min_r, n_min_c, n_max_r, n_max_c = counts
    n_cell_max = n_max_r * n_max_c
    # Cells are gathered into batches of up to max(512, one cell) sub-facets, by row.
    cap = max(n_cell_max, 512) if mode == 1 else 0
    inv_wl = 1.0 / wavelength
    for blk in prange(n_blocks):
        ta, tn, r_rx = np.empty((4, 3)), np.empty((4, 3)), np.empty(rx.shape[0])
        us, ws = np.empty(n_cell_max), np.empty(n_cell_max)
        scratch = np.zeros((CELL_FIELDS, cap))
        r_rx_sub, cos_sin = np.empty((rx.shape[0], cap)), np.empty((2, rx.shape[0], cap), np.float32)
        k = np.int64(0)  # items in the batch (typed int64, not the literal 0: one compile of the callees)
        for i in range(blk, ny - 1, n_blocks):  # interleaved rows: blocks share the work evenly
            for j in range(nx - 1):
                if _cell_behind(p_ant, i, j) or _cell_beyond(p_ant, i, j, r_max):
                    continue
                nu, nw = cell_counts(p_ant, i, j, v_ground_ant, n_min_r, n_min_c, n_max_r, n_max_c, adapt)
                n_sub = nu * nw
                _sub_centres(us, ws, nu, nw)
                _corner_terms(p_ant, i, j, ta)
                if use_horizon:
                    _corner_terms(p_ned, i, j, tn)
                if mode != 1:
                    _reference_cell(
                        ta,
                        tn,
                        up_ant,
                        tx,
                        rx,
                        r_rx,
                        v_ground_ant,
                        nu,
                        nw,
                        wavelength,
                        d_range,
                        d_vel,
                        coupling,
                        power_const,
                        gain2,
                        gain2_step,
                        refl_table,
                        horizon,
                        az_bin_rad,
                        h_bin_m,
                        use_horizon,
                        r_max,
                        out,
                        sparse,
                        blk,
                    )
                    continue
                if k + n_sub > cap:  # the batch is full: into the cube first
                    _flush(
                        scratch,
                        k,
                        tx,
                        rx,
                        r_rx_sub,
                        cos_sin,
                        v_ground_ant,
                        r_max,
                        d_range,
                        d_vel,
                        coupling,
                        n_range,
                        n_dopp,
                        inv_wl,
                        power_const,
                        gain2,
                        gain2_step,
                        refl_table,
                        horizon,
                        az_bin_rad,
                        h_bin_m,
                        use_horizon,
                        out,
                        sparse,
                        blk,
                        speckle_key,
                    )
                    k = np.int64(0)
                # The cell's own geometry loops pay off from 16 sub-facets; below, their set-up per
                # row costs more (30 m hill grids, ~13 a cell: 18.7 -> 10.9 ms a frame with 16, not 8).
                if n_sub >= 16:
                    cell_geometry(scratch, k, ta, tn, us[:n_sub], ws[:n_sub], up_ant, use_horizon)
                else:
                    cell_geometry_scalar(scratch, k, ta, tn, us[:n_sub], ws[:n_sub], up_ant, use_horizon)
                number_items(scratch, k, float((i * (nx - 1) + j) * n_cell_max), n_sub)
                k += n_sub
        if k > 0:  # the block's last batch
            _flush(
                scratch,
                k,
                tx,
                rx,
                r_rx_sub,
                cos_sin,
                v_ground_ant,
                r_max,
                d_range,
                d_vel,
                coupling,
                n_range,
                n_dopp,
                inv_wl,
                power_const,
                gain2,
                gain2_step,
                refl_table,
                horizon,
                az_bin_rad,
                h_bin_m,
                use_horizon,
                out,
                sparse,
                blk,
                speckle_key,
            )


@njit(inline="always")
def _flush(
    scratch,
    k,
    tx,
    rx,
    r_rx_sub,
    cos_sin,
    v_ground_ant,
    r_max,
    d_range,
    d_vel,
    coupling,
    n_range,
    n_dopp,
    inv_wl,
    power_const,
    gain2,
    gain2_step,
    refl_table,
    horizon,
    az_bin_rad,
    h_bin_m,
    use_horizon,
    out,
    sparse,
    blk,
    speckle_key,
):
    item_returns(
        scratch,
        k,
        tx,
        rx,
        r_rx_sub,
        cos_sin,
        v_ground_ant,
        r_max,
        d_range,
        d_vel,
        coupling,
        n_range,
        n_dopp,
        inv_wl,
        power_const,
        gain2,
        gain2_step,
        refl_table,
        horizon,
        az_bin_rad,
        h_bin_m,
        use_horizon,
        speckle_key,
    )
    scatter_items(out, sparse, blk, scratch, cos_sin, k)


@njit(fastmath=True, error_model="numpy")
def _reference_cell(
    ta,
    tn,
    up_ant,
    tx,
    rx,
    r_rx,
    v_ground_ant,
    nsub_r,
    nsub_c,
    wavelength,
    d_range,
    d_vel,
    coupling,
    power_const,
    gain2,
    gain2_step,
    refl_table,
    horizon,
    az_bin_rad,
    h_bin_m,
    use_horizon,
    r_max,
    out,
    sparse,
    blk,
):
    """The scalar reference: one cell's sub-facets one at a time, with early exits."""
    n_range, n_dopp = out.shape[1], out.shape[2]
    refl_step = 1.0 / (refl_table.shape[0] - 1)
    for a in range(nsub_r):
        u = (a + 0.5) / nsub_r
        for b in range(nsub_c):
            w = (b + 0.5) / nsub_c
            x = _patch_point(ta, u, w, 0)
            y, z = _patch_point(ta, u, w, 1), _patch_point(ta, u, w, 2)
            r0 = math.sqrt(x * x + y * y + z * z)
            if x <= 0.0 or r0 > r_max or (use_horizon and _hidden(tn, u, w, horizon, az_bin_rad, h_bin_m)):
                continue
            nx_, ny_, nz_, area2 = _patch_normal(ta, u, w, up_ant)
            cos_inc = -(nx_ * x + ny_ * y + nz_ * z) / (area2 * r0 + 1e-300)
            if cos_inc <= 0.0:
                continue  # facet turned away from the radar (or degenerate)
            r_tx = _two_way_paths(x, y, z, tx, rx, r_rx)
            rng = 0.5 * (r_tx + r_rx.mean())
            v_r = (v_ground_ant[0] * x + v_ground_ant[1] * y + v_ground_ant[2] * z) / r0
            kr = int(math.floor((rng + coupling * v_r) / d_range + 0.5))
            if kr < 0 or kr >= n_range:
                continue
            kd = wrap_index(int(math.floor(v_r / d_vel + 0.5)) + n_dopp // 2, n_dopp)
            power = (
                power_const
                * _table2(y / r0, z / r0, gain2_step, gain2)
                * _table(cos_inc, 0.0, refl_step, refl_table)
                * area2
                / (nsub_r * nsub_c)
            )
            _accumulate(
                out,
                sparse,
                blk,
                kr,
                kd,
                math.sqrt(power) / (rng * rng),
                r_tx,
                r_rx,
                1.0 / wavelength,
            )
