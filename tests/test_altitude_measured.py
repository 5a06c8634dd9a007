"""The tracks' and alerts' ``altitude_measured``: False while a track's height is the co-altitude prior."""

from __future__ import annotations

import numpy as np
import pandas as pd
from hypothesis import given, settings
from hypothesis import strategies as st

from skyradar.daa.pipeline import alerts_from_tracks
from skyradar.track.ground_doa import altitude_measured
from skyradar.track.track_table import track_detections


def _by_hand(ids, rows, measured_det, n, least):
    out = []
    for k, tid in enumerate(ids):
        mine = [r for i, r in zip(ids[: k + 1], rows[: k + 1], strict=True) if i == tid and r >= 0]
        out.append(sum(measured_det[r] for r in mine[-n:]) >= least)
    return out


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.tuples(st.integers(0, 2), st.integers(-1, 7)), min_size=1, max_size=40),
    st.lists(st.booleans(), min_size=8, max_size=8),
    st.integers(1, 6),
    st.integers(1, 4),
)
def test_flag_counts_the_last_n_detections_of_each_track(rows, measured_det, n, least):
    ids = [r[0] for r in rows]
    det_rows = [r[1] for r in rows]
    det = pd.DataFrame({"north_m": 0.0, "elevation_measured": measured_det})
    got = altitude_measured(np.array(ids), np.array(det_rows), det, n=n, least=least)
    assert got.tolist() == _by_hand(ids, det_rows, measured_det, n, least)


def _detections(elevation_measured: bool, n: int = 40) -> pd.DataFrame:
    # A closing aircraft 200 m above a level own-ship at the origin, one detection per 0.1 s frame.
    t = np.arange(n) * 0.1
    north = 2000.0 - 60.0 * t
    down = np.where(elevation_measured, -200.0, 0.0)  # the prior puts it co-altitude
    slant = np.hypot(north, 200.0)
    return pd.DataFrame(
        {
            "time_s": t,
            "range_m": slant,
            "radial_velocity_mps": -60.0 * north / slant,
            "north_m": north,
            "east_m": 0.0,
            "down_m": down,
            "snr_db": 25.0,
            "elevation_measured": elevation_measured,
        }
    )


def test_tracks_and_alerts_say_when_the_height_is_a_prior():
    own = pd.DataFrame(
        {
            "time_s": [0.0, 10.0],
            "own_north_m": 0.0,
            "own_east_m": 0.0,
            "own_down_m": 0.0,
            "own_vn_mps": 0.0,
            "own_ve_mps": 0.0,
            "own_vd_mps": 0.0,
        }
    )
    for measured in (True, False):
        tracks = track_detections(_detections(measured))
        confirmed = tracks[tracks["confirmed"]]
        assert len(confirmed) > 10
        flag = confirmed["altitude_measured"]
        assert flag.all() if measured else not flag.any()
        alerts = alerts_from_tracks(tracks, own, with_advice=False)
        assert len(alerts) and (alerts["altitude_measured"] == measured).all()


def test_alerts_of_tracks_without_the_flag_count_their_height_as_measured():
    tracks = track_detections(_detections(True)).drop(columns="altitude_measured")
    own = pd.DataFrame(
        {
            "time_s": [0.0, 10.0],
            "own_north_m": 0.0,
            "own_east_m": 0.0,
            "own_down_m": 0.0,
            "own_vn_mps": 0.0,
            "own_ve_mps": 0.0,
            "own_vd_mps": 0.0,
        }
    )
    assert alerts_from_tracks(tracks, own, with_advice=False)["altitude_measured"].all()
