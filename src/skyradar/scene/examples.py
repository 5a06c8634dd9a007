"""The example scenarios shipped with skyradar (``skyradar scenarios`` lists them)."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from skyradar.errors import InputError

__all__ = ["list_example_scenarios", "example_scenario", "THREE_HEAD_RADARS"]

# The shipped three-head layout (a scenario's ``radars:`` list): the nose's 70 deg beam covers
# +-35 deg and wingtip heads yawed +-75 deg cover 40..110 deg each side, so the three reach the
# +-110 deg azimuth field of regard of RTCA DO-366 (presets in skyradar.config.Mount).
THREE_HEAD_RADARS: list[dict] = [
    {"name": "nose", "mount": "nose"},
    {"name": "left", "mount": "left-wingtip"},
    {"name": "right", "mount": "right-wingtip"},
]


def _scenario_dir():
    # Shipped inside the package, so they work from a wheel as from a checkout.
    return resources.files("skyradar") / "data" / "scenarios"


def list_example_scenarios() -> list[str]:
    """Names of the example scenarios shipped with skyradar.

    Examples
    --------
    >>> "ch2_flat_forward" in list_example_scenarios()
    True
    """
    return sorted(p.name[: -len(".yaml")] for p in _scenario_dir().iterdir() if p.name.endswith(".yaml"))


def example_scenario(name: str) -> Path:
    """Path of a shipped example scenario (see :func:`list_example_scenarios`).

    Parameters
    ----------
    name : str
        One of :func:`list_example_scenarios`, with or without ``.yaml``.

    Returns
    -------
    Path
        The scenario file inside the installed package.

    Raises
    ------
    InputError
        For a name not shipped, listing the names that are.

    Examples
    --------
    >>> example_scenario("ch2_flat_forward").name, example_scenario("ch2_flat_forward.yaml").is_file()
    ('ch2_flat_forward.yaml', True)
    """
    stem = name[: -len(".yaml")] if name.endswith(".yaml") else name
    path = _scenario_dir() / f"{stem}.yaml"
    if not path.is_file():
        raise InputError(f"example scenario {name!r} unknown; choose from {list_example_scenarios()}")
    return Path(str(path))
