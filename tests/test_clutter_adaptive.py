"""Adaptive post-Doppler nulls where the clutter prediction fails (over relief)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from skyradar.config import RadarConfig
from skyradar.process.clutter_adaptive import (
    ADAPTIVE_WINDOW,
    _packed_sat,
    _ring_matrix,
    _sat_row,
    adaptive_nulls,
)
from skyradar.process.clutter_frames import detect_suppressed, frame_subspace
from skyradar.process.clutter_suppress import suppress_clutter
from skyradar.process.doa import direction_from_angles, steering_vector
from skyradar.process.top_eigen import top_eigenpairs, top_two_eigenpairs

CFG = RadarConfig.prototype_2022()
ONES = np.ones(4, np.complex64)


def _gauss(rng, *shape):
    return (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)) / np.sqrt(2)


def _steer(az_deg, el_deg):
    return steering_vector(direction_from_angles(np.radians(az_deg), np.radians(el_deg)), CFG)


def _clutter(rng, shape, directions, cnr):
    """Rank-len(directions) clutter: independent complex amplitudes per cell on fixed directions."""
    cube = np.zeros(shape, complex)
    for s in directions:
        cube += np.sqrt(cnr)[..., None] * _gauss(rng, *shape[:2])[..., None] * s
    return cube


def _reference(cube, cnr, floor, power0, window=ADAPTIVE_WINDOW, gate=3.0, max_nulls=2):
    """The rule written out cell by cell: numpy eigh of the ring's sample covariance, explicit projector."""
    hr, hd, gr, gd = window
    n_r, n_d, k = cube.shape
    power, nulls = power0.astype(float), np.zeros((n_r, n_d), int)
    mask, unsup = np.zeros((n_r, n_d), bool), np.zeros((n_r, n_d), bool)
    for r in range(n_r):
        for d in range(n_d):
            ring = [
                (rr, (d + o) % n_d)
                for rr in range(max(r - hr, 0), min(r + hr + 1, n_r))
                for o in range(-hd, hd + 1)
                if not (abs(rr - r) <= gr and abs(o) <= gd)
            ]
            rr, dd = np.array(ring).T
            if (
                len(ring) < 16
                or not cnr[r, d] > gate
                or np.minimum(power0[rr, dd], 8 * floor).mean() <= 2 * floor
            ):
                continue
            z = cube[rr, dd]
            lam, e = np.linalg.eigh(z.T @ z.conj() / len(ring) / floor)
            lam, e = lam[::-1], e[:, ::-1]
            m = int(np.sum(lam[:max_nulls] > 2.0))
            kept = lam[m:].sum()
            if m == 0 or kept / (k - m) >= power0[rr, dd].mean() / floor:
                continue
            proj = np.eye(k) - e[:, :m] @ e[:, :m].conj().T
            power[r, d] = np.linalg.norm(proj @ cube[r, d]) ** 2 / (k - m)
            nulls[r, d], mask[r, d], unsup[r, d] = m, True, (kept - (k - m)) / k > 1
    return power, nulls, mask, unsup


def test_adaptive_nulls_match_numpy_eigh_of_the_ring_covariance():
    rng = np.random.default_rng(4)
    shape = (36, 30, 4)
    cnr = np.where(np.arange(30) < 18, 10 ** rng.uniform(0.5, 4.0, shape[:2]), 0.0)  # a clutter region
    cube = (_gauss(rng, *shape) + _clutter(rng, shape, [_steer(-35, 5), _steer(40, -3)], cnr / 2)).astype(
        np.complex64
    )
    raw = (np.abs(cube) ** 2).mean(axis=2).astype(np.float32)
    power, nulls, unsup = raw.copy(), np.zeros(shape[:2], np.int8), np.zeros(shape[:2], bool)
    level = np.maximum(raw - 1.0, 0.0)
    mask, vectors = adaptive_nulls(cube, ONES, level, 1.0, power, nulls, unsup)
    ref_power, ref_nulls, ref_mask, ref_unsup = _reference(cube.astype(complex), level, 1.0, raw)
    assert 0.2 < mask.mean() < 0.8  # some cells adaptive, some not
    np.testing.assert_array_equal(mask, ref_mask)
    np.testing.assert_array_equal(nulls, ref_nulls)
    np.testing.assert_array_equal(unsup, ref_unsup)
    # float32 snapshots under up to 40 dB of clutter, eigenvectors converged to 1e-4 of the noise (a
    # cell whose two strongest eigenvalues nearly tie converges slower): far below the noise
    diff = np.abs(power - ref_power)
    assert np.quantile(diff, 0.99) < 1e-3 and diff.max() < 0.1


