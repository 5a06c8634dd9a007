"""The streaming chain, fed frame by frame, gives the batch chain's detections, tracks and alerts: on a
clear-sky head-on, over flat terrain with clutter suppression and navigation errors, and with two heads.

Equal: every detection, every confirmed track row, every alert row (values to float tolerance).
Not equal by design (:mod:`skyradar.stream`): the stream's tracks table holds no tentative rows of
a track before its confirmation (the batch keeps those of tracks confirmed later); each row it does
hold is the batch's row of that frame and track.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from skyradar.chain import run_chain
from skyradar.daa.alerting import RADAR_ALERT_CONFIG
from skyradar.scene.scenario import Scenario
from skyradar.scene.trajectories import TrajectorySample
from skyradar.stream import FrameResult, StreamingChain

# A clear-sky head-on: the intruder closes from 1.2 km at 90 m/s and is warned within the 4 s.
HEAD_ON = {
    "name": "stream head-on",
    "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    "radar": {"range_limit_m": 1500},
    "ownship": {"type": "straight", "start_ned_m": [0, 0, -2000], "speed_mps": 50},
    "intruders": [
        {
            "name": "A",
            "type": "straight",
            "start_ned_m": [1200, -60, -2000],
            "heading_deg": 180,
            "speed_mps": 40,
        }
    ],
    "frame_rate_hz": 9.4,
    "duration_s": 4.0,
}
# Flat ground 500 m below, clutter suppressed, GNSS/AHRS errors: ground detections, clutter tracks
# held by the ground test, the clutter predictions' anchors moving with the navigation noise.
OVER_TERRAIN = {
    "name": "stream terrain",
    "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    "mount": "forward",
    "radar": {"range_limit_m": 1500},
    "terrain": {"type": "flat", "size_m": 3000, "spacing_m": 60},
    "navigation": {"model": "ga-typical"},
    "ownship": {"type": "straight", "start_ned_m": [0, 0, -500], "heading_deg": 0, "speed_mps": 40},
    "intruders": [
        {
            "name": "A",
            "type": "encounter",
            "kind": "head-on",
            "t_cpa_s": 10,
            "rcs_m2": 2.0,
            "intruder_speed_mps": 40,
        }
    ],
    "frame_rate_hz": 5.0,
    "duration_s": 3.0,
    "simulation": {"facet_size_m": 30.0},
}
# Two heads whose beams overlap on a converging intruder: the heads' detections fused frame by frame.
TWO_HEADS = {
    **HEAD_ON,
    "name": "stream two heads",
    "radars": [{"name": "nose", "mount": "nose"}, {"name": "left", "mount": "left-wingtip"}],
    "intruders": [
        {
            "name": "A",
            "type": "straight",
            "start_ned_m": [1000, -700, -2000],
            "heading_deg": 150,
            "speed_mps": 40,
        }
    ],
    "duration_s": 3.0,
}
CASES = {
    "head-on": (HEAD_ON, {}),
    "terrain": (OVER_TERRAIN, {"suppression": "auto"}),
    "two heads": (TWO_HEADS, {}),
}


@pytest.fixture(scope="module", params=list(CASES))
def both(request):
    spec, options = CASES[request.param]
    built = Scenario.from_dict(spec).build()
    batch = run_chain(built, RADAR_ALERT_CONFIG, process_options=options)
    chain = StreamingChain(built, RADAR_ALERT_CONFIG, process_options=options)
    results = chain.run()
    return request.param, batch, chain.tables(), results


def _assert_same(stream: pd.DataFrame, batch: pd.DataFrame) -> None:
    """Same rows and columns; numbers equal to float tolerance, other values (flags, names, advice
    bands) equal."""
    stream, batch = stream.reset_index(drop=True), batch.reset_index(drop=True)
    assert list(stream.columns) == list(batch.columns)
    assert len(stream) == len(batch)
    for column in batch.columns:
        a, b = stream[column], batch[column]
        if pd.api.types.is_numeric_dtype(b) and not pd.api.types.is_bool_dtype(b):
            np.testing.assert_allclose(
                a.to_numpy(float), b.to_numpy(float), rtol=1e-9, atol=1e-9, err_msg=column
            )
        elif len(b) and isinstance(b.iloc[0], list | np.ndarray):
            assert all(np.allclose(x, y, equal_nan=True) for x, y in zip(a, b, strict=True)), column
        else:
            assert a.tolist() == b.tolist(), column


def test_the_stream_gives_the_batch_detections(both):
    case, batch, stream, _ = both
    assert len(batch["detections"]) > 0
    if case == "terrain":  # the case means something only with ground returns in it
        assert batch["detections"]["is_ground"].sum() > 100
    if case == "two heads":  # and with both heads seeing the intruder
        assert batch["detections"]["radar"].nunique() == 2
    _assert_same(stream["detections"], batch["detections"])
    _assert_same(stream["ownship"], batch["ownship"])


def test_the_stream_gives_the_batch_confirmed_tracks(both):
    _, batch, stream, _ = both
    confirmed = batch["tracks"][batch["tracks"]["confirmed"]]
    assert len(confirmed) > 10
    _assert_same(stream["tracks"][stream["tracks"]["confirmed"]], confirmed)


def test_every_track_row_of_the_stream_is_the_batch_row_of_its_frame_and_track(both):
    _, batch, stream, _ = both
    tracks = stream["tracks"]
    keys = ["frame", "track_id"]
    matched = tracks[keys].merge(batch["tracks"].reset_index(), on=keys, how="left")
    assert matched["index"].notna().all()
    _assert_same(tracks, batch["tracks"].loc[matched["index"].astype(int)])
    # What the stream leaves out are tentative rows: tracks not yet confirmed on those frames.
    assert len(tracks) <= len(batch["tracks"])


def test_the_stream_gives_the_batch_alerts(both):
    case, batch, stream, results = both
    if case != "two heads":
        assert (batch["alerts"]["level"] == 3).any()  # the head-on intruder is warned
    _assert_same(stream["alerts"], batch["alerts"])
    assert stream["alerts"].attrs["rows_skipped_no_state"] == batch["alerts"].attrs["rows_skipped_no_state"]
    advised = [r for r in results if r.advice is not None]
    assert all(np.isfinite(r.advice.preferred_heading_deg) for r in advised)
    assert bool(advised) == bool((batch["alerts"]["level"] > 0).any())


def test_frames_come_in_time_order_and_stepping_past_the_end_raises_stop_iteration(both):
    _, batch, _, results = both
    assert all(isinstance(r, FrameResult) for r in results)
    assert [r.frame for r in results] == list(range(len(results)))
    times = np.array([r.time_s for r in results])
    assert np.all(np.diff(times) > 0) and np.array_equal(times, batch["ownship"]["time_s"].to_numpy())
    for r in results:  # each frame's rows are that frame's
        assert (r.detections["frame"] == r.frame).all() and (r.tracks["time_s"] == r.time_s).all()
        assert (r.alerts["time_s"] == r.time_s).all() and r.tracks["confirmed"].all()


def test_a_finished_chain_raises_stop_iteration():
    built = Scenario.from_dict({**HEAD_ON, "duration_s": 0.3}).build()
    chain = StreamingChain(built, with_advice=False)
    assert len(chain.run()) == chain.n_frames == chain.frame
    with pytest.raises(StopIteration):
        chain.step()
    assert list(chain) == []


class _Displaced(StreamingChain):
    """The closed loop's seam: an own-ship flown 100 m east of the scenario's."""

    def ownship_state(self, frame: int) -> TrajectorySample:
        own = super().ownship_state(frame)
        east = own.position_ned_m + np.array([0.0, 100.0, 0.0])
        return TrajectorySample(
            own.time_s,
            east,
            own.velocity_ned_mps,
            own.attitude_rad,
            own.lat_deg,
            own.lon_deg + 100.0 / 68_600.0,
            own.alt_m,
        )


def test_the_ownship_state_seam_moves_everything_the_frame_sees():
    built = Scenario.from_dict({**HEAD_ON, "duration_s": 0.5}).build()
    plain, displaced = StreamingChain(built, with_advice=False), _Displaced(built, with_advice=False)
    plain.run()
    displaced.run()
    a, b = plain.tables(), displaced.tables()
    np.testing.assert_allclose(b["ownship"]["own_east_m"] - a["ownship"]["own_east_m"], 100.0)
    # The intruder is seen from the displaced own-ship: 100 m further west of it.
    da, db = a["detections"], b["detections"]
    assert len(da) and len(db)
    assert abs(db["east_m"].mean() - da["east_m"].mean()) < 20.0
    assert abs(np.median(db["azimuth_rad"]) - np.median(da["azimuth_rad"])) > 0.05
