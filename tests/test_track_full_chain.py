"""One track per aircraft on the full chain: simulate -> process -> track -> evaluate.

A circling glider given as ADS-B gives it (OpenSky units, fixes every 5-12 s) and a fast head-on
intruder whose radial velocity aliases (-120 m/s closing against VLim = 39 m/s), with the own-ship
in 35 deg bank S-turns that swing the beam off the glider and back. The truth is the scenario's
(in a beam, expected SNR at the CA-CFAR's 50 % threshold), never the detections or tracks.
Minutes of CPU: ``make test-slow``.
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from scipy.interpolate import CubicHermiteSpline

from cli_helpers import skyradar_in_process
from skyradar.geo import ned_to_geodetic
from skyradar.io.frames import open_frames, radar_config_of
from skyradar.track.detectable import detectable

ORIGIN = (49.78, 11.12, 700.0)
FT, KT = 0.3048, 1852.0 / 3600.0


def _opensky_csv(path, t, pos, vel) -> None:
    lat, lon, alt = (np.asarray(v, float) for v in ned_to_geodetic(pos, *ORIGIN))
    pd.DataFrame(
        {
            "timestamp": 1_700_000_000 + t,
            "latitude": lat,
            "longitude": lon,
            "altitude": alt / FT,
            "groundspeed": np.hypot(vel[:, 0], vel[:, 1]) / KT,
            "track": np.degrees(np.arctan2(vel[:, 1], vel[:, 0])) % 360.0,
            "vertical_rate": -vel[:, 2] / FT * 60.0,
        }
    ).to_csv(path, index=False)


def _scene(tmp_path, duration_s: float = 40.0) -> None:
    rng = np.random.default_rng(12)
    # Own-ship: 45 m/s, 35 deg bank S-turns (period 24 s), 1 Hz fixes of the exact path.
    t = np.arange(0.0, duration_s + 2.0, 0.25)
    bank = np.deg2rad(35.0) * np.tanh(3.0 * np.sin(2 * np.pi * t / 24.0))
    psi = (
        np.concatenate([[0.0], np.cumsum(0.5 * np.diff(t) * (np.tan(bank[1:]) + np.tan(bank[:-1])))])
        * 9.80665
        / 45
    )
    psi -= psi.mean()
    vel = np.column_stack([45 * np.cos(psi), 45 * np.sin(psi), 0 * t])
    pos = np.concatenate([[[0.0, 0.0, 0.0]], np.cumsum(0.5 * np.diff(t)[:, None] * (vel[1:] + vel[:-1]), 0)])
    pos += [-1500.0, 0.0, -100.0]
    _opensky_csv(tmp_path / "own.csv", t, pos, vel)
    # Glider: thermalling (radius 120 m, 25 m/s) and drifting, fixes every 5-12 s as ADS-B has them.
    ts = [-6.0]
    while ts[-1] < duration_s + 6.0:
        ts.append(ts[-1] + rng.uniform(5.0, 12.0))
    ts, w = np.array(ts), 25.0 / 120.0
    gp = np.column_stack([3 * ts + 120 * np.cos(w * ts), 2 * ts + 120 * np.sin(w * ts), np.zeros(ts.size)])
    gv = np.column_stack([3 - 25 * np.sin(w * ts), 2 + 25 * np.cos(w * ts), np.zeros(ts.size)])
    spline = CubicHermiteSpline(ts, gp, gv)  # the fixes lie on a smooth path
    _opensky_csv(tmp_path / "glider.csv", ts, spline(ts), spline(ts, 1))
    (tmp_path / "scene.yaml").write_text(f"""name: glider and aliasing head-on, own-ship in 35 deg S-turns
origin: {{lat_deg: {ORIGIN[0]}, lon_deg: {ORIGIN[1]}, alt_m: {ORIGIN[2]}}}
ownship: {{type: file, path: own.csv}}
intruders:
  - {{name: glider, type: file, path: glider.csv, rcs_m2: 0.5}}
  - {{name: jet, type: encounter, kind: head-on, t_cpa_s: 36, intruder_speed_mps: 75,
      horizontal_miss_m: 150, vertical_miss_m: 60, rcs_m2: 2.0}}
frame_rate_hz: 9.4
duration_s: {duration_s}
""")


@pytest.mark.slow
def test_one_track_per_aircraft_on_the_full_chain(tmp_path, monkeypatch, capsys):
    _scene(tmp_path)
    steps = [
        ("simulate", "scene.yaml", "-o", "run.zarr"),
        ("process", "run.zarr", "-o", "det.parquet"),
        ("track", "det.parquet", "--ownship", "run.zarr", "-o", "trk.parquet"),
        ("evaluate", "run.zarr", "trk.parquet", "--json"),
    ]
    monkeypatch.chdir(tmp_path)
    for args in steps:
        code, out, err = skyradar_in_process(monkeypatch, capsys, *args)
        assert code == 0, (args, err)
    result = json.loads(out.strip().splitlines()[-1])
    ds = open_frames(tmp_path / "run.zarr")
    seen = detectable(ds["tgt_visible"].values, ds["tgt_snr_db"].values, result["truth_snr_threshold_db"])
    assert seen.sum(axis=0).min() > 50, "both aircraft must be detectable for a while, else nothing is tested"
    v = ds["tgt_radial_velocity_mps"].values[:, 1]
    assert np.nanmin(v[seen[:, 1]]) < -radar_config_of(ds).v_lim_mps  # the jet aliases while detectable
    # At most one extra track per aircraft over its visible spans; no track off the aircraft.
    assert all(n <= s + 1 for n, s in zip(result["tracks_per_target"], _spans(seen), strict=True)), result
    assert result["false_tracks"] == 0 and result["completeness"] >= 0.8, result


def _spans(seen: np.ndarray, frames_apart: int = 75) -> list[int]:
    """Visible spans per target: runs of detectable frames, gaps within 8 s (75 frames) bridged."""
    out = []
    for col in seen.T:
        k = np.flatnonzero(col)
        out.append(int(1 + np.count_nonzero(np.diff(k) > frames_apart)) if k.size else 0)
    return out
