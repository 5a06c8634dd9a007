"""Time-division MIMO: configuration, interleaved raw ADC, virtual cube, slot phase and its ambiguity."""

from __future__ import annotations

import json

import numpy as np
import pytest

from cli_helpers import assert_one_line_error, skyradar, small_scenario
from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.process import mimo
from skyradar.process.doa import (
    angles_from_direction,
    direction_from_angles,
    doa_crlb,
    estimate_directions,
    steering_vector,
)
from skyradar.process.rangedoppler import range_doppler
from skyradar.rx_layouts import rx_layout_m
from skyradar.sim.raw import adc_noise, simulate_adc

PROTO = RadarConfig.prototype_2022()
MIMO = RadarConfig.prototype_2022(rx_positions_m="mimo-2x4")
LAM = PROTO.wavelength_m


# ---- configuration ----------------------------------------------------------------------------
def test_one_transmitter_keeps_its_dict_and_hash():
    one_row = RadarConfig.prototype_2022(tx_positions_m=[[0.0, 0.0, 0.0]])
    assert one_row.tx_positions_m is None and one_row.n_tx == 1
    assert "tx_positions_m" not in PROTO.to_dict()
    assert one_row.to_dict() == PROTO.to_dict() and hash(one_row) == hash(PROTO) and one_row == PROTO
    assert PROTO.n_virtual == PROTO.n_rx and PROTO.doppler_axis_mps.size == PROTO.n_doppler
    # Moving the one transmitter still works through tx_position_m.
    moved = PROTO.replace(tx_position_m=np.array([0.0, 0.01, 0.0]))
    assert moved.n_tx == 1 and moved.tx_position_m[1] == 0.01


def test_mimo_2x4_virtual_positions_are_the_closed_form_uniform_2x4():
    # By hand: transmitters at down = -+lambda/4, receivers at right = -3, -1, 1, 3 lambda/4;
    # tx + rx is the 2x4 grid of half-wavelength pitch, top row first, left to right.
    q = LAM / 4.0
    expected = np.array([[0.0, r * q, d * q] for d in (-1, 1) for r in (-3, -1, 1, 3)])
    assert MIMO.n_tx == 2 and MIMO.n_rx == 4 and MIMO.n_virtual == 8
    np.testing.assert_allclose(MIMO.virtual_positions_m, expected, rtol=0, atol=1e-15)
    np.testing.assert_allclose(MIMO.virtual_positions_m, rx_layout_m("ura-2x4", LAM), rtol=0, atol=1e-15)
    np.testing.assert_allclose(MIMO.tx_position_m, [0.0, 0.0, -q])


def test_each_transmitter_slow_time_halves_the_unambiguous_doppler():
    assert MIMO.v_lim_mps == pytest.approx(MIMO.prf_hz * LAM / 8.0, rel=1e-15)
    assert MIMO.n_doppler_per_tx == 125 and MIMO.doppler_axis_mps.size == 125
    assert MIMO.doppler_resolution_mps == pytest.approx(PROTO.doppler_resolution_mps, rel=1e-12)
    assert MIMO.doppler_axis_mps[0] == pytest.approx(-MIMO.v_lim_mps + MIMO.doppler_resolution_mps / 2)
    # A velocity and its alias one per-transmitter span away share a bin.
    v = np.array([5.0, -17.0])
    np.testing.assert_array_equal(MIMO.doppler_bin(v + 2 * MIMO.v_lim_mps), MIMO.doppler_bin(v))
    assert not np.array_equal(PROTO.doppler_bin(v + 2 * MIMO.v_lim_mps), PROTO.doppler_bin(v))


def test_mimo_config_round_trips_through_dict_and_recording(tmp_path):
    from skyradar.io.recording_writer import write_recording, write_sigmf_recording
    from skyradar.io.recordings import read_recording

    back = RadarConfig.from_dict(MIMO.to_dict())
    assert back == MIMO and back.n_tx == 2
    np.testing.assert_array_equal(back.tx_positions_m, MIMO.tx_positions_m)
    cfg = MIMO.replace(n_doppler=8)
    adc = np.zeros((1, 4, 8, cfg.samples_per_chirp), np.complex64)
    adc[0, :, 1::2] = 1.0  # transmitter 1's chirps
    frames, read = read_recording(write_recording(tmp_path / "rec.bin", adc, cfg, dtype="complex64"))
    assert read == cfg and read.n_tx == 2
    split = mimo.split_chirps(np.asarray(frames[0]), read)
    assert np.all(split[:4] == 0) and np.all(split[4:] == 1)
    sigmf_frames, sigmf_read = read_recording(write_sigmf_recording(tmp_path / "rec", adc, cfg, "cf32_le"))
    assert sigmf_read == cfg and sigmf_read.n_tx == 2
    np.testing.assert_array_equal(np.asarray(sigmf_frames[0]), adc[0])


