"""The scenario runner: impairments from the scenario file reach the frames, noise is never doubled."""

from __future__ import annotations

import numpy as np

from skyradar.scene.scenario import Scenario
from skyradar.sim.scenario_frames import make_simulator, simulate_frames

BASE = {
    "name": "impaired",
    "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    "mount": "forward",
    "ownship": {"type": "straight", "start_ned_m": [0, 0, -500], "heading_deg": 0, "speed_mps": 40},
    "frame_rate_hz": 5.0,
    "duration_s": 0.4,
}


def test_thesis_look_preset_puts_spurs_and_zero_doppler_line_in_every_frame(tmp_path):
    built = Scenario.from_dict(
        {**BASE, "impairments": {"preset": "thesis_flight_look"}}, tmp_path / "s.yaml"
    ).build()
    cfg = built.radar
    frames = simulate_frames(built, np.arange(2))
    power_db = 10 * np.log10(np.mean(np.abs(frames) ** 2, axis=-1) / cfg.noise_power_w)
    k = int(round(1200.0 / cfg.range_resolution_m))
    j = int(round(5.0 / cfg.doppler_resolution_mps)) + cfg.n_doppler // 2
    assert np.all(power_db[:, k, j] > 20.0)  # the spur at 1200 m, +5 m/s, in both frames
    zero = cfg.n_doppler // 2
    assert np.median(power_db[:, 20:200, zero]) > 15.0  # bright zero-Doppler line
    assert np.median(power_db[:, 20:200, zero + 40]) < 3.0  # away from it: noise
    assert make_simulator(built).ground_gain == 10 ** (-10.0 / 10)  # weaker ground


def test_impairment_noise_replaces_simulator_noise(tmp_path):
    data = {**BASE, "impairments": {"noise": {"enabled": True}}}
    built = Scenario.from_dict(data, tmp_path / "s.yaml").build()
    frames = simulate_frames(built, np.arange(1))
    measured = np.mean(np.abs(frames) ** 2)
    assert abs(measured / built.radar.noise_power_w - 1.0) < 0.02  # once, not twice
