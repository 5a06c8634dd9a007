"""Physics of the image-domain simulator against closed-form geometry."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from skyradar.config import SPEED_OF_LIGHT, Mount, RadarConfig
from skyradar.geo import rotation_matrix
from skyradar.scene.synthetic_terrain import centred_grid, flat_terrain
from skyradar.scene.terrain import Terrain
from skyradar.sim.image import ImageSimulator, PlatformState, PointTarget

CFG = RadarConfig.prototype_2022()


def _unit(az: float, el: float) -> np.ndarray:
    return np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)])


def _place(
    config: RadarConfig, platform: PlatformState, r_m: float, az: float, el: float, v_r: float, v_perp: float
):
    """Target at range r_m and antenna-frame direction (az, el) with radial velocity v_r (closed form)."""
    sim = ImageSimulator(config, noise=False)
    geom = sim.geometry(platform)
    ant_to_ned = geom.rot_ned_to_ant.T
    u = ant_to_ned @ _unit(az, el)
    side = np.cross(u, [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side)
    position = geom.origin_ned_m + r_m * u
    velocity = platform.velocity_ned_mps + v_r * u + v_perp * side
    return sim, PointTarget(position, velocity, 1.0)


def _expected_bins(config: RadarConfig, r_m: float, v_r: float) -> tuple[int, int]:
    k = int(
        np.floor(
            (r_m + v_r * config.fc_hz / (config.bandwidth_hz * config.prf_hz)) / config.range_resolution_m
            + 0.5
        )
    )
    j = (int(np.floor(v_r / config.doppler_resolution_mps + 0.5)) + config.n_doppler // 2) % config.n_doppler
    return k, j


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    r_m=st.floats(100.0, 4800.0),
    az_deg=st.floats(-40.0, 40.0),
    el_deg=st.floats(-30.0, 30.0),
    v_r=st.floats(-150.0, 150.0),  # up to about 2 Nyquist widths: aliased velocities included
    yaw=st.floats(-np.pi, np.pi),
    pitch=st.floats(-0.3, 0.3),
    roll=st.floats(-0.5, 0.5),
)
def test_point_target_lands_in_closed_form_bin(r_m, az_deg, el_deg, v_r, yaw, pitch, roll):
    platform = PlatformState(
        np.array([100.0, -50.0, -800.0]), np.array([40.0, 10.0, -2.0]), np.array([yaw, pitch, roll])
    )
    sim, target = _place(CFG, platform, r_m, np.radians(az_deg), np.radians(el_deg), v_r, 17.0)
    cube = sim.frame(platform, [target])
    k, j = _expected_bins(CFG, r_m, v_r)
    # Range is checked to the half-bin; ignore targets sitting on a bin edge.
    frac = ((r_m + v_r * CFG.range_doppler_coupling_s) / CFG.range_resolution_m) % 1.0
    vfrac = (v_r / CFG.doppler_resolution_mps) % 1.0
    if min(abs(frac - 0.5), abs(vfrac - 0.5)) < 1e-3:
        return
    got = np.unravel_index(np.abs(cube[..., 0]).argmax(), cube.shape[:2])
    assert got == (k, j)


def test_power_follows_radar_equation_and_r4():
    platform = PlatformState(np.zeros(3), np.zeros(3), np.zeros(3))
    powers = []
    for r_m in (1000.0, 2000.0):
        sim, target = _place(CFG, platform, r_m, 0.0, 0.0, 0.0, 0.0)
        powers.append(np.abs(sim.frame(platform, [target])[..., 0]).max() ** 2)
    assert powers[0] / powers[1] == pytest.approx(16.0, rel=1e-3)
    gain = 10 ** (CFG.antenna.peak_db / 10)
    expected = CFG.pe_w * gain**2 * 1.0 * CFG.wavelength_m**2 / ((4 * np.pi) ** 3 * 1000.0**4)
    assert powers[0] == pytest.approx(expected, rel=1e-3)


@pytest.mark.parametrize(("az_deg", "el_deg"), [(20.0, 0.0), (0.0, -25.0), (-30.0, 15.0)])
def test_power_follows_antenna_pattern(az_deg, el_deg):
    platform = PlatformState(np.zeros(3), np.zeros(3), np.zeros(3))
    sim, on_axis = _place(CFG, platform, 1500.0, 0.0, 0.0, 0.0, 0.0)
    _, off_axis = _place(CFG, platform, 1500.0, np.radians(az_deg), np.radians(el_deg), 0.0, 0.0)
    p_on = np.abs(sim.frame(platform, [on_axis])[..., 0]).max() ** 2
    p_off = np.abs(sim.frame(platform, [off_axis])[..., 0]).max() ** 2
    expected_db = 2 * (CFG.antenna.gain_db(np.radians(az_deg), np.radians(el_deg)) - CFG.antenna.peak_db)
    assert 10 * np.log10(p_off / p_on) == pytest.approx(float(expected_db), abs=0.01)


@settings(max_examples=40, deadline=None)
@given(az_deg=st.floats(-35.0, 35.0), el_deg=st.floats(-35.0, 35.0), r_m=st.floats(500.0, 4500.0))
def test_phase_differences_match_plane_wave(az_deg, el_deg, r_m):
    platform = PlatformState(np.zeros(3), np.zeros(3), np.array([0.3, 0.1, -0.2]))
    sim, target = _place(CFG, platform, r_m, np.radians(az_deg), np.radians(el_deg), 0.0, 0.0)
    cube = sim.frame(platform, [target])
    k, j = np.unravel_index(np.abs(cube[..., 0]).argmax(), cube.shape[:2])
    measured = np.angle(cube[k, j, :] * np.conj(cube[k, j, 0]))
    u = _unit(np.radians(az_deg), np.radians(el_deg))
    expected = -2 * np.pi / CFG.wavelength_m * (CFG.rx_positions_m - CFG.rx_positions_m[0]) @ u
    error = np.angle(np.exp(1j * (measured - expected)))
    assert np.degrees(np.abs(error)).max() < 1.0


def test_noise_power_is_calibrated():
    sim = ImageSimulator(CFG, noise=True, seed=3)
    cube = sim.frame(PlatformState(np.zeros(3), np.zeros(3), np.zeros(3)), frame_index=5)
    assert np.mean(np.abs(cube) ** 2) == pytest.approx(CFG.noise_power_w, rel=0.01)
    again = sim.frame(PlatformState(np.zeros(3), np.zeros(3), np.zeros(3)), frame_index=5)
    np.testing.assert_array_equal(cube, again)  # any frame is reproducible on its own
    assert CFG.noise_power_w == pytest.approx(1.380649e-23 * 290 * CFG.prf_hz / CFG.n_doppler * 10**0.6)


def _flat(height_m: float = 0.0, size_m: float = 12000.0, spacing_m: float = 30.0) -> Terrain:
    return flat_terrain(0.0, 0.0, height_m, size_m, spacing_m)


def _ground_image(speed: float, height: float = 1000.0, **kwargs) -> np.ndarray:
    cfg = CFG.replace(mount=Mount.preset("forward"))
    sim = ImageSimulator(cfg, _flat(), origin=(0.0, 0.0, 0.0), noise=False, **kwargs)
    platform = PlatformState(np.array([0.0, 0.0, -height]), np.array([speed, 0.0, 0.0]), np.zeros(3))
    return (np.abs(sim.frame(platform)) ** 2).sum(axis=-1)


def test_flat_ground_asymptotes_match_closed_form():
    power = _ground_image(30.0)
    ground = power > 1e-6 * CFG.noise_power_w
    rows = np.nonzero(ground.any(axis=1))[0]
    cols = np.nonzero(ground.any(axis=0))[0]
    # Nearest ground is straight below (R = H); the fastest closing ground is dead ahead at the
    # last range bin, approaching the asymptote V = -speed as sqrt(1 - (H/R)^2) -> 1.
    assert abs(CFG.range_axis_m[rows.min()] - 1000.0) <= CFG.range_resolution_m
    v_far = -30.0 * np.sqrt(1 - (1000.0 / CFG.range_axis_m[-1]) ** 2)
    assert abs(CFG.doppler_axis_mps[cols.min()] - v_far) <= CFG.doppler_resolution_mps
    assert CFG.doppler_axis_mps[cols.max()] <= CFG.doppler_resolution_mps  # no ground recedes
    # Every range bin from H to RLim is filled (facets no larger than dR/2 leave no gaps).
    assert ground.any(axis=1)[rows.min() : CFG.n_range - 1].all()
    # Closed form: at range r the ground dead ahead closes at speed * sqrt(1 - (H/r)^2).
    for r_m in (1500.0, 3000.0, 4500.0):
        k = int(round(r_m / CFG.range_resolution_m))
        v_edge = CFG.doppler_axis_mps[np.nonzero(ground[k])[0].min()]
        v_expected = -30.0 * np.sqrt(1 - (1000.0 / r_m) ** 2)
        assert abs(v_edge - v_expected) <= 1.5 * CFG.doppler_resolution_mps


def test_fast_platform_ground_wraps_to_right_edge():
    power = _ground_image(60.0)
    ground = power > 1e-6 * CFG.noise_power_w
    cols = np.nonzero(ground.any(axis=0))[0]
    # Ground closing faster than VLim aliases by 2 VLim onto the right edge of the image: the
    # fastest (dead ahead at RLim) lands at -60 sqrt(1 - (H/R)^2) + 2 VLim.
    v_far = -60.0 * np.sqrt(1 - (1000.0 / CFG.range_axis_m[-1]) ** 2) + 2 * CFG.v_lim_mps
    right = cols[CFG.doppler_axis_mps[cols] > 0]
    assert right.max() == CFG.n_doppler - 1  # touches the right edge
    assert abs(CFG.doppler_axis_mps[right.min()] - v_far) <= 1.5 * CFG.doppler_resolution_mps


def test_occlusion_hides_terrain_behind_a_ridge():
    # A 1.8 km wide strip running north with a wall across it 2 km ahead: all terrain beyond
    # 3.5 km range lies behind the wall as seen from 300 m.
    spacing = 30.0
    elevation = np.zeros((401, 61))
    ridge_row = 200 - int(2000 / spacing)
    elevation[ridge_row - 2 : ridge_row + 3, :] = 900.0
    terrain = centred_grid(elevation, 0.0, 0.0, spacing, "ridge")
    cfg = CFG.replace(mount=Mount.preset("forward"))
    platform = PlatformState(np.array([0.0, 0.0, -300.0]), np.array([40.0, 0.0, 0.0]), np.zeros(3))
    hidden = ImageSimulator(cfg, terrain, (0, 0, 0), noise=False, occlusion=True).frame(platform)
    seen = ImageSimulator(cfg, terrain, (0, 0, 0), noise=False, occlusion=False).frame(platform)
    k_far = int(3500 / CFG.range_resolution_m)
    far_hidden = (np.abs(hidden[k_far:]) ** 2).sum()
    far_seen = (np.abs(seen[k_far:]) ** 2).sum()
    assert far_seen > 0
    assert far_hidden < 1e-3 * far_seen
    # In front of the wall nothing is hidden.
    k_near = int(1500 / CFG.range_resolution_m)
    np.testing.assert_allclose(np.abs(hidden[:k_near]), np.abs(seen[:k_near]), rtol=1e-5, atol=0)


def test_reflectivity_is_pluggable_and_scales_power():
    cos_img = _ground_image(30.0, reflectivity="cosine")
    const_img = _ground_image(30.0, reflectivity="constant")
    custom = _ground_image(30.0, reflectivity=lambda theta: 0.5 * np.cos(theta))
    # Power is linear in reflectivity (to float32 rounding: pixels accumulate in complex64).
    np.testing.assert_allclose(custom, 0.5 * cos_img, rtol=2e-5)
    # Straight below the incidence is 0: both models agree there; at grazing cosine is darker.
    k_near = int(round(1000.0 / CFG.range_resolution_m))
    k_far = int(round(4500.0 / CFG.range_resolution_m))
    near_ratio = cos_img[k_near].sum() / const_img[k_near].sum()
    far_ratio = cos_img[k_far].sum() / const_img[k_far].sum()
    assert near_ratio > 0.9
    assert far_ratio == pytest.approx(1000.0 / 4500.0, rel=0.05)


def test_flat_earth_option_differs_by_curvature_only():
    terrain = _flat(size_m=12000.0)
    exact = ImageSimulator(CFG, terrain, (0.0, 0.0, 0.0), noise=False)._grid_ned
    flat = ImageSimulator(CFG, terrain, (0.0, 0.0, 0.0), noise=False, flat_earth=True)._grid_ned
    corner = np.hypot(exact[0, 0, 0], exact[0, 0, 1])
    drop = corner**2 / (2 * 6_371_000.0)  # Earth curvature over the corner distance
    assert abs(exact[0, 0, 2] - flat[0, 0, 2]) == pytest.approx(drop, rel=0.05)


def test_attitude_rotates_the_antenna():
    # A 90 deg yaw makes a target due east appear at boresight.
    platform = PlatformState(np.zeros(3), np.zeros(3), np.array([np.pi / 2, 0.0, 0.0]))
    sim = ImageSimulator(CFG, noise=False)
    truth = sim.target_truth(platform, [PointTarget(np.array([0.0, 2000.0, 0.0]), np.zeros(3))])
    assert truth["azimuth_rad"][0] == pytest.approx(0.0, abs=1e-6)
    assert truth["range_m"][0] == pytest.approx(2000.0, abs=1e-3)
    assert np.allclose(rotation_matrix(np.pi / 2, 0, 0) @ [1, 0, 0], [0, 1, 0])


def test_speed_of_light_constant():
    assert CFG.range_resolution_m == pytest.approx(SPEED_OF_LIGHT / 2e7)


def test_terrain_masks_an_aircraft_behind_a_ridge():
    elevation = np.zeros((401, 61))
    ridge_row = 200 - int(2000 / 30.0)
    elevation[ridge_row - 2 : ridge_row + 3, :] = 900.0
    terrain = centred_grid(elevation, 0.0, 0.0, 30.0, "ridge")
    cfg = CFG.replace(mount=Mount.preset("forward"))
    platform = PlatformState(np.array([0.0, 0.0, -300.0]), np.array([40.0, 0.0, 0.0]), np.zeros(3))
    behind = PointTarget(np.array([3500.0, 0.0, -400.0]), np.zeros(3), 10.0)  # low, beyond the wall
    above = PointTarget(np.array([3500.0, 0.0, -2500.0]), np.zeros(3), 10.0)  # high above the wall's shadow
    in_front = PointTarget(np.array([1000.0, 0.0, -300.0]), np.zeros(3), 10.0)
    sim = ImageSimulator(cfg, terrain, (0, 0, 0), noise=False, occlusion=True)
    truth = sim.target_truth(platform, [behind, above, in_front])
    assert truth["visible"].tolist() == [False, True, True]
    alone = sim.frame(platform, [behind])
    ground = sim.frame(platform)
    np.testing.assert_array_equal(alone, ground)  # the hidden aircraft adds nothing
    unmasked = ImageSimulator(cfg, terrain, (0, 0, 0), noise=False, occlusion=False)
    assert unmasked.target_truth(platform, [behind])["visible"].tolist() == [True]
