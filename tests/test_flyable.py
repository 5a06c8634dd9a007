"""Flyable paths from recorded fixes: within the class's limits whatever the fixes' faults.

Real ADS-B fixes are noisy, quantised, stale (the last position repeated), late against the velocity
they are reported with, and jittered in time. Each of these is drawn here on a flight an aircraft can
fly (coordinated turns up to 40 deg of bank, climbs and descents), written as a file in the
``traffic`` convention and read back: the built path must stay within the class's kinematic limits
everywhere between its samples, stay near the flight, and the one line logged for the file must
name what was repaired.
"""

from __future__ import annotations

import logging

import numpy as np
import pandas as pd
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cli_helpers import assert_one_line_error, skyradar, small_scenario
from skyradar.errors import InputError
from skyradar.geo import ned_to_geodetic
from skyradar.scene.adsb import FPM_MPS, FT_M, KT_MPS, read_trajectory
from skyradar.scene.flyable import (
    AIRCRAFT_CLASSES,
    GRAVITY_MPS2,
    MAX_DROPPED_SHARE,
    flyable_path,
    hermite_accelerations,
    kinematic_violation,
)

ORIGIN = (47.0, 11.0, 0.0)
T0 = 1_700_000_000  # unix s of the flights' time 0
GA = AIRCRAFT_CLASSES["ga"]


def _flight(speed_mps: float, legs: list[tuple[float, float, float]], step_s: float = 0.05):
    """Truth (t, position NED, velocity NED) of legs (duration s, bank deg, climb m/s) at ``speed_mps``."""
    t, pos, vel, heading = [0.0], [np.array([0.0, 0.0, -1000.0])], [], 0.0
    rows_v = []
    for duration, bank_deg, climb in legs:
        rate = GRAVITY_MPS2 * np.tan(np.radians(bank_deg)) / speed_mps
        for _ in range(int(duration / step_s)):
            v = np.array([speed_mps * np.cos(heading), speed_mps * np.sin(heading), -climb])
            rows_v.append(v)
            heading += rate * step_s
            pos.append(pos[-1] + v * step_s)
            t.append(t[-1] + step_s)
    vel = np.array([*rows_v, rows_v[-1]])
    return np.array(t), np.array(pos), vel


def _fixes_file(path, t, pos, vel, *, interval_s, jitter_s, noise_m, lag_s, stale_share, rng):
    """Write faulty fixes of a truth flight as a traffic-convention CSV; (stale rows, number of fixes)."""
    fix_t = np.arange(5.0, t[-1] - 5.0, interval_s)
    fix_t = np.sort(fix_t + rng.uniform(-jitter_s, jitter_s, fix_t.size))
    at_pos = np.clip(np.searchsorted(t, fix_t - lag_s), 0, t.size - 1)  # positions lag the velocity
    at_vel = np.clip(np.searchsorted(t, fix_t), 0, t.size - 1)
    p = pos[at_pos] + rng.normal(0.0, noise_m, (fix_t.size, 3)) * [1, 1, 0.3]
    stale = [i for i in range(2, fix_t.size) if rng.random() < stale_share]
    for i in stale:
        p[i] = p[i - 1]
    lat, lon, alt = ned_to_geodetic(p, *ORIGIN)
    v = vel[at_vel]
    pd.DataFrame(
        {
            "timestamp": T0 + fix_t,
            "latitude": lat,
            "longitude": lon,
            "altitude": np.round(alt / FT_M / 25.0) * 25.0,  # 25 ft steps
            "groundspeed": np.round(np.hypot(v[:, 0], v[:, 1]) / KT_MPS),  # whole knots
            "track": np.round(np.degrees(np.arctan2(v[:, 1], v[:, 0])) % 360.0),  # whole degrees
            "vertical_rate": np.round(-v[:, 2] / FPM_MPS / 64.0) * 64.0,  # 64 ft/min steps
        }
    ).to_csv(path, index=False)
    return stale, fix_t.size


def _read(path, caplog):
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="skyradar.scene.adsb"):
        traj = read_trajectory(path, origin=ORIGIN, time_zero_s=T0)
    lines = [r.getMessage() for r in caplog.records if str(path) in r.getMessage()]
    assert len(lines) <= 1, lines
    return traj, (lines[0] if lines else "")


