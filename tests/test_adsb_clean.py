"""Real ADS-B downloads: each repair of skyradar.scene.adsb_clean on a small file the test writes.

The reference is the same flight written cleanly (unix seconds, in order, one row per time, every
position present); a repaired file must give the same flyable path (within centimetres: the smoother
sees the same fixes) and say in one line what was done.
"""

from __future__ import annotations

import gzip
import logging

import numpy as np
import pandas as pd
import pytest

from skyradar.errors import InputError
from skyradar.scene.adsb import read_trajectories, read_trajectory
from skyradar.scene.adsb_clean import glitch_rows
from skyradar.scene.flights import straight

T0 = 1_700_000_000  # unix s
ORIGIN = (47.0, 11.0, 900.0)


def _rows(n: int = 12) -> pd.DataFrame:
    """A climbing straight flight at 1 Hz in the traffic/OpenSky convention (ft, kt, ft/min)."""
    truth = straight([0.0, 0.0, -600.0], 70.0, 55.0, n - 1.0, climb_mps=2.0, origin=ORIGIN, rate_hz=1.0)
    s = truth.sample(truth.time_s)
    return pd.DataFrame(
        {
            "timestamp": T0 + s.time_s,
            "icao24": "3c6444",
            "latitude": s.lat_deg,
            "longitude": s.lon_deg,
            "altitude": s.alt_m / 0.3048,
        }
    )


def _same(a, b, atol_m: float = 0.2) -> None:
    assert (a.start_s, a.end_s) == pytest.approx((b.start_s, b.end_s), abs=1e-6)
    times = np.linspace(a.start_s, a.end_s, 50)
    np.testing.assert_allclose(a.sample(times).position_ned_m, b.sample(times).position_ned_m, atol=atol_m)
    assert a.epoch_s == pytest.approx(b.epoch_s) and a.origin == pytest.approx(b.origin)


@pytest.fixture
def reference(tmp_path):
    _rows().to_csv(tmp_path / "ref.csv", index=False)
    return read_trajectory(tmp_path / "ref.csv")


def _read(path, caplog):
    """The trajectory and the one line logged for the file."""
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="skyradar.scene.adsb"):
        traj = read_trajectory(path)
    lines = [r.getMessage() for r in caplog.records if str(path) in r.getMessage()]
    assert len(lines) == 1 and "\n" not in lines[0], lines
    return traj, lines[0]


def test_pandas_default_json_gz_in_epoch_milliseconds(tmp_path, reference, caplog):
    # What pandas' to_json() wrote for datetimes by default (orient="columns", epoch ms), gzipped;
    # written as integer ms here since pandas 3 deprecates the epoch date format itself.
    df = _rows().assign(timestamp=lambda d: (d["timestamp"] * 1000).astype("int64"))
    df.to_json(tmp_path / "f.json.gz")
    traj, line = _read(tmp_path / "f.json.gz", caplog)
    _same(traj, reference)
    assert "timestamp in epoch ms" in line


@pytest.mark.parametrize(("unit", "scale"), [("us", 1e6), ("ns", 1e9)])
def test_epoch_micro_and_nanoseconds_csv_gz(tmp_path, reference, caplog, unit, scale):
    _rows().assign(timestamp=lambda d: (d["timestamp"] * scale).astype("int64")).to_csv(
        tmp_path / "f.csv.gz", index=False
    )
    traj, line = _read(tmp_path / "f.csv.gz", caplog)
    _same(traj, reference)
    assert f"timestamp in epoch {unit}" in line


def test_iso_dates_and_other_json_orients(tmp_path, reference):
    iso = _rows().assign(
        timestamp=lambda d: pd.to_datetime(d["timestamp"], unit="s", utc=True).dt.strftime(
            "%Y-%m-%dT%H:%M:%S"
        )
    )  # no zone: taken as UTC
    iso.to_csv(tmp_path / "iso.csv", index=False)
    _same(read_trajectory(tmp_path / "iso.csv"), reference)
    for orient in ("split", "index", "table", "records"):
        with gzip.open(tmp_path / f"{orient}.json.gz", "wt") as fh:
            fh.write(_rows().to_json(orient=orient))
        _same(read_trajectory(tmp_path / f"{orient}.json.gz"), reference)


def test_rows_out_of_order_and_a_step_back(tmp_path, reference, caplog):
    df = _rows()
    df.iloc[[0, 5, 3, 1, 2, 4, 6, 7, 8, 9, 11, 10]].to_csv(tmp_path / "f.csv", index=False)
    traj, line = _read(tmp_path / "f.csv", caplog)
    _same(traj, reference)
    assert "sorted by time (3 step(s) back)" in line
    late = pd.concat([df.drop(index=4), df.iloc[[4]]])  # one late message at the end
    late.to_csv(tmp_path / "late.csv", index=False)
    traj, line = _read(tmp_path / "late.csv", caplog)
    _same(traj, reference)
    assert "sorted by time (1 step(s) back)" in line


def test_duplicated_timestamps_merge_position_and_velocity_rows(tmp_path, caplog):
    df = _rows()
    vel = df[["timestamp", "icao24"]].assign(groundspeed=107.0, track=70.0, vertical_rate=394.0)
    both = pd.concat([df.assign(groundspeed=np.nan, track=np.nan, vertical_rate=np.nan), vel])
    both.sort_values("timestamp", kind="stable").to_csv(tmp_path / "f.csv", index=False)
    traj, line = _read(tmp_path / "f.csv", caplog)
    assert f"merged {len(df)} row(s) sharing a timestamp" in line and traj.end_s == len(df) - 1
    gs = 107.0 * 1852.0 / 3600.0  # the merged rows carry the velocity messages' values
    assert np.hypot(*traj.velocity_ned_mps[0, :2]) == pytest.approx(gs, abs=0.3)


