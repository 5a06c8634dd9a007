"""Measured antenna cuts from CSV: exact interpolated gains, scenario paths, one-line errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from cli_helpers import assert_one_line_error as _assert_one_line_error
from cli_helpers import skyradar as _skyradar
from skyradar.antenna import AntennaPattern, GainCut, read_gain_cut, read_gain_cuts
from skyradar.errors import InputError
from skyradar.io.frames import open_frames, radar_config_of
from skyradar.scene.scenario import load_scenario
from skyradar.sim.image import two_way_gain_table

AZ = "angle_deg,gain_db\n-90,-21\n-40,2\n0,11\n30,5\n90,-17\n"
EL = "angle_deg,gain_db\n90,-25\n20,4\n0,11\n-90,-19\n"  # decreasing: allowed
SCENARIO = {
    "name": "measured",
    "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    "mount": "forward",
    "radar": {
        "range_limit_m": 1000,
        "antenna": {"azimuth_csv": "cuts/az.csv", "elevation_csv": "cuts/el.csv"},
    },
    "ownship": {"type": "straight", "start_ned_m": [0, 0, -500], "heading_deg": 0, "speed_mps": 40},
    "frame_rate_hz": 5.0,
    "duration_s": 0.4,
}


def _scenario_with_cuts(tmp_path: Path, az: str = AZ, el: str = EL) -> Path:
    (tmp_path / "scen" / "cuts").mkdir(parents=True)
    (tmp_path / "scen" / "cuts" / "az.csv").write_text(az)
    (tmp_path / "scen" / "cuts" / "el.csv").write_text(el)
    path = tmp_path / "scen" / "s.yaml"
    path.write_text(yaml.safe_dump(SCENARIO))
    return path


def test_two_files_give_exactly_the_interpolated_gains(tmp_path):
    (tmp_path / "az.csv").write_text(AZ)
    (tmp_path / "el.csv").write_text(EL)
    l1 = AntennaPattern.from_csv(tmp_path / "az.csv", tmp_path / "el.csv")
    l2 = AntennaPattern.from_csv(tmp_path / "az.csv", tmp_path / "el.csv", combine="L2")
    assert l1.peak_db == 11.0
    # On the principal planes: the measured values and straight lines in dB between them.
    az = np.radians([-90.0, -40.0, -20.0, 0.0, 15.0, 30.0, 60.0])
    np.testing.assert_allclose(l1.gain_db(az, 0.0), [-21.0, 2.0, 6.5, 11.0, 8.0, 5.0, -6.0], atol=1e-12)
    el = np.radians([-90.0, -45.0, 10.0, 20.0, 55.0, 90.0])
    np.testing.assert_allclose(l1.gain_db(0.0, el), [-19.0, -4.0, 7.5, 4.0, -10.5, -25.0], atol=1e-12)
    # Off the planes: L1 adds the dB losses (the thesis' choice), L2 takes their norm.
    loss_az, loss_el = 11.0 - 5.0, 11.0 - 4.0  # az 30 deg, el 20 deg
    assert float(l1.gain_db(np.radians(30.0), np.radians(20.0))) == pytest.approx(11.0 - loss_az - loss_el)
    assert float(l2.gain_db(np.radians(30.0), np.radians(20.0))) == pytest.approx(
        11.0 - np.hypot(loss_az, loss_el)
    )


def test_one_file_with_a_cut_column_equals_two_files(tmp_path):
    rows = ["cut,angle_deg,gain_db,phase_deg"]  # an extra column is ignored
    rows += [f"azimuth,{line},0" for line in AZ.splitlines()[1:]]
    rows += [f"Elevation,{line},0" for line in EL.splitlines()[1:]]
    (tmp_path / "cuts.csv").write_text("\n".join(rows) + "\n")
    (tmp_path / "az.csv").write_text(AZ)
    (tmp_path / "el.csv").write_text(EL)
    az, el = read_gain_cuts(tmp_path / "cuts.csv")
    for got, want in ((az, read_gain_cut(tmp_path / "az.csv")), (el, read_gain_cut(tmp_path / "el.csv"))):
        np.testing.assert_array_equal(got.angle_deg, want.angle_deg)
        np.testing.assert_array_equal(got.gain_db, want.gain_db)


def test_scenario_cut_paths_are_relative_to_the_scenario_file(tmp_path, monkeypatch):
    path = _scenario_with_cuts(tmp_path)
    monkeypatch.chdir(tmp_path)  # not the scenario's folder
    radar = load_scenario(path).build().radar
    assert float(radar.antenna.gain_db(np.radians(30.0), 0.0)) == pytest.approx(5.0)
    assert float(radar.antenna.gain_db(0.0, np.radians(-90.0))) == pytest.approx(-19.0)
    # The simulator's two-way table at boresight is the measured peak, squared in linear units.
    table, _ = two_way_gain_table(radar)
    centre = table.shape[0] // 2
    assert float(table[centre, centre]) == pytest.approx(10 ** (2 * 11.0 / 10), rel=1e-6)


def test_scenario_cuts_csv_is_one_file_for_both_cuts(tmp_path):
    path = _scenario_with_cuts(tmp_path)
    rows = ["cut,angle_deg,gain_db"] + [f"azimuth,{line}" for line in AZ.splitlines()[1:]]
    rows += [f"elevation,{line}" for line in EL.splitlines()[1:]]
    (path.parent / "cuts" / "all.csv").write_text("\n".join(rows) + "\n")
    data = yaml.safe_load(path.read_text())
    data["radar"]["antenna"] = {"cuts_csv": "cuts/all.csv", "combine": "L2"}
    path.write_text(yaml.safe_dump(data))
    antenna = load_scenario(path).build().radar.antenna
    assert antenna.combine == "L2"
    assert float(antenna.gain_db(np.radians(-40.0), 0.0)) == pytest.approx(2.0)
    assert float(antenna.gain_db(0.0, np.radians(20.0))) == pytest.approx(4.0)


def test_simulate_stores_the_measured_cuts(tmp_path):
    path = _scenario_with_cuts(tmp_path)
    result = _skyradar("simulate", str(path), "-o", "run.zarr", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    antenna = radar_config_of(open_frames(tmp_path / "run.zarr")).antenna
    np.testing.assert_array_equal(antenna.azimuth.gain_db, [-21.0, 2.0, 11.0, 5.0, -17.0])
    np.testing.assert_array_equal(antenna.elevation.angle_deg, [-90.0, 0.0, 20.0, 90.0])


@pytest.mark.parametrize(
    ("az", "needles"),
    [
        ("angle_deg,gain_db\n-90,-21\n0,11\n30,nan\n90,-17\n", ["az.csv", "line 4", "gain_db", "nan"]),
        ("angle_deg,gain_db\n-90,-21\n30,5\n0,11\n90,-17\n", ["az.csv", "line 4", "angle_deg", "0 after 30"]),
        ("angle,gain_db\n-90,-21\n0,11\n90,-17\n", ["az.csv", "missing column 'angle_deg'"]),
        ("angle_deg,gain_db\n-60,-21\n0,11\n60,-17\n", ["az.csv", "angle_deg", "[-60, 60]", "[-90, 90]"]),
    ],
    ids=["nan-gain", "non-monotonic", "missing-column", "short-coverage"],
)
def test_simulate_refuses_a_bad_cut_in_one_line(tmp_path, az, needles, cli):
    path = _scenario_with_cuts(tmp_path, az=az)
    result = cli("simulate", str(path), "-o", "run.zarr", cwd=tmp_path)
    _assert_one_line_error(result, *needles)
    assert not (tmp_path / "run.zarr").exists()


@pytest.mark.parametrize(
    ("text", "match"),
    [
        (
            "cut,angle_deg,gain_db\nazimuth,-90,-1\nazimuth,90,-1\n",
            r"cuts\.csv: field 'cut': no 'elevation' rows",
        ),
        ("cut,angle_deg,gain_db\nazimut,-90,-1\n", r"cuts\.csv: line 2: field 'cut': 'azimut'"),
        (
            "cut,angle_deg,gain_db\nazimuth,-90,-1\nazimuth,90,high\n",
            r"line 3: field 'gain_db': 'high' is not",
        ),
        ("cut,angle_deg,gain_db\nazimuth,-90,-1\nazimuth,,-1\n", r"line 3: field 'angle_deg': an empty cell"),
        ("cut,angle_deg,gain_db\n", r"cuts\.csv: no data rows"),
    ],
)
def test_bad_cuts_file_names_file_line_and_field(tmp_path, text, match):
    (tmp_path / "cuts.csv").write_text(text)
    with pytest.raises(InputError, match=match):
        read_gain_cuts(tmp_path / "cuts.csv")


def test_scenario_takes_one_antenna_source(tmp_path):
    path = _scenario_with_cuts(tmp_path)
    data = yaml.safe_load(path.read_text())
    data["radar"]["antenna"]["cuts_csv"] = "cuts/all.csv"
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(InputError, match="radar.antenna"):
        load_scenario(path)


def test_gain_cut_arrays_are_checked_like_files():
    with pytest.raises(InputError, match=r"row 2: field 'angle_deg': 0 after 45"):
        GainCut(np.array([-90.0, 45.0, 0.0, 90.0]), np.zeros(4))
    with pytest.raises(InputError, match=r"covers \[-90, 45\]"):
        GainCut(np.array([-90.0, 45.0]), np.zeros(2))
