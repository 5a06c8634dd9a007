"""Fast closures aliased into the ground's Doppler band: judged objects on their range history.

Own-ship at 50 m/s; closing speeds of about 78-117 m/s alias (image width 78.3 m/s) into the band
of radial velocities the ground ahead fills. A static point's range rate never exceeds the
own-ship's speed, so the range history of such a closure, falling a whole image width per second
faster than the ground of its Doppler, tells it from ground within a few detections, whatever its
direction of arrival says (over relief, after clutter suppression, often nothing).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from skyradar.config import RadarConfig
from skyradar.track.ground_tracks import (
    GroundTrackTest,
    faster_than_ground,
    flat_surface,
    hold_ground_tracks,
    range_doppler_consistent,
    static_point_measurements,
)

CFG = RadarConfig.prototype_2022()
WIDTH = 2.0 * CFG.v_lim_mps
C = CFG.range_doppler_coupling_s
FRAME_S = 1.0 / 9.4
AGL_M = 600.0


def _own(t: np.ndarray, bank_deg: float = 0.0, speed_mps: float = 50.0) -> pd.DataFrame:
    """Own-ship level at the origin's height, 600 m above a level ground, straight north or in a
    coordinated turn at ``bank_deg``."""
    rate = 9.80665 * np.tan(np.radians(bank_deg)) / speed_mps
    heading = rate * t
    if rate == 0.0:
        north, east = speed_mps * t, 0.0 * t
    else:
        north, east = speed_mps / rate * np.sin(heading), speed_mps / rate * (1.0 - np.cos(heading))
    return pd.DataFrame(
        {
            "time_s": t,
            "own_north_m": north,
            "own_east_m": east,
            "own_down_m": 0.0 * t,
            "own_vn_mps": speed_mps * np.cos(heading),
            "own_ve_mps": speed_mps * np.sin(heading),
            "own_vd_mps": 0.0 * t,
            "own_height_agl_m": AGL_M + 0.0 * t,
        }
    )


def _state(own: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    return (
        own[["own_north_m", "own_east_m", "own_down_m"]].to_numpy(),
        own[["own_vn_mps", "own_ve_mps", "own_vd_mps"]].to_numpy(),
    )


def _closure_detections(
    closing_mps: float, miss_m: float, rng: np.random.Generator, n: int, width_mps: float = WIDTH
) -> tuple:
    """Detections of a co-altitude intruder closing head-on at ``closing_mps`` with a lateral miss,
    range noise 2.5 m (13-20 dB), Doppler noise 0.05 m/s, aliased into an image ``width_mps`` wide;
    its direction of arrival unmeasured (elevation 0, the chain's co-altitude prior)."""
    t = np.arange(n) * FRAME_S
    own = _own(t)
    own_p, _ = _state(own)
    intruder = np.column_stack([1800.0 - (closing_mps - 50.0) * t, miss_m + 0 * t, 0 * t])
    d = intruder - own_p
    r = np.linalg.norm(d, axis=1)
    v = np.sum(d * ([-(closing_mps - 50.0), 0, 0] - np.array([50.0, 0, 0])), axis=1) / r
    measured_v = v + rng.normal(0.0, 0.05, n)
    det = pd.DataFrame(
        {
            "time_s": t,
            "range_m": r + C * v + rng.normal(0.0, 2.5, n),
            "radial_velocity_mps": (measured_v + width_mps / 2) % width_mps - width_mps / 2,
            "azimuth_rad": rng.choice([-0.9, 0.9], n),
            "elevation_rad": 0.0 * t,
            "elevation_measured": False,
            "north_m": intruder[:, 0],
            "east_m": intruder[:, 1],
            "down_m": 0 * t,
        }
    )
    return det, own


@pytest.mark.parametrize("closing_mps", [80.0, 95.0, 106.7, 117.0])
def test_an_aliased_closure_clears_the_ground_hold_within_five_detections(closing_mps):
    # Its aliased Doppler lies inside the ground's band (|V| < own speed) and no elevation is measured:
    # the direction test alone would hold it for ten detections, a static fit for longer.
    rng = np.random.default_rng(int(closing_mps))
    for trial in range(10):
        det, own = _closure_detections(closing_mps, 70.0 + 30.0 * trial, rng, 12)
        aliased = det["radial_velocity_mps"].to_numpy()
        assert (np.abs(aliased) < 50.0).all()  # inside the ground band
        tracks = pd.DataFrame(
            {"time_s": det["time_s"], "track_id": 1, "detection_row": np.arange(12), "confirmed": True}
        )
        out = hold_ground_tracks(tracks, det, own, WIDTH, C, flat_surface(AGL_M))
        confirmed = out["confirmed"].to_numpy() if len(out) else np.zeros(0, bool)
        assert confirmed.any(), trial
        assert int(np.argmax(confirmed)) <= 4, trial  # the fifth detection, index 4
        assert confirmed[4:].all(), trial


def test_a_patch_whose_doppler_hops_in_every_detection_stays_held():
    # Residual clutter whose two scatterers take turns: its Doppler hops by a bin at every detection,
    # though its ranges walk as fast as a closure's. Leaving one detection out does not smooth it.
    rng = np.random.default_rng(7)
    det, own = _closure_detections(106.7, 120.0, rng, 12)
    det["radial_velocity_mps"] += 0.65 * (-1.0) ** np.arange(12)  # two scatterers a bin apart, in turn
    tracks = pd.DataFrame(
        {"time_s": det["time_s"], "track_id": 1, "detection_row": np.arange(12), "confirmed": True}
    )
    out = hold_ground_tracks(tracks, det, own, WIDTH, C, flat_surface(AGL_M))
    assert not out["confirmed"].to_numpy().any()


@pytest.mark.parametrize("bank_deg", [0.0, 30.0, 45.0])
def test_static_ground_is_never_judged_faster_than_ground(bank_deg):
    # Ground points all around (ranges 0.7-4 km) from a straight or banked own-ship, with range
    # jitter at the test's stated error and Doppler noise: none may pass for a fast object.
    rng = np.random.default_rng(int(bank_deg))
    t = np.arange(10) * FRAME_S
    own = _own(t, bank_deg)
    own_p, own_v = _state(own)
    speed = np.linalg.norm(own_v, axis=1)
    released = 0
    for _ in range(600):
        ground_range = rng.uniform(300.0, 4000.0)
        azimuth = rng.uniform(-np.pi, np.pi)
        point = np.array([ground_range * np.cos(azimuth), ground_range * np.sin(azimuth), AGL_M])
        rho, v = static_point_measurements(point, own_p, own_v, C)
        n = rng.integers(5, 11)
        rho = rho[:n] + rng.normal(0.0, GroundTrackTest().sigma_range_jitter_m, n)
        v = (v[:n] + rng.normal(0.0, 0.1, n) + WIDTH / 2) % WIDTH - WIDTH / 2
        released += faster_than_ground(t[:n], rho, v, speed[:n], WIDTH, C)
    assert released <= 2  # the test's tail is 1e-3 per judgement


def test_clutter_hopping_between_range_cells_is_not_judged_fast():
    # The scatterers of a clutter patch taking turns: ranges hop by a bin (15 m) and more between
    # frames. A steep line through them is rejected by the range fit about the alias.
    rng = np.random.default_rng(5)
    t = np.arange(8) * FRAME_S
    speed = np.full(t.size, 50.0)
    judged_fast = 0
    for _ in range(300):
        hops = rng.choice([-30.0, -15.0, 0.0, 15.0, 30.0], t.size)
        ranges = 1500.0 - 90.0 * t + hops
        doppler = np.full(t.size, -11.7) + rng.normal(0.0, 0.1, t.size)
        judged_fast += faster_than_ground(t, ranges, doppler, speed, WIDTH, C)
    assert judged_fast <= 15  # hops that happen to lie near a line: rare


def test_a_closure_inside_the_ground_band_is_left_to_the_other_tests():
    # A closure at 40 m/s (slower than the own-ship) has a radial velocity some static point has:
    # the range rate cannot tell it from ground.
    t = np.arange(10) * FRAME_S
    ranges = 1500.0 - 40.0 * t
    assert not faster_than_ground(t, ranges, np.full(10, -40.0), np.full(10, 50.0), WIDTH, C)
    # Too few detections to tell the aliases apart.
    assert not faster_than_ground(t[:2], ranges[:2], np.full(2, -28.4), np.full(2, 50.0), WIDTH, C)


def test_a_closure_lost_for_seconds_keeps_its_identity_and_its_warning():
    # A head-on intruder closing at 100 m/s fades for 2.5 s (a clutter ridge, a Swerling fade) 8.5 s
    # before the loss of well clear. Through the fade the track's prediction holds its warning on
    # every frame; the reacquired track keeps its id, so the alert filter keeps its state, and its 3-D
    # filter keeps the velocity it had: the first measured rows after the fade predict the warning
    # again (raw level), not a fresh track's unconverged velocity that the gate silences.
    from skyradar.daa.alerting import RADAR_ALERT_CONFIG
    from skyradar.daa.conflict import WellClearVolume
    from skyradar.daa.pipeline import alerts_from_tracks
    from skyradar.track.track_table import track_detections

    rng = np.random.default_rng(3)
    t = np.arange(0.0, 16.0, FRAME_S)
    own = _own(t).assign(own_yaw_rad=0.0)
    lowc_s = 14.0
    start_m = WellClearVolume.do365_noncoop().dthr_m + 100.0 * lowc_s
    intruder = np.column_stack([start_m - 50.0 * t, 60.0 + 0 * t, 0 * t])
    own_p, own_v = _state(own)
    d = intruder - own_p
    r = np.linalg.norm(d, axis=1)
    v = np.sum(d * ([-50.0, 0, 0] - own_v), axis=1) / r
    seen = ~((t > 5.5) & (t < 8.0))
    measured_v = v + rng.normal(0, 0.05, t.size)
    det = pd.DataFrame(
        {
            "time_s": t,
            "range_m": r + C * v + rng.normal(0.0, 2.5, t.size),
            "radial_velocity_mps": (measured_v + WIDTH / 2) % WIDTH - WIDTH / 2,
            "north_m": intruder[:, 0] + rng.normal(0, 15.0, t.size),
            "east_m": intruder[:, 1] + rng.normal(0, 15.0, t.size),
            "down_m": intruder[:, 2] + rng.normal(0, 5.0, t.size),
            "snr_db": 18.0 + 0 * t,
        }
    )[seen].reset_index(drop=True)
    tracks = track_detections(det, ownship=own, ground_test=GroundTrackTest(surface_down=flat_surface(AGL_M)))
    confirmed = tracks[tracks["confirmed"]]
    assert confirmed["track_id"].nunique() == 1
    alerts = alerts_from_tracks(tracks, own, RADAR_ALERT_CONFIG, with_advice=False)
    before = alerts[alerts["time_s"] < 5.5]
    measured = alerts[(alerts["time_s"] >= 8.0) & ~alerts["extrapolated"]]
    assert (before["level"] == 3).any()
    assert (alerts.loc[alerts["time_s"] >= before["time_s"].max(), "level"] == 3).all()  # through the fade
    assert alerts.loc[alerts["extrapolated"], "time_s"].between(5.5, 9.0).all()  # until reconfirmed
    assert (measured["raw_level"].iloc[:5] == 3).all()


PATCH_TEST = GroundTrackTest(patch_directions=True)  # an array whose directions can tell a patch


def _confirmed(
    det: pd.DataFrame, own: pd.DataFrame, test: GroundTrackTest = PATCH_TEST, width_mps: float = WIDTH
) -> np.ndarray:
    tracks = pd.DataFrame(
        {"time_s": det["time_s"], "track_id": 1, "detection_row": np.arange(len(det)), "confirmed": True}
    )
    out = hold_ground_tracks(tracks, det, own, width_mps, C, flat_surface(AGL_M), test=test)
    return out["confirmed"].to_numpy(bool) if len(out) else np.zeros(len(det), bool)


def _read_on_the_surface(det: pd.DataFrame, own: pd.DataFrame, azimuth_rad: np.ndarray) -> pd.DataFrame:
    """``det`` read at the ground's depression at its range, from ``azimuth_rad``: its elevations
    measured and its DoA points on the surface."""
    own_p, _ = _state(own)
    r = det["range_m"].to_numpy()
    depression = np.arcsin(AGL_M / r)
    ground_range = r * np.cos(depression)
    return det.assign(
        azimuth_rad=azimuth_rad,
        elevation_rad=-depression,
        elevation_measured=True,
        north_m=own_p[:, 0] + ground_range * np.cos(azimuth_rad),
        east_m=own_p[:, 1] + ground_range * np.sin(azimuth_rad),
        down_m=AGL_M,
    )


def _taking_turns(rng: np.random.Generator, n: int) -> np.ndarray:
    """Azimuths (rad) of four scatterers of a patch, left and right of the track, taking turns in
    a random order within every four detections."""
    scatterers = np.radians([-48.0, -30.0, 40.0, 64.0])
    return np.concatenate([rng.permutation(scatterers) for _ in range(-(-n // 4))])[:n]


def test_a_ground_patch_strung_along_a_closing_alias_is_not_released_by_its_range_rate():
    # A ground patch fills one Doppler bin over many ranges; the tracker can string its scatterers,
    # left and right of the own-ship's track, along a line as steep as a closure's. The line alone
    # passes the range-rate test, but the directions read the surface and scatter across the beam:
    # the patch is held, and stays held once its history outgrows the first ten detections and no
    # single static point fits the line.
    rng = np.random.default_rng(11)
    for trial in range(10):
        det, own = _closure_detections(106.7, 90.0 + 20.0 * trial, rng, 40)
        patch = _read_on_the_surface(det, own, _taking_turns(rng, len(det)))
        assert not _confirmed(patch, own).any(), trial


def test_an_aircraft_read_on_the_surface_from_one_azimuth_is_not_held_as_a_patch():
    # Inside the ground's band (a 30 m/s converging closure, no early release), read at the ground's
    # elevation by its cell's mixture but from one azimuth: the patch rule does not hold it.
    rng = np.random.default_rng(15)
    det, own = _closure_detections(80.0, 400.0, rng, 40)
    one_azimuth = np.radians(-25.0) + rng.normal(0.0, 0.01, len(det))
    on_surface = _read_on_the_surface(det, own, one_azimuth)
    assert _confirmed(on_surface, own).any()


def test_the_squares_directions_do_not_hold_back_a_closure_that_reads_like_a_patch():
    # The 2x2 square keeps two channels after its two nulls: an aircraft in a ground cell over relief
    # can read the surface and scatter in azimuth at once, so its default test releases on the range
    # rate alone, at the fifth detection.
    from skyradar.track.ground_tracks import default_ground_test

    square = default_ground_test(RadarConfig.prototype_2022(), flat_surface(AGL_M))
    rng = np.random.default_rng(14)
    det, own = _closure_detections(106.7, 120.0, rng, 12)
    scattered = _taking_turns(rng, len(det))
    confirmed = _confirmed(_read_on_the_surface(det, own, scattered), own, square)
    assert confirmed.any() and int(np.argmax(confirmed)) <= 4


def test_an_aliased_closure_read_at_the_grounds_elevation_from_one_azimuth_is_released():
    # An aircraft whose cell's mixture pulls its measured elevation onto the surface keeps one
    # azimuth: the range-rate release stands, at its fifth detection.
    rng = np.random.default_rng(12)
    for trial in range(10):
        det, own = _closure_detections(106.7, 90.0 + 20.0 * trial, rng, 12)
        one_azimuth = np.radians(25.0) + rng.normal(0.0, 0.01, len(det))
        confirmed = _confirmed(_read_on_the_surface(det, own, one_azimuth), own)
        assert confirmed.any() and int(np.argmax(confirmed)) <= 4, trial


def test_a_history_receding_faster_than_the_ground_waits_for_the_slower_tests():
    # Receding at 107 m/s (its Doppler aliased to +28.4 m/s) is faster than any static point, but it
    # is no closure: the early release is not for it, and its unmeasured direction holds it for ten.
    rng = np.random.default_rng(13)
    det, own = _closure_detections(106.7, 120.0, rng, 12)
    t = det["time_s"].to_numpy()
    det = det.assign(
        range_m=1800.0 + 106.7 * t + rng.normal(0.0, 2.5, t.size),
        radial_velocity_mps=(106.7 + rng.normal(0.0, 0.05, t.size) + WIDTH / 2) % WIDTH - WIDTH / 2,
    )
    speed = np.full(t.size, 50.0)
    args = (t[:5], det["range_m"].to_numpy()[:5], det["radial_velocity_mps"].to_numpy()[:5], speed[:5])
    assert faster_than_ground(*args, WIDTH, C)
    assert not faster_than_ground(*args, WIDTH, C, closing=True)
    assert not _confirmed(det, own)[:9].any()


def test_a_150_mps_closure_through_a_mimo_image_is_an_object_faster_than_the_ground():
    # Two transmitters halve the image (39.15 m/s at the prototype's PRF): a 150 m/s head-on closure
    # is four widths from its measured Doppler, beyond the two aliases that cover +-195 m/s in the
    # prototype's image. The ground tests' alias bound follows the image, so the range history still
    # says "one object, faster than any static point" by its fifth detection.
    mimo = RadarConfig.prototype_2022(rx_positions_m="mimo-2x4")
    width = 2.0 * mimo.v_lim_mps
    assert mimo.range_doppler_coupling_s == C
    rng = np.random.default_rng(16)
    det, own = _closure_detections(150.0, 120.0, rng, 12, width)
    t, r, v = (det[c].to_numpy() for c in ("time_s", "range_m", "radial_velocity_mps"))
    assert np.abs(v).max() <= width / 2.0
    assert range_doppler_consistent(t[:10], r[:10], v[:10], width, C)
    assert not range_doppler_consistent(t[:10], r[:10], v[:10], width, C, max_alias=2)
    assert faster_than_ground(t[:5], r[:5], v[:5], np.full(5, 50.0), width, C, closing=True)
    confirmed = _confirmed(det, own, GroundTrackTest(), width)
    assert confirmed.any() and int(np.argmax(confirmed)) <= 4
