"""Which elevations a track's height rests on in the ground's range-Doppler band (track.elevation_trust).

Over hills, an aircraft overtaken 339 m above the own-ship can have its elevation measured on
30-70 % of its detections, within a few degrees of the truth; held at the co-altitude prior of the
unmeasured rest its track stays 74 m up and it is warned. Over flat ground 300 m below, a co-altitude
intruder's "measured" elevations can be the ground's depression (the plain DoA of a cell the ground
fills); trusted, they carry the track 250-360 m down and its warning is missed.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from hypothesis import given, settings
from hypothesis import strategies as st

from skyradar.config import RadarConfig
from skyradar.track.elevation_trust import (
    BAND_ELEVATION_SIGMA_RAD,
    FREE_ELEVATION_SIGMA_RAD,
    AboveVotes,
    BelowConsensus,
    band_elevation_sigma_rad,
    elevation_trusted,
    place_elevations,
)
from skyradar.track.track_table import track_detections
from skyradar.track.tracker3d import Tracker3D

CFG = RadarConfig.prototype_2022()
SPEED_MPS, AGL_M, N = 50.0, 500.0, 190  # 20 s at 9.4 Hz


def _own(agl_m: float = AGL_M) -> pd.DataFrame:
    t = np.arange(N) / 9.4
    return pd.DataFrame(
        {
            "time_s": t,
            "own_north_m": SPEED_MPS * t,
            "own_east_m": 0.0,
            "own_down_m": 0.0,
            "own_vn_mps": SPEED_MPS,
            "own_ve_mps": 0.0,
            "own_vd_mps": 0.0,
            "own_height_agl_m": agl_m,
        }
    )


def _aircraft(
    up_m: float, speed_mps: float, reading: np.ndarray, ahead_m: float = 1800.0, noise_rad: float = 0.02
) -> pd.DataFrame:
    """Detections of an aircraft flying north ``up_m`` above the own-ship, ``ahead_m`` ahead and 250 m
    aside at first. ``reading`` per detection: 'true' (measured at its elevation, ``noise_rad`` noise),
    'prior' (unmeasured, elevation 0), 'ground' (measured, at the ground's depression) or 'mixed'
    (measured, anywhere between the two)."""
    rng = np.random.default_rng(0)
    t = np.arange(N) / 9.4
    own = np.column_stack([SPEED_MPS * t, 0 * t, 0 * t])
    d = np.column_stack([ahead_m + speed_mps * t, 250.0 + 0 * t, -up_m + 0 * t]) - own
    r = np.linalg.norm(d, axis=1)
    v = d[:, 0] * (speed_mps - SPEED_MPS) / r
    az = np.arctan2(d[:, 1], d[:, 0]) + rng.normal(0, 0.02, N)
    true_el, ground_el = np.arcsin(-d[:, 2] / r), -np.arcsin(np.minimum(AGL_M / r, 1.0))
    mixed = true_el + rng.random(N) * (ground_el - true_el)  # the ground's pull, changing from frame to frame
    el = np.select(
        [reading == "true", reading == "ground", reading == "mixed"],
        [true_el + rng.normal(0, noise_rad, N), ground_el, mixed],
        0.0,
    )
    apparent = r + CFG.range_doppler_coupling_s * v
    u = np.column_stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)])
    p = own + apparent[:, None] * u
    return pd.DataFrame(
        {
            "time_s": t,
            "range_m": apparent,
            "radial_velocity_mps": v,
            "snr_db": 25.0,
            "azimuth_rad": az,
            "elevation_rad": el,
            "north_m": p[:, 0],
            "east_m": p[:, 1],
            "down_m": p[:, 2],
            "elevation_measured": reading != "prior",
        }
    )


def _last(tracks: pd.DataFrame) -> pd.Series:
    confirmed = tracks[tracks.confirmed]
    assert confirmed.track_id.nunique() == 1
    return confirmed.iloc[-1]


def _up_m(row: pd.Series) -> float:
    return -float(row["down_m"])


def test_an_aircraft_above_with_some_measured_elevations_is_tracked_at_its_height():
    # Overtaken at 20 m/s, 340 m above: inside the ground's band. 40 % measured, the rest unmeasured.
    reading = np.where(np.random.default_rng(1).random(N) < 0.4, "true", "prior")
    last = _last(track_detections(_aircraft(340.0, 30.0, reading), ownship=_own(), ground_test=False))
    assert abs(_up_m(last) - 340.0) < 60.0 and last["altitude_measured"]


def test_elevations_scattered_past_their_bound_still_bring_the_track_to_its_height():
    # Jacksboro: elevations measured through the nulls scatter by degrees, far past their Cramer-Rao
    # bound at 25 dB (under 1 deg). Trusted at the bound, the first ones would set the track's height
    # and gate the rest out (11 of 18 in its first 2 s); it would reach its true height (339 m up) only
    # after 12 s, and be warned meanwhile (its free readings then hold the track's predicted height; at
    # the co-altitude prior they weigh little against trusted ones).
    for seed in range(4):
        reading = np.where(np.random.default_rng(seed).random(N) < 0.5, "true", "prior")
        det = _aircraft(340.0, 30.0, reading, ahead_m=1200.0, noise_rad=0.06)
        tracks = track_detections(det, ownship=_own(), ground_test=False)
        after_8_s = tracks[tracks.confirmed & (tracks.time_s > 8.0)]
        assert len(after_8_s) > 100 and np.all(np.abs(-after_8_s["down_m"] - 340.0) < 60.0), seed


def test_an_aircraft_above_first_seen_close_is_at_its_height_a_second_after_its_readings_agree():
    # Flat ground 300 m below: overtaken 339 m above, first seen 780 m away (already inside the
    # warning's horizontal volume), 30 % of its elevations measured, at 14-43 deg for a true 27-32 deg.
    # One reading at a time, the first accepted would set the height (170 m up) and the gate keep out
    # the rest for 20 s: a false warning. Here 10 deg (1 sigma) of scatter.
    for seed in range(4):
        reading = np.where(np.random.default_rng(seed).random(N) < 0.3, "true", "prior")
        det = _aircraft(340.0, 30.0, reading, ahead_m=700.0, noise_rad=0.15)
        confirmed = track_detections(det, ownship=_own(), ground_test=False).query("confirmed")
        first = confirmed.time_s[confirmed.altitude_measured].min()
        after = confirmed[confirmed.time_s > first + 1.0]
        assert first < 5.0 and len(after) > 100, seed
        assert np.all(np.abs(-after["down_m"] - 340.0) < 80.0), seed


def test_a_track_keeps_its_agreed_height_through_a_run_of_readings_the_ground_pulls():
    # Flat ground 300 m below: 280 m above, its vote lost on a run of readings pulled to the ground,
    # the co-altitude prior of its free readings would drag the track down to 103 m in 20 s and it
    # would be warned. Here the readings are at the ground's depression after 6 s (at the co-altitude
    # prior again the track ends 30-70 m up).
    t = np.arange(N) / 9.4
    for seed in range(4):
        rng = np.random.default_rng(seed)
        reading = np.where(rng.random(N) < 0.5, np.where(t < 6.0, "true", "ground"), "prior")
        det = _aircraft(300.0, 30.0, reading, ahead_m=900.0, noise_rad=0.05)
        confirmed = track_detections(det, ownship=_own(), ground_test=False).query("confirmed")
        later = confirmed[confirmed.time_s > 6.0]
        assert len(later) > 100 and np.all(np.abs(-later["down_m"] - 300.0) < 80.0), seed


def _lift(det: pd.DataFrame, rows: np.ndarray, elevation_rad: np.ndarray) -> pd.DataFrame:
    """``det`` with the readings ``rows`` at ``elevation_rad`` above the horizontal (same range, bearing)."""
    out = det.copy()
    own = np.column_stack([SPEED_MPS * det.time_s, 0 * det.time_s, 0 * det.time_s])[rows]
    d = det.loc[rows, ["north_m", "east_m", "down_m"]].to_numpy() - own
    r, b = np.linalg.norm(d, axis=1), np.arctan2(d[:, 1], d[:, 0])
    u = np.column_stack(
        [np.cos(elevation_rad) * np.cos(b), np.cos(elevation_rad) * np.sin(b), -np.sin(elevation_rad)]
    )
    out.loc[rows, ["north_m", "east_m", "down_m"]] = own + r[:, None] * u
    out.loc[rows, "elevation_rad"] = elevation_rad
    return out


def test_outliers_above_do_not_lift_a_co_altitude_intruder():
    # Hills: an aircraft 39 m below, overtaken (a near collision), with 1.7 % of its 303 elevations
    # more than 8.6 deg up. Trusted one by one, each would lift its track and the free readings hold
    # it there: 620 m up, never warned. Here 5 % of the readings at 10-30 deg, in bursts of three
    # (without the track's vote: 573, 233 and 340 m off).
    for seed in range(3):
        rng = np.random.default_rng(seed)
        det = _aircraft(-39.0, 30.0, np.full(N, "true"), noise_rad=0.05)
        starts = np.flatnonzero(rng.random(N) < 0.05 / 3)
        rows = np.unique(np.clip((starts[:, None] + np.arange(3)).ravel(), 0, N - 1))
        det = _lift(det, rows, rng.uniform(np.radians(10.0), np.radians(30.0), rows.size))
        confirmed = track_detections(det, ownship=_own(), ground_test=False).query("confirmed")
        assert len(confirmed) > 150 and np.all(np.abs(-confirmed["down_m"] + 39.0) < 60.0), seed


def test_a_track_without_trusted_elevations_stays_co_altitude():
    # Hills: overtaken 110 m below, every reading below the horizontal (none trusted). Placed at the
    # track's predicted elevation they hold nothing, the radial-velocity update lifts the track to
    # 500 m up and the conflict is missed. At the co-altitude prior the track stays co-altitude:
    # warned as if level with the own-ship.
    for up_m in (-110.0, -40.0):
        det = _aircraft(up_m, 35.0, np.full(N, "true"), noise_rad=0.05)
        confirmed = track_detections(det, ownship=_own(), ground_test=False).query("confirmed")
        assert len(confirmed) > 150 and np.all(np.abs(confirmed["down_m"]) < 60.0)
        assert not confirmed["altitude_measured"].any()


def test_ground_readings_of_a_co_altitude_intruder_do_not_carry_its_track_down():
    reading = np.where(np.random.default_rng(2).random(N) < 0.5, "ground", "prior")
    det = _aircraft(0.0, 30.0, reading)
    last = _last(track_detections(det, ownship=_own(), ground_test=False))
    assert abs(_up_m(last)) < 40.0 and not last["altitude_measured"]
    # Without a ground known (no height above it) the same readings are taken: the band is what helps.
    unknown = _last(track_detections(det, ownship=_own(np.nan), ground_test=False))
    assert _up_m(unknown) < -150.0


def test_measured_elevations_below_count_outside_the_ground_band():
    # Clear sky (no ground known) or a closing speed no static point has, not even through the
    # Doppler alias (a radar with V_lim 100 m/s: the ground's band at 50 m/s folds nowhere): an
    # aircraft 300 m below is tracked at its height.
    reading = np.full(N, "true")
    below_clear = _last(
        track_detections(_aircraft(-300.0, 30.0, reading), ownship=_own(np.nan), ground_test=False)
    )
    fast_radar = RadarConfig.prototype_2022(prf_hz=CFG.prf_hz * 100.0 / CFG.v_lim_mps)
    head_on = track_detections(
        _aircraft(-300.0, -30.0, reading, ahead_m=3000.0),
        config=fast_radar,
        ownship=_own(),
        ground_test=False,
    )
    for last in (below_clear, _last(head_on)):
        assert abs(_up_m(last) + 300.0) < 40.0 and last["altitude_measured"]


def test_a_closing_speed_whose_alias_the_ground_fills_is_in_the_band():
    # The prototype's V_lim is 39 m/s: at 50 m/s the ground's band folds over every Doppler cell, so a
    # head-on closure of 80 m/s shares its cell (alias -1.7 m/s) with the ground, whose pull gives
    # readings below that look like these (over Jacksboro, 47 m below: trusted because -115 m/s is
    # outside the unfolded band, they would hold its track 245-335 m below it and it would never be
    # warned). Readings below in the band are not trusted unless they agree clear of the ground (here
    # 200 m above it, less than 3 bounds at these ranges): the track stays co-altitude.
    reading = np.full(N, "true")
    det = _aircraft(-300.0, -30.0, reading, ahead_m=3000.0)
    assert np.all(np.abs(det.radial_velocity_mps) > SPEED_MPS + 5.0)
    last = _last(track_detections(det, ownship=_own(), ground_test=False))
    assert abs(_up_m(last)) < 40.0 and not last["altitude_measured"]


def test_an_aircraft_below_whose_elevations_agree_is_tracked_at_its_height():
    # Hills: overtaken 281 m below, its in-band readings agreeing within their bound, 200 m above the
    # terrain; held at the co-altitude prior it would be warned (a false warning). Here 300 m below,
    # 200 m above a level ground, readings at the bound (25 dB: 0.013 rad).
    det = _aircraft(-300.0, 30.0, np.full(N, "true"), ahead_m=700.0, noise_rad=0.013)
    confirmed = track_detections(det, ownship=_own(), ground_test=False).query("confirmed")
    after_5_s = confirmed[confirmed.time_s > 5.0]
    assert len(after_5_s) > 100 and np.all(np.abs(-after_5_s["down_m"] + 300.0) < 60.0)
    assert after_5_s["altitude_measured"].all()


def test_readings_the_ground_pulls_keep_a_co_altitude_intruder_at_its_height():
    # Readings of a mixture scatter between the target and the ground (no consensus, as over hills
    # above); readings the ground dominates agree, on the surface (as over Jacksboro).
    for reading in ("mixed", "ground"):
        det = _aircraft(0.0, 30.0, np.full(N, reading), ahead_m=700.0)
        confirmed = track_detections(det, ownship=_own(), ground_test=False).query("confirmed")
        assert len(confirmed) > 150 and np.all(np.abs(confirmed["down_m"]) < 60.0), reading
        assert not confirmed["altitude_measured"].any(), reading


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.tuples(st.floats(-600.0, 600.0), st.floats(1.0, 100.0), st.booleans(), st.floats(-300.0, 300.0)),
        min_size=10,
        max_size=30,
    )
)
def test_a_consensus_below_is_the_median_of_agreeing_readings_clear_of_the_ground(rows):
    up, bound, below, clear = (np.array(c) for c in zip(*rows, strict=True))
    consensus = BelowConsensus(window=10, least=7)
    for k in range(len(rows)):
        h = consensus.update(
            np.array([5]),
            up[k : k + 1],
            bound[k : k + 1],
            below[k : k + 1],
            np.array([True]),
            clear[k : k + 1],
        )[0]
    last = slice(len(rows) - 10, len(rows))
    if np.isfinite(h):
        assert h == np.median(up[last]) and below[last].sum() >= 7 and np.median(clear[last]) > 0.0
        assert 1.4826 * np.median(np.abs(up[last] - h)) <= 1.5 * np.median(bound[last])
    else:
        spread_ok = 1.4826 * np.median(np.abs(up[last] - np.median(up[last]))) <= 1.5 * np.median(bound[last])
        assert not (below[last].sum() >= 7 and np.median(clear[last]) > 0.0 and spread_ok)


@settings(max_examples=50, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.floats(200.0, 5000.0),
            st.floats(-3.0, 3.0),
            st.floats(-1.2, 1.2),
            st.booleans(),
            st.floats(-80.0, 80.0),
        ),
        min_size=1,
        max_size=8,
    ),
)
def test_free_detections_keep_range_and_bearing_and_trusted_ones_do_not_move(rows):
    rng_m, bearing, el, measured, v = (np.array(c) for c in zip(*rows, strict=True))
    own = np.array([100.0, -50.0, -800.0])
    pos = own + rng_m[:, None] * np.column_stack(
        [np.cos(el) * np.cos(bearing), np.cos(el) * np.sin(bearing), -np.sin(el)]
    )
    sigma = np.full(len(rows), 0.02)
    out, el_sigma, trusted, _, _ = place_elevations(pos, own, 50.0, sigma, measured, v, 600.0)
    d = out - own
    assert np.allclose(np.linalg.norm(d, axis=1), rng_m)
    horizontal = np.hypot(d[:, 0], d[:, 1]) > 1e-6 * rng_m
    assert np.allclose(np.cos(np.arctan2(d[:, 1], d[:, 0]) - bearing)[horizontal], 1.0)
    assert np.allclose(out[trusted], pos[trusted])
    assert np.all(el_sigma[trusted] == 0.02)
    assert np.allclose(d[~trusted, 2], 0.0, atol=1e-6 * rng_m.max())  # at the co-altitude prior
    assert np.all(el_sigma[~trusted] == FREE_ELEVATION_SIGMA_RAD) and not trusted[~measured].any()


def _vertical_speed_z_scores(seed: int, per_feed_window: int) -> np.ndarray:
    # A level aircraft 230 m above, overtaken in the ground's band (400-600 m away, 500 m above the
    # ground): its elevations carry a slow clutter pull (0.04 rad over a 20 s period) and white noise.
    rng = np.random.default_rng(seed)
    phase, votes, t3, dt = rng.uniform(0.0, 2.0 * np.pi), AboveVotes(), Tracker3D(), 1 / 9.4
    votes.window = per_feed_window  # 1: each fed height weighed as one reading (before)
    z = []
    for k in range(int(30 / dt)):
        t = k * dt
        own, rel = np.array([50.0 * t, 0.0, -500.0]), np.array([600.0 - 15.0 * t, 40.0, -230.0])
        r = np.linalg.norm(rel)
        el = np.arcsin(230.0 / r) + 0.04 * np.sin(2 * np.pi * t / 20.0 + phase) + rng.normal(0.0, 0.01)
        az = np.arctan2(rel[1], rel[0])
        pos = own + r * np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)])
        one = np.array([True])
        p, sigma, *_ = place_elevations(
            pos[None], own, 50.0, np.array([0.01]), one, np.array([-15.0]), 500.0, votes, np.array([1])
        )
        x, P = t3.step(t, np.array([1]), p, np.diag([25.0, (r * 0.01) ** 2, (r * sigma[0]) ** 2])[None])
        if t > 10.0:
            z.append(abs(x[0, 5]) / np.sqrt(P[0, 5, 5]))
    return np.array(z)


def test_a_voted_height_fed_every_frame_does_not_make_a_drift_a_vertical_speed():
    ours = np.concatenate([_vertical_speed_z_scores(seed, AboveVotes().window) for seed in range(4)])
    before = np.concatenate([_vertical_speed_z_scores(seed, 1) for seed in range(4)])
    assert (ours > 3.0).mean() < 0.02  # the level aircraft's vertical speed stays within its sigma
    assert (before > 3.0).mean() > 0.1  # fed at one reading's weight, the drift became a speed


def test_an_aircraft_above_is_voted_above_by_its_median_before_any_single_reading_would_count():
    """300 m above at 3 km (5.7 deg), readings scattered by 3.5 deg through the nulls: few pass the
    single-reading threshold (8.6 deg), the median of ten to twenty passes its own error."""
    from skyradar.track.elevation_trust import AboveVotes, median_above

    rng = np.random.default_rng(11)
    votes = AboveVotes()
    ids = np.array([5])
    heights = []
    for _ in range(20):
        el = np.radians(5.7 + 3.5 * rng.standard_normal(1))
        up = 3000.0 * np.sin(el)
        above = el > 3 * 0.05
        heights.append(votes.update(ids, above, np.ones(1, bool), up, el)[0][0])
    assert np.isnan(heights[:9]).all()  # ten readings first
    assert abs(heights[-1] - 300.0) < 120.0
    # A level aircraft: at most one window in a thousand reads it above, of ten readings as of
    # twenty; with the readings sharing a 1-deg bias (three times the ga-typical AHRS's pitch bias),
    # at most one in a hundred.
    level_rng = np.random.default_rng(2)
    for n in (10, 20):
        level = np.radians(3.5 * level_rng.standard_normal((8000, n)))
        assert np.mean([median_above(w, spread_floor_rad=BAND_ELEVATION_SIGMA_RAD) for w in level]) <= 1e-3
        biased = np.radians(1.0) + level
        assert np.mean([median_above(w, spread_floor_rad=BAND_ELEVATION_SIGMA_RAD) for w in biased]) <= 0.01
    # Ten readings' own spread, without the array's floor, would read a level aircraft above often.
    assert np.mean([median_above(w) for w in level[:, :10]]) > 2e-3


def test_the_median_votes_an_aircraft_above_within_a_dozen_readings_and_a_level_one_rarely():
    """Readings fed one frame at a time to 300 tracks at once: an aircraft 300 m above at 3 km is
    voted by its twelfth reading on half the tracks, by its twentieth on nineteen in twenty; over
    sixty readings (growing windows, then sliding ones) a level aircraft is voted above, at any
    time, on at most one track in a hundred."""
    from skyradar.track.elevation_trust import AboveVotes

    rng, n_tracks = np.random.default_rng(7), 300
    ids, on = np.arange(n_tracks), np.ones(n_tracks, bool)
    first_vote = {}
    for name, centre_deg in (("above", 5.7), ("level", 0.0)):
        votes, voted_at = AboveVotes(), np.full(n_tracks, np.inf)
        for reading in range(1, 61):
            el = np.radians(centre_deg + 3.5 * rng.standard_normal(n_tracks))
            up, _ = votes.update(ids, el > 3 * BAND_ELEVATION_SIGMA_RAD, on, 3000.0 * np.sin(el), el)
            voted_at = np.where(np.isfinite(up) & np.isinf(voted_at), reading, voted_at)
        first_vote[name] = voted_at
    assert np.median(first_vote["above"]) <= 12 and np.mean(first_vote["above"] <= 20) >= 0.95
    assert np.mean(np.isfinite(first_vote["level"])) <= 0.01


def test_a_taller_array_trusts_in_band_readings_its_aperture_resolves():
    """An aircraft 250 m above the own-ship 3 km ahead is 4.8 deg up. Through ``ura-4x2`` (an
    elevation bound of 1.3 deg at 10 dB per channel) most of its in-band readings clear three of
    that array's floors, none clear three of the square's; a level aircraft's readings, at the
    same scatter, clear neither."""
    from skyradar.process.doa import channel_positions_m, doa_crlb

    tall = RadarConfig.prototype_2022(rx_positions_m="ura-4x2")
    floor = band_elevation_sigma_rad(channel_positions_m(tall), tall.wavelength_m)
    assert floor < 0.5 * band_elevation_sigma_rad(channel_positions_m(CFG), CFG.wavelength_m)
    sigma = float(doa_crlb(10.0, 0.0, 0.0, tall)[1])
    rng = np.random.default_rng(4)
    above = np.arcsin(250.0 / 3000.0) + sigma * rng.standard_normal(2000)
    level = sigma * rng.standard_normal(2000)
    measured, band, sig = np.ones(2000, bool), np.ones(2000, bool), np.full(2000, sigma)
    trusted_tall = elevation_trusted(above, sig, measured, band, band_sigma_rad=floor)
    trusted_square = elevation_trusted(above, sig, measured, band)
    assert trusted_tall.mean() > 0.7 and trusted_square.mean() < 0.01
    assert elevation_trusted(level, sig, measured, band, band_sigma_rad=floor).mean() < 0.01


def _with_gap(det: pd.DataFrame, start_s: float, end_s: float, unmeasured_after_s: float) -> pd.DataFrame:
    """``det`` without its detections from ``start_s`` to ``end_s`` (the track is deleted and a new
    one reacquires its id) and unmeasured for ``unmeasured_after_s`` after the gap."""
    t = det["time_s"].to_numpy(float)
    kept = det[(t < start_s) | (t >= end_s)].copy()
    first = (kept["time_s"] >= end_s) & (kept["time_s"] < end_s + unmeasured_after_s)
    kept.loc[first, "elevation_measured"] = False
    return kept.reset_index(drop=True)


def test_a_track_below_that_reacquires_its_id_resumes_its_height():
    # Jacksboro: an aircraft 250 m below, tracked at its height for 20 s, lost for 2 s and picked up
    # again by a new track whose readings are too few to agree: without the lost track's evidence it
    # sits at the co-altitude prior, tens of metres off horizontally too, misses the lost filter's
    # fusion gate, and is warned at once. Here 300 m below, 3 s without detections, then unmeasured
    # readings for half a second before measured ones again.
    det = _with_gap(
        _aircraft(-300.0, 30.0, np.full(N, "true"), ahead_m=700.0, noise_rad=0.013), 8.0, 11.0, 0.5
    )
    tracks = track_detections(det, ownship=_own(), ground_test=False)
    confirmed = tracks.query("confirmed")
    assert confirmed.track_id.nunique() == 1  # the new track took the lost one's id
    after_gap = confirmed[confirmed.time_s >= 11.0]
    assert len(after_gap) > 50 and np.all(np.abs(-after_gap["down_m"] + 300.0) < 60.0)


def test_a_reacquired_track_whose_readings_contradict_the_lost_height_does_not_inherit_it():
    # The reacquisition matches range and range rate, not height: a track whose own in-band readings
    # lie at the surface is not held at the height above the lost track's readings agreed on (a
    # co-altitude aircraft held 300 m above would go unwarned). Its readings start a vote of their own.
    t = np.arange(N) / 9.4
    reading = np.where(t < 8.0, "true", "ground")
    det = _with_gap(_aircraft(300.0, 30.0, reading, ahead_m=700.0, noise_rad=0.013), 8.0, 11.0, 0.0)
    confirmed = track_detections(det, ownship=_own(), ground_test=False).query("confirmed")
    before, after_gap = confirmed[confirmed.time_s < 8.0], confirmed[confirmed.time_s >= 12.0]
    assert np.all(np.abs(-before["down_m"].iloc[-20:] - 300.0) < 60.0)
    assert len(after_gap) > 50 and np.all(np.abs(after_gap["down_m"]) < 100.0)
    assert not after_gap["altitude_measured"].any()
