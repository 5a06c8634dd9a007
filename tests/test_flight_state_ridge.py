"""Ridge extraction and per-frame flight state on range-Doppler images built here from a flat plane.

The images are made independently of the simulator: random ground points on a flat plane,
mapped to their nearest (range, Doppler) bin with the package's conventions (range bin k
at k dR, Doppler bin j at (j - nV/2) dV, wrap outside +-VLim, sawtooth coupling), powers from
the radar equation with cosine reflectivity and the default antenna pattern, random phases.
"""

from __future__ import annotations

import numpy as np
import pytest

from skyradar.config import Mount, RadarConfig
from skyradar.nav.flight_state import estimate_frame
from skyradar.nav.inversion import ridge_velocity
from skyradar.nav.ridge import band_start, extract_ridge, noise_floor_w

CFG = RadarConfig.prototype_2022(mount=Mount.preset("forward-down"), range_limit_m=2500.0)


def flat_ground_cube(vx, vz, h, cfg=CFG, n_points=600_000, seed=0, noise=True, extra=()):
    """(range, doppler, rx) cube of a flat plane ``h`` below a level radar moving at (vx, 0, vz)."""
    rng = np.random.default_rng(seed)
    rho_max = np.sqrt((cfg.range_limit_m + cfg.range_resolution_m) ** 2 - h * h)
    rho = rho_max * np.sqrt(rng.random(n_points))
    phi = rng.uniform(-np.radians(75.0), np.radians(75.0), n_points)
    p = np.stack(
        [rho * np.cos(phi), rho * np.sin(phi), np.full(n_points, h)], axis=1
    )  # level: fwd, right, down
    r = np.linalg.norm(p, axis=1)
    u = p / r[:, None]
    v_r = -(u @ np.array([vx, 0.0, vz]))
    u_ant = u @ cfg.mount.rotation  # level = body here; body -> antenna is rotation^T
    az, el = np.arctan2(u_ant[:, 1], u_ant[:, 0]), np.arcsin(-u_ant[:, 2])
    area = np.pi * rho_max**2 * (150.0 / 360.0) / n_points
    gain2 = 10 ** (cfg.antenna.gain_db(az, el) / 5.0)
    power = cfg.pe_w * gain2 * cfg.wavelength_m**2 * area * (h / r) / ((4 * np.pi) ** 3 * r**4)
    k = np.floor((r + cfg.range_doppler_coupling_s * v_r) / cfg.range_resolution_m + 0.5).astype(int)
    j = (np.floor(v_r / cfg.doppler_resolution_mps + 0.5).astype(int) + cfg.n_doppler // 2) % cfg.n_doppler
    ok = (k >= 0) & (k < cfg.n_range) & (u_ant[:, 0] > 0)
    amp = np.sqrt(power[ok]) * np.exp(2j * np.pi * rng.random(ok.sum()))
    flat = np.ravel_multi_index((k[ok], j[ok]), (cfg.n_range, cfg.n_doppler))
    size = cfg.n_range * cfg.n_doppler
    img = np.bincount(flat, amp.real, size) + 1j * np.bincount(flat, amp.imag, size)
    cube = np.repeat(img.reshape(cfg.n_range, cfg.n_doppler, 1), cfg.n_rx, axis=2)
    for kk, jj, pw in extra:
        cube[kk, jj] += np.sqrt(pw)
    if noise:
        sigma = np.sqrt(cfg.noise_power_w / 2)
        cube = cube + sigma * (rng.standard_normal(cube.shape) + 1j * rng.standard_normal(cube.shape))
    return cube.astype(np.complex64)


def test_noise_floor_and_cut():
    rng = np.random.default_rng(0)
    p = rng.exponential(CFG.noise_power_w, (CFG.n_range, CFG.n_doppler, 4)).sum(axis=2)
    assert noise_floor_w(p, 4) == pytest.approx(4 * CFG.noise_power_w, rel=0.03)
    occ = np.zeros(250, bool)
    occ[240:] = occ[:10] = True  # a band across the wrap
    assert band_start(occ) == 240
    occ[120] = True  # the widest remaining gap still ends at the band
    assert band_start(occ) == 240
    assert band_start(np.zeros(250, bool)) is None and band_start(np.ones(250, bool)) is None


@pytest.mark.parametrize(("vx", "vz", "h"), [(45.0, 0.0, 500.0), (60.0, 3.0, 700.0), (35.0, -4.0, 400.0)])
def test_ridge_follows_the_flat_plane_curve(vx, vz, h):
    ridge = extract_ridge(flat_ground_cube(vx, vz, h), CFG)
    assert len(ridge) > 100
    err = ridge.radial_velocity_mps - ridge_velocity(ridge.range_m, vx, vz, h)
    # Doppler bin quantisation (uniform +-dV/2) plus a few faded far-range bins.
    assert np.median(np.abs(err)) < CFG.doppler_resolution_mps / 2
    assert np.mean(np.abs(err) < 0.5) > 0.9
    assert np.all(ridge.radial_velocity_mps < 0)  # ground ahead closes


@pytest.mark.parametrize(("vx", "vz", "h"), [(45.0, 0.0, 500.0), (60.0, 3.0, 700.0), (35.0, -4.0, 400.0)])
def test_robust_frame_estimate_on_flat_plane(vx, vz, h):
    # 60 m/s aliases the far-range ground (VLim = 39.2 m/s); no prior is given.
    est = estimate_frame(flat_ground_cube(vx, vz, h, seed=1), CFG)
    assert not est.low_quality and est.quality > 0.5
    assert est.fit.h_m == pytest.approx(h, abs=4.0)
    assert est.fit.vx_mps == pytest.approx(vx, abs=0.3)
    assert est.fit.vz_mps == pytest.approx(vz, abs=0.4)


def test_bin_centre_pairing_biases_height_by_half_a_bin():
    cube = flat_ground_cube(50.0, 0.0, 600.0, seed=2)
    centre = extract_ridge(cube, CFG, edge_offset_bins=0.0)
    edge = extract_ridge(cube, CFG)
    from skyradar.nav.inversion import fit_robust

    h_centre = fit_robust(centre.range_m, centre.radial_velocity_mps).h_m
    h_edge = fit_robust(edge.range_m, edge.radial_velocity_mps).h_m
    assert abs(h_edge - 600.0) < 3.0
    assert h_centre - 600.0 == pytest.approx(-CFG.range_resolution_m / 2, abs=3.0)


def test_intruder_closing_faster_than_the_ground_is_not_the_ridge():
    k = 100  # 1500 m
    j_ground = int(
        np.round(ridge_velocity(np.array([k * CFG.range_resolution_m]), 40.0, 0.0, 500.0)[0] / 0.3133)
    )
    j = j_ground + CFG.n_doppler // 2 - 20  # 6 m/s faster closing
    cube = flat_ground_cube(40.0, 0.0, 500.0, seed=3, extra=[(k, j, 1e-9)])
    ridge = extract_ridge(cube, CFG)
    row = np.flatnonzero(ridge.range_bin == k)
    assert row.size == 1 and ridge.doppler_bin[row[0]] != j
    est = estimate_frame(cube, CFG)
    assert est.fit.h_m == pytest.approx(500.0, abs=4.0)


def test_sky_only_frames_are_low_quality_not_wrong():
    rng = np.random.default_rng(4)
    sigma = np.sqrt(CFG.noise_power_w / 2)
    cube = sigma * (
        rng.standard_normal((CFG.n_range, CFG.n_doppler, 4))
        + 1j * rng.standard_normal((CFG.n_range, CFG.n_doppler, 4))
    )
    cube[60, 100] += 1e-6  # one aircraft
    cube[61, 100] += 3e-7
    for method in ("robust", "thesis"):
        est = estimate_frame(cube, CFG, method=method)
        assert est.low_quality and np.isnan(est.fit.h_m) and np.isnan(est.fit.vx_mps)
    est = estimate_frame(np.zeros((CFG.n_range, CFG.n_doppler, 4), np.complex64), CFG)
    assert est.low_quality and est.quality == 0.0
