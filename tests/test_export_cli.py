"""`skyradar export`: own-ship navigation and truth, and intruder truth, of a run as Parquet tables."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from cli_helpers import assert_one_line_error, skyradar
from skyradar.io.frames import FrameStoreWriter
from skyradar.io.run_export import intruder_table
from skyradar.web.sample import sample_run_dataset


def _write_run(path, n_frames: int = 8):
    """The web sample run with a navigation solution beside the truth (GNSS 2.5 m north, 0.01 rad yaw)."""
    ds = sample_run_dataset(n_frames=n_frames)
    ds = ds.assign(nav_north_m=ds["own_north_m"] + 2.5, nav_yaw_rad=ds["own_yaw_rad"] + 0.01)
    ds.attrs |= {"origin_lat_deg": 47.0, "origin_lon_deg": 11.0, "start_time": "2026-05-01T10:00:00Z"}
    writer = FrameStoreWriter(path, ds.assign(iq=ds["iq"].chunk({"time": 4})), 4, fingerprint="export-test")
    for k in writer.pending_chunks():
        writer.write_chunk(k, ds["iq"].values[writer.chunk_slice(k)])
    writer.close()
    return ds


def test_export_writes_navigation_truth_and_intruders(tmp_path, monkeypatch, capsys):
    import sys

    from skyradar.cli import main

    ds = _write_run(tmp_path / "run.zarr")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "argv", ["skyradar", "export", "run.zarr", "-o", "tables", "--json"])
    main()  # the entry point, in this process (the bad input below goes through a subprocess)
    out = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert (out["ownship_rows"], out["intruder_rows"], out["targets"], out["navigation"]) == (8, 16, 2, True)
    own = pd.read_parquet(tmp_path / "tables" / "ownship.parquet")
    np.testing.assert_array_equal(own["nav_north_m"], ds["own_north_m"].values + 2.5)  # navigation
    np.testing.assert_array_equal(own["own_north_m"], ds["own_north_m"].values)  # and truth, side by side
    assert own["utc"].iloc[1] == pd.Timestamp("2026-05-01T10:00:01Z")
    intr = pd.read_parquet(tmp_path / "tables" / "intruders.parquet")
    crossing = intr[intr["target"] == "crossing"]
    np.testing.assert_array_equal(crossing["tgt_east_m"], ds["tgt_east_m"].sel(target="crossing").values)
    bad = skyradar("export", "tables", "-o", "again", cwd=tmp_path)  # a folder of tables is not a run
    assert_one_line_error(bad, "tables")
    csv = skyradar("export", "run.zarr", "-o", "own.csv", cwd=tmp_path)  # a table name, but not Parquet
    assert_one_line_error(csv, "--output own.csv", "own.parquet")
    assert not (tmp_path / "own.csv").exists()


def test_intruder_table_adds_each_heads_view():
    ds = sample_run_dataset(n_frames=3)
    left = ds.assign(tgt_visible=~ds["tgt_visible"])
    table = intruder_table(ds, {"nose": ds, "left": left})
    assert {"tgt_visible@nose", "tgt_visible@left"} <= set(table) and "tgt_north_m@left" not in table
    np.testing.assert_array_equal(table["tgt_visible@left"], ~table["tgt_visible"])
    assert table[["time_s", "target_index"]].values.tolist()[:3] == [[0.0, 0], [0.0, 1], [1.0, 0]]


@pytest.mark.parametrize("name", ["run.parquet"])
def test_export_paths_beside_a_parquet_name(name):
    from skyradar.io.run_export import export_paths

    assert [p.name for p in export_paths(name)] == ["run.parquet", "run.intruders.parquet"]
