"""No command loses data: outputs are checked before any work, resume never mixes runs,
unfinished stores are refused, and a run that cannot fit on the disk does not start.

Every case goes through the real entry point (``python -m skyradar``) in a subprocess.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from cli_helpers import assert_one_line_error as _assert_one_line_error
from cli_helpers import skyradar as _skyradar
from skyradar.config import RadarConfig
from skyradar.io.frames import FrameStoreWriter, frames_dataset, open_frames
from skyradar.scene.scenario import load_scenario
from skyradar.sim.fingerprint import fingerprint
from skyradar.sim.scenario_frames import make_simulator
from skyradar.sim.simulate_store import _template

TINY = {
    "name": "tiny",
    "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    "mount": "forward",
    "radar": {"range_limit_m": 600.0, "n_doppler": 16},
    "terrain": {"type": "flat", "size_m": 2000, "spacing_m": 100},
    "ownship": {"type": "straight", "start_ned_m": [0, 0, -300], "heading_deg": 0, "speed_mps": 40},
    "frame_rate_hz": 5.0,
    "duration_s": 1.2,
    "simulation": {"facet_size_m": 50.0},
}


def _scenario(folder: Path, data: dict | None = None, name: str = "s.yaml") -> Path:
    path = folder / name
    path.write_text(yaml.safe_dump(data or TINY))
    return path


def _store(path: Path, n: int = 4) -> Path:
    """A small finished frames store (written by frames_dataset + to_zarr, like the test suite's)."""
    cfg = RadarConfig.prototype_2022(range_limit_m=600.0, n_doppler=16)
    rng = np.random.default_rng(0)
    shape = (n, cfg.n_range, cfg.n_doppler, cfg.n_rx)
    iq = (rng.normal(size=shape) + 1j * rng.normal(size=shape)).astype(np.complex64) * 1e-7
    frames_dataset(iq, np.arange(n) * 0.1, cfg).to_zarr(path, consolidated=False)
    return path


def _tree(path: Path) -> dict[str, bytes]:
    """Every file under ``path`` with its bytes (what must survive a refused command)."""
    if path.is_file():
        return {path.name: path.read_bytes()}
    return {str(p.relative_to(path)): p.read_bytes() for p in sorted(path.rglob("*")) if p.is_file()}


# ---- outputs that are inputs, or that skyradar did not write -------------------------------------


def test_simulate_refuses_an_existing_folder_and_keeps_it(tmp_path):
    scenario = _scenario(tmp_path)
    (tmp_path / "photos").mkdir()
    (tmp_path / "photos" / "a.jpg").write_bytes(b"precious")
    result = _skyradar("simulate", str(scenario), "-o", "photos/", cwd=tmp_path)
    _assert_one_line_error(result, "photos", "--overwrite")
    assert (tmp_path / "photos" / "a.jpg").read_bytes() == b"precious"


def test_simulate_into_parent_refused_and_parent_kept(tmp_path):
    sub = tmp_path / "work"
    sub.mkdir()
    scenario = _scenario(sub)
    (tmp_path / "other.txt").write_text("keep")
    before = _tree(tmp_path)
    result = _skyradar("simulate", str(scenario), "-o", "..", cwd=sub)
    _assert_one_line_error(result, "..")
    assert _tree(tmp_path) == before


def test_simulate_onto_its_scenario_refused(tmp_path):
    scenario = _scenario(tmp_path)
    before = scenario.read_bytes()
    _assert_one_line_error(_skyradar("simulate", "s.yaml", "-o", "s.yaml", cwd=tmp_path), "s.yaml", "input")
    # Even --overwrite never replaces an input.
    result = _skyradar("simulate", "s.yaml", "-o", "./s.yaml", "--overwrite", cwd=tmp_path)
    _assert_one_line_error(result, "s.yaml", "input")
    assert scenario.read_bytes() == before


def test_simulate_refuses_partial_name_and_symlink_to_input(tmp_path):
    _scenario(tmp_path)
    _assert_one_line_error(
        _skyradar("simulate", "s.yaml", "-o", "run.zarr.partial", cwd=tmp_path),
        "run.zarr.partial",
        ".partial",
    )
    (tmp_path / "link").symlink_to(tmp_path / "s.yaml")
    _assert_one_line_error(
        _skyradar("simulate", "s.yaml", "-o", "link", "--overwrite", cwd=tmp_path), "link", "input"
    )
    assert (tmp_path / "s.yaml").is_file()


def test_rd_onto_its_recording_refused(tmp_path):
    cfg = RadarConfig.prototype_2022()
    rec = tmp_path / "rec.npy"
    np.save(rec, np.ones((2, cfg.n_rx, 8, cfg.samples_per_chirp), np.complex64))
    before = rec.read_bytes()
    _assert_one_line_error(_skyradar("rd", "rec.npy", "-o", "rec.npy", cwd=tmp_path), "rec.npy", "input")
    assert rec.read_bytes() == before


def test_process_onto_its_run_refused(tmp_path):
    run = _store(tmp_path / "run.zarr")
    before = _tree(run)
    for extra in ((), ("--overwrite",)):
        result = _skyradar("process", "run.zarr", "-o", "run.zarr", *extra, cwd=tmp_path)
        _assert_one_line_error(result, "run.zarr", "input")
        assert _tree(run) == before


def test_track_onto_its_detections_refused(tmp_path):
    detections = tmp_path / "det.parquet"
    pd.DataFrame({"time_s": [0.0], "range_m": [100.0], "radial_velocity_mps": [1.0]}).to_parquet(detections)
    before = detections.read_bytes()
    _assert_one_line_error(_skyradar("track", "det.parquet", "-o", "det.parquet", cwd=tmp_path), "input")
    assert detections.read_bytes() == before


def test_table_output_over_a_foreign_file_needs_overwrite(tmp_path):
    _store(tmp_path / "run.zarr")
    (tmp_path / "notes.parquet").write_text("my notes")
    result = _skyradar("state", "run.zarr", "-o", "notes.parquet", cwd=tmp_path)
    _assert_one_line_error(result, "notes.parquet", "--overwrite")
    assert (tmp_path / "notes.parquet").read_text() == "my notes"


def test_experiment_refuses_a_foreign_folder(tmp_path):
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "thesis.tex").write_text("keep")
    result = _skyradar("experiment", "ch2", "--output", "mine", "--frames", "1", cwd=tmp_path)
    _assert_one_line_error(result, "mine", "--overwrite")
    assert sorted(p.name for p in (tmp_path / "mine").iterdir()) == ["thesis.tex"]


