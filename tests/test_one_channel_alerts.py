"""A one-channel radar alerts from range and range rate alone: on the 3-D miss against the well-clear
cylinders' corners, a head-on warned before the loss of well clear, a pass 1.5 km abeam never
alerted, and an intruder passing 300 m below alerted (the limit of one channel: no range can split
the miss into horizontal and vertical)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from skyradar.chain import run_chain
from skyradar.daa.alerting import AlertConfig
from skyradar.daa.conflict import WellClearVolume, loss_of_well_clear_interval
from skyradar.daa.pipeline import alerts_from_tracks
from skyradar.daa.range_miss import range_only_fit
from skyradar.daa.range_only import corner_entry_time, corner_m, range_only_levels
from skyradar.scene.scenario import Scenario

OWN_SPEED, INTRUDER_SPEED = 50.0, 40.0  # m/s, own north, intruders south: 90 m/s closing
CLOSING = OWN_SPEED + INTRUDER_SPEED
HEAD_ON = np.array([1400.0, -10.0, 0.0])  # start relative to the own-ship, NED, m
ABEAM = np.array([1700.0, 1500.0, 0.0])
BELOW = np.array([2200.0, 0.0, 300.0])
WARNING = 3
NONCOOP = WellClearVolume.do365_noncoop()


def _scenario() -> dict:
    def intruder(name: str, start: np.ndarray, **extra) -> dict:
        ned = [float(start[0]), float(start[1]), -2000.0 + float(start[2])]
        return {
            "name": name,
            "type": "straight",
            "start_ned_m": ned,
            "heading_deg": 180,
            "speed_mps": INTRUDER_SPEED,
            **extra,
        }

    return {
        "name": "one channel",
        "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
        "radar": {"range_limit_m": 2500, "rx_positions_m": [[0.0, 0.0, 0.0]]},
        "ownship": {"type": "straight", "start_ned_m": [0, 0, -2000], "speed_mps": OWN_SPEED},
        # The abeam intruder is seen at 40-60 deg off boresight: a larger aircraft, so that it is tracked.
        "intruders": [
            intruder("head-on", HEAD_ON),
            intruder("abeam", ABEAM, rcs_m2=50.0),
            intruder("below", BELOW),
        ],
        "frame_rate_hz": 9.4,
        "duration_s": 10.0,
    }


@pytest.fixture(scope="module")
def chain() -> dict:
    return run_chain(Scenario.from_dict(_scenario()).build())


def _alerts_of(chain: dict, start: np.ndarray) -> pd.DataFrame:
    """The alert rows of the track whose first range is the intruder's."""
    alerts = chain["alerts"]
    first = alerts.sort_values("time_s").groupby("track_id").first()
    t0 = first["time_s"].to_numpy()
    expected = np.linalg.norm(start - np.outer(t0, [CLOSING, 0.0, 0.0]), axis=1)
    tid = first.index[np.argmin(np.abs(first["range_m"].to_numpy() - expected))]
    assert abs(first.loc[tid, "range_m"] - expected[first.index.get_loc(tid)]) < 50.0
    return alerts[alerts["track_id"] == tid]


def test_every_track_of_one_channel_is_alerted_on_its_range_only_geometry(chain):
    alerts = chain["alerts"]
    assert alerts["track_id"].nunique() == 3 and (alerts["geometry"] == "range-only").all()
    assert alerts["bearing_deg"].isna().all() and (alerts["sector"] == -1).all()
    assert not alerts["altitude_measured"].any() and alerts["hmd_m"].isna().all()
    # No bearing, no advice: the frames with an alert have none, and nothing crashed computing it.
    alerting = alerts[alerts["level"] > 0]
    assert len(alerting) and alerting["preferred_heading_deg"].isna().all()
    assert all(len(b) == 0 for b in alerting["heading_bands_deg"])


