"""Impairments: positions and levels of spurs, zero-Doppler line, near-range leakage; channel
errors undone by calibration; noise level; ADC and image forms agree; the thesis preset."""

from __future__ import annotations

import numpy as np
import pytest

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.process.rangedoppler import range_doppler, window_gain_db
from skyradar.sim.impairments import (
    ImpairmentConfig,
    apply_channel_errors,
    apply_impairments,
    apply_impairments_adc,
    apply_impairments_frames,
    channel_errors,
    dbm_to_w,
    near_range_leakage,
    receiver_noise,
    spur_adc,
    spur_cube,
    thesis_flight_look,
    zero_doppler_line,
)
from skyradar.sim.raw import simulate_adc

CFG = RadarConfig.prototype_2022()
NV = CFG.n_doppler


def power_dbm(x) -> np.ndarray:
    return 10 * np.log10(np.abs(x) ** 2) + 30


def test_listed_spurs_land_on_their_pixel_with_their_power_and_wrap():
    spurs = [(600.0, 10.0, -120.0), (1500.0, 39.16 * 2 + 5.0, -125.0)]  # second one aliased
    cube = spur_cube(CFG, spurs, leakage=False, seed=3)
    j1 = int(round(10.0 / CFG.doppler_resolution_mps)) + NV // 2
    j2 = int(round(5.0 / CFG.doppler_resolution_mps)) + NV // 2
    assert np.allclose(power_dbm(cube[40, j1]), -120.0, atol=1e-3)
    assert np.allclose(power_dbm(cube[100, j2]), -125.0, atol=1e-3)
    assert np.count_nonzero(np.abs(cube).sum(axis=2)) == 2
    assert np.array_equal(cube, spur_cube(CFG, spurs, leakage=False, seed=3))  # same every frame
    leaky = spur_cube(CFG, spurs[:1], leakage=True, seed=3)
    assert np.count_nonzero(np.abs(leaky).sum(axis=2)) == 9
    assert np.allclose(leaky[41, j1] / leaky[40, j1], -0.5) and np.allclose(
        leaky[41, j1 + 1] / leaky[40, j1], 0.25
    )


def test_spur_map_pixels_get_the_map_level():
    spur_map = np.zeros((CFG.n_range, NV), bool)
    spur_map[[5, 200], [17, 240]] = True
    cube = spur_cube(CFG, spur_map=spur_map, map_power_dbm=-128.0, leakage=False)
    assert np.allclose(power_dbm(cube[5, 17]), -128.0, atol=1e-3)
    assert np.allclose(power_dbm(cube[200, 240]), -128.0, atol=1e-3)
    with pytest.raises(InputError, match="spur map shape"):
        spur_cube(CFG, spur_map=np.zeros((3, 3), bool))
    with pytest.raises(InputError, match="range_m 9000"):
        spur_cube(CFG, [(9000.0, 0.0, -120.0)])


def test_adc_spur_matches_the_image_spur_after_the_fft():
    spurs = [(450.0, -12.0, -118.0)]
    rd = range_doppler(spur_adc(CFG, spurs, seed=2), CFG, "hann", "hann")
    img = spur_cube(CFG, spurs, leakage=True, seed=2) * np.float32(10 ** (window_gain_db() / 20))
    k, j = 30, int(round(-12.0 / CFG.doppler_resolution_mps)) + NV // 2
    # Hann on-bin: centre and its 8 neighbours are exactly the image spur with leakage.
    near = (slice(k - 1, k + 2), slice(j - 1, j + 2))
    assert np.allclose(rd[near], img[near], rtol=0, atol=1e-4 * abs(img[k, j, 0]))


