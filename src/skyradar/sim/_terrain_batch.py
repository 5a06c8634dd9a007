"""The terrain kernel's per-sub-facet physics for batches of sub-facets, in vectorisable loops.

The scalar loop in ``_terrain_kernel`` spends most of its time on branches (culling, quadrant,
table bounds) and on one sub-facet at a time. Here the sub-facets of up to a few hundred grid
cells (one cell holds 1 to ~120 of them) are laid out as rows of a scratch array and the same
quantities are computed in short branch-free loops over those rows, which LLVM turns into SIMD
code (square roots and floors included; the antenna-gain and reflectivity table look-ups stay
scalar, LLVM emits no gathers here). Culling becomes a validity flag and only the scatter into
the pixels stays scalar. The formulas are the scalar kernel's, term for term, except that the
path phase is reduced exactly as an integer count of 2^-32 turns and its polynomials run in
float32 (error 1e-7, the precision of the complex64 pixels); ``tests/test_sim_kernel.py`` checks
both paths give the same cube. With speckle, each sub-facet's draw joins its phase as another
count and its radius joins the amplitude: one sine and cosine per receiver, no complex product.

Why so many small loops: LLVM vectorises a loop over arrays it cannot prove distinct only
behind a few run-time overlap checks (8 by default), so each loop writes one or two rows and
reads a handful, and loop-invariant values come in as scalars, not as array reads.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import int64, njit, uint64

from skyradar.sim._elementary import fast_atan2
from skyradar.sim._noise_kernel import cis_count_f32, mix64, polar_normal

__all__ = [
    "CELL_FIELDS",
    "cell_geometry",
    "cell_geometry_scalar",
    "item_returns",
    "number_items",
    "scatter_items",
]

# Rows of the per-thread scratch array (one column per sub-facet of the batch).
_X, _Y, _Z, _R0, _AREA, _COS_INC, _RTX, _RSUM, _RNG, _VR, _VALID, _KR, _KD, _AMP, _N, _E, _D = range(17)
_TMP0, _TMP1 = 17, 18  # per-loop temporaries (table positions, horizon index and slope)
_ID = 19  # the sub-facet's number in the frame (cell * sub-facets per cell + m): its speckle draw
_TMP2, _TMP3 = 20, 21  # more temporaries (table look-ups)
CELL_FIELDS = 22

_OPTS: dict[str, Any] = {"error_model": "numpy", "fastmath": True}
_GAMMA = uint64(0x9E3779B97F4A7C15)
_SQRT_HALF = np.float32(math.sqrt(0.5))
_NEAR_M = 0.1  # receivers within this of the phase centre (per axis): _near_distance_row


@njit(**_OPTS)
def _patch_row(out, us, ws, t0, t1, t2, t3):
    # out[m] = t0 + u t1 + w t2 + u w t3: one coordinate of the bilinear patch (_patch_point).
    for m in range(out.shape[0]):
        u, w = us[m], ws[m]
        out[m] = t0 + u * t1 + w * t2 + u * w * t3


@njit(inline="always")
def _normal(u, w, e1, e2, e3, up):
    """Upward normal of the patch at (u, w), as the scalar kernel's _patch_normal."""
    dux, duy, duz = e1[0] + w * e3[0], e1[1] + w * e3[1], e1[2] + w * e3[2]
    dwx, dwy, dwz = e2[0] + u * e3[0], e2[1] + u * e3[1], e2[2] + u * e3[2]
    nx = duy * dwz - duz * dwy
    ny = duz * dwx - dux * dwz
    nz = dux * dwy - duy * dwx
    flip = nx * up[0] + ny * up[1] + nz * up[2] < 0.0
    return (-nx if flip else nx), (-ny if flip else ny), (-nz if flip else nz)


@njit(**_OPTS)
def _scale_row(x, factor):
    for m in range(x.shape[0]):
        x[m] *= factor


