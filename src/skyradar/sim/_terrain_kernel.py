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
from numba import njit, prange

__all__ = ["cis_cycles", "horizon_map", "terrain_returns"]


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
def _polar_bin(n, e, d, az_bin_rad, h_bin_m, n_az, n_h):
    h = math.sqrt(n * n + e * e)
    a = int((math.atan2(e, n) + math.pi) / az_bin_rad) % n_az
    k = min(int(h / h_bin_m), n_h - 1)
    return a, k, math.atan2(-d, h)


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
    """Highest elevation angle seen so far along each azimuth, before each horizontal-range bin.

    ``p_ned`` holds grid points relative to the antenna (NED, m). Returns an (n_az, n_h) array:
    a facet in bin (a, k) is visible if its elevation angle is at least ``out[a, k]``. Only
    cells in front of the antenna plane count: a ray from the antenna to a point in front
    never passes behind the plane. Each sample stands for a patch ``sample_m`` wide, so it
    raises every azimuth bin that patch spans (near samples span many bins): without this,
    narrow bins between sparse near samples would let far terrain show through a ridge.
    """
    ny, nx = p_ned.shape[0], p_ned.shape[1]
    best = np.full((n_blocks, n_az, n_h), -np.inf, dtype=np.float32)
    rows_per_block = (ny - 1 + n_blocks - 1) // n_blocks
    for blk in prange(n_blocks):
        pt = np.empty(3)
        for i in range(blk * rows_per_block, min((blk + 1) * rows_per_block, ny - 1)):
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
                        ia, k, elev = _polar_bin(pt[0], pt[1], pt[2], az_bin_rad, h_bin_m, n_az, n_h)
                        h = math.sqrt(pt[0] * pt[0] + pt[1] * pt[1])
                        spread = min(int(0.5 * sample_m / (max(h, 1.0) * az_bin_rad)) + 1, n_az // 4)
                        for da in range(-spread, spread + 1):
                            ib = (ia + da) % n_az
                            if elev > best[blk, ib, k]:
                                best[blk, ib, k] = elev
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
    return table[i] * (1.0 - t) + table[i + 1] * t


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
    return (1 - ty) * ((1 - tz) * table[iy, iz] + tz * table[iy, iz + 1]) + ty * (
        (1 - tz) * table[iy + 1, iz] + tz * table[iy + 1, iz + 1]
    )


@njit(inline="always")
def _corner_terms(g, i, j, out):
    # Bilinear patch p(u, w) = p00 + u*e1 + w*e2 + u*w*e3 over one grid cell.
    for c in range(3):
        out[0, c] = g[i, j, c]
        out[1, c] = g[i + 1, j, c] - g[i, j, c]
        out[2, c] = g[i, j + 1, c] - g[i, j, c]
        out[3, c] = g[i + 1, j + 1, c] - g[i + 1, j, c] - g[i, j + 1, c] + g[i, j, c]


@njit(parallel=True, cache=True, fastmath=True)
def terrain_returns(
    p_ned,
    p_ant,
    up_ant,
    tx,
    rx,
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
    n_blocks,
    out,
):
    """Accumulate terrain returns into ``out`` of shape (n_blocks, n_range, n_doppler, n_rx).

    Parameters are in SI units. ``p_ned`` and ``p_ant`` are the cropped grid relative to the
    antenna phase centre in NED and in the antenna frame (m); ``up_ant`` is the local up
    direction in the antenna frame; ``tx``/``rx`` are antenna positions in the antenna frame;
    ``v_ground_ant`` is the velocity of the static ground relative to the radar in the antenna
    frame. ``power_const`` is Pe * lambda^2 / (4 pi)^3. ``gain2`` is the two-way linear gain
    G^2 on a regular grid of antenna-frame direction cosines (u_y, u_z) over [-1, 1]^2 with
    spacing ``gain2_step``. ``fastmath`` is safe here: every input is finite.
    """
    ny, nx = p_ned.shape[0], p_ned.shape[1]
    n_range, n_dopp, n_rx = out.shape[1], out.shape[2], out.shape[3]
    half = n_dopp // 2
    rows_per_block = (ny - 1 + n_blocks - 1) // n_blocks
    refl_step = 1.0 / (refl_table.shape[0] - 1)
    inv_wavelength = 1.0 / wavelength
    for blk in prange(n_blocks):
        ta = np.empty((4, 3))
        tn = np.empty((4, 3))
        r_rx = np.empty(n_rx)
        for i in range(blk * rows_per_block, min((blk + 1) * rows_per_block, ny - 1)):
            for j in range(nx - 1):
                if (
                    p_ant[i, j, 0] <= 0.0
                    and p_ant[i + 1, j, 0] <= 0.0
                    and p_ant[i, j + 1, 0] <= 0.0
                    and p_ant[i + 1, j + 1, 0] <= 0.0
                ):
                    continue  # the whole cell is behind the antenna plane
                _corner_terms(p_ant, i, j, ta)
                if use_horizon:
                    _corner_terms(p_ned, i, j, tn)
                for a in range(nsub_r):
                    u = (a + 0.5) / nsub_r
                    for b in range(nsub_c):
                        w = (b + 0.5) / nsub_c
                        uw = u * w
                        x = ta[0, 0] + u * ta[1, 0] + w * ta[2, 0] + uw * ta[3, 0]
                        if x <= 0.0:
                            continue
                        y = ta[0, 1] + u * ta[1, 1] + w * ta[2, 1] + uw * ta[3, 1]
                        z = ta[0, 2] + u * ta[1, 2] + w * ta[2, 2] + uw * ta[3, 2]
                        r0 = math.sqrt(x * x + y * y + z * z)
                        if r0 > d_range * n_range + 2 * d_range:
                            continue
                        if use_horizon:
                            pn = tn[0, 0] + u * tn[1, 0] + w * tn[2, 0] + uw * tn[3, 0]
                            pe = tn[0, 1] + u * tn[1, 1] + w * tn[2, 1] + uw * tn[3, 1]
                            pd = tn[0, 2] + u * tn[1, 2] + w * tn[2, 2] + uw * tn[3, 2]
                            ia, k, elev = _polar_bin(
                                pn, pe, pd, az_bin_rad, h_bin_m, horizon.shape[0], horizon.shape[1]
                            )
                            if elev < horizon[ia, k]:
                                continue
                        # Tangents of the bilinear patch give the exact area and normal.
                        dux, duy, duz = (
                            ta[1, 0] + w * ta[3, 0],
                            ta[1, 1] + w * ta[3, 1],
                            ta[1, 2] + w * ta[3, 2],
                        )
                        dwx, dwy, dwz = (
                            ta[2, 0] + u * ta[3, 0],
                            ta[2, 1] + u * ta[3, 1],
                            ta[2, 2] + u * ta[3, 2],
                        )
                        nx_ = duy * dwz - duz * dwy
                        ny_ = duz * dwx - dux * dwz
                        nz_ = dux * dwy - duy * dwx
                        area2 = math.sqrt(nx_ * nx_ + ny_ * ny_ + nz_ * nz_)
                        if area2 == 0.0:
                            continue
                        if nx_ * up_ant[0] + ny_ * up_ant[1] + nz_ * up_ant[2] < 0.0:
                            nx_, ny_, nz_ = -nx_, -ny_, -nz_  # normal points to the sky
                        inv_r0 = 1.0 / r0
                        ux, uy, uz = x * inv_r0, y * inv_r0, z * inv_r0
                        cos_inc = -(nx_ * ux + ny_ * uy + nz_ * uz) / area2
                        if cos_inc <= 0.0:
                            continue  # facet turned away from the radar
                        refl = _table(cos_inc, 0.0, refl_step, refl_table)
                        gain_lin2 = _table2(uy, uz, gain2_step, gain2)
                        # Exact two-way paths; bin on their mean half-length.
                        dx, dy, dz = x - tx[0], y - tx[1], z - tx[2]
                        r_tx = math.sqrt(dx * dx + dy * dy + dz * dz)
                        r_rx_sum = 0.0
                        for q in range(n_rx):
                            dx, dy, dz = x - rx[q, 0], y - rx[q, 1], z - rx[q, 2]
                            r_rx[q] = math.sqrt(dx * dx + dy * dy + dz * dz)
                            r_rx_sum += r_rx[q]
                        rng = 0.5 * (r_tx + r_rx_sum / n_rx)
                        v_r = v_ground_ant[0] * ux + v_ground_ant[1] * uy + v_ground_ant[2] * uz
                        kr = int(math.floor((rng + coupling * v_r) / d_range + 0.5))
                        if kr < 0 or kr >= n_range:
                            continue
                        kd = (int(math.floor(v_r / d_vel + 0.5)) + half) % n_dopp
                        area = area2 / (nsub_r * nsub_c)
                        amp = math.sqrt(power_const * gain_lin2 * area * refl) / (rng * rng)
                        for q in range(n_rx):
                            cos_p, sin_p = cis_cycles((r_tx + r_rx[q]) * inv_wavelength)
                            out[blk, kr, kd, q] += complex(amp * cos_p, amp * sin_p)
