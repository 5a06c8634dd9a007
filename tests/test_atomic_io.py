"""Atomic writers (unique temporary names, nothing left after a crash) and streamed recordings."""

from __future__ import annotations

import json
import os
import re
import tracemalloc
from pathlib import Path

import matplotlib
import numpy as np
import pandas as pd
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from skyradar.config import RadarConfig  # noqa: E402
from skyradar.errors import InputError  # noqa: E402
from skyradar.io import recording_writer, recordings  # noqa: E402
from skyradar.io.json_results import write_json_atomic
from skyradar.io.recording_writer import write_recording  # noqa: E402
from skyradar.io.recordings import read_recording  # noqa: E402
from skyradar.io.tables import read_table, write_table  # noqa: E402

SRC = Path(__file__).resolve().parents[1] / "src" / "skyradar"


def _crash_after_partial_write(self, path, *args, **kwargs):
    Path(path).write_bytes(b"half a file")
    raise OSError("disk full")


def test_crashed_table_write_leaves_target_and_no_temporary(tmp_path, monkeypatch):
    target = tmp_path / "t.parquet"
    write_table(pd.DataFrame({"a": [1, 2]}), target)
    monkeypatch.setattr(pd.DataFrame, "to_parquet", _crash_after_partial_write)
    with pytest.raises(OSError, match="disk full"):
        write_table(pd.DataFrame({"a": [9]}), target)
    monkeypatch.undo()
    assert [p.name for p in tmp_path.iterdir()] == ["t.parquet"]  # no t.parquet.tmp left behind
    assert read_table(target)["a"].tolist() == [1, 2]


def test_two_writers_of_one_table_do_not_share_a_temporary(tmp_path, monkeypatch):
    # Writer A is interrupted mid-write by writer B of the same target (another process, say).
    # With a fixed name B renames A's temporary away and A fails; with unique names both finish.
    target = tmp_path / "t.parquet"
    original = pd.DataFrame.to_parquet
    calls = []

    def interleaved(self, path, *args, **kwargs):
        calls.append(path)
        original(self, path, *args, **kwargs)
        if len(calls) == 1:
            write_table(pd.DataFrame({"a": [2]}), target)

    monkeypatch.setattr(pd.DataFrame, "to_parquet", interleaved)
    write_table(pd.DataFrame({"a": [1]}), target)
    monkeypatch.undo()
    assert calls[0] != calls[1]
    assert read_table(target)["a"].tolist() == [1]  # the last to finish wins, whole
    assert [p.name for p in tmp_path.iterdir()] == ["t.parquet"]


def test_json_write_crash_keeps_old_file(tmp_path):
    target = tmp_path / "s.json"
    write_json_atomic(target, {"x": 1.0, "bad": float("nan")})
    assert json.loads(target.read_text()) == {"x": 1.0, "bad": None}
    with pytest.raises(TypeError):
        write_json_atomic(target, {"x": object()})
    assert json.loads(target.read_text())["x"] == 1.0
    assert [p.name for p in tmp_path.iterdir()] == ["s.json"]


def test_written_files_get_the_usual_permissions(tmp_path):
    umask = os.umask(0)
    os.umask(umask)
    path = write_json_atomic(tmp_path / "s.json", {})
    assert path.stat().st_mode & 0o777 == 0o666 & ~umask  # not mkstemp's 0o600


def test_crashed_figure_leaves_no_temporary(tmp_path, monkeypatch):
    from skyradar.viz.rangedoppler import save_frame_figure

    cfg = RadarConfig.prototype_2022(n_doppler=8, range_limit_m=300.0)
    frame = np.ones((cfg.n_range, cfg.n_doppler, cfg.n_rx), np.complex64)
    target = tmp_path / "f.png"
    target.write_bytes(b"old figure")
    monkeypatch.setattr(Figure, "savefig", _crash_after_partial_write)
    with pytest.raises(OSError, match="disk full"):
        save_frame_figure(frame, cfg, target)
    monkeypatch.undo()
    assert [p.name for p in tmp_path.iterdir()] == ["f.png"]  # no f.tmp.png left behind
    assert target.read_bytes() == b"old figure"
    save_frame_figure(frame, cfg, target)
    assert target.read_bytes()[:4] == b"\x89PNG"
    plt.close("all")