def test_zero_doppler_line_is_at_zero_velocity_and_falls_with_range():
    cube = zero_doppler_line(CFG, power_dbm_at_100m=-115.0, falloff_db_per_decade=20.0)
    power = np.abs(cube[..., 0]) ** 2
    assert np.count_nonzero(power[:, NV // 2]) == CFG.n_range and np.count_nonzero(power) == CFG.n_range
    k100, k1000 = 100 / CFG.range_resolution_m, 1000 / CFG.range_resolution_m
    r = CFG.range_axis_m
    for k in (int(k100), int(k1000), 300):
        assert power_dbm(cube[k, NV // 2, 0]) == pytest.approx(-115.0 - 20 * np.log10(r[k] / 100.0), abs=1e-3)
    wide = zero_doppler_line(CFG, width_bins=3)
    assert np.count_nonzero(np.abs(wide[..., 0]).sum(axis=0)) == 3


def test_near_range_leakage_covers_all_velocities_below_the_range():
    rng = np.random.default_rng(0)
    cube = near_range_leakage(CFG, power_dbm=-110.0, range_m=100.0, rng=rng)
    power = np.abs(cube[..., 0]) ** 2
    inside = CFG.range_axis_m <= 100.0
    assert np.all(power[inside].min(axis=1) > 0) and not np.any(power[~inside])
    # Mean over Doppler at zero range: the set level (exponential statistics, 250 samples).
    assert 10 * np.log10(power[0].mean()) + 30 == pytest.approx(-110.0, abs=1.0)
    assert 10 * np.log10(power[6].mean()) + 30 == pytest.approx(
        -110.0 - 30 * CFG.range_axis_m[6] / 100, abs=1.0
    )


def test_channel_errors_are_undone_by_calibration():
    errors = channel_errors(4, gain_sd_db=1.0, phase_sd_deg=20.0, seed=7)
    assert errors[0] == 1.0 and np.allclose(
        errors, channel_errors(4, gain_sd_db=1.0, phase_sd_deg=20.0, seed=7)
    )
    adc = simulate_adc(CFG, [[900.0, 100.0, -50.0]], noise=False)
    clean = range_doppler(adc, CFG)
    measured = apply_channel_errors(adc, errors, layout="adc")
    assert np.allclose(
        range_doppler(measured, CFG, calibration=errors), clean, atol=1e-6 * np.abs(clean).max()
    )
    # Same thing done on the image: linear, so identical.
    assert np.allclose(
        range_doppler(measured, CFG), apply_channel_errors(clean, errors), atol=1e-6 * np.abs(clean).max()
    )
    with pytest.raises(InputError, match="need 4 gains"):
        channel_errors(4, gain_db=[0, 1])


def test_receiver_noise_level_from_noise_figure():
    noise = receiver_noise(CFG, rng=np.random.default_rng(1))
    assert np.mean(np.abs(noise) ** 2) == pytest.approx(CFG.noise_power_w, rel=0.01)
    louder = receiver_noise(CFG, noise_figure_db=CFG.noise_figure_db + 10, rng=np.random.default_rng(1))
    assert np.mean(np.abs(louder) ** 2) == pytest.approx(10 * CFG.noise_power_w, rel=0.01)


def test_config_from_dict_switches_and_errors():
    imp = ImpairmentConfig.from_dict(
        {
            "spurs": {"spurs": [{"range_m": 600, "velocity_mps": 10, "power_dbm": -120}], "leakage": False},
            "zero_doppler": {"enabled": False},
            "noise": {},
        }
    )
    cube = apply_impairments(np.zeros((CFG.n_range, NV, CFG.n_rx), np.complex64), CFG, imp, frame_index=1)
    assert np.allclose(power_dbm(cube[40, NV // 2 + 32]), -120.0, atol=0.1)  # spur on top of noise
    assert np.mean(np.abs(cube) ** 2) == pytest.approx(CFG.noise_power_w, rel=0.02)  # no zero-Doppler line
    with pytest.raises(InputError, match=r"field 'spurs.spurs.0.power_dbm'"):
        ImpairmentConfig.from_dict({"spurs": {"spurs": [{"range_m": 600, "velocity_mps": 1}]}})
    with pytest.raises(InputError, match="field 'sparks'"):
        ImpairmentConfig.from_dict({"sparks": {}})


def test_preset_in_config_with_overrides():
    imp = ImpairmentConfig.from_dict(
        {"preset": "thesis_flight_look", "seed": 3, "zero_doppler": {"width_bins": 3}}
    )
    preset = thesis_flight_look(seed=3)
    assert imp.spurs == preset.spurs and imp.seed == 3 and imp.ground_reflectivity_db == -10.0
    assert imp.zero_doppler.width_bins == 3 and imp.zero_doppler.power_dbm_at_100m == -115.0
    with pytest.raises(InputError, match="field 'preset'"):
        ImpairmentConfig.from_dict({"preset": "rainy_day"})


def test_spur_map_file(tmp_path):
    spur_map = np.zeros((CFG.n_range, NV), bool)
    spur_map[9, 9] = True
    np.save(tmp_path / "map.npy", spur_map)
    imp = ImpairmentConfig.from_dict({"spurs": {"map_file": str(tmp_path / "map.npy"), "leakage": False}})
    cube = apply_impairments(np.zeros((CFG.n_range, NV, CFG.n_rx), np.complex64), CFG, imp)
    assert np.allclose(power_dbm(cube[9, 9]), -130.0, atol=1e-3)
    bad = ImpairmentConfig.from_dict({"spurs": {"map_file": str(tmp_path / "none.npy")}})
    with pytest.raises(InputError, match="cannot read spur map"):
        apply_impairments(cube, CFG, bad)


def test_thesis_preset_gives_the_flight_data_look():
    imp = thesis_flight_look()
    assert imp.ground_reflectivity_db < 0
    frames = [
        apply_impairments(receiver_noise(CFG, rng=np.random.default_rng(i)), CFG, imp, frame_index=i)
        for i in range(3)
    ]
    noise_dbm = 10 * np.log10(CFG.noise_power_w) + 30
    for cube in frames:
        p = power_dbm(cube[..., 0])
        # fixed bright spurs in every frame, at the same pixels
        for spur in imp.spurs.spurs:
            k = int(round(spur.range_m / CFG.range_resolution_m))
            j = int(np.floor(spur.velocity_mps / CFG.doppler_resolution_mps + 0.5)) + NV // 2
            assert p[k, j] > noise_dbm + 20
        # returns at all velocities near 100 m range
        assert np.median(p[2]) > noise_dbm + 20
        # bright vertical line at V = 0, far beyond the leakage region
        assert np.median(p[20:, NV // 2]) > np.median(p[20:, :]) + 15
    assert not np.allclose(frames[0][2], frames[1][2])  # leakage changes frame to frame


def test_adc_impairments_match_image_impairments():
    imp = ImpairmentConfig.from_dict(
        {
            "spurs": {"spurs": [{"range_m": 450, "velocity_mps": -12, "power_dbm": -118}]},
            "channel_errors": {"phase_deg": [0, 20, -40, 90], "gain_db": [0, 1, -1, 0.5]},
        }
    )
    adc = simulate_adc(CFG, [[1200.0, 0.0, 0.0]], [[-5.0, 0, 0]], noise=False)
    via_adc = range_doppler(apply_impairments_adc(adc, CFG, imp), CFG, "none", "none")
    via_img = apply_impairments(
        range_doppler(adc, CFG, "none", "none"), CFG, imp.model_copy(update={"spurs": None})
    )
    # Without windows the ADC spur is exactly the single image pixel; channel errors are linear.
    spur = spur_cube(CFG, [(450, -12, -118)], leakage=False)
    assert np.allclose(via_adc, via_img + spur, rtol=0, atol=1e-3 * np.sqrt(dbm_to_w(-118)))


def test_frames_helper_is_chunking_invariant():
    imp = thesis_flight_look(seed=2)
    block = np.zeros((4, CFG.n_range, NV, CFG.n_rx), np.complex64)
    whole = apply_impairments_frames(block, CFG, imp)
    parts = np.concatenate(
        [
            apply_impairments_frames(block[:2], CFG, imp, [0, 1]),
            apply_impairments_frames(block[2:], CFG, imp, [2, 3]),
        ]
    )
    assert np.array_equal(whole, parts)


def test_scenario_file_impairments_section(tmp_path):
    import yaml

    from skyradar.scene.scenario import example_scenario, load_scenario

    data = yaml.safe_load(example_scenario("ch2_flat_forward").read_text())
    data["impairments"] = {"preset": "thesis_flight_look", "near_range": {"enabled": False}}
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(data))
    built = load_scenario(tmp_path / "s.yaml").build()
    assert built.impairments.ground_reflectivity_db == -10.0 and not built.impairments.near_range.enabled
    data["impairments"] = {"spurs": {"spurs": [{"range_m": 5.0, "velocity_mps": 0.0}]}}
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(data))
    with pytest.raises(InputError, match="impairments.spurs.spurs.0.power_dbm"):
        load_scenario(tmp_path / "s.yaml")
