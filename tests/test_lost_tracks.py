"""A lost track's prediction holds its alert through the gap, never raises one, and stops in time."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from skyradar.daa.alerting import RADAR_ALERT_CONFIG
from skyradar.daa.conflict import WellClearVolume
from skyradar.daa.lost_tracks import lost_track_hold, lost_track_rows
from skyradar.daa.pipeline import alerts_from_tracks

FRAME_S = 1.0 / 9.4
D_NC = WellClearVolume.do365_noncoop().dthr_m


def _head_on(seconds_to_lowc: float, duration_s: float, sigma_v: float = 2.0):
    """Own-ship north at 50 m/s; an intruder closing head-on at 100 m/s, a converged track of it."""
    t = np.arange(0.0, duration_s, FRAME_S)
    own = pd.DataFrame(
        {
            "time_s": t,
            "own_north_m": 50.0 * t,
            "own_east_m": 0.0,
            "own_down_m": -1000.0,
            "own_vn_mps": 50.0,
            "own_ve_mps": 0.0,
            "own_vd_mps": 0.0,
            "own_yaw_rad": 0.0,
        }
    )
    start = D_NC + 100.0 * seconds_to_lowc
    tracks = pd.DataFrame(
        {
            "time_s": t,
            "track_id": 4,
            "north_m": start - 50.0 * t,
            "east_m": 30.0,
            "down_m": -1000.0,
            "vn_mps": -50.0,
            "ve_mps": 0.0,
            "vd_mps": 0.0,
        }
    )
    cov = {
        f"cov_{k}_{i}{j}": ((400.0 if k == "pp" else sigma_v**2) if i == j and k != "pv" else 0.0)
        for k in ("pp", "vv", "pv")
        for i in range(3)
        for j in range(3)
    }
    return own, tracks.assign(**cov)


def test_a_warning_is_held_on_every_frame_of_a_fade():
    own, tracks = _head_on(seconds_to_lowc=15.0, duration_s=12.0)
    faded = tracks[(tracks["time_s"] < 5.0) | (tracks["time_s"] > 8.0)]
    alerts = alerts_from_tracks(faded, own, RADAR_ALERT_CONFIG, with_advice=False)
    assert len(alerts) == len(tracks)  # one row per frame, the fade's predicted
    gap = alerts[(alerts["time_s"] > 5.0) & (alerts["time_s"] < 8.0)]
    assert gap["extrapolated"].all() and (gap["level"] == 3).all()
    # The prediction follows the intruder: 100 m/s closing, from its last row.
    last = faded[faded["time_s"] < 5.0].iloc[-1]
    dt = gap["time_s"].to_numpy() - last["time_s"]
    np.testing.assert_allclose(
        gap["range_m"].to_numpy(),
        np.hypot(last["north_m"] - 50.0 * last["time_s"] - 100.0 * dt, 30.0),
        rtol=1e-6,
    )


def test_a_prediction_never_raises_an_alert():
    # The track was seen only far out (no warning yet: too young); its prediction alone would put it
    # inside the volume within the warning's time, but a prediction is no evidence of a conflict.
    own, tracks = _head_on(seconds_to_lowc=12.0, duration_s=10.0)
    seen = tracks[tracks["time_s"] < 0.4]
    alerts = alerts_from_tracks(seen, own, RADAR_ALERT_CONFIG, with_advice=False)
    assert alerts["extrapolated"].iloc[len(seen) :].all()
    assert alerts["level"].max() == 0 and alerts["raw_level"].max() == 0


def test_predictions_stop_after_the_hold_and_widen_with_time():
    own, tracks = _head_on(seconds_to_lowc=30.0, duration_s=20.0)
    seen = tracks[tracks["time_s"] < 2.0]
    rows = lost_track_rows(seen, own["time_s"].to_numpy(), hold_s=8.0)
    predicted = rows[rows["extrapolated"]]
    assert predicted["time_s"].max() <= seen["time_s"].max() + 8.0 + 1e-9
    assert predicted["time_s"].max() > seen["time_s"].max() + 8.0 - FRAME_S
    sigma = np.sqrt(predicted["cov_pp_00"].to_numpy())
    assert (np.diff(sigma) > 0).all() and sigma[0] > 20.0
    assert len(lost_track_rows(seen, own["time_s"].to_numpy(), hold_s=0.0)) == len(seen)


def test_predictions_count_neither_for_nor_against_raising_a_level():
    # A track at "no conflict" is lost for 2 s and comes back predicting a warning: the 2-of-4-seconds
    # filter raises it as soon as the measured rows say so, not later because the predictions of the
    # gap were counted as "no conflict".
    from skyradar.daa.alerting import filter_alert_levels

    t = np.arange(0.0, 8.0, 0.25)
    measured = np.where(t < 1.0, 0, 3)
    gap = (t >= 1.0) & (t < 3.0)
    as_evidence = filter_alert_levels(t, np.where(gap, 0, measured), RADAR_ALERT_CONFIG)
    as_prediction = filter_alert_levels(t, np.where(gap, -1, measured), RADAR_ALERT_CONFIG)
    first = {name: t[np.argmax(levels == 3)] for name, levels in (("e", as_evidence), ("p", as_prediction))}
    # Half the measured rows of the last 4 s: the four before the gap say no, the fourth after it tips it.
    assert first["p"] == 3.75
    assert first["e"] > first["p"]


def test_a_closing_track_is_held_until_its_closest_approach():
    # Closed form: a crossing at 100 m/s relative with a 300 m miss, 2 km before the closest point,
    # reaches it in 20 s; its range rate (-98.9 m/s) would say 20.2 s, an upper bound.
    s = np.array([[2000.0, 300.0, -50.0], [2000.0, 300.0, -50.0], [5000.0, 0.0, 0.0], [1500.0, 0.0, 0.0]])
    v = np.array([[-100.0, 0.0, 0.0], [100.0, 0.0, 0.0], [-100.0, 0.0, 0.0], [-100.0, 0.0, 0.0]])
    holds = lost_track_hold(s, v, hold_s=8.0, closing_hold_s=25.0)
    np.testing.assert_allclose(holds, [20.0, 8.0, 25.0, 15.0])  # closing, receding, capped, closing
    # A CPA sooner than the hold, a state without velocity, and a closing hold below the hold: the hold.
    odd = lost_track_hold(
        np.array([[300.0, 0.0, 0.0], [2000.0, 0.0, 0.0], [2000.0, 0.0, 0.0]]),
        np.array([[-100.0, 0.0, 0.0], [np.nan, 0.0, 0.0], [0.0, 0.0, 0.0]]),
        hold_s=8.0,
        closing_hold_s=25.0,
    )
    assert odd.tolist() == [8.0, 8.0, 8.0]
    assert lost_track_hold(s, v, hold_s=8.0, closing_hold_s=0.0).tolist() == [8.0] * 4


def test_a_warning_is_held_through_a_fade_longer_than_the_hold_until_the_closest_approach():
    # A head-on closure warned before it fades behind a clutter ridge for 12 s, longer than the 8-s
    # hold of any lost track: closing, it is predicted until its closest approach, and the warning
    # stays on every frame of the fade; held only 8 s, it drops 4 s before the track is seen again.
    own, tracks = _head_on(seconds_to_lowc=15.0, duration_s=19.0)
    faded = tracks[(tracks["time_s"] < 5.0) | (tracks["time_s"] > 17.0)]
    gap = (own["time_s"] > 5.0) & (own["time_s"] < 17.0)
    held = alerts_from_tracks(faded, own, RADAR_ALERT_CONFIG, with_advice=False)
    assert RADAR_ALERT_CONFIG.closing_track_hold_s > 12.0 > RADAR_ALERT_CONFIG.lost_track_hold_s
    assert len(held) == len(own)
    during = held[held["time_s"].between(5.0, 17.0, inclusive="neither")]
    assert len(during) == int(gap.sum()) and during["extrapolated"].all() and (during["level"] == 3).all()
    short = replace(RADAR_ALERT_CONFIG, closing_track_hold_s=0.0)
    dropped = alerts_from_tracks(faded, own, short, with_advice=False)
    assert dropped["time_s"].between(13.1, 17.0, inclusive="neither").sum() == 0


def test_a_receding_track_is_held_only_the_hold():
    own, tracks = _head_on(seconds_to_lowc=15.0, duration_s=30.0)
    receding = tracks.assign(vn_mps=100.0, north_m=tracks["north_m"].iloc[0] + 100.0 * tracks["time_s"])
    seen = receding[receding["time_s"] < 2.0]
    alerts = alerts_from_tracks(seen, own, RADAR_ALERT_CONFIG, with_advice=False)
    assert alerts["time_s"].max() <= seen["time_s"].max() + RADAR_ALERT_CONFIG.lost_track_hold_s + 1e-9


@pytest.mark.parametrize("per_row_hold", [False, True])
def test_one_frames_predictions_are_those_of_the_whole_run_on_that_frame(per_row_hold):
    # A stream adds the predicted rows of its latest frame only (``only_at_s``): the same rows the
    # whole run's call adds on that frame, for tracks that start late, fade, end and come back.
    rng = np.random.default_rng(3)
    frames = np.round(np.arange(0.0, 20.0, FRAME_S), 9)
    rows = []
    for track_id in range(1, 9):
        seen = frames[(frames >= rng.uniform(0, 4)) & (frames <= rng.uniform(14, 20))]
        seen = seen[rng.random(seen.size) > rng.uniform(0.0, 0.6)]  # fades of a frame or two
        fade = rng.uniform(2, 5)  # and one of up to 12 s: longer than the hold on some tracks
        seen = seen[(seen < fade) | (seen > fade + rng.uniform(0, 12))]
        for t in seen:
            rows.append((t, track_id, *rng.normal(0.0, 1000.0, 3), *rng.normal(0.0, 50.0, 3)))
    cols = ["time_s", "track_id", "north_m", "east_m", "down_m", "vn_mps", "ve_mps", "vd_mps"]
    tracks = pd.DataFrame(rows, columns=cols).sort_values(["time_s", "track_id"], kind="stable")
    tracks = tracks.reset_index(drop=True).assign(range_m=1000.0)
    for name in [f"cov_{k}_{i}{j}" for k in ("pp", "vv", "pv") for i in range(3) for j in range(3)]:
        tracks[name] = rng.random(len(tracks))
    # Each row's own hold (a closing track's is longer) or one for all.
    hold = rng.uniform(2.0, 20.0, len(tracks)) if per_row_hold else 8.0
    whole = lost_track_rows(tracks, frames, hold_s=hold)
    checked = 0
    for at_s in frames[::3]:
        one = lost_track_rows(tracks, frames, hold_s=hold, only_at_s=at_s)
        expected = whole[~whole["extrapolated"] | (whole["time_s"] == at_s)].reset_index(drop=True)
        pd.testing.assert_frame_equal(one, expected)
        checked += int(one["extrapolated"].sum())
    assert checked > 20  # the frames checked hold predictions
