"""Scoring labels a track by what it followed while confirmed.

An intruder's track that took the id of a lost ground track keeps the ground track's unconfirmed hops
under that id; read over every row they outvote the intruder, read over the confirmed rows they do not.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import xarray as xr

from skyradar.chain import confirmed_rows, label_tracks
from skyradar.experiments.encounter_score import track_counts


def _truth(times: np.ndarray) -> xr.Dataset:
    # One intruder flying north at 60 m/s, 400 m above the own-ship, which is parked at the origin.
    north = 2000.0 - 60.0 * times
    zeros = np.zeros_like(times)
    return xr.Dataset(
        {
            "tgt_north_m": (("time", "target"), north[:, None]),
            "tgt_east_m": (("time", "target"), zeros[:, None]),
            "tgt_down_m": (("time", "target"), np.full((times.size, 1), -400.0)),
            **{f"own_{a}_m": ("time", zeros) for a in ("north", "east", "down")},
        },
        coords={"time": times, "target": ["intruder"]},
    )


def _reacquired_track(times: np.ndarray, n_ground: int) -> pd.DataFrame:
    """A lost ground track's hops (unconfirmed, on the ground 1-3 km away) whose id an intruder's
    newly confirmed track took: the table keeps both under one id."""
    rng = np.random.default_rng(3)
    north = 2000.0 - 60.0 * times
    down = np.full(times.size, -400.0)
    east = np.zeros(times.size)
    north[:n_ground] = rng.uniform(1000.0, 3000.0, n_ground)
    east[:n_ground] = rng.uniform(-2000.0, 2000.0, n_ground)
    down[:n_ground] = 0.0
    confirmed = np.arange(times.size) >= n_ground
    return pd.DataFrame(
        {
            "time_s": times,
            "track_id": 118,
            "north_m": north,
            "east_m": east,
            "down_m": down,
            "confirmed": confirmed,
            "altitude_measured": True,
            "lat_deg": np.nan,
            "lon_deg": np.nan,
            "alt_m": -down,
        }
    )


def test_a_track_is_its_intruders_when_its_confirmed_rows_follow_it():
    times = np.arange(300) / 9.4
    track = _reacquired_track(times, n_ground=200)  # 2/3 of its rows are the ground track's
    assert label_tracks(track, _truth(times)) == {118: "intruder"}
    # Read over every row, the ground's hops outvote the intruder.
    everything = track.assign(confirmed=True)
    assert label_tracks(everything, _truth(times)) == {118: "clutter"}


def test_confirmed_rows_keep_a_never_confirmed_track_whole():
    times = np.arange(300) / 9.4
    one = _reacquired_track(times, n_ground=200)
    other = one.assign(track_id=7, confirmed=False)
    rows = confirmed_rows(pd.concat([one, other], ignore_index=True))
    assert (rows["track_id"] == 118).sum() == 100 and (rows["track_id"] == 7).sum() == 300


def test_the_warned_intruder_track_is_not_counted_as_a_ground_track():
    class Flat:
        def height_at(self, lat, lon):
            return np.zeros(np.shape(lat))

    times = np.arange(300) / 9.4
    track = _reacquired_track(times, n_ground=200)
    labels = label_tracks(track, _truth(times))
    counts = track_counts(confirmed_rows(track), {118}, labels, Flat(), 500.0)
    assert counts["intruder_tracks"] == 1 and counts["ground_warning_tracks"] == 0
