"""`skyradar state` end to end on small simulated runs, including a radar that sees only sky."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from skyradar.config import Mount, RadarConfig
from skyradar.io.frames import frames_dataset
from skyradar.nav.flight_state import estimate_run


def _run(tmp_path, mount: Mount, name: str, n: int = 4, height_m: float = 600.0):
    from skyradar.scene.terrain import flat_terrain
    from skyradar.sim.image import ImageSimulator, PlatformState

    cfg = RadarConfig.seed_prototype(mount=mount, range_limit_m=2500.0)
    terrain = flat_terrain(52.0, 5.0, 0.0, size_m=8000.0)
    sim = ImageSimulator(cfg, terrain, origin=(52.0, 5.0, 0.0), facet_size_m=10.0, seed=1)
    times = np.arange(n, dtype=float)
    cubes, truth = [], {k: [] for k in ("own_vn_mps", "own_vd_mps", "own_height_agl_m", "own_pitch_rad")}
    for i, t in enumerate(times):
        own = PlatformState(
            np.array([-1500.0 + 45.0 * t, 0.0, -height_m]), np.array([45.0, 0.0, 0.0]), np.zeros(3)
        )
        cubes.append(sim.frame(own, frame_index=i))
        for key, value in zip(truth, (45.0, 0.0, height_m, 0.0), strict=True):
            truth[key].append(value)
    ds = frames_dataset(np.stack(cubes), times, cfg, ownship={k: np.array(v) for k, v in truth.items()})
    path = tmp_path / f"{name}.zarr"
    ds.to_zarr(path)
    return ds, path


@pytest.fixture(scope="module")
def ground_run(tmp_path_factory):
    return _run(tmp_path_factory.mktemp("ground"), Mount.preset("forward-down"), "ground")


def test_state_command_writes_table(ground_run, tmp_path):
    _, path = ground_run
    out = tmp_path / "state.parquet"
    proc = subprocess.run(
        [
            sys.executable,
            "-c",
            "from skyradar.cli import main; main()",
            "state",
            str(path),
            "-o",
            str(out),
            "--json",
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    summary = json.loads(proc.stdout.strip().splitlines()[-1])
    table = pd.read_parquet(out)
    columns = [
        "time_s",
        "vx_raw_mps",
        "vz_raw_mps",
        "h_raw_m",
        "h_raw_sd_m",
        "vx_mps",
        "vz_mps",
        "h_m",
        "h_sd_m",
    ]
    assert set(columns + ["quality", "low_quality"]) <= set(table.columns)
    assert summary["low_quality_frames"] == 0
    # Antenna 0.3 m below the reference point; facets of 10 m put the ridge up to a few m short.
    assert np.all(np.abs(table["h_raw_m"] - 600.0) < 6.0)
    assert np.all(np.abs(table["vx_raw_mps"] - 45.0) < 0.3)


@pytest.mark.parametrize("method", ["thesis", "terrain"])
def test_other_methods_run(ground_run, method):
    ds, _ = ground_run
    table = estimate_run(ds, method=method)
    assert len(table) == ds.sizes["time"] and np.isfinite(table["vx_raw_mps"]).all()


def test_sky_only_run_is_flagged_not_wrong(tmp_path):
    # Antenna turned 60 deg up: no ground return above the noise floor.
    ds, path = _run(tmp_path, Mount(position_m=(2.0, 0.0, 0.0), pitch_deg=60.0), "sky", n=2, height_m=1500.0)
    for method in ("robust", "thesis", "terrain"):
        table = estimate_run(ds, method=method)
        assert table["low_quality"].all()
        assert table[["vx_raw_mps", "vz_raw_mps", "h_raw_m", "vx_mps", "h_m"]].isna().all().all()


def test_bad_input_is_one_line_and_exit_2(ground_run, tmp_path):
    _, path = ground_run
    main = "from skyradar.cli import main; main()"
    missing = str(tmp_path / "nope.zarr")
    proc = subprocess.run([sys.executable, "-c", main, "state", missing, "-o", "x.parquet"],
                          capture_output=True, text=True, check=False)  # fmt: skip
    assert (
        proc.returncode == 2
        and proc.stderr.startswith("error:")
        and len(proc.stderr.strip().splitlines()) == 1
    )
    proc = subprocess.run([sys.executable, "-c", main, "state", str(path), "-o", str(tmp_path / "s.parquet"),
                           "--method", "magic"], capture_output=True, text=True, check=False)  # fmt: skip
    assert proc.returncode == 2 and "method" in proc.stderr
