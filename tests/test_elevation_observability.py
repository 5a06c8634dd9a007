"""The elevation of a detection after clutter suppression: measured when its Cramer-Rao bound through
the cell's projector or whitening allows, a co-altitude prior otherwise, and a track with no measured
elevation flies at that prior and says so."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyradar.config import RadarConfig
from skyradar.process.clutter_doa import (
    MAX_ELEVATION_SIGMA_RAD,
    angle_sigmas_rad,
    elevation_sigma_rad,
    projected_directions,
)
from skyradar.process.doa import direction_from_angles, doa_crlb, steering_vector
from skyradar.track.track_table import track_detections

# The properties run on hypothesis' fixed sequence of examples, the same on every run and machine: a
# boresight target (azimuth and elevation 0) and a ground null mirrored exactly below the target are
# degenerate geometries these properties do not hold at, and a random run would meet them by chance.
CFG = RadarConfig.prototype_2022()
N0 = CFG.noise_power_w


def _off(steering: np.ndarray) -> np.ndarray:
    """Projector (1, n_rx, n_rx) off the span of the steering vectors ``steering`` (k, n_rx): the nulls."""
    e, _ = np.linalg.qr(steering.T)
    return (np.eye(steering.shape[1]) - e @ e.conj().T)[None]


@settings(max_examples=40, deadline=None, derandomize=True)
@given(
    st.floats(-1.0, 1.0),
    st.floats(-0.7, 0.7),
    st.floats(5.0, 40.0),
)
def test_without_nulls_the_bound_is_the_arrays_crlb(az, el, snr_db):
    # Peer: doa_crlb, the closed-form bound of the 2x2 array in white noise.
    u = direction_from_angles(np.array([az]), np.array([el]))
    z = np.sqrt(10 ** (snr_db / 10) * N0) * steering_vector(u, CFG)
    got = elevation_sigma_rad(u, z, np.eye(4)[None], CFG, N0)[0]
    assert np.isclose(got, doa_crlb(snr_db, az, el, CFG)[1], rtol=1e-6)
    # ... and so is the azimuth's, for each layout (doa_crlb takes the layout from the config).
    for layout in ("square", "kite"):
        cfg = RadarConfig.prototype_2022(rx_positions_m=layout)
        z = np.sqrt(10 ** (snr_db / 10) * N0) * steering_vector(u, cfg)
        sd_el, sd_az = angle_sigmas_rad(u, z, np.eye(4)[None], cfg, N0)
        want_az, want_el = doa_crlb(snr_db, az, el, cfg)
        assert np.isclose(sd_az[0], want_az, rtol=1e-6) and np.isclose(sd_el[0], want_el, rtol=1e-6)


def _ring_whitening(cnr_db: float, el_c: float = -0.6, az_c: float = 1.2) -> np.ndarray:
    """``N0 R^-1`` of noise plus clutter from two directions left and right at one elevation."""
    s = steering_vector(direction_from_angles(np.array([az_c, -az_c]), np.full(2, el_c)), CFG)
    r = np.eye(4) + 10 ** (cnr_db / 10) * (s.T @ s.conj()) / 2
    return np.linalg.inv(r)


def test_two_nulls_at_one_elevation_leave_no_elevation_and_finite_clutter_some():
    u = direction_from_angles(np.array([-0.5]), np.array([0.45]))
    z = np.sqrt(10**2.7 * N0) * steering_vector(u, CFG)  # 27 dB, as the hills intruder
    s_c = steering_vector(direction_from_angles(np.array([1.2, -1.2]), np.full(2, -0.6)), CFG)
    nulled = elevation_sigma_rad(u, z, _off(s_c), CFG, N0)[0]
    assert np.isinf(nulled)
    bounds = [elevation_sigma_rad(u, z, _ring_whitening(c)[None], CFG, N0)[0] for c in (0, 10, 20, 30, 40)]
    assert np.all(np.isfinite(bounds)) and np.all(np.diff(bounds) > 0)  # the more clutter, the less elevation
    assert bounds[2] < MAX_ELEVATION_SIGMA_RAD < bounds[4]


@settings(max_examples=60, deadline=None, derandomize=True)
@given(
    st.floats(-0.95, 0.95),
    st.floats(-0.25, 0.25),
    st.floats(-1.2, -0.3),
    st.floats(0.3, 1.2),
)
def test_with_no_elevation_the_azimuth_keeps_the_measured_cone(az, el, el_null, az_null):
    # Two nulls at one elevation leave the score a function of the horizontal direction cosine only:
    # the prior's azimuth is the point of that cone at elevation 0 (closed form), wherever on the cone
    # the 2-D search's best point falls (up to 28 deg high on a track over flat ground 1000 m below).
    u = direction_from_angles(np.array([az]), np.array([el]))
    z = np.sqrt(10**2.0 * N0) * steering_vector(u, CFG)
    s_c = steering_vector(direction_from_angles(np.array([az_null, -az_null]), np.full(2, el_null)), CFG)
    got, measured = projected_directions(z, _off(s_c), CFG, N0)
    on_cone = np.degrees(np.arcsin(np.cos(el) * np.sin(az)))
    assert not measured[0] and got[0, 2] == 0.0
    assert abs(np.degrees(np.arctan2(got[0, 1], got[0, 0])) - on_cone) < 0.1


def test_a_direction_whitened_by_moderate_clutter_is_measured_near_the_truth():
    rng = np.random.default_rng(3)
    w = _ring_whitening(20.0)
    u_true = direction_from_angles(np.array([-0.5]), np.array([0.45]))
    s_c = steering_vector(direction_from_angles(np.array([1.2, -1.2]), np.full(2, -0.6)), CFG)
    errors, bounds = [], []
    for _ in range(200):
        clutter = (rng.standard_normal(2) + 1j * rng.standard_normal(2)) * np.sqrt(10**2.0 / 4) @ s_c
        noise = (rng.standard_normal(4) + 1j * rng.standard_normal(4)) * np.sqrt(0.5)
        z = (np.sqrt(10**2.7) * steering_vector(u_true, CFG)[0] + clutter + noise) * np.sqrt(N0)
        u, measured = projected_directions(z[None], w[None], CFG, N0)
        bounds.append(np.degrees(elevation_sigma_rad(u, z[None], w[None], CFG, N0)[0]))
        if measured[0]:
            errors.append(np.degrees(np.arcsin(-u[0, 2]) - 0.45))
    # Unbiased, and as spread as its bound says (5.6 deg here: the AMF is efficient at 27 dB).
    assert len(errors) >= 190 and abs(np.median(errors)) < 1.5
    assert 0.7 < np.std(errors) / np.median(bounds) < 1.4


def _doppler_extended_crb(n_bins: int, cnr_db: float) -> float:
    """Elevation bound of a target off the clutter ridge with 1, 3 or 5 adjacent Doppler bins of
    space-time training (Hann-windowed 250-chirp filters; clutter continuous in Doppler, two azimuth
    branches at one depression), independent of the package: numpy only."""
    n, w = 250, np.hanning(250)
    k0, v, el_c = 12, 0.2, np.radians(-39.0)

    def filt(f, k):
        return np.sum(w * np.exp(2j * np.pi * (f - k / n) * np.arange(n))) / w.sum()

    def steer(az, el):
        a = [1, np.exp(1j * np.pi * np.sin(az) * np.cos(el))]
        return np.kron(a, [1, np.exp(1j * np.pi * np.sin(el))])

    bins = range(-(n_bins // 2), n_bins // 2 + 1)

    def st_vec(f, az, el):
        return np.concatenate([filt(f, k0 + d) * steer(az, el) for d in bins])

    r = np.zeros((4 * n_bins,) * 2, complex)
    for f in np.linspace((k0 - 4) / n, (k0 + 4) / n, 200):
        for az in (np.arccos(f / (v * np.cos(el_c))), -np.arccos(f / (v * np.cos(el_c)))):
            s = st_vec(f, az, el_c)
            r += np.outer(s, s.conj())
    r = np.eye(r.shape[0]) + 10 ** (cnr_db / 10) * n_bins * r / np.trace(r).real * 4
    ri, az_t, el_t, h = np.linalg.inv(r), np.radians(-29.0), np.radians(26.0), 1e-6
    s = st_vec(k0 / n, az_t, el_t)
    d = np.stack(
        [
            (st_vec(k0 / n, az_t, el_t + h) - st_vec(k0 / n, az_t, el_t - h)) / (2 * h),
            (st_vec(k0 / n, az_t + h, el_t) - st_vec(k0 / n, az_t - h, el_t)) / (2 * h),
        ],
        1,
    )
    rs = ri @ s
    j = np.real(d.conj().T @ ri @ d - np.outer(d.conj().T @ rs, rs.conj() @ d) / (s.conj() @ rs).real)
    return float(np.sqrt(np.linalg.inv(2 * 10**2.7 * j)[0, 0]))


def test_training_over_neighbouring_doppler_bins_does_not_restore_the_elevation():
    # The claim of clutter_doa's module docstring: clutter is continuous in Doppler, so more bins
    # bring more clutter dimensions with them; the bound drops by 7-12 %, and grows with the clutter
    # as fast as one bin's.
    for cnr_db in (20.0, 40.0):
        one = _doppler_extended_crb(1, cnr_db)
        assert all(0.8 < _doppler_extended_crb(b, cnr_db) / one <= 1.0 for b in (3, 5))
    assert _doppler_extended_crb(5, 40.0) > 8 * _doppler_extended_crb(5, 20.0)


def _level_track(measured: np.ndarray, height_m: float) -> pd.DataFrame:
    """Detections of an aircraft closing head-on ``height_m`` above a level own-ship at the origin;
    rows not ``measured`` carry the co-altitude prior (elevation 0), as process.clutter_doa places them."""
    t = np.arange(measured.size) / 9.4
    north = 1500.0 - 60.0 * t
    slant = np.hypot(north, height_m)
    el = np.where(measured, np.arctan2(height_m, north), 0.0)
    return pd.DataFrame(
        {
            "time_s": t,
            "range_m": slant,
            "radial_velocity_mps": -60.0 * north / slant,
            "snr_db": 25.0,
            "azimuth_rad": 0.0,
            "elevation_rad": el,
            "north_m": slant * np.cos(el),
            "east_m": 0.0,
            "down_m": -slant * np.sin(el),
            "elevation_measured": measured,
        }
    )


def _own(n: int) -> pd.DataFrame:
    t = np.arange(n) / 9.4
    return pd.DataFrame(
        {
            "time_s": t,
            "own_north_m": 0.0,
            "own_east_m": 0.0,
            "own_down_m": 0.0,
            "own_vn_mps": 0.0,
            "own_ve_mps": 0.0,
            "own_vd_mps": 0.0,
        }
    )


def test_a_track_with_no_measured_elevation_stays_at_the_co_altitude_prior():
    tracks = track_detections(_level_track(np.zeros(150, bool), 300.0), ownship=_own(150), ground_test=False)
    last = tracks[tracks.confirmed].groupby("track_id").tail(1)
    assert len(last) == 1 and abs(last["down_m"].iloc[0]) < 30.0 and not last["altitude_measured"].iloc[0]


def test_a_plain_doa_that_follows_the_predicted_clutter_has_no_elevation():
    # Ground 15 dB over the intruder in its cell: the snapshot is one plane wave, the ground's, and the
    # plain DoA points at it. Through the cell's nulls that direction carries (almost) nothing.
    u_ground = direction_from_angles(np.array([0.3]), np.array([-0.35]))
    u_target = direction_from_angles(np.array([-0.3]), np.array([0.1]))
    s_g, s_t = steering_vector(u_ground, CFG), steering_vector(u_target, CFG)
    z = np.sqrt(10**4.0 * N0) * s_g + np.sqrt(10**2.5 * N0) * s_t
    proj = _off(s_g)  # one null, at the predicted ground direction
    assert elevation_sigma_rad(u_ground, z, proj, CFG, N0)[0] > MAX_ELEVATION_SIGMA_RAD
    assert elevation_sigma_rad(u_target, z, proj, CFG, N0)[0] < np.radians(3.0)  # the intruder's is kept


def _in_plane(rx: np.ndarray, angle_rad: float) -> np.ndarray:
    """Receive positions rotated by ``angle_rad`` about the boresight (in the antenna's y-z plane)."""
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    out = rx.copy()
    out[:, 1], out[:, 2] = c * rx[:, 1] - s * rx[:, 2], s * rx[:, 1] + c * rx[:, 2]
    return out


@settings(max_examples=40, deadline=None, derandomize=True)
@given(
    st.floats(0.0, np.pi / 2),
    st.floats(-0.6, 0.6),
    st.floats(0.1, 0.7),
    st.floats(-0.9, -0.2),
    st.floats(0.3, 1.2),
)
def test_no_rotation_of_the_square_array_keeps_an_elevation_through_two_ground_nulls(
    roll, az, el, el_ground, az_ground
):
    # Mounting the 2x2 turned about its boresight (a diamond) does not help: the array is centro-
    # symmetric, so after two nulls the target's projected snapshot carries one real angle, not two
    # (the Fisher information of azimuth and elevation has rank 1 for every rotation). One null leaves both.
    cfg = RadarConfig.prototype_2022(rx_positions_m=_in_plane(CFG.rx_positions_m, roll))
    u = direction_from_angles(np.array([az]), np.array([el]))
    z = np.sqrt(10**2.7 * N0) * steering_vector(u, cfg)
    ground = steering_vector(
        direction_from_angles(np.array([az_ground, -az_ground]), np.full(2, el_ground)), cfg
    )
    assert np.isinf(elevation_sigma_rad(u, z, _off(ground), cfg, N0)[0])
    one = ground[:1].T / np.linalg.norm(ground[0])
    assert np.isfinite(elevation_sigma_rad(u, z, (np.eye(4) - one @ one.conj().T)[None], cfg, N0)[0])


def test_an_array_without_centre_symmetry_keeps_its_elevation_through_two_nulls():
    # Four channels are not the limit, the symmetry is: the kite layout (the lower pair moved onto
    # the vertical axis) keeps its elevation through the same two nulls (0.44 deg against 0.40 deg
    # without nulls at 27 dB here).
    cfg = RadarConfig.prototype_2022(rx_positions_m="kite")
    u = direction_from_angles(np.array([0.17]), np.array([0.52]))
    z = np.sqrt(10**2.7 * N0) * steering_vector(u, cfg)
    ground = steering_vector(direction_from_angles(np.array([1.05, -1.05]), np.full(2, -0.35)), cfg)
    nulled = elevation_sigma_rad(u, z, _off(ground), cfg, N0)[0]
    free = elevation_sigma_rad(u, z, np.eye(4)[None], cfg, N0)[0]
    assert free < nulled < 1.5 * free


@pytest.mark.parametrize(
    "az, el, az_ground, el_ground",
    [(0.17, 0.52, 1.05, -0.35), (-0.084, 0.058, 0.9, -0.21), (0.3, -0.1, 0.5, -0.3), (-0.2, 0.0, 0.2, -0.25)],
)
def test_the_kite_pays_for_its_elevation_with_its_azimuth(az, el, az_ground, el_ground):
    # Two nulls at one elevation, left and right: the square keeps its azimuth (the y pairs survive
    # the elevation null) and loses the elevation; the kite, mirror-symmetric about its vertical
    # axis, keeps the elevation and loses most of the azimuth: its only horizontal baseline is the
    # upper pair, and the antisymmetric combination of the two nulls lies on that pair alone.
    sigmas = {}
    for layout in ("square", "kite"):
        cfg = RadarConfig.prototype_2022(rx_positions_m=layout)
        u = direction_from_angles(np.array([az]), np.array([el]))
        z = np.sqrt(10**2.7 * N0) * steering_vector(u, cfg)
        ground = steering_vector(
            direction_from_angles(np.array([az_ground, -az_ground]), np.full(2, el_ground)), cfg
        )
        nulled = angle_sigmas_rad(u, z, _off(ground), cfg, N0)
        free = angle_sigmas_rad(u, z, np.eye(4)[None], cfg, N0)
        sigmas[layout] = [float(s[0]) for s in (*nulled, *free)]
    (sq_el, sq_az, _, sq_az_free), (k_el, k_az, _, k_az_free) = sigmas["square"], sigmas["kite"]
    assert np.isinf(sq_el) and sq_az < 4.0 * sq_az_free  # the square: azimuth kept, elevation gone
    assert k_el <= MAX_ELEVATION_SIGMA_RAD and k_az > 5.0 * sq_az and k_az > 5.0 * k_az_free
