"""The BlueSky plugin: BlueSky, headless, resolves conflicts on skyradar's radar tracks.

Each scenario is flown in clear sky at the plugin's default 2 radar frames/s. The resolution is
BlueSky's MVP; the intruders do not give way (``RESOOFF``), so every manoeuvre is the own-ship's.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cli_helpers import assert_one_line_error
from skyradar.integrations.bluesky.runner import run_scenario

_SETUP = """00:00:00.00>ASAS ON
00:00:00.00>RESO MVP
00:00:00.00>ZONER 0.3
00:00:00.00>ZONEDH 300
00:00:00.00>DTLOOK 30
00:00:00.00>CRE OWN C172 52.000 4.360 0 3000 145
"""
# Head-on: 7.8 km ahead at the same altitude, closing at about 156 m/s.
AHEAD = (
    _SETUP
    + """00:00:00.00>CRE AHEAD C172 52.070 4.360 180 3000 145
00:00:00.00>RESOOFF AHEAD
00:00:00.00>SKYRADAR OWN ON forward
00:01:00.00>HOLD
"""
)
# Overtaking: 2.2 km behind (80 m to the east), 40 m/s faster; behind the nose and both wingtip
# heads (+-110 deg) until it draws level at about t = 55 s.
BEHIND = (
    _SETUP
    + """00:00:00.00>CRE BEHIND C182 51.980 4.3612 0 3000 230
00:00:00.00>RESOOFF BEHIND
00:00:00.00>SKYRADAR OWN ON forward left-wingtip right-wingtip
00:00:40.00>HOLD
"""
)


def _scenario(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / f"{name}.scn"
    path.write_text(text)
    return path


def _own_track_change_deg(run, until_s: float = np.inf) -> float:
    own = run.states[(run.states.acid == "OWN") & (run.states.time_s <= until_s)]
    return float(np.max(np.abs((own.trk_deg.to_numpy() + 180.0) % 360.0 - 180.0)))


def test_an_intruder_ahead_is_resolved_against_once_the_radar_tracks_it(tmp_path):
    run = run_scenario(_scenario(tmp_path, "ahead", AHEAD), "radar", log_path=tmp_path / "bs.log")
    assert run.radars["OWN"]["frames"] == 120  # 60 s at 2 frames/s
    used = [r.time_s for r in run.detections if ("OWN", "AHEAD") in r.used_pairs]
    truth = [r.time_s for r in run.detections if ("OWN", "AHEAD") in r.truth_pairs]
    tracked = [r.time_s for r in run.detections if "AHEAD" in r.tracked["OWN"]]
    assert used and truth and tracked
    # The conflict BlueSky acted on came from the track: never before it, later than the truth's.
    assert used[0] >= tracked[0] and used[0] > truth[0]
    assert all("AHEAD" in r.tracked["OWN"] for r in run.detections if ("OWN", "AHEAD") in r.used_pairs)
    # MVP turned the own-ship, and only once the radar had given the conflict.
    assert _own_track_change_deg(run, until_s=used[0] - 1.0) < 0.5
    assert _own_track_change_deg(run) > 5.0
    own = run.states[run.states.acid == "OWN"]
    assert own[own.resolving].time_s.min() >= used[0]


def test_an_intruder_behind_out_of_every_beam_is_not_resolved_against(tmp_path):
    path = _scenario(tmp_path, "behind", BEHIND)
    truth = run_scenario(path, "truth", log_path=tmp_path / "bs.log")
    radar = run_scenario(path, "radar", log_path=tmp_path / "bs.log")
    # On perfect state BlueSky resolves the conflict: the own-ship turns away.
    assert any(("OWN", "BEHIND") in r.used_pairs for r in truth.detections)
    assert _own_track_change_deg(truth) > 5.0
    # Through its radar the own-ship never sees the intruder: the conflict is there, unresolved.
    assert any(("OWN", "BEHIND") in r.truth_pairs for r in radar.detections)
    assert not any(("OWN", "BEHIND") in r.used_pairs for r in radar.detections)
    assert not any("BEHIND" in r.tracked["OWN"] for r in radar.detections)
    assert _own_track_change_deg(radar) < 0.5
    assert radar.radars["OWN"]["mounts"] == ["forward", "left-wingtip", "right-wingtip"]


_BAD = {
    "airliner": (
        "00:00:00.00>CRE KL204 B744 52.0 4.36 0 3000 250\n00:00:00.00>SKYRADAR KL204 ON\n00:00:20.00>HOLD\n",
        ["SKYRADAR KL204: aircraft type B744 cannot carry the radar", "C172"],
    ),
    "unknown-type": (
        "00:00:00.00>CRE X1 ZZZZ 52.0 4.36 0 3000 120\n00:00:00.00>SKYRADAR X1 ON\n00:00:20.00>HOLD\n",
        ["SKYRADAR X1: aircraft type ZZZZ cannot carry the radar"],
    ),
    "dem-elsewhere": (
        "00:00:00.00>SKYRADARTERRAIN JACKSBORO\n00:00:00.00>CRE OWN C172 52.0 4.36 0 3000 100\n"
        "00:00:00.00>SKYRADAR OWN ON\n00:00:20.00>HOLD\n",
        ["SKYRADAR OWN: no terrain data under the radar", "the aircraft OWN is at lat 52"],
    ),
    "no-dem-file": (
        "00:00:00.00>SKYRADARTERRAIN FILE missing.tif\n00:00:00.00>CRE OWN C172 52.0 4.36 0 3000 100\n"
        "00:00:00.00>SKYRADAR OWN ON\n00:00:20.00>HOLD\n",
        ["missing.tif: no such DEM file"],
    ),
}


@pytest.mark.parametrize("case", sorted(_BAD))
def test_bad_input_is_one_line_through_the_command(tmp_path, case, cli):
    text, needles = _BAD[case]
    path = _scenario(tmp_path, case, text)
    result = cli(
        "experiment",
        "bluesky",
        "--scenario",
        str(path),
        "--output",
        str(tmp_path / "out"),
        "--json",
        cwd=tmp_path,
    )
    assert_one_line_error(result, f"{path}: ", *needles)
    assert result.stdout == ""


_USER_RUN = """
import contextlib, io, sys
import bluesky as bs