@njit(**_OPTS)
def _area_row(area, us, ws, e1, e2, e3, up):
    for m in range(area.shape[0]):
        nx, ny, nz = _normal(us[m], ws[m], e1, e2, e3, up)
        area[m] = math.sqrt(nx * nx + ny * ny + nz * nz)


@njit(**_OPTS)
def _cos_inc_row(cos_inc, us, ws, x_, y_, z_, r0_, area, e1, e2, e3, up):
    for m in range(cos_inc.shape[0]):
        nx, ny, nz = _normal(us[m], ws[m], e1, e2, e3, up)
        cos_inc[m] = -(nx * x_[m] + ny * y_[m] + nz * z_[m]) / (area[m] * r0_[m] + 1e-300)


@njit(**_OPTS)
def _distance_row(out, x_, y_, z_, px, py, pz):
    for m in range(out.shape[0]):
        dx, dy, dz = x_[m] - px, y_[m] - py, z_[m] - pz
        out[m] = math.sqrt(dx * dx + dy * dy + dz * dz)


@njit(**_OPTS)
def _inverse_row(out, x):
    for m in range(out.shape[0]):
        out[m] = 1.0 / x[m]


@njit(**_OPTS)
def _near_distance_row(out, x_, y_, z_, r0_, inv_r0, ax, ay, az):
    # |p - a| for an antenna a a few cm from the phase centre, without a square root:
    # |p - a| - r0 = (|a|^2 - 2 s) / (|p - a| + r0), s = a.p, and 1 / (|p - a| + r0) =
    # (1 + s / (2 r0^2)) / (2 r0) to first order. Left out: about |a|^3 / r0^2 (1e-12 m for the
    # prototype's 1.1 cm at 100 m; at most 1e-7 m with a <= _NEAR_M at 100 m).
    a2 = ax * ax + ay * ay + az * az
    for m in range(out.shape[0]):
        dot = ax * x_[m] + ay * y_[m] + az * z_[m]
        h = 0.5 * inv_r0[m]
        out[m] = r0_[m] + (a2 - 2.0 * dot) * h * (1.0 + dot * inv_r0[m] * h)


@njit(**_OPTS)
def _add_row(acc, x):
    for m in range(acc.shape[0]):
        acc[m] += x[m]


@njit(**_OPTS)
def _range_velocity_rows(rng_, v_r_, r_tx, rsum, x_, y_, z_, r0_, n_rx, vg):
    for m in range(rng_.shape[0]):
        rng_[m] = 0.5 * (r_tx[m] + rsum[m] / n_rx)
    for m in range(v_r_.shape[0]):
        v_r_[m] = (vg[0] * x_[m] + vg[1] * y_[m] + vg[2] * z_[m]) / r0_[m]


@njit(**_OPTS)
def _bins_rows(kr_, kd_, rng_, v_r_, coupling, d_range, d_vel, n_dopp, half_dopp):
    # Bins as floats (n_dopp, half_dopp: float counts); the Doppler wrap is Python's modulo
    # done with a floor, then one select against the rounding of kd / n_dopp at a multiple.
    for m in range(kr_.shape[0]):
        kr_[m] = math.floor((rng_[m] + coupling * v_r_[m]) / d_range + 0.5)
    for m in range(kd_.shape[0]):
        kd = math.floor(v_r_[m] / d_vel + 0.5) + half_dopp
        kd = kd - n_dopp * math.floor(kd / n_dopp)
        kd = kd - n_dopp if kd >= n_dopp else kd
        kd_[m] = kd + n_dopp if kd < 0.0 else kd


@njit(**_OPTS)
def _valid_row(valid, x_, r0_, cos_inc, kr_, r_max, n_range):
    # The scalar kernel's culling: behind the antenna, beyond r_max, turned away, off the cube.
    for m in range(valid.shape[0]):
        ok = (x_[m] > 0.0) & (r0_[m] <= r_max) & (cos_inc[m] > 0.0) & (kr_[m] >= 0.0) & (kr_[m] < n_range)
        valid[m] = 1.0 if ok else 0.0


