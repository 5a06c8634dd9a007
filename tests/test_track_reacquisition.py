"""One track per aircraft: gaps, aliasing, clutter in a grown gate, gliders, S-turns.

Truth comes from the scene geometry (which aircraft is in the beam and when its detections are
withheld), never from the detections or the tracks being scored. Each test needs reacquisition
(:mod:`skyradar.track.reacquisition`): without it the deleter closes a track 2 s into a gap and the
aircraft comes back as a new track.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy.interpolate import CubicHermiteSpline

from skyradar.config import RadarConfig
from skyradar.track.io import Truth
from skyradar.track.metrics import track_metrics, truth_segments
from skyradar.track.models import radar_model
from skyradar.track.reacquisition import LostTracks
from skyradar.track.simulated_detections import synthetic_detections
from skyradar.track.track_table import OWNSHIP_COLUMNS, track_detections
from skyradar.track.types import TrackerConfig

CFG = RadarConfig.prototype_2022()
RATE_HZ = 9.4
PIXEL = (CFG.range_resolution_m, CFG.doppler_resolution_mps)
WIDTH = 2 * CFG.v_lim_mps


def _ids_on(tracks: pd.DataFrame, det: pd.DataFrame, target: int) -> np.ndarray:
    """Confirmed track ids that were updated with a detection of ``target``."""
    rows = tracks[tracks["confirmed"] & (tracks["detection_row"] >= 0)]
    on = det["target"].to_numpy()[rows["detection_row"].to_numpy()] == target
    return np.unique(rows["track_id"].to_numpy()[on])


def _straight(gap_s: tuple[float, float], v_mps: float, seed: int = 0, clutter: float = 1.0):
    t = np.arange(0.0, 20.0, 1 / RATE_HZ)
    r = (3000.0 + v_mps * t)[:, None]
    vis = ~((t >= gap_s[0]) & (t < gap_s[1]))[:, None]
    det = synthetic_detections(
        t,
        r,
        np.full_like(r, v_mps),
        visible=vis,
        config=CFG,
        sigma_range_m=4.4,
        sigma_velocity_mps=0.093,
        clutter_per_frame=clutter,
        seed=seed,
    )
    return t, r, vis, det


@pytest.mark.parametrize("gap_s", [3.0, 5.0, 7.0])
def test_detection_gap_keeps_the_track_id(gap_s):
    """Deleter: a gap of several seconds (beam edge, SNR dip) does not start a second track."""
    t, _, _, det = _straight((6.0, 6.0 + gap_s), -30.0)
    tracks = track_detections(det, "radar", CFG, frame_times_s=t)
    assert _ids_on(tracks, det, 0).size == 1


def test_gap_longer_than_reacquisition_is_a_new_track():
    """An aircraft not closing that stays away longer than ``reacquire_s`` is a new track, as without
    reacquisition."""
    t, _, _, det = _straight((6.0, 15.0), 30.0)
    tracks = track_detections(
        det, "radar", CFG, tracker_config=TrackerConfig(reacquire_s=8.0), frame_times_s=t
    )
    assert _ids_on(tracks, det, 0).size == 2


def test_a_closing_aircraft_keeps_its_id_through_a_gap_longer_than_reacquisition():
    """A closure hidden for 9 s (a clutter ridge) is still the same aircraft: closing at 30 m/s from
    2.8 km it cannot have passed for 90 s, so its lost track waits (up to ``reacquire_closing_s``)."""
    t, _, _, det = _straight((6.0, 15.0), -30.0)
    config = TrackerConfig(reacquire_s=8.0, reacquire_closing_s=25.0)
    tracks = track_detections(det, "radar", CFG, tracker_config=config, frame_times_s=t)
    assert _ids_on(tracks, det, 0).size == 1
    no_longer = TrackerConfig(reacquire_s=8.0, reacquire_closing_s=0.0)
    tracks = track_detections(det, "radar", CFG, tracker_config=no_longer, frame_times_s=t)
    assert _ids_on(tracks, det, 0).size == 2


def test_a_lost_closing_track_is_kept_until_it_could_have_passed():
    """The memory of a closing track is its range over its closing speed (the latest its closest
    approach can come), between ``max_age_s`` and ``closing_max_age_s``: the rate the range follows
    is the radial velocity once the alias is resolved, the range-rate state before."""
    lost = LostTracks(radar_model(WIDTH), max_age_s=8.0, closing_max_age_s=25.0)
    x = np.array(
        [
            [1500.0, -100.0, -100.0, 0.0],  # 15 s to pass
            [1500.0, 10.0, -100.0, 0.0],  # unresolved: aliased +10, range falling at 100 m/s
            [4000.0, -100.0, -100.0, 0.0],  # 40 s: the cap
            [500.0, -100.0, -100.0, 0.0],  # 5 s: the plain memory
            [1500.0, 40.0, 40.0, 0.0],  # receding
        ]
    )
    resolved = np.array([True, False, True, True, True])
    np.testing.assert_allclose(lost.memory_of(x, resolved), [15.0, 15.0, 25.0, 8.0, 8.0])
    lost.add(np.arange(5), x, np.repeat(np.diag([16.0, 0.04, 1.0, 0.25])[None], 5, axis=0), resolved, 0.0)
    lost.expire(14.0)
    assert lost.ids.tolist() == [0, 1, 2]
    lost.expire(20.0)
    assert lost.ids.tolist() == [2]


def test_fast_intruder_reacquired_with_its_alias():
    """De-aliasing: a 120 m/s closing intruder (|V| > VLim) keeps its id and its resolved alias."""
    t, _, _, det = _straight((6.0, 10.0), -120.0, seed=3)
    tracks = track_detections(det, "radar", CFG, frame_times_s=t)
    ids = _ids_on(tracks, det, 0)
    assert ids.size == 1
    after = tracks[(tracks["track_id"] == ids[0]) & (tracks["time_s"] > 10.0) & tracks["confirmed"]]
    # Unresolved, the new track would report the aliased -120 + 2 W = +36.6 m/s for a second or more.
    assert np.all(np.abs(after["radial_velocity_mps"].to_numpy() + 120.0) < 2.0)


def test_clutter_taken_after_a_long_coast_does_not_break_the_track():
    """Association: a clutter point inside the gap's grown gate does not drag the track away."""
    t, r, vis, det = _straight((6.0, 9.0), -30.0, clutter=0.0)
    k = int(np.searchsorted(t, 7.8))
    lure = {
        "time_s": t[k],
        "frame": k,
        "range_m": r[k, 0] + 0.19 * -30.0 + 3.0,
        "radial_velocity_mps": -45.0,
        "target": -1,
    }
    det = pd.concat([det, pd.DataFrame([lure])]).sort_values(["time_s", "range_m"]).reset_index(drop=True)
    tracks = track_detections(det, "radar", CFG, frame_times_s=t)
    assert _ids_on(tracks, det, 0).size == 1
    # The track is not reported confirmed on the lure: after a long coast it is confirmed again first.
    lured = tracks[tracks["detection_row"] == int(np.flatnonzero(det["target"] == -1)[0])]
    assert not lured["confirmed"].any()


