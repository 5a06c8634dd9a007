"""Recorded flights that ship inside the ``traffic`` package: real ADS-B of GA, survey and glider flights.

The ``traffic`` package (the ``flights`` extra) carries OpenSky recordings of whole flights as
``.json.gz`` files: calibration aircraft flying patterns around airports, survey aircraft flying
lines, gliders thermalling. They are real fixes with every fault real ADS-B has (stale and
misaligned positions, gaps, quantised values), which makes them the test of what a recorded
trajectory does to the chain. They are found on disk without importing ``traffic``.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

from skyradar.errors import InputError
from skyradar.extras import MissingExtraError

__all__ = ["SAMPLE_GROUPS", "sample_flight", "sample_flights"]

# Groups of the package's samples that hold single flights of the kind a GA radar meets.
SAMPLE_GROUPS = ("calibration", "surveys", "gliders")


def _samples_folder() -> Path:
    spec = importlib.util.find_spec("traffic")
    if spec is None or not spec.submodule_search_locations:
        raise MissingExtraError(
            "recorded sample flights need the optional 'flights' extra: pip install 'skyradar[flights]'"
        )
    return Path(next(iter(spec.submodule_search_locations))) / "data" / "samples"


def sample_flights(group: str) -> list[Path]:
    """The sample flight files of one group (:data:`SAMPLE_GROUPS`), sorted by name.

    Examples
    --------
    >>> [p.name for p in sample_flights("gliders")][:2]
    ['alpi_italiane.json.gz', 'alto_adige.json.gz']
    """
    if group not in SAMPLE_GROUPS:
        raise InputError(f"sample flight group {group!r} is not one of {', '.join(SAMPLE_GROUPS)}")
    return sorted((_samples_folder() / group).glob("*.json.gz"))


def sample_flight(name: str) -> Path:
    """The file of one sample flight, ``GROUP/NAME`` (``calibration/cardiff``).

    Examples
    --------
    >>> sample_flight("calibration/cardiff").name
    'cardiff.json.gz'
    """
    group, _, stem = name.partition("/")
    path = _samples_folder() / group / f"{stem}.json.gz"
    if group not in SAMPLE_GROUPS or not path.is_file():
        raise InputError(
            f"no sample flight {name!r} (GROUP/NAME with GROUP one of {', '.join(SAMPLE_GROUPS)})"
        )
    return path