@njit(**_OPTS)
def _horizon_rows(flat_, slope_, n_, e_, d_, az_bin_rad, h_bin_m, n_az, n_h):
    # The scalar kernel's _polar_bin: flat horizon index (as a float) and slope; the azimuth
    # wrap is a select.
    for m in range(flat_.shape[0]):
        n, e, d = n_[m], e_[m], d_[m]
        h = math.sqrt(n * n + e * e)
        a = math.floor((fast_atan2(e, n) + math.pi) / az_bin_rad)
        a = min(max(a - n_az if a >= n_az else a, 0.0), n_az - 1.0)
        flat_[m] = a * n_h + min(math.floor(h / h_bin_m), n_h - 1.0)
        slope_[m] = -d / max(h, 1e-9)


@njit(error_model="numpy")
def _visible_row(valid, flat_, slope_, horizon_flat):
    # Table look-ups stay scalar: LLVM will not emit gathers here.
    for m in range(valid.shape[0]):
        if slope_[m] < horizon_flat[uint64(flat_[m])]:
            valid[m] = 0.0


@njit(**_OPTS)
def _direction_rows(fy_, fz_, y_, z_, r0_, gain2_step):
    # Positions on the gain table's grid of direction cosines.
    for m in range(fy_.shape[0]):
        fy_[m] = (y_[m] / r0_[m] + 1.0) / gain2_step
        fz_[m] = (z_[m] / r0_[m] + 1.0) / gain2_step


@njit(**_OPTS)
def _table_rows(iy_, ty_, iz_, tz_, ir_, tr_, fy_, fz_, cos_inc, n_gain, n_refl, refl_step):
    # Cells and weights of the gain and reflectivity look-ups (the scalar kernel's _table2 and
    # _table, same clamping), branch-free: the loop vectorises; only the loads stay scalar.
    for m in range(iy_.shape[0]):
        fy, fz = fy_[m], fz_[m]
        iy = min(max(math.floor(fy), 0.0), n_gain - 1.0)
        iz = min(max(math.floor(fz), 0.0), n_gain - 1.0)
        iy_[m], ty_[m] = iy, min(max(fy - iy, 0.0), 1.0)
        iz_[m], tz_[m] = iz, min(max(fz - iz, 0.0), 1.0)
    for m in range(ir_.shape[0]):
        f = min(max(cos_inc[m] / refl_step, 0.0), n_refl - 1.0)
        i = min(math.floor(f), n_refl - 2.0)
        ir_[m], tr_[m] = i, f - i


@njit(error_model="numpy", fastmath=True)
def _lookup_rows(gain_, refl_, iy_, ty_, iz_, tz_, ir_, tr_, gain2, refl_table):
    # Scalar: LLVM will not emit gathers here. Unsigned indices: no wrap-around checks.
    one = uint64(1)
    for m in range(gain_.shape[0]):
        iy, iz, ty, tz = uint64(iy_[m]), uint64(iz_[m]), ty_[m], tz_[m]
        row0, row1 = gain2[iy], gain2[iy + one]
        gain_[m] = (1 - ty) * ((1 - tz) * row0[iz] + tz * row0[iz + one]) + ty * (
            (1 - tz) * row1[iz] + tz * row1[iz + one]
        )
        i, t = uint64(ir_[m]), tr_[m]
        refl_[m] = refl_table[i] * (1.0 - t) + refl_table[i + one] * t


@njit(**_OPTS)
def _amplitude_row(amp, gain_, refl_, area, rng_, power_const):
    for m in range(amp.shape[0]):
        power = power_const * gain_[m] * refl_[m] * area[m]
        amp[m] = math.sqrt(max(power, 0.0)) / (rng_[m] * rng_[m])


