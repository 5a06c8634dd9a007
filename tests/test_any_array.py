"""Any receive array of 1 to 32 channels: named URAs, refusals, the DoA bound, and the chain on 1 and 6."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from cli_helpers import assert_one_line_error, small_scenario
from skyradar.chain import run_chain
from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.process.cfar import _floor_tables, cfar_2d_floor
from skyradar.process.doa import doa_crlb, estimate_directions
from skyradar.rx_layouts import MAX_RX, RX_LAYOUTS, rx_layout_m
from skyradar.scene.scenario import Scenario

LAM = RadarConfig.prototype_2022().wavelength_m


@pytest.mark.parametrize(("name", "rows", "cols"), [("ura-2x3", 2, 3), ("ura-2x4", 2, 4), ("ura-4x2", 4, 2)])
def test_ura_layouts_are_centred_half_wavelength_grids(name, rows, cols):
    assert name in RX_LAYOUTS
    rx = rx_layout_m(name, LAM)
    assert rx.shape == (rows * cols, 3) and np.all(rx[:, 0] == 0.0)
    np.testing.assert_allclose(rx.mean(axis=0), 0.0, atol=1e-15)
    assert np.unique(rx[:, 1].round(9)).size == cols and np.unique(rx[:, 2].round(9)).size == rows
    np.testing.assert_allclose(np.diff(np.unique(rx[:, 1].round(12))), LAM / 2)
    np.testing.assert_allclose(np.diff(np.unique(rx[:, 2].round(12))), LAM / 2)
    assert RadarConfig.prototype_2022(rx_positions_m=name).n_rx == rows * cols


def test_upright_ura_measures_elevation_the_square_cannot():
    """Four rows of two: the rows' second moment is 5 times the square's and the channels twice as
    many, so the elevation bound is sqrt(10) times smaller in a clear cell; through two nulls at one
    elevation (ground left and right at one range and Doppler) the square has no elevation left,
    the upright array keeps one."""
    from skyradar.process.clutter_doa import angle_sigmas_rad
    from skyradar.process.doa import direction_from_angles, steering_vector

    square, tall = (RadarConfig.prototype_2022(rx_positions_m=n) for n in ("square", "ura-4x2"))
    for snr_db in (10.0, 20.0):
        sq_az, sq_el = doa_crlb(snr_db, 0.0, 0.0, square)
        tall_az, tall_el = doa_crlb(snr_db, 0.0, 0.0, tall)
        np.testing.assert_allclose(sq_el / tall_el, np.sqrt(10.0), rtol=1e-9)
        np.testing.assert_allclose(sq_az / tall_az, np.sqrt(2.0), rtol=1e-9)
    target = direction_from_angles(np.radians([8.0]), np.radians([5.0]))  # 5 deg above boresight
    ground = direction_from_angles(np.radians([-35.0, 35.0]), np.radians(-12.0))  # one depression
    sigmas = {}
    for name, cfg in (("square", square), ("ura-4x2", tall)):
        z = 10.0 * steering_vector(target, cfg) * np.sqrt(cfg.noise_power_w)  # 20 dB per channel
        e, _ = np.linalg.qr(steering_vector(ground, cfg).T)
        proj = (np.eye(cfg.n_rx) - e @ e.conj().T)[None]
        sigmas[name] = np.degrees(angle_sigmas_rad(target, z, proj, cfg, cfg.noise_power_w)[0][0])
    assert np.isinf(sigmas["square"])
    assert sigmas["ura-4x2"] < 1.0


def _bad_arrays() -> list:
    return [
        ([[0, 0, 0], [0, 0.01, 0], [0, 0.01, 0]], "coincide"),
        ([[0, 0, 0], [0, float("nan"), 0]], "finite"),
        ((np.arange(MAX_RX + 1)[:, None] * [0, 0.005, 0]).tolist(), "1 to 32"),
        (np.zeros((0, 3)).tolist(), "1 to 32"),
    ]


@pytest.mark.parametrize(("rx", "needle"), _bad_arrays())
def test_bad_arrays_are_refused_naming_the_field(rx, needle):
    with pytest.raises(InputError, match=needle) as err:
        RadarConfig.prototype_2022(rx_positions_m=np.array(rx, float).reshape(-1, 3))
    assert "radar.rx_positions_m" in str(err.value) and "\n" not in str(err.value)


@pytest.mark.parametrize(("rx", "needle"), _bad_arrays())
def test_bad_arrays_are_one_line_through_the_cli(tmp_path, rx, needle, cli):
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(small_scenario("bad", radar={"rx_positions_m": rx})))
    result = cli("simulate", "s.yaml", "--output", "r.zarr", cwd=tmp_path)
    assert_one_line_error(result, "s.yaml", "rx_positions_m", needle)
    assert not (tmp_path / "r.zarr").exists()


def test_cfar_tables_reach_32_channels_and_keep_the_first_eight():
    from scipy import stats

    table = _floor_tables(1e-6, 10)
    assert table.shape == (MAX_RX + 1, 11)
    for big_l in (1, 8, 32):
        assert table[big_l, 0] == np.float32(stats.gamma.isf(1e-6, big_l, scale=1.0 / big_l))
    rng = np.random.default_rng(3)
    power = rng.gamma(24.0, 1.0 / 24.0, (300, 300)).astype(np.float32)  # 24-channel noise means
    hits, _ = cfar_2d_floor(power, np.full(power.shape, 24, np.int8), 1.0, pfa=1e-3)
    assert hits.mean() < 3e-3  # clipped at 8 channels, the wider law would pass far fewer


def test_crlb_of_the_2x3_array_is_the_closed_form():
    r"""The bound of a planar array for one source in white noise, from the centred second moments.

    Channel ``k`` sees ``z_k = A exp(i (phi - kappa u . r_k)) + n_k``, ``kappa = 2 pi / lambda``,
    ``n_k`` circular white noise of variance ``sigma^2``, ``A`` and ``phi`` unknown. For a
    deterministic signal the Fisher information on ``theta = (az, el)`` is
    ``J = (2 A^2 / sigma^2) Re(D^H P D)``, ``D_k = d s_k / d theta``; the unknown common phase
    ``phi`` projects out the mean over channels (``P`` the centring projector), so only the
    positions' deviations ``q_k = r_k - mean(r)`` enter:

        J = 2 SNR kappa^2 G^T M G,    M = sum_k q_k q_k^T (3 x 3),    G = [du/daz, du/del] (3 x 2).

    With ``u = (cos el cos az, cos el sin az, -sin el)`` at boresight ``G = [(0, 1, 0), (0, 0, -1)]``,
    so ``J = 2 SNR kappa^2 diag(sum q_y^2, sum q_z^2)`` (the URA's ``sum q_y q_z`` is 0) and the bound
    is ``var(az) = 1 / (2 SNR kappa^2 sum q_y^2)``, ``var(el) = 1 / (2 SNR kappa^2 sum q_z^2)``. For
    the 2x3 at spacing ``d = lambda / 2``: ``sum q_y^2 = 4 d^2`` (two rows of -d, 0, d) and
    ``sum q_z^2 = 6 (d / 2)^2 = 1.5 d^2``. Off boresight the general ``G^T M G`` is inverted.
    """
    cfg = RadarConfig.prototype_2022(rx_positions_m="ura-2x3")
    snr_db, snr, kappa, d = 20.0, 100.0, 2 * np.pi / LAM, LAM / 2
    sd_az, sd_el = doa_crlb(snr_db, 0.0, 0.0, cfg)
    assert float(sd_az) == pytest.approx((2 * snr * kappa**2 * 4 * d**2) ** -0.5, rel=1e-12)
    assert float(sd_el) == pytest.approx((2 * snr * kappa**2 * 1.5 * d**2) ** -0.5, rel=1e-12)
    q = cfg.rx_positions_m - cfg.rx_positions_m.mean(axis=0)
    m = q.T @ q
    for az, el in [(0.4, -0.2), (-0.7, 0.5)]:
        g = np.array(
            [
                [-np.cos(el) * np.sin(az), np.cos(el) * np.cos(az), 0.0],
                [-np.sin(el) * np.cos(az), -np.sin(el) * np.sin(az), -np.cos(el)],
            ]
        ).T
        cov = np.linalg.inv(2 * snr * kappa**2 * g.T @ m @ g)
        np.testing.assert_allclose(doa_crlb(snr_db, az, el, cfg), np.sqrt(np.diag(cov)), rtol=1e-10)


def test_one_channel_has_no_direction():
    cfg = RadarConfig.prototype_2022(rx_positions_m=[[0.0, 0.0, 0.0]])
    assert np.isnan(estimate_directions(np.ones((3, 1), complex), cfg)).all()
    assert np.isnan(doa_crlb(30.0, 0.0, 0.0, cfg)).all()


def _head_on(rx, duration_s: float) -> dict:
    return {
        "name": "array",
        "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
        "radar": {"range_limit_m": 1500, "rx_positions_m": rx}
        if not isinstance(rx, str)
        else {"range_limit_m": 1500, "rx_layout": rx},
        "ownship": {"type": "straight", "start_ned_m": [0, 0, -2000], "speed_mps": 50},
        "intruders": [
            {
                "name": "A",
                "type": "straight",
                "start_ned_m": [600, -100, -2000],
                "heading_deg": 180,
                "speed_mps": 40,
            }
        ],
        "frame_rate_hz": 9.4,
        "duration_s": duration_s,
    }


def test_one_channel_chain_runs_to_alerts_in_range_and_range_rate():
    out = run_chain(Scenario.from_dict(_head_on([[0.0, 0.0, 0.0]], 1.0)).build(), with_advice=False)
    det, tracks = out["detections"], out["tracks"]
    assert len(det) >= 8 and det["azimuth_rad"].isna().all() and det["north_m"].isna().all()
    assert (np.abs(det["range_m"] - 560) < 60).all()
    assert len(tracks) > 0 and tracks["range_m"].notna().all() and tracks["north_m"].isna().all()
    # A track without a position is alerted on its range-only geometry (tests/test_one_channel_alerts.py):
    # every confirmed row is in the alerts, none skipped; in 1 s the range fit has not spanned the 4 s
    # it needs, so no row has a miss distance yet and none alerts.
    alerts = out["alerts"]
    assert len(alerts) == tracks["confirmed"].sum() and (alerts["geometry"] == "range-only").all()
    assert alerts.attrs["rows_skipped_no_state"] == 0
    assert alerts["miss_m"].isna().all() and (alerts["level"] == 0).all()
    assert np.allclose(alerts["range_m"], tracks.loc[tracks["confirmed"], "range_m"])


def test_ura_2x3_direction_error_is_within_a_few_bounds_on_a_clear_sky_target():
    built = Scenario.from_dict(_head_on("ura-2x3", 1.0)).build()
    assert built.radar.n_rx == 6
    out = run_chain(built, with_advice=False)
    det, truth = out["detections"], out["truth"]
    det = det[~det["is_ground"]]
    frame = det["frame"].to_numpy()
    az_true = truth["tgt_azimuth_rad"].values.reshape(truth.sizes["time"], -1)[frame, 0]
    el_true = truth["tgt_elevation_rad"].values.reshape(truth.sizes["time"], -1)[frame, 0]
    sd_az, sd_el = doa_crlb(det["snr_db"].to_numpy(), az_true, el_true, built.radar)
    assert len(det) >= 8
    err_az = det["azimuth_rad"].to_numpy() - az_true
    err_el = det["elevation_rad"].to_numpy() - el_true
    # RMS error within a few bounds (measured 1.3x and 0.5x at 40 dB: 0.085 and 0.052 deg).
    assert np.sqrt(np.mean(err_az**2)) < 3 * np.sqrt(np.mean(sd_az**2))
    assert np.sqrt(np.mean(err_el**2)) < 3 * np.sqrt(np.mean(sd_el**2))


def test_bench_reports_frames_per_second_of_1_6_and_8_channels():
    from skyradar.benchmarks.process import run_arrays

    out = run_arrays(n_cubes=1, n_targets=2, min_time_s=0.05)
    for n_rx in (1, 6, 8):
        assert out[f"rx{n_rx}_frames_per_s"] > 0 and out[f"rx{n_rx}_cpu_frames_per_s"] > 0


def test_larger_arrays_can_null_the_clutter_relief_leaves_and_keep_the_intruder():
    """Over hills, two nulls per cell (the default on any array) leave an eight-channel array's
    cells full of the clutter its aperture resolves; with six (``max_nulls=n_rx - 2``) it detects as
    few cells as the square does with two, and the head-on intruder (3 km to 1.8 km, aliased into
    the ground's band) is detected in every frame either way."""
    from skyradar.benchmarks.process_adaptive import SPEED_MPS, relief_cubes
    from skyradar.process.clutter import clutter_subspace
    from skyradar.process.clutter_suppress import default_max_nulls, suppress_clutter

    assert default_max_nulls(4) == 2 and default_max_nulls(8) == 2

    def detections(layout: str, max_nulls: int | None) -> tuple[list[int], list[bool]]:
        """Cells CFAR detects on each suppressed frame (as the chain's detection step runs it), and
        whether the intruder is among them."""
        config = RadarConfig.prototype_2022(rx_positions_m=layout)
        cubes, agl = relief_cubes(config, 3, 0)
        velocity = np.array([SPEED_MPS, 0.0, 0.0])
        sub = clutter_subspace(config, velocity, config.mount.rotation, agl, n_azimuth=720)
        v_lim = config.v_lim_mps
        aliased = (-2.0 * SPEED_MPS + v_lim) % (2.0 * v_lim) - v_lim  # the closing speed, aliased
        counts, seen = [], []
        for range_m, cube in zip(np.linspace(3000.0, 1800.0, 3), cubes, strict=True):
            det = suppress_clutter(cube, sub, config, max_nulls=max_nulls).detections(config)
            near = np.abs(det.range_m(config) - range_m) < 20.0
            near &= np.abs(det.radial_velocity_mps(config) - aliased) < 1.0
            counts.append(len(det.range_index))
            seen.append(bool(near.any()))
        return counts, seen

    two, two_seen = detections("ura-4x2", None)
    six, six_seen = detections("ura-4x2", 6)
    square, _ = detections("square", None)
    assert all(two_seen) and all(six_seen)
    assert np.mean(six) < 0.6 * np.mean(two)
    assert np.mean(six) < 1.2 * np.mean(square)
