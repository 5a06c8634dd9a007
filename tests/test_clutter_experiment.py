"""``skyradar experiment clutter``: terrain cases, the summary per terrain, the intruder's detections."""

from __future__ import annotations

import json
import re

import numpy as np
import pandas as pd
import pytest

from cli_helpers import skyradar, skyradar_in_process
from skyradar.code_version import code_version
from skyradar.config import RadarConfig
from skyradar.experiments.clutter import _hit

CFG = RadarConfig.prototype_2022()
_NEW_KEYS = (
    "intruder_cell_if_db_median",
    "intruder_cell_if_db_min",
    "detection_fraction_none",
    "detection_fraction_suppressed",
    "detection_fraction_suppressed_with_secondary",
    "own_agl_m_median",
    "mdv_mps_suppressed",
    "usable_doppler_fraction_suppressed",
)


def test_relief_cases_write_one_summary_entry_and_figures_per_terrain(tmp_path, monkeypatch, capsys):
    code, out, err = skyradar_in_process(
        monkeypatch,
        capsys,
        "experiment",
        "clutter",
        "--frames",
        "4",
        "--terrain",
        "hills,jacksboro",
        "--output",
        tmp_path / "c",
        "--json",
    )
    assert code == 0, err
    summary = json.loads(out.strip().splitlines()[-1])
    assert list(summary["terrains"]) == ["hills", "jacksboro"]
    for name, case in summary["terrains"].items():
        assert case["frames"] == 4 and case["visible_frames"] >= 1, name
        for key in _NEW_KEYS:
            assert np.isfinite(case[key]), (name, key)
        assert case["own_agl_m_min"] >= 300.0 and case["own_agl_m_max"] <= 700.0, name  # the fast closures'
        assert case["closing_mps"] == pytest.approx(106.7)
        assert (tmp_path / "c" / f"sinr_loss_{name}.png").exists()
        assert (tmp_path / "c" / f"intruder_{name}.png").exists()
    assert [row["terrain"] for row in summary["rows"]] == ["hills", "jacksboro"]
    # Provenance, as every measured result records it; the same in the saved summary.
    assert summary["command"].startswith("skyradar experiment clutter --frames 4 --terrain hills,jacksboro")
    assert summary["version"] == code_version()
    assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", summary["date_utc"])
    assert summary["load_average_1min"] >= 0.0
    saved = json.loads((tmp_path / "c" / "summary.json").read_text())
    assert {k: saved[k] for k in ("version", "command", "date_utc")} == {
        k: summary[k] for k in ("version", "command", "date_utc")
    }
    frames = pd.read_csv(tmp_path / "c" / "frames.csv")
    assert set(frames.terrain) == {"hills", "jacksboro"} and "cell_if_db" in frames
    assert set(pd.read_csv(tmp_path / "c" / "sinr_loss.csv").terrain) == {"hills", "jacksboro"}
    assert "`intruder_jacksboro.png`" in (tmp_path / "c" / "summary.md").read_text()


def test_intruder_hit_counts_secondary_rows_only_when_asked():
    near = {"frame": [0], "range_bin": [100], "doppler_bin": [CFG.n_doppler - 1]}  # Doppler wraps: 2 bins off
    flagged = pd.DataFrame(near | {"secondary": [True]})
    assert not _hit(flagged, 0, 101, 1, CFG)
    assert _hit(flagged, 0, 101, 1, CFG, secondary=True)
    assert _hit(pd.DataFrame(near), 0, 101, 1, CFG)  # no `secondary` column: every row is primary
    assert not _hit(pd.DataFrame(near), 0, 104, 1, CFG, secondary=True)  # 4 range bins off


@pytest.mark.slow
def test_flat_cases_write_figures_table_and_json(tmp_path):
    result = skyradar(
        "experiment",
        "clutter",
        "--frames",
        "2",
        "--terrain",
        "flat-1000,flat-300",
        "--output",
        "c",
        "--json",
        cwd=tmp_path,
    )
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout.strip().splitlines()[-1])
    flat = summary["terrains"]["flat-1000"]
    assert flat["frames"] == 2 and "usable_doppler_fraction_suppressed" in summary["terrains"]["flat-300"]
    assert {"if_db_lost_cells_median", "if_db_lost_cells_min"} <= set(flat)
    for name in (
        "sinr_loss_flat-1000.png",
        "intruder_flat-300.png",
        "frames.csv",
        "sinr_loss.csv",
        "summary.json",
        "summary.md",
    ):
        assert (tmp_path / "c" / name).exists()


def test_command_default_is_the_experiments_default():
    from skyradar.cli.commands_clutter import _DEFAULT_TERRAINS
    from skyradar.experiments.clutter import DEFAULT_TERRAINS, parse_terrains

    assert tuple(parse_terrains(_DEFAULT_TERRAINS)) == DEFAULT_TERRAINS
