"""Bin <-> unit conversions (skyradar.units, RadarConfig methods) against closed-form values."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from skyradar.config import SPEED_OF_LIGHT, RadarConfig
from skyradar.units import centred_bin, centred_bin_value, nearest_bin

CFG = RadarConfig.prototype_2022()
DR = SPEED_OF_LIGHT / (2 * 10e6)  # c / 2B of the prototype, independent of the config code
DV = 2 * (4921 * SPEED_OF_LIGHT / 9.425e9 / 4) / 250  # 2 VLim / nV, VLim = PRF lambda / 4


def test_closed_form_prototype_values():
    assert np.isclose(CFG.range_resolution_m, DR) and np.isclose(CFG.doppler_resolution_mps, DV)
    assert CFG.range_bin(0.0) == 0 and CFG.range_bin(100 * DR) == 100
    assert CFG.range_bin(100.49 * DR) == 100 and CFG.range_bin(100.51 * DR) == 101
    assert CFG.doppler_bin(0.0) == 125 and CFG.doppler_bin(DV) == 126 and CFG.doppler_bin(-125 * DV) == 0
    assert CFG.doppler_bin(124.4 * DV) == 249 and CFG.doppler_bin(125 * DV) == 0  # +VLim wraps onto -VLim
    assert np.isclose(CFG.radial_velocity_at_bin_mps(125 + 10), 10 * DV)
    assert np.isclose(CFG.range_at_bin_m(7.25), 7.25 * DR)


def test_ties_round_up_not_to_even():
    # numpy's round(): 0.5 -> 0, 2.5 -> 2; the thesis axis convention rounds ties up.
    assert nearest_bin([0.5, 1.5, 2.5, -0.5, -1.5], 1.0).tolist() == [1, 2, 3, 0, -1]
    assert centred_bin([0.5, 2.5], 1.0, 8).tolist() == [5, 7]


def test_range_bin_includes_range_doppler_coupling():
    v = 20.0
    expected = np.floor((1000.0 + v * 9.425e9 / (10e6 * 4921)) / DR + 0.5)
    assert CFG.range_bin(1000.0, v) == expected


def test_axes_use_the_same_formula():
    assert np.array_equal(CFG.doppler_axis_mps, CFG.radial_velocity_at_bin_mps(np.arange(250)))
    assert np.array_equal(CFG.doppler_bin(CFG.doppler_axis_mps), np.arange(250))
    assert np.array_equal(CFG.range_bin(CFG.range_axis_m), np.arange(CFG.n_range))


@settings(max_examples=200, deadline=None)
@given(st.integers(-5000, 5000), st.integers(2, 513))
def test_bin_velocity_bin_round_trip(j, n):
    cfg = CFG.replace(n_doppler=n)
    v = cfg.radial_velocity_at_bin_mps(j)
    assert cfg.doppler_bin(v) == j % n


@settings(max_examples=200, deadline=None)
@given(st.floats(-1e4, 1e4, allow_nan=False), st.integers(2, 64))
def test_velocity_to_bin_is_nearest_centre_modulo_the_axis(v, n):
    step = 0.37
    j = centred_bin(v, step, n)
    assert 0 <= j < n
    err = v - centred_bin_value(j, step, n)
    period = n * step
    err = (err + period / 2) % period - period / 2  # distance to the bin centre, modulo the wrap
    assert abs(err) <= step / 2 + 1e-9 * max(1.0, abs(v))
