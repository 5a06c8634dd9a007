"""3-D track quality for the DAA layer and sliding-window confirmation."""

import numpy as np
import pandas as pd
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from skyradar.config import RadarConfig
from skyradar.track.measure3d import angle_sigma_rad, position_covariance
from skyradar.track.models import radar_model
from skyradar.track.track_table import OWNSHIP_COLUMNS, track_detections
from skyradar.track.tracker import RangeDopplerTracker, TrackerConfig
from skyradar.track.tracker3d import RadialObservation, Tracker3D, range_rate_update
from skyradar.units import wrap

CFG = RadarConfig.prototype_2022()
W = 2 * CFG.v_lim_mps
DT = 0.106


def _straight_encounter(seed: int, sigma_angle_rad: float = 0.03, gap=None):
    """Own-ship flying north at 50 m/s, an intruder flying straight at 60 m/s; DoA positions at
    the measured (coupled) range with angle noise across the line of sight."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 25.0, DT)
    own_v = np.array([50.0, 0.0, 0.0])
    own = t[:, None] * own_v
    vel = np.array([-45.0, -40.0, 1.5])
    pos = np.array([3500.0, 1500.0, -150.0]) + t[:, None] * vel
    d = pos - own
    R = np.linalg.norm(d, axis=1)
    u = d / R[:, None]
    V = u @ (vel - own_v)
    a = rng.normal(0.0, sigma_angle_rad, (t.size, 3))
    a -= np.sum(a * u, axis=1)[:, None] * u
    un = (u + a) / np.linalg.norm(u + a, axis=1)[:, None]
    rm = R + CFG.range_doppler_coupling_s * V + rng.normal(0.0, 4.5, t.size)
    keep = rng.random(t.size) < 0.9
    if gap is not None:
        keep[gap[0] : gap[1]] = False
    ned = own + rm[:, None] * un
    det = pd.DataFrame(
        {
            "time_s": t,
            "frame": np.arange(t.size),
            "range_m": rm,
            "radial_velocity_mps": wrap(V + rng.normal(0.0, 0.1, t.size), W),
            "north_m": ned[:, 0],
            "east_m": ned[:, 1],
            "down_m": ned[:, 2],
        }
    )[keep]
    cols = {
        c: own[:, i] if i < 3 else np.full(t.size, own_v[i - 3]) for i, c in enumerate(OWNSHIP_COLUMNS[1:])
    }
    return t, det, pd.DataFrame({"time_s": t, **cols}), vel, pos, own, own_v


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_straight_intruder_3d_speed_within_a_few_mps_after_convergence(seed):
    t, det, ownship, vel, pos, own, own_v = _straight_encounter(seed)
    tracks = track_detections(det, "radar", CFG, frame_times_s=t, ownship=ownship, position_sigma_rad=0.03)
    assert tracks.track_id.nunique() == 1
    late = tracks[tracks.time_s > 10.0]
    v = late[["vn_mps", "ve_mps", "vd_mps"]].to_numpy()
    speed_err = np.abs(np.linalg.norm(v, axis=1) - np.linalg.norm(vel))
    assert speed_err.max() < 5.0 and np.median(speed_err) < 2.5
    # The radial velocity (the radar's accurate measurement) pins the line-of-sight component.
    k = late.frame.to_numpy()
    u = (pos[k] - own[k]) / np.linalg.norm(pos[k] - own[k], axis=1)[:, None]
    radial_err = np.sum(u * (v - vel), axis=1)
    assert np.median(np.abs(radial_err)) < 0.5
    # Velocity covariance is written, symmetric and positive definite.
    cov = late[[f"cov_vv_{i}{j}" for i in range(3) for j in range(3)]].to_numpy(float).reshape(-1, 3, 3)
    np.testing.assert_allclose(cov, np.swapaxes(cov, 1, 2), atol=1e-9)
    assert np.all(np.linalg.eigvalsh(cov) > 0)
    assert all(f"cov_pv_{i}{j}" in tracks.columns for i in range(3) for j in range(3))


def test_radial_velocity_update_beats_positions_alone():
    t, det, ownship, vel, pos, own, _ = _straight_encounter(5, sigma_angle_rad=0.05)
    errs = []
    for own_table in (None, ownship):
        tracks = track_detections(
            det, "radar", CFG, frame_times_s=t, ownship=own_table, position_sigma_rad=0.05
        )
        late = tracks[tracks.time_s > 10.0]
        k = late.frame.to_numpy()
        u = (pos[k] - own[k]) / np.linalg.norm(pos[k] - own[k], axis=1)[:, None]
        v = late[["vn_mps", "ve_mps", "vd_mps"]].to_numpy()
        errs.append(np.median(np.abs(np.sum(u * (v - vel), axis=1))))
    assert errs[1] < 0.5 * errs[0]


def test_a_range_rate_moves_the_horizontal_velocity_only_along_the_line_of_sight():
    # The range rate says nothing about the position or the horizontal velocity across the line of
    # sight: with position-velocity and cross-velocity correlations in P, the update leaves the
    # position alone and changes the horizontal velocity along the horizontal line of sight only.
    # The vertical speed takes the optimal gain (P h / S), small under its tight level-flight prior.
    rng = np.random.default_rng(3)
    A = rng.normal(size=(6, 6))
    P = (A @ A.T + 6.0 * np.eye(6))[None] * 25.0
    x = np.array([[2000.0, 1000.0, -300.0, -40.0, 10.0, 1.0]])
    obs = RadialObservation(np.zeros(3), np.array([50.0, 0.0, 0.0]), np.array([-99.0]), 0.2)
    x1, P1 = range_rate_update(x, P, obs.radial_velocity_mps, obs)
    u = x[0, :3] / np.linalg.norm(x[0, :3])
    u_h = u[:2] / np.linalg.norm(u[:2])
    dv = x1[0, 3:] - x[0, 3:]
    assert np.array_equal(x1[0, :3], x[0, :3])
    assert abs(dv[0] * u_h[1] - dv[1] * u_h[0]) < 1e-9  # nothing across the horizontal line of sight
    Ph = P[0] @ np.concatenate([np.zeros(3), u])  # the optimal gain's direction, times S
    assert dv[2] / (dv[:2] @ u_h) == pytest.approx(Ph[5] / (Ph[3:5] @ u_h))
    assert np.all(np.linalg.eigvalsh(P1[0]) > 0.0) and np.allclose(P1[0], P1[0].T)


def test_a_range_rate_straight_above_moves_only_the_vertical_speed():
    # Straight above the own-ship the line of sight has no horizontal part: the range rate measures
    # the vertical closure alone, and the horizontal velocity and the covariance stay finite.
    obs = RadialObservation(np.zeros(3), np.array([50.0, 0.0, 0.0]), np.array([-3.0]), 0.2)
    x = np.array([[0.0, 0.0, -300.0, 0.0, 0.0, 0.0]])
    x1, P1 = range_rate_update(x, np.eye(6)[None] * 100.0, obs.radial_velocity_mps, obs)
    assert np.all(np.isfinite(x1)) and np.all(np.isfinite(P1))
    assert np.array_equal(x1[0, :5], x[0, :5]) and x1[0, 5] > 2.5  # closing from above: descending


def test_range_rates_do_not_send_a_level_intruder_down_the_line_of_sight_vertically():
    # A level intruder 250 m above, 3.5 km ahead: the line of sight climbs at 4 deg, so a gain along
    # the 3-D line of sight would put 7 % of the first range rate's 50 m/s correction into the
    # vertical speed (3.5 m/s of descent towards the own-ship at 2 s, a false vertical conflict).
    # The vertical speed's own gain, under its 3 m/s prior, keeps it level.
    rng = np.random.default_rng(11)
    own_v, int_v = np.array([50.0, 0.0, 0.0]), np.array([-50.0, 0.0, 0.0])
    rel0, runs = np.array([3500.0, 100.0, -250.0]), 300
    t3, ids = Tracker3D(), np.arange(runs)
    for k in range(int(6.0 / DT) + 1):
        t = k * DT
        own = own_v * t
        rel = rel0 + (int_v - own_v) * t
        r = np.linalg.norm(rel)
        u = rel / r
        across = rng.normal(0.0, 0.02, (runs, 3))
        across -= (across @ u)[:, None] * u
        seen = (u + across) / np.linalg.norm(u + across, axis=1)[:, None]
        pos = own + (r + rng.normal(0.0, 5.0, (runs, 1))) * seen
        cov = position_covariance(pos, own, np.full(runs, 0.02), np.full(runs, r * 0.02))
        rr = u @ (int_v - own_v) + rng.normal(0.0, 0.2, runs)
        x, _ = t3.step(t, ids, pos, cov, RadialObservation(own, own_v, rr, 0.2))
        if k in (int(2.0 / DT), int(6.0 / DT)):
            assert abs(float(np.mean(x[:, 5]))) < 0.5, t


def test_confirmed_false_while_coasting_and_true_again_after():
    t, det, ownship, *_ = _straight_encounter(0, gap=(100, 110))
    tracks = track_detections(det, "radar", CFG, frame_times_s=t, ownship=ownship)
    assert tracks.track_id.nunique() == 1
    coasting = tracks.misses >= 5
    assert coasting.any() and not tracks.confirmed[coasting].any()
    assert tracks.confirmed[tracks.frame > 112].all()


def test_patchy_redetection_is_confirmed_by_sliding_window():
    # Hits in frames 0, 2, 3, 5, 6: no 4-of-5 window starts at the first hit, but 2..6 has four.
    hits = {0, 2, 3, 5, 6}
    trk = RangeDopplerTracker(radar_model(W), TrackerConfig(confirm_m=4, confirm_n=5))
    seen = []
    for k in range(9):
        z = np.array([[1500.0 + 2.0 * k, 12.0]]) if k in hits else np.zeros((0, 2))
        seen.append(trk.step(k * DT, z).track_id.tolist())
    assert seen[6] == [0] and seen[5] == []
    # Isolated detections two frames apart never confirm, and die after two misses.
    trk = RangeDopplerTracker(radar_model(W), TrackerConfig(confirm_m=4, confirm_n=5))
    for k in range(12):
        z = np.array([[1500.0 + 2.0 * k, 12.0]]) if k % 3 == 0 else np.zeros((0, 2))
        assert trk.step(k * DT, z).track_id.size == 0


def test_position_covariance_and_range_rate_update_shapes():
    C = position_covariance(np.array([[0.0, 2000.0, 0.0]]), np.zeros(3), np.array([0.02]), 5.0)
    np.testing.assert_allclose(np.diag(C[0]), [1600.0, 25.0, 1600.0])
    s = angle_sigma_rad(np.array([12.0, 25.0]), CFG)
    assert 0.01 <= s[1] < s[0] < 0.3
    obs = RadialObservation(np.zeros(3), np.array([50.0, 0.0, 0.0]), np.array([np.nan]), 0.2)
    x = np.array([[1000.0, 1000.0, 0.0, -40.0, 0.0, 0.0]])
    x1, P1 = range_rate_update(x, np.eye(6)[None] * 100.0, np.array([-70.0]), obs)
    u = np.array([1.0, 1.0, 0.0]) / np.sqrt(2.0)
    assert np.dot(u, x1[0, 3:] - obs.own_velocity_mps) == pytest.approx(-70.0, abs=1.0)
    assert np.all(np.linalg.eigvalsh(P1[0]) > 0)


def _miss_direction_velocity_errors(sigma_angle_rad: float, ages_s: tuple[float, ...], runs: int = 300):
    """A head-on intruder at 50 m/s passing 800 m abeam of the own-ship (north at 50 m/s), first seen
    3.5 km away, level: DoA positions with ``sigma_angle_rad`` across the line of sight, the range
    rate to 0.2 m/s, every frame. ``runs`` independent tracks (one filter each) at once; per age (s),
    the error of the relative velocity along the true miss direction (m/s) and its stated sigma."""
    rng = np.random.default_rng(7)
    own_v, int_v = np.array([50.0, 0.0, 0.0]), np.array([-50.0, 0.0, 0.0])
    rel0 = np.array([3500.0, 800.0, 0.0])
    t3 = Tracker3D()
    ids = np.arange(runs)
    out = {}
    for k in range(int(max(ages_s) / DT) + 2):
        t = k * DT
        own = own_v * t
        rel = rel0 + (int_v - own_v) * t
        r = np.linalg.norm(rel)
        u = rel / r
        across = rng.normal(0.0, sigma_angle_rad, (runs, 3))
        across -= (across @ u)[:, None] * u
        seen = (u + across) / np.linalg.norm(u + across, axis=1)[:, None]
        pos = own + (r + rng.normal(0.0, 5.0, (runs, 1))) * seen
        sigma = np.full(runs, sigma_angle_rad)
        cov = position_covariance(pos, own, sigma, r * sigma)
        rr = u @ (int_v - own_v) + rng.normal(0.0, 0.2, runs)
        x, P = t3.step(t, ids, pos, cov, RadialObservation(own, own_v, rr, 0.2))
        for age in ages_s:
            if abs(t - age) < DT / 2:
                miss = np.array([0.0, 1.0, 0.0])  # the relative path runs south, 800 m east of the own-ship
                out[age] = ((x[:, 3:] - int_v) @ miss, np.sqrt(miss @ P[:, 3:, 3:] @ miss))
    return out


def test_range_rates_do_not_bias_the_predicted_miss_towards_a_collision_course():
    # The range rate measures the velocity along the true line of sight; the filter's line of sight is
    # its own estimate, off by the angle error of its position. A gain acting across it reads that
    # error as cross-range information and holds the cross velocity near the first updates' (the
    # intruder sent down the line of sight: 7 m/s short along the miss at 6 s, 23 m/s with the
    # measured directions instead of the predicted one). Confined to the line of sight, the range
    # rate leaves the velocity across it to the positions, and the estimate is unbiased.
    out = _miss_direction_velocity_errors(0.05, (6.0, 10.0))
    for age, (err, sigma) in out.items():
        assert abs(err.mean()) < max(3.0 * err.std() / np.sqrt(err.size), 0.5), age
        assert 0.3 < np.mean((err / sigma) ** 2) < 1.5, age  # the stated sigma is not too small
    fine = _miss_direction_velocity_errors(0.01, (6.0,), runs=100)[6.0][0]
    assert np.sqrt(np.mean(fine**2)) < 3.0  # precise directions converge within seconds


@settings(max_examples=80, deadline=None)
@given(
    st.tuples(st.floats(-3000, 3000), st.floats(-3000, 3000), st.floats(-800, 800)),
    st.tuples(st.floats(-80, 80), st.floats(-80, 80), st.floats(-8, 8)),
    st.floats(-0.9, 0.9),
)
def test_a_height_restart_keeps_range_bearing_range_rate_and_vertical_speed(rel, vel, up_fraction):
    # Tracker3D.reset_height moves a filter on its range sphere: range (measured to a metre) and
    # range rate (to a few cm/s) must not change, nor the bearing or the vertical speed.
    rel, own = np.array(rel), np.array([10.0, -20.0, -500.0, 45.0, 5.0, 0.5])
    r = np.linalg.norm(rel)
    assume(np.hypot(rel[0], rel[1]) > 50.0)
    t3 = Tracker3D()
    t3.step(0.0, np.array([4]), (own[:3] + rel)[None], np.array([100.0]))
    t3.x[0, 3:] = own[3:] + np.array(vel)
    before = t3.x[0].copy()

    def seen(x):
        d, v = x[:3] - own[:3], x[3:] - own[3:]
        return np.linalg.norm(d), np.arctan2(d[1], d[0]), d @ v / np.linalg.norm(d)

    t3.reset_height(np.array([4]), own, np.array([up_fraction * r]), np.array([30.0]))
    assert np.allclose(seen(t3.x[0]), seen(before), atol=1e-6)
    assert np.isclose(own[2] - t3.x[0, 2], up_fraction * r) and t3.x[0, 5] == before[5]
    assert np.isclose(np.sqrt(t3.P[0, 2, 2]), 30.0)


def _fly(t3: Tracker3D, track_id: int, times: np.ndarray, velocity: np.ndarray, start: np.ndarray) -> None:
    rng = np.random.default_rng(track_id)
    for t in times:
        pos = start + velocity * t + rng.normal(0.0, 20.0, 3)
        t3.step(float(t), np.array([track_id]), pos[None], np.array([400.0]))


def test_a_reacquired_filter_keeps_the_lost_ones_velocity():
    # 6 s of 10 Hz positions (20 m noise) give the velocity to a few m/s; after a 3 s gap, a new
    # filter with 0.4 s of positions knows it to tens of m/s. Renamed to the lost id, it is fused
    # with the lost filter predicted across the gap: the velocity error is that of the history.
    velocity, start = np.array([-60.0, 20.0, 0.0]), np.array([3000.0, -500.0, -50.0])
    t3 = Tracker3D()
    _fly(t3, 1, np.arange(0.0, 6.0, 0.1), velocity, start)
    _fly(t3, 2, np.arange(9.0, 9.4, 0.1), velocity, start)  # track 1 is lost, track 2 is new
    fresh_sd = np.sqrt(t3.P[0, 3, 3])
    t3.rename(np.array([2]), np.array([1]))
    assert t3.ids.tolist() == [1]
    fused_sd = np.sqrt(t3.P[0, 3, 3])
    assert fused_sd < fresh_sd / 3
    assert np.linalg.norm(t3.x[0, 3:5] - velocity[:2]) < 4.0 * fused_sd * np.sqrt(2) + 1.0


def test_a_lost_filter_of_another_aircraft_is_not_fused():
    # The lost filter predicts an aircraft 1 km from where the new track is: not one aircraft's.
    t3 = Tracker3D()
    _fly(t3, 1, np.arange(0.0, 6.0, 0.1), np.array([-60.0, 0.0, 0.0]), np.array([3000.0, 0.0, -50.0]))
    _fly(t3, 2, np.arange(9.0, 9.4, 0.1), np.array([-60.0, 0.0, 0.0]), np.array([3000.0, 1000.0, -50.0]))
    before = t3.x.copy(), t3.P.copy()
    t3.rename(np.array([2]), np.array([1]))
    np.testing.assert_array_equal(t3.x, before[0])
    np.testing.assert_array_equal(t3.P, before[1])
    # Nor is one forgotten after the memory.
    t3 = Tracker3D(lost_memory_s=2.0)
    _fly(t3, 1, np.arange(0.0, 6.0, 0.1), np.array([-60.0, 0.0, 0.0]), np.array([3000.0, 0.0, -50.0]))
    _fly(t3, 2, np.arange(9.0, 9.4, 0.1), np.array([-60.0, 0.0, 0.0]), np.array([3000.0, 0.0, -50.0]))
    before = t3.P.copy()
    t3.rename(np.array([2]), np.array([1]))
    np.testing.assert_array_equal(t3.P, before)


def _mirror_then_truth(restart: bool) -> tuple[np.ndarray, np.ndarray]:
    """A filter fed an aircraft 310 m above (down -1310 m) as each frame reads it: until 1 s the
    frames alternate between it and its mirror 860 m lower (a MIMO radar's two velocity residues,
    where the field of view cannot choose), then every position is the aircraft's (the track's range
    rate now chooses). The first frame and two of every three read the mirror; the stated noise
    varies with the SNR frame by frame. Returns the filter's down position and vertical speed per
    frame after 1 s."""
    t3 = Tracker3D()
    ids = np.array([0])
    rng = np.random.default_rng(3)
    downs, climbs = [], []
    for k, t in enumerate(np.arange(0.0, 4.0, DT)):
        cov = np.diag([1.0, 0.7, 1.2]) ** 2 * rng.uniform(8.0, 18.0) ** 2  # stated noise, SNR by SNR, m^2
        truth = np.array([1000.0 - 15.0 * t, 300.0, -1310.0])
        mirror = truth + [0.0, 0.0, 860.0]
        seen = mirror if (t < 1.0 and k % 3 != 2) else truth
        first_truth_frame = restart and t >= 1.0 and t - DT < 1.0
        x, _ = t3.step(
            t, ids, (seen + rng.normal(0.0, 10.0, 3))[None], cov[None],
            restart_ids=ids if first_truth_frame else None,
        )  # fmt: skip
        if t >= 1.0:
            downs.append(x[0, 2])
            climbs.append(-x[0, 5])
    return np.array(downs), np.array(climbs)


def test_a_filter_fed_two_hypotheses_restarts_when_told_which_is_right():
    # Fed mostly the mirror and now and then the aircraft, the filter learns a noise scale of
    # hundreds and sits at the mirror; once the positions are all the aircraft's, a filter told so
    # restarts on the first one that misses its gate at the stated noise and holds the aircraft's
    # height, level.
    # Left to its gate, the aircraft's positions straddle it with that noise scale (the stated noise
    # varies), so the five rejections in a row its restart waits for do not come: it accepts one now
    # and then and slides towards the aircraft: 3 s later it is still hundreds of metres off and
    # climbing, a vertical speed a level aircraft never had.
    downs, climbs = _mirror_then_truth(restart=True)
    assert np.all(np.abs(downs + 1310.0) < 30.0)
    assert np.all(np.abs(climbs) < 5.0)
    downs, climbs = _mirror_then_truth(restart=False)
    assert np.min(np.abs(downs + 1310.0)) > 500.0 and climbs[-1] > 3.0
