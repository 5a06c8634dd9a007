"""The fingerprint of a simulation run: a hash of everything that determines its frames.

A frames store records it; a rerun with the same fingerprint resumes the store, a different one
refuses to mix frames of two runs.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

__all__ = ["fingerprint", "referenced_files"]


def referenced_files(built) -> list[Path]:
    """Every file the scenario file of ``built`` refers to (trajectories, DEMs, antenna cuts).

    Read from the scenario's own fields named ``path`` or ``*_csv``, resolved as the scenario
    resolves them (relative to its folder). Empty when the scenario has no source file.
    """
    source = getattr(built, "source", None)
    if not source or not Path(source).is_file():
        return []
    from skyradar.scene.scenario import load_scenario

    scenario = load_scenario(source)
    found: list[Path] = []

    def walk(value: Any, key: str) -> None:
        if isinstance(value, dict):
            for k, v in value.items():
                walk(v, str(k))
        elif isinstance(value, list | tuple):
            for v in value:
                walk(v, key)
        elif isinstance(value, str) and (key == "path" or key.endswith("_csv")):
            found.append(scenario._path(value))

    walk(scenario.model.model_dump(), "")
    return found


def _file_digest(path: Path) -> str:
    try:
        with open(path, "rb") as f:
            return hashlib.file_digest(f, "sha256").hexdigest()  # streams: big DEMs are fine
    except OSError:
        return "unreadable"


def fingerprint(built) -> str:
    """Hash of everything that determines the frames.

    The scenario text, every file it refers to (contents), radar, times, options and the package
    version. (:class:`~skyradar.io.frames.FrameStoreWriter` adds the chunk layout and codec.)
    """
    from skyradar import __version__

    source_text = (
        built.source.read_text() if getattr(built, "source", None) and Path(built.source).exists() else ""
    )
    payload = {
        "name": built.name,
        "origin": list(built.origin),
        "radar": built.radar.to_json(),
        "times": [float(built.times_s[0]), float(built.times_s[-1]), int(built.times_s.size)],
        "options": {k: str(v) for k, v in sorted(built.sim_options.items())},
        "source": source_text,
        "files": {str(p): _file_digest(p) for p in referenced_files(built)},
        "version": __version__,
        "format": "frames/2",  # frames/2: UTC datetime time + time_s, CF and radar_* attributes
        "start_time": str(getattr(built, "start_time", None)),
    }
    return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()[:16]
