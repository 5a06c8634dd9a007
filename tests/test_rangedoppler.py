"""ADC cube -> range-Doppler cube: exactness against numpy, normalisation, window leakage, errors."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal
from hypothesis import given, settings
from hypothesis import strategies as st

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.process.rangedoppler import (
    RangeDopplerProcessor,
    get_window,
    range_doppler,
    rd_frames_dataset,
    window_gain_db,
    window_noise_gain_db,
)

CFG = RadarConfig.prototype_2022()
NS, NV = CFG.samples_per_chirp, CFG.n_doppler
WINDOWS = ["none", "hann", "hamming", "blackmanharris", "chebyshev", "chebyshev:60"]


def tone(range_bin: float, doppler_bin: float, amp: complex = 1.0, cfg: RadarConfig = CFG) -> np.ndarray:
    """Complex tone at a (fractional) range bin and unshifted Doppler bin, all channels equal."""
    t = np.arange(cfg.samples_per_chirp) / cfg.fs_hz
    n = np.arange(cfg.n_doppler)
    fast = np.exp(2j * np.pi * range_bin * (cfg.fs_hz / cfg.samples_per_chirp) * t)
    slow = np.exp(2j * np.pi * doppler_bin * n / cfg.n_doppler)
    frame = amp * slow[:, None] * fast[None, :]
    return np.broadcast_to(frame, (cfg.n_rx, *frame.shape)).astype(np.complex64)


def reference(adc: np.ndarray, rw: str, dw: str, cfg: RadarConfig = CFG) -> np.ndarray:
    """Plain numpy implementation (float64) of the documented processing."""
    wr, wd = get_window(rw, adc.shape[2]), get_window(dw, cfg.n_doppler)
    r = np.fft.fft(adc.astype(np.complex128) * wr, n=cfg.samples_per_chirp, axis=-1)[..., : cfg.n_range]
    rd = np.fft.fftshift(np.fft.fft(r * wd[None, :, None], axis=1), axes=1) / (adc.shape[2] * cfg.n_doppler)
    return (rd / cfg.rx_calibration[:, None, None]).transpose(2, 1, 0)


@pytest.mark.parametrize("method", ["pruned", "fft"])
@pytest.mark.parametrize("rw,dw", [("hann", "hann"), ("chebyshev:70", "blackmanharris"), ("none", "hamming")])
def test_matches_numpy_reference(method, rw, dw):
    rng = np.random.default_rng(3)
    adc = (rng.standard_normal((CFG.n_rx, NV, NS)) + 1j * rng.standard_normal((CFG.n_rx, NV, NS))).astype(
        np.complex64
    )
    out = RangeDopplerProcessor(CFG, rw, dw, method=method)(adc)
    ref = reference(adc, rw, dw)
    assert out.shape == (CFG.n_range, NV, CFG.n_rx) and out.dtype == np.complex64
    assert np.abs(out - ref).max() < 1e-5 * np.abs(ref).max()


@pytest.mark.parametrize("dtype", [np.complex64, np.complex128, np.int16])
def test_split_dft_paths_match_the_full_fft(dtype):
    # 2032 = 16 x 127 (compiled radix-4x4 path for complex64), 2040 = 120 x 17 (numpy path)
    for cfg in (CFG, RadarConfig(prf_hz=10e6 / 2040)):
        rng = np.random.default_rng(4)
        shape = (cfg.n_rx, cfg.n_doppler, cfg.samples_per_chirp)
        adc = rng.standard_normal(shape) * 1000
        adc = (adc + 1j * rng.standard_normal(shape) * 1000) if dtype != np.int16 else adc
        adc = adc.astype(dtype)
        pruned = RangeDopplerProcessor(cfg, "hann", "hamming", method="pruned")
        assert pruned.method == "pruned"
        ref = reference(adc, "hann", "hamming", cfg)
        assert np.abs(pruned(adc) - ref).max() < 1e-5 * np.abs(ref).max()


def test_pruned_is_chosen_for_the_prototype_and_fft_for_smooth_lengths():
    assert RangeDopplerProcessor(CFG).method == "pruned"  # 2032 = 16 * 127
    smooth = RadarConfig(fs_hz=10e6, prf_hz=10e6 / 2048)  # 2048 samples per chirp
    assert smooth.samples_per_chirp == 2048 and RangeDopplerProcessor(smooth).method == "fft"


@pytest.mark.parametrize("window", WINDOWS)
def test_on_bin_tone_power_is_amplitude_times_coherent_gain(window):
    adc = tone(57, 30, amp=0.5)
    rd = range_doppler(adc, CFG, window, window)
    expected_db = 10 * np.log10(0.25) + window_gain_db(window, window)
    assert np.unravel_index(np.abs(rd[..., 0]).argmax(), rd.shape[:2]) == (57, 30 + NV // 2)
    assert 10 * np.log10(abs(rd[57, 30 + NV // 2, 0]) ** 2) == pytest.approx(expected_db, abs=1e-3)


def test_window_gain_values_match_closed_form():
    assert window_gain_db("none", "none") == pytest.approx(0.0)
    assert window_gain_db("hann", "hann") == pytest.approx(20 * np.log10(0.25), abs=1e-9)
    assert window_gain_db("hamming", "none") == pytest.approx(20 * np.log10(0.54), abs=1e-9)
    # Hann: mean(w^2) = 3/8 per axis.
    assert window_noise_gain_db("hann", "hann") == pytest.approx(20 * np.log10(3 / 8), abs=1e-9)


def dtft_db(w: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Window spectrum |W(f)| at fractional bin offsets, dB relative to W(0)."""
    n = np.arange(w.size)
    spec = np.abs(np.exp(-2j * np.pi * np.outer(offsets, n) / w.size) @ w)
    return 20 * np.log10(spec / w.sum())


