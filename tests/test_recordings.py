"""Raw recordings: round trips for every dtype and axis order, and clear errors for bad files."""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

from cli_helpers import skyradar_in_process
from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.io.recording_writer import write_recording
from skyradar.io.recordings import read_recording

CFG = RadarConfig.prototype_2022(n_doppler=6, range_limit_m=600.0)
NS = CFG.samples_per_chirp


def frames(n: int = 3, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    shape = (n, CFG.n_rx, CFG.n_doppler, NS)
    return (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)).astype(np.complex64)


@pytest.mark.parametrize("dtype", ["complex_int16", "complex64", "int16", "float32"])
@pytest.mark.parametrize("fmt", ["json", "yaml"])
def test_round_trip(tmp_path, dtype, fmt):
    data = frames()
    if dtype in ("int16", "float32"):
        data = data.real.copy()
    sidecar = write_recording(tmp_path / "rec.bin", data, CFG, dtype=dtype, sidecar_format=fmt)
    assert sidecar.suffix == "." + fmt and not list(tmp_path.glob("*.tmp"))
    for opened in (tmp_path / "rec.bin", sidecar):
        got, config = read_recording(opened)
        assert got.shape == data.shape and len(got) == 3
        assert config == CFG
        tol = 1e-6 if "int16" not in dtype else np.abs(data).max() / 30000.0
        assert np.abs(got[2] - data[2]).max() <= tol
        assert np.allclose(got.times_s, np.arange(3) * CFG.frame_duration_s)


def test_other_axis_order_big_endian_offset_and_times(tmp_path):
    data = frames(2)
    on_disk = data.transpose(2, 0, 3, 1)  # chirp, frame, sample, rx
    header = b"HEADER!!"
    raw = np.stack([on_disk.real * 1000, on_disk.imag * 1000], axis=-1).round().astype(">i2")
    (tmp_path / "x.dat").write_bytes(header + raw.tobytes())
    meta = {
        "data_file": "x.dat",
        "dtype": "complex_int16",
        "byte_order": "big",
        "offset_bytes": len(header),
        "shape": list(on_disk.shape),
        "axes": ["chirp", "frame", "sample", "rx"],
        "sample_rate_hz": CFG.fs_hz,
        "fc_hz": CFG.fc_hz,
        "bandwidth_hz": CFG.bandwidth_hz,
        "prf_hz": CFG.prf_hz,
        "scale": 1e-3,
        "frame_times_s": [10.0, 10.5],
        "radar": {"range_limit_m": 600.0},
    }
    (tmp_path / "x.yaml").write_text(yaml.safe_dump(meta))
    got, config = read_recording(tmp_path / "x.yaml")
    assert got.shape == data.shape and config.n_doppler == CFG.n_doppler and config.range_limit_m == 600.0
    assert np.abs(got[1] - data[1]).max() <= 1e-3
    assert list(got.times_s) == [10.0, 10.5]


def test_npy_with_and_without_sidecar(tmp_path):
    data = frames(2)
    np.save(tmp_path / "a.npy", data)
    got, config = read_recording(tmp_path / "a.npy")
    assert np.array_equal(got[1], data[1]) and config.fc_hz == RadarConfig().fc_hz
    assert config.n_doppler == CFG.n_doppler
    np.save(tmp_path / "b.npy", data[0].transpose(2, 0, 1))  # one frame, (sample, rx, chirp)
    (tmp_path / "b.json").write_text(json.dumps({"axes": ["sample", "rx", "chirp"], "prf_hz": 4900.0}))
    got, config = read_recording(tmp_path / "b.npy")
    assert got.shape == (1, *data.shape[1:]) and config.prf_hz == 4900.0
    assert np.array_equal(got[0], data[0])


def write_valid(tmp_path, **changes):
    sidecar = write_recording(tmp_path / "rec.bin", frames(2), CFG)
    meta = json.loads(sidecar.read_text())
    for key, value in changes.items():
        if value is None:
            meta.pop(key)
        else:
            meta[key] = value
    sidecar.write_text(json.dumps(meta))
    return sidecar


def test_truncated_file_names_both_sizes(tmp_path):
    sidecar = write_valid(tmp_path)
    data = tmp_path / "rec.bin"
    full = data.stat().st_size
    with open(data, "r+b") as fh:
        fh.truncate(full - 100)
    with pytest.raises(
        InputError, match=rf"rec.bin: truncated: file has {full - 100} bytes.*needs {full} bytes"
    ):
        read_recording(sidecar)


def test_size_mismatch_names_both_sizes(tmp_path):
    sidecar = write_valid(tmp_path, shape=[1, CFG.n_rx, CFG.n_doppler, NS])
    need = CFG.n_rx * CFG.n_doppler * NS * 4
    with pytest.raises(
        InputError, match=rf"larger than described: file has {2 * need} bytes.*needs {need} bytes"
    ):
        read_recording(sidecar)


@pytest.mark.parametrize(
    "changes,match",
    [
        ({"prf_hz": None}, r"missing field\(s\) \['prf_hz'\]"),
        ({"axes": ["frame", "antenna", "chirp", "sample"]}, r"unknown name\(s\) \['antenna'\]"),
        ({"axes": ["frame", "rx", "chirp", "chirp"]}, "repeats"),
        ({"axes": ["rx", "chirp", "sample"]}, "3 names but the data has 4"),
        ({"dtype": "int8"}, "field 'dtype' is 'int8'"),
        ({"shape": [2, CFG.n_rx, CFG.n_doppler, NS + 1]}, "bytes"),
        ({"sample_rate_hz": -1}, "sample_rate_hz"),
        ({"scale": 0}, "scale"),
        ({"frame_times_s": [1.0, 0.5]}, "goes backwards"),
        ({"byte_order": "middle"}, "byte_order"),
        ({"data_file": "nope.bin"}, "does not exist"),
    ],
)
def test_bad_sidecar_fields(tmp_path, changes, match):
    sidecar = write_valid(tmp_path, **changes)
    with pytest.raises(InputError, match=match):
        read_recording(sidecar)