@pytest.mark.slow
def test_simulate_replaces_its_own_run_and_a_foreign_one_only_with_overwrite(tmp_path):
    _scenario(tmp_path)
    assert _skyradar("simulate", "s.yaml", "-o", "run.zarr", cwd=tmp_path).returncode == 0
    # A run skyradar wrote is replaced without --overwrite, at the end, and nothing is left aside.
    again = _skyradar("simulate", "s.yaml", "-o", "run.zarr", cwd=tmp_path)
    assert again.returncode == 0, again.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.zarr", "s.yaml"]
    (tmp_path / "old").mkdir()
    (tmp_path / "old" / "x").write_text("x")
    result = _skyradar("simulate", "s.yaml", "-o", "old", "--overwrite", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert open_frames(tmp_path / "old").sizes["time"] == 6
    assert not (tmp_path / "old" / "x").exists()


# ---- resume never mixes runs ------------------------------------------------------------------


def _interrupted(scenario: Path, out: Path, chunk_frames: int) -> np.ndarray:
    """A partial store of ``scenario`` with only chunk 0 written (a sentinel value)."""
    built = load_scenario(scenario).build()
    template = _template(built, chunk_frames, make_simulator(built))
    writer = FrameStoreWriter(out, template, chunk_frames, fingerprint(built))
    sentinel = np.full((chunk_frames, *template.iq.shape[1:]), 7 + 7j, np.complex64)
    writer.write_chunk(0, sentinel)
    return sentinel


def test_resume_with_another_chunk_size_starts_afresh(tmp_path):
    scenario = _scenario(tmp_path)
    _interrupted(scenario, tmp_path / "run.zarr", chunk_frames=2)
    result = _skyradar("simulate", "s.yaml", "-o", "run.zarr", "--chunk-frames", "4", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    iq = open_frames(tmp_path / "run.zarr").iq.values
    assert np.all(np.abs(iq).reshape(iq.shape[0], -1).max(axis=1) > 0)  # no frame left all zeros
    assert not np.any(iq == 7 + 7j)
    assert "discarding" in result.stderr


def test_resume_after_a_referenced_file_changed_starts_afresh(tmp_path):
    own = tmp_path / "own.csv"

    def write_ownship(alt_ft: float) -> None:
        rows = [f"{1700000000 + k},aaaaaa,OWN,{52.0 + k * 4e-4},4.36,{alt_ft},80,0,0" for k in range(6)]
        head = "timestamp,icao24,callsign,latitude,longitude,altitude,groundspeed,track,vertical_rate\n"
        own.write_text(head + "\n".join(rows) + "\n")

    write_ownship(1000.0)
    scenario = _scenario(tmp_path, {**TINY, "ownship": "own.csv"})
    _interrupted(scenario, tmp_path / "run.zarr", chunk_frames=2)
    write_ownship(1500.0)  # the user edits the own-ship track, then reruns the same command
    result = _skyradar("simulate", "s.yaml", "-o", "run.zarr", "--chunk-frames", "2", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert not np.any(open_frames(tmp_path / "run.zarr").iq.values == 7 + 7j)  # no old frames mixed in
    assert "discarding" in result.stderr


def test_same_job_still_resumes(tmp_path):
    scenario = _scenario(tmp_path)
    sentinel = _interrupted(scenario, tmp_path / "run.zarr", chunk_frames=2)
    result = _skyradar("simulate", "s.yaml", "-o", "run.zarr", "--chunk-frames", "2", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    np.testing.assert_array_equal(open_frames(tmp_path / "run.zarr").iq.values[:2], sentinel)


def test_foreign_partial_is_not_discarded(tmp_path):
    _scenario(tmp_path)
    (tmp_path / "run.zarr.partial").mkdir()
    (tmp_path / "run.zarr.partial" / "data.txt").write_text("keep")
    result = _skyradar("simulate", "s.yaml", "-o", "run.zarr", cwd=tmp_path)
    _assert_one_line_error(result, "run.zarr.partial", "move it away")
    assert (tmp_path / "run.zarr.partial" / "data.txt").read_text() == "keep"


# ---- unfinished stores are refused by readers ------------------------------------------------------


def test_process_refuses_a_partial_store(tmp_path):
    _interrupted(_scenario(tmp_path), tmp_path / "run.zarr", chunk_frames=2)
    result = _skyradar("process", "run.zarr.partial", "-o", "d.parquet", cwd=tmp_path)
    _assert_one_line_error(result, "run.zarr.partial", "unfinished", "rerun")
    assert not (tmp_path / "d.parquet").exists()


def test_state_refuses_an_unfinished_store_renamed_by_hand(tmp_path):
    _interrupted(_scenario(tmp_path), tmp_path / "run.zarr", chunk_frames=2)
    (tmp_path / "run.zarr.partial").rename(tmp_path / "copy.zarr")
    result = _skyradar("state", "copy.zarr", "-o", "s.parquet", cwd=tmp_path)
    _assert_one_line_error(result, "copy.zarr", "unfinished", "rerun")


# ---- disk space ---------------------------------------------------------------------------------


def test_simulate_refuses_a_run_that_cannot_fit(tmp_path):
    # A slow own-ship: the run is absurdly long (13 TB of frames), the flight itself plausible.
    slow = {**TINY["ownship"], "speed_mps": 0.01}
    _scenario(tmp_path, {**TINY, "radar": {}, "duration_s": 1e6, "ownship": slow})
    result = _skyradar("simulate", "s.yaml", "-o", "run.zarr", cwd=tmp_path, timeout=120)
    _assert_one_line_error(result, "run.zarr", "GB", "free")
    assert not any(tmp_path.glob("run.zarr*"))


# ---- compressed store -----------------------------------------------------------------------------


@pytest.mark.slow
def test_compressed_store_reads_back_identical(tmp_path):
    _scenario(tmp_path)
    for codec in ("none", "blosc"):
        result = _skyradar("simulate", "s.yaml", "-o", f"{codec}.zarr", "--compress", codec, cwd=tmp_path)
        assert result.returncode == 0, result.stderr
    raw, packed = (open_frames(tmp_path / f"{c}.zarr").iq.values for c in ("none", "blosc"))
    np.testing.assert_array_equal(raw, packed)
    _assert_one_line_error(
        _skyradar("simulate", "s.yaml", "-o", "x.zarr", "--compress", "lzw", cwd=tmp_path),
        "--compress",
        "lzw",
    )


def test_rd_resume_key_covers_sidecar_data_file_and_chunking(tmp_path):
    from skyradar.io.recording_writer import write_recording
    from skyradar.io.recordings import read_recording
    from skyradar.process.rd_store import _fingerprint, recording_files

    cfg = RadarConfig.prototype_2022(n_doppler=8)
    write_recording(tmp_path / "rec.bin", np.ones((2, 4, 8, cfg.samples_per_chirp), np.complex64), cfg)
    frames, _ = read_recording(tmp_path / "rec.json")
    files = recording_files(tmp_path / "rec.json", frames)
    assert {f.name for f in files} == {"rec.json", "rec.bin"}
    before = _fingerprint(files, {"chunk": 32})
    sidecar = tmp_path / "rec.json"
    sidecar.write_text(sidecar.read_text() + "\n")  # an edited sidecar is another job
    assert _fingerprint(files, {"chunk": 32}) != before
    assert _fingerprint(files, {"chunk": 16}) != _fingerprint(files, {"chunk": 32})