def test_outputs_go_through_the_atomic_helpers():
    # Plain to_csv / savefig / write_text to a final name can leave a half-written file.
    pattern = re.compile(r"\.(to_csv|savefig|write_text)\(")
    folders = ("experiments", "viz", "benchmarks")
    files = [p for folder in folders for p in sorted((SRC / folder).rglob("*.py"))]
    names = ("demo.py", "io/tables.py", "io/recording_writer.py", "process/spurs.py", "cli/commands_sim.py")
    files += [SRC / name for name in names]
    offenders = []
    for path in files:
        for n, line in enumerate(path.read_text().splitlines(), 1):
            # writing to a temporary name from atomic_path is the way to do it; a docstring example
            # (a ">>>" or "..." prompt) writes its input files in a temporary folder it makes
            example = line.lstrip().startswith((">>>", "..."))
            if pattern.search(line) and not example and "tmp" not in line:
                offenders.append(f"{path.relative_to(SRC)}:{n}: {line.strip()}")
    assert not offenders, "\n".join(offenders)


# ---------------------------------------------------------------- streamed recordings
CFG = RadarConfig.prototype_2022(n_doppler=8, range_limit_m=300.0)


def _old_encoding(frames: np.ndarray, dtype: str) -> bytes:
    """The bytes the whole-array writer produced (the previous implementation)."""
    code, per = recordings.DTYPES[dtype]
    peak = float(np.abs(frames).max())
    scale = peak / 30000.0 if code == "i2" and peak > 0 else 1.0
    values = frames / scale
    if per == 2:
        values = np.stack([values.real, values.imag], axis=-1)
    if code == "i2":
        values = np.clip(np.round(values), -32768, 32767)
    return values.astype("<" + code).tobytes()


@pytest.mark.parametrize("dtype", ["complex_int16", "complex64", "int16", "float32"])
def test_streamed_recording_bytes_are_unchanged(tmp_path, monkeypatch, dtype):
    rng = np.random.default_rng(1)
    shape = (7, CFG.n_rx, CFG.n_doppler, 64)
    frames = rng.standard_normal(shape) + 1j * rng.standard_normal(shape)  # complex128, as users pass
    if dtype in ("int16", "float32"):
        frames = frames.real.copy()
    frame_bytes = frames[0].nbytes
    monkeypatch.setattr(recording_writer, "_CHUNK_BYTES", 2 * frame_bytes, raising=False)  # 4 chunks
    cfg = RadarConfig.prototype_2022(n_doppler=8, range_limit_m=300.0)
    sidecar = write_recording(tmp_path / "r.bin", frames, cfg, dtype=dtype)
    assert (tmp_path / "r.bin").read_bytes() == _old_encoding(frames, dtype)
    got, _ = read_recording(sidecar)
    assert got.shape == shape
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.bin", "r.json"]


def test_recording_write_memory_is_bounded(tmp_path, monkeypatch):
    # 48 frames of 1 MB (complex128) written in 1-frame chunks: the old writer held complex128 and
    # float64 copies of the whole recording (> 100 MB here); streaming needs a few chunks.
    shape = (48, CFG.n_rx, CFG.n_doppler, 2000)
    frames = np.lib.format.open_memmap(tmp_path / "in.npy", mode="w+", dtype=np.complex128, shape=shape)
    frames[:] = 1.0 + 0.5j
    frames[5, 1, 2, 3] = 4.0 - 3.0j
    chunk = frames[0].nbytes
    monkeypatch.setattr(recording_writer, "_CHUNK_BYTES", chunk, raising=False)
    tracemalloc.start()
    try:
        write_recording(tmp_path / "r.bin", frames, CFG)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 3 * chunk, f"peak {peak / 2**20:.1f} MiB for {chunk / 2**20:.1f} MiB chunks"
    got, _ = read_recording(tmp_path / "r.json")
    assert complex(got[5][1, 2, 3]) == pytest.approx(4.0 - 3.0j, abs=2e-4)
    assert complex(got[47][0, 0, 0]) == pytest.approx(1.0 + 0.5j, abs=2e-4)


def test_recording_data_file_cannot_be_its_own_sidecar(tmp_path):
    frames = np.ones((1, CFG.n_rx, CFG.n_doppler, 16), np.complex64)
    with pytest.raises(InputError, match=r"rec.json would be its own sidecar"):
        write_recording(tmp_path / "rec.json", frames, CFG)
    assert not list(tmp_path.iterdir())
