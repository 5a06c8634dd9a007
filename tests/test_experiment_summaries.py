"""Each experiment's ``summary.md``: its headline numbers come from the summary dict, and it lists
the files its folder holds, no others.

The summaries here carry the keys each experiment's ``run`` returns, with values of real runs
(ch2 and clutter: ``docs/results/clutter``) or of the size real runs give; nothing is run.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from skyradar.experiments import ch2, ch3, ch4, ch7
from skyradar.experiments.ch5 import THESIS_TABLE as CH5_THESIS
from skyradar.experiments.ch5_report import summary_markdown as ch5_summary
from skyradar.experiments.ch6 import THESIS_TABLE as CH6_THESIS
from skyradar.experiments.ch6_report import summary_markdown as ch6_summary
from skyradar.experiments.clutter_report import summary_markdown as clutter_summary
from skyradar.experiments.summary_md import markdown_table, number, page, write_summary

ROOT = Path(__file__).resolve().parents[1]
NAN = math.nan


def _folder(tmp_path: Path, names: list[str]) -> Path:
    for name in names:
        (tmp_path / name).write_bytes(b"x")
    return tmp_path


def _listed(text: str) -> list[str]:
    """The file names the page lists (``- `name`: ...`` lines)."""
    return [line.split("`")[1] for line in text.splitlines() if line.startswith("- `")]


def _table_rows(text: str) -> list[list[str]]:
    rows = [line.strip("|").split(" | ") for line in text.splitlines() if line.startswith("| ")]
    return [[cell.strip() for cell in row] for row in rows[1:]]  # without the header


def test_page_lists_only_present_files_and_patterns(tmp_path):
    out = _folder(tmp_path, ["a.png", "state_flat_robust.parquet"])
    files = {"a.png": "a", "b.png": "b", "state_<case>.parquet": "states", "x_<case>.csv": "none"}
    text = page("t", ["p"], ["k", "v"], [["x", 1.0]], files, out)
    assert _listed(text) == ["a.png", "state_<case>.parquet"]
    assert write_summary(out, text).read_text() == text
    assert not [p for p in out.iterdir() if p.name.startswith(".")]  # no temporary file left


def test_numbers_and_table_cells():
    assert [number(v) for v in (None, NAN, math.inf, True, 7, 2.345)] == [
        "n/a",
        "n/a",
        "n/a",
        "yes",
        "7",
        "2.3",
    ]
    assert markdown_table(["a"], [["x|y"]]).splitlines()[-1] == "| x\\|y |"
    with pytest.raises(ValueError, match="2 cells for 1 columns"):
        markdown_table(["a"], [[1.0, 2.0]])


CH2 = {  # a real run (n_frames=1)
    "asymptote_range_m": 992.921832182103,
    "asymptote_range_expected_m": 1000.0,
    "first_ground_range_m": 1004.3047343000001,
    "asymptote_velocity_mps": -29.98491119888356,
    "asymptote_velocity_expected_mps": -30.0,
    "intruder_range_m": 1993.6198457,
    "intruder_velocity_mps": 18.157276133144617,
    "intruder_snr_db": 18.509900903921206,
    "intruder_expected_range_m": 1993.6198457,
    "intruder_expected_velocity_mps": 18.157276133144617,
    "intruder_true_radial_velocity_mps": -60.000000000000014,
    "wrap60_right_edge": True,
    "wrap60_min_velocity_mps": 19.409502073361487,
    "wrap60_expected_min_velocity_mps": 19.48793562274112,
    "range_bin_m": 14.9896229,
    "doppler_bin_mps": 0.3130564850542175,
    "frames_per_s": 17.362434393830668,
    "thesis_frames_per_s": 3.3,
}


def test_ch2_summary_names_asymptotes_wrap_and_speed(tmp_path):
    out = _folder(tmp_path, ["ch2_flat_30mps.png", "ch2_flat_60mps.png", "ch2_table.csv", "ch2.json"])
    text = ch2.summary_markdown(CH2, out)
    rows = {row[0]: row[1:] for row in _table_rows(text)}
    assert rows["near-range asymptote R [m]"] == ["992.9", "1000.0"]
    assert rows["60 m/s: wrapped ground starts at [m/s]"] == ["19.4", "19.5"]
    assert rows["simulated frames per second"] == ["17.4", "3.3 (thesis)"]
    assert "ground wraps to the right edge" in " ".join(text.split())
    assert _listed(text) == ["ch2_flat_30mps.png", "ch2_flat_60mps.png", "ch2_table.csv", "ch2.json"]
    failed = ch2.summary_markdown({**CH2, "wrap60_right_edge": False}, out)
    assert "does not wrap" in " ".join(failed.split())


CH3_SWEEP = [
    {"rx_spacing_wavelengths": s, "az_sd_deg": az, "el_sd_deg": el}
    for s, az, el in ((0.5, 0.74, 0.86), (0.6, 0.62, 0.71), (0.7, 0.55, 0.62))
]
CH3 = {
    "rx_spacing_wavelengths": 0.6,
    "az_sd_deg": 0.62,
    "el_sd_deg": 0.71,
    "az_crlb_deg": 0.56,
    "el_crlb_deg": 0.64,
    "detected_frames": 262,
    "doa_outliers": 0,
    "calib_phase_err_deg": 0.35,
    "az_mean_deg": 0.04,
    "el_mean_deg": -0.08,
    "az_hann_sd_deg": 0.31,
    "el_hann_sd_deg": 0.38,
    "dist_mean_m": 18.7,
    "dist_sd_m": 13.9,
    "dist_hann_mean_m": 11.2,
    "dist_hann_sd_m": 7.4,
    "frames": 300,
    "detected_frames_snr13": 258,
    "frames_snr13": 262,
    "false_alarms_per_frame": 0.0033,
    "path": "circuit",
    "building_up_m": 15.4,
    "spacing_sweep": CH3_SWEEP,
    "runtime_s": 120.0,
}


def test_ch3_summary_sets_each_error_beside_the_thesis(tmp_path):
    out = _folder(tmp_path, ["ch3_errors.png", "ch3_spacing.png", "ch3_table.csv", "ch3.json"])
    text = ch3.summary_markdown(CH3, out)
    rows = {row[0]: row[1:] for row in _table_rows(text)}
    thesis = ch3.THESIS_TABLE
    assert rows["azimuth error SD, raw [deg]"] == ["0.62", f"{thesis['az_deg'][1]:.2f}"]
    assert rows["3-D position error mean, raw [m]"] == ["18.7", f"{thesis['dist_m'][0]:.1f}"]
    assert len(rows) == 10
    words = " ".join(text.split())
    assert "detected in 258 of the 262 frames" in words and "0.70 wavelengths 0.55 deg" in words
    assert _listed(text) == ["ch3_errors.png", "ch3_spacing.png", "ch3_table.csv", "ch3.json"]
    single = ch3.summary_markdown({**CH3, "spacing_sweep": CH3_SWEEP[1:2]})
    assert "ch3_spacing.png" not in _listed(single) and "Per receive spacing" not in single


def _ch4_scenario(truth: int, radar: int, traditional: int) -> dict:
    return {
        "truth_tracks": truth,
        "tracks_radar": radar,
        "tracks_traditional": traditional,
        "false_tracks_radar": 0,
        "false_tracks_traditional": traditional - truth,
        "missed_truth_tracks_radar": 1,
        "completeness_radar": 0.91,
        "innov_mean_radar": 1.4,
        "innov_p95_radar": 3.6,
        "innov_mean_traditional": 2.2,
        "innov_p95_traditional": 6.9,
        "gospa_radar": 40.0,
        "gospa_traditional": 80.0,
    }


CH4 = {
    "detections_source": "full chain: ImageSimulator frames (free space, noise) -> process_cube detections",
    "scenarios": {"circuit": _ch4_scenario(13, 14, 31), "free": _ch4_scenario(12, 12, 40)},
    "radar_p95_below_traditional_all": True,
    "radar_tracks_at_most_traditional_all": True,
    "thesis": ch4.THESIS,
    "figures": ["ch4_tracks_range_doppler.png", "ch4_tracks_body.png", "ch4_innovation_hist.png"],
    "seed": 0,
}


def test_ch4_summary_has_a_row_per_scenario_with_the_thesis_counts(tmp_path):
    present = ["ch4_tracks_body.png", "ch4_results.json", "tracks_free_radar.parquet"]
    text = ch4.summary_markdown(CH4, _folder(tmp_path, present))
    rows = {row[0]: row[1:] for row in _table_rows(text)}
    t = ch4.THESIS["circuit"]
    assert rows["circuit"][:3] == [f"13 ({t['truth']})", f"14 ({t['tracks'][1]})", f"31 ({t['tracks'][0]})"]
    assert rows["free"][4] == f"3.6 ({ch4.THESIS['free']['innov_p95'][1]})"
    words = " ".join(text.split())
    assert "at most as many tracks as the traditional one in every scenario" in words
    assert "circuit: 14 radar-aware and 31 traditional tracks for 13 true tracks" in words
    assert _listed(text) == ["ch4_tracks_body.png", "ch4_results.json", "tracks_<scenario>_<model>.parquet"]
    worse = ch4.summary_markdown({**CH4, "radar_p95_below_traditional_all": False})
    assert "smaller not in every scenario" in " ".join(worse.split())


def _errors(mean: float | None, sd: float | None) -> dict:
    return {"h_err_mean_m": mean, "h_err_sd_m": sd, "valid_fraction": 0.0 if mean is None else 1.0}


CH5 = {  # as read back from ch5.json: a case without any estimate has null errors
    "rate_1hz": {
        "flat": {"thesis": _errors(4.1, 2.2), "robust": _errors(0.6, 1.3), "terrain": _errors(0.9, 1.6)},
        "sd251": {
            "thesis": _errors(None, None),
            "robust": _errors(None, None),
            "terrain": _errors(31.0, 88.0),
        },
    },
    "rate_9p4hz": {"flat": {"robust": _errors(0.5, 1.1)}},
    "ahrs": {"rate_1hz": {"flat": {"terrain": _errors(1.8, 2.0)}, "sd251": {"terrain": _errors(35.0, 90.0)}}},
    "acceptance_failures": [],
    "thesis_table": {k: {"h_err_mean_m": m, "h_err_sd_m": s} for k, (m, s) in CH5_THESIS.items()},
    "duration_s": 40.0,
}


def test_ch5_summary_sets_each_method_beside_the_thesis(tmp_path):
    present = [
        "ch5_flat_rate_1hz.png",
        "ch5_flat_rate_9p4hz.png",
        "ch5.json",
        "state_flat_rate_1hz_robust.parquet",
    ]
    text = ch5_summary(CH5, _folder(tmp_path, present))
    rows = {row[0]: row[1:] for row in _table_rows(text)}
    m, s = CH5_THESIS["flat"]
    assert rows["flat"] == ["4.1 +- 2.2", "0.6 +- 1.3", "0.9 +- 1.6", "1.8 +- 2.0", f"{m:.1f} +- {s:.1f}"]
    assert rows["sd251"][:3] == ["no estimate", "no estimate", "31.0 +- 88.0"]
    words = " ".join(text.split())
    assert f"flat: robust 0.6 +- 1.3 m (thesis {m:.1f} +- {s:.1f} m)" in words
    assert "Every case meets its stated share" in words
    assert _listed(text) == present[:3] + ["state_<terrain>_<rate>_<method>.parquet"]
    failing = ch5_summary({**CH5, "acceptance_failures": ["rate_1hz: a", "rate_1hz: b"]})
    assert "2 cases miss their stated share" in " ".join(failing.split())


def _ch6_row(method: str, correct: int, head: float, pos: float, fp: float) -> dict:
    t_head, t_pos, t_fp, t_correct = CH6_THESIS[method]
    return {
        "method": method,
        "frames": 20,
        "correct": correct,
        "heading_error_deg": head,
        "position_error_m": pos,
        "false_positive_fraction": fp,
        "thesis_correct": t_correct,
        "thesis_heading_error_deg": t_head,
        "thesis_position_error_m": t_pos,
        "thesis_false_positive_fraction": t_fp,
    }


CH6 = {
    "frames": 20,
    "best_method": "clahe_ridge",
    "best_correct": 20,
    "best_false_positive": 0.012,
    "search_decided": 20,
    "search_correct": 19,
    "search_median_position_m": 3.4,
    "search_median_heading_deg": 0.21,
    "roc_false_alarm": 0.0,
    "monitor_false_alarm": 0.05,
    "spoof_50m_detection": 1.0,
    "wing_up_frames": 5,
    "wing_up_all_no_decision": True,
    "acceptance_failures": [],
    "figures": ["/somewhere/ch6/poses.png", "/somewhere/ch6/roc.png"],
    "table": [
        _ch6_row("clahe_ridge", 20, 0.4, 2.2, 0.012),
        _ch6_row("gamma", 11, 1.9, 9.0, 0.31),
        {
            "method": "search (clahe_ridge, NCC)",
            "frames": 20,
            "correct": 19,
            "heading_error_deg": 0.21,
            "position_error_m": 3.4,
            "false_positive_fraction": NAN,
            "thesis_correct": None,
            "thesis_heading_error_deg": None,
            "thesis_position_error_m": None,
            "thesis_false_positive_fraction": None,
        },
    ],
}


def test_ch6_summary_sets_each_method_beside_the_thesis(tmp_path):
    out = _folder(tmp_path, ["poses.png", "roc.png", "table.csv", "ch6.json"])
    text = ch6_summary(CH6, out)
    rows = {row[0]: row[1:] for row in _table_rows(text)}
    assert rows["clahe_ridge"] == ["20 of 20 (17)", "0.4 (1.0)", "2.2 (1.0)", "0.01 (0.14)"]
    assert rows["gamma"][0] == "11 of 20" and rows["gamma"][3] == "0.31 (0.53)"
    assert rows["search (clahe_ridge, NCC)"] == ["19 of 20", "0.2", "3.4", "n/a"]
    words = " ".join(text.split())
    assert "in 20 of 20 frames" in words and "detected in 100 % of the frames" in words
    assert "Every acceptance bound holds." in words
    assert _listed(text) == ["poses.png", "roc.png", "table.csv", "ch6.json"]
    missed = ch6_summary({**CH6, "acceptance_failures": ["search median position error 12.0 m > 10 m"]})
    assert "1 acceptance bounds are missed: search median position error 12.0 m > 10 m" in " ".join(
        missed.split()
    )


CH7 = {
    "rotations": 9,
    "clusters": 5,
    "clusters_seen_every_rotation": 5,
    "cluster_rotations": {"Vianen": 9},
    "aircraft_seen": 9,
    "aircraft_passes": 9,
    "aircraft_median_error_m": 58.3,
    "false_total": 2,
    "false_max_per_rotation": 1,
    "false_mean_per_rotation": 0.22,
    "detections": 1130,
    "scan_period_s": 4.4444,
    "hann_peak_ms": 0.15,
    "plain_peak_ms": 0.15,
    "hann_echo_visible": True,
    "plain_echo_visible": False,
    "simulate_s": 60.1,
    "process_s": 70.2,
    "total_s": 131.9,
    "acceptance": {"clusters_9_of_9": True, "aircraft_8_of_9": True, "under_5_min": False},
}


def test_ch7_summary_sets_ours_beside_the_thesis_findings(tmp_path):
    present = ["ch7_testpulse.png", "ch7_sweeps.png", "ch7.json"]
    text = ch7.summary_markdown(CH7, _folder(tmp_path, present))
    rows = {row[0]: row[1:] for row in _table_rows(text)}
    assert rows["small aircraft seen"] == [ch7.THESIS["aircraft_seen"], "9/9 passes"]
    assert rows["aircraft median position error"][1] == "58.3 m"
    words = " ".join(text.split())
    assert "5 of 5 towns are seen in every rotation" in words and "median position error of 58.3 m" in words
    assert "Acceptance bounds missed: under 5 min." in words
    assert _listed(text) == present
    kept = ch7.summary_markdown(CH7, _folder(tmp_path, ["ch7_recording.sigmf-meta"]))
    assert "ch7_recording.<...>" in _listed(kept)


def test_clutter_summary_of_a_saved_run_names_each_terrain(tmp_path):
    saved = json.loads((ROOT / "docs" / "results" / "clutter" / "clutter-seed0.json").read_text())
    present = ["sinr_loss_hills.png", "intruder_hills.png", "frames.csv", "summary.json"]
    text = clutter_summary(saved, _folder(tmp_path, present))
    rows = {row[0]: row[1:] for row in _table_rows(text)}
    assert list(rows) == [r["terrain"] for r in saved["rows"]]
    flat = next(r for r in saved["rows"] if r["terrain"] == "flat-1000")
    assert rows["flat-1000"][2] == f"{flat['if_db_lost_cells_median']:.1f}"
    assert rows["flat-1000"][1].startswith(f"{100 * flat['detection_fraction_none']:.0f} %")
    words = " ".join(text.split())
    assert f"its {flat['visible_frames']} visible frames" in words and "(seed 0)" in words
    assert _listed(text) == present
