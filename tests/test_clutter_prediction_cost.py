"""The cheap clutter prediction: packed sums, compiled Jacobi, lazy cells, fewer predictions.

Checked against the straightforward computation (every tap's outer product summed with numpy,
``numpy.linalg.eigh``), and for the reuse of a prediction under navigation noise and in a turn.
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import replace

import numpy as np

from skyradar.config import RadarConfig
from skyradar.geo import rotation_matrix
from skyradar.io.ownship_states import OwnShipStates
from skyradar.process import clutter_frames
from skyradar.process.clutter import clutter_subspace, hermitian_eigh
from skyradar.process.doa import steering_vector

CFG = RadarConfig.prototype_2022()


def _reference(velocity: np.ndarray, ant_to_ned: np.ndarray, height_m: float, n_azimuth: int):
    """The predicted covariance with every (sample, tap) outer product added by numpy, then eigh."""
    # Flat ground: every range bin's ring beyond the height, depression asin(h / R), all azimuths.
    rng = CFG.range_axis_m[CFG.range_axis_m > height_m]
    r_grid, phi = np.meshgrid(rng, np.linspace(-np.pi, np.pi, n_azimuth, endpoint=False), indexing="ij")
    down = height_m / r_grid.ravel()
    horizontal = np.sqrt(1.0 - down**2)
    u_ned = np.stack([horizontal * np.cos(phi.ravel()), horizontal * np.sin(phi.ravel()), down], axis=1)
    slant = r_grid.ravel()
    radial = -(u_ned @ velocity)
    r_pos = (slant + radial * CFG.range_doppler_coupling_s) / CFG.range_resolution_m
    d_pos = radial / CFG.doppler_resolution_mps + CFG.n_doppler // 2
    u_ant = u_ned @ ant_to_ned
    az, el = np.arctan2(u_ant[:, 1], u_ant[:, 0]), np.arcsin(-u_ant[:, 2])
    weight = 10.0 ** (2.0 * CFG.antenna.gain_db(az, el) / 10.0) * u_ned[:, 2]
    steer = steering_vector(u_ant, CFG)
    outer = steer[:, :, None] * np.conj(steer[:, None, :])
    cov = np.zeros((CFG.n_range, CFG.n_doppler, CFG.n_rx, CFG.n_rx), complex)

    def lobe(x: np.ndarray) -> np.ndarray:  # Hann main lobe, sinc(x) / (1 - x^2), 0.5 at one bin
        with np.errstate(all="ignore"):
            return np.where(np.isclose(np.abs(x), 1.0), 0.5, np.sinc(x) / (1.0 - x * x))

    for dr in (-1, 0, 1):
        r = np.floor(r_pos + 0.5).astype(int) + dr
        for dd in range(-2, 3):
            d = np.floor(d_pos + 0.5).astype(int) + dd
            w = weight * (lobe(r_pos - r) * lobe(d_pos - d)) ** 2
            ok = (r >= 0) & (r < CFG.n_range) & (w > 0)
            np.add.at(cov, (r[ok], d[ok] % CFG.n_doppler), w[ok, None, None] * outer[ok])
    total = np.einsum("rdii->rd", cov).real
    predicted = total > 0
    lam, vec = np.linalg.eigh(cov[predicted] / total[predicted, None, None])
    return predicted, lam[:, ::-1], vec[..., ::-1]


def _projector(vectors: np.ndarray, k: int) -> np.ndarray:
    e = vectors[..., :k]
    return np.einsum("nik,njk->nij", e, np.conj(e))


def test_prediction_matches_the_straightforward_covariance_and_eigh():
    v = np.array([58.0, 2.0, 1.0])
    ant_to_ned = rotation_matrix(0.0, np.radians(3.0), np.radians(20.0)) @ CFG.mount.rotation
    predicted, lam, vec = _reference(v, ant_to_ned, 545.0, 120)
    sub = clutter_subspace(CFG, v, ant_to_ned, 545.0, n_azimuth=120)
    np.testing.assert_array_equal(sub.predicted, predicted)
    np.testing.assert_allclose(sub.fractions[predicted], np.clip(lam, 0, None), atol=2e-6)
    for k in (1, 2):  # the nulled subspaces, where their eigenvalue gap defines them
        gap = (lam[:, k - 1] - lam[:, k]) > 1e-3
        got = _projector(sub.vectors[predicted][gap].astype(complex), k)
        assert np.abs(got - _projector(vec[gap], k)).max() < 1e-4
    assert np.all(sub.vectors[~predicted] == np.eye(CFG.n_rx))


def test_cells_decomposed_on_demand_equal_the_whole_decomposition():
    # Each cell's rotations start from the last decomposed cell's basis, so the order of the cells
    # changes the eigenvectors' phases and the last bits, not the eigenvalues or the nulled spaces.
    v, rot = np.array([50.0, 0.0, 0.0]), CFG.mount.rotation
    lazy = clutter_subspace(CFG, v, rot, 1000.0, n_azimuth=180)
    rows, cols = np.array([200, 201, 5, 120]), np.array([30, 31, 125, 100])
    part = lazy.cell_vectors(rows, cols).astype(complex)
    assert lazy.done.sum() == 4
    whole = clutter_subspace(CFG, v, rot, 1000.0, n_azimuth=180)
    np.testing.assert_allclose(lazy.fractions, whole.fractions, atol=1e-6)
    assert np.all(lazy.vectors[5, 125] == np.eye(CFG.n_rx))  # nearer than the ground: identity
    ours, ref = whole.vectors[rows, cols].astype(complex), lazy.vectors.astype(complex)
    for k in (1, 2):
        gap = (whole.fractions[..., k - 1] - whole.fractions[..., k]) > 1e-3
        assert np.abs(_projector(part, k) - _projector(ours, k))[gap[rows, cols]].max() < 1e-5
        assert (
            np.abs(_projector(ref[gap], k) - _projector(whole.vectors[gap].astype(complex), k)).max() < 1e-4
        )


def test_jacobi_eigen_pairs_of_small_hermitian_matrices():
    rng = np.random.default_rng(3)
    for n, kind in [(4, "full"), (4, "rank1"), (4, "diagonal"), (4, "repeated"), (3, "full"), (6, "full")]:
        x = rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n))
        if kind == "full":
            a = x @ x.conj().T
        elif kind == "rank1":
            a = np.outer(x[0], x[0].conj())
        elif kind == "diagonal":
            a = np.diag([3.0, 1.0, 2.0, 0.5])
        else:  # two repeated eigenvalues
            a = np.eye(n) + np.outer(x[0], x[0].conj())
        work, v = a.astype(complex).copy(), np.empty((n, n), complex)
        lam, order = np.empty(n), np.empty(n, np.int64)
        hermitian_eigh(work, v, lam, order)
        np.testing.assert_allclose(lam[order], np.linalg.eigvalsh(a)[::-1], atol=1e-9 * np.abs(a).max())
        np.testing.assert_allclose(v @ np.diag(lam) @ v.conj().T, a, atol=1e-9 * np.abs(a).max())
        np.testing.assert_allclose(v.conj().T @ v, np.eye(n), atol=1e-12)


def _turning_own(n: int, bank_deg: float, noise_mps: float) -> OwnShipStates:
    """Own-ship frames at 9.4 Hz, 60 m/s, in a coordinated turn at ``bank_deg`` (0: straight)."""
    rng = np.random.default_rng(0)
    t = np.arange(n) / 9.4
    rate = 9.81 * np.tan(np.radians(bank_deg)) / 60.0
    yaw = 0.2 + rate * t
    own = {
        "own_vn_mps": 60 * np.cos(yaw),
        "own_ve_mps": 60 * np.sin(yaw),
        "own_vd_mps": noise_mps * rng.standard_normal(n),
        "own_yaw_rad": yaw,
        "own_pitch_rad": np.zeros(n),
        "own_roll_rad": np.full(n, np.radians(bank_deg)),
    }
    own["own_vn_mps"] = own["own_vn_mps"] + noise_mps * rng.standard_normal(n)
    position = {"own_north_m": np.zeros(n), "own_east_m": np.zeros(n), "own_down_m": np.full(n, -600.0)}
    return OwnShipStates.from_columns(own | position | {"time_s": t, "own_height_agl_m": np.full(n, 600.0)})


def _predictions(own: OwnShipStates, monkeypatch) -> list:
    calls = []
    monkeypatch.setattr(clutter_frames, "clutter_subspace", lambda *a, **k: calls.append(a) or object())
    monkeypatch.setattr(clutter_frames, "_CACHE", OrderedDict())
    for i in range(len(own)):
        clutter_frames.frame_subspace(own, i, CFG)
    return calls


def test_navigation_noise_and_a_banked_turn_do_not_force_new_predictions(monkeypatch):
    # GNSS velocity noise (0.2 m/s white per frame) alone crosses the 0.35 m/s reuse tolerance on
    # many frames; the 5-frame mean keeps 100 frames on one or two predictions, in level flight and
    # in a steady 35 deg banked turn (the velocity in the heading-free frame is constant there).
    assert len(_predictions(_turning_own(100, 0.0, 0.2), monkeypatch)) <= 2
    assert len(_predictions(_turning_own(100, 35.0, 0.2), monkeypatch)) <= 2
    # A real change is followed within the 5 frames: a climb of 1 m/s from frame 50 on.
    own = replace(_turning_own(100, 0.0, 0.0), vd_mps=np.where(np.arange(100) >= 50, -1.0, 0.0))
    calls = _predictions(own, monkeypatch)
    assert 2 <= len(calls) <= 3 and calls[-1][1][2] == -1.0


def test_a_config_read_again_for_each_block_reuses_the_prediction(monkeypatch):
    # A run processed in blocks reads its stored config once per block: equal content, a new object.
    # The prediction depends on the content only, so the blocks share it: one prediction, not one
    # per block.
    calls = []
    monkeypatch.setattr(clutter_frames, "clutter_subspace", lambda *a, **k: calls.append(a) or object())
    monkeypatch.setattr(clutter_frames, "_CACHE", OrderedDict())
    own = _turning_own(32, 0.0, 0.0)
    for block in range(4):
        config = RadarConfig.from_json(CFG.to_json())
        for i in range(8 * block, 8 * block + 8):
            clutter_frames.frame_subspace(own, i, config)
    assert len(calls) == 1
    # A config that differs (another calibration) gets its own prediction.
    other = RadarConfig.from_dict(CFG.to_dict() | {"rx_calibration": [[1.0, 0.1]] * CFG.n_rx})
    clutter_frames.frame_subspace(own, 0, other)
    assert len(calls) == 2 and calls[-1][0] is other
