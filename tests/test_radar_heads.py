"""Several radar heads: scenario radars:, the multi-head store, process, fused tracking."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from cli_helpers import assert_one_line_error, skyradar
from skyradar.chain import label_tracks, run_chain
from skyradar.config import Mount
from skyradar.errors import InputError
from skyradar.geo import rotation_matrix
from skyradar.io.frames import open_frames
from skyradar.io.frames_heads import store_heads
from skyradar.io.safe_yaml import load_yaml
from skyradar.process.detect_run import detect_run_heads
from skyradar.scene.examples import THREE_HEAD_RADARS
from skyradar.scene.scenario import Scenario, example_scenario, load_scenario
from skyradar.sim.scenario_frames import simulate
from skyradar.sim.simulate_store import simulate_to_zarr
from skyradar.track.track_table import OWNSHIP_COLUMNS, track_detections


def _spec(**changes) -> dict:
    spec = {
        "name": "two heads",
        "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
        "radar": {"range_limit_m": 1500},
        "radars": [
            {"name": "nose", "mount": "nose"},
            {"name": "left", "mount": {"preset": "left-wingtip", "lever_arm_m": [0.5, -6.0, 0.0]}},
        ],
        "ownship": {"type": "straight", "start_ned_m": [0, 0, -2000], "speed_mps": 50},
        "intruders": [
            {
                "name": "A",
                "type": "straight",
                "start_ned_m": [600, -600, -2000],
                "heading_deg": 90,
                "speed_mps": 40,
            },
        ],
        "frame_rate_hz": 9.4,
        "duration_s": 0.25,
    }
    return spec | changes


# ---- scenario ---------------------------------------------------------------------------------
def test_radars_list_builds_named_heads_with_mounts_lever_arms_and_overrides():
    spec = _spec()
    spec["radars"][1]["radar"] = {"pe_dbm": 37.0}
    built = Scenario.from_dict(spec).build()
    nose, left = built.heads
    assert (nose.name, left.name) == ("nose", "left") and built.radar == nose.config
    assert nose.config.mount == Mount.preset("nose") == Mount.preset("forward")
    assert left.config.mount == Mount((0.5, -6.0, 0.0), -75.0, 0.0, 0.0)
    assert (nose.config.pe_dbm, left.config.pe_dbm, left.config.range_limit_m) == (40.0, 37.0, 1500.0)


def test_no_radars_list_is_one_head_at_the_top_level_mount():
    spec = _spec(mount="forward-down")
    del spec["radars"]
    built = Scenario.from_dict(spec).build()
    assert [h.name for h in built.heads] == ["radar"] and built.heads[0].config.mount == Mount.preset(
        "forward-down"
    )


def test_three_head_layout_covers_plus_minus_110_deg():
    built = load_scenario(example_scenario("three_heads_crossing")).build()
    assert [h.name for h in built.heads] == [r["name"] for r in THREE_HEAD_RADARS]
    # Beam edges (+-35 deg about each head's yaw) leave no gap wider than 5 deg up to +-110 deg.
    edges = sorted((h.config.mount.yaw_deg - 35.0, h.config.mount.yaw_deg + 35.0) for h in built.heads)
    assert edges[0][0] <= -110.0 and edges[-1][1] >= 110.0
    assert all(b[0] - a[1] <= 5.0 for a, b in zip(edges, edges[1:], strict=False))


@pytest.mark.parametrize(
    ("change", "needles"),
    [
        (
            {"radars": [{"name": "a", "mount": "nose"}, {"name": "a", "mount": "tail"}]},
            ["radars.1.name", "twice"],
        ),
        ({"radars": [{"name": "a", "mount": "belly"}]}, ["radars.0.mount.preset", "belly"]),
        ({"radars": [{"name": "a", "mount": {"lever_arm_m": [1, 2]}}]}, ["radars.0.mount.lever_arm_m"]),
        ({"radars": [{"name": "a", "mount": "nose"}], "mount": "forward"}, ["'mount'", "radars"]),
        ({"radars": []}, ["radars"]),
        (
            {"radars": [{"name": "a", "mount": {"lever_arm_m": [1, 2, 3], "position_m": [1, 2, 3]}}]},
            ["radars.0.mount", "not both"],
        ),
        (
            {"radars": [{"name": "a", "mount": "nose", "radar": {"n_doppler": 1}}]},
            ["radars.0.radar.n_doppler"],
        ),
    ],
)
def test_bad_radars_are_one_line_naming_the_field(change, needles):
    with pytest.raises(InputError) as err:
        Scenario.from_dict(_spec(**change), source="s.yaml").build()
    msg = str(err.value)
    assert "\n" not in msg and msg.startswith("s.yaml") and all(n in msg for n in needles), msg


def test_bad_radars_through_the_command_line(tmp_path):
    (tmp_path / "s.yaml").write_text(
        "origin: {lat_deg: 52, lon_deg: 4}\nduration_s: 1\n"
        "ownship: {type: straight, speed_mps: 50, start_ned_m: [0, 0, -500]}\n"
        "radars: [{name: nose, mount: nose}, {name: nose, mount: left-wingtip}]\n"
    )
    result = skyradar("simulate", "s.yaml", "-o", "run.zarr", cwd=tmp_path)
    assert_one_line_error(result, "s.yaml", "radars.1.name", "twice")
    assert not (tmp_path / "run.zarr").exists()


# ---- store and process --------------------------------------------------------------------------
def test_two_head_store_round_trip_and_process(tmp_path):
    built = Scenario.from_dict(_spec()).build()
    path = simulate_to_zarr(built, tmp_path / "run.zarr", chunk_frames=1)
    assert store_heads(path) == ["nose", "left"]
    for head in ("nose", "left"):
        ds, mem = open_frames(path, head=head), simulate(built, head=head)
        assert ds.attrs["radar_head"] == head and ds.sizes == mem.sizes
        np.testing.assert_array_equal(ds.iq.values, mem.iq.values)
        np.testing.assert_array_equal(ds.tgt_azimuth_rad.values, mem.tgt_azimuth_rad.values)
    assert open_frames(path).attrs["radar_head"] == "nose"  # default: the first head
    with pytest.raises(InputError, match="'tail' unknown"):
        open_frames(path, head="tail")
    det, configs = detect_run_heads(path)
    assert list(configs) == ["nose", "left"] and set(det["radar"]) == {"nose", "left"}
    assert np.all(np.diff(det["time_s"].to_numpy()) >= 0)
    # Each head locates the intruder in the world frame (lever arm and mount applied).
    truth = open_frames(path)
    for _, row in det.iterrows():
        want = [truth[f"tgt_{a}_m"].values[row["frame"], 0] for a in ("north", "east", "down")]
        assert np.linalg.norm(row[["north_m", "east_m", "down_m"]].to_numpy(float) - want) < 100.0
    # The left head's body-frame position starts at its lever arm: range x direction + arm.
    left = det[det["radar"] == "left"].iloc[0]
    body = left[["x_body_m", "y_body_m", "z_body_m"]].to_numpy(float)
    assert abs(np.linalg.norm(body - np.array([0.5, -6.0, 0.0])) - left["range_m"]) < 1e-6


# ---- fused tracking: the handover -----------------------------------------------------------------
def _head_detections(built, beam_deg: float = 45.0, seed: int = 0) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Detections each head would make of the intruder (inside +-beam_deg of its boresight), with noise.

    Range from each head's own antenna (lever arm), radial velocity wrapped into the Doppler width,
    DoA position with 2 deg angle noise; and the own-ship table.
    """
    rng = np.random.default_rng(seed)
    t = built.times_s
    own, tgt = built.ownship.sample(t), built.intruders[0].trajectory.sample(t)
    rows = []
    for k in range(t.size):
        b2n = rotation_matrix(*own.attitude_rad[k])
        for head in built.heads:
            cfg = head.config
            antenna = own.position_ned_m[k] + b2n @ np.asarray(cfg.mount.position_m)
            los = tgt.position_ned_m[k] - antenna
            u_ant = (b2n @ cfg.mount.rotation).T @ (los / np.linalg.norm(los))
            if np.degrees(abs(np.arctan2(u_ant[1], u_ant[0]))) > beam_deg:
                continue
            r = np.linalg.norm(los) + rng.normal(0.0, 3.0)
            vr = (tgt.velocity_ned_mps[k] - own.velocity_ned_mps[k]) @ los / np.linalg.norm(los)
            width = 2.0 * cfg.v_lim_mps
            vr = (vr + rng.normal(0.0, 0.2) + width / 2) % width - width / 2
            u_noisy = u_ant + rng.normal(0.0, np.radians(2.0), 3)
            u_noisy /= np.linalg.norm(u_noisy)
            body = np.asarray(cfg.mount.position_m) + r * (cfg.mount.rotation @ u_noisy)
            ned = own.position_ned_m[k] + b2n @ body
            rows.append((t[k], k, head.name, r, vr, 20.0, *body, *ned))
    cols = [
        "time_s",
        "frame",
        "radar",
        "range_m",
        "radial_velocity_mps",
        "snr_db",
        "x_body_m",
        "y_body_m",
        "z_body_m",
        "north_m",
        "east_m",
        "down_m",
    ]
    own_table = pd.DataFrame(
        np.column_stack([t, own.position_ned_m, own.velocity_ned_mps]), columns=list(OWNSHIP_COLUMNS)
    )
    return pd.DataFrame(rows, columns=cols), own_table


