"""One DoA error moves both height and static Doppler: the ground test fits ONE ground direction."""

import numpy as np

from skyradar.config import RadarConfig
from skyradar.process.doa import direction_from_angles
from skyradar.process.ground import flag_ground, static_radial_velocity_mps, surface_height_fn
from skyradar.process.ground_fit import surface_fit_chi2

CFG = RadarConfig.prototype_2022()
V_OWN = np.array([50.0, 0.0, 0.0])  # level, north; antenna frame = NED (boresight north)
HEIGHT_FN = surface_height_fn(1000.0, None, None)  # flat ground 1000 m below the radar at the origin


def _frame(range_m, az_deg, el_deg, v_mps, snr_db):
    u = direction_from_angles(np.radians(az_deg), np.radians(el_deg))
    r = np.asarray(range_m, float)
    ned = r[:, None] * u
    return {
        "range_m": r,
        "radial_velocity_mps": np.asarray(v_mps, float),
        "snr_db": np.asarray(snr_db, float),
        "azimuth_rad": np.radians(az_deg),
        "elevation_rad": np.radians(el_deg),
        "u_ant": u,
        "north_m": ned[:, 0],
        "east_m": ned[:, 1],
        "down_m": ned[:, 2],
        "coherence": np.ones(r.size),
    }


def test_a_weak_aircraft_below_own_ship_whose_doppler_no_ground_point_has_is_kept():
    # Measured (psf + speckle, ground scenes, flat 1000 m): a glider 180 m above the ground at
    # 1812 m, SNR 10.9 dB (DoA sd ~4 deg). Ground at that range is 33.5 deg down and at most
    # 41.7 m/s closing (aliased: >= 36.6 m/s); the glider reads 29.7 m/s. The two halves of the
    # old test (height within its large sd, Doppler within the sd of the angle) each passed.
    el_ground = -np.degrees(np.arcsin(1000.0 / 1812.0))
    u_ground = direction_from_angles(np.radians(-13.4), np.radians(el_ground))[None]
    v_ground = float(static_radial_velocity_mps(u_ground, V_OWN)[0])
    out = _frame(
        [1812.0, 1812.0, 2263.0],
        np.array([-13.4, -13.4, 13.2]),
        np.array([-26.8, el_ground, -21.7]),
        [29.74, v_ground, 27.14],
        [10.9, 10.9, 8.7],
    )
    u_ned = out["u_ant"]
    flags = flag_ground(out, u_ned, V_OWN, np.eye(3), HEIGHT_FN, 1000.0, CFG)
    assert flags.tolist() == [False, True, False]


def test_a_pixel_of_ground_left_and_right_reads_an_azimuth_between_them_and_fits():
    # Ground at +-25 deg azimuth, same range and Doppler: the mixture's azimuth is in between. A
    # receding 10 m/s (aliased -68 m/s) is no ground's in front at any azimuth.
    rng = 2500.0
    el = -np.arcsin(1000.0 / rng)
    u = direction_from_angles(np.radians(25.0), el)[None]
    v = static_radial_velocity_mps(u, V_OWN)
    mixed = direction_from_angles(np.radians(5.0), el)[None]
    chi2 = surface_fit_chi2(
        mixed, np.array([rng]), v, 0.02, 0.02, np.zeros(3), np.eye(3), HEIGHT_FN, V_OWN, CFG
    )
    off = surface_fit_chi2(
        mixed, np.array([rng]), np.array([10.0]), 0.02, 0.02, np.zeros(3), np.eye(3), HEIGHT_FN, V_OWN, CFG
    )
    assert chi2[0] < 1.0 and off[0] > 100.0
