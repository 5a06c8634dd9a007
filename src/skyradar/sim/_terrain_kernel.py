"""Compiled inner loop of the image-domain simulator: terrain facets into the range-Doppler cube.

Everything per facet happens in one pass without intermediate arrays: bilinear sub-facet
position, exact surface area and normal, behind-the-antenna and range culling, line-of-sight
test against a polar horizon, two-way antenna gain, incidence-angle reflectivity, radar
equation, exact two-way path phase per receive antenna, and the scatter-add into the pixel.
Row blocks run in parallel, each into its own cube, so no two threads add into one pixel.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange, uint64

__all__ = ["add_sparse", "cis_cycles", "fast_atan2", "horizon_map", "terrain_returns"]


@njit(inline="always")
def _bilinear(p, i, j, u, w, out):
    for c in range(3):
        out[c] = (
            (1 - u) * (1 - w) * p[i, j, c]
            + (1 - u) * w * p[i, j + 1, c]
            + u * (1 - w) * p[i + 1, j, c]
            + u * w * p[i + 1, j + 1, c]
        )


@njit(inline="always")
def cis_cycles(x):
    """(cos, sin) of 2*pi*x for any real ``x`` (cycles), error below 1e-9.

    Reduce to the nearest quarter cycle, evaluate Taylor polynomials on [-pi/4, pi/4] and
    rotate by the quadrant: about four times cheaper than libm's fmod + cos + sin, which
    dominated the per-facet cost.
    """
    q = 4.0 * (x - math.floor(x))
    n = math.floor(q + 0.5)
    r = (q - n) * (0.5 * math.pi)
    r2 = r * r
    s = r * (1.0 - r2 / 6.0 * (1.0 - r2 / 20.0 * (1.0 - r2 / 42.0 * (1.0 - r2 / 72.0 * (1.0 - r2 / 110.0)))))
    c = 1.0 - r2 / 2.0 * (
        1.0 - r2 / 12.0 * (1.0 - r2 / 30.0 * (1.0 - r2 / 56.0 * (1.0 - r2 / 90.0 * (1.0 - r2 / 132.0))))
    )
    quadrant = int(n) % 4
    if quadrant == 0:
        return c, s
    if quadrant == 1:
        return -s, c
    if quadrant == 2:
        return -c, -s
    return s, -c


@njit(inline="always")
def fast_atan2(y, x):
    """atan2 to within 1.1e-5 rad (minimax polynomial on [0, 1] plus octant fix-ups)."""
    ax, ay = abs(x), abs(y)
    if ax == 0.0 and ay == 0.0:
        return 0.0
    swap = ay > ax
    z = ax / ay if swap else ay / ax
    z2 = z * z
    a = z * (0.9998660 + z2 * (-0.3302995 + z2 * (0.1801410 + z2 * (-0.0851330 + z2 * 0.0208351))))
    if swap:
        a = 0.5 * math.pi - a
    if x < 0.0:
        a = math.pi - a
    return -a if y < 0.0 else a


@njit(inline="always")
def _polar_bin(n, e, d, az_bin_rad, h_bin_m, n_az, n_h):
    # Azimuth bin, horizontal-range bin, and the slope -d/h (tan of the elevation angle: the
    # same order as the angle, without an atan2).
    h = math.sqrt(n * n + e * e)
    a = int((fast_atan2(e, n) + math.pi) / az_bin_rad) % n_az
    k = min(int(h / h_bin_m), n_h - 1)
    return a, k, -d / max(h, 1e-9)


@njit(inline="always")
def _cell_in_front(p_ned, rot_n2a, i, j):
    for ci in range(2):
        for cj in range(2):
            xa = (
                rot_n2a[0, 0] * p_ned[i + ci, j + cj, 0]
                + rot_n2a[0, 1] * p_ned[i + ci, j + cj, 1]
                + rot_n2a[0, 2] * p_ned[i + ci, j + cj, 2]
            )
            if xa > 0.0:
                return True
    return False


@njit(parallel=True, cache=True)
def horizon_map(p_ned, rot_n2a, nsub_r, nsub_c, r_lim, az_bin_rad, h_bin_m, n_az, n_h, n_blocks, sample_m):
    """Steepest slope (tan of elevation) seen so far along each azimuth, before each range bin.

    ``p_ned`` holds grid points relative to the antenna (NED, m). Returns an (n_az, n_h) array:
    a facet in bin (a, k) is visible if its slope -down/horizontal is at least ``out[a, k]``. Only
    cells in front of the antenna plane count: a ray from the antenna to a point in front
    never passes behind the plane. Each sample stands for a patch ``sample_m`` wide, so it
    raises every azimuth bin that patch spans (near samples span many bins): without this,
    narrow bins between sparse near samples would let far terrain show through a ridge.
    """
    ny, nx = p_ned.shape[0], p_ned.shape[1]
    best = np.full((n_blocks, n_az, n_h), -np.inf, dtype=np.float32)
    for blk in prange(n_blocks):
        pt = np.empty(3)
        for i in range(blk, ny - 1, n_blocks):  # interleaved rows: blocks share the work evenly
            for j in range(nx - 1):
                if not _cell_in_front(p_ned, rot_n2a, i, j):
                    continue
                for a in range(nsub_r):
                    u = (a + 0.5) / nsub_r
                    for b in range(nsub_c):
                        w = (b + 0.5) / nsub_c
                        _bilinear(p_ned, i, j, u, w, pt)
                        if pt[0] * pt[0] + pt[1] * pt[1] > r_lim * r_lim:
                            continue
                        ia, k, slope = _polar_bin(pt[0], pt[1], pt[2], az_bin_rad, h_bin_m, n_az, n_h)
                        h = math.sqrt(pt[0] * pt[0] + pt[1] * pt[1])
                        spread = min(int(0.5 * sample_m / (max(h, 1.0) * az_bin_rad)) + 1, n_az // 4)
                        for da in range(-spread, spread + 1):
                            ib = (ia + da) % n_az
                            if slope > best[blk, ib, k]:
                                best[blk, ib, k] = slope
    # Exclusive running maximum along range: what lies strictly closer can hide a facet.
    out = np.empty((n_az, n_h), dtype=np.float32)
    for ia in prange(n_az):
        running = -np.inf
        for k in range(n_h):
            out[ia, k] = running
            for blk in range(n_blocks):
                if best[blk, ia, k] > running:
                    running = best[blk, ia, k]
    return out


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
def _cell_beyond(p_ant, i, j, r_max):
    # No point of the cell can be within r_max when its nearest corner is further than r_max
    # plus the cell's largest extent.
    nearest, extent = 1e300, 0.0
    for ci in range(2):
        for cj in range(2):
            x, y, z = p_ant[i + ci, j + cj, 0], p_ant[i + ci, j + cj, 1], p_ant[i + ci, j + cj, 2]
            nearest = min(nearest, math.sqrt(x * x + y * y + z * z))
    for c in range(3):
        extent += abs(p_ant[i + 1, j + 1, c] - p_ant[i, j, c]) + abs(p_ant[i + 1, j, c] - p_ant[i, j + 1, c])
    return nearest > r_max + extent


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


@njit(cache=True)
def add_sparse(frame, idx, val, count):
    """Add recorded contributions into ``frame`` of shape (n_range * n_doppler, n_rx)."""
    for blk in range(count.shape[0]):
        for n in range(count[blk]):
            for q in range(frame.shape[1]):
                frame[idx[blk, n], q] += val[blk, n, q]


@njit(parallel=True, cache=True, fastmath=True)
def terrain_returns(
    p_ned, p_ant, up_ant, tx, rx, v_ground_ant, nsub_r, nsub_c, wavelength, d_range, d_vel, coupling,
    power_const, gain2, gain2_step, refl_table, horizon, az_bin_rad, h_bin_m, use_horizon, n_blocks, out,
    sparse,
):  # fmt: skip
    """Accumulate terrain returns into ``out`` of shape (n_blocks, n_range, n_doppler, n_rx).

    Parameters are in SI units. ``p_ned`` and ``p_ant`` are the cropped grid relative to the
    antenna phase centre in NED and in the antenna frame (m); ``up_ant`` is the local up
    direction in the antenna frame; ``tx``/``rx`` are antenna positions in the antenna frame;
    ``v_ground_ant`` is the velocity of the static ground relative to the radar in the antenna
    frame. ``power_const`` is Pe * lambda^2 / (4 pi)^3. ``gain2`` is the two-way linear gain
    G^2 on a regular grid of antenna-frame direction cosines (u_y, u_z) over [-1, 1]^2 with
    spacing ``gain2_step``. ``sparse`` is (idx, val, count): with ``idx`` of shape (n_blocks, cap)
    and cap > 0 contributions are recorded there instead of added to ``out`` (see
    :func:`add_sparse`). ``fastmath`` is safe here: every input is finite.
    """
    ny, nx = p_ned.shape[0], p_ned.shape[1]
    n_range, n_dopp = out.shape[1], out.shape[2]
    refl_step = 1.0 / (refl_table.shape[0] - 1)
    r_max = d_range * (n_range + 2)
    for blk in prange(n_blocks):
        ta, tn, r_rx = np.empty((4, 3)), np.empty((4, 3)), np.empty(rx.shape[0])
        for i in range(blk, ny - 1, n_blocks):  # interleaved rows: blocks share the work evenly
            for j in range(nx - 1):
                if _cell_behind(p_ant, i, j) or _cell_beyond(p_ant, i, j, r_max):
                    continue
                _corner_terms(p_ant, i, j, ta)
                if use_horizon:
                    _corner_terms(p_ned, i, j, tn)
                for a in range(nsub_r):
                    u = (a + 0.5) / nsub_r
                    for b in range(nsub_c):
                        w = (b + 0.5) / nsub_c
                        x = _patch_point(ta, u, w, 0)
                        y, z = _patch_point(ta, u, w, 1), _patch_point(ta, u, w, 2)
                        r0 = math.sqrt(x * x + y * y + z * z)
                        if (
                            x <= 0.0
                            or r0 > r_max
                            or (use_horizon and _hidden(tn, u, w, horizon, az_bin_rad, h_bin_m))
                        ):
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
                        kd = (int(math.floor(v_r / d_vel + 0.5)) + n_dopp // 2) % n_dopp
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