def test_a_head_on_collision_course_is_warned_before_the_loss_of_well_clear(chain):
    # Closed form: co-altitude, 10 m aside, 90 m/s closing: horizontally within D at this time.
    d, aside = NONCOOP.dthr_m, abs(HEAD_ON[1])
    t_lowc = (HEAD_ON[0] - np.sqrt(d**2 - aside**2)) / CLOSING
    assert 8.0 < t_lowc < 8.2  # the scenario runs 10 s: past it
    alerts = _alerts_of(chain, HEAD_ON)
    warned = alerts.loc[alerts["level"] >= WARNING, "time_s"]
    assert len(warned) and warned.min() < t_lowc - 2.0
    assert (alerts["miss_m"].dropna() < 50.0).all()  # the fit's 3-D miss: a collision course


def test_a_pass_far_beyond_the_corner_is_never_alerted(chain):
    alerts = _alerts_of(chain, ABEAM)
    fitted = alerts["miss_m"].dropna()
    assert len(fitted) > 20 and np.all(np.abs(fitted - 1500.0) < 30.0)  # the 3-D miss, well measured
    assert fitted.min() > 2 * corner_m(NONCOOP)
    assert alerts["level"].max() == 0 and alerts["flarm_level"].max() == 0


def test_the_limit_of_one_channel_an_intruder_passing_below_inside_the_corner_is_alerted(chain):
    # 300 m straight below: it never loses well clear (300 m > Z = 137 m), but its 3-D miss is inside
    # the corner sqrt(D^2 + Z^2) = 684 m and no range or range rate says whether it is below or
    # ahead at the own-ship's level. One channel alerts on it; a radar measuring elevation would not.
    alerts = _alerts_of(chain, BELOW)
    assert abs(BELOW[2]) > NONCOOP.zthr_m and abs(BELOW[2]) < corner_m(NONCOOP)
    fitted = alerts["miss_m"].dropna()
    assert len(fitted) > 20 and np.all(np.abs(fitted - 300.0) < 40.0)
    assert alerts["level"].max() == WARNING


# The range-only geometry against closed form.

T = np.arange(0.0, 12.0, 1 / 9.4)


