"""Direction of a detection whose cell was projected off its clutter: the projected matched filter.

The direction is the unit vector maximising ``|s^H P z|^2 / (s^H P s)`` (``P = I - E E^H`` the
cell's projector, ``z`` its calibrated snapshot, ``s`` the receive steering vector): the plain
phase estimate of the unsuppressed snapshot would follow the clutter that dominates the cell.
Search: a 2 deg grid over the field of view (+-70 deg, steering vectors cached per radar), then
the 0.05 deg lattice within +-1.5 deg of its best point, searched coarse to fine (0.25 deg steps
over +-1.5 deg, then 0.05 deg steps over +-0.35 deg around the best of those). The score is smooth
at this scale (the 2x2 array's beam is tens of degrees wide), so the two steps find the same
lattice point as an exhaustive search of the 61 x 61 lattice; a test checks it on random
snapshots and projections. Both steps are compiled (numba). The coarse grid's scores come from a
real basis cached per radar (the real and imaginary parts of each steering vector and of each pair
product ``conj(s_k) s_m``, grid points along the rows), so each of its ``n_rx^2 + 2 n_rx`` terms is
one vectorised pass over the 5041 points; tens of microseconds per detection instead of the 2 ms a
numpy version costs.

Whether the elevation was measured follows its Cramer-Rao bound through the cell's projector or
whitening at the detection's amplitude (:func:`elevation_sigma_rad`). Two nulls at one elevation
(clutter left and right at one range and Doppler) take the whole elevation dimension of the 2x2
array: the bound is infinite, and training over neighbouring Doppler bins does not help (the
clutter ridge is continuous in Doppler: over 3 or 5 bins the bound is only 7-12 % below one bin's).
Whitened by a ring's finite clutter (adaptive cells) the elevation keeps a bound that grows with
the clutter-to-noise ratio, a few degrees at 20-25 dB. Above :data:`MAX_ELEVATION_SIGMA_RAD` the
detection is placed in the antenna's horizontal plane (elevation 0, co-altitude for a level
forward radar): a prior, not a measurement; the azimuth is still measured (a 0.05 deg search over
+-1.5 deg of azimuth at elevation 0, around the point at elevation 0 of the cone of equal horizontal
direction cosine through the 2-D search's best point: without elevation the score is flat along
that cone, so the best point's own azimuth may be tens of degrees off).

Examples
--------
>>> from skyradar.config import RadarConfig
>>> from skyradar.process.doa import direction_from_angles, steering_vector
>>> cfg = RadarConfig.prototype_2022()
>>> z = steering_vector(direction_from_angles(0.2, -0.1), cfg)[None]
>>> u = directions_after_projection(z, np.eye(4)[None], cfg, cfg.noise_power_w)
>>> np.degrees(np.arctan2(u[0, 1], u[0, 0])).round(1), np.degrees(np.arcsin(-u[0, 2])).round(1)
(np.float64(11.5), np.float64(-5.8))
"""

from __future__ import annotations

import numpy as np
from numba import njit

from skyradar.config import RadarConfig
from skyradar.process.clutter import steering_into
from skyradar.process.doa import channel_positions_m, direction_from_angles, steering_vector

__all__ = [
    "directions_after_projection",
    "projected_directions",
    "projected_scores",
    "elevation_sigma_rad",
    "angle_sigmas_rad",
    "MAX_ELEVATION_SIGMA_RAD",
]

MAX_ELEVATION_SIGMA_RAD = float(np.radians(10.0))  # Cramer-Rao bound above which elevation is a prior
_COARSE_DEG = np.arange(-70.0, 70.5, 2.0)
_FINE_STEP_DEG, _FINE_HALF_DEG = 0.05, 1.5
_MID_STEP, _MID_HALF, _LAST_HALF = 5, 6, 7  # in fine steps: 0.25 deg over +-1.5 deg, then +-0.35 deg
_COARSE_CACHE: dict[int, tuple[RadarConfig, np.ndarray]] = {}
_BLOCK = 512  # coarse grid points scored together: three blocks of partial sums fit the L1 cache


