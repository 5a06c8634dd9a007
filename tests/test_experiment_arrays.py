"""``skyradar experiment arrays``: the receive-array trade study.

The DoA Monte-Carlo of a 2x3 array against the closed-form bound of a uniform rectangular array
(written here, independent of :func:`skyradar.process.doa.doa_crlb`), the table's one row per array
and terrain on the same encounters, bad input through the real CLI, and a small run's files.
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from cli_helpers import assert_one_line_error
from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.experiments import arrays
from skyradar.io.json_results import jsonable


def _ura_bound_deg(rows: int, cols: int, snr_db: float) -> tuple[float, float]:
    """Closed-form Cramer-Rao bound (azimuth, elevation), deg, of a rows x cols uniform rectangular
    array at half-wavelength spacing in the y-z plane, target on boresight.

    The phase of element (m, n) is ``-k (y_n sin(az) cos(el) - z_m sin(el))``; at boresight its
    derivatives are ``-k y_n`` and ``k z_m``. With the common phase eliminated the Fisher information
    is ``2 SNR k^2 diag(sum (y - mean)^2, sum (z - mean)^2)`` (the cross sum vanishes by symmetry),
    ``sum y^2 = rows d^2 cols (cols^2 - 1) / 12`` and ``sum z^2 = cols d^2 rows (rows^2 - 1) / 12``;
    ``k d = pi``.
    """
    snr = 10.0 ** (snr_db / 10.0)
    syy = rows * cols * (cols**2 - 1) / 12.0
    szz = cols * rows * (rows**2 - 1) / 12.0
    return (
        float(np.degrees(1.0 / (np.pi * np.sqrt(2.0 * snr * syy)))),
        float(np.degrees(1.0 / (np.pi * np.sqrt(2.0 * snr * szz)))),
    )


def test_the_closed_form_is_the_known_2x3_value():
    # 2 rows x 3 columns: sum y^2 = 4 d^2, sum z^2 = 1.5 d^2 (by hand from the positions).
    az, el = _ura_bound_deg(2, 3, 20.0)
    assert az == pytest.approx(np.degrees(1.0 / (np.pi * np.sqrt(2.0 * 100.0 * 4.0))), rel=1e-12)
    assert el == pytest.approx(np.degrees(1.0 / (np.pi * np.sqrt(2.0 * 100.0 * 1.5))), rel=1e-12)


def test_doa_error_of_a_2x3_array_approaches_its_closed_form_bound_at_high_snr():
    rows = arrays.doa_against_bound("ura-2x3", snrs_db=(30.0, 40.0), trials=4000, direction_deg=(0.0, 0.0))
    for row in rows:
        az, el = _ura_bound_deg(2, 3, row["snr_db"])
        # The Monte-Carlo RMS of 4000 trials has a relative SD of about 1.1 %: 6 % is 5 of them.
        assert row["rms_azimuth_deg"] == pytest.approx(az, rel=0.06)
        assert row["rms_elevation_deg"] == pytest.approx(el, rel=0.06)
        # The study's bound column is the library's bound: it must equal the closed form too.
        assert row["bound_azimuth_deg"] == pytest.approx(az, rel=1e-9)
        assert row["bound_elevation_deg"] == pytest.approx(el, rel=1e-9)


def test_more_channels_give_a_smaller_doa_error_in_the_study():
    square = arrays.doa_against_bound("square", snrs_db=(30.0,), trials=2000)[0]
    ura = arrays.doa_against_bound("ura-2x3", snrs_db=(30.0,), trials=2000)[0]
    assert ura["rms_azimuth_deg"] < square["rms_azimuth_deg"]


def test_array_config_has_the_layouts_channels():
    assert arrays.array_config("ura-2x4").n_rx == 8
    mimo = arrays.array_config("mimo-2x4")
    assert (mimo.n_tx, mimo.n_rx, mimo.n_virtual) == (2, 4, 8)
    assert arrays.array_config("square").n_rx == RadarConfig.prototype_2022().n_rx
    with pytest.raises(InputError, match="--arrays"):
        arrays.array_config("ring")


def _summary(terrains: list[str], false: int) -> dict:
    row = {
        "encounters": 3,
        "conflicts": 2,
        "observable_conflicts": 2,
        "missed_warnings": 0,
        "missed_warning_rate": 0.0,
        "missed_warning_rate_ci95": [0.0, 0.66],
        "late_warnings": 1,
        "must_not_alert_encounters": 1,
        "false_warnings": false,
        "false_warning_rate": float(false),
        "false_warning_rate_ci95": [0.2, 1.0],
        "median_warning_lead_s": 20.0,
        "ground_tracks_per_min": 0.0,
        "ground_track_warnings": 0,
        "clutter_tracks_per_min": 0.5,
        "track_fragments_per_intruder": {"median": 1.0, "mean": 1.5, "max": 2},
        "flight_minutes": 2.0,
    }
    return {"rows": [{"terrain": t, **row} for t in terrains]}


def _table(terrains: list[str], shift: float = 0.0) -> pd.DataFrame:
    params = pd.DataFrame(
        {"kind": ["head-on", "crossing", "overtaking"], "miss_m": [10.0, 300.0 + shift, 900.0]}
    )
    return pd.concat(
        [params.assign(terrain=t, encounter=range(3), layout="single") for t in terrains], ignore_index=True
    )


def test_rows_are_one_per_array_and_terrain_and_name_the_encounters_flown():
    terrains = ["none", "flat-300"]
    rows = []
    for array in ("square", "ura-2x3"):
        rows += arrays.array_rows(array, _summary(terrains, 1), _table(terrains), ["kind", "miss_m"])
    assert [(r["array"], r["terrain"]) for r in rows] == [
        ("square", "none"),
        ("square", "flat-300"),
        ("ura-2x3", "none"),
        ("ura-2x3", "flat-300"),
    ]
    assert [r["n_rx"] for r in rows] == [4, 4, 6, 6]
    assert len({r["encounter_set"] for r in rows if r["terrain"] == "none"}) == 1
    assert rows[0]["late_warning_rate"] == 0.5
    assert rows[0]["late_warning_rate_ci95"][0] < 0.5 < rows[0]["late_warning_rate_ci95"][1]
    other = arrays.array_rows("kite", _summary(terrains, 1), _table(terrains, shift=1.0), ["kind", "miss_m"])
    assert other[0]["encounter_set"] != rows[0]["encounter_set"]  # other encounters: another digest


def test_a_mimo_array_is_a_row_with_its_virtual_channels():
    rows = arrays.array_rows("mimo-2x4", _summary(["none"], 0), _table(["none"]), ["kind", "miss_m"])
    assert (rows[0]["n_rx"], rows[0]["n_tx"], rows[0]["channels"]) == (4, 2, 8)


def test_two_transmitters_fill_the_doppler_image_with_ground_and_the_nulls_take_it_out():
    # Flat ground 300 m below at 50 m/s: static points in the field of view close at about 17-50
    # m/s. One transmitter's 78.3 m/s image keeps more than a third of its bins free of ground even
    # without suppression; two transmitters fold the band into a 39.15 m/s image where every bin
    # holds ground above the -5 dB loss. Nulled on the virtual channels (each alias with its slot
    # phase predicted), most of the image is usable again, as for the same positions with one
    # transmitter (ura-2x4) to within a tenth.
    ura, _ = arrays.doppler_notch("ura-2x4", n_frames=1)
    mimo, curve = arrays.doppler_notch("mimo-2x4", n_frames=1)
    assert len(curve) == arrays.array_config("mimo-2x4").frame_shape[1]
    assert ura["usable_doppler_fraction_none"] > 0.35
    assert mimo["usable_doppler_fraction_none"] == 0.0
    assert mimo["usable_doppler_fraction"] > 0.8
    assert mimo["usable_doppler_fraction"] > ura["usable_doppler_fraction"] - 0.1


def test_parse_arrays_keeps_order_and_refuses_unknown_names():
    assert arrays.parse_arrays("ura-2x4,square") == ["ura-2x4", "square"]
    assert arrays.parse_arrays("mimo-2x4") == ["mimo-2x4"]
    with pytest.raises(InputError, match="--arrays"):
        arrays.parse_arrays("square,")


@pytest.mark.parametrize(
    ("args", "needles"),
    [
        (["--arrays", "square,ring"], ["--arrays", "ring"]),
        (["--n", "0"], ["--n", "0"]),
        (["--terrain", "moon"], ["--terrain", "moon"]),
    ],
)
def test_bad_input_is_one_line_and_exit_2_through_the_cli(tmp_path, args, needles, cli):
    result = cli("experiment", "arrays", "-o", str(tmp_path / "out"), *args, cwd=tmp_path)
    assert_one_line_error(result, *needles)
    assert not (tmp_path / "out").exists()  # refused before anything was written


@pytest.mark.slow
def test_a_small_run_writes_its_files_with_one_row_per_array_on_the_same_encounters(tmp_path):
    out = tmp_path / "arrays"
    result = arrays.run(
        out,
        arrays=("square", "ura-2x3"),
        terrains=("none",),
        n_encounters=1,
        workers=1,
        doa_trials=200,
        timing_s=0.1,
    )
    for name in ("arrays.parquet", "arrays.csv", "doa.csv", "doppler.csv", "summary.json", "summary.md"):
        assert (out / name).is_file(), name
    for name in ("arrays_warnings.png", "arrays_doa.png", "arrays_doppler.png", "arrays_frames_per_s.png"):
        assert (out / name).stat().st_size > 1000, name
    table = pd.read_parquet(out / "arrays.parquet")
    assert list(zip(table["array"], table["terrain"], strict=True)) == [
        ("square", "none"),
        ("ura-2x3", "none"),
    ]
    assert table["encounter_set"].nunique() == 1  # both arrays flew the same encounter
    assert (table["encounters"] == 1).all()
    saved = json.loads((out / "summary.json").read_text())
    assert saved["arrays"] == ["square", "ura-2x3"] and saved["rows"] == jsonable(result["rows"])
    per = {a["array"]: a for a in saved["per_array"]}
    assert per["ura-2x3"]["n_rx"] == 6 and per["square"]["n_rx"] == 4
    assert all(a["frames_per_s"] > 0 and len(a["doa"]) == 3 for a in per.values())
    # Two nulls take less of a boresight target from six channels than from four.
    assert per["ura-2x3"]["usable_doppler_fraction"] > per["square"]["usable_doppler_fraction"]
    assert "| square | none |" in (out / "summary.md").read_text()
