"""Trajectories: interpolation, attitude, frames, ADS-B readers, parametric flights, encounters."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pymap3d
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import minimize_scalar

from skyradar.errors import InputError
from skyradar.geo import geodetic_to_ned
from skyradar.scene.adsb import FPM_MPS, FT_M, KT_MPS
from skyradar.scene.trajectories import (
    GRAVITY_MPS2,
    Trajectory,
    circle,
    circuit,
    derive_attitude,
    encounter,
    read_trajectories,
    read_trajectory,
    straight,
)

ORIGIN = (52.0, 4.36, 10.0)


# ---- Trajectory ---------------------------------------------------------------------------------
@given(
    coeffs=st.lists(st.floats(-50, 50), min_size=12, max_size=12),
    n=st.integers(2, 6),
)
@settings(max_examples=30, deadline=None)
def test_hermite_reproduces_cubics_exactly(coeffs, n):
    # Cubic Hermite interpolation with exact derivatives is exact for cubic polynomials,
    # so straight lines (and constant acceleration) come out exactly between sparse samples.
    c = np.array(coeffs).reshape(4, 3) * np.array([[1.0], [1.0], [0.1], [0.01]])
    knots = np.linspace(0.0, 20.0, n)

    def pos(t):
        return c[0] + np.outer(t, c[1]) + np.outer(t**2, c[2]) + np.outer(t**3, c[3])

    def vel(t):
        return c[1] + np.outer(2 * t, c[2]) + np.outer(3 * t**2, c[3])

    traj = Trajectory.from_states(knots, pos(knots), vel(knots), origin=ORIGIN)
    t = np.linspace(0.0, 20.0, 97)
    np.testing.assert_allclose(traj.sample(t).position_ned_m, pos(t), atol=1e-9, rtol=1e-12)


def test_straight_line_sampled_between_knots_is_exact():
    traj = straight([100.0, -50.0, -800.0], 37.0, 42.0, 30.0, climb_mps=2.5, origin=ORIGIN, rate_hz=0.1)
    assert len(traj) == 4
    t = np.linspace(0.0, 30.0, 301)
    psi = np.radians(37.0)
    truth = np.array([100.0, -50.0, -800.0]) + np.outer(t, [42.0 * np.cos(psi), 42.0 * np.sin(psi), -2.5])
    s = traj.sample(t)
    np.testing.assert_allclose(s.position_ned_m, truth, atol=1e-9)
    np.testing.assert_allclose(
        s.velocity_ned_mps, np.broadcast_to(truth[1] - truth[0], truth.shape) * 10, atol=1e-9
    )


def test_circle_interpolation_within_tolerance():
    radius, speed = 800.0, 50.0
    traj = circle([0.0, 0.0, -600.0], radius, speed, 120.0, origin=ORIGIN, rate_hz=1.0)
    t = np.linspace(0.0, 120.0, 2401)  # mostly between the 1 Hz knots
    bearing = speed / radius * t
    truth = np.stack([radius * np.cos(bearing), radius * np.sin(bearing), np.full_like(t, -600.0)], axis=1)
    err = np.linalg.norm(traj.sample(t).position_ned_m - truth, axis=1)
    # Hermite error bound ~ R (w dt)^4 / 384 = 3e-5 m for w dt = 0.0625 rad.
    assert err.max() < 1e-4


def test_yaw_interpolates_the_short_way_round():
    t = np.array([0.0, 1.0])
    att = np.radians([[179.0, 0.0, 0.0], [-179.0, 0.0, 0.0]])
    traj = Trajectory(t, np.zeros((2, 3)), np.zeros((2, 3)), att, ORIGIN, "turner")
    yaw = np.degrees(traj.sample([0.5, 0.25]).attitude_rad[:, 0])
    assert abs(abs(yaw[0]) - 180.0) < 1e-9
    assert abs(yaw[1] - 179.5) < 1e-9


def test_sample_outside_span_names_trajectory():
    traj = straight([0, 0, -100], 0, 30, 10, name="own-ship A")
    with pytest.raises(InputError, match="own-ship A.*10.5"):
        traj.sample([1.0, 10.5])
    assert traj.sample([10.0 + 1e-9]).position_ned_m.shape == (1, 3)


def test_trajectory_rejects_bad_arrays():
    z = np.zeros((3, 3))
    with pytest.raises(InputError, match="'bad'.*time_s.*row 2"):
        Trajectory(np.array([0.0, 1.0, 1.0]), z, z, z, ORIGIN, "bad")
    with pytest.raises(InputError, match="position_ned_m"):
        Trajectory(np.array([0.0, 1.0, 2.0]), np.zeros((2, 3)), z, z, ORIGIN, "bad")


def test_shifted_and_duration():
    traj = circle([0, 0, -500], 500, 40, 60, origin=ORIGIN)
    later = traj.shifted(12.5)
    assert later.duration_s == pytest.approx(60.0) and later.start_s == pytest.approx(12.5)
    t = np.array([0.0, 17.3, 60.0])
    np.testing.assert_allclose(
        later.sample(t + 12.5).position_ned_m, traj.sample(t).position_ned_m, atol=1e-9
    )


def test_reframed_is_exact_and_reversible():
    traj = circle([2000.0, -3000.0, -700.0], 600.0, 45.0, 30.0, climb_mps=3.0, origin=ORIGIN)
    new_origin = (52.05, 4.45, 120.0)
    moved = traj.reframed(new_origin)
    a, b = traj.sample(traj.time_s), moved.sample(traj.time_s)
    np.testing.assert_allclose(b.lat_deg, a.lat_deg, atol=1e-10)
    np.testing.assert_allclose(b.lon_deg, a.lon_deg, atol=1e-10)
    np.testing.assert_allclose(b.alt_m, a.alt_m, atol=1e-6)
    # Velocities are the same physical vectors: compare in ECEF with pymap3d's own rotation.
    u1 = np.array(pymap3d.enu2uvw(*a.velocity_ned_mps[:, [1, 0]].T, -a.velocity_ned_mps[:, 2], *ORIGIN[:2]))
    u2 = np.array(
        pymap3d.enu2uvw(*b.velocity_ned_mps[:, [1, 0]].T, -b.velocity_ned_mps[:, 2], *new_origin[:2])
    )
    np.testing.assert_allclose(u1, u2, atol=1e-9)
    np.testing.assert_allclose(moved.attitude_rad, traj.attitude_rad)
    back = moved.reframed(ORIGIN)
    np.testing.assert_allclose(back.position_ned_m, traj.position_ned_m, atol=1e-6)


# ---- attitude -----------------------------------------------------------------------------------
@pytest.mark.parametrize("clockwise", [True, False])
@pytest.mark.parametrize(("radius", "speed"), [(300.0, 30.0), (1000.0, 60.0), (150.0, 25.0)])
def test_circle_bank_matches_coordinated_turn(radius, speed, clockwise):
    traj = circle([0, 0, -1000], radius, speed, 90.0, clockwise=clockwise, origin=ORIGIN)
    roll = traj.attitude_rad[len(traj) // 4 : 3 * len(traj) // 4, 2]
    expected = np.arctan(speed**2 / (GRAVITY_MPS2 * radius)) * (1 if clockwise else -1)
    np.testing.assert_allclose(roll, expected, atol=2e-4)  # 2e-4 rad: local-vertical tilt over the circle


def test_attitude_of_climbing_straight_flight():
    traj = straight([0, 0, -300], 250.0, 40.0, 20.0, climb_mps=4.0, origin=ORIGIN)
    att = np.degrees(traj.attitude_rad)
    np.testing.assert_allclose(att[:, 0], 250.0 - 360.0, atol=0.01)
    np.testing.assert_allclose(att[:, 1], np.degrees(np.arctan2(4.0, 40.0)), atol=0.01)
    # A straight line in the tangent plane slowly turns against the local meridians: ~0.002 deg bank.
    np.testing.assert_allclose(att[:, 2], 0.0, atol=0.01)


def test_derive_attitude_holds_heading_when_stopped():
    t = np.arange(5.0)
    v = np.array([[0.0, 10.0, 0.0], [0.0, 5.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 3.0, 0.0]])
    np.testing.assert_allclose(derive_attitude(t, v)[:, 0], np.pi / 2)


# ---- readers ------------------------------------------------------------------------------------
def _opensky_rows():
    """Four fixes 5 s apart of an aircraft at 100 kt on track 30 deg climbing at 300 ft/min: the
    positions move as the reported velocity says (0.002 deg north and 0.00188 deg east per fix)."""
    return pd.DataFrame(
        {
            "timestamp": [1_700_000_000, 1_700_000_005, 1_700_000_010, 1_700_000_015],
            "icao24": ["4840d6"] * 4,
            "callsign": ["PHABC"] * 4,
            "latitude": [52.0, 52.002, 52.004, 52.006],
            "longitude": [4.36, 4.36188, 4.36376, 4.36564],
            "altitude": [1500.0, 1525.0, 1550.0, 1575.0],
            "groundspeed": [100.0] * 4,
            "track": [30.0] * 4,
            "vertical_rate": [300.0] * 4,
        }
    )


def test_opensky_units_are_converted_exactly(tmp_path):
    from skyradar.scene.adsb import _local_velocity

    df = _opensky_rows()
    gs, trk = df["groundspeed"] * 1852.0 / 3600.0, np.radians(df["track"])
    np.testing.assert_allclose(
        _local_velocity(df),
        np.column_stack([gs * np.cos(trk), gs * np.sin(trk), -df["vertical_rate"] * 0.3048 / 60]),
    )
    assert (FT_M, KT_MPS, FPM_MPS) == (0.3048, 1852.0 / 3600.0, 0.3048 / 60.0)
    path = tmp_path / "track.csv"
    df.to_csv(path, index=False)
    traj = read_trajectory(path)
    assert traj.name == "PHABC" and traj.epoch_s == 1_700_000_000.0
    assert traj.origin == (52.0, 4.36, 1500.0 * 0.3048)
    assert (traj.start_s, traj.end_s) == (0.0, 15.0)
    s = traj.sample(np.array([0.0, 5.0, 10.0, 15.0]))
    np.testing.assert_allclose(s.alt_m, df["altitude"] * 0.3048, atol=0.5)
    np.testing.assert_allclose(s.lat_deg, df["latitude"], atol=2e-5)  # 2 m
    np.testing.assert_allclose(np.degrees(s.attitude_rad[:, 0]), df["track"], atol=0.5)


def test_formats_agree_and_iso_timestamps(tmp_path):
    df = _opensky_rows()
    df.to_csv(tmp_path / "a.csv", index=False)
    df.to_parquet(tmp_path / "a.parquet", index=False)
    (tmp_path / "a.json").write_text(json.dumps(df.to_dict(orient="records")))
    iso = df.assign(
        timestamp=pd.to_datetime(df["timestamp"], unit="s", utc=True).dt.strftime("%Y-%m-%dT%H:%M:%SZ")
    )
    iso.to_csv(tmp_path / "iso.csv", index=False)
    df.to_json(tmp_path / "a.jsonl", orient="records", lines=True)
    ref = read_trajectory(tmp_path / "a.csv")
    for name in ("a.parquet", "a.json", "iso.csv", "a.jsonl"):
        other = read_trajectory(tmp_path / name)
        np.testing.assert_allclose(other.position_ned_m, ref.position_ned_m, atol=1e-6, err_msg=name)
        np.testing.assert_allclose(other.velocity_ned_mps, ref.velocity_ned_mps, atol=1e-6, err_msg=name)
        np.testing.assert_allclose(other.time_s, ref.time_s, err_msg=name)
        assert other.epoch_s == ref.epoch_s


def test_si_columns_and_derived_velocities(tmp_path):
    truth = straight([0, 0, -400], 60.0, 35.0, 20.0, climb_mps=1.5, origin=ORIGIN, rate_hz=1.0)
    s = truth.sample(truth.time_s)
    base = pd.DataFrame({"time_s": s.time_s, "latitude": s.lat_deg, "longitude": s.lon_deg, "alt_m": s.alt_m})
    base.to_csv(tmp_path / "nov.csv", index=False)
    derived = read_trajectory(tmp_path / "nov.csv", origin=ORIGIN)
    times = np.linspace(0.0, 20.0, 41)
    np.testing.assert_allclose(
        derived.sample(times).position_ned_m, truth.sample(times).position_ned_m, atol=0.05
    )
    np.testing.assert_allclose(
        derived.sample(times).velocity_ned_mps, truth.sample(times).velocity_ned_mps, atol=0.05
    )
    assert np.isnan(derived.epoch_s)
    # SI velocity columns are local NED at each aircraft: rotate the truth there first.
    from skyradar.scene.trajectories import origin_to_local_rotation

    local = np.einsum(
        "nij,nj->ni", origin_to_local_rotation(s.lat_deg, s.lon_deg, *ORIGIN[:2]), s.velocity_ned_mps
    )
    base.assign(vn=local[:, 0], ve=local[:, 1], vd=local[:, 2]).to_parquet(tmp_path / "si.parquet")
    given_v = read_trajectory(tmp_path / "si.parquet", origin=ORIGIN)
    np.testing.assert_allclose(
        given_v.sample(times).velocity_ned_mps, truth.sample(times).velocity_ned_mps, atol=0.05
    )


def test_opensky_impala_state_vectors(tmp_path):
    df = _opensky_rows()
    impala = pd.DataFrame(
        {
            "time": df["timestamp"],
            "icao24": df["icao24"],
            "lat": df["latitude"],
            "lon": df["longitude"],
            "geoaltitude": df["altitude"] * 0.3048,
            "velocity": df["groundspeed"] * 1852.0 / 3600.0,
            "heading": df["track"],
            "vertrate": df["vertical_rate"] * 0.3048 / 60.0,
        }
    )
    impala.to_parquet(tmp_path / "impala.parquet")
    df.to_csv(tmp_path / "traffic.csv", index=False)
    a, b = read_trajectory(tmp_path / "impala.parquet"), read_trajectory(tmp_path / "traffic.csv")
    np.testing.assert_allclose(a.position_ned_m, b.position_ned_m, atol=1e-9)
    np.testing.assert_allclose(a.velocity_ned_mps, b.velocity_ned_mps, atol=1e-12)
    assert a.epoch_s == b.epoch_s


def test_read_trajectories_groups_by_aircraft(tmp_path):
    a = _opensky_rows()
    b = _opensky_rows().assign(icao24="008123", callsign="DLH1", timestamp=lambda d: d["timestamp"] + 2)
    b["latitude"] += 0.01
    pd.concat([a, b]).sort_values("timestamp").to_csv(tmp_path / "many.csv", index=False)
    tracks = read_trajectories(tmp_path / "many.csv")
    assert sorted(tracks) == ["008123", "4840d6"]
    assert tracks["4840d6"].origin == tracks["008123"].origin == (52.0, 4.36, 1500.0 * 0.3048)
    assert (tracks["008123"].start_s, tracks["008123"].end_s) == (2.0, 17.0)  # shared clock
    assert tracks["008123"].name == "DLH1"
    np.testing.assert_allclose(
        tracks["008123"].position_ned_m[0, 0],
        geodetic_to_ned(52.01, 4.36, 457.2, *tracks["4840d6"].origin)[0],
        atol=0.5,  # the smoothed path, not the first fix exactly
    )
    with pytest.raises(InputError, match="many.csv.*'icao24'.*read_trajectories"):
        read_trajectory(tmp_path / "many.csv")


@pytest.mark.parametrize(
    ("change", "pattern"),
    [
        (lambda d: d.drop(columns="latitude"), "track.csv: missing required field 'latitude'"),
        (lambda d: d.drop(columns="altitude"), "track.csv: missing required field 'altitude'"),
        (lambda d: d.drop(columns="timestamp"), "track.csv: missing required field 'timestamp'"),
        # Steps back in time, repeated times and NaN positions are repaired (tests/test_adsb_clean.py);
        # what cannot be is refused with the reason:
        (
            lambda d: d.assign(timestamp=[1000.0, 1001.0, 1001.0, 1002.0], latitude=[52, 52, 52.1, 52]),
            r"track.csv: field 'timestamp' repeats at rows \[1, 2\] with positions 1113[23] m apart",
        ),
        (
            lambda d: d.assign(longitude=[4.0, np.nan, np.nan, np.nan]),
            "track.csv: field 'timestamp' has 1 row.* with a time and a position",
        ),
        (
            lambda d: d.assign(timestamp=[5e9, 5e9 + 1, 5e9 + 2, 5e9 + 3]),
            "track.csv: field 'timestamp' runs from 5e.09 to .*fits no one unit",
        ),
        (
            lambda d: d.assign(latitude=[52.0, 52.0, 95.0, 52.0]),
            "track.csv: field 'latitude' out of range at row 2",
        ),
        (lambda d: d.iloc[:1], "track.csv: field 'timestamp' has 1 row"),
        (
            lambda d: d.assign(timestamp=["2024-01-01T00:00:00", "soon", "x", "y"]),
            "track.csv: field 'timestamp' is not a time at row 1",
        ),
    ],
)
def test_bad_files_name_file_field_and_row(tmp_path, change, pattern):
    path = tmp_path / "track.csv"
    change(_opensky_rows()).to_csv(path, index=False)
    with pytest.raises(InputError, match=pattern) as info:
        read_trajectory(path)
    assert "\n" not in str(info.value)


def test_unknown_and_missing_files(tmp_path):
    (tmp_path / "track.xyz").write_text("a,b\n")
    with pytest.raises(InputError, match=r"track.xyz: unknown file type '.xyz'"):
        read_trajectory(tmp_path / "track.xyz")
    with pytest.raises(InputError, match="nothere.csv: no such file"):
        read_trajectory(tmp_path / "nothere.csv")
    (tmp_path / "bad.json").write_text('{"a": 1}')
    with pytest.raises(InputError, match="bad.json"):
        read_trajectory(tmp_path / "bad.json")


# ---- parametric flights -------------------------------------------------------------------------
def test_circuit_geometry_speed_and_bank():
    speed, bank = 40.0, 25.0
    traj = circuit([100.0, 200.0, -5.0], 280.0, 300.0, speed, 600.0, origin=ORIGIN, bank_deg=bank)
    v = traj.velocity_ned_mps
    np.testing.assert_allclose(np.hypot(v[:, 0], v[:, 1]), speed, rtol=1e-12)  # constant ground speed
    s = traj.sample(traj.time_s)
    np.testing.assert_allclose(s.position_ned_m, traj.position_ned_m, atol=1e-9)
    # Central differences of the positions match the analytic velocities to their truncation
    # error V w^2 dt^2 / 6 (w = V / r in the turns), except at the few samples where legs join.
    radius = speed**2 / (GRAVITY_MPS2 * np.tan(np.radians(bank)))
    num = np.gradient(traj.position_ned_m, traj.time_s, axis=0)
    bound = speed * (speed / radius) ** 2 * 0.05**2 / 6.0
    assert np.percentile(np.linalg.norm(num - v, axis=1), 99) < 1.01 * bound
    # Steady climbing turn: tan(roll) = V_total * turn_rate / g, so the turn flown while climbing at
    # 6 deg banks by atan(tan(25 deg) / cos(6 deg)) = 25.12 deg; left turns only.
    roll = np.degrees(traj.attitude_rad[:, 2])
    expected = np.degrees(np.arctan(np.tan(np.radians(bank)) / np.cos(np.radians(6.0))))
    assert roll.min() == pytest.approx(-expected, abs=0.02) and roll.max() < 0.05
    level = circuit(
        [0, 0, 0], 280.0, 300.0, speed, 300.0, origin=ORIGIN, touch_and_go=False, start_leg="downwind"
    )
    assert np.degrees(level.attitude_rad[:, 2]).min() == pytest.approx(-bank, abs=0.02)
    np.testing.assert_allclose(level.position_ned_m[:, 2], -300.0)
    height = -5.0 - traj.position_ned_m[:, 2]  # above the threshold (5 m above the origin)
    assert height.min() == pytest.approx(0.0, abs=1.0) and height.max() == pytest.approx(300.0)
    # It is a closed loop: the same state one lap later.
    lap = (2 * (3500.0 + 1200.0) - 8 * radius + 2 * np.pi * radius) / speed
    np.testing.assert_allclose(
        traj.sample([10.0 + lap]).position_ned_m, traj.sample([10.0]).position_ned_m, atol=1e-6
    )


def test_circuit_rejects_tight_legs():
    with pytest.raises(InputError, match="width_m"):
        circuit([0, 0, 0], 90.0, 300.0, 60.0, 100.0, width_m=400.0)
    with pytest.raises(InputError, match="pattern_altitude_m"):
        circuit([0, 0, 0], 90.0, 1500.0, 40.0, 100.0)


def _cpa(own: Trajectory, intruder: Trajectory) -> tuple[float, float]:
    """CPA (time, distance) of two sampled trajectories: grid search, then a bounded minimiser."""
    t = np.linspace(own.start_s, own.end_s, 4001)
    d = np.linalg.norm(intruder.sample(t).position_ned_m - own.sample(t).position_ned_m, axis=1)
    k = int(d.argmin())
    lo, hi = t[max(k - 1, 0)], t[min(k + 1, t.size - 1)]

    def dist(x):
        return float(np.linalg.norm(intruder.sample([x]).position_ned_m - own.sample([x]).position_ned_m))

    res = minimize_scalar(dist, bounds=(lo, hi), method="bounded", options={"xatol": 1e-7})
    return float(res.x), float(res.fun)


@given(
    kind=st.sampled_from(["head-on", "crossing", "overtaking", "converging"]),
    angle=st.floats(20.0, 160.0) | st.floats(-160.0, -20.0),
    h_miss=st.floats(0.0, 1500.0),
    v_miss=st.floats(-300.0, 300.0),
    t_cpa=st.floats(10.0, 50.0),
    own_heading=st.floats(0.0, 360.0),
    own_speed=st.floats(20.0, 70.0),
    own_climb=st.floats(-5.0, 5.0),
    side=st.sampled_from(["right", "left"]),
)
@settings(max_examples=40, deadline=None)
def test_encounter_cpa_matches_request(
    kind, angle, h_miss, v_miss, t_cpa, own_heading, own_speed, own_climb, side
):
    own = straight([0.0, 0.0, -1500.0], own_heading, own_speed, 60.0, climb_mps=own_climb, origin=ORIGIN)
    intruder = encounter(own, kind, t_cpa, h_miss, v_miss, crossing_angle_deg=angle, side=side)
    t_found, d_found = _cpa(own, intruder)
    assert d_found == pytest.approx(np.hypot(h_miss, v_miss), abs=1e-3)
    assert t_found == pytest.approx(t_cpa, abs=1e-3)
    at = intruder.sample([t_cpa]).position_ned_m[0] - own.sample([t_cpa]).position_ned_m[0]
    assert -at[2] == pytest.approx(v_miss, abs=1e-6)  # positive vertical miss = intruder above
    assert np.hypot(at[0], at[1]) == pytest.approx(h_miss, abs=1e-6)
    right = np.array([-np.sin(np.radians(own_heading)), np.cos(np.radians(own_heading))])
    if h_miss > 1.0:
        assert (at[:2] @ right > -1e-6) == (side == "right")


@given(
    h_miss=st.floats(200.0, 1000.0),
    v_miss=st.floats(-150.0, 150.0),
    climb=st.floats(-3.0, 3.0),
    angle=st.floats(30.0, 150.0),
)
@settings(max_examples=20, deadline=None)
def test_encounter_with_intruder_climb(h_miss, v_miss, climb, angle):
    own = straight([0.0, 0.0, -1500.0], 10.0, 45.0, 60.0, origin=ORIGIN)
    intruder = encounter(
        own, "crossing", 30.0, h_miss, v_miss, crossing_angle_deg=angle, intruder_climb_mps=climb
    )
    t_found, d_found = _cpa(own, intruder)
    assert t_found == pytest.approx(30.0, abs=1e-3)
    assert d_found == pytest.approx(np.hypot(h_miss, v_miss), abs=1e-3)


def test_encounter_extrapolates_and_rejects_impossible():
    own = straight([0, 0, -1000], 0, 30, 10, origin=ORIGIN)
    head_on = encounter(own, "head-on", 2000.0 / 60.0, intruder_speed_mps=30.0)
    d0 = np.linalg.norm(head_on.sample([0.0]).position_ned_m - own.sample([0.0]).position_ned_m)
    assert d0 == pytest.approx(2000.0, abs=1e-6)
    with pytest.raises(InputError, match="vertical_miss_m"):
        encounter(own, "crossing", 5.0, 0.0, 100.0, intruder_climb_mps=4.0)
    with pytest.raises(InputError, match="intruder_speed_mps"):
        encounter(own, "overtaking", 5.0, 100.0, intruder_speed_mps=30.0)
    with pytest.raises(InputError, match="kind"):
        encounter(own, "sideways", 5.0)
