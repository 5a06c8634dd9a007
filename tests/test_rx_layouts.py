"""Named receive arrays: geometry, scenario key, encounter option, and what the kite buys."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from cli_helpers import assert_one_line_error, small_scenario
from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.process.doa import direction_from_angles, estimate_directions, steering_vector
from skyradar.rx_layouts import RX_LAYOUTS, rx_layout_m
from skyradar.scene.scenario import Scenario

WAVELENGTH_M = RadarConfig.prototype_2022().wavelength_m


def test_square_is_the_prototype_default():
    np.testing.assert_array_equal(
        RadarConfig.prototype_2022().rx_positions_m, rx_layout_m("square", WAVELENGTH_M)
    )


@pytest.mark.parametrize("name", RX_LAYOUTS)
def test_every_layout_is_planar_with_half_wavelength_pairs_spanning_the_plane(name):
    # DoA unwraps longer baselines from the pairs at most lambda/2 apart: those must span y and z.
    rx = rx_layout_m(name, WAVELENGTH_M)
    n = rx.shape[0]
    assert rx.shape[1] == 3 and n >= 4 and np.all(rx[:, 0] == 0.0)
    short = [
        rx[j] - rx[i]
        for i in range(n)
        for j in range(i + 1, n)
        if np.linalg.norm(rx[j] - rx[i]) <= WAVELENGTH_M / 2 + 1e-12
    ]
    assert np.linalg.matrix_rank(np.array(short)[:, 1:]) == 2


def test_kite_has_no_centre_of_symmetry_and_the_square_has():
    for name, symmetric in (("square", True), ("kite", False)):
        rx = rx_layout_m(name, WAVELENGTH_M)
        mirrored = 2 * rx.mean(axis=0) - rx
        same = all(np.min(np.linalg.norm(rx - m, axis=1)) < 1e-12 for m in mirrored)
        assert same is symmetric


@pytest.mark.parametrize(("az_deg", "el_deg"), [(0.0, 0.0), (30.0, -20.0), (-25.0, 28.0), (5.0, -34.0)])
def test_kite_directions_are_exact_without_noise_across_the_beam(az_deg, el_deg):
    # The one-wavelength vertical baseline wraps; the estimator must unwrap it, not report a grating lobe.
    cfg = RadarConfig.prototype_2022(rx_positions_m="kite")
    u = direction_from_angles(np.radians([az_deg]), np.radians([el_deg]))
    np.testing.assert_allclose(estimate_directions(steering_vector(u, cfg), cfg), u, atol=1e-9)


def _spec(radar: dict) -> dict:
    return small_scenario("layout", duration_s=1.0, frame_rate_hz=2.0, radar=radar)


def test_scenario_rx_layout_names_the_array():
    cfg = Scenario.from_dict(_spec({"rx_layout": "kite"})).radar_config()
    np.testing.assert_allclose(cfg.rx_positions_m, rx_layout_m("kite", cfg.wavelength_m))


def test_a_head_overrides_the_top_level_layout():
    spec = _spec({"rx_layout": "kite"}) | {
        "radars": [
            {"name": "nose", "mount": "forward"},
            {"name": "tail", "mount": "forward", "radar": {"rx_layout": "square"}},
        ],
    }
    heads = Scenario.from_dict(spec).build().heads
    assert [h.config.rx_positions_m[3, 2] > 0.02 for h in heads] == [True, False]


@pytest.mark.parametrize(
    ("radar", "needles"),
    [
        ({"rx_layout": "ring"}, ["'radar.rx_layout'", "'ring'"]),
        (
            {"rx_layout": "kite", "rx_positions_m": [[0, 0, 0], [0, 0.01, 0], [0, 0, 0.01]]},
            ["'radar'", "not both"],
        ),
    ],
)
def test_bad_layout_is_one_line(tmp_path, radar, needles, cli):
    import yaml

    (tmp_path / "s.yaml").write_text(yaml.safe_dump(_spec(radar)))
    result = cli("simulate", "s.yaml", "--output", "r.zarr", cwd=tmp_path)
    assert_one_line_error(result, "s.yaml", *needles)
    assert not (tmp_path / "r.zarr").exists()


def test_config_refuses_an_unknown_layout_name():
    with pytest.raises(InputError, match="'ring'"):
        RadarConfig.prototype_2022(rx_positions_m="ring")


def test_encounter_scenario_carries_the_layout_to_every_head():
    from skyradar.experiments.encounter_set import encounter_scenario, make_encounters
    from skyradar.scene.examples import THREE_HEAD_RADARS

    p = pd.Series(make_encounters(1, 0).iloc[0])
    spec = encounter_scenario(p, 0.0, 2.0, 2.0, 0, radars=THREE_HEAD_RADARS, rx_layout="kite")
    heads = Scenario.from_dict(spec).build().heads
    assert len(heads) == 3
    for h in heads:
        np.testing.assert_allclose(h.config.rx_positions_m, rx_layout_m("kite", h.config.wavelength_m))
    plain = Scenario.from_dict(encounter_scenario(p, 0.0, 2.0, 2.0, 0)).radar_config()
    np.testing.assert_array_equal(plain.rx_positions_m, rx_layout_m("square", plain.wavelength_m))
