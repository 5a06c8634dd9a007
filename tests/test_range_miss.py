"""The range-only miss distance against closed-form straight-line geometry, and its use in alerting."""

from __future__ import annotations

import numpy as np
import pandas as pd
from hypothesis import given, settings
from hypothesis import strategies as st

from skyradar.daa.pipeline import alerts_from_tracks
from skyradar.daa.range_miss import cannot_enter, range_miss_distance, range_only_fit

T = np.arange(0.0, 12.0, 1 / 9.4)
OWN_V = np.array([50.0, 0.0, 0.0])


def _range_rows(rel_m: np.ndarray, rel_v_mps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r = np.linalg.norm(rel_m, axis=1)
    return r, np.einsum("ij,ij->i", rel_m, rel_v_mps) / r


@settings(max_examples=60, deadline=None)
@given(
    miss=st.floats(50.0, 2000.0),
    split=st.floats(0.0, np.pi),
    speed=st.floats(10.0, 150.0),
    t_cpa=st.floats(15.0, 60.0),
)
def test_miss_distance_is_the_closed_form_one_for_any_split(miss, split, speed, t_cpa):
    # Relative path p(t) = p_c + u (t - t_cpa), p_c perpendicular to u: |p_c| whatever its direction.
    u = np.array([-speed, 0.0, 0.0])
    p_c = miss * np.array([0.0, np.cos(split), np.sin(split)])
    rel = p_c + np.outer(T - t_cpa, u)
    r, rdot = _range_rows(rel, np.tile(u, (T.size, 1)))
    got, sigma = range_miss_distance(np.zeros(T.size, int), T, r, rdot, np.tile(OWN_V, (T.size, 1)))
    ok = np.isfinite(got)
    assert ok[-1] and not ok[0]
    np.testing.assert_allclose(got[ok], miss, rtol=1e-6)
    assert np.all(sigma[ok] < 1e-3 * miss)


def test_noisy_rows_give_a_miss_within_their_sigma():
    rng = np.random.default_rng(1)
    u = np.array([-20.0, 0.0, 0.0])  # overtaking: a slow closure, 374 m below and 221 m aside
    rel = np.array([0.0, 221.0, 374.0]) + np.outer(T - 40.0, u)
    r, rdot = _range_rows(rel, np.tile(u, (T.size, 1)))
    noisy_r, noisy_rdot = r + rng.normal(0, 2.0, T.size), rdot + rng.normal(0, 0.05, T.size)
    got, sigma = range_miss_distance(
        np.zeros(T.size, int), T, noisy_r, noisy_rdot, np.tile(OWN_V, (T.size, 1))
    )
    ok = np.isfinite(got)
    assert ok.sum() > 50
    assert np.all(np.abs(got[ok] - np.hypot(221.0, 374.0)) < 4.0 * sigma[ok] + 5.0)


def test_clutter_hits_in_the_window_widen_the_sigma_to_cover_the_miss():
    # A 110 m/s closure passing 233 m aside whose track takes, on a share of its frames, a ground
    # cell at its range (range rate -40 m/s, an alias inside the ground band). The hits bend the
    # fitted slope while the rows can still agree on a wrong miss (one run read 400 m for 233 m);
    # the rows off the straight line of ``r rdot`` are set aside before the slope is fitted (up to a
    # third of them), and the slope's standard error belongs in the sigma, so the truth stays
    # within about 3 sigmas. The fit's full 10 s window keeps a sigma of tens of metres.
    u = np.array([-110.0, 0.0, 0.0])
    rel = np.array([0.0, 233.0, 0.0]) + np.outer(T - 25.0, u)
    r, rdot = _range_rows(rel, np.tile(u, (T.size, 1)))
    ids, own_v = np.zeros(T.size, int), np.tile(OWN_V, (T.size, 1))
    z = []
    for seed in range(6):
        rng = np.random.default_rng(seed)
        for share in (0.0, 0.05, 0.1, 0.2, 0.3):
            hit = rng.random(T.size) < share
            noisy_rdot = np.where(hit, -40.0 + rng.normal(0, 3.0, T.size), rdot + rng.normal(0, 0.1, T.size))
            got, sigma = range_miss_distance(ids, T, r + rng.normal(0, 4.0, T.size), noisy_rdot, own_v)
            ok = np.isfinite(got)
            assert ok.sum() > 50 and sigma[-1] < 30.0 and abs(got[-1] - 233.0) < 60.0, (seed, share)
            z.extend(np.abs(got[ok] - 233.0) / sigma[ok])
    assert np.mean(np.array(z) < 3.0) > 0.99 and max(z) < 4.0


def test_the_wanted_rows_get_the_whole_fit_and_the_others_feed_it():
    # A stream fits only its latest frame's rows; their windows still hold the earlier rows.
    u = np.array([-90.0, 0.0, 0.0])
    rel = np.array([0.0, 300.0, 150.0]) + np.outer(T - 30.0, u)
    r, rdot = _range_rows(rel, np.tile(u, (T.size, 1)))
    rdot = rdot + np.random.default_rng(2).normal(0, 0.1, T.size)
    ids = np.repeat([4, 9], T.size)
    args = (ids, np.tile(T, 2), np.tile(r, 2), np.tile(rdot, 2), np.tile(OWN_V, (2 * T.size, 1)))
    wanted = np.zeros(ids.size, bool)
    wanted[[T.size - 1, 2 * T.size - 40]] = True
    full, some = np.array(range_only_fit(*args)), np.array(range_only_fit(*args, wanted=wanted))
    np.testing.assert_array_equal(some[:, wanted], full[:, wanted])
    assert np.isfinite(some[:, wanted]).all() and np.isnan(some[:, ~wanted]).all()


def test_an_own_ship_turn_or_a_short_track_refuses():
    u = np.array([-100.0, 0.0, 0.0])
    rel = np.array([0.0, 800.0, 0.0]) + np.outer(T - 30.0, u)
    r, rdot = _range_rows(rel, np.tile(u, (T.size, 1)))
    turning = np.column_stack([50.0 * np.cos(0.1 * T), 50.0 * np.sin(0.1 * T), 0 * T])
    assert np.isnan(range_miss_distance(np.zeros(T.size, int), T, r, rdot, turning)[0]).all()
    few = slice(0, 30)  # 3.1 s of rows
    assert np.isnan(range_miss_distance(np.zeros(30, int), T[few], r[few], rdot[few], turning[few])[0]).all()


def test_tracks_are_fitted_apart():
    u = np.array([-60.0, 0.0, 0.0])
    rows = []
    for tid, miss in ((7, 300.0), (3, 900.0)):
        rel = np.array([0.0, 0.0, miss]) + np.outer(T - 30.0, u)
        r, rdot = _range_rows(rel, np.tile(u, (T.size, 1)))
        rows.append(pd.DataFrame({"track_id": tid, "t": T, "r": r, "rdot": rdot}))
    df = pd.concat(rows).sort_values("t", kind="stable")
    got, _ = range_miss_distance(
        df.track_id.to_numpy(),
        df.t.to_numpy(),
        df.r.to_numpy(),
        df.rdot.to_numpy(),
        np.tile(OWN_V, (len(df), 1)),
    )
    last = pd.Series(got, index=df.track_id.to_numpy()).groupby(level=0).last()
    np.testing.assert_allclose(last.loc[[7, 3]], [300.0, 900.0], rtol=1e-6)


def test_cannot_enter_needs_the_corner_cleared_by_three_sigmas():
    corner = np.hypot(670.56, 137.16)
    got = cannot_enter(np.array([corner + 31.0, corner + 29.0]), np.full(2, 10.0), 670.56, 137.16)
    assert got.tolist() == [True, False]


def _tracks(vertical_m: float, horizontal_m: float, measured: bool) -> tuple[pd.DataFrame, pd.DataFrame]:
    """An intruder passing ``vertical_m`` below and ``horizontal_m`` aside, head-on at 150 m/s closure,
    its track held co-altitude (the prior) unless ``measured``; range and range rate are the truth.
    The track starts 35 s before the CPA, 10 s before the warning's alerting time."""
    t = np.arange(0.0, 34.0, 1 / 9.4)
    own = np.column_stack([50.0 * t, 0 * t, -1000.0 + 0 * t])
    intruder = np.column_stack([5250.0 - 100.0 * t, horizontal_m + 0 * t, -1000.0 + vertical_m + 0 * t])
    rel = intruder - own
    r, rdot = _range_rows(rel, np.tile([-150.0, 0.0, 0.0], (t.size, 1)))
    shown = intruder.copy()
    if not measured:  # co-altitude: same range and bearing, at the own-ship's height
        horiz = r / np.hypot(rel[:, 0], rel[:, 1])
        shown = own + np.column_stack([rel[:, 0] * horiz, rel[:, 1] * horiz, 0 * t])
    tracks = pd.DataFrame(
        {
            "time_s": t,
            "track_id": 1,
            "north_m": shown[:, 0],
            "east_m": shown[:, 1],
            "down_m": shown[:, 2],
            "vn_mps": -100.0,
            "ve_mps": 0.0,
            "vd_mps": 0.0,
            "range_m": r,
            "range_rate_mps": rdot,
            "altitude_measured": measured,
        }
    )
    ownship = pd.DataFrame(
        {
            "time_s": t,
            "own_north_m": own[:, 0],
            "own_east_m": own[:, 1],
            "own_down_m": own[:, 2],
            "own_vn_mps": 50.0,
            "own_ve_mps": 0.0,
            "own_vd_mps": 0.0,
            "own_yaw_rad": 0.0,
        }
    )
    return tracks, ownship


def test_a_co_altitude_prior_is_not_warned_when_the_range_says_it_passes_clear():
    # 400 m below and 600 m aside: a 721 m miss, outside the warning cylinder's 684 m corner. Held
    # co-altitude, its track passes 600 m aside (inside 670 m): warned without the range's miss.
    tracks, own = _tracks(400.0, 600.0, measured=False)
    warned = alerts_from_tracks(tracks, own, with_advice=False)["level"].max()
    tracks_plain = tracks.drop(columns=["range_m", "range_rate_mps"])
    assert warned < 3 <= alerts_from_tracks(tracks_plain, own, with_advice=False)["level"].max()


def test_a_real_conflict_is_still_warned_whatever_the_altitude_flag():
    for measured in (False, True):  # 100 m below, 300 m aside: inside the cylinder
        tracks, own = _tracks(100.0, 300.0, measured=measured)
        assert alerts_from_tracks(tracks, own, with_advice=False)["level"].max() == 3


def test_range_and_horizontal_direction_cannot_split_below_from_descending_through():
    # Flat ground 300 m below: overtaken 250 m below, 28 m aside, 29.5 m/s closing; its elevation is
    # nulled with the ground (square array), so the track holds range, range rate and the horizontal
    # direction cosine east / r. Rotating the relative path about the antenna's y axis (east, own-ship
    # level and heading north) keeps all three; 10 deg of rotation is an intruder ahead near the
    # own-ship's level descending at 5.1 m/s (1000 ft/min) that loses well clear 22 s before the
    # closest approach.
    t = np.arange(-40.0, 20.0, 1 / 9.4)
    level = np.column_stack([-29.5 * t, np.full_like(t, -27.6), np.full_like(t, 250.2)])
    turn = np.radians(-10.0)
    about_east = np.array([[np.cos(turn), 0, -np.sin(turn)], [0, 1, 0], [np.sin(turn), 0, np.cos(turn)]])
    descending = level @ about_east.T
    v_level, v_desc = np.gradient(level, t, axis=0), np.gradient(descending, t, axis=0)
    for a, b in zip(_range_rows(level, v_level), _range_rows(descending, v_desc), strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(
        level[:, 1] / np.linalg.norm(level, axis=1),
        descending[:, 1] / np.linalg.norm(descending, axis=1),
        rtol=1e-12,
    )
    assert np.isclose(v_desc[0, 2], 29.5 * np.sin(-turn)) and v_desc[0, 2] < 5.2  # down, m/s
    volume = {"dthr_m": 670.56, "zthr_m": 137.16}  # the warning cylinder (DO-365 non-cooperative)

    def inside(rel):
        return (np.hypot(rel[:, 0], rel[:, 1]) <= volume["dthr_m"]) & (np.abs(rel[:, 2]) <= volume["zthr_m"])

    assert not inside(level).any() and inside(descending).any()
