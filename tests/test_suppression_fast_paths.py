"""The fast paths of clutter suppression against the straightforward versions."""

from __future__ import annotations

from collections import OrderedDict

import numpy as np
import pytest

from skyradar.config import RadarConfig
from skyradar.io.ownship_states import OwnShipStates
from skyradar.process import clutter_anchors, clutter_frames
from skyradar.process.cfar import cfar_2d_floor
from skyradar.process.clutter_doa import (
    _COARSE_DEG,
    _coarse,
    _grid_scores,
    projected_directions,
    projected_scores,
)
from skyradar.process.doa import direction_from_angles, steering_vector

CFG = RadarConfig.prototype_2022()


def _lattice_best(z: np.ndarray, p: np.ndarray, measured: bool) -> tuple[np.ndarray, float]:
    """Exhaustive search: 2 deg grid, then every point of the 0.05 deg lattice within +-1.5 deg;
    where the elevation is not measured, the lattice row at elevation 0 around the azimuth with that
    point's horizontal direction cosine."""

    def score(az_deg: np.ndarray, el_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        a, e = np.meshgrid(np.radians(az_deg), np.radians(el_deg), indexing="ij")
        u = direction_from_angles(a.ravel(), e.ravel())
        ps = steering_vector(u, CFG) @ p.T  # rows (P s)^T
        num = np.abs(np.conj(ps) @ z) ** 2
        return u, num / np.sum(np.abs(ps) ** 2, axis=1)

    coarse = np.arange(-70.0, 70.5, 2.0)
    _, s = score(coarse, coarse)
    ia, ie = np.unravel_index(np.argmax(s), (coarse.size, coarse.size))
    fine = np.arange(-1.5, 1.525, 0.05)
    u, s = score(coarse[ia] + fine, coarse[ie] + fine)
    if not measured:  # the cone through the best point (its horizontal direction cosine) at elevation 0
        az = np.degrees(np.arcsin(u[np.argmax(s), 1]))
        u, s = score(az + fine, np.zeros(1))
    return u[np.argmax(s)], float(s.max())


def test_coarse_to_fine_direction_search_finds_the_exhaustive_lattice_best():
    rng = np.random.default_rng(0)
    for _ in range(25):
        u_true = direction_from_angles(rng.uniform(-1.0, 1.0), rng.uniform(-0.8, 0.8))
        noise = rng.standard_normal(4) + 1j * rng.standard_normal(4)
        z = steering_vector(u_true, CFG) * rng.uniform(3.0, 10.0) + noise
        m = int(rng.integers(0, 3))
        e = np.linalg.qr(rng.standard_normal((4, 4)) + 1j * rng.standard_normal((4, 4)))[0][:, :m]
        p = np.eye(4) - e @ e.conj().T
        u, measured = projected_directions(z[None], p[None], CFG, 1.0)
        u_ref, best = _lattice_best(z, p, bool(measured[0]))
        u = u[0]
        ps = p @ steering_vector(u, CFG)
        got = abs(np.vdot(ps, z)) ** 2 / np.vdot(ps, ps).real
        assert got >= best * (1 - 1e-5)
        assert np.degrees(np.arccos(min(1.0, float(u @ u_ref)))) < 0.1


def test_coarse_grid_scores_from_the_real_basis_equal_the_projected_matched_filter_per_point():
    rng = np.random.default_rng(3)
    a, e = np.meshgrid(np.radians(_COARSE_DEG), np.radians(_COARSE_DEG), indexing="ij")
    steer = steering_vector(direction_from_angles(a.ravel(), e.ravel()), CFG)
    for m in (0, 1, 2):
        z = rng.standard_normal(4) + 1j * rng.standard_normal(4)
        q = np.linalg.qr(rng.standard_normal((4, 4)) + 1j * rng.standard_normal((4, 4)))[0][:, :m]
        for p in (
            np.eye(4) - q @ q.conj().T,
            np.linalg.inv(np.cov(rng.standard_normal((4, 40))) + 0.5 * np.eye(4)),
        ):
            p = np.ascontiguousarray(p, complex)
            got = _grid_scores(_coarse(CFG), z, p, np.empty(len(steer)))
            np.testing.assert_allclose(got, projected_scores(steer, z, p), rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("clutter_rows", [10, 60])  # under and over 1 % of pixels that could be hits
def test_sparse_cfar_after_suppression_gives_the_full_maps_hits(clutter_rows):
    rng = np.random.default_rng(2)
    shape = (200, 160)
    channels = rng.choice(np.array([2, 3, 4], np.int8), size=shape)
    power = (rng.gamma(channels, 1.0 / channels)).astype(np.float32)
    skip = np.zeros(shape, bool)
    skip[40 : 40 + clutter_rows, 30:55] = True  # unsuppressed clutter: bright, out of the others' training
    power[skip] *= 300.0
    for r, d, snr in ((50, 95, 40.0), (120, 20, 25.0), (121, 22, 18.0), (5, 158, 30.0), (199, 0, 30.0)):
        power[r, d] += snr  # targets beside the clutter, in clutter-free noise, at the edges
    for pfa in (2e-8, 1e-4):
        full_hits, full_noise = cfar_2d_floor(power, channels, 1.0, skip, pfa=pfa)
        hits, noise = cfar_2d_floor(power, channels, 1.0, skip, pfa=pfa, noise_map=False)
        assert full_hits.sum() >= 5 and np.array_equal(hits, full_hits)
        known = np.isfinite(noise)
        assert known[hits].all() and known.mean() < 0.1
        np.testing.assert_allclose(noise[known], full_noise[known], rtol=1e-5)


def test_frame_subspace_is_reused_within_the_tolerance_and_recomputed_beyond(monkeypatch):
    calls = []

    def fake_subspace(config, v, ant_to_ned, height, depth_fn, n_azimuth):
        calls.append((tuple(v), height))
        return object()

    monkeypatch.setattr(clutter_frames, "clutter_subspace", fake_subspace)
    monkeypatch.setattr(clutter_frames, "_CACHE", OrderedDict())
    # One run: GNSS-like jitter (vertical velocity, height, attitude) inside the tolerance, 7 % higher,
    # a 1 m/s climb, then back (each frame stands alone: the velocity mean is over one frame here).
    vd = np.array([0.0, 0.3, -0.2, 0.1, 0.0, 0.0, 1.0, 0.05])
    height = np.array([1000.0, 1000.0, 1008.0, 993.0, 1040.0, 1070.0, 1000.0, 1003.0])
    pitch = np.radians([0.0, 0.0, 0.3, -0.4, 0.0, 0.0, 0.0, 0.0])
    n = vd.size
    own = OwnShipStates.from_columns(
        {
            "time_s": np.arange(n) / 9.4,
            "own_north_m": np.zeros(n),
            "own_east_m": np.zeros(n),
            "own_down_m": -height,
            "own_vn_mps": np.full(n, 50.0),
            "own_ve_mps": np.zeros(n),
            "own_vd_mps": vd,
            "own_yaw_rad": np.full(n, 0.3),
            "own_pitch_rad": pitch,
            "own_height_agl_m": height,
        }
    )
    monkeypatch.setattr(clutter_anchors, "_SMOOTH_FRAMES", 1)
    got = [clutter_frames.frame_subspace(own, i, CFG) for i in range(n)]
    assert all(g is got[0] for g in got[:5]) and len(calls) == 3  # 4 % higher too
    assert got[5] is not got[0] and got[6] is not got[0]  # 7 % higher; climbing 1 m/s
    assert got[7] is got[0]  # back: the first anchor again, no new prediction


def test_measured_floor_is_the_median_of_the_ground_free_cells():
    from skyradar.process.clutter_suppress import _GAMMA_MEDIAN, measured_floor

    rng = np.random.default_rng(4)
    for n in (4000, 4001):  # even and odd counts
        raw = rng.gamma(4.0, 0.25, (n, 3)).astype(np.float32)
        predicted = np.zeros(raw.shape, bool)
        predicted[:, 1] = True
        expected = np.median(raw[:, [0, 2]]) / _GAMMA_MEDIAN[4]
        assert measured_floor(raw, predicted, 1.0) == expected
        assert measured_floor(raw, predicted, 1.0, free=np.flatnonzero(~predicted)) == expected