@pytest.mark.parametrize(
    ("changes", "needles"),
    [
        (
            {"tx_positions_m": [[0, 0, 0.01], [0, 0, 0.01]]},
            ["transmitters 0 and 1 coincide", "[0.0, 0.0, 0.01]"],
        ),
        ({"tx_positions_m": [[0, 0, 0], [0, float("nan"), 0]]}, ["transmitter 1 is not finite", "nan"]),
        ({"tx_positions_m": [[0, 0, 0.01 * i] for i in range(5)]}, ["5 transmitters", "1 to 4"]),
        (
            {"rx_positions_m": "ura-2x4", "tx_positions_m": [[0, 0, 0.01 * i] for i in range(5)]},
            ["5 transmitters"],
        ),
        (
            {
                "rx_positions_m": np.vstack(
                    [rx_layout_m("ura-2x4", LAM), rx_layout_m("ura-2x4", LAM) + [0, 0, 0.05]]
                ),
                "tx_positions_m": [[0, 0, 0.0], [0, 0, 0.2], [0, 0, 0.4]],
            },
            ["3 transmitters x 16 receivers are 48 virtual channels", "at most 32"],
        ),
        ({"tx_positions_m": [0.0, 0.0, 0.0]}, ["(n_tx, 3)", "shape (3,)"]),
        ({"tx_positions_m": [[0, 0, 0], [0, 0, 0.01], [0, 0, 0.02]]}, ["n_doppler 250", "3 transmitters"]),
    ],
)
def test_bad_transmitters_give_one_clear_line(changes, needles):
    with pytest.raises(InputError) as info:
        RadarConfig.prototype_2022(**changes)
    message = str(info.value)
    assert "\n" not in message and "radar." in message
    for needle in needles:
        assert needle in message, message


def test_thirty_two_virtual_channels_are_the_limit():
    tx = [[0, 0, 0.02 * i] for i in range(4)]
    assert (
        RadarConfig.prototype_2022(rx_positions_m="ura-2x4", tx_positions_m=tx, n_doppler=248).n_virtual == 32
    )
    nine = np.vstack([rx_layout_m("ura-2x4", LAM), [[0.0, 0.0, 0.05]]])
    with pytest.raises(InputError, match="4 transmitters x 9 receivers are 36 virtual channels"):
        RadarConfig.prototype_2022(rx_positions_m=nine, tx_positions_m=tx, n_doppler=248)


def test_given_transmitters_set_the_transmitter_position():
    cfg = RadarConfig.prototype_2022(tx_positions_m=[[0, 0, 0.01], [0, 0, 0.03]])
    np.testing.assert_array_equal(cfg.tx_position_m, [0, 0, 0.01])
    # A copy with new transmitters follows them, not the carried-over first position.
    moved = cfg.replace(tx_positions_m=[[0, 0.01, 0], [0, 0.02, 0], [0, 0.03, 0]], n_doppler=249)
    assert moved.n_tx == 3 and moved.tx_position_m.tolist() == [0, 0.01, 0]
    assert cfg.replace(tx_positions_m=None).n_tx == 1
    with pytest.raises(InputError, match=r"radar.tx_positions_m: 3 m from the antenna frame's origin"):
        RadarConfig.prototype_2022(tx_positions_m=[[0, 0, 0], [0, 0, 3.0]])


def _scenario(radar: dict) -> dict:
    return small_scenario("layout", duration_s=1.0, frame_rate_hz=2.0, radar=radar)


@pytest.mark.parametrize(
    ("radar", "needles"),
    [
        (
            {"tx_positions_m": [[0, 0, 0.01], [0, 0, 0.01]]},
            ["radar.tx_positions_m", "transmitters 0 and 1 coincide", "[0.0, 0.0, 0.01]"],
        ),
        (
            {"tx_positions_m": [[0, 0, 0.01 * i] for i in range(5)]},
            ["radar.tx_positions_m", "5 transmitters"],
        ),
        (
            {"tx_position_m": [0, 0, 0], "tx_positions_m": [[0, 0, 0], [0, 0, 0.01]]},
            ["'radar'", "not both"],
        ),
    ],
)
def test_bad_transmitters_are_one_line_through_the_cli(tmp_path, radar, needles, cli):
    import yaml

    (tmp_path / "s.yaml").write_text(yaml.safe_dump(_scenario(radar)))
    result = cli("simulate", "s.yaml", "--output", "r.zarr", cwd=tmp_path)
    assert_one_line_error(result, *needles)
    assert not (tmp_path / "r.zarr").exists()


