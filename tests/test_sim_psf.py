"""The image simulator's window point-spread, speckle and Swerling against the raw ADC chain.

The peer is the chirp-level simulation (:mod:`skyradar.sim.raw`: beat signal from the exact
delays of every sample) through the windowed FFTs of ``process.rangedoppler``. Its pixels are
divided by the windows' coherent amplitude gain, the image simulator's pixel units.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal
from hypothesis import given, settings
from hypothesis import strategies as st

from skyradar.config import RadarConfig
from skyradar.process.rangedoppler import range_doppler
from skyradar.process.windows import get_window, window_gain_db
from skyradar.scene.synthetic_terrain import flat_terrain, fractal_terrain
from skyradar.sim.image import ImageSimulator, PlatformState, PointTarget
from skyradar.sim.psf import PSFKernels, _window, apply_psf, binned_kernel, psf_kernels, window_response
from skyradar.sim.raw import received_power_w, simulate_adc

ORIGIN = (52.0, 4.36, 0.0)
# A small radar (250 samples per chirp, 64 chirps, 15 m bins to 600 m, 0.62 m/s Doppler bins,
# ground Doppler aliased) keeps the raw chain cheap.
SMALL = {"fs_hz": 625e3, "prf_hz": 2.5e3, "n_doppler": 64, "range_limit_m": 600.0}


def _raw_scale(cfg: RadarConfig) -> float:
    return 10 ** (-window_gain_db("hann", "hann", cfg) / 20.0)  # raw pixel -> image pixel units


def test_sim_windows_are_the_processing_windows():
    for n in (250, 2032):
        np.testing.assert_array_equal(_window("hann", n), get_window("hann", n))


def test_point_target_gets_the_raw_chains_window_response():
    cfg = RadarConfig.prototype_2022(**SMALL)
    own = PlatformState(np.zeros(3), np.array([30.0, 0, 0]), np.zeros(3))
    # Fractional range (off-bin) and Doppler (a quarter bin off) position.
    v_target = 30.0 - 0.25 * cfg.doppler_resolution_mps + 11.3
    target = PointTarget(np.array([307.0, 0.0, 0.0]), np.array([v_target, 0.0, 0.0]))
    sim = ImageSimulator(cfg, noise=False, psf=True)
    image = sim.frame(own, [target])
    geom = sim.geometry(own)
    p_ant = geom.rot_ned_to_ant @ (target.position_ned_m - geom.origin_ned_m)
    v_ant = geom.rot_ned_to_ant @ (target.velocity_ned_mps - geom.velocity_ned_mps)
    adc = simulate_adc(cfg, p_ant[None], v_ant[None], 1.0, noise=False)
    raw = range_doppler(adc, cfg) * _raw_scale(cfg)
    k, j = np.unravel_index(np.abs(raw[..., 0]).argmax(), raw.shape[:2])
    patch = (slice(k - 3, k + 4), slice(j - 3, j + 4), 0)
    p_img, p_raw = np.abs(image[patch]) ** 2, np.abs(raw[patch]) ** 2
    peak = p_raw.max()
    # The same 7 x 7 response (main lobe, straddle loss, first sidelobes) to 3 % of the peak power.
    assert np.abs(10 * np.log10(p_img.max() / peak)) < 0.2
    np.testing.assert_allclose(p_img, p_raw, atol=0.03 * peak)
    # Without the point-spread the target is one pixel; the raw chain spreads it over several.
    plain = ImageSimulator(cfg, noise=False).frame(own, [target])
    assert np.count_nonzero(plain[patch]) == 1 and np.count_nonzero(p_raw > 0.01 * peak) >= 6


def _patch_facets(sim: ImageSimulator, own: PlatformState):
    """DEM-cell facets (flat earth, cosine reflectivity) as the simulator sees them at DEM spacing."""
    geom = sim.geometry(own)
    grid = sim.terrain.points_ned(*sim.origin, flat_earth=True) - geom.origin_ned_m
    centre = 0.25 * (grid[:-1, :-1] + grid[1:, :-1] + grid[:-1, 1:] + grid[1:, 1:]).reshape(-1, 3)
    e1 = (grid[1:, :-1] - grid[:-1, :-1] + grid[1:, 1:] - grid[:-1, 1:]).reshape(-1, 3) / 2
    e2 = (grid[:-1, 1:] - grid[:-1, :-1] + grid[1:, 1:] - grid[1:, :-1]).reshape(-1, 3) / 2
    normal = np.cross(e1, e2)
    normal[normal[:, 2] > 0] *= -1.0  # up is -down
    area = np.linalg.norm(normal, axis=1)
    cos_inc = np.clip(-np.einsum("ij,ij->i", normal, centre) / (area * np.linalg.norm(centre, axis=1)), 0, 1)
    p_ant = centre @ geom.rot_ned_to_ant.T
    v_ant = np.broadcast_to(geom.rot_ned_to_ant @ -geom.velocity_ned_mps, p_ant.shape)
    power = received_power_w(sim.config, p_ant, area * cos_inc)
    keep = power > 0
    return p_ant[keep], v_ant[keep], power[keep]


def _raw_expected_power(cfg: RadarConfig, p_ant, v_ant, power) -> np.ndarray:
    """Exact mean power per cell over random facet phases: the sum of each facet's own response power."""
    acc = np.zeros((cfg.n_range, cfg.n_doppler))
    for i in range(len(power)):
        adc = simulate_adc(cfg, p_ant[i : i + 1], v_ant[i : i + 1], power_w=power[i : i + 1], noise=False)
        acc += np.abs(range_doppler(adc, cfg, workers=1)[..., 0]) ** 2
    return acc * _raw_scale(cfg) ** 2


