"""`process` gives the same detections however a run is cut: whole, in Dask-sized chunks, in blocks,
or after other runs in the same Python process (the clutter predictions' anchors are the run's own,
walked from its first frame: `skyradar.process.clutter_anchors`)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from skyradar.io.frames import open_frames
from skyradar.process import clutter_frames
from skyradar.process.pipeline import clutter_anchors, navigated_own_state, process_frames
from skyradar.scene.scenario import Scenario
from skyradar.sim.simulate_store import simulate_to_zarr

# Flat ground 500 m below with ga-typical navigation: its GNSS noise moves the anchors between frames.
SCENARIO = {
    "name": "chunks",
    "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    "mount": "forward",
    "terrain": {"type": "flat", "size_m": 3000, "spacing_m": 60},
    "ownship": {"type": "straight", "start_ned_m": [0, 0, -500], "heading_deg": 0, "speed_mps": 40},
    "intruders": [
        {
            "name": "A",
            "type": "encounter",
            "kind": "head-on",
            "t_cpa_s": 30,
            "rcs_m2": 1.0,
            "intruder_speed_mps": 40,
        }
    ],
    "frame_rate_hz": 5.0,
    "duration_s": 2.4,
    "simulation": {"facet_size_m": 30.0},
}


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("chunks")
    built = Scenario.from_dict(SCENARIO, source=tmp / "s.yaml").build()
    return open_frames(simulate_to_zarr(built, tmp / "run.zarr", chunk_frames=4))


@pytest.fixture(scope="module")
def whole(run):
    clutter_frames._CACHE.clear()
    return process_frames(run, suppression="auto")


def test_the_anchors_move_in_this_run(run):
    # The comparison below means something only if frames are predicted at different geometries.
    anchors = clutter_anchors(run)
    assert np.isfinite(anchors).all() and len({tuple(a) for a in anchors}) >= 2


def test_chunks_of_two_frames_give_the_whole_runs_rows(run, whole):
    # A Dask chunk (`process_chunk`) reads the whole run and processes its own frames.
    n = run.sizes["time"]
    parts = [process_frames(run, suppression="auto", frames=slice(s, s + 2)) for s in range(0, n, 2)]
    pd.testing.assert_frame_equal(pd.concat(parts, ignore_index=True), whole)


def test_blocks_with_the_runs_anchors_give_the_whole_runs_rows(run, whole):
    # The encounter chain simulates and processes blocks of frames (skyradar.chain).
    anchors, parts = clutter_anchors(run), []
    for s in range(0, run.sizes["time"], 3):
        block = process_frames(run.isel(time=slice(s, s + 3)), suppression="auto", anchors=anchors[s : s + 3])
        block["frame"] += s
        parts.append(block)
    pd.testing.assert_frame_equal(pd.concat(parts, ignore_index=True), whole)


def test_a_run_processed_after_another_gives_the_same_rows(run, whole):
    # The predictions cached by a run flown 3 % higher were within the reuse tolerance of this one's
    # and served its frames when the cache chose by history.
    higher = run.copy()
    for name in ("own_height_agl_m", "nav_height_agl_m"):
        if name in higher:
            higher[name] = higher[name] * 1.03
    assert navigated_own_state(higher).height_agl_m[0] != navigated_own_state(run).height_agl_m[0]
    clutter_frames._CACHE.clear()
    process_frames(higher, suppression="auto")
    pd.testing.assert_frame_equal(process_frames(run, suppression="auto"), whole)


def test_the_velocity_mean_is_the_last_five_frames_and_a_gap_spoils_only_those():
    from dataclasses import replace

    from skyradar.geo import rotation_matrix
    from skyradar.io.ownship_states import OwnShipStates
    from skyradar.process.clutter_anchors import frame_geometries

    rng = np.random.default_rng(1)
    n = 12
    own = OwnShipStates.from_columns(
        {
            "time_s": np.arange(n) / 9.4,
            "own_north_m": np.zeros(n),
            "own_east_m": np.zeros(n),
            "own_down_m": np.full(n, -400.0),
            "own_vn_mps": 50 + rng.normal(0, 0.2, n),
            "own_ve_mps": rng.normal(0, 0.2, n),
            "own_vd_mps": rng.normal(0, 0.2, n),
            "own_yaw_rad": rng.uniform(-3, 3, n),
            "own_height_agl_m": np.full(n, 400.0),
        }
    )
    got = frame_geometries(own)
    for i in range(n):  # peer: each frame's velocity rotated into its heading-free frame, then averaged
        rows = range(max(i - 4, 0), i + 1)
        v = [rotation_matrix(own.yaw_rad[j], 0.0, 0.0).T @ own.velocity_ned_mps[j] for j in rows]
        np.testing.assert_allclose(got[i, :3], np.mean(v, axis=0), atol=1e-12)
    gap = own.vn_mps.copy()
    gap[3] = np.nan  # a navigation gap
    spoiled = ~np.isfinite(frame_geometries(replace(own, vn_mps=gap))).all(axis=1)
    assert spoiled.tolist() == [i in range(3, 8) for i in range(n)]