def _assert_within(traj, limits) -> None:
    start, end = hermite_accelerations(traj.time_s, traj.position_ned_m, traj.velocity_ned_mps)
    both = np.concatenate([start, end])  # a cubic's acceleration is bounded by its ends
    assert np.hypot(both[:, 0], both[:, 1]).max() <= limits.horizontal_accel_mps2 + 1e-6
    assert np.abs(both[:, 2]).max() <= limits.vertical_accel_mps2 + 1e-6
    assert np.linalg.norm(traj.velocity_ned_mps, axis=1).max() <= limits.speed_mps


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    speed=st.floats(30.0, 70.0),
    legs=st.lists(
        st.tuples(st.floats(15.0, 50.0), st.floats(-40.0, 40.0), st.floats(-4.0, 4.0)), min_size=2, max_size=4
    ),
    interval_s=st.sampled_from([1.0, 2.0, 5.0, 12.0]),
    jitter_s=st.floats(0.0, 0.5),
    noise_m=st.floats(0.0, 30.0),
    lag_s=st.floats(-2.0, 2.0),
    stale_share=st.sampled_from([0.0, 0.05, 0.15]),
    seed=st.integers(0, 2**16),
)
def test_paths_from_faulty_fixes_stay_within_the_limits(
    tmp_path, caplog, speed, legs, interval_s, jitter_s, noise_m, lag_s, stale_share, seed
):
    rng = np.random.default_rng(seed)
    t, pos, vel = _flight(speed, legs)
    path = tmp_path / f"fixes_{seed}.csv"
    stale, n_fixes = _fixes_file(
        path,
        t,
        pos,
        vel,
        interval_s=interval_s,
        jitter_s=jitter_s,
        noise_m=noise_m,
        lag_s=lag_s,
        stale_share=stale_share,
        rng=rng,
    )
    if len(stale) > MAX_DROPPED_SHARE * n_fixes:  # more faults than a file may have repaired
        with pytest.raises(InputError, match=rf"^{path}: \d+ of {n_fixes} fixes cannot be reconciled"):
            read_trajectory(path)
        return
    traj, line = _read(path, caplog)
    _assert_within(traj, GA)
    # Near the flight: a few noise spreads, plus what a turn's bank does over one fix interval's
    # uncertainty (the path cannot know when between two fixes a roll-in happened), plus the lag's
    # shift along the track, which no data can see on a straight leg (the lagged fixes lie on the
    # same line).
    inside = (t >= traj.start_s) & (t <= traj.end_s)
    error = np.linalg.norm(traj.sample(t[inside]).position_ned_m - pos[inside], axis=1)
    allowed = 3 * noise_m + 10.0 + 0.5 * GA.horizontal_accel_mps2 * interval_s**2 / 4 + abs(lag_s) * speed
    assert np.median(error) < allowed
    if stale:
        assert "stale fix(es) repeating the last position (row" in line


def test_stale_fixes_are_named_by_row(tmp_path, caplog):
    rng = np.random.default_rng(0)
    t, pos, vel = _flight(55.0, [(60.0, 0.0, 0.0), (30.0, 30.0, 2.0)])
    stale, _n = _fixes_file(
        tmp_path / "own.csv",
        t,
        pos,
        vel,
        interval_s=1.0,
        jitter_s=0.0,
        noise_m=5.0,
        lag_s=0.0,
        stale_share=0.05,
        rng=rng,
    )
    _traj, line = _read(tmp_path / "own.csv", caplog)
    assert line.startswith(f"{tmp_path / 'own.csv'}: cleaned: ") and "\n" not in line
    assert f"dropped {len(stale)} stale fix(es)" in line
    assert f"rows {stale[0]}, {stale[1]}" in line


def test_a_late_position_stream_is_retimed_and_named(tmp_path, caplog):
    t, pos, vel = _flight(60.0, [(30.0, 0.0, 0.0), (60.0, 35.0, 0.0), (30.0, 0.0, 0.0)])
    _fixes_file(
        tmp_path / "late.csv",
        t,
        pos,
        vel,
        interval_s=1.0,
        jitter_s=0.0,
        noise_m=3.0,
        lag_s=1.5,
        stale_share=0.0,
        rng=np.random.default_rng(1),
    )
    traj, line = _read(tmp_path / "late.csv", caplog)
    assert "positions re-timed by -1.4" in line or "positions re-timed by -1.5" in line
    inside = (t >= traj.start_s + 2) & (t <= traj.end_s - 2)
    error = np.linalg.norm(traj.sample(t[inside]).position_ned_m - pos[inside], axis=1)
    assert np.median(error) < 5.0  # without the re-timing the path runs 90 m behind