def test_rolling_summed_area_table_gives_the_whole_table_ring_covariances_exactly():
    # The adaptive step holds 2 hr + 2 rows of the table, built as the candidates' range grows; each
    # ring covariance from it equals the whole table's bit for bit, at the range edges too.
    rng = np.random.default_rng(9)
    cube = (_gauss(rng, 30, 24, 4) * 10 ** rng.uniform(0, 2, (30, 24, 1))).astype(np.complex64)
    inv_gain = np.exp(1j * rng.uniform(0, 6.3, 4)).astype(np.complex64)
    hr, hd = ADAPTIVE_WINDOW[:2]
    whole = _packed_sat(cube, inv_gain, hd)
    rows = 2 * hr + 2
    rolling = np.zeros((rows, *whole.shape[1:]))
    row, z = np.zeros(whole.shape[1:]), np.empty(4, complex)
    a, b = np.empty((4, 4), complex), np.empty((4, 4), complex)
    built = 0
    for r in range(30):
        while built < min(r + hr + 1, 30):
            _sat_row(cube, inv_gain, hd, built, rolling[built % rows], rolling[(built + 1) % rows], row, z)
            built += 1
        for d in range(24):
            assert _ring_matrix(rolling, r, d, ADAPTIVE_WINDOW, 30, a, rows, 0.5) == _ring_matrix(
                whole, r, d, ADAPTIVE_WINDOW, 30, b, 31, 0.5
            )
            np.testing.assert_array_equal(a, b)
    # and the whole table's covariance is the ring's sample covariance
    ring = [(rr, dd % 24) for rr in range(0, 6) for dd in range(-5, 6) if not (rr <= 2 and abs(dd) <= 2)]
    x = cube[tuple(np.array(ring).T)].astype(complex) * inv_gain.astype(complex)
    _ring_matrix(whole, 0, 0, ADAPTIVE_WINDOW, 30, b, 31, 0.5)
    np.testing.assert_allclose(b, 0.5 * x.T @ x.conj() / len(ring), rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("solver", [top_eigenpairs, top_two_eigenpairs])
def test_subspace_iteration_finds_the_strongest_pairs_from_any_start(solver):
    rng = np.random.default_rng(0)
    for _ in range(200):
        q, _ = np.linalg.qr(_gauss(rng, 4, 4))
        lam_true = np.sort(10 ** rng.uniform(-0.5, 5.0, 4))[::-1]
        a = (q * lam_true) @ q.conj().T
        v, lam = np.linalg.qr(_gauss(rng, 4, 2))[0], np.empty(2)
        solver(a, v, lam, 2.0)
        m = int(np.sum(lam_true[:2] > 2.0))
        np.testing.assert_allclose(lam[:m], lam_true[:m], rtol=1e-3)
        # nulling the pairs found leaves what nulling the true ones leaves (a in noise units: to 5 % of
        # the noise, or 1e-3 of what is left when strong eigenvalues are nearly equal)
        left = np.trace(a - v[:, :m] @ (v[:, :m].conj().T @ a)).real
        assert left - lam_true[m:].sum() < 0.05 + 1e-3 * lam_true[m:].sum()


def test_two_pair_solver_agrees_with_numpy_eigh_on_ring_covariances_warm_started():
    # Sample covariances of 96 snapshots with one to three clutter directions 5-45 dB over the
    # noise, each solve warm-started from the previous one's pairs as the adaptive step does.
    rng = np.random.default_rng(7)
    v, lam = np.eye(4, 2).astype(complex), np.empty(2)
    for _ in range(300):
        x = _gauss(rng, 4, 96)
        for _ in range(int(rng.integers(1, 4))):
            amplitude = 10 ** rng.uniform(0.25, 2.25)
            x += amplitude * _steer(rng.uniform(-60, 60), rng.uniform(-20, 5))[:, None] * _gauss(rng, 96)
        a = x @ x.conj().T / 96
        lam_true, e_true = np.linalg.eigh(a)
        lam_true, e_true = lam_true[::-1], e_true[:, ::-1]
        top_two_eigenpairs(a, v, lam, 2.0)
        m = int(np.sum(lam_true[:2] > 2.0))
        # converged to a squared residual of 1e-4 of the eigenvalue: the eigenvalues to that
        np.testing.assert_allclose(lam[:m], lam_true[:m], rtol=1e-4)
        # nulling the pairs found leaves what nulling the true ones leaves, to 1e-3 of the noise
        left = np.trace(a - v[:, :m] @ (v[:, :m].conj().T @ a)).real
        assert abs(left - lam_true[m:].sum()) < 1e-3 + 1e-6 * lam_true.sum()


@pytest.fixture(scope="module")
def flat_prediction():
    from skyradar.io.ownship_states import OwnShipStates

    one = np.ones(1)
    own = OwnShipStates.from_columns(
        {
            "time_s": 0 * one,
            "own_north_m": 0 * one,
            "own_east_m": 0 * one,
            "own_down_m": -1000 * one,
            "own_vn_mps": 50 * one,
            "own_ve_mps": 0 * one,
            "own_vd_mps": 0 * one,
            "own_yaw_rad": 0 * one,
            "own_height_agl_m": 1000 * one,
        }
    )
    return frame_subspace(own, 0, CFG)


def _hits(cube, sub, adaptive, pixel):
    out = suppress_clutter(cube, sub, CFG, adaptive=adaptive)
    det = out.detections(CFG)
    found = np.any((det.range_index == pixel[0]) & (det.doppler_index == pixel[1]))
    return out, bool(found), len(det)


def test_target_in_clutter_the_prediction_misses_is_found_only_with_adaptive_nulls(flat_prediction):
    rng = np.random.default_rng(7)
    shape = (CFG.n_range, CFG.n_doppler, CFG.n_rx)
    noise_w = CFG.noise_power_w
    cnr = np.zeros(shape[:2])
    cnr[120:200, 150:230] = 10**4  # 40 dB from above the horizon and beside the track: not flat ground
    clutter = _clutter(rng, shape, [_steer(-30, 12), _steer(25, 15)], cnr / 2) * np.sqrt(noise_w)
    cube = _gauss(rng, *shape) * np.sqrt(noise_w) + clutter
    pixel = (160, 190)
    cube[pixel] += np.sqrt(10**2.5 * noise_w) * _steer(0, 0) * np.exp(1j * rng.uniform(0, 6.3))  # 25 dB
    cube = cube.astype(np.complex64)
    out, found, n = _hits(cube, flat_prediction, True, pixel)
    _, found_plain, _ = _hits(cube, flat_prediction, False, pixel)
    assert found and not found_plain
    assert out.adaptive[120:200, 150:230].mean() > 0.9 and out.nulls[pixel] == 2
    assert n <= 3  # no false alarms from the clutter
    # the direction comes through the adaptive projector
    vectors = out.cell_vectors(flat_prediction, np.array([pixel[0]]), np.array([pixel[1]]))
    e = vectors[0][:, :2]
    assert np.linalg.norm(e.conj().T @ _steer(-30, 12)) > 0.99 * np.linalg.norm(_steer(-30, 12))
    # its direction through the ring's whitening: the target's (25 dB, 2 of 4 dimensions nulled), not
    # the clutter's (25-30 deg away)
    found = detect_suppressed(cube, CFG, flat_prediction)
    det, u, coherence = found.detections, found.directions.u_ant, found.directions.coherence
    k = np.flatnonzero((det.range_index == pixel[0]) & (det.doppler_index == pixel[1]))[0]
    assert np.degrees(np.arccos(u[k] @ direction_from_angles(0.0, 0.0))) < 10.0 and coherence[k] > 0.9


def test_one_unpredicted_clutter_plane_wave_is_not_taken_for_the_target(flat_prediction):
    rng = np.random.default_rng(8)
    shape = (CFG.n_range, CFG.n_doppler, CFG.n_rx)
    noise_w = CFG.noise_power_w
    cnr = np.zeros(shape[:2])
    cnr[120:200, 150:230] = 10**4  # one direction, 40 dB: the raw snapshot is one plane wave
    cube = _gauss(rng, *shape) * np.sqrt(noise_w) + _clutter(rng, shape, [_steer(-20, -25)], cnr) * np.sqrt(
        noise_w
    )
    pixel = (160, 190)
    cube[pixel] += np.sqrt(10**2.5 * noise_w) * _steer(5, 0) * np.exp(1j * rng.uniform(0, 6.3))  # 25 dB
    found = detect_suppressed(cube.astype(np.complex64), CFG, flat_prediction)
    det, u = found.detections, found.directions.u_ant
    k = np.flatnonzero((det.range_index == pixel[0]) & (det.doppler_index == pixel[1]))[0]
    assert np.degrees(np.arccos(u[k] @ direction_from_angles(np.radians(5.0), 0.0))) < 10.0


def _lobe(rng, shape, pixel, snr, direction):
    """A point target spread over its Hann main lobe (+-1 range bin, +-2 Doppler bins, straddled)."""
    cube = np.zeros(shape, complex)
    phase = np.exp(1j * rng.uniform(0, 6.3))
    for dr, wr in ((-1, 0.5), (0, 1.0), (1, 0.5)):
        for dd, wd in ((-2, 0.17), (-1, 0.85), (0, 0.85), (1, 0.17), (2, 0.05)):
            cube[pixel[0] + dr, pixel[1] + dd] = np.sqrt(snr) * wr * wd * phase * direction
    return cube


@pytest.mark.parametrize("window, kept", [(ADAPTIVE_WINDOW, True), ((5, 5, 0, 0), False)])
def test_a_target_is_not_nulled_by_its_own_training_with_the_guard(window, kept):
    rng = np.random.default_rng(3)
    shape = (40, 40, 4)
    s_t, s_c = _steer(5, 0), _steer(-40, -10)
    cube = _gauss(rng, *shape) + _clutter(rng, shape, [s_c], np.full(shape[:2], 1000.0))
    cube += _lobe(rng, shape, (20, 20), 10**3, s_t)  # 30 dB
    cube = cube.astype(np.complex64)
    raw = (np.abs(cube) ** 2).mean(axis=2).astype(np.float32)
    power, nulls, unsup = raw.copy(), np.zeros(shape[:2], np.int8), np.zeros(shape[:2], bool)
    adaptive_nulls(cube, ONES, np.full(shape[:2], 1000.0), 1.0, power, nulls, unsup, window=window)
    e = s_c / np.linalg.norm(s_c)
    expected = 10**3 * 0.85**2 * np.linalg.norm(s_t - e * np.vdot(e, s_t)) ** 2 / (4 - nulls[20, 20])
    assert (10 * np.log10(power[20, 20] / expected) > -1.0) == kept


def test_noise_stays_at_the_floor_with_the_gamma_law_after_adaptive_nulls():
    rng = np.random.default_rng(5)
    shape = (60, 64, 4)
    cube = _gauss(rng, *shape) + _clutter(
        rng, shape, [_steer(-20, -5), _steer(30, -8)], np.full(shape[:2], 3e3)
    )
    cube = cube.astype(np.complex64)
    raw = (np.abs(cube) ** 2).mean(axis=2).astype(np.float32)
    power, nulls, unsup = raw.copy(), np.zeros(shape[:2], np.int8), np.zeros(shape[:2], bool)
    mask, _ = adaptive_nulls(cube, ONES, np.full(shape[:2], 3e3), 1.0, power, nulls, unsup)
    two = mask & (nulls == 2)
    assert two.mean() > 0.95
    # the cell under test is not in its training: |P z|^2 / L of noise is Gamma(2, 1/2), mean 1 (plus
    # the clutter a 96-sample estimate leaves, about 2 x L / 96 of the noise)
    assert abs(power[two].mean() - 1.0) < 0.05  # + 2 nulls x L / 96 samples
    assert stats.kstest(power[two][::3], stats.gamma(2, scale=0.5).cdf).pvalue > 1e-3


def test_clear_sky_with_a_strong_target_is_bit_identical(flat_prediction):
    rng = np.random.default_rng(11)
    shape = (CFG.n_range, CFG.n_doppler, CFG.n_rx)
    cube = _gauss(rng, *shape) * np.sqrt(CFG.noise_power_w)
    cube += _lobe(rng, shape, (150, 60), 10**4 * CFG.noise_power_w, _steer(3, 1))  # 40 dB
    cube = cube.astype(np.complex64)
    on, found_on, _ = _hits(cube, flat_prediction, True, (150, 60))
    off, found_off, _ = _hits(cube, flat_prediction, False, (150, 60))
    assert found_on and found_off and not on.adaptive.any()
    for name in ("power", "nulls", "unsuppressed", "channels"):
        np.testing.assert_array_equal(getattr(on, name), getattr(off, name))


@pytest.mark.slow
def test_relief_benchmark_agrees_with_its_numpy_baseline():
    from skyradar.benchmarks.process_adaptive import run_adaptive

    result = run_adaptive(n_cubes=1)
    assert result["relief_adaptive_cells_per_frame"] > 1000  # the flat prediction misses the hills
    assert result["relief_adaptive_same_nulls"] > 0.999
    for n_rx in (6, 8):  # the compiled step on six and eight channels against eigh
        assert result[f"relief_rx{n_rx}_adaptive_cells_per_frame"] > 1000
        assert result[f"relief_rx{n_rx}_adaptive_same_nulls"] > 0.999
