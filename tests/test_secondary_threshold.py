"""The secondary threshold of nulled cells, and the tracker rule that uses it.

Nulling ground clutter in a cell costs a target there several dB of SNR. A second, lower CFAR
threshold in those cells finds it again; its false alarms are spread over the whole nulled region,
so its detections only update a confirmed track inside the few cells its gate predicts and never
start or confirm one.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.process.detect import detect
from skyradar.track.fusion import fuse_heads
from skyradar.track.models import radar_model
from skyradar.track.tracker import RangeDopplerTracker

CFG = RadarConfig.prototype_2022()
SHAPE = (CFG.n_range, CFG.n_doppler)


def _suppressed_noise(rng: np.random.Generator, channels: np.ndarray) -> np.ndarray:
    """Thermal noise of a suppressed image: each pixel the mean of its L unit-noise channels."""
    return (rng.gamma(channels.astype(float), 1.0 / channels) * CFG.noise_power_w).astype(np.float32)


def _nulled_band(n_rx_left: int = 2) -> np.ndarray:
    """Channels per pixel: a ground band of Doppler columns 40-79 nulled down to ``n_rx_left``."""
    channels = np.full(SHAPE, CFG.n_rx, np.int8)
    channels[:, 40:80] = n_rx_left
    return channels


def test_secondary_false_alarms_follow_their_probability_and_stay_in_nulled_cells():
    rng = np.random.default_rng(0)
    channels = _nulled_band()
    pfa2, count, cells = 1e-3, 0, 0
    for _ in range(4):
        power = _suppressed_noise(rng, channels)
        det = detect(power, CFG, channels=channels, noise_floor_w=CFG.noise_power_w, pfa_secondary=pfa2)
        sec = det.select(det.secondary)
        assert np.all(channels[sec.range_index, sec.doppler_index] < CFG.n_rx)
        count += len(sec)
        cells += int((channels < CFG.n_rx).sum())
    # Blobs, not pixels: a false alarm seldom has a neighbour over the threshold at this Pfa. CA-CFAR
    # is exact for its noise law; the blobs and the band's edges move the count by less than 2x.
    rate = count / cells
    assert pfa2 / 2.0 < rate < 2.0 * pfa2, rate


def test_a_target_weakened_by_the_nulls_is_found_by_the_secondary_threshold_only():
    rng = np.random.default_rng(1)
    channels = _nulled_band()
    found_primary = found_secondary = 0
    for trial in range(40):
        power = _suppressed_noise(rng, channels)
        r, d = 100 + trial, 60
        # 9 dB over the noise: under two channels' threshold at 2e-8 (10.2 dB), over it at 1e-4 (7.7 dB).
        power[r, d] += np.float32(8.0 * CFG.noise_power_w)
        det = detect(power, CFG, channels=channels, noise_floor_w=CFG.noise_power_w, pfa_secondary=1e-4)
        at = (np.abs(det.range_index - r) <= 1) & (det.doppler_index == d)
        found_primary += bool(np.any(at & ~det.secondary))
        found_secondary += bool(np.any(at & det.secondary))
    assert found_primary <= 8 and found_primary + found_secondary >= 36


def test_a_blob_with_a_primary_hit_is_one_primary_detection():
    rng = np.random.default_rng(2)
    channels = _nulled_band()
    power = _suppressed_noise(rng, channels)
    power[200, 60] += np.float32(1e4 * CFG.noise_power_w)  # 40 dB and its skirt
    power[199:202, 59:62] += np.float32(30.0 * CFG.noise_power_w)
    det = detect(power, CFG, channels=channels, noise_floor_w=CFG.noise_power_w, pfa_secondary=1e-4)
    near = (np.abs(det.range_index - 200) <= 2) & (np.abs(det.doppler_index - 60) <= 2)
    assert near.sum() == 1 and not det.secondary[near].any()


def test_no_secondary_detections_outside_nulled_cells_or_without_a_lower_threshold():
    rng = np.random.default_rng(3)
    clean = np.full(SHAPE, CFG.n_rx, np.int8)
    power = _suppressed_noise(rng, clean)
    det = detect(power, CFG, channels=clean, noise_floor_w=CFG.noise_power_w, pfa_secondary=1e-2)
    assert not det.secondary.any()
    nulled = _nulled_band()
    power = _suppressed_noise(rng, nulled)
    same = detect(power, CFG, channels=nulled, noise_floor_w=CFG.noise_power_w, pfa=1e-3, pfa_secondary=1e-4)
    assert not same.secondary.any()
    with pytest.raises(InputError, match="pfa_secondary"):
        detect(power, CFG, channels=nulled, pfa_secondary=1.5)


def _tracker() -> RangeDopplerTracker:
    return RangeDopplerTracker(radar_model(2.0 * CFG.v_lim_mps))


def _closing(k: int) -> np.ndarray:
    """A target at 1500 m closing at 30 m/s (aliased radial velocity), frame ``k`` at 9.4 Hz."""
    return np.array([[1500.0 - 30.0 * k / 9.4, -30.0]])


def test_secondary_detections_never_start_a_track():
    trk = _tracker()
    for k in range(20):
        out = trk.step(k / 9.4, _closing(k), np.array([True]))
    assert trk.n_tracks == 0 and out.track_id.size == 0


def test_a_confirmed_track_is_kept_by_secondary_detections_and_a_tentative_one_is_not():
    trk = _tracker()
    for k in range(6):  # confirmed on primary detections
        out = trk.step(k / 9.4, _closing(k))
    assert out.confirmed.all() and out.track_id.size == 1
    for k in range(6, 40):  # then only secondary ones: the track keeps being updated
        out = trk.step(k / 9.4, _closing(k), np.array([True]))
        assert out.track_id.tolist() == [0] and out.detection_index.tolist() == [0]
    fresh = _tracker()
    fresh.step(0.0, _closing(0))  # one primary detection: tentative
    for k in range(1, 10):
        fresh.step(k / 9.4, _closing(k), np.array([True]))
    assert fresh.n_tracks == 0


def test_a_primary_detection_in_the_gate_comes_before_a_secondary_one():
    trk = _tracker()
    for k in range(6):
        trk.step(k / 9.4, _closing(k))
    z = np.vstack([_closing(6) + [1.0, 0.0], _closing(6) + [6.0, 0.1]])  # secondary nearer, primary next
    out = trk.step(6 / 9.4, z, np.array([True, False]))
    assert out.detection_index.tolist() == [1]
    with pytest.raises(ValueError, match="secondary"):
        trk.step(7 / 9.4, z, np.array([True]))


def test_fusion_keeps_secondary_rows_apart_from_the_duplicate_search():
    det = pd.DataFrame(
        {
            "time_s": [0.0, 0.0, 0.0],
            "range_m": [1000.0, 1002.0, 1001.0],
            "radial_velocity_mps": [-20.0, -20.05, -20.0],
            "snr_db": [14.0, 11.0, 12.0],
            "secondary": [True, False, False],
            "radar": ["nose", "left", "right"],
        }
    )
    fused, rows = fuse_heads(det)
    # The two primary rows are one object (the stronger kept); the secondary row is left to the gates.
    assert rows.tolist() == [0, 2] and fused["secondary"].tolist() == [True, False]