@pytest.fixture(scope="module")
def crossing():
    built = load_scenario(example_scenario("three_heads_crossing")).build()
    return (built, *_head_detections(built))


def test_crossing_intruder_keeps_one_track_id_from_left_head_to_nose(crossing):
    built, det, own = crossing
    counts = det.groupby("radar")["frame"].agg(["min", "max"])
    # The geometry: the left head first, then both (beams overlap 30..45 deg), then the nose only.
    assert counts.loc["left", "min"] == 0 and counts.loc["nose", "max"] == built.times_s.size - 1
    assert counts.loc["nose", "min"] < counts.loc["left", "max"]
    tracks = track_detections(det, config=built.radar, frame_times_s=built.times_s, ownship=own)
    confirmed = tracks[tracks["confirmed"]]
    assert confirmed["track_id"].nunique() == 1
    used = det.iloc[tracks["detection_row"][tracks["detection_row"] >= 0].to_numpy()]
    assert set(used["radar"]) == {"left", "nose"}
    # It follows the intruder through the handover, in range and in 3-D.
    tid = confirmed["track_id"].iloc[0]
    one = tracks[tracks["track_id"] == tid]
    assert one["time_s"].min() < 1.0 and one["time_s"].max() > built.times_s[-1] - 0.2
    truth = built.intruders[0].trajectory.sample(one["time_s"].to_numpy()).position_ned_m
    err = np.linalg.norm(one[["north_m", "east_m", "down_m"]].to_numpy() - truth, axis=1)
    assert np.median(err) < 60.0