def test_a_spline_through_misaligned_fixes_would_not_be_flyable(tmp_path, caplog):
    """The situation the smoother exists for: fixes 0.5 s off in time at 60 m/s, 1 s apart."""
    t, pos, vel = _flight(60.0, [(60.0, 0.0, 0.0), (60.0, 30.0, 0.0)])
    _fixes_file(
        tmp_path / "jitter.csv",
        t,
        pos,
        vel,
        interval_s=1.0,
        jitter_s=0.5,
        noise_m=0.0,
        lag_s=0.0,
        stale_share=0.0,
        rng=np.random.default_rng(2),
    )
    df = pd.read_csv(tmp_path / "jitter.csv")
    # The fixes' times are jittered: stamped with a fake uniform clock, they say 30-90 m/s.
    stamped = np.round(df["timestamp"].to_numpy())
    lat, lon = df["latitude"].to_numpy(), df["longitude"].to_numpy()
    step = np.hypot(np.diff(lat) * 111_200.0, np.diff(lon) * 111_200.0 * np.cos(np.radians(47.0)))
    df.assign(timestamp=stamped).drop_duplicates("timestamp").to_csv(tmp_path / "stamped.csv", index=False)
    assert (step / np.maximum(np.diff(stamped), 1.0)).max() > 80.0
    traj, _line = _read(tmp_path / "stamped.csv", caplog)
    _assert_within(traj, GA)
    speed = np.linalg.norm(traj.velocity_ned_mps, axis=1)
    assert np.percentile(speed, 95) < 66.0 and np.percentile(speed, 5) > 54.0


def test_too_many_faults_refuse_the_file_in_one_line(tmp_path):
    rng = np.random.default_rng(4)
    t = np.arange(0.0, 200.0, 1.0)
    pos = np.column_stack([50.0 * t, 0 * t, -1000 + 0 * t])
    off = rng.random(t.size) < 0.4
    pos[off] += rng.normal(0, 3000.0, (int(off.sum()), 3))  # 40 % of fixes kilometres off
    with pytest.raises(InputError, match=r"^own.csv: \d+ of 200 fixes cannot be"):
        flyable_path(t, pos, None, GA, label="own.csv")


def test_kinematic_violation_names_the_limit_and_the_time():
    t = np.arange(0.0, 20.0, 0.05)
    v = np.column_stack([50.0 + 0 * t, 0 * t, 0 * t])
    v[t >= 10.0, 2] = -12.0  # a step into a 12 m/s climb: 6 m/s^2 over the 2-s window
    when, what = kinematic_violation(t, v, GA)
    assert 8.0 <= when <= 10.0
    assert what == "vertical acceleration 6 m/s^2 over 2 s (ga limit 4.9 m/s^2)"
    v[:, 2] = np.where(t >= 10.0, -8.0 * np.clip((t - 10.0) / 4.0, 0, 1), 0.0)  # over 4 s: 2 m/s^2
    assert kinematic_violation(t, v, GA) is None
    v[:, 0] = 200.0
    assert "speed 200 m/s (ga limit 160 m/s)" in kinematic_violation(t, v, GA)[1]


def test_a_banked_turn_at_45_deg_is_flyable_by_ga_but_not_by_a_transport():
    t, _pos, vel = _flight(60.0, [(20.0, 0.0, 0.0), (40.0, 45.0, 0.0)])
    assert kinematic_violation(t, vel, GA) is None
    assert "horizontal acceleration" in kinematic_violation(t, vel, AIRCRAFT_CLASSES["transport"])[1]


BASE = small_scenario("kinematics", duration_s=2.0)


