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
    resolves them (relative to its folder). The files need not exist.

    Parameters
    ----------
    built : BuiltScenario
        Any object with a ``source`` attribute (the scenario file's path, or None).

    Returns
    -------
    list of Path
        The referenced files; empty when the scenario has no source file.

    Examples
    --------
    >>> import tempfile
    >>> from types import SimpleNamespace
    >>> tmp = tempfile.TemporaryDirectory()
    >>> folder = Path(tmp.name)
    >>> _ = (folder / "s.yaml").write_text(
    ...     "{origin: {lat_deg: 52.0, lon_deg: 4.0}, duration_s: 1, "
    ...     "ownship: {type: straight, speed_mps: 50, start_ned_m: [0, 0, -500]}, "
    ...     "intruders: [{name: B, type: file, path: tracks/adsb.csv}]}"
    ... )
    >>> built = SimpleNamespace(source=folder / "s.yaml")
    >>> [p.relative_to(folder).as_posix() for p in referenced_files(built)]
    ['tracks/adsb.csv']
    >>> referenced_files(SimpleNamespace(source=None))
    []
    >>> tmp.cleanup()
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

    Parameters
    ----------
    built : BuiltScenario
        Read: ``name``, ``origin``, ``radar``, ``times_s`` (s), ``sim_options`` and, when present,
        ``source`` and ``start_time``.

    Returns
    -------
    str
        16 hexadecimal digits of the SHA-256 of those inputs.

    Examples
    --------
    >>> import numpy as np
    >>> from types import SimpleNamespace
    >>> from skyradar.config import RadarConfig
    >>> built = SimpleNamespace(name="demo", origin=(52.0, 4.0, 0.0), radar=RadarConfig.prototype_2022(),
    ...                         times_s=np.arange(10) * 0.1, sim_options={"seed": 0})
    >>> key = fingerprint(built)
    >>> len(key), key == fingerprint(built)  # the same inputs, the same key
    (16, True)
    >>> fingerprint(SimpleNamespace(**{**vars(built), "sim_options": {"seed": 1}})) != key
    True
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
