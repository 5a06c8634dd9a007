"""Spur maps: learned from static frames, false alarms after masking, save/load, online variant."""

from __future__ import annotations

import numpy as np
import pytest

from skyradar.benchmarks.process import synthetic_frame
from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.process.detect import detect, integrate_channels
from skyradar.process.spurs import THESIS_THRESHOLDS, OnlineSpurMap, SpurMap, detection_pixels, learn_spur_map

CFG = RadarConfig.prototype_2022()
# Fixed self-interference: (range bin, Doppler bin, SNR dB); one on the Doppler edge, one weak.
SPURS = [(20, 125, 35.0), (150, 0, 25.0), (260, 60, 16.0), (7, 200, 45.0)]


def spur_frame(rng, targets=()):
    cube, _ = synthetic_frame(CFG, targets, rng)
    for r, d, snr_db in SPURS:
        # Spurs keep their pixel but not their phase from frame to frame.
        amp = np.sqrt(CFG.noise_power_w * 10 ** (snr_db / 10))
        cube[r, d, :] += (amp * np.exp(1j * rng.uniform(0, 2 * np.pi, CFG.n_rx))).astype(np.complex64)
    return integrate_channels(cube)


@pytest.fixture(scope="module")
def learned():
    rng = np.random.default_rng(0)
    return learn_spur_map((spur_frame(rng) for _ in range(40)), CFG, threshold=0.05)


def test_learned_map_covers_every_spur_and_little_else(learned):
    for r, d, _ in SPURS:
        assert learned.mask[r, d]
        assert (
            learned.mask[r, (d + 1) % CFG.n_doppler] and learned.mask[r, (d - 1) % CFG.n_doppler]
        )  # dilated
    assert learned.mask.sum() <= 9 * len(SPURS) + 20
    assert learned.n_frames == 40


def test_false_alarms_after_the_spur_map_below_one_per_hundred_frames(learned):
    rng = np.random.default_rng(1)
    raw = kept = 0
    n_frames = 150
    for _ in range(n_frames):
        det = detect(spur_frame(rng), CFG)
        raw += len(det)
        kept += int(np.sum(~learned.contains(det.range_bin, det.doppler_bin)))
    assert raw >= 3 * n_frames  # the spurs are detected every frame without the map
    assert kept / n_frames <= 0.01


def test_target_on_a_free_pixel_is_not_masked(learned):
    rng = np.random.default_rng(2)
    det = detect(spur_frame(rng, [(3000.0, 10.0, 0.0, 0.0, 15.0)]), CFG)
    free = ~learned.contains(det.range_bin, det.doppler_bin)
    assert free.sum() == 1
    assert det.range_m(CFG)[free][0] == pytest.approx(3000.0, abs=8.0)


def test_higher_thresholds_mask_fewer_pixels(learned):
    sizes = [learned.with_threshold(t).mask.sum() for t in THESIS_THRESHOLDS]
    assert sizes == sorted(sizes, reverse=True)


def test_save_load_round_trip_and_bad_files(tmp_path, learned):
    path = learned.save(tmp_path / "spurs.npz")
    back = SpurMap.load(path, CFG)
    np.testing.assert_array_equal(back.frequency, learned.frequency)
    assert back.threshold == learned.threshold and back.n_frames == learned.n_frames
    with pytest.raises(InputError, match="no such spur map"):
        SpurMap.load(tmp_path / "missing.npz")
    small = SpurMap(np.zeros((10, 10)), 0.1, 1).save(tmp_path / "small.npz")
    with pytest.raises(InputError, match="frequency"):
        SpurMap.load(small, CFG)
    (tmp_path / "junk.npz").write_text("not a map")
    with pytest.raises(InputError, match="not a spur map"):
        SpurMap.load(tmp_path / "junk.npz")
    with pytest.raises(InputError, match="no frames"):
        learn_spur_map([], CFG)


def test_online_map_learns_fixed_spurs_while_the_scene_moves():
    rng = np.random.default_rng(3)
    online = OnlineSpurMap(
        (CFG.n_range, CFG.n_doppler), time_constant_frames=30, threshold=0.5, min_frames=10
    )
    for i in range(60):
        # An object moving by 2 range bins per frame (approaching aircraft / passing ground feature).
        target = [(4000.0 - 30.0 * i, -20.0, 0.1, 0.0, 30.0)]
        power = spur_frame(rng, target)
        mask = online.update(detection_pixels(power, CFG))
    for r, d, _ in SPURS:
        assert mask[r, d]
    moving = round((4000.0 - 30.0 * 59) / CFG.range_resolution_m)
    d_moving = round(-20.0 / CFG.doppler_resolution_mps) + CFG.n_doppler // 2
    assert not mask[moving, d_moving]
    assert online.snapshot().mask.sum() == mask.sum()


def test_hits_map_masks_zero_doppler_line_and_near_range_leakage_but_not_a_target_beside_them():
    from skyradar.sim.impairments import near_range_leakage, zero_doppler_line

    rng = np.random.default_rng(4)
    line = zero_doppler_line(CFG, power_dbm_at_100m=-110.0, falloff_db_per_decade=15.0)

    def frame(targets=()):
        cube, _ = synthetic_frame(CFG, targets, rng)
        return integrate_channels(cube + line + near_range_leakage(CFG, -110.0, 100.0, rng))

    spur_map = learn_spur_map((frame() for _ in range(30)), CFG, threshold=0.05, pixels="hits")
    centre = CFG.n_doppler // 2
    assert spur_map.mask[50:, centre].all() and spur_map.mask[:6].all()
    # A 15 dB aircraft three Doppler bins from the line at 2 km.
    target = [(2000.0, 3 * CFG.doppler_resolution_mps, 0.1, 0.1, 15.0)]
    found = false_alarms = 0
    for _ in range(40):
        det = detect(frame(target), CFG, exclude=spur_map.mask)
        on_target = (np.abs(det.range_m(CFG) - 2000.0) < 10) & (det.doppler_index == centre + 3)
        found += int(on_target.sum())
        false_alarms += int((~on_target).sum())
    assert found == 40 and false_alarms <= 0
    # Without the mask the line inflates the CFAR noise estimate beside it and swallows the target.
    det = detect(frame(target), CFG)
    assert not np.any((np.abs(det.range_m(CFG) - 2000.0) < 10) & (det.doppler_index == centre + 3))
