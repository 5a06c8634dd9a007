"""An elevation clutter suppression left unobservable is carried as ``elevation_measured`` False, not
guessed from the value 0: the ground filter and the track-level ground test do not count it as
a measured direction (tests/test_ground_tracks.py); clutter_doa.projected_directions' doctest shows the
flag itself."""

import numpy as np

from skyradar.config import RadarConfig
from skyradar.io.frames import frames_dataset
from skyradar.process.pipeline import DETECTION_COLUMNS, process_frames


def test_clear_sky_detections_all_have_measured_elevations():
    cfg = RadarConfig.prototype_2022()
    rng = np.random.default_rng(1)
    shape = (2, cfg.n_range, cfg.n_doppler, cfg.n_rx)
    iq = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)) * np.sqrt(cfg.noise_power_w / 2)
    iq[:, 120, 60, :] += np.sqrt(1e4 * cfg.noise_power_w)
    table = process_frames(frames_dataset(iq.astype(np.complex64), np.array([0.0, 0.1]), cfg))
    assert "elevation_measured" in DETECTION_COLUMNS and table["elevation_measured"].dtype == bool
    assert len(table) >= 2 and table["elevation_measured"].all()
