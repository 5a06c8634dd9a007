"""GPS check (ch6): SSIM against scikit-image, decoy test, pose search, layover, monitor verdicts."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.ndimage import binary_erosion, gaussian_filter
from skimage.metrics import structural_similarity
from skimage.registration import phase_cross_correlation

from skyradar.config import Mount, RadarConfig
from skyradar.errors import InputError
from skyradar.nav.gpscheck.check import correct_layover, radar_side
from skyradar.nav.gpscheck.compare import decoy_test, ssim_scores
from skyradar.nav.gpscheck.monitor import (
    CONSISTENT,
    INCONSISTENT,
    LOW_STRUCTURE,
    WING_UP,
    MonitorSettings,
    alerts,
    frame_verdict,
)
from skyradar.nav.gpscheck.preprocess import METHODS, preprocess
from skyradar.nav.gpscheck.search import PoseOffset, _template, ncc_surface, search_offset
from skyradar.scene.ground_grid import GroundGrid, PoseGrid, sample_at_pose


@pytest.fixture(scope="module")
def city():
    """A 1.2 x 1.2 km synthetic city on 4 m pixels: blocks and streets, smoothed a little."""
    rng = np.random.default_rng(3)
    grid = GroundGrid(0.0, 0.0, 4.0, (300, 300))
    image = np.full(grid.shape, 0.6)
    for _ in range(400):
        r, c = rng.integers(0, 300, 2)
        h, w = rng.integers(3, 12, 2)
        image[r : r + h, c : c + w] = rng.uniform(0.0, 0.4)
    for pos in np.cumsum(rng.integers(12, 30, 20)):
        if pos < 298:
            image[pos : pos + 2, :] = 1.0
            image[:, pos : pos + 2] = 1.0
    return grid, gaussian_filter(image, 0.7).astype(np.float32)


def _radar_of(world, grid, body, pose, rng):
    """The map at ``pose`` as a radar would distort it: contrast curve, speckle, a half-disc footprint."""
    clean = sample_at_pose(world, grid, body, *pose, fill=0.0)
    forward, right = np.meshgrid(body.forward_m, body.right_m, indexing="ij")
    mask = (np.hypot(forward, right) < 190.0) & (np.hypot(forward, right) > 40.0)
    power = (0.05 + clean**2) * rng.exponential(1.0, clean.shape)
    return np.where(mask, power, np.nan), mask


def test_ssim_scores_match_scikit_image_over_the_footprint():
    rng = np.random.default_rng(0)
    ref = rng.random((40, 30))
    cand = np.stack([0.6 * ref + 0.4 * rng.random((40, 30)) for _ in range(3)])
    mask = np.ones(ref.shape, bool)
    mask[:8] = False
    inner = binary_erosion(mask, np.ones((7, 7), bool), border_value=0)
    for k in range(3):
        _, full = structural_similarity(ref, cand[k], data_range=1.0, full=True)
        assert ssim_scores(ref, cand, mask)[k] == pytest.approx(full[inner].mean(), abs=1e-6)


@pytest.mark.parametrize("method", METHODS)
def test_preprocess_is_unit_range_and_zero_outside_the_mask(method):
    rng = np.random.default_rng(1)
    image = rng.exponential(1.0, (40, 40))
    mask = np.zeros(image.shape, bool)
    mask[5:35, 5:35] = True
    out = preprocess(image, method, mask, log_power=True, despeckle_px=3)
    assert out.dtype == np.float32 and out.min() >= 0.0 and out.max() <= 1.0
    assert not out[~mask].any() and out[mask].std() > 0


def test_unknown_method_is_one_line():
    with pytest.raises(InputError, match="--method"):
        preprocess(np.ones((8, 8)), "sobel")


def test_ssim_ranking_picks_the_true_pose_among_300_decoys(city):
    grid, world = city
    body = PoseGrid.side_looking(range_m=200.0, pixel_m=4.0)
    truth = np.array([600.0, 500.0, 0.4])
    power, mask = _radar_of(world, grid, body, truth, np.random.default_rng(2))
    radar = preprocess(power, "clahe_ridge", mask, log_power=True, despeckle_px=3)
    result = decoy_test(
        radar, mask, preprocess(world, "clahe_ridge"), grid, body, truth, np.random.default_rng(4)
    )
    assert result.correct() and result.position_error_m == 0.0
    assert result.false_positive_fraction <= 0.01


def test_ncc_surface_finds_the_shift_scikit_image_finds():
    rng = np.random.default_rng(5)
    patch = gaussian_filter(rng.random((60, 50)), 1.5)
    mask = np.ones((30, 20), bool)
    mask[:5, :5] = False
    template, n = _template(patch[12:42, 9:29], mask)
    surface = ncc_surface(
        np.fft.rfft2(template, s=patch.shape),
        np.fft.rfft2(mask.astype(float), s=patch.shape),
        n,
        patch,
        (31, 31),
    )
    ours = np.unravel_index(np.argmax(surface), surface.shape)
    padded, padded_mask = np.zeros(patch.shape), np.zeros(patch.shape, bool)
    padded[:30, :20], padded_mask[:30, :20] = patch[12:42, 9:29], mask
    peer = phase_cross_correlation(
        patch, padded, reference_mask=np.ones(patch.shape, bool), moving_mask=padded_mask
    )
    assert tuple(int(v) for v in ours) == (12, 9) == tuple(int(v) for v in peer[0])


@pytest.mark.parametrize("offset", [(35.0, -20.0, 4.0), (-60.0, 45.0, -7.5)])
def test_search_recovers_a_known_shift_and_rotation(city, offset):
    grid, world = city
    body = PoseGrid.side_looking(range_m=200.0, pixel_m=4.0)
    truth = np.array([600.0, 500.0, 0.4])
    power, mask = _radar_of(world, grid, body, truth, np.random.default_rng(6))
    radar = preprocess(power, "clahe_ridge", mask, log_power=True, despeckle_px=3)
    gps = truth + np.array([offset[0], offset[1], np.radians(offset[2])])
    off = search_offset(radar, mask, preprocess(world, "clahe_ridge"), grid, body, gps, margin_m=100.0)
    corrected = gps + np.array([off.d_north_m, off.d_east_m, np.radians(off.d_heading_deg)])
    assert np.hypot(*(corrected[:2] - truth[:2])) < 3.0
    assert abs(np.degrees(corrected[2] - truth[2])) < 0.5
    assert off.psr > 5.0


def test_layover_moves_a_roof_to_the_closed_form_ground_range():
    body = PoseGrid(0.0, 0.5, 1.0, (2, 500))
    image = np.zeros(body.shape)
    shown = 300.5  # ground range where the projection put the roof
    image[:, int(shown - 0.5)] = 1.0
    moved = correct_layover(image, body, 250.0, 20.0)
    stands = np.sqrt(shown**2 + 2 * 250.0 * 20.0 - 20.0**2)  # x' = sqrt(x^2 - 2Hh + h^2), inverted
    assert body.right_m[np.nanargmax(moved[0])] == pytest.approx(stands, abs=1.0)
    assert np.isnan(moved[0, 0])  # no ground range maps to the nearest columns


def test_a_forward_mount_is_refused_naming_the_run():
    with pytest.raises(InputError, match="run.zarr: radar mount yaw 0 deg .* side-looking"):
        radar_side(RadarConfig(mount=Mount.preset("forward")), "run.zarr")
    assert radar_side(RadarConfig(mount=Mount.preset("side-right"))) == "right"


def test_monitor_verdict_sequence_and_alert():
    settings = MonitorSettings(min_psr=5.0, alert_frames=3)
    good = PoseOffset(3.0, -2.0, 0.4, 0.5, 0.5, 9.0)
    spoofed = PoseOffset(48.0, 14.0, 0.2, 0.5, 0.1, 9.0)
    flat = PoseOffset(90.0, 0.0, 3.0, 0.1, 0.1, 2.0)
    sequence = [
        (0.8, good),
        (0.8, spoofed),
        (0.8, spoofed),
        (0.1, None),
        (0.8, flat),
        (0.8, spoofed),
        (0.8, good),
    ]
    verdicts = [frame_verdict(f, o, settings) for f, o in sequence]
    assert verdicts == [
        CONSISTENT,
        INCONSISTENT,
        INCONSISTENT,
        WING_UP,
        LOW_STRUCTURE,
        INCONSISTENT,
        CONSISTENT,
    ]
    # Undecided frames neither break nor extend the streak; a consistent frame ends it.
    assert alerts(verdicts, 3).tolist() == [False, False, False, False, False, True, False]