@njit(error_model="numpy")
def _speckle_rows(amp, turn, ids, speckle_key):
    # Each sub-facet's complex reflectivity, a unit-power circular Gaussian drawn from its number
    # by the noise kernel's counter-based generator, in polar form: its radius scales the
    # amplitude, its angle (a count of 2^-32 turns) is added to every receiver's path phase.
    for m in range(amp.shape[0]):
        radius, count = polar_normal(mix64(speckle_key + (uint64(ids[m]) + uint64(1)) * _GAMMA), _SQRT_HALF)
        amp[m] *= radius
        turn[m] = float(count)


@njit(**_OPTS)
def _phase_rows(re_q, im_q, r_tx, r_rx, amp, turn, counts_per_m):
    # amp * exp(2 pi i (path / wavelength + turn / 2^32)). The path phase as an integer count of
    # 2^-32 turns (exact below 2^53 counts: paths up to 30 km), so the reduction to one turn is
    # an integer mask, not float64 floors. The float64 products round once to float32.
    for m in range(re_q.shape[0]):
        count = uint64(int64((r_tx[m] + r_rx[m]) * counts_per_m)) + uint64(int64(turn[m]))
        c, s = cis_count_f32(count)
        re_q[m], im_q[m] = c * amp[m], s * amp[m]


@njit(error_model="numpy")
def cell_geometry(s, k, ta, tn, us, ws, up, use_horizon):
    """Points, range, area, incidence (and NED points) of one cell's sub-facets, vectorised.

    ``ta``/``tn`` are the cell's bilinear patch terms (4, 3) in the antenna frame and in NED,
    ``us``/``ws`` the sub-facet centres, ``up`` the local up direction (antenna frame). Fills
    the geometry rows of ``s`` (CELL_FIELDS, >= k + n_sub) from item ``k``.
    """
    n = us.shape[0]
    x_, y_, z_, r0_ = s[_X][k : k + n], s[_Y][k : k + n], s[_Z][k : k + n], s[_R0][k : k + n]
    for c, row in ((0, x_), (1, y_), (2, z_)):
        _patch_row(row, us, ws, ta[0, c], ta[1, c], ta[2, c], ta[3, c])
    _distance_row(r0_, x_, y_, z_, 0.0, 0.0, 0.0)
    e1, e2 = (ta[1, 0], ta[1, 1], ta[1, 2]), (ta[2, 0], ta[2, 1], ta[2, 2])
    e3 = (ta[3, 0], ta[3, 1], ta[3, 2])
    upt = (up[0], up[1], up[2])
    area = s[_AREA][k : k + n]
    _area_row(area, us, ws, e1, e2, e3, upt)
    _cos_inc_row(s[_COS_INC][k : k + n], us, ws, x_, y_, z_, r0_, area, e1, e2, e3, upt)
    _scale_row(area, 1.0 / n)  # area per unit (u, w) -> the sub-facet's area
    if use_horizon:
        for c, row in ((0, s[_N][k : k + n]), (1, s[_E][k : k + n]), (2, s[_D][k : k + n])):
            _patch_row(row, us, ws, tn[0, c], tn[1, c], tn[2, c], tn[3, c])


@njit(inline="always")
def cell_geometry_scalar(s, k, ta, tn, us, ws, up, use_horizon):
    """:func:`cell_geometry` one sub-facet at a time, appended from item ``k``.

    For cells of few sub-facets (DEM spacing): cells are gathered into one batch of items so
    that :func:`item_returns` still runs over long vectors.
    """
    e1, e2 = (ta[1, 0], ta[1, 1], ta[1, 2]), (ta[2, 0], ta[2, 1], ta[2, 2])
    e3 = (ta[3, 0], ta[3, 1], ta[3, 2])
    upt = (up[0], up[1], up[2])
    for m in range(us.shape[0]):
        u, w, i = us[m], ws[m], k + m
        x, y, z = _point(ta, u, w, 0), _point(ta, u, w, 1), _point(ta, u, w, 2)
        r0 = math.sqrt(x * x + y * y + z * z)
        nx, ny, nz = _normal(u, w, e1, e2, e3, upt)
        area = math.sqrt(nx * nx + ny * ny + nz * nz)
        s[_X, i], s[_Y, i], s[_Z, i], s[_R0, i], s[_AREA, i] = x, y, z, r0, area / us.shape[0]
        s[_COS_INC, i] = -(nx * x + ny * y + nz * z) / (area * r0 + 1e-300)
        if use_horizon:
            s[_N, i], s[_E, i], s[_D, i] = _point(tn, u, w, 0), _point(tn, u, w, 1), _point(tn, u, w, 2)


