"""RadarConfig, antenna pattern and mount against the thesis prototype's published numbers."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from skyradar.antenna import AntennaPattern, GainCut, read_gain_cut
from skyradar.config import SPEED_OF_LIGHT, Mount, RadarConfig
from skyradar.errors import InputError


def test_prototype_2022_derived_quantities():
    cfg = RadarConfig.prototype_2022()
    assert cfg.wavelength_m == pytest.approx(0.03181, abs=1e-5)
    assert cfg.rmax_m == pytest.approx(30_460, rel=1e-3)  # c Fs / (2 B PRF), about 30.5 km
    assert cfg.range_resolution_m == pytest.approx(14.99, abs=0.01)
    assert cfg.v_lim_mps == pytest.approx(4921 * cfg.wavelength_m / 4)
    assert cfg.v_lim_mps == pytest.approx(39.1, abs=0.1)
    assert cfg.doppler_resolution_mps == pytest.approx(2 * cfg.v_lim_mps / 250)
    assert cfg.samples_per_chirp == 2032
    assert cfg.n_range == 333 and cfg.range_axis_m[-1] < cfg.range_limit_m
    assert cfg.doppler_axis_mps[cfg.n_doppler // 2] == 0.0
    assert cfg.doppler_axis_mps[0] == pytest.approx(-cfg.v_lim_mps)
    assert cfg.n_rx == 4
    assert cfg.frame_duration_s == pytest.approx(250 / 4921)
    assert cfg.range_doppler_coupling_s == pytest.approx(9.425e9 / (10e6 * 4921))


def test_default_array_is_coplanar_half_wavelength_square():
    cfg = RadarConfig.prototype_2022()
    rx = cfg.rx_positions_m
    assert np.allclose(rx[:, 0], 0.0)
    spacing = np.linalg.norm(rx[1] - rx[0])
    assert spacing == pytest.approx(cfg.wavelength_m / 2)


def test_round_trip_through_json():
    cfg = RadarConfig.prototype_2022(
        mount=Mount.preset("side-right"), rx_calibration=np.exp(1j * np.array([0.1, -0.2, 0.3, 0.0]))
    )
    again = RadarConfig.from_json(cfg.to_json())
    assert again == cfg
    np.testing.assert_allclose(again.rx_calibration, cfg.rx_calibration)
    assert again.mount.yaw_deg == 90.0


@pytest.mark.parametrize(
    ("changes", "field"),
    [
        ({"rx_positions_m": np.zeros((4, 3))}, "rx_positions_m"),
        ({"prf_hz": -1.0}, "prf_hz"),
        ({"n_doppler": 1}, "n_doppler"),
        ({"range_limit_m": 40_000.0}, "range_limit_m"),
        ({"rx_positions_m": np.ones((4, 2))}, "rx_positions_m"),
        ({"rx_calibration": np.zeros(4)}, "rx_calibration"),
    ],
)
def test_bad_config_names_the_field(changes, field):
    with pytest.raises(InputError, match=field):
        RadarConfig.prototype_2022(**changes)


def test_default_pattern_beamwidth_and_peak():
    pattern = AntennaPattern.default(70.0)
    assert pattern.peak_db == pytest.approx(10 * np.log10(41253 / 70**2))
    for half in (np.radians(35.0), np.radians(-35.0)):
        assert pattern.peak_db - float(pattern.gain_db(half, 0.0)) == pytest.approx(3.0, abs=1e-2)
        assert pattern.peak_db - float(pattern.gain_db(0.0, half)) == pytest.approx(3.0, abs=1e-2)


@given(az=st.floats(-1.2, 1.2), el=st.floats(-1.2, 1.2))
def test_l1_and_l2_combinations(az, el):
    l1 = AntennaPattern.default(combine="L1")
    l2 = AntennaPattern.default(combine="L2")
    loss_az = l1.peak_db - float(l1.azimuth(az))
    loss_el = l1.peak_db - float(l1.elevation(el))
    assert float(l1.gain_db(az, el)) == pytest.approx(l1.peak_db - loss_az - loss_el)
    assert float(l2.gain_db(az, el)) == pytest.approx(l2.peak_db - np.hypot(loss_az, loss_el))
    assert float(l2.gain_db(az, el)) >= float(l1.gain_db(az, el)) - 1e-9


def test_asymmetric_cuts_from_csv(tmp_path):
    az = tmp_path / "az.csv"
    el = tmp_path / "el.csv"
    az.write_text("angle_deg,gain_db\n-90,-15\n-30,6\n0,10\n45,4\n90,-25\n")
    el.write_text("angle_deg,gain_db\n90,-20\n0,10\n-90,-20\n")  # unsorted on purpose
    pattern = AntennaPattern.from_csv(az, el)
    assert float(pattern.gain_db(np.radians(-30.0), 0.0)) == pytest.approx(6.0)
    assert float(pattern.gain_db(np.radians(45.0), 0.0)) == pytest.approx(4.0)
    assert float(pattern.gain_db(0.0, np.radians(45.0))) == pytest.approx(-5.0)


def test_bad_gain_cut_file(tmp_path):
    bad = tmp_path / "cut.csv"
    bad.write_text("angle,gain\n0,1\n10,2\n")
    with pytest.raises(InputError, match=r"cut\.csv: missing column 'angle_deg'"):
        read_gain_cut(bad)
    with pytest.raises(InputError, match="NaN"):
        GainCut(np.array([0.0, 1.0]), np.array([0.0, np.nan]))


def test_mount_presets_point_where_they_say():
    forward_down = Mount.preset("forward-down").rotation @ [1.0, 0.0, 0.0]
    assert forward_down[2] > 0  # boresight below the horizon (down is +z)
    side = Mount.preset("side-right").rotation @ [1.0, 0.0, 0.0]
    assert side[1] > 0.8  # boresight to the right wing
    with pytest.raises(InputError, match="preset"):
        Mount.preset("upside-down")


def test_speed_of_light():
    assert SPEED_OF_LIGHT == 299_792_458.0
