"""Resolution advice: bands against brute-force propagation, MVP resolves, terrain bands."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyradar.daa.advice import (
    _choose,
    band_intervals,
    heading_bands,
    mvp_velocity,
    resolution_advice,
    vertical_speed_bands,
)
from skyradar.daa.conflict import WellClearVolume, cpa

VOL = WellClearVolume.do365_noncoop()
LOOK = 55.0


def _brute_conflict(own_v, s, v_int, vol, lookahead, dt=0.05):
    """Independent check: propagate every intruder on a time grid and test the cylinder."""
    t = np.arange(0.0, lookahead + dt / 2, dt)
    for si, vi in zip(s, v_int, strict=True):
        rel = si[None, :] + t[:, None] * (vi - own_v)[None, :]
        if np.any((np.hypot(rel[:, 0], rel[:, 1]) <= vol.dthr_m) & (np.abs(rel[:, 2]) <= vol.zthr_m)):
            return True
    return False


def _encounter(rng, n):
    own = np.array([50.0, 0.0, 0.0])
    s, v = [], []
    for _ in range(n):
        tc, miss, psi, sp = (
            rng.uniform(15, 50),
            rng.uniform(-900, 900),
            rng.uniform(0, 2 * np.pi),
            rng.uniform(20, 70),
        )
        vi = np.array([sp * np.cos(psi), sp * np.sin(psi), rng.uniform(-3, 3)])
        vrel = vi - own
        perp = np.array([-vrel[1], vrel[0], 0.0]) / (np.hypot(vrel[0], vrel[1]) + 1e-9)
        s.append(-vrel * tc + perp * miss + np.array([0, 0, rng.uniform(-150, 150)]))
        v.append(vi)
    return own, np.array(s), np.array(v)


@given(st.integers(0, 10_000), st.integers(1, 3))
@settings(max_examples=25, deadline=None)
def test_heading_bands_match_brute_force(seed, n):
    own, s, v = _encounter(np.random.default_rng(seed), n)
    headings, conflict = heading_bands(own, s, v, VOL, LOOK, step_deg=10.0)
    for h, c in zip(headings, conflict, strict=True):
        cand = np.array([50.0 * np.cos(np.radians(h)), 50.0 * np.sin(np.radians(h)), 0.0])
        brute = _brute_conflict(cand, s, v, VOL, LOOK)
        if brute != c:
            # Only grazing encounters (closest approach within a grid step of the boundary) may differ.
            _, hmd, _ = cpa(s, v - cand)
            assert np.min(np.abs(hmd - VOL.dthr_m)) < 5.0


def test_head_on_bands_and_preferred_heading():
    own = np.array([50.0, 0.0, 0.0])
    s = np.array([[4000.0, 50.0, 0.0]])
    v = np.array([[-50.0, 0.0, 0.0]])
    adv = resolution_advice(own, s, v, VOL, LOOK)
    bands = adv["heading_bands_deg"]
    assert any(lo <= 0.0 <= hi or lo <= 360.0 <= hi for lo, hi in bands)  # present heading conflicts
    assert adv["n_conflicts"] == 1
    # Intruder slightly right: MVP turns left, and the preferred heading is conflict-free.
    assert 180.0 < adv["preferred_heading_deg"] < 360.0
    ph = np.radians(adv["preferred_heading_deg"])
    assert not _brute_conflict(np.array([50 * np.cos(ph), 50 * np.sin(ph), 0.0]), s, v, VOL, LOOK)
    # Vertical: climbing or descending fast enough clears the 450 ft cylinder before the encounter.
    assert adv["vs_bands_mps"] and adv["vs_bands_mps"][0][0] < 0 < adv["vs_bands_mps"][0][1]


def test_preferred_manoeuvre_is_conflict_free_for_several_intruders():
    rng = np.random.default_rng(7)
    solved = 0
    for _ in range(30):
        own, s, v = _encounter(rng, 3)
        adv = resolution_advice(own, s, v, VOL, LOOK)
        if adv["heading_saturated"]:
            continue
        ph = np.radians(adv["preferred_heading_deg"])
        cand = np.array([50 * np.cos(ph), 50 * np.sin(ph), 0.0])
        # Judged with the own-ship's (unchanged) vertical speed of 0.
        assert not _brute_conflict(cand, s, v, VOL, LOOK, dt=0.02) or _grazing(cand, s, v)
        solved += 1
    assert solved >= 20


def _grazing(cand, s, v):
    _, hmd, _ = cpa(s, v - cand)
    return np.min(np.abs(hmd - VOL.dthr_m)) < 2.0


def test_mvp_separates_single_horizontal_conflict():
    rng = np.random.default_rng(3)
    ratios = []
    for _ in range(300):
        own, s, v = _encounter(rng, 1)
        s[:, 2] = 0.0
        v[:, 2] = 0.0
        new, conf = mvp_velocity(own, s, v, VOL, LOOK)
        if not conf[0]:
            continue
        _, hmd0, _ = cpa(s[0], v[0] - own)
        _, hmd1, _ = cpa(s[0], v[0] - np.array([new[0], new[1], 0.0]))
        assert hmd1 > hmd0  # always pushes apart
        ratios.append(hmd1 / VOL.dthr_m)
    # MVP aims at 1.05 x DTHR at the old closest approach; measured: median 1.05, 92 % above 1.0.
    assert np.median(ratios) == pytest.approx(1.05, abs=0.01)
    assert np.mean(np.array(ratios) >= 0.999) > 0.85


def test_mvp_head_on_turns_perpendicular():
    new, conf = mvp_velocity(
        np.array([50.0, 0, 0]), np.array([[3000.0, 0, 0]]), np.array([[-50.0, 0, 0]]), VOL, LOOK
    )
    assert conf[0]
    assert abs(new[1]) > 5.0 and new[0] == pytest.approx(50.0)


def test_mvp_vertical_moves_away_from_level_intruder_above():
    # Intruder 100 m above, level, head-on: own-ship pushed down.
    new, _ = mvp_velocity(
        np.array([50.0, 0, 0]), np.array([[3000.0, 0, -100.0]]), np.array([[-50.0, 0, 0]]), VOL, LOOK
    )
    assert new[2] > 0  # down positive


def test_no_conflict_no_advice():
    own = np.array([50.0, 0.0, 0.0])
    adv = resolution_advice(own, np.array([[3000.0, 1500.0, 0.0]]), np.array([[0.0, -50.0, 0.0]]), VOL, LOOK)
    assert adv["heading_bands_deg"] and adv["n_conflicts"] == 0  # some headings would conflict
    assert adv["preferred_heading_deg"] == pytest.approx(0.0)
    assert adv["preferred_vs_mps"] == pytest.approx(0.0)


def test_terrain_vertical_speed_bands():
    own = np.array([50.0, 0.0, 0.0])
    none = np.zeros((0, 3))
    vs, traffic, terrain = vertical_speed_bands(
        own, none, none, VOL, LOOK, height_agl_m=200.0, min_height_agl_m=150.0, terrain_lookahead_s=20.0
    )
    assert not traffic.any()
    np.testing.assert_array_equal(terrain, 200.0 + vs * 20.0 < 150.0)
    # Below the minimum: only climbs that recover within the terrain lookahead are free.
    _, _, low = vertical_speed_bands(own, none, none, VOL, LOOK, height_agl_m=100.0, terrain_lookahead_s=20.0)
    assert low[vs < 2.5].all() and not low[vs >= 2.5].any()
    adv = resolution_advice(
        np.array([50.0, 0, 3.0]),
        np.array([[4000.0, 0.0, 0.0]]),
        np.array([[-50.0, 0, 0]]),
        VOL,
        LOOK,
        height_agl_m=120.0,
    )
    assert adv["terrain_vs_bands_mps"]
    assert adv["preferred_vs_mps"] >= (150.0 - 120.0) / 30.0


def test_band_intervals_wraps_headings():
    h = np.arange(0.0, 360.0, 10.0)
    c = (h <= 20) | (h >= 340) | ((h >= 100) & (h <= 120))
    assert band_intervals(h, c, 10.0, circular=True) == [[95.0, 125.0], [335.0, 385.0]]
    assert band_intervals(h, np.zeros_like(c), 10.0) == []


def test_recovery_choice_when_every_candidate_conflicts():
    vs = np.arange(-10.0, 10.5, 0.5)
    entry = 20.0 - np.abs(vs - 4.0)  # latest loss of well clear at +4 m/s
    terrain = vs < 1.5
    # Nearest free wins when one exists.
    some_free = np.where(vs == 8.0, np.inf, entry)
    assert _choose(vs, some_free, ~terrain, -6.0, circular=False) == 8.0
    # All conflict: the allowed candidate whose conflict comes latest, never into the terrain.
    assert _choose(vs, entry, ~terrain, -6.0, circular=False) == 4.0
    assert _choose(vs, np.where(vs < 0, 25.0, entry), ~terrain, -6.0, circular=False) == 4.0
    # Headings wrap: 350 is 20 deg from 10, nearer than 40.
    h = np.arange(0.0, 360.0, 10.0)
    free = np.where((h == 350) | (h == 40), np.inf, 1.0)
    assert _choose(h, free, np.ones(h.size, bool), 10.0, circular=True) == 350.0
