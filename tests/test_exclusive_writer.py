"""Two `skyradar simulate` on the same output at once: one writes the store, the other is refused.

Started together, both pass the output checks; without a lock they interleaved their chunks, and one
printed success for a store that lacked arrays. With the lock the second gets one line and exit 2,
and the store the first reports is complete (`process` reads it).
"""

from __future__ import annotations

import subprocess
import sys

import yaml

from cli_helpers import skyradar, small_scenario

SCENARIO = small_scenario(
    "two writers",
    duration_s=3.0,
    frame_rate_hz=9.4,
    intruders=[{"type": "encounter", "kind": "head-on", "t_cpa_s": 30.0, "horizontal_miss_m": 100.0}],
    terrain={"type": "flat", "height_m": 0.0, "size_m": 6000.0, "spacing_m": 30.0},
)
ROUNDS = 3  # the lock is checked 20 rounds in a row by hand; three keep the suite short


def test_a_second_writer_of_the_same_store_is_refused(tmp_path):
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(SCENARIO))
    raced: list[bool] = []
    for k in range(ROUNDS):
        out = f"run{k}.zarr"
        cmd = [sys.executable, "-m", "skyradar", "simulate", "s.yaml", "-o", out, "--chunk-frames", "4"]
        pipes = {"stdout": subprocess.PIPE, "stderr": subprocess.PIPE, "text": True}
        procs = [subprocess.Popen(cmd, cwd=tmp_path, **pipes) for _ in range(2)]
        results = [(p.wait(timeout=300), *p.communicate()) for p in procs]
        codes = sorted(code for code, _out, _err in results)
        refused = [err for code, _out, err in results if code == 2]
        if codes == [0, 0]:  # the first finished before the second started: both complete, in turn
            raced.append(False)
            continue
        raced.append(True)
        assert codes == [0, 2], results
        lines = [line for line in refused[0].strip().splitlines() if line.strip()]
        assert len(lines) == 1 and "another skyradar command is writing it now" in lines[0], refused[0]
        processed = skyradar("process", out, "-o", f"det{k}.parquet", cwd=tmp_path)
        assert processed.returncode == 0, processed.stderr  # the store that was reported is whole
        assert not (tmp_path / f".{out}.lock").exists()
    assert any(raced), "the two writers never overlapped: the test checked nothing"