def test_without_fusion_the_overlap_gives_duplicate_tracks(crossing):
    # Control: the same detections as one head's (duplicates not merged) break the single track.
    built, det, own = crossing
    tracks = track_detections(
        det.drop(columns="radar"), config=built.radar, frame_times_s=built.times_s, ownship=own
    )
    assert tracks[tracks["confirmed"]]["track_id"].nunique() > 1


def test_example_yaml_lists_the_three_head_layout():
    path = example_scenario("three_heads_crossing")
    assert load_yaml(path.read_text(), path)["radars"] == THREE_HEAD_RADARS


@pytest.mark.slow
def test_full_chain_handover_left_head_to_nose_keeps_one_track_id():
    # The acceptance point on the whole chain (simulate -> process -> fused track), nose and left heads
    # of three_heads_crossing: 470 frames x 2 heads, a few minutes.
    built = load_scenario(example_scenario("three_heads_crossing")).build()
    out = run_chain(built, heads=["nose", "left"], with_advice=False)
    labels = label_tracks(out["tracks"], out["truth"])
    mine = [tid for tid, name in labels.items() if name == "crossing-left"]
    assert len(mine) == 1
    det = out["detections"]  # the tracks' detection_row indexes this table
    one = out["tracks"][out["tracks"]["track_id"] == mine[0]]
    used = det.iloc[one["detection_row"][one["detection_row"] >= 0].to_numpy()]
    first = used.groupby("radar")["time_s"].min()
    assert first["left"] < 1.0 and first["nose"] > first["left"]  # the left head first, then the nose
    assert one["time_s"].max() > built.times_s[-1] - 1.0  # to the end, as the nose's (and left's) track


@pytest.mark.parametrize("precision", ["complex64", "cint16"])
def test_multi_head_store_resumes_and_keeps_each_head(tmp_path, precision):
    import dask.array as da

    from skyradar.config import RadarConfig
    from skyradar.io.frames import FrameStoreWriter, frames_dataset

    cfg = RadarConfig.prototype_2022(range_limit_m=300.0, n_doppler=8)
    shape = (3, cfg.n_range, cfg.n_doppler, cfg.n_rx)
    times = np.arange(3) * 0.1
    templates = {
        h: frames_dataset(da.zeros(shape, dtype=np.complex64, chunks=(2, -1, -1, -1)), times, cfg)
        for h in ("nose", "tail")
    }
    rng = np.random.default_rng(1)
    cubes = {
        h: (rng.normal(size=shape) + 1j * rng.normal(size=shape)).astype(np.complex64) for h in templates
    }
    path = tmp_path / "run.zarr"
    first = FrameStoreWriter(path, templates, 2, "job", precision=precision)
    first.write_chunk(0, {h: c[:2] for h, c in cubes.items()})  # then "interrupted"
    again = FrameStoreWriter(path, templates, 2, "job", precision=precision)
    assert again.pending_chunks() == [1]  # resumed, not restarted
    again.write_chunk(1, {h: c[2:] for h, c in cubes.items()})
    again.close()
    for h, cube in cubes.items():  # each head reads back as that head's frames written alone
        alone = FrameStoreWriter(tmp_path / f"{h}.zarr", templates[h], 2, "job", precision=precision)
        alone.write_chunk(0, cube[:2])
        alone.write_chunk(1, cube[2:])
        want = open_frames(alone.close()).iq.values
        np.testing.assert_array_equal(open_frames(path, head=h).iq.values, want)
        assert precision == "cint16" or np.array_equal(want, cube)
