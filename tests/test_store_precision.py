"""The cint16 frames store: bounded round-trip error, same reader API, resume keys and disk-space check."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from hypothesis import example, given, settings
from hypothesis import strategies as st

from cli_helpers import assert_one_line_error as _assert_one_line_error
from cli_helpers import skyradar as _skyradar
from skyradar.config import RadarConfig
from skyradar.io import cint16, frames
from skyradar.io.frames import FrameStoreWriter, check_store_space, frames_dataset, open_frames, store_bytes

# A tiny scenario (as in test_cli_sim.py): straight flight 500 m over flat ground, one head-on intruder.
BASE = {
    "name": "tiny",
    "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    "mount": "forward",
    "terrain": {"type": "flat", "size_m": 3000, "spacing_m": 60},
    "ownship": {"type": "straight", "start_ned_m": [0, 0, -500], "heading_deg": 0, "speed_mps": 40},
    "intruders": [{"name": "A", "type": "encounter", "kind": "head-on", "t_cpa_s": 20, "rcs_m2": 1.0}],
    "frame_rate_hz": 5.0,
    "duration_s": 1.0,
    "simulation": {"facet_size_m": 30.0},
}


def _write(tmp_path: Path, data: dict, name: str = "scenario.yaml") -> Path:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return path


# Float32 rounding of code * scale adds at most 2^-24 * 32767 steps to the half-step rounding error.
BOUND_STEPS = 0.5 + 2.0**-9


def _cube(seed: int, n: int, decades: float, zero_frames: int) -> np.ndarray:
    """Random (n, 5, 7, 2) complex64 cube spanning ``decades`` orders of magnitude, some frames all zero."""
    rng = np.random.default_rng(seed)
    shape = (n, 5, 7, 2)
    magnitude = 10.0 ** rng.uniform(-decades / 2, decades / 2, shape)
    cube = (magnitude * np.exp(2j * np.pi * rng.random(shape))).astype(np.complex64)
    cube[:zero_frames] = 0
    return cube


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(1, 4),
    decades=st.floats(0.0, 70.0),
    zero_frames=st.integers(0, 4),
)
@example(seed=0, n=2, decades=70.0, zero_frames=1)  # 1e-35..1e35: float32 scales near subnormal and max
def test_round_trip_error_at_most_half_a_step(seed, n, decades, zero_frames):
    iq = _cube(seed, n, decades, zero_frames)
    codes, scale = cint16.encode(iq)
    assert codes.dtype == np.int16 and scale.dtype == np.float32
    assert np.abs(codes.astype(int)).max() <= cint16.CODE_MAX  # never -32768, never wrapped
    decoded = cint16.decode_block(codes, scale)
    step = scale.astype(np.float64)[:, :, None, :]
    for part in (np.real, np.imag):
        error = np.abs(part(decoded).astype(np.float64) - part(iq).astype(np.float64))
        assert np.all(error <= step * BOUND_STEPS)
    assert np.all(decoded[: min(zero_frames, n)] == 0)  # all-zero frames stay exactly zero


def test_peak_maps_to_full_scale_without_clipping():
    iq = np.zeros((1, 1, 100, 1), np.complex64)
    iq[0, 0, :3, 0] = [1e30 + 0j, -1e30j, 1e-30]
    codes, _ = cint16.encode(iq)
    assert codes[0, 0, 0, 0, 0] == 32767 and codes[0, 0, 1, 0, 1] == -32767


def test_step_follows_the_noise_floor():
    # Noise-only rows: the step is sigma / 4, not peak / 32767, so the codes stay small (compressible).
    rng = np.random.default_rng(3)
    iq = (rng.standard_normal((2, 8, 256, 2)) + 1j * rng.standard_normal((2, 8, 256, 2))).astype(np.complex64)
    codes, scale = cint16.encode(iq)
    assert np.std(codes.astype(float)) == pytest.approx(cint16.STEPS_PER_SIGMA, rel=0.15)
    assert np.all(scale >= 0.2)


def test_encode_refuses_nan():
    with pytest.raises(ValueError, match="NaN"):
        cint16.encode(np.full((1, 1, 2, 1), np.nan, np.complex64))


def _tiny_config() -> RadarConfig:
    return RadarConfig.prototype_2022()


def _write_store(path: Path, iq: np.ndarray, precision: str, compressor: str = "none") -> Path:
    import dask.array as da

    cfg = _tiny_config()
    times = np.arange(iq.shape[0]) * 0.1
    template = frames_dataset(da.zeros(iq.shape, dtype=np.complex64, chunks=(2, -1, -1, -1)), times, cfg)
    writer = FrameStoreWriter(path, template, 2, "job", compressor=compressor, precision=precision)
    for index in writer.pending_chunks():
        writer.write_chunk(index, iq[writer.chunk_slice(index)])
    return writer.close()


def _noise_frames(n: int) -> np.ndarray:
    cfg = _tiny_config()
    rng = np.random.default_rng(1)
    shape = (n, cfg.n_range, cfg.n_doppler, cfg.n_rx)
    iq = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)) * np.sqrt(cfg.noise_power_w / 2)
    iq[:, 20, 100, :] *= 1e4  # a return 80 dB above the noise in one pixel per frame
    return iq.astype(np.complex64)


def test_open_frames_decodes_cint16_store_to_complex64(tmp_path):
    iq = _noise_frames(3)
    path = _write_store(tmp_path / "q.zarr", iq, "cint16", "zstd")
    ds = open_frames(path)
    assert ds["iq"].dtype == np.complex64 and ds["iq"].dims == ("time", "range", "doppler", "rx")
    assert "iq_int16" not in ds and ds["iq"].chunks is not None  # lazy (dask), like a complex64 store
    decoded = ds["iq"].values
    step = np.asarray(frames.xr.open_zarr(path, consolidated=False)["iq_scale"].values, np.float64)
    error = np.maximum(np.abs(decoded.real - iq.real), np.abs(decoded.imag - iq.imag))
    assert np.all(error <= step[:, :, None, :] * BOUND_STEPS)
    # Quantisation noise stays far below the thermal noise (the documented -22.8 dB in noise rows).
    quant_noise = np.mean(np.abs(decoded - iq) ** 2) / _tiny_config().noise_power_w
    assert 10 * np.log10(quant_noise) < -20.0


def test_resume_does_not_mix_precisions(tmp_path):
    import dask.array as da

    iq = _noise_frames(4)
    cfg = _tiny_config()
    lazy = da.zeros(iq.shape, dtype=np.complex64, chunks=(2, -1, -1, -1))
    template = frames_dataset(lazy, np.arange(4.0), cfg)
    path = tmp_path / "r.zarr"
    first = FrameStoreWriter(path, template, 2, "job", precision="complex64")
    first.write_chunk(0, iq[:2])  # interrupted after one chunk
    again = FrameStoreWriter(path, template, 2, "job", precision="complex64")
    assert again.pending_chunks() == [1]  # same precision resumes
    other = FrameStoreWriter(path, template, 2, "job", precision="cint16")
    assert other.pending_chunks() == [0, 1]  # another precision starts afresh, never mixes
    for index in other.pending_chunks():
        other.write_chunk(index, iq[other.chunk_slice(index)])
    ds = open_frames(other.close())
    assert np.abs(ds["iq"].values - iq).max() > 0  # quantised everywhere: chunk 0 was rewritten


def test_store_bytes_and_disk_check_account_for_precision(tmp_path, monkeypatch):
    cfg = _tiny_config()
    raw64, raw16 = store_bytes(cfg, 100), store_bytes(cfg, 100, precision="cint16")
    assert raw16 == pytest.approx(raw64 / 2 * (1 + 1 / cfg.n_doppler))  # codes + one scale per row
    assert store_bytes(cfg, 100, "zstd", "cint16") < 0.5 * raw16
    # A disk that holds the cint16 store but not the complex64 one: only the complex64 run is refused.
    free = store_bytes(cfg, 1000, "zstd", "cint16") * 2
    usage = shutil.disk_usage(tmp_path)._replace(free=int(free))
    monkeypatch.setattr(shutil, "disk_usage", lambda _path: usage)
    check_store_space(tmp_path / "a.zarr", cfg, 1000, 16, "zstd", "cint16")
    with pytest.raises(frames.InputError, match="complex64 store"):
        check_store_space(tmp_path / "a.zarr", cfg, 1000, 16, "zstd", "complex64")


@pytest.mark.parametrize("command", ["simulate", "rd"])
def test_bad_precision_is_one_line(tmp_path, command, cli):
    source = _write(tmp_path, BASE) if command == "simulate" else tmp_path / "rec.npy"
    result = cli(command, str(source), "-o", "out.zarr", "--precision", "int8", cwd=tmp_path)
    _assert_one_line_error(result, "--precision", "int8")
    assert not (tmp_path / "out.zarr").exists()


def _detections(tmp_path: Path, scenario: Path, precision: str) -> pd.DataFrame:
    store = f"{precision}.zarr"
    args = ("--precision", precision, "--compress", "zstd", "--chunk-frames", "2")
    result = _skyradar("simulate", str(scenario), "-o", store, *args, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    result = _skyradar("process", store, "-o", f"{precision}.parquet", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    table = pd.read_parquet(tmp_path / f"{precision}.parquet")
    table["rb"], table["db"] = table.range_bin.round().astype(int), table.doppler_bin.round().astype(int)
    return table


@pytest.mark.slow  # minutes of CPU: `make test-slow` (make test stays under 10 min)
def test_process_on_cint16_store_matches_complex64(tmp_path):
    # Three frames 1 s before a head-on CPA over flat ground 500 m below: an intruder and clutter.
    scenario = _write(tmp_path, {**BASE, "start_s": 18.6, "duration_s": 0.6})
    exact, quantised = _detections(tmp_path, scenario, "complex64"), _detections(tmp_path, scenario, "cint16")
    assert (~exact.is_ground).sum() >= 1  # the intruder is seen: the comparison means something
    assert abs(len(quantised) - len(exact)) <= max(2, 0.02 * len(exact))
    key = ["frame", "rb", "db"]
    strong = exact[exact.snr_db >= 15.0]
    matched = strong.merge(quantised, on=key, suffixes=("", "_q"))
    assert len(matched) == len(strong)  # every strong detection is still there, in the same pixel
    # Bounds measured on circuit_three_intruders (non-ground, t = 36 s): 0.18 m, 0.004 m/s, 0.015 rad.
    assert np.abs(matched.range_m - matched.range_m_q).max() <= 0.5
    assert np.abs(matched.radial_velocity_mps - matched.radial_velocity_mps_q).max() <= 0.02
    air = matched[~matched.is_ground]
    for column in ("azimuth_rad", "elevation_rad"):
        assert np.abs(air[column] - air[f"{column}_q"]).max() <= 0.03
    # The pixel's power is what quantisation touches. The SNR is against the CFAR's local noise
    # estimate, whose training cells follow discrete decisions (a neighbour nulled or left out of
    # training): one flip moved a ground cell's SNR by 10 dB at the same power (-133.205 dBW both).
    assert np.abs(matched.power_db - matched.power_db_q).max() <= 0.1
    assert np.median(np.abs(matched.snr_db - matched.snr_db_q)) <= 0.1


def test_rd_writes_cint16_store_within_the_bound(tmp_path):
    from skyradar.io.recording_writer import write_recording
    from skyradar.process.rangedoppler import range_doppler

    cfg = RadarConfig.prototype_2022(n_doppler=6, range_limit_m=600.0)
    rng = np.random.default_rng(0)
    shape = (3, cfg.n_rx, cfg.n_doppler, cfg.samples_per_chirp)
    data = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)).astype(np.complex64)
    sidecar = write_recording(tmp_path / "rec.bin", data, cfg, dtype="complex64")
    args = ("-o", "run.zarr", "--chunk-frames", "2", "--precision", "cint16", "--compress", "blosc")
    result = _skyradar("rd", str(sidecar), *args, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    decoded = open_frames(tmp_path / "run.zarr")["iq"].values
    step = frames.xr.open_zarr(tmp_path / "run.zarr", consolidated=False)["iq_scale"].values.astype(float)
    for i in range(3):
        exact = range_doppler(data[i], cfg)
        error = np.maximum(np.abs(decoded[i].real - exact.real), np.abs(decoded[i].imag - exact.imag))
        # The FFT itself differs by float32 rounding between the two paths: allow 1e-6 of the peak.
        assert np.all(error <= step[i][:, None, :] * BOUND_STEPS + 1e-6 * np.abs(exact).max())
