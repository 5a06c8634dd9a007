"""Several radar heads on one aircraft: the scenario's ``radars:`` list as named RadarConfigs.

Each head is a whole radar (by default the 2x2 thesis prototype) at its own mount: a yaw, pitch
and roll of the antenna and a lever arm (``position_m``, body frame forward/right/down, metres).
A scenario without ``radars:`` has one head named ``"radar"`` at the top-level ``mount``, exactly
as before. Per-head ``radar:`` keys override the top-level ``radar:`` for that head only.

The shipped three-head layout (:data:`skyradar.scene.examples.THREE_HEAD_RADARS`): the nose
covers +-35 deg at the -3 dB beam edge and the wingtip heads, yawed +-75 deg, 40..110 deg on each
side, so together the field of regard of RTCA DO-366 (+-110 deg azimuth) is covered.

Example
-------
>>> from skyradar.scene.scenario import Scenario
>>> data = {"origin": {"lat_deg": 52.0, "lon_deg": 4.0}, "duration_s": 1,
...         "ownship": {"type": "straight", "speed_mps": 50, "start_ned_m": [0, 0, -500]},
...         "radars": [{"name": "nose", "mount": "nose"}, {"name": "left", "mount": "left-wingtip"}]}
>>> heads = Scenario.from_dict(data).build().heads
>>> [h.name for h in heads], heads[1].config.mount.yaw_deg, heads[1].config.mount.position_m
(['nose', 'left'], -75.0, (0.5, -5.0, 0.0))
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from skyradar.config import RadarConfig
from skyradar.errors import InputError

__all__ = ["RadarHead", "SINGLE_HEAD_NAME", "scenario_heads", "select_heads", "head_of"]

SINGLE_HEAD_NAME = "radar"  # the head of a scenario without a radars: list


@dataclass(frozen=True)
class RadarHead:
    """One radar head: its name (the detections' ``radar`` column) and its hardware and mount.

    Attributes
    ----------
    name : str
        The head's name; its frames are the store's group of that name.
    config : RadarConfig
        The head's radar, its mount (``config.mount``) inside.

    Examples
    --------
    >>> from skyradar.config import Mount
    >>> head = RadarHead("right", RadarConfig(mount=Mount.preset("right-wingtip")))
    >>> head.name, head.config.mount.yaw_deg
    ('right', 75.0)
    """

    name: str
    config: RadarConfig


def scenario_heads(scenario: Any) -> list[RadarHead]:
    """The heads of a :class:`~skyradar.scene.scenario.Scenario` (one head without ``radars:``).

    Raises :class:`InputError` naming the scenario and the field on a duplicate name, an unknown
    mount or a bad override, and when both ``mount`` and ``radars`` are given.

    Parameters
    ----------
    scenario : Scenario
        The validated scenario.

    Returns
    -------
    list of RadarHead
        In the order of ``radars:``; one head named ``"radar"`` without it.

    Examples
    --------
    A head's ``radar`` keys override the top-level ones for that head only:

    >>> from skyradar.scene.scenario import Scenario
    >>> data = {"origin": {"lat_deg": 52.0, "lon_deg": 4.0}, "duration_s": 1, "radar": {"pe_dbm": 30},
    ...         "ownship": {"type": "straight", "speed_mps": 50, "start_ned_m": [0, 0, -500]},
    ...         "radars": [{"name": "nose", "mount": "nose"},
    ...                    {"name": "tail", "mount": "tail", "radar": {"pe_dbm": 40}}]}
    >>> heads = scenario_heads(Scenario.from_dict(data))
    >>> [(h.name, h.config.pe_dbm, h.config.mount.yaw_deg) for h in heads]
    [('nose', 30.0, 0.0), ('tail', 40.0, 180.0)]
    >>> del data["radars"]
    >>> [(h.name, h.config.pe_dbm) for h in scenario_heads(Scenario.from_dict(data))]
    [('radar', 30.0)]
    """
    m = scenario.model
    if m.radars is None:
        return [RadarHead(SINGLE_HEAD_NAME, scenario._radar())]
    if m.mount is not None:
        raise InputError(
            f"{scenario._label}: field 'mount': give each head its mount in 'radars', not a top-level mount"
        )
    heads: list[RadarHead] = []
    for i, spec in enumerate(m.radars):
        if any(h.name == spec.name for h in heads):
            raise InputError(f"{scenario._label}: field 'radars.{i}.name': '{spec.name}' is used twice")
        mount = scenario._mount(spec.mount, f"radars.{i}.mount")
        heads.append(RadarHead(spec.name, scenario._radar(spec.radar, mount, f"radars.{i}.radar")))
    return heads


def select_heads(heads: list[RadarHead], wanted: list[str] | None, source: str = "heads") -> list[RadarHead]:
    """The heads named in ``wanted`` (in the scenario's order); all of them for None.

    Examples
    --------
    >>> heads = [RadarHead("nose", RadarConfig()), RadarHead("left", RadarConfig())]
    >>> [h.name for h in select_heads(heads, ["left"])]
    ['left']
    """
    if wanted is None:
        return list(heads)
    names = [h.name for h in heads]
    unknown = [w for w in wanted if w not in names]
    if unknown or not wanted:
        raise InputError(f"{source}: radar head(s) {unknown or wanted!r} unknown; choose from {names}")
    return [h for h in heads if h.name in wanted]


def head_of(heads: list[RadarHead], head: int | str, source: str = "head") -> RadarHead:
    """The head at index ``head`` or named ``head``.

    Examples
    --------
    >>> heads = [RadarHead("nose", RadarConfig()), RadarHead("left", RadarConfig())]
    >>> head_of(heads, "left").name, head_of(heads, 0).name
    ('left', 'nose')
    """
    names = [h.name for h in heads]
    if isinstance(head, str):
        if head not in names:
            raise InputError(f"{source}: radar head {head!r} unknown; choose from {names}")
        return heads[names.index(head)]
    if not -len(heads) <= int(head) < len(heads):
        raise InputError(f"{source}: radar head index {head} out of range; there are {len(heads)} ({names})")
    return heads[int(head)]
