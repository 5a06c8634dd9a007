"""Track ids through reacquisition: an aircraft's track does not take a ground track's id.

Over hills, an intruder's new track can meet a lost chain of ground clutter tracks whose
prediction, alias unresolved, has a range spread of 168 m and takes the intruder inside its gate.
Reacquiring that id, the intruder would be warned under the ground track's id, with the ground
track's rows as its history.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from tests.test_ground_tracks import AGL_M, SPEED_MPS, _detections, _own

from skyradar.track.reacquired_ids import relabel_reacquired
from skyradar.track.track_table import track_detections

T = np.arange(0.0, 12.0, 1.0 / 9.4)
GROUND_POINT = np.array([2500.0, 900.0, AGL_M])


def _aircraft_where_the_ground_point_is(t: np.ndarray, up_deg: float, cross_mps: float) -> np.ndarray:
    """An aircraft at the ground point's range ``up_deg`` above its direction at ``t[0]``, flying
    ``cross_mps`` across the line of sight: same range and Doppler as the point, not static."""
    own = np.array([SPEED_MPS * t[0], 0.0, 0.0])
    d = GROUND_POINT - own
    el = np.arcsin(-d[2] / np.linalg.norm(d)) + np.radians(up_deg)
    az = np.arctan2(d[1], d[0])
    u = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)])
    return (
        own + np.linalg.norm(d) * u + (t - t[0])[:, None] * cross_mps * np.array([-np.sin(az), np.cos(az), 0])
    )


@pytest.mark.parametrize("cross_mps", [25.0, 35.0])
def test_aircraft_does_not_take_the_id_and_rows_of_a_lost_ground_track(cross_mps):
    ground = T < 2.5  # the ground point, then a gap in which its track is closed and kept as lost
    air = T >= 4.6  # then an aircraft inside the lost track's gate
    aircraft = _aircraft_where_the_ground_point_is(T[air], 3.0, cross_mps)
    det = pd.concat(
        [
            _detections(np.tile(GROUND_POINT, (ground.sum(), 1)), t=T[ground], seed=1),
            _detections(aircraft, t=T[air], seed=2),
        ],
        ignore_index=True,
    )
    tracks = track_detections(det, ownship=_own(T), frame_times_s=T)
    assert tracks.track_id.nunique() == 1 and tracks.confirmed.any()
    # No row of the aircraft's track is the ground point's, nor any time before the aircraft came.
    assert tracks.time_s.min() > 4.5
    assert not np.isin(tracks.detection_row, np.arange(ground.sum())).any()


def test_aircraft_keeps_its_id_through_a_gap_with_the_ground_test_on():
    # A converging aircraft 150 m over the ground fades for 3 s: its two tracks are one object.
    start, vel = np.array([3000.0, 600.0, AGL_M - 150.0]), np.array([-40.0, -10.0, 0.0])
    keep = (T < 3.0) | (T > 6.0)
    det = _detections(start + T[keep, None] * vel, t=T[keep], seed=3)
    tracks = track_detections(det, ownship=_own(T), frame_times_s=T)
    confirmed = tracks[tracks.confirmed]
    assert confirmed.track_id.nunique() == 1
    assert confirmed.time_s.min() < 3.0 and confirmed.time_s.max() > 11.0


def test_a_chain_of_reacquisitions_joins_only_behind_objects():
    # Track 1 (ground) lost; 2 reacquires it (undone: 2 keeps its id); 3 reacquires 2 (kept: 2 is
    # an object); 4 reacquires 3's id later and 3 was not (4 keeps its own id).
    reported = [1, 1, 2, 1, 1, 3, 1, 1, 4, 1]
    t = np.arange(10.0)
    df = pd.DataFrame({"time_s": t, "track_id": reported, "detection_row": np.arange(10)})
    pairs, times = np.array([[2, 1], [3, 1], [4, 1]]), np.array([3.0, 6.0, 9.0])

    def is_object(rows: pd.DataFrame) -> bool:  # the lost track's rows: 0-1, then 2-4, then 5-7
        return rows.detection_row.tolist() == [2, 3, 4]

    out = relabel_reacquired(df, pairs, times, is_object)
    assert out.track_id.tolist() == [1, 1, 2, 2, 2, 2, 2, 2, 4, 4]


def test_known_verdicts_are_read_not_judged_again():
    # A stream relabels its growing table every frame: each reacquisition is judged once, on the
    # lost track's rows before it, which later rows do not change.
    df = pd.DataFrame(
        {"time_s": np.arange(6.0), "track_id": [1, 1, 2, 1, 1, 1], "detection_row": np.arange(6)}
    )
    pairs, times = np.array([[2, 1]]), np.array([3.0])
    calls: list[list[int]] = []

    def is_object(rows: pd.DataFrame) -> bool:
        calls.append(rows.detection_row.tolist())
        return True

    verdicts: dict = {}
    first = relabel_reacquired(df.iloc[:4], pairs, times, is_object, verdicts)
    again = relabel_reacquired(df, pairs, times, is_object, verdicts)
    assert calls == [[0, 1]] and verdicts == {(2, 1, 3.0): True}
    assert again.iloc[:4].equals(first) and again.track_id.tolist() == [1] * 6