def _image_mean_power(sim: ImageSimulator, own: PlatformState, n_frames: int) -> np.ndarray:
    acc = np.zeros((sim.config.n_range, sim.config.n_doppler))
    for i in range(n_frames):
        acc += np.abs(sim.frame(own, frame_index=i)[..., 0]) ** 2
    return acc / n_frames


_RAW: dict[int, np.ndarray] = {}


def clutter_agreement_db(terrain, n_frames: int, psf: bool = True) -> tuple[float, int]:
    """Mean |dB difference| of the clutter-averaged power, image vs raw, over the clutter cells.

    Clutter cells: raw expected power within 30 dB of its peak. The image side averages
    ``n_frames`` speckle realisations; the raw side is exact (each facet's response power summed).
    """
    cfg = RadarConfig.prototype_2022(**SMALL)
    kwargs = {"facet_size_m": float("inf"), "occlusion": False, "flat_earth": True, "noise": False}
    sim = ImageSimulator(cfg, terrain, ORIGIN, psf=psf, speckle=True, **kwargs)
    if id(terrain) not in _RAW:  # the raw side does not depend on the image simulator's options
        _RAW[id(terrain)] = _raw_expected_power(cfg, *_patch_facets(sim, OWN))
    raw = _RAW[id(terrain)]
    image = _image_mean_power(sim, OWN, n_frames)
    cells = raw > raw.max() * 1e-3
    diff_db = 10 * np.log10(np.maximum(image[cells], 1e-300) / raw[cells])
    return float(np.mean(np.abs(diff_db))), int(cells.sum())


OWN = PlatformState(np.array([0.0, 0.0, -150.0]), np.array([35.0, 4.0, 0.0]), np.radians([0.0, -12, 0]))
PATCH = flat_terrain(52.0 + 325.0 / 111_250.0, 4.36, 0.0, size_m=150.0, spacing_m=7.5)  # 250-400 m ahead


def test_image_and_raw_clutter_agree_within_1db_per_cell_on_a_patch():
    # 7.5 m facets (half a range bin): 400 facets, about 80 clutter cells.
    mean_db, n_cells = clutter_agreement_db(PATCH, n_frames=300)
    assert n_cells > 50
    assert mean_db < 1.0, mean_db


def test_without_the_point_spread_the_clutter_does_not_agree():
    mean_db, _ = clutter_agreement_db(PATCH, n_frames=20, psf=False)
    assert mean_db > 3.0, mean_db