def test_a_patchy_return_keeps_the_track_until_the_deleter_closes_it():
    """Deletion: an aircraft seen in bursts (a closure in ground clutter: 3 of every 7 frames, never 4
    of 5) after a gap keeps its track, unconfirmed, and is confirmed again with its id and its resolved
    alias as soon as the returns are steady, even after longer than ``reacquire_s`` of bursts. A track
    never confirmed is dropped when its window fails, so the same bursts alone confirm nothing."""
    t = np.arange(0.0, 22.0, 1 / RATE_HZ)
    v_mps = -115.0  # aliased once: observed near -115 + W
    r = (4000.0 + v_mps * t)[:, None]
    k = np.arange(t.size)
    bursts = (t >= 5.0) & (t < 15.0)
    in_burst = np.isin((k - np.searchsorted(t, 5.0)) % 7, (0, 2, 3))
    vis = (~bursts | in_burst)[:, None]
    det = synthetic_detections(
        t,
        r,
        np.full_like(r, v_mps),
        visible=vis,
        config=CFG,
        sigma_range_m=4.4,
        sigma_velocity_mps=0.093,
        seed=4,
    )
    tracks = track_detections(det, "radar", CFG, frame_times_s=t)
    ids = _ids_on(tracks, det, 0)
    assert ids.size == 1
    mine = tracks[tracks["track_id"] == ids[0]]
    steady = mine[mine["time_s"] >= 15.0]
    first = steady.loc[steady["confirmed"], "time_s"].min()
    assert first <= t[np.searchsorted(t, 15.0) + 4] + 1e-9  # four steady frames: M of N again
    after = steady[steady["confirmed"]]
    assert np.all(np.abs(after["radial_velocity_mps"].to_numpy() - v_mps) < 2.0)
    # The bursts alone (no steady start) never confirm a track.
    alone = det[(det["time_s"] >= 5.0) & (det["time_s"] < 15.0)].reset_index(drop=True)
    lone = track_detections(alone, "radar", CFG, frame_times_s=t[bursts])
    assert not lone["confirmed"].any()


