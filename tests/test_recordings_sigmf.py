"""SigMF radar recordings: round trips, ``skyradar rd`` on one, and one clear line for each bad file."""

from __future__ import annotations

import json

import numpy as np
import pytest

from cli_helpers import assert_one_line_error, skyradar, skyradar_in_process
from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.io.recording_writer import write_recording, write_sigmf_recording
from skyradar.io.recordings import read_recording
from skyradar.io.sigmf_io import read_iq_recording

CFG = RadarConfig.prototype_2022(n_doppler=6, range_limit_m=600.0)
NS = CFG.samples_per_chirp


def frames(n: int = 3, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    shape = (n, CFG.n_rx, CFG.n_doppler, NS)
    return (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)).astype(np.complex64)


@pytest.mark.parametrize("datatype", ["ci16_le", "cf32_le", "ri16_le", "rf32_le"])
def test_round_trip_every_datatype_and_name(tmp_path, datatype):
    data = frames() if datatype.startswith("c") else frames().real.copy()
    meta = write_sigmf_recording(tmp_path / "radar", data, CFG, datatype, start_time="2026-01-01T00:00:00Z")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["radar.sigmf-data", "radar.sigmf-meta"]
    tol = 1e-6 if "f32" in datatype else np.abs(data).max() / 30000.0
    for name in ("radar.sigmf-meta", "radar.sigmf-data", "radar"):
        got, config = read_recording(tmp_path / name)
        assert got.shape == data.shape and config == CFG
        assert np.abs(got[2] - data[2]).max() <= tol
        assert np.allclose(got.times_s, np.arange(3) * CFG.frame_duration_s)
    glob = json.loads(meta.read_text())["global"]
    assert glob["core:num_channels"] == CFG.n_rx and glob["skyradar:sample_count"] == 3 * CFG.n_doppler * NS


def test_channels_interleaved_big_endian_header_and_frame_times(tmp_path):
    """A file written by hand as SigMF lays it out: samples of every channel interleaved, chirp by chirp."""
    data = frames(2)
    on_disk = np.moveaxis(data, 1, -1)  # (frame, chirp, sample, rx)
    pairs = np.stack([on_disk.real, on_disk.imag], axis=-1).astype(">f4")
    (tmp_path / "x.sigmf-data").write_bytes(b"HDR!" + pairs.tobytes())
    glob = {
        "core:version": "1.2.0",
        "core:datatype": "cf32_be",
        "core:sample_rate": CFG.fs_hz,
        "core:num_channels": 4,
        "skyradar:bandwidth_hz": CFG.bandwidth_hz,
        "skyradar:prf_hz": CFG.prf_hz,
        "skyradar:chirps_per_frame": CFG.n_doppler,
        "skyradar:frame_times_s": [5.0, 5.5],
        "skyradar:radar": {"range_limit_m": 600.0},
    }
    capture = {"core:sample_start": 0, "core:frequency": CFG.fc_hz, "core:header_bytes": 4}
    meta = {"global": glob, "captures": [capture], "annotations": []}
    (tmp_path / "x.sigmf-meta").write_text(json.dumps(meta))
    got, config = read_recording(tmp_path / "x.sigmf-meta")
    assert got.shape == data.shape and config.range_limit_m == 600.0 and list(got.times_s) == [5.0, 5.5]
    assert np.array_equal(got[1], data[1])


def test_rd_command_reads_sigmf_like_a_sidecar_recording(tmp_path, monkeypatch, capsys):
    from skyradar.io.frames import open_frames

    data = frames(3)
    write_recording(tmp_path / "rec.bin", data, CFG, dtype="complex64")
    write_sigmf_recording(tmp_path / "rec", data, CFG, "cf32_le")
    stores = {}
    for name in ("rec.json", "rec.sigmf-meta"):
        out = tmp_path / f"{name}.zarr"
        code, _, err = skyradar_in_process(monkeypatch, capsys, "rd", str(tmp_path / name), "-o", str(out))
        assert code == 0, err
        stores[name] = open_frames(out).iq.values
    assert np.array_equal(stores["rec.json"], stores["rec.sigmf-meta"])


def _edit(meta_path, **changes):
    meta = json.loads(meta_path.read_text())
    for key, value in changes.items():
        where = meta["captures"][0] if key == "core:frequency" else meta["global"]
        if value is None:
            where.pop(key)
        else:
            where[key] = value
    meta_path.write_text(json.dumps(meta))