with contextlib.redirect_stdout(io.StringIO()):
    bs.init(mode="sim", detached=True, workdir=sys.argv[1])
    bs.stack.stack("PCALL " + sys.argv[2] + " ABS")
    for _ in range(200):  # 10 s at BlueSky's 0.05 s step
        bs.sim.step()
from skyradar.integrations.bluesky.plugin import plugin

print(plugin.radars["OWN"].n_frames, len(plugin.log))
"""


def test_bluesky_loads_the_plugin_file_from_its_own_plugin_folder(tmp_path):
    """What a BlueSky user does: the plugin's file in the working folder's plugins, PLUGIN LOAD SKYRADAR."""
    import os
    import shutil
    import subprocess
    import sys
    import tempfile

    from skyradar.integrations.bluesky import PLUGIN_DIR

    (tmp_path / "plugins").mkdir()
    shutil.copy(PLUGIN_DIR / "skyradar_radar.py", tmp_path / "plugins")
    # BlueSky's navigation-data cache from the runner's folder, when it has one: 4 s less to start.
    cache = Path(tempfile.gettempdir()) / f"skyradar-bluesky-{os.getuid()}" / "cache"
    if cache.is_dir():
        shutil.copytree(cache, tmp_path / "cache")
    scenario = _scenario(tmp_path, "user", "00:00:00.00>PLUGIN LOAD SKYRADAR\n" + AHEAD)
    script = tmp_path / "user_run.py"
    script.write_text(_USER_RUN)
    result = subprocess.run(
        [sys.executable, str(script), str(tmp_path), str(scenario)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, result.stderr
    frames, steps = (int(v) for v in result.stdout.split())
    assert frames == 20 and steps >= 9  # frames at 0, 0.5, ..., 9.5 s; a detection step a second
