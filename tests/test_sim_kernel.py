"""The terrain kernel's vectorised batches against its scalar reference loop, and its helpers."""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

from skyradar.config import Mount, RadarConfig
from skyradar.errors import InputError
from skyradar.geo import rotation_matrix
from skyradar.scene.synthetic_terrain import centred_grid
from skyradar.sim._elementary import cis_cycles, cis_cycles_f32, fast_atan2, wrap_index
from skyradar.sim._horizon_kernel import horizon_map
from skyradar.sim._terrain_kernel import add_sparse, relative_points, rotate_points
from skyradar.sim.image import ImageSimulator, PlatformState, PointTarget

CFG = RadarConfig.prototype_2022()


def _hills(spacing_m: float, n: int = 141, seed: int = 3):
    # Rough hills and a ridge, so that occlusion, slopes facing away and grazing facets occur.
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:n, 0:n] * spacing_m
    z = 80.0 * np.sin(x / 700.0) * np.cos(y / 500.0) + rng.normal(0.0, 6.0, (n, n))
    z[n // 3 : n // 3 + 2, :] += 250.0
    return centred_grid(z, 47.0, 8.0, spacing_m, "hills")


def _both_modes(sim: ImageSimulator, platform: PlatformState) -> tuple[np.ndarray, np.ndarray]:
    cubes = []
    for mode in (0, 1):
        sim._kernel_mode = mode
        cubes.append(sim.frame(platform, frame_index=3))
    return cubes[0], cubes[1]


_AT_ORIGIN = (0.0, 0.0, 0.0)


@pytest.mark.parametrize(
    ("spacing_m", "facet_m", "occlusion", "speed_mps", "attitude", "tx_m"),
    [
        # 3 x 3 sub-facets per cell, dense cube
        (40.0, None, True, 45.0, (0.0, 0.0, 0.0), _AT_ORIGIN),
        # Doppler aliases twice, turned antenna
        (40.0, None, False, 120.0, (0.4, 0.1, -0.2), _AT_ORIGIN),
        # DEM spacing: sparse list, row batches of one-facet cells
        (60.0, float("inf"), True, 60.0, (0.0, 0.05, 0.0), _AT_ORIGIN),
        # 3 x 3 sub-facets, other heading
        (60.0, 25.0, True, 30.0, (-1.0, 0.0, 0.3), _AT_ORIGIN),
        # 2 x 2 sub-facets: row batches of small cells
        (30.0, 20.0, True, 30.0, (2.0, 0.0, 0.0), _AT_ORIGIN),
        # transmitter off the phase-centre reference
        (40.0, None, True, 45.0, (0.2, 0.0, 0.0), (0.0, 0.03, -0.01)),
    ],
)
def test_vectorised_kernel_matches_scalar_reference(spacing_m, facet_m, occlusion, speed_mps, attitude, tx_m):
    terrain = _hills(spacing_m)
    cfg = CFG.replace(mount=Mount.preset("forward-down"), tx_position_m=np.array(tx_m))
    sim = ImageSimulator(
        cfg, terrain, (47.0, 8.0, 0.0), facet_size_m=facet_m, occlusion=occlusion, noise=True
    )
    platform = PlatformState(
        np.array([-300.0, 200.0, -400.0]), np.array([speed_mps, 10.0, -2.0]), np.array(attitude)
    )
    reference, batched = _both_modes(sim, platform)
    noise_sd = np.sqrt(CFG.noise_power_w / 2)
    assert np.abs(reference).max() > 1e3 * noise_sd  # terrain returns, not just noise
    # Same physics: equal to float32 rounding of the largest pixel (the order of float
    # operations differs between SIMD and scalar code).
    np.testing.assert_allclose(batched, reference, rtol=0, atol=1e-6 * np.abs(reference).max())
    assert np.count_nonzero(np.abs(batched) > 3 * noise_sd) == np.count_nonzero(
        np.abs(reference) > 3 * noise_sd
    )


def test_frame_writes_into_a_given_buffer():
    sim = ImageSimulator(CFG, _hills(60.0), (47.0, 8.0, 0.0), facet_size_m=float("inf"), seed=4)
    platform = PlatformState(np.array([0.0, 0.0, -500.0]), np.array([40.0, 0.0, 0.0]), np.zeros(3))
    target = PointTarget(np.array([1200.0, 100.0, -600.0]), np.zeros(3), 5.0)
    buffer = np.full((CFG.n_range, CFG.n_doppler, CFG.n_rx), np.nan + 0j, np.complex64)
    got = sim.frame(platform, [target], frame_index=7, out=buffer)
    assert got is buffer
    np.testing.assert_array_equal(buffer, sim.frame(platform, [target], frame_index=7))
    for bad in (
        np.empty((CFG.n_range, CFG.n_doppler, CFG.n_rx), np.complex128),
        np.empty((CFG.n_range, CFG.n_doppler, CFG.n_rx + 1), np.complex64),
        np.empty((CFG.n_rx, CFG.n_doppler, CFG.n_range), np.complex64).transpose(2, 1, 0),
    ):
        with pytest.raises(InputError, match="out must be"):
            sim.frame(platform, out=bad)


def test_frames_do_not_depend_on_the_frame_before():
    # frame() reuses its work arrays between frames; a view handed out is never one of them.
    sim = ImageSimulator(CFG, _hills(60.0), (47.0, 8.0, 0.0), seed=2)
    first = PlatformState(np.array([0.0, 0.0, -500.0]), np.array([40.0, 0.0, 0.0]), np.zeros(3))
    other = PlatformState(
        np.array([900.0, -700.0, -800.0]), np.array([0.0, 50.0, 0.0]), np.array([1.6, 0, 0])
    )
    view = sim.terrain_view(sim.geometry(first))
    kept = view.p_ned.copy()
    cube = sim.frame(first, frame_index=1)
    sim.frame(other, frame_index=2)
    np.testing.assert_array_equal(sim.frame(first, frame_index=1), cube)
    np.testing.assert_array_equal(view.p_ned, kept)


@njit
def _atan2_all(y, x, out):
    for i in range(y.size):
        out[i] = fast_atan2(y[i], x[i])


@njit
def _cis_all(x, c, s):
    for i in range(x.size):
        c[i], s[i] = cis_cycles(x[i])


@njit
def _cis_f32_all(x, c, s):
    for i in range(x.size):
        c[i], s[i] = cis_cycles_f32(x[i])


@njit
def _wrap_all(i, n, out):
    for k in range(i.size):
        out[k] = wrap_index(i[k], n)


def test_fast_atan2_matches_numpy_in_every_octant():
    rng = np.random.default_rng(1)
    y = np.concatenate([rng.normal(size=100_000), [0.0, 0.0, 0.0, 1.0, -1.0, 1.0, -1.0, 2.0]])
    x = np.concatenate([rng.normal(size=100_000), [0.0, 1.0, -1.0, 0.0, 0.0, 1.0, -1.0, 2.0]])
    got = np.empty_like(x)
    _atan2_all(y, x, got)
    want = np.arctan2(y, x)
    want[(x < 0) & (y == 0)] = np.pi  # the kernel's convention on the negative axis: +pi
    assert np.max(np.abs(got - want)) < 1.15e-5  # largest at 45 degrees
    assert got[100_000] == 0.0  # the origin


def test_cis_cycles_and_wrap_index_match_numpy():
    x = np.concatenate(
        [np.linspace(-3.0, 3.0, 200_001), np.random.default_rng(2).uniform(-4e5, 4e5, 100_000)]
    )
    c, s = np.empty_like(x), np.empty_like(x)
    _cis_all(x, c, s)
    reduced = 2 * np.pi * (x - np.floor(x))  # numpy's own reduction of large arguments is no better
    assert np.max(np.abs(c - np.cos(reduced))) < 1e-9
    assert np.max(np.abs(s - np.sin(reduced))) < 1e-9
    c32, s32 = np.empty(x.size, np.float32), np.empty(x.size, np.float32)
    _cis_f32_all(x, c32, s32)
    assert np.max(np.abs(c32 - np.cos(reduced))) < 2e-7
    assert np.max(np.abs(s32 - np.sin(reduced))) < 2e-7
    i = np.arange(-1000, 1000)
    out = np.empty_like(i)
    _wrap_all(i, 250, out)
    np.testing.assert_array_equal(out, i % 250)


def test_relative_and_rotated_points():
    grid = np.random.default_rng(0).normal(size=(50, 40, 3))
    origin = np.array([10.0, -3.0, 0.5])
    out = np.empty((26, 33, 3))
    np.testing.assert_array_equal(relative_points(grid, 5, 31, 7, 40, origin, out), grid[5:31, 7:40] - origin)
    rot = rotation_matrix(0.3, -0.2, 0.1)
    np.testing.assert_allclose(rotate_points(out, rot, np.empty_like(out)), out @ rot.T, rtol=0, atol=1e-12)


def _horizon_numpy(p_ned, rot, nsub, r_lim, az_bin, h_bin, n_az, n_h, sample_m):
    """horizon_map's definition in plain numpy (exact atan2): the reference for its bins."""
    front = (p_ned @ rot[0]) > 0
    cell_front = front[:-1, :-1] | front[:-1, 1:] | front[1:, :-1] | front[1:, 1:]
    best = np.full((n_az, n_h), -np.inf)
    for i, j in zip(*np.nonzero(cell_front), strict=True):
        for a in range(nsub):
            for b in range(nsub):
                u, w = (a + 0.5) / nsub, (b + 0.5) / nsub
                p = (1 - u) * (1 - w) * p_ned[i, j] + (1 - u) * w * p_ned[i, j + 1]
                p = p + u * (1 - w) * p_ned[i + 1, j] + u * w * p_ned[i + 1, j + 1]
                h = np.hypot(p[0], p[1])
                if h > r_lim:
                    continue
                ia = int((np.arctan2(p[1], p[0]) + np.pi) / az_bin) % n_az
                k = min(int(h / h_bin), n_h - 1)
                spread = min(int(0.5 * sample_m / (max(h, 1.0) * az_bin)) + 1, n_az // 4)
                cols = (ia + np.arange(-spread, spread + 1)) % n_az
                best[cols, k] = np.maximum(best[cols, k], -p[2] / max(h, 1e-9))
    running = np.maximum.accumulate(best, axis=1)
    return np.concatenate([np.full((n_az, 1), -np.inf), running[:, :-1]], axis=1)


@pytest.mark.parametrize("n_blocks", [1, 3])
def test_horizon_map_matches_numpy_definition(n_blocks):
    terrain = _hills(50.0, n=41)
    p_ned = terrain.points_ned(47.0, 8.0, 0.0) - np.array([0.0, 0.0, -300.0])
    rot = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # looking east
    bins = (900.0, 2 * np.pi / 90, 25.0, 90, 37)  # r_lim, azimuth bin, range bin, n_az, n_h
    got = horizon_map(p_ned, rot, 2, 2, *bins, n_blocks, 25.0)
    want = _horizon_numpy(p_ned, rot, 2, *bins, 25.0)
    assert np.isfinite(want).sum() > 500  # plenty of bins raised
    # fast_atan2 (1.2e-5 rad) can move a sample across an azimuth-bin edge: compare bins
    # away from such edges only, i.e. all but a few.
    same = (got == want.astype(np.float32)) | (np.isneginf(got) & np.isneginf(want))
    assert same.mean() > 0.99


@pytest.mark.parametrize("n_lists", [1, 2, 3])
def test_add_sparse_matches_numpy_add_at(n_lists):
    rng = np.random.default_rng(n_lists)
    n_pix, n_rx, cap = 500, 4, 400
    idx = rng.integers(0, n_pix, (n_lists, cap))
    val = (rng.normal(size=(n_lists, cap, n_rx)) + 1j * rng.normal(size=(n_lists, cap, n_rx))).astype(
        np.complex64
    )
    count = rng.integers(0, cap, n_lists)
    frame = (rng.normal(size=(n_pix, n_rx)) + 0j).astype(np.complex64)
    want = frame.astype(complex)
    for b in range(n_lists):
        np.add.at(want, idx[b, : count[b]], val[b, : count[b]])
    add_sparse(frame, idx, val, count)
    np.testing.assert_allclose(frame, want, rtol=0, atol=1e-5)