def test_nan_positions_and_times_are_dropped(tmp_path, reference, caplog):
    df = _rows()
    extra = df.iloc[[3, 7]].assign(timestamp=[T0 + 3.5, T0 + 7.5], latitude=np.nan)
    no_time = df.iloc[[2]].assign(timestamp=np.nan)
    pd.concat([df, extra, no_time]).to_csv(tmp_path / "f.csv", index=False)
    traj, line = _read(tmp_path / "f.csv", caplog)
    _same(traj, reference)
    assert "dropped 2 row(s) without a position" in line and "dropped 1 row(s) without a time" in line


def test_geoaltitude_preferred_gaps_filled_from_barometric(tmp_path, caplog):
    df = _rows()
    geo_ft = df["altitude"] + 150.0  # geometric 150 ft above pressure altitude
    df.assign(geoaltitude=geo_ft.where(df.index != 5)).to_csv(tmp_path / "f.csv", index=False)
    traj, line = _read(tmp_path / "f.csv", caplog)
    alt = traj.sample(np.arange(len(df), dtype=float)).alt_m
    np.testing.assert_allclose(alt, geo_ft * 0.3048, atol=0.2)  # the gap: baro + median offset
    assert "1 geoaltitude gap(s) filled from 'altitude' + median offset 46 m" in line
    df.to_csv(tmp_path / "baro.csv", index=False)
    assert "no geoaltitude: barometric 'altitude' taken as height" in _read(tmp_path / "baro.csv", caplog)[1]


def test_impala_state_vectors_use_geoaltitude_in_metres(tmp_path):
    df = _rows()
    alt_m = df["altitude"] * 0.3048
    impala = pd.DataFrame(
        {
            "time": df["timestamp"],
            "icao24": df["icao24"],
            "lat": df["latitude"],
            "lon": df["longitude"],
            "baroaltitude": alt_m - 30.0,
            "geoaltitude": alt_m.where(df.index != 2),
        }
    )
    impala.to_parquet(tmp_path / "f.parquet")
    traj = read_trajectory(tmp_path / "f.parquet")
    np.testing.assert_allclose(traj.sample(np.arange(len(df), dtype=float)).alt_m, alt_m, atol=0.2)


def test_glitch_fixes_dropped_within_budget_refused_beyond(tmp_path, reference, caplog):
    df = pd.concat([_rows(40)] * 1, ignore_index=True)
    bad = df.copy()
    bad.loc[17, "latitude"] += 0.5  # a bad decode 55 km away
    bad.loc[30, "altitude"] = 120_000.0  # and an impossible altitude
    bad.to_csv(tmp_path / "f.csv", index=False)
    traj, line = _read(tmp_path / "f.csv", caplog)
    assert "dropped 2 glitch fix(es) (1 out of range, 1 out of reach)" in line
    kept = np.delete(np.arange(40.0), [17, 30])
    clean = _rows(40)
    clean.to_csv(tmp_path / "clean.csv", index=False)
    _same(traj, read_trajectory(tmp_path / "clean.csv"), atol_m=0.5)  # the two glitches left no trace
    assert traj.covers(kept).all()
    bad.loc[[3, 9, 21], "latitude"] += 0.5  # 5 of 40 fixes: more than 5 %
    bad.to_csv(tmp_path / "f.csv", index=False)
    with pytest.raises(InputError, match=r"f.csv: field 'altitude' out of range at row 30 .*; 5 of 40 fixes"):
        read_trajectory(tmp_path / "f.csv")


def test_glitch_rows_property_an_isolated_spike_only():
    rng = np.random.default_rng(3)
    t = np.cumsum(rng.uniform(0.5, 2.0, 50))
    pos = np.outer(t, [60.0, -20.0, 1.0]) + rng.normal(0, 5.0, (50, 3))
    assert not glitch_rows(pos, t, 1029.0).any()
    for k in (0, 24, 49):  # first, middle, last fix
        spiked = pos.copy()
        spiked[k] += 20_000.0
        assert np.flatnonzero(glitch_rows(spiked, t, 1029.0)).tolist() == [k]


def test_several_aircraft_one_line_per_file(tmp_path, caplog):
    a = _rows()
    b = _rows().assign(icao24="008123", latitude=lambda d: d["latitude"] + 0.02)
    pd.concat([a, b]).sample(frac=1.0, random_state=1).to_csv(tmp_path / "many.csv.gz", index=False)
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="skyradar.scene.adsb"):
        tracks = read_trajectories(tmp_path / "many.csv.gz")
    assert sorted(tracks) == ["008123", "3c6444"]
    (line,) = [r.getMessage() for r in caplog.records]
    assert "3c6444: sorted by time" in line and "008123: sorted by time" in line


def test_readsb_trace_json(tmp_path, reference, caplog):
    """readsb / ADS-B Exchange trace_full_*.json: offsets from a base time, "ground" altitudes."""
    import json

    df = _rows()
    trace = [
        [
            float(r.timestamp - T0),
            r.latitude,
            r.longitude,
            r.altitude,
            107.0,
            70.0,
            0,
            394.0,
            None,
            "adsb_icao",
        ]
        for r in df.itertuples()
    ]
    trace[3][8] = {"type": "adsb_icao", "flight": "DLH4AB  "}
    trace.append([11.5, 47.1, 11.1, "ground", None, None, 0, None, None, "adsb_icao"])
    (tmp_path / "trace_full_3c6444.json").write_text(
        json.dumps({"icao": "3c6444", "timestamp": T0, "trace": trace})
    )
    traj, line = _read(tmp_path / "trace_full_3c6444.json", caplog)
    _same(traj, reference)
    assert traj.name == "DLH4AB" and "dropped 1 row(s) without an altitude" in line