@njit(inline="always")
def _point(t, u, w, c):
    return t[0, c] + u * t[1, c] + w * t[2, c] + u * w * t[3, c]


@njit(error_model="numpy")
def item_returns(
    s,
    n,
    tx,
    rx,
    r_rx,
    cos_sin,
    v_ground,
    r_max,
    d_range,
    d_vel,
    coupling,
    n_range,
    n_dopp,
    inv_wavelength,
    power_const,
    gain2,
    gain2_step,
    refl_table,
    horizon,
    az_bin_rad,
    h_bin_m,
    use_horizon,
    speckle_key,
):
    """Validity, pixel (range, Doppler) as floats and per-receiver complex value of items.

    Reads the geometry rows of the first ``n`` items of ``s``; writes their _VALID, _KR, _KD,
    _AMP rows and ``cos_sin`` (2, n_rx, >= n): real and imaginary part of each receiver's value,
    with speckle when ``speckle_key`` is not 0; ``r_rx`` (n_rx, >= n) is scratch. The _AREA row
    holds each sub-facet's own area.
    """
    x_, y_, z_, r0_ = s[_X][:n], s[_Y][:n], s[_Z][:n], s[_R0][:n]
    r_tx, rsum, rng_, v_r_ = s[_RTX][:n], s[_RSUM][:n], s[_RNG][:n], s[_VR][:n]
    valid, kr_, kd_, cos_inc = s[_VALID][:n], s[_KR][:n], s[_KD][:n], s[_COS_INC][:n]
    tmp0, tmp1 = s[_TMP0][:n], s[_TMP1][:n]
    if tx[0] == 0.0 and tx[1] == 0.0 and tx[2] == 0.0:
        r_tx[:] = r0_  # the transmitter at the phase-centre reference: the same numbers
    else:
        _distance_row(r_tx, x_, y_, z_, tx[0], tx[1], tx[2])
    rsum[:] = 0.0
    near = True
    for q in range(rx.shape[0]):
        near = near and abs(rx[q, 0]) <= _NEAR_M and abs(rx[q, 1]) <= _NEAR_M and abs(rx[q, 2]) <= _NEAR_M
    if near:
        _inverse_row(tmp0, r0_)
    for q in range(rx.shape[0]):
        if near:
            _near_distance_row(r_rx[q][:n], x_, y_, z_, r0_, tmp0, rx[q, 0], rx[q, 1], rx[q, 2])
        else:
            _distance_row(r_rx[q][:n], x_, y_, z_, rx[q, 0], rx[q, 1], rx[q, 2])
        _add_row(rsum, r_rx[q][:n])
    vg = (v_ground[0], v_ground[1], v_ground[2])
    _range_velocity_rows(rng_, v_r_, r_tx, rsum, x_, y_, z_, r0_, rx.shape[0], vg)
    _bins_rows(kr_, kd_, rng_, v_r_, coupling, d_range, d_vel, float(n_dopp), float(n_dopp // 2))
    _valid_row(valid, x_, r0_, cos_inc, kr_, r_max, n_range)
    if use_horizon:
        n_az, n_h = horizon.shape[0], horizon.shape[1]
        n_, e_, d_ = s[_N][:n], s[_E][:n], s[_D][:n]
        _horizon_rows(tmp0, tmp1, n_, e_, d_, az_bin_rad, h_bin_m, float(n_az), float(n_h))
        _visible_row(valid, tmp0, tmp1, horizon.reshape(n_az * n_h))
    _direction_rows(tmp0, tmp1, y_, z_, r0_, gain2_step)
    # Look-up cells and weights into rows free by now (horizon, Doppler and range sums done).
    iy_, ty_, iz_, tz_, ir_, tr_ = s[_N][:n], s[_E][:n], s[_D][:n], rsum, v_r_, s[_TMP2][:n]
    n_refl = refl_table.shape[0]
    _table_rows(
        iy_,
        ty_,
        iz_,
        tz_,
        ir_,
        tr_,
        tmp0,
        tmp1,
        cos_inc,
        float(gain2.shape[0] - 1),
        float(n_refl),
        1.0 / (n_refl - 1),
    )
    gain_, refl_ = s[_TMP3][:n], tmp1
    _lookup_rows(gain_, refl_, iy_, ty_, iz_, tz_, ir_, tr_, gain2, refl_table)
    amp, turn = s[_AMP][:n], tmp0
    _amplitude_row(amp, gain_, refl_, s[_AREA][:n], rng_, power_const)
    if speckle_key != 0:
        _speckle_rows(amp, turn, s[_ID][:n], speckle_key)
    else:
        turn[:] = 0.0
    counts_per_m = inv_wavelength * 2.0**32
    for q in range(rx.shape[0]):
        _phase_rows(cos_sin[0, q][:n], cos_sin[1, q][:n], r_tx, r_rx[q][:n], amp, turn, counts_per_m)


@njit(inline="always")
def number_items(s, k, first, n):
    """Number items ``k .. k + n - 1`` of the batch ``first, first + 1, ...`` (their speckle draws)."""
    for m in range(n):
        s[_ID, k + m] = first + m


@njit(error_model="numpy")
def scatter_items(out, sparse, blk, s, cos_sin, n_items):
    """Add the valid items into the thread's cube (or its sparse list)."""
    idx, val, count = sparse
    n_rx = cos_sin.shape[1]
    if idx.shape[1] == 0:
        _scatter_dense(out[blk].view(np.float32), s, cos_sin, n_items)
        return
    for m in range(n_items):
        if s[_VALID, m] == 0.0:
            continue
        n = count[blk]
        idx[blk, n] = int(s[_KR, m]) * out.shape[2] + int(s[_KD, m])
        count[blk] = n + 1
        for q in range(n_rx):
            val[blk, n, q] = complex(cos_sin[0, q, m], cos_sin[1, q, m])


@njit(inline="always")
def _scatter_dense(cube, s, cos_sin, n_items):
    # ``cube``: the thread's block as float32 (n_range, n_doppler, 2 n_rx). Unsigned pixel
    # indices (>= 0 for valid items): numba then skips its wrap-around check. Four receivers
    # (the usual 2 x 2 array) written out: their eight floats are one contiguous update.
    n_rx = cos_sin.shape[1]
    for m in range(n_items):
        if s[_VALID, m] == 0.0:
            continue
        px = cube[uint64(s[_KR, m]), uint64(s[_KD, m])]
        if n_rx == 4:
            px[0] += cos_sin[0, 0, m]
            px[1] += cos_sin[1, 0, m]
            px[2] += cos_sin[0, 1, m]
            px[3] += cos_sin[1, 1, m]
            px[4] += cos_sin[0, 2, m]
            px[5] += cos_sin[1, 2, m]
            px[6] += cos_sin[0, 3, m]
            px[7] += cos_sin[1, 3, m]
        else:
            for q in range(n_rx):
                px[2 * q] += cos_sin[0, q, m]
                px[2 * q + 1] += cos_sin[1, q, m]
