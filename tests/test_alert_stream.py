"""AlertStream, one frame at a time, gives the batch alerts of a run longer than its window.

The stream keeps a trailing window of rows and each track's filter state; the batch sees the whole
run. A run of 80 s (two windows) with a head-on conflict whose track drops out for 4 s (lost-track
predictions, then the same id again), a crossing track with covariances (the velocity gate and
the widened volumes), a range-only track (the range fit), a track that dies and comes back after
the hold with the same id must give the same table, advice included.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from skyradar.daa.alerting import RADAR_ALERT_CONFIG
from skyradar.daa.pipeline import AlertStream, alerts_from_tracks

FRAME_S = 0.2
TIMES = np.round(np.arange(0.0, 80.0, FRAME_S), 6)


def _own() -> pd.DataFrame:
    return pd.DataFrame(
        {
            "time_s": TIMES,
            "own_north_m": 50.0 * TIMES,
            "own_east_m": 0.0,
            "own_down_m": -1000.0,
            "own_vn_mps": 50.0,
            "own_ve_mps": 0.0,
            "own_vd_mps": 0.0,
            "own_yaw_rad": 0.0,
        }
    )


def _straight(track_id, times, start, velocity, rng, sigma_v=None) -> pd.DataFrame:
    start, velocity = np.asarray(start, float), np.asarray(velocity, float)
    pos = start + times[:, None] * velocity + rng.normal(0.0, 5.0, (times.size, 3))
    vel = velocity + rng.normal(0.0, 1.0, (times.size, 3))
    rows = pd.DataFrame(
        {
            "time_s": times,
            "track_id": track_id,
            "north_m": pos[:, 0],
            "east_m": pos[:, 1],
            "down_m": pos[:, 2],
            "vn_mps": vel[:, 0],
            "ve_mps": vel[:, 1],
            "vd_mps": vel[:, 2],
        }
    )
    if sigma_v is not None:  # a velocity covariance that shrinks as the track converges
        var_v = (sigma_v / np.sqrt(1.0 + times - times[0])) ** 2
        for i in range(3):
            for j in range(3):
                rows[f"cov_pp_{i}{j}"] = 400.0 if i == j else 0.0
                rows[f"cov_vv_{i}{j}"] = var_v if i == j else 0.0
    return rows


def _range_only(track_id, times, start, velocity) -> pd.DataFrame:
    rel = np.asarray(start, float) + times[:, None] * (np.asarray(velocity, float) - [50.0, 0.0, 0.0])
    rng_m = np.linalg.norm(rel, axis=1)
    rate = np.einsum("ij,j->i", rel, np.asarray(velocity, float) - [50.0, 0.0, 0.0]) / rng_m
    nan = np.full(times.size, np.nan)
    return pd.DataFrame(
        {
            "time_s": times,
            "track_id": track_id,
            "north_m": nan,
            "east_m": nan,
            "down_m": nan,
            "vn_mps": nan,
            "ve_mps": nan,
            "vd_mps": nan,
            "range_m": rng_m,
            "range_rate_mps": rate,
        }
    )


def tracks_and_ownship() -> tuple[pd.DataFrame, pd.DataFrame]:
    rng = np.random.default_rng(3)
    head_on_t = TIMES[(TIMES >= 2.0) & ~((TIMES >= 20.0) & (TIMES < 24.0))]  # a 4-s drop-out
    head_on = _straight(1, head_on_t, [4500.0, 30.0, -1000.0], [-60.0, 0.0, 0.0], rng)
    crossing_t = TIMES[TIMES >= 5.0]
    crossing = _straight(2, crossing_t, [2400.0, -2000.0, -1010.0], [0.0, 55.0, 0.0], rng, sigma_v=20.0)
    ranged_t = TIMES[(TIMES >= 1.0) & (TIMES < 40.0)]
    ranged = _range_only(3, ranged_t, [3000.0, 200.0, 0.0], [-40.0, 0.0, 0.0])
    comeback_t = TIMES[((TIMES >= 3.0) & (TIMES < 12.0)) | (TIMES >= 45.0)]  # gone longer than the hold
    comeback = _straight(4, comeback_t, [3000.0, 900.0, -1000.0], [-20.0, -10.0, 0.0], rng)
    tracks = pd.concat([head_on, crossing, ranged, comeback], ignore_index=True)
    tracks = tracks.sort_values(["time_s", "track_id"], kind="stable").reset_index(drop=True)
    tracks["confirmed"] = True
    return tracks, _own()


@pytest.fixture
def run() -> tuple[pd.DataFrame, pd.DataFrame]:
    return tracks_and_ownship()


def _streamed(tracks: pd.DataFrame, own: pd.DataFrame, **kw) -> pd.DataFrame:
    stream = AlertStream(RADAR_ALERT_CONFIG, **kw)
    frames = []
    for t in TIMES:
        frames.append(stream.step(t, tracks[tracks["time_s"] == t], own[own["time_s"] == t]))
    return pd.concat(frames, ignore_index=True)


def test_the_stream_gives_the_batch_alerts_over_a_run_of_two_windows(run):
    tracks, own = run
    batch = alerts_from_tracks(tracks, own, RADAR_ALERT_CONFIG, with_advice=True)
    streamed = _streamed(tracks, own, with_advice=True)
    assert (batch["level"] >= 3).any() and (batch["extrapolated"]).any()  # the run holds what is tested
    assert (batch["geometry"] == "range-only").any()
    pd.testing.assert_frame_equal(streamed, batch, check_dtype=False)