@pytest.mark.slow
def test_image_and_raw_clutter_agree_on_a_hilly_patch():
    north = 52.0 + 400.0 / 111_250.0
    hills = fractal_terrain(north, 4.36, 15.0, size_m=300.0, spacing_m=7.5, seed=2, cell_m=(150.0, 150.0))
    mean_db, n_cells = clutter_agreement_db(hills, n_frames=1000)
    assert n_cells > 200  # 234 clutter cells on this patch
    assert mean_db < 1.0, mean_db


def test_speckle_makes_terrain_pixels_exponential_and_new_each_frame():
    cfg = RadarConfig.prototype_2022(**SMALL)
    terrain = flat_terrain(52.0, 4.36, -200.0, size_m=1400.0, spacing_m=30.0)
    sim = ImageSimulator(cfg, terrain, ORIGIN, noise=False, speckle=True)
    own = PlatformState(np.zeros(3), np.array([40.0, 0, 0]), np.radians([0.0, -20.0, 0.0]))
    a, b = sim.frame(own, frame_index=1)[..., 0], sim.frame(own, frame_index=2)[..., 0]
    lit = np.abs(a) > 0
    assert lit.sum() > 500
    # Same geometry, new draw: the frames decorrelate; a pixel's power over pixels of one
    # frame (normalised by the mean over many frames) has the exponential law's SD/mean of 1.
    rho = np.abs(np.vdot(a[lit], b[lit])) / (np.linalg.norm(a[lit]) * np.linalg.norm(b[lit]))
    assert rho < 0.1
    mean = np.mean([np.abs(sim.frame(own, frame_index=i)[..., 0]) ** 2 for i in range(3, 43)], axis=0)
    ratio = np.abs(a[lit]) ** 2 / mean[lit]
    assert 0.8 < ratio.std() / ratio.mean() < 1.25
    # Reproducible: the same frame index gives the same frame.
    np.testing.assert_array_equal(sim.frame(own, frame_index=1)[..., 0], a)


def test_swerling1_target_power_is_exponential_and_defaults_keep_it_constant():
    cfg = RadarConfig.prototype_2022(**SMALL)
    own = PlatformState(np.zeros(3), np.array([30.0, 0, 0]), np.zeros(3))
    target = [PointTarget(np.array([300.0, 0, 0]), np.zeros(3))]
    sw = ImageSimulator(cfg, noise=False, swerling=1)
    powers = np.array([np.abs(sw.frame(own, target, frame_index=i)).max() ** 2 for i in range(400)])
    steady = np.abs(ImageSimulator(cfg, noise=False).frame(own, target)).max() ** 2
    assert powers.mean() / steady == pytest.approx(1.0, abs=0.15)
    assert np.median(powers) / steady == pytest.approx(np.log(2), abs=0.1)
    assert np.ptp(powers) > steady


def test_psf_noise_per_pixel_is_the_windows_enbw():
    cfg = RadarConfig.prototype_2022(**SMALL)
    sim = ImageSimulator(cfg, psf=True, seed=4)
    frame = sim.frame(PlatformState(np.zeros(3), np.zeros(3), np.zeros(3)))
    assert psf_kernels(cfg).oversample == 2
    assert sim.noise_per_pixel_w == pytest.approx(cfg.noise_power_w * 1.5 * 1.5, rel=1e-4)
    assert np.mean(np.abs(frame) ** 2) == pytest.approx(sim.noise_per_pixel_w, rel=0.03)


def test_bad_swerling_is_one_clear_error():
    from skyradar.errors import InputError

    with pytest.raises(InputError, match="simulation.swerling must be 0 or 1, got 2"):
        ImageSimulator(RadarConfig.prototype_2022(**SMALL), swerling=2)


@settings(max_examples=40, deadline=None)
@given(
    name=st.sampled_from(["hann", "hamming", "blackman", "boxcar"]),
    n=st.integers(8, 2048),
    offsets=st.lists(st.floats(-40.0, 40.0), min_size=1, max_size=8),
)
def test_closed_form_window_response_is_the_direct_sum(name, n, offsets):
    # The closed form (Dirichlet kernels) against the DTFT summed over scipy's own window samples,
    # integer offsets and multiples of n (the kernel's poles) included.
    u = np.r_[offsets, -3.0, 0.0, 1.0, float(n), -float(n), n / 2.0]
    w = scipy.signal.get_window(name, n, fftbins=True)
    direct = np.exp(-2j * np.pi * np.outer(u, np.arange(n) - n / 2.0) / n) @ w / w.sum()
    np.testing.assert_allclose(window_response(name, n, u), direct, atol=1e-9)


