"""`skyradar state` end to end on small simulated runs, including a radar that sees only sky."""

from __future__ import annotations

import json
import sys

import numpy as np
import pandas as pd
import pytest

from skyradar.config import Mount, RadarConfig
from skyradar.io.frames import frames_dataset
from skyradar.nav.flight_state import estimate_run
from test_flight_state_ridge import CFG, flat_ground_cube


def _simulated_run(tmp_path, mount: Mount, name: str, n: int = 4, height_m: float = 600.0):
    """A run from the image simulator over flat ground (first use compiles its kernel: slow)."""
    from skyradar.scene.synthetic_terrain import flat_terrain
    from skyradar.sim.image import ImageSimulator, PlatformState

    cfg = RadarConfig.prototype_2022(mount=mount, range_limit_m=2500.0)
    terrain = flat_terrain(52.0, 5.0, 0.0, size_m=8000.0)
    sim = ImageSimulator(cfg, terrain, origin=(52.0, 5.0, 0.0), facet_size_m=10.0, seed=1)
    times = np.arange(n, dtype=float)
    cubes = []
    for i, t in enumerate(times):
        own = PlatformState(
            np.array([-1500.0 + 45.0 * t, 0.0, -height_m]), np.array([45.0, 0.0, 0.0]), np.zeros(3)
        )
        cubes.append(sim.frame(own, frame_index=i))
    ds = frames_dataset(np.stack(cubes), times, cfg, ownship={"own_height_agl_m": np.full(n, height_m)})
    ds.to_zarr(tmp_path / f"{name}.zarr", consolidated=False)
    return ds


@pytest.fixture(scope="module")
def ground_run(tmp_path_factory):
    """Three frames of the flat-plane images of test_flight_state_ridge: 45 m/s, 600 m (antenna)."""
    cubes = np.stack([flat_ground_cube(45.0, 0.0, 600.0, seed=s) for s in range(3)])
    truth = {"own_height_agl_m": np.full(3, 600.0), "own_pitch_rad": np.zeros(3)}
    ds = frames_dataset(cubes, np.arange(3.0), CFG, ownship=truth)
    path = tmp_path_factory.mktemp("ground") / "ground.zarr"
    ds.to_zarr(path, consolidated=False)
    return ds, path


def _main(monkeypatch, capsys, *args):
    """Run the `skyradar` entry point in-process; returns (exit code, stdout, stderr)."""
    from skyradar.cli import main

    monkeypatch.setattr(sys, "argv", ["skyradar", *args])
    code = 0
    try:
        main()
    except SystemExit as exc:
        code = exc.code
    out = capsys.readouterr()
    return code, out.out, out.err


def test_state_command_writes_table(ground_run, tmp_path, monkeypatch, capsys):
    _, path = ground_run
    out = tmp_path / "state.parquet"
    code, stdout, stderr = _main(monkeypatch, capsys, "state", str(path), "-o", str(out), "--json")
    assert code == 0, stderr
    summary = json.loads(stdout.strip().splitlines()[-1])
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
    # The reference point is 0.3 m above the antenna of the forward-down mount.
    assert np.all(np.abs(table["h_raw_m"] - 600.3) < 4.0)
    assert np.all(np.abs(table["vx_raw_mps"] - 45.0) < 0.3)


@pytest.mark.parametrize("method", ["thesis", "terrain"])
def test_other_methods_run(ground_run, method):
    ds, _ = ground_run
    table = estimate_run(ds, method=method)
    assert len(table) == ds.sizes["time"] and np.isfinite(table["vx_raw_mps"]).all()


def test_noise_only_run_is_flagged_not_wrong(tmp_path):
    rng = np.random.default_rng(0)
    shape = (3, CFG.n_range, CFG.n_doppler, CFG.n_rx)
    cubes = np.sqrt(CFG.noise_power_w / 2) * (rng.standard_normal(shape) + 1j * rng.standard_normal(shape))
    ds = frames_dataset(cubes.astype(np.complex64), np.arange(3.0), CFG)
    for method in ("robust", "thesis", "terrain"):
        table = estimate_run(ds, method=method)
        assert table["low_quality"].all() and (table["quality"] == 0).all()
        assert table[["vx_raw_mps", "vz_raw_mps", "h_raw_m", "vx_mps", "h_m"]].isna().all().all()


@pytest.mark.slow
def test_simulated_sky_only_run_is_flagged_not_wrong(tmp_path):
    # Antenna turned 60 deg up at 1500 m: the ground stays below the noise floor.
    ds = _simulated_run(
        tmp_path, Mount(position_m=(2.0, 0.0, 0.0), pitch_deg=60.0), "sky", n=2, height_m=1500.0
    )
    for method in ("robust", "thesis", "terrain"):
        table = estimate_run(ds, method=method)
        assert table["low_quality"].all()
        assert table[["vx_raw_mps", "vz_raw_mps", "h_raw_m", "vx_mps", "h_m"]].isna().all().all()


def test_bad_input_is_one_line_and_exit_2(ground_run, tmp_path, monkeypatch, capsys):
    _, path = ground_run
    code, _, err = _main(monkeypatch, capsys, "state", str(tmp_path / "nope.zarr"), "-o", "x.parquet")
    assert code == 2 and err.startswith("error:") and len(err.strip().splitlines()) == 1
    code, _, err = _main(
        monkeypatch, capsys, "state", str(path), "-o", str(tmp_path / "s.parquet"), "--method", "x"
    )
    assert code == 2 and "method" in err and not (tmp_path / "s.parquet").exists()