def test_another_aircraft_does_not_take_a_lost_id():
    """A new aircraft elsewhere in the image after a track was lost gets its own id."""
    t = np.arange(0.0, 12.0, 1 / RATE_HZ)
    r = np.column_stack([2000.0 - 30.0 * t, 3500.0 - 20.0 * t])
    v = np.column_stack([np.full(t.size, -30.0), np.full(t.size, -20.0)])
    vis = np.column_stack([t < 4.0, t > 6.0])
    det = synthetic_detections(t, r, v, visible=vis, config=CFG, sigma_range_m=4.4, seed=1)
    tracks = track_detections(det, "radar", CFG, frame_times_s=t)
    a, b = _ids_on(tracks, det, 0), _ids_on(tracks, det, 1)
    assert a.size == b.size == 1 and a[0] != b[0]


def test_clutter_alone_gives_no_more_tracks_with_reacquisition():
    """Reacquisition only renames confirmed tracks: pure clutter confirms no more tracks than before."""
    t = np.arange(0.0, 30.0, 1 / RATE_HZ)
    det = synthetic_detections(
        t, np.zeros((t.size, 0)), np.zeros((t.size, 0)), config=CFG, clutter_per_frame=30.0, seed=2
    )
    with_r = track_detections(det, "radar", CFG, frame_times_s=t)
    without = track_detections(
        det, "radar", CFG, tracker_config=TrackerConfig(reacquire_s=0.0), frame_times_s=t
    )
    n_with = with_r.loc[with_r["confirmed"], "track_id"].nunique()
    assert n_with <= without.loc[without["confirmed"], "track_id"].nunique()


def test_lost_track_matches_in_observed_space():
    """The comparison uses H x: an unresolved new track (aliased V, coupling) still matches."""
    model = radar_model(WIDTH, coupling_s=CFG.range_doppler_coupling_s)
    lost = LostTracks(model)
    c = model.coupling_s
    x_lost = np.array([[2000.0, -100.0, -100.0, 0.0]])
    lost.add(np.array([7]), x_lost, np.diag([16.0, 0.04, 1.0, 0.25])[None], np.array([True]), 0.0)
    # Five seconds on: true range 1500 m, V -100 m/s observed as -100 + W, range corrected by c (-100 + W).
    v_obs = -100.0 + WIDTH
    x_new = np.array([[1500.0 + c * -100.0 - c * v_obs, v_obs, v_obs, 0.0]])
    ids, alias = lost.match(x_new, np.diag([16.0, 0.04, 900.0, 1.0])[None], 5.0)
    assert ids.tolist() == [7] and alias.tolist() == [-1.0]
    assert len(lost) == 0


def _ownship_s_turn(t: np.ndarray, bank_deg: float, speed_mps: float = 50.0, period_s: float = 30.0):
    bank = np.deg2rad(bank_deg) * np.tanh(3.0 * np.sin(2 * np.pi * t / period_s))
    rate = 9.80665 * np.tan(bank) / speed_mps
    psi = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(t))])
    vel = np.column_stack([speed_mps * np.cos(psi), speed_mps * np.sin(psi), np.zeros_like(t)])
    pos = np.zeros_like(vel)
    pos[1:] = np.cumsum(0.5 * (vel[1:] + vel[:-1]) * np.diff(t)[:, None], axis=0)
    pos[:, 2] = -1000.0
    return pos, vel, psi


def _circling_glider(t: np.ndarray, rng, centre, radius_m=120.0, speed_mps=25.0):
    """A thermalling glider as ADS-B gives it: states every 5-12 s, Hermite-interpolated."""
    ts = [t[0] - 1.0]
    while ts[-1] < t[-1] + 1.0:
        ts.append(ts[-1] + rng.uniform(5.0, 12.0))
    ts, w = np.array(ts), speed_mps / radius_m
    p = np.column_stack(
        [
            centre[0] + 3 * ts + radius_m * np.cos(w * ts),
            centre[1] + 2 * ts + radius_m * np.sin(w * ts),
            np.full(ts.size, centre[2]),
        ]
    )
    v = np.column_stack([3 - speed_mps * np.sin(w * ts), 2 + speed_mps * np.cos(w * ts), np.zeros(ts.size)])
    spline = CubicHermiteSpline(ts, p, v)
    return spline(t), spline(t, 1)


