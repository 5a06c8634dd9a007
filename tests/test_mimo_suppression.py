"""Clutter suppression of a time-division MIMO radar's frames: nulls on the virtual channels with the
transmit-slot phase in, the intruder's direction read through them with its residue chosen."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import xarray as xr
import yaml

from cli_helpers import skyradar
from skyradar.config import RadarConfig
from skyradar.process.clutter import clutter_subspace
from skyradar.process.clutter_frames import detect_suppressed
from skyradar.process.clutter_suppress import suppress_clutter
from skyradar.process.doa import angles_from_direction, direction_from_angles
from skyradar.process.pipeline import process_cube

MIMO = RadarConfig.prototype_2022(rx_positions_m="mimo-2x4")
OWN_V = np.array([50.0, 0.0, 0.0])


def _flat_ground_frame(seed: int, az_deg: float, el_deg: float, range_m: float, radial_mps: float):
    """A MIMO frame flying north at 50 m/s, flat ground 300 m below, noise on, and an intruder at
    (az, el) closing at ``radial_mps``; the frame's clutter prediction."""
    from skyradar.scene.terrain import Terrain
    from skyradar.sim.image import ImageSimulator, PlatformState, PointTarget

    terrain = Terrain.projected(np.zeros((400, 400)), 52.0, 4.0, 30.0, 30.0)
    lat, lon = terrain.center_latlon
    sim = ImageSimulator(MIMO, terrain, origin=(lat, lon, 300.0), noise=True, seed=seed)
    u = direction_from_angles(np.radians(az_deg), np.radians(el_deg))
    target = PointTarget(range_m * u, OWN_V + radial_mps * u, rcs_m2=1.0)
    frame = np.asarray(sim.frame(PlatformState(np.zeros(3), OWN_V, np.zeros(3)), [target]))
    return frame, clutter_subspace(MIMO, OWN_V, MIMO.mount.rotation, 300.0)


def _aliased(v: float) -> float:
    return (v + MIMO.v_lim_mps) % (2.0 * MIMO.v_lim_mps) - MIMO.v_lim_mps


@pytest.mark.parametrize(
    ("az_deg", "el_deg", "range_m", "radial_mps", "residue"),
    [(20.0, 7.0, 2000.0, -30.0, 1), (-25.0, -3.0, 1800.0, -60.0, 0)],
)
def test_an_intruder_in_the_folded_ground_band_is_read_through_the_nulls(
    az_deg, el_deg, range_m, radial_mps, residue
):
    # Static points in the field of view close at 17-50 m/s; two transmitters halve the Doppler span
    # to 39.15 m/s, so every Doppler bin holds ground and the intruder (-30 m/s reads +9.2, -60 m/s
    # +18.3) shares its cell with it. Suppressed on the virtual channels with the slot phase in,
    # the ground cells come down to the noise, and the intruder is detected with its direction
    # within 2 deg and the residue of its velocity (-30 = 9.2 - 2 VLim: 1; -60 = 18.3 - 4 VLim: 0).
    truth = np.array([az_deg, el_deg])
    for seed in (1, 2, 3):
        frame, sub = _flat_ground_frame(seed, az_deg, el_deg, range_m, radial_mps)
        sup = suppress_clutter(frame, sub, MIMO)
        raw = np.mean(np.abs(frame) ** 2, axis=-1)
        assert np.median(raw[sub.predicted]) / MIMO.noise_power_w > 10.0
        assert np.median(sup.power[sub.predicted]) / sup.noise_floor_w < 1.3
        found = detect_suppressed(frame, MIMO, sub)
        det = found.detections
        hit = (np.abs(det.radial_velocity_mps(MIMO) - _aliased(radial_mps)) < MIMO.doppler_resolution_mps) & (
            np.abs(det.range_m(MIMO) - range_m) < 30.0  # the range-Doppler coupling moves it up to 17 m
        )
        assert hit.any(), seed
        k = np.flatnonzero(hit)[np.argmax(det.snr_db[hit])]
        got = np.degrees(angles_from_direction(found.directions.u_ant[k : k + 1])).ravel()
        assert np.all(np.abs(got - truth) < 2.0), (seed, got)
        assert found.directions.residue[k] == residue and found.directions.other_residue[k] == 1 - residue
        # the runner-up residue's direction is the mirror along the transmitters: far from the truth
        other = np.degrees(angles_from_direction(found.directions.other_u_ant[k : k + 1])).ravel()
        assert np.abs(other[1] - el_deg) > 20.0