@njit(cache=True)
def _score(s, pz, p):  # pragma: no cover - compiled
    # |s^H P z|^2 / (s^H P s), P Hermitian and idempotent: the upper triangle of P gives s^H P s.
    n_k = pz.size
    num = 0j
    den = 0.0
    for k in range(n_k):
        num += np.conj(s[k]) * pz[k]
        den += p[k, k].real * (s[k].real * s[k].real + s[k].imag * s[k].imag)
        cross = 0j
        for m in range(k + 1, n_k):
            cross += p[k, m] * s[m]
        den += 2.0 * (np.conj(s[k]) * cross).real
    return (num.real * num.real + num.imag * num.imag) / max(den, 1e-9)


@njit(cache=True)
def _scores(steer, z, p, out):  # pragma: no cover - compiled
    pz = p @ z
    for n in range(steer.shape[0]):
        out[n] = _score(steer[n], pz, p)
    return out


@njit(cache=True)
def _grid_best(az0, el0, i_lo, i_hi, j_lo, j_hi, step, step_rad, rx, wavenumber, z, p):  # pragma: no cover
    # Best lattice point (i, j) of az0 + i * step_rad, el0 + j * step_rad, i and j multiples of `step`.
    # The cosines and sines of each row's azimuth and each column's elevation are formed once, not
    # per point: the same values, so the same scores and the same best point as per point.
    n_k = z.size
    pz = p @ z
    s = np.empty(n_k, np.complex128)
    n_j = max((j_hi - j_lo) // step + 1, 0)
    cos_el, sin_el = np.empty(n_j), np.empty(n_j)
    for t in range(n_j):
        el = el0 + (j_lo + t * step) * step_rad
        cos_el[t], sin_el[t] = np.cos(el), np.sin(el)
    best, bi, bj = -1.0, 0, 0
    for i in range(i_lo, i_hi + 1, step):
        az = az0 + i * step_rad
        cos_az, sin_az = np.cos(az), np.sin(az)
        for t in range(n_j):
            u0, u1, u2 = cos_el[t] * cos_az, cos_el[t] * sin_az, -sin_el[t]
            steering_into(u0, u1, u2, rx, wavenumber, s)
            score = _score(s, pz, p)
            if score > best:
                best, bi, bj = score, i, j_lo + t * step
    return bi, bj


@njit(cache=True)
def _grid_scores(basis, z, p, out):  # pragma: no cover - compiled
    # _scores over a fixed grid from its real basis (:func:`_coarse`): a row of the basis per real
    # term of the numerator s^H P z and of the denominator s^H P s, the grid points along each row,
    # so every term is one pass over contiguous points (vectorised) instead of a loop per point.
    # The points go in blocks of _BLOCK whose partial sums stay in the first-level cache.
    n_k = z.size
    pz = p @ z
    num_re, num_im, den = np.empty(_BLOCK), np.empty(_BLOCK), np.empty(_BLOCK)
    for lo in range(0, out.size, _BLOCK):
        nb = min(_BLOCK, out.size - lo)
        num_re[:nb], num_im[:nb], den[:nb] = 0.0, 0.0, 0.0
        for k in range(n_k):
            sr, si = basis[2 * k, lo : lo + nb], basis[2 * k + 1, lo : lo + nb]
            pr, pi = pz[k].real, pz[k].imag
            for n in range(nb):  # conj(s_k) (P z)_k
                num_re[n] += sr[n] * pr + si[n] * pi
                num_im[n] += sr[n] * pi - si[n] * pr
        row = 2 * n_k
        for k in range(n_k):
            g, w = basis[row, lo : lo + nb], p[k, k].real
            for n in range(nb):  # P_kk |s_k|^2
                den[n] += w * g[n]
            row += 1
            for m in range(k + 1, n_k):  # 2 Re(P_km conj(s_k) s_m) = Re P_km 2 Re(c) - Im P_km 2 Im(c)
                g_re, g_im = basis[row, lo : lo + nb], basis[row + 1, lo : lo + nb]
                w_re, w_im = p[k, m].real, p[k, m].imag
                for n in range(nb):
                    den[n] += w_re * g_re[n] - w_im * g_im[n]
                row += 2
        for n in range(nb):
            out[lo + n] = (num_re[n] * num_re[n] + num_im[n] * num_im[n]) / max(den[n], 1e-9)
    return out


@njit(cache=True)
def _one_direction(basis, coarse_rad, rx, wavenumber, step_rad, half, z, p):  # pragma: no cover
    # Coarse grid, then the 0.05 deg lattice coarse to fine: (az, el) in rad.
    n_c = coarse_rad.size
    score = _grid_scores(basis, z, p, np.empty(basis.shape[1]))
    best = np.argmax(score)
    az0, el0 = coarse_rad[best // n_c], coarse_rad[best % n_c]
    i, j = _grid_best(az0, el0, -half, half, -half, half, _MID_STEP, step_rad, rx, wavenumber, z, p)
    lo_i, hi_i = max(i - _LAST_HALF, -half), min(i + _LAST_HALF, half)
    lo_j, hi_j = max(j - _LAST_HALF, -half), min(j + _LAST_HALF, half)
    i, j = _grid_best(az0, el0, lo_i, hi_i, lo_j, hi_j, 1, step_rad, rx, wavenumber, z, p)
    return az0 + i * step_rad, el0 + j * step_rad


@njit(cache=True)
def _directions(basis, coarse_rad, rx, wavenumber, step_rad, half, z_all, p_all):  # pragma: no cover
    # _one_direction of every snapshot: (n, 2) of (az, el) in rad.
    out = np.empty((z_all.shape[0], 2))
    for n in range(z_all.shape[0]):
        out[n, 0], out[n, 1] = _one_direction(
            basis, coarse_rad, rx, wavenumber, step_rad, half, z_all[n], p_all[n]
        )
    return out


@njit(cache=True)
def _azimuth_at_zero(az0, rx, wavenumber, step_rad, half, z, p):  # pragma: no cover - compiled
    # The 0.05 deg lattice row at elevation 0 within +-1.5 deg of az0: azimuth in rad.
    i, _ = _grid_best(az0, 0.0, -half, half, 0, 0, 1, step_rad, rx, wavenumber, z, p)
    return az0 + i * step_rad


def _coarse(config: RadarConfig) -> np.ndarray:
    """The real basis of the coarse (azimuth, elevation) grid's scores, cached per radar: rows
    ``Re s_k, Im s_k`` (k = 0..n_rx-1), then per channel ``|s_k|^2`` followed by
    ``2 Re(conj(s_k) s_m), 2 Im(conj(s_k) s_m)`` for m > k; columns the grid points."""
    hit = _COARSE_CACHE.get(id(config))
    if hit is None or hit[0] is not config:
        a, e = np.meshgrid(np.radians(_COARSE_DEG), np.radians(_COARSE_DEG), indexing="ij")
        s = steering_vector(direction_from_angles(a.ravel(), e.ravel()), config).T  # (n_rx, points)
        rows = [part for s_k in s for part in (s_k.real, s_k.imag)]
        for k in range(len(s)):
            rows.append(np.abs(s[k]) ** 2)
            for m in range(k + 1, len(s)):
                c = 2.0 * np.conj(s[k]) * s[m]
                rows += [c.real, c.imag]
        hit = (config, np.ascontiguousarray(np.array(rows), np.float64))
        _COARSE_CACHE.clear()
        _COARSE_CACHE[id(config)] = hit
    return hit[1]


def projected_scores(steer: np.ndarray, z: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Projected matched filter ``|s^H P z|^2 / (s^H P s)`` for the rows ``s`` of ``steer`` (n, n_rx).

    Parameters
    ----------
    steer : ndarray, shape (n, n_rx), complex
        Candidate steering vectors (:func:`skyradar.process.doa.steering_vector`).
    z : ndarray, shape (n_rx,), complex
        One calibrated snapshot (amplitude, sqrt(W)).
    p : ndarray, shape (n_rx, n_rx), complex
        The cell's projector ``I - E E^H`` (or whitening).

    Returns
    -------
    ndarray, shape (n,)
        Score of each candidate, W.

    Examples
    --------
    Without a projection the score of the snapshot's own direction is ``|s|^2 = n_rx = 4``;
    a null on the second direction leaves it no score, and removes its share of the snapshot
    from the first:

    >>> from skyradar.config import RadarConfig
    >>> from skyradar.process.doa import direction_from_angles, steering_vector
    >>> cfg = RadarConfig.prototype_2022()
    >>> s = steering_vector(direction_from_angles(np.radians([10.0, -10.0]), 0.0), cfg)
    >>> projected_scores(s, s[0], np.eye(4)).round(6).tolist()
    [4.0, 2.923084]
    >>> e = s[1][:, None] / 2.0  # unit vector along s[1]
    >>> projected_scores(s, s[0] + 5.0 * s[1], np.eye(4) - e @ e.conj().T).round(6).tolist()
    [1.076916, 0.0]
    """
    steer = np.ascontiguousarray(steer, np.complex128)
    args = (np.ascontiguousarray(z, np.complex128), np.ascontiguousarray(p, np.complex128))
    return _scores(steer, *args, np.empty(len(steer)))


def angle_sigmas_rad(
    u: np.ndarray, pixels: np.ndarray, proj: np.ndarray, config: RadarConfig, noise_floor_w: float
) -> tuple[np.ndarray, np.ndarray]:
    """Cramer-Rao bounds on the elevation and the azimuth of each direction ``u`` (n, 3) seen through
    ``proj``, rad (two arrays of n).

    For a plane wave of unknown complex amplitude in Gaussian interference the Fisher information
    of (elevation, azimuth) is ``2 |a|^2 / N0 Re(D^H W D - D^H W s s^H W D / s^H W s)`` (``D`` the
    steering vector's derivatives, ``W`` the cell's projector ``P`` or whitening ``N0 R^-1``,
    ``a = s^H W z / s^H W s`` the amplitude estimate, ``N0`` the noise floor, W). The elevation's
    bound is a diagonal entry of its inverse (the azimuth a nuisance), infinite where ``W`` leaves
    the elevation no information. The azimuth's is the same where the elevation is measured (bound
    at most :data:`MAX_ELEVATION_SIGMA_RAD`); elsewhere the detection is placed at the elevation
    prior (:func:`projected_directions`) and the azimuth's bound is the one given that elevation,
    ``1 / sqrt(J_az,az)``. Two nulls at one elevation, left and right of boresight (ground on both
    sides at one range and Doppler), take the 2x2 array's elevation (its Kronecker structure) and
    the kite's azimuth (:mod:`skyradar.rx_layouts`: mirror-symmetric about its vertical axis, its
    only horizontal baseline is the pair the antisymmetric null takes).

    Examples
    --------
    >>> from skyradar.process.doa import direction_from_angles, steering_vector
    >>> cfg = RadarConfig.prototype_2022()
    >>> u = direction_from_angles(np.radians([10.0, 10.0]), np.radians([-5.0, -5.0]))
    >>> z = 10.0 * steering_vector(u, cfg) * np.sqrt(cfg.noise_power_w)  # 20 dB per channel: doa_crlb's
    >>> e, _ = np.linalg.qr(steering_vector(direction_from_angles(np.radians([-20.0, 20.0]), -0.35), cfg).T)
    >>> proj = np.stack([np.eye(4), np.eye(4) - e @ e.conj().T])
    >>> el, az = angle_sigmas_rad(u, z, proj, cfg, cfg.noise_power_w)
    >>> np.degrees(el).round(2).tolist(), np.degrees(az).round(2).tolist()
    ([1.29, inf], [1.31, 3.36])
    """
    fisher, seen = _direction_fisher(u, pixels, proj, config, noise_floor_w)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # no information: inf
        det = fisher[:, 0, 0] * fisher[:, 1, 1] - fisher[:, 0, 1] * fisher[:, 1, 0]
        scale = np.maximum((fisher[:, 0, 0] + fisher[:, 1, 1]) ** 2, 1e-300)  # rank 1: one angle only
        full = seen & (det > 1e-9 * scale)
        var_el = np.where(full, fisher[:, 1, 1] / det, np.inf)
        var_el = np.where(var_el > 0, var_el, np.inf)
        given_el = np.where(seen & (fisher[:, 1, 1] > 0), 1.0 / fisher[:, 1, 1], np.inf)
        var_az = np.where(var_el <= MAX_ELEVATION_SIGMA_RAD**2, fisher[:, 0, 0] / det, given_el)
        return np.sqrt(var_el), np.sqrt(np.where(var_az > 0, var_az, np.inf))


def elevation_sigma_rad(
    u: np.ndarray, pixels: np.ndarray, proj: np.ndarray, config: RadarConfig, noise_floor_w: float
) -> np.ndarray:
    """Cramer-Rao bound on the elevation of each direction ``u`` (n, 3) seen through ``proj``, rad.

    The first of :func:`angle_sigmas_rad`. Infinite where ``W`` leaves the elevation no information
    (two nulls at one elevation: the 2x2 array's Kronecker structure).

    Examples
    --------
    >>> from skyradar.process.doa import direction_from_angles, steering_vector
    >>> cfg = RadarConfig.prototype_2022()
    >>> u = direction_from_angles(np.radians([10.0]), np.radians([-5.0]))  # no nulls: doa_crlb's bound
    >>> z = 10.0 * steering_vector(u, cfg) * np.sqrt(cfg.noise_power_w)
    >>> np.degrees(elevation_sigma_rad(u, z, np.eye(4)[None], cfg, cfg.noise_power_w)).round(2).tolist()
    [1.29]
    """
    return angle_sigmas_rad(u, pixels, proj, config, noise_floor_w)[0]


def _direction_fisher(
    u: np.ndarray, pixels: np.ndarray, proj: np.ndarray, config: RadarConfig, noise_floor_w: float
) -> tuple[np.ndarray, np.ndarray]:
    """Fisher information (n, 2, 2) of (elevation, azimuth) through ``proj``, and where ``u`` is seen."""
    k = 2.0 * np.pi / config.wavelength_m
    az, el = np.arctan2(u[:, 1], u[:, 0]), np.arcsin(np.clip(-u[:, 2], -1.0, 1.0))
    du_del = np.stack([-np.sin(el) * np.cos(az), -np.sin(el) * np.sin(az), -np.cos(el)], -1)
    du_daz = np.stack([-np.cos(el) * np.sin(az), np.cos(el) * np.cos(az), np.zeros_like(az)], -1)
    s = steering_vector(u, config)
    rx = np.asarray(channel_positions_m(config), float)
    d = np.stack([-1j * k * (g @ rx.T) * s for g in (du_del, du_daz)], -1)  # (n, n_rx, 2)
    ws, wd = np.einsum("nkl,nl->nk", proj, s), np.einsum("nkl,nlj->nkj", proj, d)
    sws = np.einsum("nk,nk->n", s.conj(), ws).real
    seen = sws > 1e-9 * np.einsum("nk,nk->n", s.conj(), s).real  # a direction the nulls took: inf
    sws = np.where(seen, sws, 1.0)
    amp2 = np.abs(np.einsum("nk,nk->n", ws.conj(), pixels) / sws) ** 2  # proj Hermitian
    dws = np.einsum("nkj,nk->nj", d.conj(), ws)
    info = (
        np.einsum("nkj,nkl->njl", d.conj(), wd)
        - dws[:, :, None] * dws.conj()[:, None, :] / sws[:, None, None]
    )
    return 2.0 * amp2[:, None, None] / noise_floor_w * info.real, seen


def projected_directions(
    pixels: np.ndarray, proj: np.ndarray, config: RadarConfig, noise_floor_w: float
) -> tuple[np.ndarray, np.ndarray]:
    """Antenna-frame unit vectors (n, 3) of calibrated snapshots (n, n_rx) seen through ``proj``,
    and whether each one's elevation was measured (n,) bool.

    ``proj`` holds each snapshot's projector ``P = I - E E^H`` or whitening ``N0 R^-1``, shape
    (n, n_rx, n_rx); ``noise_floor_w`` is ``N0``. Where the elevation's Cramer-Rao bound through
    ``proj`` (:func:`elevation_sigma_rad`) exceeds :data:`MAX_ELEVATION_SIGMA_RAD` the vector has
    elevation 0 (a prior, see the module docstring) and its flag is False.

    Examples
    --------
    >>> from skyradar.process.doa import direction_from_angles, steering_vector
    >>> cfg = RadarConfig.prototype_2022()
    >>> u = direction_from_angles(np.radians([10.0, 10.0]), np.radians([-5.0, -5.0]))
    >>> z = 10.0 * steering_vector(u, cfg) * np.sqrt(cfg.noise_power_w)  # 20 dB per channel
    >>> u_nulls = direction_from_angles(np.radians([-20.0, 20.0]), np.radians([-20.0, -20.0]))
    >>> e, _ = np.linalg.qr(steering_vector(u_nulls, cfg).T)  # two nulls at one elevation
    >>> proj = np.stack([np.eye(4), np.eye(4) - e @ e.conj().T])
    >>> u, measured = projected_directions(z, proj, cfg, cfg.noise_power_w)
    >>> measured.tolist(), np.degrees(np.arcsin(-u[:, 2])).round(1).tolist()
    ([True, False], [-5.0, 0.0])
    """
    basis = _coarse(config)
    rx = np.ascontiguousarray(channel_positions_m(config), float)
    wavenumber = 2.0 * np.pi / config.wavelength_m
    half = int(round(_FINE_HALF_DEG / _FINE_STEP_DEG))
    rule = (np.radians(_COARSE_DEG), rx, wavenumber, np.radians(_FINE_STEP_DEG), half)
    z_all = np.ascontiguousarray(pixels, np.complex128)
    p_all = np.ascontiguousarray(proj, np.complex128)
    angles = _directions(basis, *rule, z_all, p_all)
    u = direction_from_angles(angles[:, 0], angles[:, 1])
    measured = elevation_sigma_rad(u, z_all, p_all, config, noise_floor_w) <= MAX_ELEVATION_SIGMA_RAD
    for n in np.flatnonzero(~measured):  # the co-altitude prior; azimuth measured along it
        # The score is flat along the cone of equal horizontal direction cosine, so the search's best
        # point may lie anywhere on it: start at the cone's elevation-0 point, not at its azimuth.
        on_cone = np.arcsin(np.clip(np.cos(angles[n, 1]) * np.sin(angles[n, 0]), -1.0, 1.0))
        angles[n] = _azimuth_at_zero(on_cone, *rule[1:], z_all[n], p_all[n]), 0.0
    return direction_from_angles(angles[:, 0], angles[:, 1]), measured


def directions_after_projection(
    pixels: np.ndarray, proj: np.ndarray, config: RadarConfig, noise_floor_w: float
) -> np.ndarray:
    """Antenna-frame unit vectors (n, 3) of calibrated snapshots (n, n_rx) seen through ``proj``.

    Elevation 0 where the projection leaves it unmeasured (:func:`projected_directions` says where).

    Parameters
    ----------
    pixels : ndarray, shape (n, n_rx), complex
        Calibrated snapshots (amplitude, sqrt(W)).
    proj : ndarray, shape (n, n_rx, n_rx), complex
        Each snapshot's projector ``P = I - E E^H`` (or whitening ``N0 R^-1``).
    config : RadarConfig
        Receive positions (m) and wavelength (m).
    noise_floor_w : float
        Noise floor ``N0`` per pixel, W (for the elevation's Cramer-Rao bound).

    Returns
    -------
    ndarray, shape (n, 3)
        Unit vectors in the antenna frame, on the 0.05 deg search lattice.

    Examples
    --------
    A target at 10 deg right, 5 deg down in a cell whose ground clutter 30 dB stronger comes from
    40 deg down: the plain phase estimate follows the clutter, the projected matched filter finds
    the target:

    >>> from skyradar.config import RadarConfig
    >>> from skyradar.process.doa import angles_from_direction, direction_from_angles
    >>> from skyradar.process.doa import estimate_directions, steering_vector
    >>> cfg = RadarConfig.prototype_2022()
    >>> target = steering_vector(direction_from_angles(np.radians(10.0), np.radians(-5.0)), cfg)
    >>> ground = steering_vector(direction_from_angles(0.0, np.radians(-40.0)), cfg)
    >>> z = (target + 30.0 * ground)[None]
    >>> np.degrees(angles_from_direction(estimate_directions(z, cfg))).ravel().round(1).tolist()
    [0.3, -38.9]
    >>> e = ground[:, None] / 2.0
    >>> u = directions_after_projection(z, (np.eye(4) - e @ e.conj().T)[None], cfg, cfg.noise_power_w)
    >>> np.degrees(angles_from_direction(u)).ravel().round(2).tolist()
    [10.0, -5.0]
    """
    return projected_directions(pixels, proj, config, noise_floor_w)[0]
