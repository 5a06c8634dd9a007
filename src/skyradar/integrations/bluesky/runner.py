"""Run a BlueSky scenario file headless with the skyradar plugin, and keep what happened.

:func:`run_scenario` starts BlueSky in this process (simulation node, detached: no network, no
window), loads the plugin through BlueSky's own plugin loader (:data:`PLUGIN_DIR` on its plugin
path, ``PLUGIN LOAD SKYRADAR``), plays the scenario file and steps the simulation in fast time
until the scenario holds or quits, or ``end_s``. BlueSky runs one simulation per process; a second
run resets it (``RESET``) first.

BlueSky's own messages go to a log file, not to the terminal. The first error of the plugin (an
aircraft type that cannot carry the radar, no terrain data under a radar, a bad setting) ends the
run as one :class:`~skyradar.errors.InputError` line naming the scenario file.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import re
import sys
import tempfile
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import pandas as pd

from skyradar.errors import InputError
from skyradar.integrations.bluesky.plugin import PLUGIN_NAME, DetectionRecord, plugin

__all__ = ["PLUGIN_DIR", "BlueSkyRun", "run_scenario", "scenario_end_s", "require_bluesky"]

PLUGIN_DIR = Path(__file__).parent / "bluesky_plugins"
"""The folder holding the file BlueSky loads the plugin from (``skyradar_radar.py``)."""

_STOP_COMMANDS = ("HOLD", "QUIT", "STOP", "EXIT")
_MAX_IDLE_STEPS = 100  # a scenario that never starts the simulation ends the run after this many steps
_started: dict[str, Any] = {}  # the BlueSky simulation of this process, once started


def require_bluesky() -> None:
    """Raise :class:`InputError` naming the ``bluesky`` extra when BlueSky is not installed.

    Examples
    --------
    With the extra installed it returns quietly; without it, the error reads ``the BlueSky plugin needs
    the optional 'bluesky' extra: pip install 'skyradar[bluesky]'``.

    >>> require_bluesky()
    """
    from skyradar.extras import require_extra

    require_extra("bluesky", "the BlueSky plugin")


@dataclass
class BlueSkyRun:
    """What one headless BlueSky run gave.

    Attributes
    ----------
    scenario : Path
        The scenario file.
    surveillance : str
        ``radar`` (radar-equipped aircraft see through their radars) or ``truth``.
    end_s : float
        Simulation time the run ended at, s.
    detections : list of DetectionRecord
        One per conflict-detection step.
    states : DataFrame
        Every aircraft's state every ``sample_s``: ``time_s, acid, actype, lat_deg, lon_deg, alt_m,
        gs_mps, trk_deg, vs_mps, resolving`` (the resolution steering it).
    radars : dict
        Per radar-equipped aircraft: ``frames`` simulated, ``false_tracks`` (confirmed false-track rows)
        and ``mounts``.
    wall_s : float
        Wall time of the run, s.
    """

    scenario: Path
    surveillance: str
    end_s: float
    detections: list[DetectionRecord]
    states: pd.DataFrame
    radars: dict[str, dict[str, Any]] = field(default_factory=dict)
    wall_s: float = 0.0


def scenario_end_s(path: Path) -> float:
    """The time of the scenario file's first ``HOLD``/``QUIT`` command, else of its last command, s.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> scn = pathlib.Path(tempfile.mkdtemp()) / "a.scn"
    >>> _ = scn.write_text("00:00:00.00>CRE A C172 52 4 0 3000 100\\n00:02:30.00>HOLD\\n")
    >>> scenario_end_s(scn)
    150.0
    """
    last, stop = 0.0, None
    for line in path.read_text(errors="replace").splitlines():
        match = re.match(r"\s*(\d+):(\d+):(\d+(?:\.\d*)?)\s*>\s*(\S*)", line.split("#")[0])
        if not match:
            continue
        t = int(match[1]) * 3600.0 + int(match[2]) * 60.0 + float(match[3])
        last = max(last, t)
        if stop is None and match[4].upper() in _STOP_COMMANDS:
            stop = t
    return stop if stop is not None else last


def _start(workdir: Path | None, log: Any) -> Any:
    """BlueSky's simulation in this process, started once, with the plugin loaded."""
    import bluesky as bs

    if _started:
        return bs
    import bluesky.plugins

    locations = bluesky.plugins.__spec__.submodule_search_locations
    if str(PLUGIN_DIR) not in locations:
        locations.append(str(PLUGIN_DIR))
    workdir = workdir or Path(tempfile.gettempdir()) / f"skyradar-bluesky-{os.getuid()}"
    workdir.mkdir(parents=True, exist_ok=True)
    with contextlib.redirect_stdout(log), contextlib.redirect_stderr(log):
        # BlueSky writes its settings and navigation-data cache into the folder on the first start:
        # one process at a time, so that another one never reads a half-written cache.
        with open(workdir / "skyradar.lock", "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            bs.init(mode="sim", detached=True, workdir=str(workdir))
        from bluesky.core.plugin import Plugin

        if PLUGIN_NAME not in Plugin.loaded_plugins:
            ok, message = Plugin.load(PLUGIN_NAME)
            if not ok:
                raise InputError(f"BlueSky: cannot load the skyradar plugin: {message}")
    _started["workdir"] = workdir
    return bs


def run_scenario(
    path: str | Path,
    surveillance: Literal["radar", "truth"] = "radar",
    end_s: float | None = None,
    sample_s: float = 1.0,
    workdir: Path | None = None,
    log_path: Path | None = None,
    progress: Callable[[float], None] | None = None,
) -> BlueSkyRun:
    """Play BlueSky scenario file ``path`` headless with the skyradar plugin.

    Parameters
    ----------
    path : str or Path
        The ``.scn`` file.
    surveillance : {"radar", "truth"}
        ``truth``: radar-equipped aircraft see the true states like every other (BlueSky alone).
    end_s : float, optional
        Simulation time to stop at, s (default :func:`scenario_end_s`).
    sample_s : float
        Interval of the states table, s.
    workdir : Path, optional
        BlueSky's working directory (its settings, caches and output; default
        ``skyradar-bluesky-UID`` in the system's temporary directory). Only the first run of a
        process uses it.
    log_path : Path, optional
        File that receives BlueSky's messages (default: discarded).
    progress : callable, optional
        Called with the simulation time (s) every ``sample_s``.

    Raises
    ------
    InputError
        No such file, BlueSky not installed, or the plugin's first error (one line).
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such BlueSky scenario file")
    require_bluesky()
    end = scenario_end_s(path) if end_s is None else float(end_s)
    if not end > 0:
        raise InputError(
            f"{path}: the scenario has no commands after t = 0 s; "
            "give the time to run to (--end-s, or a HOLD)"
        )
    t0 = time.perf_counter()
    sink: Any = open(log_path, "a") if log_path is not None else _Discard()  # noqa: SIM115
    terminal = (sys.stdout, sys.stderr)  # progress reports go there, BlueSky's messages to the sink
    try:
        bs = _start(workdir, sink)
        with contextlib.redirect_stdout(sink), contextlib.redirect_stderr(sink), warnings.catch_warnings():
            # BlueSky's own numerics warn (numpy matrices, a 0/0 in MVP's vertical term): not ours to show.
            warnings.simplefilter("ignore", PendingDeprecationWarning)
            warnings.filterwarnings("ignore", category=RuntimeWarning, module="bluesky")
            bs.sim.reset()  # also resets the plugin
            plugin.surveillance = surveillance
            plugin.base_dir = path.parent.resolve()
            bs.stack.stack(f"PCALL {path.resolve()} ABS")
            rows: list[dict[str, Any]] = []
            next_sample = 0.0
            idle = 0  # steps the simulation did not run (nothing to fly and nothing scheduled)
            while idle < _MAX_IDLE_STEPS:
                bs.sim.step()
                idle = idle + 1 if bs.sim.state != bs.OP else 0
                if plugin.errors:
                    raise InputError(f"{path}: {plugin.errors[0]}")
                simt = float(bs.sim.simt)
                if simt + 1e-9 >= next_sample:
                    rows += _states(bs, simt)
                    next_sample += sample_s
                    if progress is not None:
                        with contextlib.redirect_stdout(terminal[0]), contextlib.redirect_stderr(terminal[1]):
                            progress(simt)
                if simt >= end - 1e-9 or bs.sim.state != bs.OP and simt > 0:
                    break
        radars = {
            acid: {"frames": r.n_frames, "false_tracks": r.false_tracks, "mounts": list(r.mounts)}
            for acid, r in plugin.radars.items()
        }
        return BlueSkyRun(
            path,
            surveillance,
            float(bs.sim.simt),
            list(plugin.log),
            pd.DataFrame(rows, columns=_STATE_COLUMNS),
            radars,
            time.perf_counter() - t0,
        )
    finally:
        if log_path is not None:
            sink.close()


_STATE_COLUMNS = [
    "time_s",
    "acid",
    "actype",
    "lat_deg",
    "lon_deg",
    "alt_m",
    "gs_mps",
    "trk_deg",
    "vs_mps",
    "resolving",
]


def _states(bs: Any, time_s: float) -> list[dict[str, Any]]:
    traf = bs.traf
    active = getattr(traf.cr, "active", [False] * traf.ntraf)
    return [
        {
            "time_s": time_s,
            "acid": traf.id[i],
            "actype": traf.type[i],
            "lat_deg": float(traf.lat[i]),
            "lon_deg": float(traf.lon[i]),
            "alt_m": float(traf.alt[i]),
            "gs_mps": float(traf.gs[i]),
            "trk_deg": float(traf.trk[i]),
            "vs_mps": float(traf.vs[i]),
            "resolving": bool(active[i]),
        }
        for i in range(traf.ntraf)
    ]


class _Discard:
    """A text sink that keeps nothing (BlueSky's messages when no log file is asked for)."""

    def write(self, text: str) -> int:
        return len(text)

    def flush(self) -> None:
        return None