def test_bad_recordings_are_one_line_naming_file_field_and_value(tmp_path):
    """Through the real entry point: exit code 2 and one ``error:`` line, no output written."""
    meta = write_sigmf_recording(tmp_path / "a", frames(2), CFG)
    data = tmp_path / "a.sigmf-data"
    out = tmp_path / "run.zarr"
    # Missing metadata: named with the data file it should sit beside.
    (tmp_path / "b.sigmf-data").write_bytes(data.read_bytes())
    assert_one_line_error(skyradar("rd", "b.sigmf-data", "-o", str(out), cwd=tmp_path), "b.sigmf-meta")
    # A datatype the radar path cannot read.
    _edit(meta, **{"core:datatype": "cu8"})
    result = skyradar("rd", str(meta), "-o", str(out), cwd=tmp_path)
    assert_one_line_error(result, "a.sigmf-meta", "'core:datatype'", "'cu8'")
    # Samples that are not whole frames: 'chirps_per_frame' does not divide the data.
    _edit(meta, **{"core:datatype": "ci16_le", "skyradar:sample_count": None, "skyradar:chirps_per_frame": 5})
    result = skyradar("rd", str(meta), "-o", str(out), cwd=tmp_path)
    assert_one_line_error(result, "a.sigmf-data", "'skyradar:chirps_per_frame' 5", f"{2 * 6 * NS} samples")
    assert not out.exists() and not (tmp_path / "run.zarr.partial").exists()


@pytest.mark.parametrize(
    ("field", "value", "match"),
    [
        ("rx_positions_m", [[0, 0, 0], [0, 0, 0]], r"'skyradar:radar.rx_positions_m': all receive antennas"),
        ("tx_positions_m", [[0, 0, 0], [0, 0, 0]], r"'skyradar:radar.tx_positions_m': transmitters 0 and 1"),
    ],
)
def test_a_bad_radar_field_is_named_by_its_sigmf_key(tmp_path, field, value, match):
    meta = write_sigmf_recording(tmp_path / "a", frames(2), CFG)
    radar = json.loads(meta.read_text())["global"]["skyradar:radar"]
    _edit(meta, **{"skyradar:radar": radar | {field: value}})
    with pytest.raises(InputError, match=match):
        read_recording(meta)


@pytest.mark.parametrize(
    ("changes", "match"),
    [
        ({"core:sample_rate": None}, r"field 'core:sample_rate' \(the ADC rate, Hz\) is missing"),
        ({"skyradar:prf_hz": -3.0}, r"field 'skyradar:prf_hz' .* must be a finite number > 0, got -3.0"),
        ({"skyradar:chirps_per_frame": 6.5}, r"'skyradar:chirps_per_frame' .* whole number > 0, got 6.5"),
        ({"core:frequency": None}, r"field 'core:frequency' .* is missing"),
        ({"core:num_channels": 2, "skyradar:radar": {}}, r"'core:num_channels' is 2: give"),
        ({"skyradar:sample_count": 7}, r"holds 24384 samples per channel, but field 'skyradar:sample_count'"),
        ({"skyradar:frame_times_s": [1.0, 0.5]}, r"field 'skyradar:frame_times_s' goes backwards"),
        ({"skyradar:scale": 0}, r"field 'skyradar:scale' .* got 0"),
        ({"skyradar:samples_per_chirp": NS + 1}, rf"'skyradar:samples_per_chirp' is {NS + 1}, more than"),
        ({"skyradar:samples_per_chirp": NS - 1}, r"not whole frames"),
    ],
)
def test_bad_fields(tmp_path, changes, match):
    meta = write_sigmf_recording(tmp_path / "a", frames(2), CFG)
    _edit(meta, **changes)
    with pytest.raises(InputError, match=match):
        read_recording(meta)


def test_truncated_data_and_passive_recording_are_named(tmp_path):
    meta = write_sigmf_recording(tmp_path / "a", frames(2), CFG)
    data = tmp_path / "a.sigmf-data"
    with open(data, "r+b") as fh:
        fh.truncate(data.stat().st_size - 4 * CFG.n_rx)  # one sample of every channel short
    with pytest.raises(InputError, match="'skyradar:sample_count' of a.sigmf-meta is 24384: truncated"):
        read_recording(meta)
    with pytest.raises(InputError, match="'core:num_channels' is 4; need 1"):
        read_iq_recording(meta, require_illuminator=False)  # a radar recording is no passive one
    rx = {"latitude": 52.0, "longitude": 5.0, "altitude": 0.0}
    from skyradar.io.sigmf_io import SigmfWriter

    with SigmfWriter(tmp_path / "p", 5e6, 2.8e9, rx, rx) as writer:
        writer.write(np.ones(100, np.complex64))
    with pytest.raises(InputError, match=r"'skyradar:prf_hz' .* is missing: not an FMCW radar's recording"):
        read_recording(tmp_path / "p.sigmf-meta")


def test_writer_refuses_bad_requests_and_leaves_nothing(tmp_path):
    with pytest.raises(InputError, match="datatype 'cu8'"):
        write_sigmf_recording(tmp_path / "w", frames(1), CFG, "cu8")
    with pytest.raises(InputError, match="real"):
        write_sigmf_recording(tmp_path / "w", frames(1), CFG, "rf32_le")
    with pytest.raises(InputError, match="n_doppler"):
        write_sigmf_recording(tmp_path / "w", frames(1), CFG.replace(n_doppler=8))
    assert list(tmp_path.iterdir()) == []