def test_one_transmitter_has_no_runner_up_residue():
    cfg = RadarConfig.prototype_2022()
    sub = clutter_subspace(cfg, OWN_V, cfg.mount.rotation, 300.0)
    rng = np.random.default_rng(0)
    shape = cfg.frame_shape
    cube = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)) * np.sqrt(cfg.noise_power_w / 2)
    found = detect_suppressed(cube.astype(np.complex64), cfg, sub)
    assert np.all(found.directions.residue == 0) and np.all(found.directions.other_residue == -1)
    assert np.isnan(found.directions.other_u_ant).all()
    out = process_cube(cube.astype(np.complex64), cfg, clutter=sub)
    assert np.isnan(out["other_body_m"]).all()


def test_a_mimo_recording_over_terrain_is_processed_with_suppression_through_the_cli(tmp_path):
    # A head-on intruder closing at 55 m/s over flat ground 300 m below: it reads -15.9 m/s, in the
    # folded ground band. Without suppression the ground in its cell and around it raises its CFAR
    # floor; with knowledge-aided suppression it is found in every frame, dead ahead and co-altitude
    # within 3 deg, its SNR at least 6 dB higher, and fewer detections are left on the ground.
    scenario = {
        "name": "mimo-flat",
        "origin": {"lat_deg": 52.5, "lon_deg": 4.36, "alt_m": 0.0},
        "duration_s": 1.0,
        "frame_rate_hz": 5.0,
        "ownship": {"type": "straight", "start_ned_m": [0, 0, -300], "heading_deg": 0, "speed_mps": 50},
        "terrain": {"type": "flat", "size_m": 6000, "spacing_m": 60},
        "radar": {"rx_layout": "mimo-2x4"},
        "intruders": [
            {"name": "head-on", "type": "encounter", "kind": "head-on", "t_cpa_s": 25.0,
             "intruder_speed_mps": 5, "rcs_m2": 1.0},
        ],
    }  # fmt: skip
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(scenario))
    assert skyradar("simulate", "s.yaml", "--output", "r.zarr", cwd=tmp_path).returncode == 0
    truth = xr.open_zarr(tmp_path / "r.zarr", consolidated=False)
    range_m = truth["tgt_range_m"].isel(target=0).values
    v = truth["tgt_radial_velocity_mps"].isel(target=0).values
    found = {}
    for suppression in ("none", "knowledge-aided"):
        out = f"{suppression}.parquet"
        result = skyradar("process", "r.zarr", "--output", out, "--suppression", suppression, cwd=tmp_path)
        assert result.returncode == 0, result.stderr
        det = pd.read_parquet(tmp_path / out)
        f = det["frame"].to_numpy()
        at_intruder = (
            (np.abs(det["range_m"].to_numpy() - range_m[f]) < 30.0)
            & (np.abs(det["radial_velocity_mps"].to_numpy() - np.vectorize(_aliased)(v[f])) < 1.0)
            & (np.abs(np.degrees(det["azimuth_rad"].to_numpy())) < 3.0)
            & (np.abs(np.degrees(det["elevation_rad"].to_numpy())) < 3.0)
        )
        if suppression == "knowledge-aided":
            # The ground below the field of view (the altitude return, within 1.4 heights of
            # range) is read by the field of view as its mirror near the horizontal: ground still,
            # through the runner-up residue's direction (without it, most of these were not).
            near = (det["range_m"] > 290.0) & (det["range_m"] < 1.4 * 300.0) & det["elevation_measured"]
            assert near.sum() > 50 and det.loc[near, "is_ground"].mean() > 0.8
        snr = det.loc[at_intruder].groupby("frame")["snr_db"].max()
        found[suppression] = (snr.reindex(range(5)).to_numpy(), int(det["is_ground"].sum()))
        if suppression == "knowledge-aided":
            assert set(det.loc[at_intruder, "residue"]) == {1}  # -55 = -15.9 - 2 VLim
    assert np.all(found["knowledge-aided"][0] >= np.nan_to_num(found["none"][0], nan=0.0) + 6.0)
    assert found["knowledge-aided"][1] < found["none"][1]