@pytest.mark.parametrize("n_blocks", [1, 2])
def test_apply_psf_is_the_separable_convolution_whatever_the_scratch_holds(n_blocks):
    # The compiled point-spread (four taps per pass, circular Doppler, range cut at the cube's
    # edges) against the definition summed with numpy; scratch full of NaN must not leak in.
    from skyradar.sim.psf import PSFKernels, apply_psf, binned_kernel

    kernels = PSFKernels(binned_kernel("hann", 64, 2), binned_kernel("hann", 32, 2), 2)
    n_r, n_d, n_rx = 20, 16, 3
    rng = np.random.default_rng(5)
    fine = (rng.standard_normal((n_blocks, 2 * n_r, 2 * n_d, n_rx, 2)) @ [1, 1j]).astype(np.complex64)
    fine[:, :7] = 0  # empty rows (the ground below the nadir range)
    fine[:, 21] = 0
    total = fine.sum(axis=0).astype(complex)
    h_r, h_d = kernels.h_range.astype(float), kernels.h_doppler.astype(float)
    sr, sd = len(h_r) // 2, len(h_d) // 2
    expected = np.zeros((n_r, n_d, n_rx), complex)
    for k in range(n_r):
        for j in range(n_d):
            for s_r in range(-sr, sr + 1):
                m = 2 * k - s_r
                if 0 <= m < 2 * n_r:
                    lags = (2 * j - np.arange(-sd, sd + 1)) % (2 * n_d)
                    expected[k, j] += h_r[s_r + sr] * (h_d[:, None] * total[m, lags]).sum(axis=0)
    out = np.full((n_r, n_d, n_rx), np.nan, np.complex64)
    scratch = np.full(2 * n_r * n_d * n_rx, np.nan, np.complex64)
    apply_psf(fine, kernels, out, scratch, clear=True)
    np.testing.assert_allclose(out, expected, rtol=0, atol=1e-5 * np.abs(expected).max())
    assert not fine.any()  # cleared for the next frame


def test_point_spread_of_blocks_is_that_of_their_sum_and_clears_them():
    # Per-thread blocks are summed on the way (and cleared); a direct 2-D convolution is the truth.
    rng = np.random.default_rng(4)
    k = PSFKernels(binned_kernel("hann", 64, 2), binned_kernel("hann", 32, 2), 2)
    blocks = np.zeros((2, 40, 64, 3), np.complex64)
    blocks[:, 10:30] = rng.normal(size=(2, 20, 64, 3)) + 1j * rng.normal(size=(2, 20, 64, 3))
    total = blocks.sum(axis=0)
    out = np.empty((20, 32, 3), np.complex64)
    apply_psf(blocks, k, out, np.empty(40 * 32 * 3, np.complex64), clear=True)
    assert not blocks.any()
    # out[r, d] = sum over fine (m, l) of total[m, l] h_r[2 r - m] h_d[2 d - l], Doppler circular.
    h_r, h_d = k.h_range.astype(float), k.h_doppler.astype(float)
    sr, sd = len(h_r) // 2, len(h_d) // 2
    expected = np.zeros(out.shape, complex)
    for r in range(20):
        for m in range(max(0, 2 * r - sr), min(40, 2 * r + sr + 1)):
            row = total[m].astype(complex)
            for d in range(32):
                lags = 2 * d - np.arange(64)
                lags = (lags + 32) % 64 - 32  # circular: the nearest image of each fine bin
                w = np.where(np.abs(lags) <= sd, h_d[np.clip(lags + sd, 0, 2 * sd)], 0.0)
                expected[r, d] += h_r[2 * r - m + sr] * (w @ row)
    np.testing.assert_allclose(out, expected, rtol=0, atol=1e-5 * np.abs(expected).max())