@settings(max_examples=20, deadline=None)
@given(
    window=st.sampled_from(WINDOWS[1:]),
    frac=st.floats(0.05, 0.95),
    axis=st.sampled_from(["range", "doppler"]),
)
def test_off_bin_leakage_follows_the_scipy_window_spectrum(window, frac, axis):
    k0, j0 = 150, 20
    adc = tone(k0 + frac, j0) if axis == "range" else tone(k0, j0 + frac)
    rd = range_doppler(adc, CFG, window, window)
    peak = np.abs(rd[k0, j0 + NV // 2, 0]) ** 2
    if axis == "range":
        m = np.arange(-12, 13)
        measured = np.abs(rd[k0 + m, j0 + NV // 2, 0]) ** 2
        w = scipy.signal.get_window(get_window_name(window), NS)
    else:
        m = np.arange(-12, 13)
        measured = np.abs(rd[k0, j0 + NV // 2 + m, 0]) ** 2
        w = scipy.signal.get_window(get_window_name(window), NV)
    expected = dtft_db(w, m - frac) - dtft_db(w, np.array([-frac]))[0]
    got = 10 * np.log10(measured / peak)
    visible = expected > -100  # float32 rounding floor
    assert np.all(np.abs(got[visible] - expected[visible]) < 1.0), (got, expected)


def get_window_name(window: str):
    name, _, param = window.partition(":")
    mapping = {
        "hann": "hann",
        "hamming": "hamming",
        "blackmanharris": "blackmanharris",
        "chebyshev": "chebwin",
    }
    key = mapping[name]
    return (key, float(param or 80)) if key == "chebwin" else key


def test_chebyshev_sidelobes_sit_at_the_requested_level():
    # Far from the main lobe, every sidelobe of a Chebyshev window has the same height.
    adc = tone(150.5, 20)
    rd = range_doppler(adc, CFG, "chebyshev:60", "none")
    prof = 20 * np.log10(np.abs(rd[:, 20 + NV // 2, 0]) / np.abs(rd[:, 20 + NV // 2, 0]).max())
    far = prof[np.r_[100:140, 161:200]]
    assert far.max() == pytest.approx(-60.0, abs=1.0)


def test_white_noise_power_per_pixel():
    rng = np.random.default_rng(0)
    sigma2 = 4.0
    adc = (rng.standard_normal((CFG.n_rx, NV, NS)) + 1j * rng.standard_normal((CFG.n_rx, NV, NS))) * np.sqrt(
        sigma2 / 2
    )
    for window in ("none", "hann"):
        rd = range_doppler(adc, CFG, window, window)
        expected = sigma2 / (NS * NV) * 10 ** (window_noise_gain_db(window, window) / 10)
        assert np.mean(np.abs(rd) ** 2) == pytest.approx(expected, rel=0.02)


def test_calibration_divides_each_channel():
    gains = np.array([1.0, 0.8 * np.exp(0.3j), 1.2 * np.exp(-1.1j), 0.5j])
    adc = tone(40, -10) * gains[:, None, None].astype(np.complex64)
    cal = range_doppler(adc, CFG, calibration=gains)
    plain = range_doppler(tone(40, -10), CFG)
    assert np.allclose(cal, plain, atol=1e-6)
    cfg_cal = CFG.replace(rx_calibration=gains)
    assert np.allclose(range_doppler(adc, cfg_cal), plain, atol=1e-6)


def test_remove_dc_suppresses_adc_offset():
    adc = tone(40, 5) + np.complex64(3.0 + 2.0j)
    kept = range_doppler(adc, CFG, remove_dc=False)
    removed = range_doppler(adc, CFG, remove_dc=True)
    assert abs(kept[0, NV // 2, 0]) == pytest.approx(abs(3 + 2j) * 0.25, rel=1e-4)  # Hann x Hann gain
    assert abs(removed[0, NV // 2, 0]) < 1e-5
    assert abs(removed[40, 5 + NV // 2, 0]) == pytest.approx(abs(kept[40, 5 + NV // 2, 0]), rel=1e-4)


def test_real_int16_input_and_short_chirps():
    t = np.arange(NS) / CFG.fs_hz
    real = np.round(1000 * np.cos(2 * np.pi * 80 * CFG.prf_hz * t)).astype(np.int16)
    adc = np.broadcast_to(real, (CFG.n_rx, NV, NS))
    rd = range_doppler(adc, CFG)
    assert np.unravel_index(np.abs(rd[..., 0]).argmax(), rd.shape[:2]) == (80, NV // 2)
    short = tone(80, 0)[..., :2000]  # fewer valid samples: zero-padded, same bin spacing
    rd = range_doppler(short, CFG)
    assert np.allclose(rd, reference(short, "hann", "hann"), atol=1e-6)
    assert np.unravel_index(np.abs(rd[..., 0]).argmax(), rd.shape[:2]) == (80, NV // 2)


@pytest.mark.parametrize("n_valid", [NS, 1901])
def test_compiled_path_with_dc_removal_and_short_chirps_matches_numpy(n_valid):
    rng = np.random.default_rng(11)
    shape = (CFG.n_rx, NV, n_valid)
    adc = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape) + (0.7 - 0.4j)).astype(np.complex64)
    out = RangeDopplerProcessor(CFG, "hann", "blackmanharris", n_samples=n_valid)(adc, remove_dc=True)
    centred = adc.astype(np.complex128) - adc.astype(np.complex128).mean(axis=-1, keepdims=True)
    ref = reference(centred, "hann", "blackmanharris")
    assert np.abs(out - ref).max() < 1e-5 * np.abs(ref).max()


@pytest.mark.parametrize("workers", [1, 2])
def test_many_frames_in_flight_give_the_per_frame_cubes_in_order(workers):
    frames = [tone(30 + 7 * i, i - 3, amp=1 + i) for i in range(5)]
    proc = RangeDopplerProcessor(CFG, workers=workers)
    batch = list(proc.many(frames, remove_dc=True))
    assert len(batch) == 5
    for b, f in zip(batch, frames, strict=True):
        one = proc(f, remove_dc=True)
        assert np.abs(b - one).max() <= 1e-6 * np.abs(one).max()
    with pytest.raises(InputError, match="shape"):
        list(proc.many([frames[0], np.zeros((3, NV, NS), np.complex64)]))


@pytest.mark.parametrize(
    "kwargs,match",
    [
        ({"range_window": "kaiser"}, "unknown window"),
        ({"range_window": "hann:3"}, "takes no parameter"),
        ({"doppler_window": "chebyshev:-5"}, "sidelobe"),
        ({"calibration": np.ones(3)}, "calibration"),
        ({"method": "dft"}, "method"),
    ],
)
def test_bad_options_raise_input_error(kwargs, match):
    with pytest.raises(InputError, match=match):
        range_doppler(tone(10, 0), CFG, **kwargs)


def test_bad_shapes_raise_input_error():
    with pytest.raises(InputError, match="shape"):
        range_doppler(np.zeros((3, NV, NS), np.complex64), CFG)
    with pytest.raises(InputError, match="dimensions"):
        range_doppler(np.zeros((NV, NS), np.complex64), CFG)
    with pytest.raises(InputError, match="samples per chirp"):
        range_doppler(np.zeros((CFG.n_rx, NV, NS + 1), np.complex64), CFG)


def test_rd_frames_dataset_has_the_frames_form():
    frames = np.stack([tone(30, 3), tone(60, -7)])
    ds = rd_frames_dataset(frames, np.array([0.0, 0.106]), CFG)
    assert ds.iq.dims == ("time", "range", "doppler", "rx")
    assert ds.iq.shape == (2, CFG.n_range, NV, CFG.n_rx)
    assert np.allclose(ds.range.values, CFG.range_axis_m) and np.allclose(
        ds.doppler.values, CFG.doppler_axis_mps
    )
    k, j = np.unravel_index(np.abs(ds.iq.values[1, ..., 0]).argmax(), (CFG.n_range, NV))
    assert (k, j) == (60, NV // 2 - 7)
    with pytest.raises(InputError, match="frame times"):
        rd_frames_dataset(frames, np.array([0.0]), CFG)


def test_benchmark_baseline_computes_the_same_cube():
    from skyradar.benchmarks.range_doppler import baseline_range_doppler

    rng = np.random.default_rng(9)
    adc = (rng.standard_normal((CFG.n_rx, NV, NS)) + 1j * rng.standard_normal((CFG.n_rx, NV, NS))).astype(
        np.complex64
    )
    ours = range_doppler(adc, CFG, "none", "none")
    assert np.allclose(baseline_range_doppler(adc, CFG), ours, atol=1e-5 * np.abs(ours).max())


def test_blas_threads_are_restored_after_concurrent_calls():
    from concurrent.futures import ThreadPoolExecutor

    from threadpoolctl import threadpool_info

    before = [lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"]
    adc = tone(20, 3)
    with ThreadPoolExecutor(3) as pool:
        results = list(pool.map(lambda _: range_doppler(adc, CFG), range(6)))
    assert all(np.array_equal(r, results[0]) for r in results)
    assert [lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"] == before