def test_a_mimo_scenario_simulates_virtual_channel_frames_through_the_cli(tmp_path):
    import xarray as xr
    import yaml

    (tmp_path / "s.yaml").write_text(yaml.safe_dump(_scenario({"rx_layout": "mimo-2x4"})))
    result = skyradar("simulate", "s.yaml", "--output", "r.zarr", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    iq = xr.open_zarr(tmp_path / "r.zarr", consolidated=False).iq
    assert iq.sizes["doppler"] == MIMO.n_doppler_per_tx and iq.sizes["rx"] == MIMO.n_virtual
    assert "virtual channel" in iq["rx"].attrs["long_name"]


def test_a_mimo_array_runs_the_encounter_experiment_in_clear_sky_through_the_cli(tmp_path):
    # Simulate -> process -> track -> alert -> score; in clear sky the frames have no height above
    # ground, so "auto" suppression leaves them as they are.
    result = skyradar(
        "experiment", "encounters", "--rx-layout", "mimo-2x4", "--n", "2", "--layout", "single",
        "--frame-rate-hz", "4.7", "--workers", "1", "--output", "enc", "--json", cwd=tmp_path,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout.strip().splitlines()[-1])
    assert (summary["rx_layout"], summary["suppression"], summary["encounters"]) == ("mimo-2x4", "auto", 2)
    assert summary["terrains"] == ["none"]


def test_the_land_cover_simulator_refuses_several_transmitters():
    from skyradar.sim.land_cover_scene import LandCoverSimulator

    with pytest.raises(InputError, match="radar.tx_positions_m: the land-cover simulator models one"):
        LandCoverSimulator(MIMO, np.zeros((2, 2)), np.zeros((2, 2)), None)  # refused before the grid is read


# ---- image-domain frames of a MIMO radar --------------------------------------------------------
def _image_frame(config: RadarConfig, position_m: np.ndarray, velocity_mps: np.ndarray) -> np.ndarray:
    from skyradar.sim.image import ImageSimulator, PlatformState, PointTarget

    simulator = ImageSimulator(config, noise=False)
    still = PlatformState(np.zeros(3), np.zeros(3), np.zeros(3))
    return simulator.frame(still, [PointTarget(position_m, velocity_mps)])


@pytest.mark.parametrize("radial_mps", [0.0, 7.0 * MIMO.doppler_resolution_mps, -15.2, 31.0])
def test_image_domain_mimo_frame_is_the_raw_chains_virtual_cube(radial_mps):
    # A target at 20 deg right, 6 deg up, with and without motion (31 m/s aliases: VLim 19.6 m/s):
    # the image-domain frame has the raw chain's bin and its virtual channels' phase differences,
    # slot phase included.
    u = direction_from_angles(np.radians(20.0), np.radians(6.0))
    r = 130 * MIMO.range_resolution_m - MIMO.range_doppler_coupling_s * radial_mps
    img = _image_frame(MIMO, r * u, radial_mps * u)
    assert img.shape == MIMO.frame_shape == (MIMO.n_range, MIMO.n_doppler // 2, 8)
    raw = mimo.virtual_range_doppler(
        simulate_adc(MIMO, (r * u)[None], (radial_mps * u)[None], noise=False), MIMO
    )
    k, j = np.unravel_index(np.abs(img).sum(axis=2).argmax(), img.shape[:2])
    assert (k, j) == np.unravel_index(np.abs(raw).sum(axis=2).argmax(), raw.shape[:2])
    assert j == int(MIMO.doppler_bin(radial_mps))
    d_img = np.angle(img[k, j] * np.conj(img[k, j, 0]))
    d_raw = np.angle(raw[k, j] * np.conj(raw[k, j, 0]))
    np.testing.assert_allclose(np.angle(np.exp(1j * (d_img - d_raw))), 0.0, atol=np.radians(1.0))


def test_image_domain_mimo_noise_is_the_raw_chains_per_virtual_pixel():
    # Each virtual pixel integrates one transmitter's nV / n_tx chirps: the noise per pixel is
    # k T F PRF / (nV / n_tx), the same in both chains.
    from skyradar.sim.image import ImageSimulator, PlatformState

    assert MIMO.noise_power_w == pytest.approx(2.0 * PROTO.noise_power_w)
    frame = ImageSimulator(MIMO, seed=3).frame(PlatformState(np.zeros(3), np.zeros(3), np.zeros(3)))
    raw = mimo.virtual_range_doppler(adc_noise(MIMO, seed=3), MIMO, "none", "none")
    assert np.mean(np.abs(frame) ** 2) == pytest.approx(MIMO.noise_power_w, rel=0.01)
    assert np.mean(np.abs(raw) ** 2) == pytest.approx(MIMO.noise_power_w, rel=0.01)


@pytest.mark.parametrize("layout", ["mimo-2x4", "three-tx"])
def test_terrain_channel_positions_give_each_virtual_channels_path_and_slot_phase(layout):
    # Static points 300 m to 4.9 km away in every direction ahead, seen from an antenna flying at
    # 50 m/s with some climb: the path through the shifted receiver equals the virtual channel's
    # exact two-way path plus 2 v_r t / PRF to within the far field's second-order term
    # |tx_t - tx_0|^2 / (2 R): 0.03 wavelengths for a 4-wavelength baseline at 300 m.
    if layout == "three-tx":
        tx = [[0.0, 0.0, 0.0], [0.0, 2 * LAM, 0.0], [0.0, 4 * LAM, -0.5 * LAM]]
        config = RadarConfig.prototype_2022(tx_positions_m=tx, n_doppler=252)
    else:
        config = MIMO
    w = -np.array([48.0, 3.0, -6.0])  # terrain relative to the antenna
    rng = np.random.default_rng(1)
    n = 500
    u = direction_from_angles(rng.uniform(-1.2, 1.2, n), rng.uniform(-1.0, 0.3, n))
    p = rng.uniform(300.0, 4900.0, n)[:, None] * u
    q = config.terrain_channel_positions_m(w)
    got = np.linalg.norm(p - config.transmitters_m[0], axis=1)[:, None] + np.linalg.norm(
        p[:, None, :] - q[None], axis=2
    )
    slot_s = np.repeat(np.arange(config.n_tx), config.n_rx) / config.prf_hz
    tx = np.repeat(config.transmitters_m, config.n_rx, axis=0)
    rx = np.tile(config.rx_positions_m, (config.n_tx, 1))
    exact = (
        np.linalg.norm(p[:, None, :] - tx[None], axis=2)
        + np.linalg.norm(p[:, None, :] - rx[None], axis=2)
        + 2.0 * (u @ w)[:, None] * slot_s[None]
    )
    baseline = np.linalg.norm(config.transmitters_m - config.transmitters_m[0], axis=1)
    second_order = np.repeat(baseline, config.n_rx)[None] ** 2 / (2.0 * np.linalg.norm(p, axis=1))[:, None]
    assert np.all(np.abs(got - exact) <= second_order + 1e-4 * LAM)


def test_terrain_of_a_mimo_radar_fills_the_virtual_frame():
    # Flat ground 300 m below an antenna flying at 50 m/s: every range bin beyond the height has
    # ground in some of the 125 Doppler bins, and each receiver carries the same power through
    # either transmitter (the slot phase moves the ground's phases, not its power).
    from skyradar.scene.terrain import Terrain
    from skyradar.sim.image import ImageSimulator, PlatformState

    terrain = Terrain.projected(np.zeros((400, 400)), 52.0, 4.0, 30.0, 30.0)
    lat, lon = terrain.center_latlon
    sim = ImageSimulator(MIMO, terrain, origin=(lat, lon, 300.0), noise=False)
    frame = sim.frame(PlatformState(np.zeros(3), np.array([50.0, 0.0, 0.0]), np.zeros(3)))
    assert frame.shape == MIMO.frame_shape
    power = np.abs(frame) ** 2
    beyond = (MIMO.range_axis_m > 400.0) & (MIMO.range_axis_m < 4500.0)
    assert (power[beyond].sum(axis=(1, 2)) > 0).all()
    per_channel_db = 10 * np.log10(power.sum(axis=(0, 1))).reshape(MIMO.n_tx, MIMO.n_rx)
    assert np.all(np.abs(per_channel_db[1] - per_channel_db[0]) < 0.2)


def _cell_residual(frame: np.ndarray, config: RadarConfig, height_m: float, nulls: int) -> float:
    """Median over the strongest half of the predicted clutter cells of the part of a cell's power
    left after projecting out the ``nulls`` dominant eigenvectors of its predicted covariance."""
    from skyradar.process.clutter import clutter_subspace

    sub = clutter_subspace(config, np.array([50.0, 0.0, 0.0]), config.mount.rotation, height_m, n_azimuth=720)
    power = np.sum(np.abs(frame) ** 2, axis=-1)
    rr, dd = np.nonzero(sub.predicted & (power > np.median(power[sub.predicted])))
    vectors, z = sub.cell_vectors(rr, dd)[:, :, :nulls], frame[rr, dd]
    kept = np.sum(np.abs(np.einsum("nkm,nk->nm", vectors.conj(), z)) ** 2, axis=1)
    return float(np.median(1.0 - kept / power[rr, dd]))


def test_the_predicted_clutter_of_a_mimo_frame_holds_its_simulated_ground(monkeypatch):
    # Flat ground 300 m below an antenna flying north at 50 m/s, noise off. Every static point of a
    # frame sees the virtual channels from the same moved receivers, so the prediction over those
    # positions (its Doppler folded into the 125-bin image) spans the simulated ground: two
    # eigenvectors take all but 1e-3 of a cell's power, as with one transmitter. A model of the
    # virtual positions without the slots' Doppler path misses most of it.
    from skyradar.scene.terrain import Terrain
    from skyradar.sim.image import ImageSimulator, PlatformState

    terrain = Terrain.projected(np.zeros((400, 400)), 52.0, 4.0, 30.0, 30.0)
    lat, lon = terrain.center_latlon
    sim = ImageSimulator(MIMO, terrain, origin=(lat, lon, 300.0), noise=False)
    frame = np.asarray(sim.frame(PlatformState(np.zeros(3), np.array([50.0, 0.0, 0.0]), np.zeros(3))))
    assert _cell_residual(frame, MIMO, 300.0, nulls=2) < 1e-3
    monkeypatch.setattr(RadarConfig, "terrain_channel_positions_m", lambda self, w: self.virtual_positions_m)
    assert _cell_residual(frame, MIMO, 300.0, nulls=2) > 0.5


def test_scenario_names_the_mimo_array():
    from skyradar.scene.scenario import Scenario

    cfg = Scenario.from_dict(_scenario({"rx_layout": "mimo-2x4"})).radar_config()
    assert cfg == MIMO
    given = Scenario.from_dict(_scenario({"tx_positions_m": [[0, 0, -0.008], [0, 0, 0.008]]})).radar_config()
    assert given.n_tx == 2 and given.n_virtual == 8


# ---- raw ADC and the virtual cube -------------------------------------------------------------
def test_split_chirps_sorts_chirp_n_to_transmitter_n_mod_n_tx():
    cfg = MIMO.replace(n_doppler=6)
    adc = (np.arange(6)[None, :, None] + 100 * np.arange(4)[:, None, None]) * np.ones((1, 1, 3))
    split = mimo.split_chirps(adc, cfg)
    assert split.shape == (8, 3, 3)
    assert split[:, :, 0].tolist() == [
        [100 * r + t + 2 * j for j in range(3)] for t in range(2) for r in range(4)
    ]


def test_the_plain_range_doppler_transform_refuses_interleaved_chirps():
    adc = np.zeros((4, MIMO.n_doppler, MIMO.samples_per_chirp), np.complex64)
    with pytest.raises(InputError, match=r"radar.tx_positions_m: the range-Doppler .*virtual_range_doppler"):
        range_doppler(adc, MIMO)


def test_a_mimo_recording_is_refused_by_skyradar_rd_in_one_line(tmp_path):
    from skyradar.io.recording_writer import write_recording

    cfg = MIMO.replace(n_doppler=8)
    adc = np.zeros((1, 4, 8, cfg.samples_per_chirp), np.complex64)
    write_recording(tmp_path / "rec.bin", adc, cfg, dtype="complex64")
    result = skyradar("rd", "rec.json", "-o", "rd.zarr", cwd=tmp_path)
    assert_one_line_error(result, "radar.tx_positions_m", "got 2", "virtual_range_doppler")
    assert not (tmp_path / "rd.zarr").exists()


def test_one_transmitter_virtual_cube_is_the_range_doppler_cube():
    adc = simulate_adc(PROTO, [[900.0, 30.0, -10.0]], [[-12.0, 0, 0]], seed=3)
    np.testing.assert_array_equal(mimo.virtual_range_doppler(adc, PROTO), range_doppler(adc, PROTO))


def test_one_row_of_transmitters_simulates_the_same_adc():
    tx = [0.0, 0.004, -0.002]
    pos, vel = [[700.0, 40.0, 20.0]], [[-20.0, 3.0, 0.0]]
    a = simulate_adc(PROTO.replace(tx_position_m=np.array(tx)), pos, vel, noise=False)
    b = simulate_adc(RadarConfig.prototype_2022(tx_positions_m=[tx]), pos, vel, noise=False)
    np.testing.assert_array_equal(a, b)


def test_a_static_target_has_the_virtual_arrays_steering_phases():
    # No motion, no slot phase: the virtual cube's pixel is the steering vector at tx + rx.
    u = direction_from_angles(np.radians(15.0), np.radians(10.0))
    adc = simulate_adc(MIMO, 1200.0 * u[None], noise=False)
    rd = mimo.virtual_range_doppler(adc, MIMO, "none", "none")
    k = int(MIMO.range_bin(1200.0))
    z = rd[k, int(MIMO.doppler_bin(0.0))]
    ref = np.exp(-1j * (2 * np.pi / LAM) * MIMO.virtual_positions_m @ u)
    ratio = z * np.conj(ref)
    np.testing.assert_allclose(np.angle(ratio / ratio[0]), 0.0, atol=2e-3)  # float32 ADC rounding
    np.testing.assert_allclose(np.abs(ratio) / np.abs(ratio[0]), 1.0, atol=1e-3)


def test_slot_phase_is_the_doppler_advance_between_transmitters():
    # A target receding at v advances 2 pi (2 v / lambda) / PRF per chirp: transmitter 1's channels
    # lead transmitter 0's by that much at the pixel (here on a Doppler bin, no window).
    v = 10 * MIMO.doppler_resolution_mps
    u = np.array([1.0, 0.0, 0.0])
    adc = simulate_adc(MIMO, 800.0 * u[None], v * u[None], noise=False)
    rd = mimo.virtual_range_doppler(adc, MIMO, "hann", "none")
    p = np.abs(rd).sum(axis=2)
    k, j = np.unravel_index(p.argmax(), p.shape)
    assert MIMO.doppler_axis_mps[j] == pytest.approx(v)
    z = rd[k, j] * np.conj(steering_vector(u, MIMO))
    step = np.angle(z[4:] * np.conj(z[:4]))
    np.testing.assert_allclose(step, 2 * np.pi * (2 * v / LAM) / MIMO.prf_hz, atol=2e-3)
    compensated = mimo.compensate_slot_phase(rd, MIMO)[k, j] * np.conj(steering_vector(u, MIMO))
    np.testing.assert_allclose(np.angle(compensated * np.conj(compensated[0])), 0.0, atol=2e-3)


# ---- angle of a moving target -----------------------------------------------------------------
AZ_DEG, EL_DEG, RANGE_M = 20.0, -5.0, 1500.0


def _trials(radial_mps: float, n_trials: int):
    """Per trial: (uncompensated, compensated) angles (deg), residue, velocity; the pixel SNR (dB)."""
    u = direction_from_angles(np.radians(AZ_DEG), np.radians(EL_DEG))
    clean = simulate_adc(MIMO, RANGE_M * u[None], radial_mps * u[None], rcs_m2=10.0, noise=False)
    rd_clean = mimo.virtual_range_doppler(clean, MIMO)
    power = np.abs(rd_clean).sum(axis=2)
    k, j = np.unravel_index(power.argmax(), power.shape)
    noise_rd = mimo.virtual_range_doppler(adc_noise(MIMO, seed=99), MIMO)
    snr_db = 10 * np.log10(np.mean(np.abs(rd_clean[k, j]) ** 2) / np.mean(np.abs(noise_rd) ** 2))
    rows = []
    for seed in range(n_trials):
        rd = mimo.virtual_range_doppler(clean + adc_noise(MIMO, seed=seed), MIMO)
        z = rd[k, j][None]
        raw = np.degrees(angles_from_direction(estimate_directions(z, MIMO, calibrated=True)))
        out = mimo.virtual_pixels(z, j, MIMO)
        comp = np.degrees(angles_from_direction(estimate_directions(out.pixels, MIMO, calibrated=True)))
        rows.append((raw[:, 0], comp[:, 0], int(out.residue[0]), float(out.radial_velocity_mps[0])))
    return rows, snr_db


@pytest.mark.parametrize(
    ("radial_mps", "residue"),
    [(-12.0, 0), (-25.0, 1)],  # -25 m/s is beyond the per-transmitter 19.6 m/s: aliased onto +14.1
)
def test_moving_target_angle_reaches_its_bound_after_slot_phase_compensation(radial_mps, residue):
    rows, snr_db = _trials(radial_mps, 40)
    sd_az, sd_el = np.degrees(doa_crlb(snr_db, np.radians(AZ_DEG), np.radians(EL_DEG), MIMO))
    assert 15.0 < snr_db < 40.0  # above the threshold where the bound holds (checked, not assumed)
    comp = np.array([r[1] for r in rows]) - [AZ_DEG, EL_DEG]
    rms = np.sqrt(np.mean(comp**2, axis=0))
    # 40 trials: the RMS has a relative SD of about 11 %; 1.5 x the bound is 4 of them.
    assert rms[0] < 1.5 * sd_az and rms[1] < 1.5 * sd_el, (rms, sd_az, sd_el)
    assert abs(comp[:, 0].mean()) < sd_az and abs(comp[:, 1].mean()) < sd_el
    # The ambiguity is resolved in every trial, and with it the velocity to a Doppler bin.
    assert {r[2] for r in rows} == {residue}
    np.testing.assert_allclose([r[3] for r in rows], radial_mps, atol=MIMO.doppler_resolution_mps)
    # Without the compensation the slot phase reads as an elevation offset of many bounds.
    raw = np.array([r[0] for r in rows]) - [AZ_DEG, EL_DEG]
    assert abs(raw[:, 1].mean()) > 10 * sd_el


def test_an_aliased_target_keeps_a_residual_bias_with_the_aliased_compensation_alone():
    # The Doppler bin's velocity alone leaves pi on transmitter 1: the residue test is what fixes it.
    u = direction_from_angles(np.radians(AZ_DEG), np.radians(EL_DEG))
    v = -25.0
    z = steering_vector(u, MIMO) * mimo.slot_phase(v, MIMO)
    j = int(MIMO.doppler_bin(v))
    aliased = z * np.conj(mimo.slot_phase(MIMO.doppler_axis_mps[j], MIMO))
    _, el = np.degrees(angles_from_direction(estimate_directions(aliased[None], MIMO)))
    assert abs(el[0] - EL_DEG) > 30.0
    out = mimo.virtual_pixels(z[None], j, MIMO)
    az, el = np.degrees(angles_from_direction(estimate_directions(out.pixels, MIMO)))
    assert az[0] == pytest.approx(AZ_DEG, abs=0.2) and el[0] == pytest.approx(EL_DEG, abs=0.2)
    assert out.residue.tolist() == [1] and out.peak_ratio[0] > 1.0


@pytest.mark.parametrize(("el_deg", "resolved"), [(-10.0, True), (10.0, True), (-20.0, False), (25.0, False)])
def test_the_ambiguity_is_resolved_where_the_alias_leaves_the_field_of_view(el_deg, resolved):
    # mimo-2x4's wrong residue mimics the down direction cosine shifted by 1: outside the prototype's
    # 49.5 deg cone within 13.9 deg of the horizontal plane (rx_layouts docstring), inside beyond.
    v = -25.0
    z = steering_vector(direction_from_angles(0.0, np.radians(el_deg)), MIMO) * mimo.slot_phase(v, MIMO)
    out = mimo.virtual_pixels(z[None], MIMO.doppler_bin(v), MIMO)
    if resolved:
        assert out.residue.tolist() == [1] and out.peak_ratio[0] > 1.01
        assert out.radial_velocity_mps[0] == pytest.approx(v, abs=MIMO.doppler_resolution_mps)
    else:  # both residues have a plane wave inside the cone that fits: the ratio says so
        assert out.peak_ratio[0] < 1.005


@pytest.mark.parametrize("radial_mps", [-5.0, 20.0, -30.0, 35.0])
def test_three_transmitters_resolve_every_residue(radial_mps):
    # A row of 4 receivers at lambda/2, transmitters at 0 and 2 lambda across and one lambda/2 up:
    # per-transmitter limit 13.0 m/s, so the velocities here alias by m = 0, 1, 2 and 1.
    rx = [[0, (2 * i - 3) * LAM / 4, 0] for i in range(4)]
    tx = [[0, 0, 0], [0, 2 * LAM, 0], [0, LAM, LAM / 2]]
    cfg = RadarConfig.prototype_2022(rx_positions_m=rx, tx_positions_m=tx, n_doppler=249)
    for az_deg, el_deg in ((10.0, -5.0), (-15.0, 3.0)):
        u = direction_from_angles(np.radians(az_deg), np.radians(el_deg))
        z = steering_vector(u, cfg) * mimo.slot_phase(radial_mps, cfg)
        out = mimo.virtual_pixels(z[None], cfg.doppler_bin(radial_mps), cfg)
        assert out.radial_velocity_mps[0] == pytest.approx(radial_mps, abs=cfg.doppler_resolution_mps)
        az, el = np.degrees(angles_from_direction(estimate_directions(out.pixels, cfg)))
        # The compensation uses the bin's centre: up to half a bin of velocity is left as phase.
        assert az[0] == pytest.approx(az_deg, abs=0.5) and el[0] == pytest.approx(el_deg, abs=0.5)


def test_virtual_array_bound_is_the_closed_form_2x4_ura():
    # 2 rows x 4 columns at d = lambda/2 (k d = pi): sum y^2 = 10 d^2, sum z^2 = 2 d^2 about the
    # centre, so at boresight sd = 1 / (pi sqrt(2 SNR sum / d^2)).
    snr_db = 20.0
    snr = 10 ** (snr_db / 10)
    sd_az, sd_el = doa_crlb(snr_db, 0.0, 0.0, MIMO)
    assert float(sd_az) == pytest.approx(1.0 / (np.pi * np.sqrt(2.0 * snr * 10.0)), rel=1e-12)
    assert float(sd_el) == pytest.approx(1.0 / (np.pi * np.sqrt(2.0 * snr * 2.0)), rel=1e-12)
    ura = RadarConfig.prototype_2022(rx_positions_m="ura-2x4")
    az, el = np.radians([10.0, -25.0]), np.radians([5.0, 15.0])
    np.testing.assert_allclose(doa_crlb(snr_db, az, el, MIMO), doa_crlb(snr_db, az, el, ura), rtol=1e-12)


def test_doa_takes_virtual_channels_and_refuses_receiver_counts():
    u = direction_from_angles(np.radians([12.0, -30.0]), np.radians([-8.0, 20.0]))
    np.testing.assert_allclose(estimate_directions(steering_vector(u, MIMO), MIMO), u, atol=1e-9)
    with pytest.raises(InputError, match="has 4 channels, radar_config has 8"):
        estimate_directions(np.ones((1, 4), complex), MIMO)


def test_a_mimo_run_is_processed_without_suppression(tmp_path):
    # A head-on intruder closing at 55 m/s in clear sky: its Doppler aliases once past the 19.6 m/s
    # limit of two transmitters, so the residue must be resolved too; left in, the phase step
    # between its slots would read 36 deg off in elevation. Simulate, then process without clutter
    # suppression: each frame's strongest detection has the intruder's direction within four times
    # its bound.
    import xarray as xr
    import yaml

    intruder = {
        "name": "head-on",
        "type": "encounter",
        "kind": "head-on",
        "t_cpa_s": 25.0,
        "intruder_speed_mps": 5,
        "rcs_m2": 1.0,
    }
    scenario = _scenario({"rx_layout": "mimo-2x4"}) | {"intruders": [intruder], "frame_rate_hz": 5.0}
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(scenario))
    assert skyradar("simulate", "s.yaml", "--output", "r.zarr", cwd=tmp_path).returncode == 0
    result = skyradar("process", "r.zarr", "--output", "d.parquet", "--suppression", "none", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    import pandas as pd

    det = pd.read_parquet(tmp_path / "d.parquet")
    truth = xr.open_zarr(tmp_path / "r.zarr", consolidated=False)
    best = det.loc[det.groupby("frame")["snr_db"].idxmax()]
    assert len(best) == truth.sizes["time"]
    frames = best["frame"].to_numpy()
    az, el = (truth[f"tgt_{a}_rad"].isel(target=0).values[frames] for a in ("azimuth", "elevation"))
    bound = doa_crlb(best["snr_db"].to_numpy(), az, el, MIMO)
    for got, expected, sd in zip((best["azimuth_rad"], best["elevation_rad"]), (az, el), bound, strict=True):
        assert np.all(np.abs(got.to_numpy() - expected) <= 4.0 * sd)
    expected_v = truth["tgt_radial_velocity_mps"].isel(target=0).values[best["frame"].to_numpy()]
    aliased = (expected_v + MIMO.v_lim_mps) % (2 * MIMO.v_lim_mps) - MIMO.v_lim_mps
    np.testing.assert_allclose(
        best["radial_velocity_mps"].to_numpy(), aliased, atol=MIMO.doppler_resolution_mps
    )


def test_the_runner_up_residue_is_the_mirror_direction_along_the_transmitters():
    # A target 50 deg right and 30 deg up, not moving: both residues fit inside the antenna's field
    # of view's reach (its down direction cosine is more than 1 - sin 49.5 deg from zero), and the
    # runner-up's pixels read the direction whose down cosine differs by lambda / (2 d) = 1.
    u = direction_from_angles(np.radians(50.0), np.radians(30.0))
    z = steering_vector(u, MIMO)
    out = mimo.virtual_pixels(z[None], MIMO.doppler_bin(0.0), MIMO)
    chosen = estimate_directions(out.pixels, MIMO, calibrated=True)[0]
    other = estimate_directions(out.other_pixels, MIMO, calibrated=True)[0]
    assert {int(out.residue[0]), int(out.other_residue[0])} == {0, 1}
    assert out.peak_ratio[0] < 1.2  # the field of view barely tells them apart
    truth, mirror = (chosen, other) if out.residue[0] == 0 else (other, chosen)
    np.testing.assert_allclose(truth, u, atol=1e-6)
    assert mirror[1] == pytest.approx(u[1], abs=1e-6) and mirror[2] - u[2] == pytest.approx(1.0, abs=1e-6)


def _overtaken_above(flip_from_s: float, with_other: bool):
    """Detections of an aircraft overtaken 230 m above and 300 m right (radial velocity about
    -10 m/s, unaliased through mimo-2x4's 39.15 m/s image) by an own-ship flying north at 50 m/s,
    level; from ``flip_from_s`` every frame chose the wrong residue: its position is the mirror
    (down direction cosine + 1) and the truth is the runner-up's."""
    import pandas as pd

    rng = np.random.default_rng(21)
    t = np.arange(0.0, 8.0, 1.0 / 9.4)
    own = np.column_stack([50.0 * t, 0 * t, 0 * t])
    rel = np.column_stack([500.0 - 15.0 * t, 300.0 + 0 * t, -230.0 + 0 * t])
    r = np.linalg.norm(rel, axis=1)
    v = np.sum(rel * [-15.0, 0.0, 0.0], axis=1) / r
    u = rel / r[:, None]
    mirror = np.column_stack([np.zeros_like(r), u[:, 1], u[:, 2] + 1.0])
    mirror[:, 0] = np.sqrt(1.0 - mirror[:, 1] ** 2 - mirror[:, 2] ** 2)
    flipped = t >= flip_from_s
    seen = np.where(flipped[:, None], mirror, u) * r[:, None] + own + rng.normal(0.0, 3.0, (t.size, 3))
    other = np.where(flipped[:, None], u, mirror) * r[:, None] + own
    det = pd.DataFrame(
        {
            "time_s": t,
            "range_m": r + MIMO.range_doppler_coupling_s * v + rng.normal(0.0, 2.0, t.size),
            "radial_velocity_mps": v + rng.normal(0.0, 0.05, t.size),
            "snr_db": 25.0,
            "north_m": seen[:, 0],
            "east_m": seen[:, 1],
            "down_m": seen[:, 2],
        }
    )
    if with_other:
        det = det.assign(
            residue=flipped.astype(int),
            other_residue=(~flipped).astype(int),
            other_north_m=other[:, 0],
            other_east_m=other[:, 1],
            other_down_m=other[:, 2],
        )
    ownship = pd.DataFrame(
        {"time_s": t, "own_north_m": own[:, 0], "own_east_m": 0 * t, "own_down_m": 0 * t}
        | {"own_vn_mps": 50.0 + 0 * t, "own_ve_mps": 0 * t, "own_vd_mps": 0 * t}
    )
    return det, ownship, t


def test_a_tracks_range_rate_chooses_each_detections_residue():
    # Where the field of view cannot choose the residue, the frames read the aircraft 230 m above
    # as the mirror below. Once the track's range rate has resolved its radial velocity, the
    # residue it implies, round((v - v_hat) / 2 VLim) mod n_tx, picks each detection's position:
    # the track's height stays the aircraft's. Without the runner-up's position it is pulled down.
    from skyradar.track.track_table import track_detections

    heights = {}
    for with_other in (True, False):
        det, ownship, t = _overtaken_above(2.0, with_other)
        tracks = track_detections(det, "radar", MIMO, frame_times_s=t, ownship=ownship, ground_test=False)
        last = tracks[tracks["confirmed"] & (tracks["time_s"] > 6.0)]
        heights[with_other] = -last["down_m"].to_numpy()
    assert np.all(np.abs(heights[True] - 230.0) < 30.0)
    assert np.median(np.abs(heights[False] - 230.0)) > 60.0


@pytest.mark.parametrize(
    "tx_down_m",
    [[-0.25, 0.25], [-0.5, 0.0, 0.5]],  # in wavelengths: two and three transmitters on one line
)
def test_a_wrong_residue_reads_as_the_shifted_direction(tx_down_m):
    # Closed form: the compensation off by residue m leaves exp(-i 2 pi m t / n_tx) on transmitter
    # t's channels, the same phases (up to one common factor) as a plane wave from u + d.
    lam = MIMO.wavelength_m
    tx = np.array([[0.0, 0.0, z * lam] for z in tx_down_m])
    cfg = RadarConfig.prototype_2022(rx_positions_m=MIMO.rx_positions_m, tx_positions_m=tx, n_doppler=252)
    shifts = mimo.residue_shifts(cfg)
    assert len(shifts) == 2 * (cfg.n_tx - 1)
    u = direction_from_angles(np.radians(12.0), np.radians(-7.0))
    slots = np.repeat(np.arange(cfg.n_tx), cfg.n_rx)
    for m in range(1, cfg.n_tx):
        read = steering_vector(u, cfg) * np.exp(-2j * np.pi * m * slots / cfg.n_tx)
        fits = [np.abs(np.vdot(steering_vector(u + d, cfg), read)) / cfg.n_virtual for d in shifts]
        assert max(fits) == pytest.approx(1.0, abs=1e-9)


def test_transmitters_off_one_uniform_line_have_no_residue_shift():
    lam = MIMO.wavelength_m
    tx = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.5 * lam], [0.0, 0.0, 1.7 * lam]])
    cfg = RadarConfig.prototype_2022(rx_positions_m=MIMO.rx_positions_m, tx_positions_m=tx, n_doppler=252)
    assert mimo.residue_shifts(cfg).shape == (0, 3)
