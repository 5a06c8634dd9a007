"""Ground filter: static-surface Doppler with aliasing, height above terrain, and their combination."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from skyradar.config import RadarConfig
from skyradar.geo import geodetic_to_ned, ned_to_geodetic
from skyradar.process.ground import (
    classify_ground,
    doppler_matches_static,
    height_above_ground_m,
    in_ground_band,
    static_radial_velocity_mps,
)
from skyradar.scene.synthetic_terrain import flat_terrain

CFG = RadarConfig.prototype_2022()


@given(
    v=st.lists(st.floats(-80, 80), min_size=3, max_size=3),
    p=st.lists(st.floats(-3000, 3000), min_size=3, max_size=3),
)
def test_static_radial_velocity_is_the_range_rate_of_a_fixed_point(v, p):
    own_v, point = np.array(v), np.array(p)
    if np.linalg.norm(point) < 10:
        return
    dt = 1e-4
    # Own-ship moves, the point is fixed: central difference of the range.
    rate = (np.linalg.norm(point - own_v * dt) - np.linalg.norm(point + own_v * dt)) / (2 * dt)
    u = point / np.linalg.norm(point)
    assert static_radial_velocity_mps(u[None], own_v)[0] == pytest.approx(rate, abs=1e-2)


def test_doppler_match_wraps_at_the_aliasing_width():
    width = 2 * CFG.v_lim_mps
    expected = np.array([-60.0, 10.0, 10.0])
    measured = np.array([-60.0 + width, 10.0 + 0.4, 10.0 + 5.0])
    assert doppler_matches_static(measured, expected, CFG, 1.0).tolist() == [True, True, False]


def test_height_above_terrain_uses_the_dem_under_each_detection():
    terrain = flat_terrain(52.0, 4.0, height_m=120.0, size_m=4000.0, spacing_m=30.0)
    lat, lon, alt = ned_to_geodetic(np.array([[500.0, 200.0, -125.0], [-800.0, 0.0, -900.0]]), 52.0, 4.0, 0.0)
    h = height_above_ground_m(lat, lon, alt, terrain)
    # NED "down" is along the origin's vertical; the difference at 800 m is millimetres.
    np.testing.assert_allclose(h, [5.0, 780.0], atol=0.2)
    assert np.isnan(height_above_ground_m(lat, lon, alt)).all()
    np.testing.assert_allclose(
        height_above_ground_m(lat, lon, alt, ground_alt_m=0.0), [125.0, 900.0], atol=0.2
    )


def test_classify_ground_separates_terrain_from_aircraft_for_a_moving_radar():
    # Own-ship at 1000 m flying north at 40 m/s; ground point 2 km ahead, aircraft at co-altitude.
    own = np.array([0.0, 0.0, -1000.0])
    own_v = np.array([40.0, 0.0, 0.0])
    points = np.array([[1732.0, 0.0, 0.0], [2000.0, 300.0, -1000.0], [1500.0, -400.0, -1000.0]])
    rel = points - own
    rng = np.linalg.norm(rel, axis=1)
    u = rel / rng[:, None]
    crossing = np.cross(u[2], [0.0, 0.0, 1.0])  # last aircraft flies across the line of sight
    target_v = np.array([[0.0, 0.0, 0.0], [-50.0, 0.0, 0.0], 40.0 * crossing / np.linalg.norm(crossing)])
    v_r = np.einsum("ij,ij->i", target_v - own_v, u)
    v_meas = (v_r + CFG.v_lim_mps) % (2 * CFG.v_lim_mps) - CFG.v_lim_mps  # aliased as measured
    lat, lon, alt = ned_to_geodetic(points, 52.0, 4.0, 0.0)
    terrain = flat_terrain(52.0, 4.0, height_m=0.0, size_m=6000.0, spacing_m=30.0)
    height = height_above_ground_m(lat, lon, alt, terrain)
    ground = classify_ground(rng, v_meas, u, CFG, own_v, height)
    assert ground.tolist() == [True, False, False]
    # The crossing aircraft has the ground's radial velocity there: Doppler alone would call it ground
    # (a circling glider can lose 158 of 348 detections that way), so without a height above ground
    # nothing is ground.
    static = doppler_matches_static(v_meas, static_radial_velocity_mps(u, own_v), CFG, 1.0)
    assert static.tolist() == [True, False, True]
    assert not classify_ground(rng, v_meas, u, CFG, own_v, None).any()
    assert not classify_ground(rng, v_meas, u, CFG, None, None).any()


def test_stationary_radar_without_terrain_calls_nothing_ground():
    u = np.array([[1.0, 0.0, 0.0]])
    assert not classify_ground(np.array([500.0]), np.array([0.0]), u, CFG, np.zeros(3), None).any()
    # With a flat ground altitude a static return at ground level is ground.
    lat, lon, alt = ned_to_geodetic(np.array([[500.0, 0.0, 0.0]]), 52.0, 4.0, 0.0)
    h = height_above_ground_m(lat, lon, alt, ground_alt_m=0.0)
    assert classify_ground(np.array([500.0]), np.array([0.0]), u, CFG, np.zeros(3), h).all()
    assert geodetic_to_ned(lat, lon, alt, 52.0, 4.0, 0.0).shape == (1, 3)


def test_ground_band_is_the_clutter_region_of_a_level_flight():
    # 1000 m above flat ground at 30 m/s: at 2 km the ground fills |v| <= 30 * sqrt(1 - 0.25) = 26 m/s.
    v_own = np.array([30.0, 0.0, 0.0])
    rng = np.full(4, 2000.0)
    v = np.array([-25.0, 20.0, 30.0, -35.0])
    assert in_ground_band(rng, v, v_own, 1000.0, CFG, tolerance_mps=0.0).tolist() == [
        True,
        True,
        False,
        False,
    ]
    # Below the own-ship height there is no ground; climbing shifts the band by -v_d h / R.
    assert not in_ground_band(np.array([800.0]), np.array([0.0]), v_own, 1000.0, CFG).any()
    climbing = np.array([30.0, 0.0, -10.0])
    assert in_ground_band(np.array([2000.0]), np.array([30.0]), climbing, 1000.0, CFG, 0.0).all()
    # Fast flight: the band covers the whole aliased Doppler axis.
    assert in_ground_band(np.array([3000.0]), np.array([10.0]), np.array([90.0, 0, 0]), 500.0, CFG, 0.0).all()


def _ridge_frame(elevation_deg: float) -> dict:
    """One unreliable detection at 500 m, azimuth 60 deg, level flight north at 50 m/s, 550 m AGL."""
    az, el = np.radians(60.0), np.radians(elevation_deg)
    u = np.array([[np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)]])
    p = 500.0 * u
    return {
        "range_m": np.array([500.0]),
        "snr_db": np.array([20.0]),
        "azimuth_rad": np.array([az]),
        "elevation_rad": np.array([el]),
        "north_m": p[:, 0],
        "east_m": p[:, 1],
        "down_m": p[:, 2],
        "radial_velocity_mps": -u[:, 0] * 50.0,  # a static point's
        "u_ant": u,
        "coherence": np.array([0.3]),  # ground left and right in one cell: the direction is unreliable
    }


def test_ridge_beside_the_track_nearer_than_the_ground_below_is_ground():
    # Flat ground 550 m below, and a ridge east of 300 m whose top is 263 m higher: its returns come
    # at 500 m, nearer than the ground below. With a fixed 30 m margin they would be "unreachable"
    # and kept as air (confirmed ground tracks over Jacksboro), so the band widens by the sampled rise.
    from skyradar.process.ground import flag_ground

    ridge_top_down_m = 500.0 * np.sin(np.radians(35.0))

    def height_fn(points):
        points = np.asarray(points, float)
        surface = np.where(points[..., 1] > 300.0, ridge_top_down_m, 550.0)
        return surface - points[..., 2]

    args = (np.array([50.0, 0.0, 0.0]), np.eye(3), height_fn, 550.0, CFG)
    on_ridge = _ridge_frame(-35.0)
    assert flag_ground(on_ridge, on_ridge["u_ant"], *args).tolist() == [True]
    # An aircraft at the same range and Doppler, 250 m above the ridge's surface, stays air.
    above = _ridge_frame(-5.0)
    assert flag_ground(above, above["u_ant"], *args).tolist() == [False]


def _level_frame(u: np.ndarray, rng: np.ndarray, v_r: np.ndarray, snr_db: float, coherence: float) -> dict:
    """One frame's detection columns at ``rng`` along antenna-frame directions ``u`` of a radar
    whose antenna frame is NED (level, facing north, at the origin)."""
    p = rng[:, None] * u
    return {
        "range_m": rng,
        "snr_db": np.full(len(rng), snr_db),
        "azimuth_rad": np.arctan2(u[:, 1], u[:, 0]),
        "elevation_rad": np.arcsin(-u[:, 2]),
        "north_m": p[:, 0],
        "east_m": p[:, 1],
        "down_m": p[:, 2],
        "radial_velocity_mps": np.asarray(v_r, float),
        "u_ant": u,
        "coherence": np.full(len(rng), coherence),
    }


def _flat_300(points):
    """Height above flat ground 300 m below the origin, m."""
    return 300.0 - np.asarray(points, float)[..., 2]


def test_altitude_return_read_straight_up_is_ground():
    # Over flat ground 300 m below, the ground just ahead of the nadir leaks into the range bin one
    # short of the height (window sidelobes, straddle) at a few m/s of closing Doppler; the DoA of
    # that far sidelobe is the end-fire of both baselines, read straight UP. Its mirror points at
    # the ground below, where the linearised Doppler error vanishes: the encounter chain confirmed
    # such returns as tracks over flat-300, flat-1000 and Jacksboro before this rule.
    from skyradar.process.ground import flag_ground

    el, az = np.radians(88.0), np.radians(90.0)
    u = np.array([[np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)]] * 3)
    rng = np.array([286.0, 200.0, 286.0])  # altitude return; nearer than the ground; closing fast
    frame = _level_frame(u, rng, np.array([-4.4, -4.4, -30.0]), snr_db=13.0, coherence=0.9)

    flags = flag_ground(frame, u, np.array([50.0, 0.0, 0.0]), np.eye(3), _flat_300, 300.0, CFG)
    assert flags.tolist() == [True, False, False]


def test_altitude_return_read_through_the_other_residue_is_ground():
    # A time-division MIMO radar with two transmitters half a wavelength apart in height reads a
    # wrong residue as a vertical direction cosine shifted by one: the ground 10 deg ahead of the
    # nadir, 300 m below, reads a little above the boresight. Through that shift it is the ground,
    # at its range and static Doppler; a level aircraft read the same way farther out, or closing
    # faster than any ground at that range, is not, and an array without transmitter slots
    # (the prototype's) has no such reading of the ground.
    from skyradar.process.ground import flag_ground

    mimo = RadarConfig.prototype_2022(rx_positions_m="mimo-2x4")
    ring = np.radians(10.0)
    truth = np.array([np.sin(ring), 0.0, np.cos(ring)])  # forward, right, down
    read = truth + np.array([0.0, 0.0, -1.0])
    read[0] = np.sqrt(1.0 - read[2] ** 2)
    u = np.repeat(read[None], 3, axis=0)
    rng = np.array([300.0 / np.cos(ring), 1000.0, 300.0 / np.cos(ring)])
    v_ground = -50.0 * np.sin(ring)
    frame = _level_frame(u, rng, np.array([v_ground, v_ground, -25.0]), snr_db=15.0, coherence=0.95)

    args = (np.array([50.0, 0.0, 0.0]), np.eye(3), _flat_300, 300.0)
    assert flag_ground(frame, u, *args, mimo).tolist() == [True, False, False]
    assert flag_ground(frame, u, *args, CFG).tolist() == [False, False, False]


def test_unmeasured_elevation_in_the_altitude_ring_is_ground_where_its_cone_meets_the_ring():
    # Over flat ground 300 m below, flying north at 50 m/s: at 310 m the ground forms a ring
    # 14.6 deg around the nadir; the point of it behind, with a horizontal direction cosine of
    # -0.1, recedes at 50 * 0.2305 = 11.5 m/s. A detection whose elevation the nulls left
    # unmeasured (the level prior) on that cone, at that range cell and Doppler, is that ground;
    # at a Doppler no point of the ring on its cone has, or beyond the ring, it is left to its track.
    from skyradar.process.ground import flag_ground

    across = -0.1
    u = np.repeat([[np.sqrt(1.0 - across**2), across, 0.0]], 3, axis=0)
    behind = np.sqrt(1.0 - across**2 - (300.0 / 310.0) ** 2)
    rng = np.array([307.0, 307.0, 600.0])
    frame = _level_frame(u, rng, np.array([50.0 * behind, -40.0, 50.0 * behind]), snr_db=15.0, coherence=0.95)
    frame["elevation_measured"] = np.zeros(len(rng), bool)

    flags = flag_ground(frame, u, np.array([50.0, 0.0, 0.0]), np.eye(3), _flat_300, 300.0, CFG)
    assert flags.tolist() == [True, False, False]


def test_altitude_return_read_just_below_the_boresight_through_the_other_residue_is_ground():
    # The nadir itself, read through the other residue, is the boresight; DoA noise of a degree
    # puts it just below, where the residue's shift lands beyond the unit circle. Within 3 sd of
    # it the shifted direction is the nadir, and the return one range cell short of the height
    # (its leak) at a few m/s is the altitude return. An aircraft read there at 600 m is not.
    from skyradar.process.ground import flag_ground

    mimo = RadarConfig.prototype_2022(rx_positions_m="mimo-2x4")
    read = np.array([np.cos(np.radians(0.6)), 0.0, np.sin(np.radians(0.6))])
    u = np.repeat(read[None], 2, axis=0)
    rng = np.array([285.0, 600.0])
    frame = _level_frame(u, rng, np.array([-3.0, -3.0]), snr_db=12.0, coherence=0.95)

    flags = flag_ground(frame, u, np.array([50.0, 0.0, 0.0]), np.eye(3), _flat_300, 300.0, mimo)
    assert flags.tolist() == [True, False]


def test_a_runner_up_direction_is_ground_only_at_the_surface():
    # A MIMO aircraft 2 km ahead, 4.6 deg below the boresight, closing faster than the ground:
    # its runner-up residue reads the vertical cosine one lower, 67 deg up, whose end-fire mirror
    # points 67 deg down, 1.8 km under flat ground 300 m below. Read as a measurement, a position
    # below the surface is ground; read as the hypothesis it is, the ground along it is nearer
    # and explains nothing.
    from skyradar.process.ground import flag_ground

    mimo = RadarConfig.prototype_2022(rx_positions_m="mimo-2x4")
    down = np.sin(np.radians(4.6)) - 1.0
    u = np.array([[np.sqrt(1.0 - down**2), 0.0, down]])
    frame = _level_frame(u, np.array([2000.0]), np.array([-19.0]), snr_db=15.0, coherence=0.95)
    args = (u, np.array([50.0, 0.0, 0.0]), np.eye(3), _flat_300, 300.0, mimo)
    assert flag_ground(frame, *args).tolist() == [True]
    assert flag_ground(frame, *args, hypothesis=True).tolist() == [False]