@pytest.mark.parametrize("bank_deg", [0.0, 35.0])
def test_gliders_and_fast_intruder_one_track_each(bank_deg):
    """Two circling gliders and a fast head-on intruder, own-ship in 35 deg S-turns, 3-6 s gaps,
    Pd 0.7 and 5 clutter points a frame: at most one extra track per aircraft over its visible span."""
    rng = np.random.default_rng(4)
    t = np.arange(0.0, 75.0, 1 / RATE_HZ)
    own_p, own_v, psi = _ownship_s_turn(t, bank_deg)
    aircraft = [
        _circling_glider(t, rng, (3500.0, 300.0, -1100.0)),
        _circling_glider(t, rng, (2500.0, -800.0, -900.0), 90.0, 22.0),
        (
            np.array([9000.0, -200.0, -1000.0]) + t[:, None] * [-70.0, 0.0, 0.0],
            np.tile([-70.0, 0, 0], (t.size, 1)),
        ),
    ]
    d = np.stack([p - own_p for p, _ in aircraft], axis=1)
    rng_m = np.linalg.norm(d, axis=2)
    v = np.einsum("tjk,tjk->tj", d, np.stack([vel - own_v for _, vel in aircraft], axis=1)) / rng_m
    az = np.angle(np.exp(1j * (np.arctan2(d[..., 1], d[..., 0]) - psi[:, None])))
    visible = (np.abs(az) < np.deg2rad(60.0)) & (rng_m < 4900.0)
    detectable = visible.copy()
    for j in range(3):
        for start in rng.uniform(0.0, 67.0, 3):
            detectable[(t >= start) & (t < start + rng.uniform(3.0, 6.0)), j] = False
    det = synthetic_detections(
        t,
        rng_m,
        v,
        visible=detectable,
        config=CFG,
        sigma_range_m=4.4,
        sigma_velocity_mps=0.093,
        pd_detect=0.7,
        clutter_per_frame=5.0,
        positions_ned_m=np.stack([p for p, _ in aircraft], 1),
        seed=5,
        clutter_min_range_m=100.0,
    )
    own = pd.DataFrame(
        {"time_s": t, **{c: np.column_stack([own_p, own_v])[:, i] for i, c in enumerate(OWNSHIP_COLUMNS[1:])}}
    )
    tracks = track_detections(det, "radar", CFG, frame_times_s=t, position_sigma_rad=0.04, ownship=own)
    # True tracks: the visible spans of each aircraft, gaps up to the 8 s reacquisition bridged.
    truth = Truth(t, rng_m, v, detectable)
    spans = truth_segments(truth, 8.0, 0.0, (4, 5))
    m = track_metrics(tracks, truth, PIXEL, WIDTH, gap_s=8.0, min_duration_s=0.0, confirm=(4, 5))
    assert m["false_tracks"] == 0 and m["completeness"] >= 0.8
    for j in range(3):
        n_spans = np.unique(spans[spans[:, j] >= 0, j]).size
        assert _ids_on(tracks, det, j).size <= n_spans + 1, j
    assert m["fragmentation"] <= 1


def test_track_closed_before_gating_after_a_gap_without_frames():
    """Deletion: with frames only at detection times (as `skyradar track` steps), a track 10 s
    without an update met the next frame with a gate over half the image and took another
    aircraft's detection, which then carried the first aircraft's id."""
    t = np.arange(0.0, 20.0, 1 / RATE_HZ)
    r = np.column_stack([2000.0 - 30.0 * t, 1800.0 + 10.0 * (t - 13.0)])
    v = np.column_stack([np.full(t.size, -30.0), np.full(t.size, 10.0)])
    vis = np.column_stack([t < 3.0, t > 13.0])
    det = synthetic_detections(t, r, v, visible=vis, config=CFG, sigma_range_m=4.4, coupling=False, seed=2)
    tracks = track_detections(det, "radar", CFG)  # no frame_times_s: frames are the detections' times
    a, b = _ids_on(tracks, det, 0), _ids_on(tracks, det, 1)
    assert a.size == b.size == 1 and a[0] != b[0]
