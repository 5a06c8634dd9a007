"""`skyradar passive` through the real entry point: errors in one line, and an end-to-end run (slow)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from cli_helpers import assert_one_line_error, skyradar
from skyradar.io.sigmf_io import SigmfWriter
from skyradar.passive.illuminator import Illuminator

RECEIVER = {"latitude": 52.10, "longitude": 5.30, "altitude": 45.0}


def _noise_recording(path, seconds=0.2, fs=2e6):
    ill = Illuminator(latitude=52.06, longitude=5.14, altitude=25.0)
    rng = np.random.default_rng(0)
    with SigmfWriter(path, fs, ill.carrier_frequency_hz, RECEIVER, ill.to_metadata()) as writer:
        n = int(seconds * fs)
        writer.write((rng.normal(size=n) + 1j * rng.normal(size=n)).astype(np.complex64) * 1e-6)


def test_recording_without_direct_path_pulses_is_one_line(tmp_path):
    _noise_recording(tmp_path / "quiet.sigmf-meta")
    result = skyradar("passive", "quiet.sigmf-meta", "-o", "det.parquet", cwd=tmp_path)
    assert_one_line_error(result, "quiet.sigmf", "no direct-path pulse")
    assert not (tmp_path / "det.parquet").exists()


def test_output_may_not_be_the_recording(tmp_path):
    _noise_recording(tmp_path / "rec.sigmf-meta")
    before = (tmp_path / "rec.sigmf-data").read_bytes()
    result = skyradar("passive", "rec.sigmf-meta", "-o", "rec.sigmf-data", cwd=tmp_path)
    assert_one_line_error(result, "rec.sigmf-data")
    assert (tmp_path / "rec.sigmf-data").read_bytes() == before


def test_bad_pulse_option_is_one_line(tmp_path):
    _noise_recording(tmp_path / "rec.sigmf-meta")
    result = skyradar("passive", "rec.sigmf-meta", "-o", "d.parquet", "--pulse", "guess", cwd=tmp_path)
    assert_one_line_error(result, "--pulse", "guess")


@pytest.mark.slow
def test_thesis_scene_five_seconds_end_to_end(tmp_path):
    """5 s of the thesis geometry: the aircraft's two beam passes found within 150 m, the scan phase right."""
    from skyradar.passive.scene import thesis_scene
    from skyradar.passive.simulate import simulate_recording

    meta = simulate_recording(thesis_scene(duration_s=5.0), tmp_path / "rec.sigmf-meta", 5e6)
    result = skyradar("passive", meta.name, "-o", "det.parquet", "--json", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    det = pd.read_parquet(tmp_path / "det.parquet")
    truth = pd.read_parquet(tmp_path / "rec.truth.parquet")
    plane = truth[truth["kind"] == "aircraft"]
    assert len(plane) == 2
    for _, row in plane.iterrows():
        near = det[(det["time_s"] - row["time_s"]).abs() < 0.3]
        assert np.hypot(near["east_m"] - row["east_m"], near["north_m"] - row["north_m"]).min() < 150
