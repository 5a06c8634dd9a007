"""Knowledge-aided clutter suppression: prediction, calibration, detection, bad input."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from cli_helpers import assert_one_line_error, skyradar
from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.io.frames import frames_dataset
from skyradar.process.cfar import cfar_2d_floor
from skyradar.process.clutter_frames import frame_subspace
from skyradar.process.clutter_suppress import null_count, projected_power, suppress_clutter
from skyradar.process.ground import in_ground_band
from skyradar.process.pipeline import navigated_own_state, process_frames
from skyradar.process.power import power_image
from skyradar.scene.synthetic_terrain import flat_terrain
from skyradar.sim.image import ImageSimulator, PlatformState, PointTarget

CFG = RadarConfig.prototype_2022()
HEIGHT_M, SPEED_MPS = 1000.0, 50.0
OWN = PlatformState(np.array([0.0, 0.0, -HEIGHT_M]), np.array([SPEED_MPS, 0.0, 0.0]), np.zeros(3))
# Head-on at 2000 m closing at 100 m/s: -100 m/s aliases to -21.7 m/s, where the ground seen
# 60 deg either side of the track (antenna sidelobes) has the same range and Doppler.
INTRUDER = PointTarget(np.array([2000.0, 0.0, -HEIGHT_M]), np.array([-50.0, 0.0, 0.0]), rcs_m2=1.0)


def _frames(ground: bool, own_state: bool = True):
    terrain = flat_terrain(52.0, 5.0, 0.0, 5000.0, 30.0) if ground else None
    sim = ImageSimulator(CFG, terrain, origin=(52.0, 5.0, 0.0), seed=3)
    cube = sim.frame(OWN, [INTRUDER], 0)
    ownship = _level_ownship(1, HEIGHT_M) if own_state else None
    return frames_dataset(cube[None], np.zeros(1), CFG, ownship=ownship)


def _level_ownship(n: int, height_m: float) -> dict[str, np.ndarray]:
    """Own-ship variables of ``n`` frames flying north, level, at ``SPEED_MPS``, ``height_m`` up."""
    one = np.ones(n)
    return {
        "own_north_m": 0 * one,
        "own_east_m": 0 * one,
        "own_down_m": -height_m * one,
        "own_vn_mps": SPEED_MPS * one,
        "own_ve_mps": 0 * one,
        "own_vd_mps": 0 * one,
        "own_yaw_rad": 0 * one,
        "own_pitch_rad": 0 * one,
        "own_roll_rad": 0 * one,
        "own_height_agl_m": height_m * one,
    }


def _intruder_hits(table) -> int:
    v_alias = -100.0 + 2 * CFG.v_lim_mps
    near = (np.abs(table.range_m - 2000.0) < 3 * CFG.range_resolution_m) & (
        np.abs(table.radial_velocity_mps - v_alias) < 3 * CFG.doppler_resolution_mps
    )
    return int(near.sum())


@pytest.fixture(scope="module")
def clutter_frame():
    return _frames(ground=True)


@pytest.fixture(scope="module")
def subspace(clutter_frame):
    # The pipeline's own cached prediction for this frame geometry (computed once per test run).
    return frame_subspace(navigated_own_state(clutter_frame), 0, CFG)


def test_head_on_intruder_in_sidelobe_clutter_is_found_only_with_suppression(clutter_frame):
    plain = process_frames(clutter_frame, suppression="none")
    suppressed = process_frames(clutter_frame, suppression="knowledge-aided")
    assert _intruder_hits(plain) == 0  # CA-CFAR's estimate is raised by the ground around it
    assert _intruder_hits(suppressed) == 1
    hit = suppressed[np.abs(suppressed.range_m - 2000.0) < 45].iloc[0]
    assert abs(hit.azimuth_rad) < np.radians(3.0) and not hit.is_ground
    primary = suppressed[~suppressed.secondary]
    assert len(primary) < len(plain) / 10  # the ground itself is suppressed too


def test_clear_sky_frame_keeps_its_detections(clutter_frame):
    clear = _frames(ground=False)
    plain = process_frames(clear, suppression="none")
    suppressed = process_frames(clear, suppression="knowledge-aided")
    assert _intruder_hits(plain) == _intruder_hits(suppressed) == 1
    assert len(suppressed) == len(plain)
    # SNR is against the noise estimate, which suppression never lets below the thermal floor.
    np.testing.assert_allclose(suppressed.snr_db, plain.snr_db, atol=1.0)
    np.testing.assert_allclose(suppressed.azimuth_rad, plain.azimuth_rad, atol=1e-9)


def test_predicted_clutter_region_matches_the_closed_form_band(subspace):
    sub = subspace
    r, d = np.meshgrid(np.arange(CFG.n_range), np.arange(CFG.n_doppler), indexing="ij")
    rng = CFG.range_at_bin_m(r)
    band = in_ground_band(
        rng,
        CFG.radial_velocity_at_bin_mps(d),
        np.array([SPEED_MPS, 0, 0]),
        HEIGHT_M,
        CFG,
        tolerance_mps=0.0,
        terrain_margin_m=0.0,
    )
    inside = band & (rng > HEIGHT_M + 5 * CFG.range_resolution_m)
    assert sub.predicted[inside].all()  # every cell the ground can reach is predicted
    wide = in_ground_band(
        rng,
        CFG.radial_velocity_at_bin_mps(d),
        np.array([SPEED_MPS, 0, 0]),
        HEIGHT_M,
        CFG,
        tolerance_mps=3 * CFG.doppler_resolution_mps,
        terrain_margin_m=0.0,
    )
    # (range PSF: near R = H a neighbouring range bin's ground is much faster; compare from 2 km on)
    assert not sub.predicted[~wide & (rng > 2 * HEIGHT_M)].any()


def test_suppressed_image_keeps_the_noise_floor_and_cfar_false_alarm_rate(subspace):
    sub = subspace
    rng = np.random.default_rng(1)
    shape = (CFG.n_range, CFG.n_doppler, CFG.n_rx)
    noise = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)) * np.sqrt(CFG.noise_power_w / 2)
    nulls = np.where(sub.predicted, 2, 0).astype(np.int8)  # two nulls wherever clutter is predicted
    two = nulls == 2
    assert two.mean() > 0.5
    power = projected_power(noise, sub.vectors, nulls)
    # |P z|^2 / L of unit noise is Gamma(L, 1/L): mean 1, and its tail as the CFAR table assumes.
    scaled = power[two] / CFG.noise_power_w
    assert abs(scaled.mean() - 1.0) < 0.01
    assert stats.kstest(scaled[::7], stats.gamma(2, scale=0.5).cdf).pvalue > 1e-3
    hits, _ = cfar_2d_floor(power, CFG.n_rx - nulls, CFG.noise_power_w, pfa=1e-3)
    assert 0.5e-3 < hits.mean() < 1.6e-3


def test_knowledge_aided_without_own_ship_state_is_one_clear_error(tmp_path):
    with pytest.raises(InputError, match="own-ship state"):
        process_frames(_frames(ground=False, own_state=False), suppression="knowledge-aided")
    _frames(ground=False, own_state=False).to_zarr(tmp_path / "run.zarr", consolidated=False)
    result = skyradar(
        "process", "run.zarr", "-o", "d.parquet", "--suppression", "knowledge-aided", cwd=tmp_path
    )
    assert_one_line_error(result, "run.zarr", "knowledge-aided", "own-ship state")
    assert result.stderr.count("run.zarr") == 1, result.stderr  # named once, not "run.zarr: run.zarr:"
    assert not (tmp_path / "d.parquet").exists()
    # The same on a local Dask cluster: its workers do not print the failed task's traceback.
    result = skyradar(
        "process",
        "run.zarr",
        "-o",
        "d.parquet",
        "--suppression",
        "knowledge-aided",
        "--workers",
        "2",
        cwd=tmp_path,
    )
    assert_one_line_error(result, "run.zarr", "knowledge-aided", "own-ship state")
    assert not (tmp_path / "d.parquet").exists()


def test_fused_kernel_matches_the_numpy_reference(clutter_frame, subspace):
    cube = np.asarray(clutter_frame.iq.values[0])
    out = suppress_clutter(cube, subspace, CFG, adaptive=False)  # the predicted pass alone
    nulls, unsuppressed = null_count(subspace.fractions, out.clutter_to_noise)
    # float32 sums in the kernel: a cell whose residual is within rounding of the limit may flip.
    assert (out.nulls != nulls).mean() < 1e-4
    assert (out.unsuppressed != unsuppressed).mean() < 1e-4
    reference = projected_power(cube / CFG.rx_calibration, subspace.vectors, nulls)
    # |z|^2 - |E^H z|^2 in float32 under 50 dB of clutter: differences stay far below the noise.
    same = out.nulls == nulls
    raw = power_image(cube, CFG.rx_calibration)
    # float32 rounding of |z|^2 - |E^H z|^2 grows with the cell's raw power (up to 55 dB of clutter).
    tolerance = 2e-3 * reference + 1e-5 * raw + 1e-3 * CFG.noise_power_w
    assert np.all(np.abs(out.power - reference)[same] <= tolerance[same])


@pytest.mark.slow
def test_bench_suppressed_agrees_with_its_numpy_baseline():
    from skyradar.benchmarks.process_clutter import run_suppressed

    result = run_suppressed(n_cubes=2, min_time_s=0.05)
    assert result["suppressed_detections_per_frame"] == result["suppressed_baseline_detections_per_frame"]
    assert result["suppressed_detections_per_frame"] < result["terrain_unsuppressed_detections_per_frame"] / 3


def test_intruder_mixed_with_sidelobe_clutter_keeps_its_detections_and_elevation():
    # Flat ground 300 m below: a head-on intruder 46 m below, 14 deg left, closing at 116 m/s (aliased
    # into the ground band), its cell shared with the ground 40-60 deg either side. The plain direction
    # of the mixture is pulled a few degrees towards the ground, not onto it: it keeps it, with its
    # measured elevation, and is not ground (one pulled onto the ground is searched through the nulls:
    # plain_wave_is_mixed's example).
    height, bearing = 300.0, np.radians(-14.0)
    own = PlatformState(np.array([0.0, 0.0, -height]), np.array([SPEED_MPS, 0.0, 0.0]), np.zeros(3))
    rel = 1500.0 * np.array([np.cos(bearing), np.sin(bearing), 0.0]) + np.array([0.0, 0.0, 46.0])
    target = PointTarget(np.array([0.0, 0.0, -height]) + rel, np.array([-65.7, 0.0, 0.0]), rcs_m2=1.1)
    sim = ImageSimulator(CFG, flat_terrain(52.0, 5.0, 0.0, 5000.0, 30.0), origin=(52.0, 5.0, 0.0), seed=5)
    n = 8
    cubes = np.stack([sim.frame(own, [target], k) for k in range(n)])
    ownship = _level_ownship(n, height)
    table = process_frames(
        frames_dataset(cubes, np.arange(n) * 0.1, CFG, ownship=ownship), suppression="auto"
    )
    closing = -(SPEED_MPS + 65.7) * rel[0] / np.linalg.norm(rel)
    v_alias = (closing + CFG.v_lim_mps) % (2 * CFG.v_lim_mps) - CFG.v_lim_mps
    hits = table[
        (np.abs(table.range_m - np.linalg.norm(rel)) < 3 * CFG.range_resolution_m)
        & (np.abs(table.radial_velocity_mps - v_alias) < 3 * CFG.doppler_resolution_mps)
    ]
    assert len(hits) >= n // 2 and not hits.is_ground.any()
    assert hits.elevation_measured.all()
    el_true = np.arcsin(-rel[2] / np.linalg.norm(rel))
    assert np.all(np.abs(np.degrees(hits.elevation_rad - el_true)) < 5.0)
    assert np.all(np.abs(np.degrees(hits.azimuth_rad - bearing)) < 7.0)


def _mimo_intruder_at_twice_the_velocity_limit(nulls_for_mimo: int | None, monkeypatch) -> tuple:
    """Detections of three frames of the 2 TX x 4 RX MIMO radar 300 m over flat ground, an
    intruder 1000 m out, 15 deg right and 3 deg up, flying at the radar at ``2 v_lim``: the whole
    table, the intruder's detections not flagged ground, and its (bearing, elevation), rad."""
    from skyradar.process import clutter_suppress

    if nulls_for_mimo is not None:
        monkeypatch.setattr(clutter_suppress, "default_max_nulls", lambda n_rx, n_tx=1: nulls_for_mimo)
    mimo = RadarConfig.prototype_2022(rx_positions_m="mimo-2x4")
    height, bearing, elevation, rng = 300.0, np.radians(15.0), np.radians(3.0), 1000.0
    horizontal = np.cos(elevation) * np.array([np.cos(bearing), np.sin(bearing)])
    los = np.array([*horizontal, -np.sin(elevation)])
    own = PlatformState(np.array([0.0, 0.0, -height]), np.array([SPEED_MPS, 0.0, 0.0]), np.zeros(3))
    speed = 2.0 * mimo.v_lim_mps
    target = PointTarget(own.position_ned_m + rng * los, -speed * los, rcs_m2=1.0)
    sim = ImageSimulator(mimo, flat_terrain(52.0, 5.0, 0.0, 5000.0, 30.0), origin=(52.0, 5.0, 0.0), seed=5)
    n = 3
    cubes = np.stack([sim.frame(own, [target], k) for k in range(n)])
    frames = frames_dataset(cubes, np.arange(n) * 0.1, mimo, ownship=_level_ownship(n, height))
    table = process_frames(frames, suppression="auto")
    window = 2.0 * mimo.v_lim_mps
    v_alias = (-SPEED_MPS * los[0] - speed + mimo.v_lim_mps) % window - mimo.v_lim_mps
    dv = (table.radial_velocity_mps - v_alias + window / 2) % window - window / 2
    near = (np.abs(table.range_m - rng) < 4 * mimo.range_resolution_m) & (
        np.abs(dv) < 3 * mimo.doppler_resolution_mps
    )
    return table, table[near & ~table.is_ground], (bearing, elevation)


def test_mimo_nulls_every_alias_of_the_ground_that_shares_an_intruders_doppler(monkeypatch):
    # An intruder whose own speed along the line of sight is 2 v_lim (39 m/s for the MIMO array)
    # shares its aliased Doppler with the ground at its azimuth, one alias away; the other alias's
    # ground lies 80 deg off the nose, in the antenna's sidelobes. Two nulls take the first pair and
    # leave the second 20-30 dB over the noise in the intruder's cell; four (two per transmitter's
    # alias) take both: the intruder stands 6 dB higher, at its direction, and fewer ground cells
    # are left to detect.
    table, hits, (bearing, elevation) = _mimo_intruder_at_twice_the_velocity_limit(None, monkeypatch)
    two_table, two_hits, _ = _mimo_intruder_at_twice_the_velocity_limit(2, monkeypatch)
    assert len(hits) == 3 and len(two_hits) >= 1
    assert np.all(np.abs(np.degrees(hits.azimuth_rad - bearing)) < 2.0)
    assert hits.elevation_measured.all()
    assert np.all(np.abs(np.degrees(hits.elevation_rad - elevation)) < 3.0)
    assert hits.snr_db.min() > two_hits.snr_db.max() + 6.0
    assert len(table) < len(two_table) / 2
