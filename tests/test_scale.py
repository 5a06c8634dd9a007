"""Scale-out: Dask runs write the same bytes as the plain loop; sweeps; dead schedulers."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pandas as pd
import pytest
import yaml

from skyradar.errors import InputError
from skyradar.io.frames import open_frames
from skyradar.scene.scenario import Scenario
from skyradar.sim.simulate_store import simulate_to_zarr
from skyradar.sim.sweep import parse_values, set_by_path, sweep

SCENARIO = {
    "name": "scale",
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
    "duration_s": 1.2,
    "simulation": {"facet_size_m": 30.0},
}


@pytest.mark.slow
def test_local_cluster_writes_the_same_bytes_as_the_plain_loop(tmp_path):
    built = Scenario.from_dict(SCENARIO, source=tmp_path / "s.yaml").build()
    loop = simulate_to_zarr(built, tmp_path / "loop.zarr", chunk_frames=2)
    dask = simulate_to_zarr(built, tmp_path / "dask.zarr", chunk_frames=2, workers=2)
    a, b = open_frames(loop), open_frames(dask)
    assert a.iq.shape[0] == 6
    assert a.iq.values.tobytes() == b.iq.values.tobytes()
    np.testing.assert_array_equal(a.tgt_range_m.values, b.tgt_range_m.values)


@pytest.mark.slow
def test_dead_scheduler_gives_one_line_and_no_output(tmp_path):
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(SCENARIO))
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "skyradar",
            "simulate",
            "s.yaml",
            "-o",
            "run.zarr",
            "--scheduler",
            "tcp://127.0.0.1:9",
        ],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 2
    assert result.stderr.strip().startswith("error: --scheduler tcp://127.0.0.1:9")
    assert "Traceback" not in result.stderr
    assert not any(tmp_path.glob("run.zarr*"))


def test_sweep_collects_one_table_row_per_run_and_intruder(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump({**SCENARIO, "duration_s": 0.4}))
    table = sweep(path, "intruders.0.rcs_m2", [0.1, 1.0, 10.0])
    assert list(table["intruders.0.rcs_m2"]) == [0.1, 1.0, 10.0]
    expected = table["expected_snr_db_median"].to_numpy()
    np.testing.assert_allclose(np.diff(expected), 10.0, atol=1e-6)  # RCS x10 -> +10 dB
    measured = table["measured_snr_db_median"].to_numpy()
    assert np.all(np.abs(measured - expected) < 1.5)  # noise adds to the pixel, within a dB or so
    assert isinstance(table, pd.DataFrame)


def test_sweep_parameter_paths():
    data = {"intruders": [{"rcs_m2": 1.0}], "terrain": {"type": "fractal"}}
    assert set_by_path(data, "intruders.0.rcs_m2", 5.0)["intruders"][0]["rcs_m2"] == 5.0
    assert set_by_path(data, "terrain.local_sd_m", 19.2)["terrain"]["local_sd_m"] == 19.2
    assert data["terrain"] == {"type": "fractal"}  # the input is not changed
    with pytest.raises(InputError, match="intruders.3"):
        set_by_path(data, "intruders.3.rcs_m2", 1.0)
    assert parse_values("0, 19.2,cosine") == [0, 19.2, "cosine"]


@pytest.mark.slow  # minutes of CPU: `make test-slow` (make test stays under 10 min)
def test_process_on_a_local_cluster_matches_the_plain_loop(tmp_path):
    built = Scenario.from_dict(SCENARIO, source=tmp_path / "s.yaml").build()
    run = simulate_to_zarr(built, tmp_path / "run.zarr", chunk_frames=3)
    tables = {}
    for name, extra in (("loop", []), ("dask", ["--workers", "2", "--chunk-frames", "2"])):
        out = tmp_path / f"{name}.parquet"
        result = subprocess.run(
            [sys.executable, "-m", "skyradar", "process", str(run), "-o", str(out), *extra],
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert result.returncode == 0, result.stderr
        tables[name] = pd.read_parquet(out)
    assert len(tables["loop"]) > 0
    assert sorted(tables["dask"]["frame"].unique()) == list(range(6))
    pd.testing.assert_frame_equal(tables["loop"], tables["dask"])


@pytest.mark.slow  # minutes of CPU: `make test-slow` (make test stays under 10 min)
def test_rd_on_a_local_cluster_matches_the_plain_loop(tmp_path):
    from skyradar.config import RadarConfig
    from skyradar.io.recording_writer import write_recording
    from skyradar.process.rd_store import recording_to_frames

    cfg = RadarConfig.prototype_2022()
    rng = np.random.default_rng(4)
    shape = (5, cfg.n_rx, cfg.n_doppler, cfg.samples_per_chirp)
    adc = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)).astype(np.complex64)
    write_recording(tmp_path / "rec.bin", adc, cfg)
    loop = recording_to_frames(tmp_path / "rec.bin", tmp_path / "loop.zarr", chunk_frames=2)
    dask = recording_to_frames(tmp_path / "rec.bin", tmp_path / "dask.zarr", chunk_frames=2, workers=2)
    assert loop["frames"] == dask["frames"] == 5
    a, b = open_frames(tmp_path / "loop.zarr"), open_frames(tmp_path / "dask.zarr")
    assert a.iq.values.tobytes() == b.iq.values.tobytes()


_PORT_TAKEN = """
import socket, sys, warnings
from skyradar.parallel import close, connect

if __name__ == "__main__":
    taken = socket.socket()
    taken.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        taken.bind(("0.0.0.0", 8787))
        taken.listen()
    except OSError:
        pass  # already taken by another cluster: the situation under test either way
    warnings.simplefilter("default")
    client = connect(None, 1)
    print(client.submit(sum, [1, 2]).result())
    close(client, owns_cluster=True)
    taken.close()
"""


def test_a_local_cluster_starts_quietly_when_the_default_dashboard_port_is_taken(tmp_path):
    # Another Dask cluster on the machine holds port 8787: ours takes a free port for its
    # scheduler's HTTP server and says nothing (a one-line error must stay one line).
    script = tmp_path / "port_taken.py"
    script.write_text(_PORT_TAKEN)
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "3"
    assert "8787" not in done.stderr and "Traceback" not in done.stderr, done.stderr


def test_a_cluster_that_times_out_on_close_is_logged_not_raised(caplog):
    from skyradar.parallel import close

    class Slow:
        def close(self) -> None:
            raise TimeoutError("workers did not stop within 30 s")

    class Client:
        cluster = Slow()

        def close(self) -> None:
            pass

    close(Client(), owns_cluster=True)  # no exception over the written result
    assert "did not shut down cleanly" in caplog.text