def _straight(
    t: np.ndarray, miss_vec: np.ndarray, u: np.ndarray, t_cpa: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Relative position (m), range (m) and range rate (m/s) of the straight path through ``miss_vec``
    at ``t_cpa`` (s) with relative velocity ``u`` (m/s)."""
    rel = miss_vec + np.outer(t - t_cpa, u)
    r = np.linalg.norm(rel, axis=1)
    return rel, r, rel @ u / r


@pytest.mark.parametrize("split_deg", [0.0, 30.0, 90.0])
def test_range_only_fit_and_corner_entry_are_the_closed_form_ones(split_deg):
    miss, u, t_cpa = 400.0, np.array([-90.0, 0.0, 0.0]), 30.0
    split = np.radians(split_deg)  # 0: all aside, 90: all below
    miss_vec = miss * np.array([0.0, np.cos(split), np.sin(split)])
    rel, r, rdot = _straight(T, miss_vec, u, t_cpa)
    m, sd, u2, tc = range_only_fit(np.zeros(T.size, int), T, r, rdot, np.tile([50.0, 0, 0], (T.size, 1)))
    ok = np.isfinite(m)
    assert ok[-1] and not ok[0]
    np.testing.assert_allclose(m[ok], miss, rtol=1e-6)
    np.testing.assert_allclose(u2[ok], 90.0**2, rtol=1e-9)
    np.testing.assert_allclose(tc[ok], t_cpa, atol=1e-6)
    assert np.all(sd[ok] < 1e-3)
    # The corner's entry: the range reaches C at t_cpa - sqrt(C^2 - m^2) / |u|, from the last row.
    c = corner_m(NONCOOP)
    expected = t_cpa - np.sqrt(c**2 - miss**2) / 90.0 - T[-1]
    got = corner_entry_time(m[-1:], u2[-1:], tc[-1:] - T[-1], NONCOOP, 60.0)
    np.testing.assert_allclose(got, expected, rtol=1e-9)
    # The sphere stands for the cylinder: the 3-D track enters the cylinder no earlier, if at all.
    t_cyl, _ = loss_of_well_clear_interval(rel[-1:], u[None, :], NONCOOP, 60.0)
    assert np.isnan(t_cyl[0]) if miss_vec[2] > NONCOOP.zthr_m else t_cyl[0] >= got[0] - 1e-9
    # Levels: a warning once the entry is within its 25 s alerting time, none beyond the corner.
    levels = range_only_levels(
        np.array([miss, 2 * c]), np.zeros(2), np.full(2, 8100.0), np.array([t_cpa - T[-1]] * 2), AlertConfig()
    )
    assert levels["level"].tolist() == [WARNING, 0] and levels["known"].all()
    np.testing.assert_allclose(levels["t_in_s"][0], expected, rtol=1e-9)


def test_a_collision_course_fits_a_zero_miss_and_warns():
    _, r, rdot = _straight(T, np.zeros(3), np.array([-90.0, 0.0, 0.0]), 20.0)
    own_v = np.tile([50.0, 0, 0], (T.size, 1))
    m, _, u2, tc = range_only_fit(np.zeros(T.size, int), T, r, rdot, own_v)
    assert m[-1] < 0.01 and abs(tc[-1] - 20.0) < 1e-6  # zero, to rounding
    # A range rate 0.1 % high puts every row's squared miss below zero: the miss is 0, not refused.
    biased, _, _, _ = range_only_fit(np.zeros(T.size, int), T, r, 1.001 * rdot, own_v)
    assert biased[-1] == 0.0
    levels = range_only_levels(m[-1:], np.zeros(1), u2[-1:], tc[-1:] - T[-1], AlertConfig())
    # Entry into the 684 m corner at 20 - 684 / 90 s, from the last row.
    np.testing.assert_allclose(levels["t_in_s"], 20.0 - corner_m(NONCOOP) / 90.0 - T[-1], rtol=1e-6)
    assert levels["level"][0] == WARNING


def test_range_only_tracks_table_alerts_beside_a_3d_track_and_carries_its_path_through_a_gap():
    t = np.arange(0.0, 14.0, 0.2)
    own = pd.DataFrame(
        {
            "time_s": t,
            "own_north_m": 50.0 * t,
            "own_east_m": 0.0,
            "own_down_m": -1000.0,
            "own_vn_mps": 50.0,
            "own_ve_mps": 0.0,
            "own_vd_mps": 0.0,
        }
    )
    _, r, rdot = _straight(t, np.array([0.0, 100.0, 0.0]), np.array([-90.0, 0.0, 0.0]), 25.0)
    ranged = pd.DataFrame(
        {
            "time_s": t,
            "track_id": 1,
            "north_m": np.nan,
            "east_m": np.nan,
            "down_m": np.nan,
            "vn_mps": np.nan,
            "ve_mps": np.nan,
            "vd_mps": np.nan,
            "range_m": r,
            "range_rate_mps": rdot,
        }
    )
    ranged = ranged[(t < 9.0) | (t > 11.0)]  # a 2 s gap: the lost track's prediction carries the path
    located = pd.DataFrame(
        {
            "time_s": t,
            "track_id": 2,
            "north_m": 50.0 * t + 3000.0 - 90.0 * t,
            "east_m": 2000.0,
            "down_m": -1000.0,
            "vn_mps": -40.0,
            "ve_mps": 0.0,
            "vd_mps": 0.0,
            "range_m": np.nan,
            "range_rate_mps": np.nan,
        }
    )
    alerts = alerts_from_tracks(pd.concat([ranged, located]), own, AlertConfig())
    one, two = alerts[alerts["track_id"] == 1], alerts[alerts["track_id"] == 2]
    assert (one["geometry"] == "range-only").all() and (two["geometry"] == "3-d").all()
    assert alerts.attrs["rows_skipped_no_state"] == 0
    gap = one[one["extrapolated"]]
    assert len(gap) and gap["miss_m"].notna().all() and (gap["level"] == WARNING).all()
    np.testing.assert_allclose(gap["range_m"], np.hypot(100.0, 90.0 * (25.0 - gap["time_s"])), rtol=1e-6)
    assert one["level"].max() == WARNING and two["level"].max() == 0
    # The 3-D track's rows are placed; the frames where the range-only track alerts carry no advice.
    assert two["bearing_deg"].notna().all() and one["bearing_deg"].isna().all()
    assert alerts.loc[alerts["level"] > 0, "preferred_heading_deg"].isna().all()
