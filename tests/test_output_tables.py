"""Every column an output table is written with is documented in its producing module's mapping
(column -> "unit; meaning", :mod:`skyradar.io.table_columns`), and every documented column that is
not marked optional is written, in the documented order.

The commands run through the real entry point on two small scenarios: one with a head-on intruder
for simulate -> process -> track -> alert (with and without advice) -> export, one over flat ground
for state. The GPS check's rows are built by the function the command calls; the passive table's
columns are its mapping's keys by construction (a passive run takes minutes).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from cli_helpers import skyradar, small_scenario
from skyradar.daa.pipeline import ALERT_COLUMNS
from skyradar.io.run_export import INTRUDER_EXPORT_COLUMNS, OWNSHIP_EXPORT_COLUMNS
from skyradar.io.table_columns import always_written, column_doc
from skyradar.nav.flight_state import STATE_TABLE_COLUMNS
from skyradar.nav.gpscheck.check import GPSCHECK_COLUMNS
from skyradar.passive.pipeline import COLUMNS as PASSIVE_COLUMNS
from skyradar.passive.pipeline import PASSIVE_TABLE_COLUMNS
from skyradar.process.pipeline import DETECTION_TABLE_COLUMNS
from skyradar.track.track_table import TRACK_TABLE_COLUMNS

ALL = {
    "detections": DETECTION_TABLE_COLUMNS,
    "tracks": TRACK_TABLE_COLUMNS,
    "alerts": ALERT_COLUMNS,
    "state": STATE_TABLE_COLUMNS,
    "passive": PASSIVE_TABLE_COLUMNS,
    "gpscheck": GPSCHECK_COLUMNS,
    "export ownship": OWNSHIP_EXPORT_COLUMNS,
    "export intruders": INTRUDER_EXPORT_COLUMNS,
}
PER_HEAD = "<variable>@<head>"  # the export's per-head columns, documented once for every variable


def _check(columns: list[str], documented: dict[str, str], table: str, ordered: bool = True) -> None:
    """Written columns documented (and in the documented order); every always-written one present."""
    plain = [c for c in columns if "@" not in c]
    undocumented = [c for c in plain if c not in documented]
    undocumented += [
        c for c in columns if "@" in c and (PER_HEAD not in documented or c[: c.index("@")] not in documented)
    ]
    missing = [c for c in always_written(documented) if c not in columns]
    assert not undocumented, f"{table}: written but not documented: {undocumented}"
    assert not missing, f"{table}: documented but not written: {missing}"
    if ordered:
        assert plain == [c for c in documented if c in plain], f"{table}: columns out of the documented order"


def _run(*args: str, cwd: Path) -> None:
    result = skyradar(*args, cwd=cwd)
    assert result.returncode == 0, (args, result.stderr[-2000:])


@pytest.fixture(scope="module")
def chain(tmp_path_factory) -> Path:
    """A 6 s run with a head-on intruder through every command of the DAA chain, and its export."""
    folder = tmp_path_factory.mktemp("tables")
    intruder = {
        "name": "A",
        "type": "encounter",
        "kind": "head-on",
        "t_cpa_s": 12.0,
        "horizontal_miss_m": 50.0,
        "intruder_speed_mps": 40.0,
        "rcs_m2": 5.0,
    }
    scenario = small_scenario("output tables", duration_s=6.0, frame_rate_hz=5.0, intruders=[intruder])
    (folder / "s.yaml").write_text(yaml.safe_dump(scenario))
    _run("simulate", "s.yaml", "-o", "run.zarr", cwd=folder)
    _run("process", "run.zarr", "-o", "det.parquet", cwd=folder)
    _run("track", "det.parquet", "--ownship", "run.zarr", "-o", "tracks.parquet", cwd=folder)
    _run("alert", "tracks.parquet", "--ownship", "run.zarr", "-o", "alerts.parquet", cwd=folder)
    _run("alert", "tracks.parquet", "--ownship", "run.zarr", "-o", "bare.parquet", "--no-advice", cwd=folder)
    _run("export", "run.zarr", "-o", "export", cwd=folder)
    return folder


def test_every_column_text_names_a_unit_and_a_meaning():
    for table, columns in ALL.items():
        assert columns, table
        for name, text in columns.items():
            doc = column_doc(text)
            assert doc.unit and doc.meaning and doc.optional != "", (table, name, text)
    assert list(PASSIVE_TABLE_COLUMNS) == PASSIVE_COLUMNS  # the passive table is written as det[COLUMNS]


def test_detections_tracks_and_alerts_are_written_as_documented(chain):
    tables = {
        name: pd.read_parquet(chain / f"{name}.parquet") for name in ("det", "tracks", "alerts", "bare")
    }
    assert len(tables["det"]) and len(tables["tracks"]) and len(tables["alerts"])  # rows to read
    assert (tables["alerts"]["level"] > 0).any()  # the head-on intruder is alerted: the advice is filled
    _check(list(tables["det"].columns), DETECTION_TABLE_COLUMNS, "detections")
    _check(list(tables["tracks"].columns), TRACK_TABLE_COLUMNS, "tracks")
    _check(list(tables["alerts"].columns), ALERT_COLUMNS, "alerts")
    _check(list(tables["bare"].columns), ALERT_COLUMNS, "alerts --no-advice")
    optional = [c for c in ALERT_COLUMNS if column_doc(ALERT_COLUMNS[c]).optional]
    assert set(tables["alerts"].columns) == set(ALERT_COLUMNS)  # with advice: every column
    assert not set(optional) & set(tables["bare"].columns)  # without: the advice columns are left out


def test_export_tables_are_written_as_documented(chain):
    own = pd.read_parquet(chain / "export" / "ownship.parquet")
    intruders = pd.read_parquet(chain / "export" / "intruders.parquet")
    _check(list(own.columns), OWNSHIP_EXPORT_COLUMNS, "export ownship")
    # The intruder variables come in the store's order.
    _check(list(intruders.columns), INTRUDER_EXPORT_COLUMNS, "export intruders", ordered=False)
    # A simulated run stores every own-ship and intruder variable: the optional columns are all there.
    assert set(own.columns) == set(OWNSHIP_EXPORT_COLUMNS)
    assert set(intruders.columns) == set(INTRUDER_EXPORT_COLUMNS) - {PER_HEAD}


def test_state_table_is_written_as_documented(tmp_path):
    scenario = small_scenario(
        "state table",
        duration_s=1.0,
        frame_rate_hz=5.0,
        mount="forward-down",
        terrain={"type": "flat", "size_m": 6000.0, "spacing_m": 60.0},
    )
    scenario["ownship"]["start_ned_m"] = [0, 0, -500]
    (tmp_path / "g.yaml").write_text(yaml.safe_dump(scenario))
    _run("simulate", "g.yaml", "-o", "g.zarr", cwd=tmp_path)
    _run("state", "g.zarr", "-o", "state.parquet", cwd=tmp_path)
    state = pd.read_parquet(tmp_path / "state.parquet")
    assert len(state) == 5 and not state["low_quality"].all()
    _check(list(state.columns), STATE_TABLE_COLUMNS, "state")


def test_gpscheck_rows_are_built_as_documented():
    """Both kinds of row `check_run` builds, a wing-up frame and a searched one, and the alert column."""
    from skyradar.nav.gpscheck.check import FrameCheck, _row
    from skyradar.nav.gpscheck.monitor import CONSISTENT, DEFAULT_SETTINGS, WING_UP, alerts
    from skyradar.nav.gpscheck.search import PoseOffset

    gps = np.array([10.0, 20.0, math.radians(90.0)])
    wing_up = FrameCheck(0.1, float("nan"), None, WING_UP)
    searched = FrameCheck(0.9, 0.4, PoseOffset(2.0, 1.0, 0.3, 0.6, 0.5, 12.0), CONSISTENT)
    table = pd.DataFrame(
        [_row(0, 0.0, gps, wing_up, DEFAULT_SETTINGS), _row(1, 0.1, gps, searched, DEFAULT_SETTINGS)]
    )
    table["alert"] = alerts(list(table["verdict"]), DEFAULT_SETTINGS.alert_frames)
    _check(list(table.columns), GPSCHECK_COLUMNS, "gpscheck")
