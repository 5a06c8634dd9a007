"""One job per module and command: daa tables apart from alerting, bench chain apart from bench flight."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from skyradar.daa.pipeline import alert_summary, alerts_for_run, alerts_from_tracks
from skyradar.daa.provenance import ownship_signature
from skyradar.daa.run_tables import has_ownship, ownship_from_frames, truth_tracks
from skyradar.errors import InputError


def _run(north0_m: float) -> xr.Dataset:
    """A 20 s run: own-ship flying north at 50 m/s, one intruder 3 km ahead coming head-on."""
    t = np.arange(0.0, 20.0, 0.5)
    own = {"own_north_m": north0_m + 50 * t, "own_east_m": 0 * t, "own_down_m": -1000 + 0 * t}
    own |= {"own_vn_mps": 50 + 0 * t, "own_ve_mps": 0 * t, "own_vd_mps": 0 * t}
    tgt = {"tgt_north_m": north0_m + 3000 - 50 * t, "tgt_east_m": 0 * t, "tgt_down_m": -1000 + 0 * t}
    tgt |= {"tgt_vn_mps": -50 + 0 * t, "tgt_ve_mps": 0 * t, "tgt_vd_mps": 0 * t}
    data = {k: ("time", v) for k, v in own.items()} | {
        k: (("time", "target"), v[:, None]) for k, v in tgt.items()
    }
    return xr.Dataset(data, coords={"time": t}, attrs={"origin_lat_deg": 52.0, "origin_lon_deg": 4.0})


def test_alerts_for_run_on_truth_is_alerts_from_tracks_on_the_truth_table():
    ds = _run(0.0)
    got = alerts_for_run(ds, run_name="a.zarr")
    want = alerts_from_tracks(truth_tracks(ds), ownship_from_frames(ds, "a.zarr"))
    pd.testing.assert_frame_equal(got, want)
    assert alert_summary(got)["max_level"] == 3  # head-on at 100 m/s closing from 3 km: a warning


def test_alerts_for_run_refuses_tracks_of_another_run():
    a, b = _run(0.0), _run(3000.0)
    tracks = truth_tracks(a)
    tracks.attrs["ownship_signature"] = ownship_signature(a, "a.zarr")
    assert len(alerts_for_run(a, tracks, run_name="a.zarr", tracks_name="trk.parquet"))
    with pytest.raises(InputError, match=r"^trk\.parquet: tracks come from run a\.zarr .* --ownship b\.zarr"):
        alerts_for_run(b, tracks, run_name="b.zarr", tracks_name="trk.parquet")


def test_a_run_without_ownship_state_has_no_ownship_table():
    ds = _run(0.0).drop_vars("own_vd_mps")
    assert not has_ownship(ds)
    with pytest.raises(InputError, match=r"^b\.zarr: no own-ship state .*own_vd_mps"):
        alerts_for_run(ds, run_name="b.zarr")