def test_too_many_samples_per_chirp_and_rx_without_positions(tmp_path):
    big = np.zeros((1, 2, CFG.n_doppler, NS + 8), np.complex64)
    sidecar = write_recording(tmp_path / "r.bin", big, CFG)
    meta = json.loads(sidecar.read_text())
    meta["radar"].pop("rx_positions_m")
    meta["radar"].pop("rx_calibration")
    sidecar.write_text(json.dumps(meta))
    with pytest.raises(InputError, match="2 rx channels; give 'radar.rx_positions_m'"):
        read_recording(sidecar)
    meta["radar"]["rx_positions_m"] = [[0, 0, 0], [0, 0.016, 0]]
    sidecar.write_text(json.dumps(meta))
    with pytest.raises(InputError, match=f"{NS + 8} samples per chirp"):
        read_recording(sidecar)


def test_empty_missing_and_unparsable(tmp_path):
    empty = np.zeros((0, CFG.n_rx, CFG.n_doppler, NS), np.complex64)
    sidecar = write_recording(tmp_path / "e.bin", empty, CFG)
    with pytest.raises(InputError, match="empty recording"):
        read_recording(sidecar)
    with pytest.raises(InputError, match="no such recording"):
        read_recording(tmp_path / "missing.bin")
    (tmp_path / "lonely.bin").write_bytes(b"\0" * 16)
    with pytest.raises(InputError, match="no sidecar"):
        read_recording(tmp_path / "lonely.bin")
    (tmp_path / "bad.json").write_text("{not json")
    with pytest.raises(InputError, match="cannot parse sidecar"):
        read_recording(tmp_path / "bad.json")
    np.save(tmp_path / "e.npy", np.zeros((0, 4, 6, 8)))
    with pytest.raises(InputError, match="empty recording"):
        read_recording(tmp_path / "e.npy")


def test_writer_rejects_bad_input_and_leaves_nothing(tmp_path):
    with pytest.raises(InputError, match="dtype"):
        write_recording(tmp_path / "w.bin", frames(1), CFG, dtype="int8")
    with pytest.raises(InputError, match="real"):
        write_recording(tmp_path / "w.bin", frames(1), CFG, dtype="float32")
    with pytest.raises(InputError, match="frame, rx, chirp, sample"):
        write_recording(tmp_path / "w.bin", frames(1)[0], CFG)
    assert list(tmp_path.iterdir()) == []


def test_rd_command_writes_frames_and_resumes(tmp_path, monkeypatch, capsys):
    from skyradar.io.frames import open_frames
    from skyradar.process.rangedoppler import range_doppler

    data = frames(3)
    sidecar = write_recording(tmp_path / "rec.bin", data, CFG, dtype="complex64")
    out = tmp_path / "run.zarr"
    code, stdout, err = skyradar_in_process(
        monkeypatch, capsys, "rd", str(sidecar), "-o", str(out), "--chunk-frames", "2", "--json"
    )
    assert code == 0, err
    result = json.loads(stdout.strip().splitlines()[-1])
    assert result["frames"] == 3 and result["chunks_written"] == 2
    ds = open_frames(out)
    assert ds.iq.shape == (3, CFG.n_range, CFG.n_doppler, CFG.n_rx)
    assert np.allclose(ds.iq.values[2], range_doppler(data[2], CFG), atol=1e-7)
    assert not (tmp_path / "run.zarr.partial").exists()


def test_rd_command_bad_recording_leaves_no_output(tmp_path, monkeypatch, capsys):
    sidecar = write_recording(tmp_path / "rec.bin", frames(2), CFG)
    with open(tmp_path / "rec.bin", "r+b") as fh:
        fh.truncate(1000)
    out = tmp_path / "run.zarr"
    code, _, err = skyradar_in_process(monkeypatch, capsys, "rd", str(sidecar), "-o", str(out))
    assert code == 2
    assert err.startswith("error: ") and "truncated" in err and len(err.strip().splitlines()) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rec.bin", "rec.json"]


def test_rd_command_resumes_after_interruption(tmp_path, monkeypatch, capsys):
    from skyradar.process.rangedoppler import RangeDopplerProcessor

    sidecar = write_recording(tmp_path / "rec.bin", frames(4), CFG, dtype="complex64")
    out = tmp_path / "run.zarr"
    original = RangeDopplerProcessor.__call__
    calls = []

    def interrupted(self, adc, **kw):
        calls.append(1)
        if len(calls) == 3:  # first chunk (2 frames) done, stop inside the second
            raise KeyboardInterrupt
        return original(self, adc, **kw)

    monkeypatch.setattr(RangeDopplerProcessor, "__call__", interrupted)
    skyradar_in_process(monkeypatch, capsys, "rd", str(sidecar), "-o", str(out), "--chunk-frames", "2")
    assert not out.exists() and (tmp_path / "run.zarr.partial").exists()
    monkeypatch.setattr(RangeDopplerProcessor, "__call__", original)
    code, stdout, err = skyradar_in_process(
        monkeypatch, capsys, "rd", str(sidecar), "-o", str(out), "--chunk-frames", "2", "--json"
    )
    assert code == 0, err
    result = json.loads(stdout.strip().splitlines()[-1])
    assert result["chunks_resumed"] == 1 and result["chunks_written"] == 1 and out.exists()