def test_simulate_refuses_a_flight_beyond_its_class_in_one_line(tmp_path):
    """Through the entry point: a 'ga' intruder at 250 m/s is refused, naming the field and the time."""
    jet = {"type": "straight", "start_ned_m": [2000, 0, -1000], "heading_deg": 180, "speed_mps": 250}
    (tmp_path / "s.yaml").write_text(yaml.safe_dump({**BASE, "intruders": [jet]}))
    result = skyradar("simulate", "s.yaml", "-o", "run.zarr", cwd=tmp_path)
    assert_one_line_error(
        result, "s.yaml", "field 'intruders.0'", "speed 250 m/s (ga limit 160 m/s)", "t = 0"
    )
    assert not (tmp_path / "run.zarr").exists()
    (tmp_path / "s.yaml").write_text(
        yaml.safe_dump({**BASE, "intruders": [{**jet, "aircraft_class": "transport"}]})
    )
    from skyradar.scene.scenario import load_scenario

    assert load_scenario(tmp_path / "s.yaml").build().intruders[0].trajectory.name == "intruder0"


def test_scenario_file_flight_is_built_within_its_class(tmp_path):
    """A recorded own-ship with faulty fixes becomes a path the simulator accepts."""
    rng = np.random.default_rng(5)
    t, pos, vel = _flight(55.0, [(40.0, 0.0, 0.0), (40.0, -30.0, 1.0), (40.0, 0.0, 0.0)])
    _fixes_file(
        tmp_path / "own.csv",
        t,
        pos,
        vel,
        interval_s=1.0,
        jitter_s=0.4,
        noise_m=15.0,
        lag_s=0.8,
        stale_share=0.1,
        rng=rng,
    )
    data = {
        "name": "file own-ship",
        "duration_s": 95.0,
        "start_s": 5.0,
        "frame_rate_hz": 5.0,
        "ownship": {"type": "file", "path": "own.csv"},
    }
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(data))
    from skyradar.scene.scenario import load_scenario

    built = load_scenario(tmp_path / "s.yaml").build()
    s = built.ownship.sample(built.times_s)
    assert kinematic_violation(s.time_s, s.velocity_ned_mps, GA) is None


def test_a_file_whose_track_is_off_flies_at_its_reported_ground_speed(tmp_path, caplog):
    """Some recordings carry a track column far off their positions' course: its ground speed still
    holds, and the path's own direction carries it (the fixes alone, jittered in time, swing it)."""
    t, pos, vel = _flight(62.0, [(60.0, 0.0, 0.0), (40.0, 20.0, 0.0), (60.0, 0.0, 0.0)])
    _fixes_file(
        tmp_path / "off.csv",
        t,
        pos,
        vel,
        interval_s=5.0,
        jitter_s=1.5,
        noise_m=10.0,
        lag_s=0.0,
        stale_share=0.0,
        rng=np.random.default_rng(6),
    )
    df = pd.read_csv(tmp_path / "off.csv")
    df.assign(track=(df["track"] + 100.0) % 360.0).to_csv(tmp_path / "off.csv", index=False)
    traj, line = _read(tmp_path / "off.csv", caplog)
    assert "track 100 deg off the positions' course: only the ground speed used" in line
    speed = np.linalg.norm(traj.sample(np.arange(15.0, 140.0)).velocity_ned_mps, axis=1)
    assert np.abs(speed - 62.0).max() < 4.0  # the fixes between each other: 40-90 m/s


@pytest.mark.slow
def test_skyradar_flight_writes_the_path_and_its_figure(tmp_path):
    t, pos, vel = _flight(55.0, [(40.0, 0.0, 0.0), (40.0, 30.0, 1.0)])
    _fixes_file(
        tmp_path / "fixes.csv",
        t,
        pos,
        vel,
        interval_s=1.0,
        jitter_s=0.3,
        noise_m=10.0,
        lag_s=0.5,
        stale_share=0.05,
        rng=np.random.default_rng(7),
    )
    result = skyradar("flight", "fixes.csv", "-o", "path.csv", "--figure", "path.png", "--json", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    import json

    summary = json.loads(result.stdout.strip().splitlines()[-1])
    assert summary["horizontal_accel_max_mps2"] <= 10.0 and "stale fix(es)" in summary["repairs"]
    assert (tmp_path / "path.png").stat().st_size > 10_000
    built = read_trajectory(tmp_path / "path.csv")  # the table a scenario flies
    assert built.duration_s == pytest.approx(summary["duration_s"], abs=0.01)
    bad = skyradar("flight", "fixes.csv", "-o", "p2.csv", "--aircraft-class", "jet", cwd=tmp_path)
    assert_one_line_error(bad, "--aircraft-class", "jet")
    bad = skyradar("flight", "fixes.csv", "-o", "p2.txt", cwd=tmp_path)
    assert_one_line_error(bad, "--output", "p2.txt")
    assert not (tmp_path / "p2.csv").exists() and not (tmp_path / "p2.txt").exists()
    again = skyradar("flight", "fixes.csv", "-o", "path.csv", cwd=tmp_path)  # never replaced unasked
    assert again.returncode == 2 and "path.csv" in again.stderr


def test_an_output_under_a_file_is_refused_before_any_work(tmp_path):
    (tmp_path / "afile").write_text("not a folder")
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(BASE))
    for args in (
        ("simulate", "s.yaml", "-o", "afile/run.zarr"),
        ("flight", "s.yaml", "-o", "afile/sub/x.csv"),
    ):
        result = skyradar(*args, cwd=tmp_path)
        assert_one_line_error(result, "afile", "is a file, not a folder")
    assert (tmp_path / "afile").read_text() == "not a folder"


def _textbook_rts(t, z_pos, r_pos, z_vel, r_vel, q):
    """The same filter and smoother in matrix form (numpy, LAPACK's inverse): the peer."""
    n = t.size
    first = int(np.argmax(np.isfinite(z_pos)))
    x, p = np.array([z_pos[first], 0.0]), np.diag([1e8, 1e6])
    xf, pf, xp, pp, total = np.zeros((n, 2)), np.zeros((n, 2, 2)), np.zeros((n, 2)), np.zeros((n, 2, 2)), 0.0
    for k in range(n):
        if k > 0:
            dt = t[k] - t[k - 1]
            f = np.array([[1.0, dt], [0.0, 1.0]])
            x = f @ x
            p = f @ p @ f.T + q * np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]])
        xp[k], pp[k] = x, p
        for j, (z, r) in enumerate(((z_pos[k], r_pos[k]), (z_vel[k], r_vel[k]))):
            if np.isfinite(z):
                s = p[j, j] + r
                if k > first:
                    total -= 0.5 * (np.log(2 * np.pi * s) + (z - x[j]) ** 2 / s)
                gain = p[:, j] / s
                x = x + gain * (z - x[j])
                p = p - np.outer(gain, p[j])
        xf[k], pf[k] = x, p
    xs = xf.copy()
    for k in range(n - 2, -1, -1):
        f = np.array([[1.0, t[k + 1] - t[k]], [0.0, 1.0]])
        c = pf[k] @ f.T @ np.linalg.inv(pp[k + 1])
        xs[k] = xf[k] + c @ (xs[k + 1] - xp[k + 1])
    return xs, total


def test_the_compiled_smoother_is_the_textbook_kalman_rts_pair():
    """The scalar-algebra filter and RTS smoother equal the matrix form on uneven, gappy fixes."""
    from skyradar.scene.flyable import _forward, _rts_axis

    rng = np.random.default_rng(3)
    t = np.cumsum(rng.uniform(0.2, 1.5, 200))
    truth = 60.0 * t + 40.0 * np.sin(t / 9.0)
    z_pos = truth + rng.normal(0.0, 25.0, t.size)
    z_vel = 60.0 + (40.0 / 9.0) * np.cos(t / 9.0) + rng.normal(0.0, 1.5, t.size)
    z_pos[:3] = np.nan  # the filter starts at the first finite position
    z_pos[rng.random(t.size) < 0.2] = np.nan
    z_vel[rng.random(t.size) < 0.3] = np.nan
    r_pos, r_vel = np.full(t.size, 25.0**2), np.full(t.size, 1.5**2)
    expected, expected_total = _textbook_rts(t, z_pos, r_pos, z_vel, r_vel, 0.5)
    np.testing.assert_allclose(_rts_axis(t, z_pos, r_pos, z_vel, r_vel, 0.5), expected, rtol=1e-9, atol=1e-7)
    assert _forward(t, z_pos, r_pos, z_vel, r_vel, 0.5)[4] == pytest.approx(expected_total, rel=1e-10)
    # The smoother is closer to the truth than the fixes (the point of smoothing them).
    assert np.nanmean(np.abs(expected[:, 0] - truth)) < 0.5 * np.nanmean(np.abs(z_pos - truth))
