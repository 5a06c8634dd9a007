"""The BlueSky plugin: radar-equipped aircraft see the traffic through skyradar's tracks.

BlueSky's traffic update calls ``cd.update(traf, traf)`` and ``cr.update(cd, traf, traf)``: its
conflict detection and resolution see every aircraft's true state. The plugin stands in front of
both (:class:`DetectionGate`, :class:`ResolutionGate`, installed on ``bs.traf.cd`` and
``bs.traf.cr``), and BlueSky's own detection and resolution methods (``CDMETHOD``, ``RESO``: state
based, MVP, ...) do the work:

- every aircraft without a radar keeps BlueSky's perfect-state detection and resolution;
- for an aircraft with a radar (``SKYRADAR acid ON``), detection runs against its
  :class:`~skyradar.integrations.bluesky.picture.TrafficPicture`: the states of the aircraft its
  radar has confirmed tracks on, as the tracks estimate them; the conflicts it keeps are those with
  tracked aircraft, and its resolution (BlueSky's method, unchanged) reads the intruders' states
  from the same picture.

Each radar is an :class:`~skyradar.integrations.bluesky.radar.AirborneRadar`, stepped before every
simulation step whose time has reached its next frame (BlueSky's ``preupdate`` hook). Losses of
separation stay BlueSky's true ones. A false track (no aircraft near it) has no aircraft for
BlueSky's resolution to act on: its conflicts are counted (:attr:`SkyradarPlugin.log`), not resolved.

Stack commands:

``SKYRADAR acid ON [head ...]`` / ``SKYRADAR acid OFF``
    Mount a radar on ``acid`` (heads: :meth:`skyradar.config.Mount.preset` names, default
    ``forward``; several heads are fused) or remove it. Only the light aircraft types of
    :data:`~skyradar.integrations.bluesky.radar.MOUNTABLE_TYPES` carry it.
``SKYRADARTERRAIN NONE | FLAT [height_m] | FRACTAL [local_sd_m] [height_m] | JACKSBORO | FILE path``
    The ground under the traffic (default ``NONE``: clear sky); give it before ``SKYRADAR ... ON``.
``SKYRADARCFG RATE hz | RANGE m | RCS m2 | SEED n | SURVEILLANCE RADAR|TRUTH``
    Radar frame rate (default 2 frames/s), instrumented range (3000 m), the other aircraft's radar
    cross-section (1 m^2), noise seed (0), and whether radar-equipped aircraft see through their
    radar (``RADAR``, the default) or, for comparison, the truth as every other aircraft does.

Errors (an aircraft type that cannot carry the radar, no terrain data under a radar) are echoed as
one line and kept in :attr:`SkyradarPlugin.errors`; a failing radar is removed.

BlueSky is imported only when the plugin is installed; this module imports without it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from skyradar.errors import InputError
from skyradar.integrations.bluesky.picture import DetectionResult, TrafficPicture, merge_detection
from skyradar.integrations.bluesky.radar import (
    DEFAULT_FRAME_RATE_HZ,
    DEFAULT_RANGE_LIMIT_M,
    DEFAULT_RCS_M2,
    AirborneRadar,
    TerrainSpec,
    TrackEstimate,
    TrafficState,
    check_mountable,
)

__all__ = [
    "PLUGIN_NAME",
    "DetectionGate",
    "DetectionRecord",
    "ResolutionGate",
    "SkyradarPlugin",
    "plugin",
    "install",
]

PLUGIN_NAME = "SKYRADAR"


@dataclass(frozen=True)
class DetectionRecord:
    """One conflict-detection step: what BlueSky's detection found on the truth and what it acted on.

    Attributes
    ----------
    time_s : float
        Simulation time, s.
    truth_pairs : frozenset of tuple of str
        Conflicts (own-ship, intruder) on the true states, every own-ship's.
    used_pairs : frozenset of tuple of str
        Conflicts the resolution acted on: radar-equipped own-ships' from their tracks, the others'
        from the truth.
    los_pairs : frozenset of tuple of str
        True losses of separation.
    equipped : tuple of str
        Aircraft whose radar gave their conflicts.
    tracked : dict of str to tuple of str
        Per radar-equipped aircraft: the aircraft it had a confirmed track on.
    false_conflicts : tuple of tuple
        (own-ship, track id) of the conflicts with false tracks (no aircraft near the track).

    Examples
    --------
    ``A``'s radar had no track on ``B`` yet: the resolution did not act on the true conflict (A, B).

    >>> record = DetectionRecord(12.0, frozenset({("A", "B"), ("B", "A")}), frozenset({("B", "A")}),
    ...     frozenset(), ("A",), {"A": ()})
    >>> sorted(record.truth_pairs - record.used_pairs)
    [('A', 'B')]
    """

    time_s: float
    truth_pairs: frozenset[tuple[str, str]]
    used_pairs: frozenset[tuple[str, str]]
    los_pairs: frozenset[tuple[str, str]]
    equipped: tuple[str, ...]
    tracked: dict[str, tuple[str, ...]]
    false_conflicts: tuple[tuple[str, int], ...] = ()


@dataclass
class SkyradarPlugin:
    """The plugin's settings, radars and records (one per BlueSky simulation process: :data:`plugin`).

    Attributes
    ----------
    frame_rate_hz, range_limit_m, rcs_m2 : float
        Settings of the radars switched on from now: frames/s, m, m^2.
    seed : int
        Noise seed of the next radar (each radar adds its order of switching on).
    terrain : TerrainSpec
        The ground under the traffic.
    surveillance : {"radar", "truth"}
        ``truth``: radar-equipped aircraft see the true states (no radar is simulated).
    base_dir : Path, optional
        Directory that relative ``SKYRADARTERRAIN FILE`` paths are taken from (the scenario's).
    radars : dict of str to AirborneRadar
        The radars, by carrying aircraft.
    requested : dict of str to tuple of str
        Every ``SKYRADAR acid ON``'s heads, by aircraft (with ``TRUTH`` surveillance too).
    errors : list of str
        Every error line so far.
    log : list of DetectionRecord
        One record per conflict-detection step.

    Examples
    --------
    The settings commands need no simulation; an error is answered and kept, ``reset`` restores the
    defaults (2 frames/s, clear sky):

    >>> p = SkyradarPlugin()
    >>> p.command_config("RATE", "4"), p.command_terrain("FLAT", "300")
    ((True, 'SKYRADARCFG: RATE 4'), (True, 'SKYRADARTERRAIN: flat'))
    >>> p.frame_rate_hz, p.terrain.kind, p.terrain.height_m
    (4.0, 'flat', 300.0)
    >>> p.command_config("RANGE", "-1")
    (False, 'SKYRADARCFG RANGE -1: must be a finite number > 0')
    >>> p.errors
    ['SKYRADARCFG RANGE -1: must be a finite number > 0']
    >>> p.reset(); p.frame_rate_hz, p.terrain.kind, p.errors
    (2.0, 'none', [])
    """

    frame_rate_hz: float = DEFAULT_FRAME_RATE_HZ
    range_limit_m: float = DEFAULT_RANGE_LIMIT_M
    rcs_m2: float = DEFAULT_RCS_M2
    seed: int = 0
    terrain: TerrainSpec = field(default_factory=TerrainSpec)
    surveillance: str = "radar"
    base_dir: Path | None = None
    radars: dict[str, AirborneRadar] = field(default_factory=dict)
    requested: dict[str, tuple[str, ...]] = field(default_factory=dict)
    errors: list[str] = field(default_factory=list)
    log: list[DetectionRecord] = field(default_factory=list)
    _lost: dict[str, dict[str, TrackEstimate]] = field(default_factory=dict)
    _switched_on: int = 0

    # ---- settings and commands ----------------------------------------------------------------
    def reset(self) -> None:
        """Back to the defaults, no radars, no records (BlueSky's ``RESET``)."""
        fresh = SkyradarPlugin()
        for name in self.__dataclass_fields__:
            setattr(self, name, getattr(fresh, name))

    def _fail(self, exc: InputError) -> tuple[bool, str]:
        message = str(exc)
        self.errors.append(message)
        return False, message

    def command_radar(self, acid: str = "", switch: str = "", *heads: str) -> tuple[bool, str]:
        """``SKYRADAR acid ON [head ...]`` / ``SKYRADAR acid OFF``."""
        import bluesky as bs

        try:
            acid, switch = acid.upper(), switch.upper()
            if not acid or switch not in ("ON", "OFF"):
                raise InputError(
                    f"SKYRADAR {acid} {switch}: give SKYRADAR acid ON [head ...] or SKYRADAR acid OFF"
                )
            if acid not in bs.traf.id:
                raise InputError(f"SKYRADAR {acid}: no such aircraft")
            if switch == "OFF":
                self.radars.pop(acid, None)
                self.requested.pop(acid, None)
                self._lost.pop(acid, None)
                return True, f"SKYRADAR {acid}: radar off"
            index = bs.traf.id.index(acid)
            check_mountable(acid, str(bs.traf.type[index]))
            mounts = tuple(h.lower() for h in heads) or ("forward",)
            self.requested[acid] = mounts
            if self.surveillance == "radar":
                self._switch_on(acid, mounts, index)
            elif self.terrain.kind in ("jacksboro", "file"):  # the same refusal as with the radar
                self._terrain_under(acid, index)
            return True, f"SKYRADAR {acid}: radar on ({', '.join(mounts)})"
        except InputError as exc:
            return self._fail(exc)

    def _terrain_under(self, acid: str, index: int) -> Any:
        """The terrain around aircraft ``acid`` (index ``index``); InputError when it has no data there."""
        import bluesky as bs

        lat, lon = float(bs.traf.lat[index]), float(bs.traf.lon[index])
        try:
            return self.terrain.build(lat, lon, what=f"aircraft {acid}")
        except InputError as exc:
            raise InputError(f"SKYRADAR {acid}: no terrain data under the radar: {exc}") from None

    def _switch_on(self, acid: str, mounts: tuple[str, ...], index: int) -> None:
        import bluesky as bs

        lat, lon = float(bs.traf.lat[index]), float(bs.traf.lon[index])
        terrain = self._terrain_under(acid, index)
        self.radars[acid] = AirborneRadar(
            acid,
            mounts,
            origin=(lat, lon),
            terrain=terrain,
            frame_rate_hz=self.frame_rate_hz,
            range_limit_m=self.range_limit_m,
            rcs_m2=self.rcs_m2,
            seed=self.seed + self._switched_on,
            start_s=float(bs.sim.simt),
            name=f"bluesky-{acid}",
        )
        self._switched_on += 1
        self._lost[acid] = {}

    def command_terrain(self, *words: str) -> tuple[bool, str]:
        """``SKYRADARTERRAIN NONE | FLAT [h] | FRACTAL [sd] [h] | JACKSBORO | FILE path`` (h, sd: m)."""
        try:
            self.terrain = TerrainSpec.parse(list(words), self.base_dir)
            if self.terrain.kind == "file" and not Path(str(self.terrain.path)).is_file():
                raise InputError(
                    f"SKYRADARTERRAIN FILE {self.terrain.path}: no such DEM file (the radar needs the "
                    "terrain's data)"
                )
            return True, f"SKYRADARTERRAIN: {self.terrain.kind}"
        except InputError as exc:
            return self._fail(exc)

    def command_config(self, key: str = "", value: str = "") -> tuple[bool, str]:
        """``SKYRADARCFG RATE hz | RANGE m | RCS m2 | SEED n | SURVEILLANCE RADAR|TRUTH``."""
        key = key.upper()
        try:
            if key == "SURVEILLANCE":
                if value.upper() not in ("RADAR", "TRUTH"):
                    raise InputError(f"SKYRADARCFG SURVEILLANCE {value}: give RADAR or TRUTH")
                self.surveillance = value.lower()
                return True, f"SKYRADARCFG: surveillance {self.surveillance}"
            names = {"RATE": "frame_rate_hz", "RANGE": "range_limit_m", "RCS": "rcs_m2", "SEED": "seed"}
            if key not in names:
                raise InputError(
                    f"SKYRADARCFG {key}: give RATE, RANGE, RCS, SEED or SURVEILLANCE and a value"
                )
            try:
                number = float(value)
            except ValueError:
                raise InputError(f"SKYRADARCFG {key} {value}: not a number") from None
            if key == "SEED":
                if not (number >= 0 and number == int(number)):
                    raise InputError(f"SKYRADARCFG SEED {value}: must be an integer >= 0")
                self.seed = int(number)
            else:
                if not (math.isfinite(number) and number > 0):
                    raise InputError(f"SKYRADARCFG {key} {value}: must be a finite number > 0")
                setattr(self, names[key], number)
            return True, f"SKYRADARCFG: {key} {value}"
        except InputError as exc:
            return self._fail(exc)

    # ---- the simulation's steps ------------------------------------------------------------------
    def preupdate(self) -> None:
        """Step every radar whose next frame is due (BlueSky's ``preupdate`` hook, every step)."""
        import bluesky as bs

        time_s = float(bs.sim.simt)
        if bs.traf.ntraf == 0 or all(r.next_frame_s > time_s + 1e-9 for r in self.radars.values()):
            return
        traffic = TrafficState.from_traffic(bs.traf, time_s)
        for acid in list(self.radars):
            radar = self.radars[acid]
            if acid not in traffic.ids:  # deleted: its radar goes with it
                del self.radars[acid]
                continue
            if radar.next_frame_s > traffic.time_s + 1e-9:
                continue
            before = {e.acid: e for e in radar.estimates if e.acid}
            try:
                radar.advance(traffic)
            except InputError as exc:
                self._fail(exc)
                del self.radars[acid]
                bs.scr.echo(str(exc))
                continue
            now = {e.acid for e in radar.estimates if e.acid}
            lost = self._lost.setdefault(acid, {})
            lost.update({k: v for k, v in before.items() if k not in now})
            for k in now:
                lost.pop(k, None)

    def picture(self, traffic: Any, acid: str, time_s: float) -> TrafficPicture:
        """What aircraft ``acid``'s detection and resolution see of ``traffic`` at ``time_s`` (s)."""
        radar = self.radars[acid]
        current = {e.acid: e for e in radar.estimates if e.acid}
        return TrafficPicture.of(traffic, acid, current, time_s, self._lost.get(acid, {}))

    def equipped(self, traffic: Any) -> list[tuple[int, str]]:
        """(index, id) of the aircraft of ``traffic`` whose detection and resolution go through a radar."""
        return [(i, acid) for i, acid in enumerate(traffic.id) if acid in self.radars]

    def detect(self, cd: Any, ownship: Any, intruder: Any) -> None:
        """Conflict detection: ``ConflictDetection.update`` with the radar-equipped rows from their radars."""
        import bluesky as bs

        truth = DetectionResult.of(cd.detect(ownship, intruder, cd.rpz, cd.hpz, cd.dtlookahead))
        result, tracked, false_conflicts = truth, {}, []
        time_s = float(bs.sim.simt)
        for index, acid in self.equipped(ownship):
            picture = self.picture(intruder, acid, time_s)
            seen = DetectionResult.of(cd.detect(ownship, picture, cd.rpz, cd.hpz, cd.dtlookahead))
            ids = {picture.id[j] for j in np.flatnonzero(picture.tracked)}
            result = merge_detection(result, seen, index, acid, ids)
            tracked[acid] = tuple(sorted(ids))
            false_conflicts += self._false_conflicts(cd, ownship, index, time_s)
        (
            cd.confpairs,
            cd.lospairs,
            cd.inconf,
            cd.tcpamax,
            cd.qdr,
            cd.dist,
            cd.dcpa,
            cd.tcpa,
            cd.tLOS,
        ) = result.astuple()
        # The rest of ConflictDetection.update: the unique and cumulative pair sets.
        unique = {frozenset(pair) for pair in result.confpairs}
        los_unique = {frozenset(pair) for pair in result.lospairs}
        cd.confpairs_all.extend(unique - cd.confpairs_unique)
        cd.lospairs_all.extend(los_unique - cd.lospairs_unique)
        cd.confpairs_unique, cd.lospairs_unique = unique, los_unique
        self.log.append(
            DetectionRecord(
                time_s,
                frozenset(truth.confpairs),
                frozenset(result.confpairs),
                frozenset(truth.lospairs),
                tuple(acid for _, acid in self.equipped(ownship)),
                tracked,
                tuple(false_conflicts),
            )
        )

    def _false_conflicts(self, cd: Any, ownship: Any, index: int, time_s: float) -> list[tuple[str, int]]:
        """The own-ship's conflicts with its false tracks, by BlueSky's detection on the pair alone."""
        acid = ownship.id[index]
        out = []
        for e in self.radars[acid].estimates:
            if e.acid:
                continue
            e = e.at(time_s)
            pair = _Pair(
                id=[acid, f"TRACK{e.track_id}"],
                lat=np.array([ownship.lat[index], e.lat_deg]),
                lon=np.array([ownship.lon[index], e.lon_deg]),
                alt=np.array([ownship.alt[index], e.alt_m]),
                gs=np.array([ownship.gs[index], math.hypot(e.vn_mps, e.ve_mps)]),
                trk=np.array([ownship.trk[index], math.degrees(math.atan2(e.ve_mps, e.vn_mps)) % 360.0]),
                vs=np.array([ownship.vs[index], e.vs_mps]),
            )
            two = [np.full(2, float(np.asarray(a)[index])) for a in (cd.rpz, cd.hpz, cd.dtlookahead)]
            found = DetectionResult.of(cd.detect(pair, pair, *two))
            if any(p[0] == acid for p in found.confpairs):
                out.append((acid, e.track_id))
        return out

    def resolve(self, cr: Any, conf: Any, ownship: Any, intruder: Any) -> None:
        """Conflict resolution: ``ConflictResolution.update`` with each radar-equipped aircraft's
        resolution and recovery computed from its picture."""
        from bluesky.traffic.asas import ConflictResolution

        if ConflictResolution.selected() is ConflictResolution:
            return  # no resolution method selected: BlueSky does nothing either
        import bluesky as bs

        time_s = float(bs.sim.simt)
        equipped = self.equipped(ownship)
        radar_ids = {acid for _, acid in equipped}
        others = [i for i, acid in enumerate(ownship.id) if acid not in radar_ids]
        groups: list[tuple[list[int], set[str] | None, Any]] = [(others, None, intruder)]
        groups += [([i], {acid}, self.picture(intruder, acid, time_s)) for i, acid in equipped]

        def owned(pair: tuple[str, str], ids: set[str] | None) -> bool:
            return pair[0] not in radar_ids if ids is None else pair[0] in ids

        if conf.confpairs:
            new = [np.array(getattr(cr, k), float).copy() for k in ("trk", "tas", "vs", "alt")]
            for rows, ids, view in groups:
                if not rows:
                    continue
                resolved = cr.resolve(_Conflicts(conf, lambda p, ids=ids: owned(p, ids)), ownship, view)
                for target, values in zip(new, resolved, strict=True):
                    target[rows] = np.asarray(values, float)[rows]
            cr.trk, cr.tas, cr.vs, cr.alt = new
        pending = set(cr.resopairs)
        kept: set[tuple[str, str]] = set()
        for _rows, ids, view in groups:
            cr.resopairs = {p for p in pending if owned(p, ids)}
            cr.resumenav(_Conflicts(conf, lambda p, ids=ids: owned(p, ids)), ownship, view)
            kept |= set(cr.resopairs)
        cr.resopairs = kept


@dataclass
class _Pair:
    """Two aircraft in the attribute names BlueSky's detection reads (the own-ship and one false track)."""

    id: list[str]
    lat: np.ndarray
    lon: np.ndarray
    alt: np.ndarray
    gs: np.ndarray
    trk: np.ndarray
    vs: np.ndarray
    ntraf: int = 2


class _Conflicts:
    """A conflict-detection object showing only the conflict pairs ``keep`` accepts (the rest: as is)."""

    def __init__(self, conf: Any, keep: Any) -> None:
        rows = [k for k, pair in enumerate(conf.confpairs) if keep(pair)]
        self._conf = conf
        self.confpairs = [conf.confpairs[k] for k in rows]
        for name in ("qdr", "dist", "dcpa", "tcpa", "tLOS"):
            setattr(self, name, np.atleast_1d(np.asarray(getattr(conf, name)))[rows])

    def __getattr__(self, name: str) -> Any:
        return getattr(self._conf, name)


class DetectionGate:
    """Stands for BlueSky's conflict detection (``bs.traf.cd``): :meth:`update` goes through the plugin,
    everything else to the detection object itself.

    Parameters
    ----------
    cd : ConflictDetection
        BlueSky's detection object.
    owner : SkyradarPlugin
        The plugin whose ``detect`` runs each step.

    Examples
    --------
    With stand-ins for BlueSky's detection and the plugin:

    >>> from types import SimpleNamespace
    >>> calls = []
    >>> owner = SimpleNamespace(detect=lambda *args: calls.append(args))
    >>> cd = SimpleNamespace(rpz=9260.0)
    >>> gate = DetectionGate(cd, owner)
    >>> gate.update("own", "intruders")
    >>> calls == [(cd, "own", "intruders")]
    True
    >>> gate.rpz = 5000.0  # settings go to the detection object
    >>> cd.rpz, gate.rpz
    (5000.0, 5000.0)
    """

    def __init__(self, cd: Any, owner: SkyradarPlugin) -> None:
        object.__setattr__(self, "_cd", cd)
        object.__setattr__(self, "_owner", owner)

    def update(self, ownship: Any, intruder: Any) -> None:
        """BlueSky's detection step, radar-equipped aircraft through their radars."""
        self._owner.detect(self._cd, ownship, intruder)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._cd, name)

    def __setattr__(self, name: str, value: Any) -> None:
        setattr(self._cd, name, value)


class ResolutionGate:
    """Stands for BlueSky's conflict resolution (``bs.traf.cr``): :meth:`update` goes through the plugin,
    everything else to the resolution object itself.

    Parameters
    ----------
    cr : ConflictResolution
        BlueSky's resolution object.
    owner : SkyradarPlugin
        The plugin whose ``resolve`` runs each step.

    Examples
    --------
    With stand-ins for BlueSky's resolution and the plugin:

    >>> from types import SimpleNamespace
    >>> calls = []
    >>> owner = SimpleNamespace(resolve=lambda *args: calls.append(args))
    >>> cr = SimpleNamespace(active=False)
    >>> gate = ResolutionGate(cr, owner)
    >>> gate.update("conf", "own", "intruders")
    >>> calls == [(cr, "conf", "own", "intruders")]
    True
    >>> gate.active = True  # settings go to the resolution object
    >>> cr.active
    True
    """

    def __init__(self, cr: Any, owner: SkyradarPlugin) -> None:
        object.__setattr__(self, "_cr", cr)
        object.__setattr__(self, "_owner", owner)

    def update(self, conf: Any, ownship: Any, intruder: Any) -> None:
        """BlueSky's resolution step, radar-equipped aircraft from their pictures."""
        self._owner.resolve(self._cr, conf, ownship, intruder)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._cr, name)

    def __setattr__(self, name: str, value: Any) -> None:
        setattr(self._cr, name, value)


plugin = SkyradarPlugin()
"""The plugin of this process (BlueSky runs one simulation per process)."""


def install() -> dict[str, Any]:
    """Install the plugin in the running BlueSky simulation: the gates on its conflict detection and
    resolution and the stack commands; returns the hooks of BlueSky's plugin configuration.

    Installing twice changes nothing.
    """
    import bluesky as bs

    if not isinstance(bs.traf.cd, DetectionGate):
        bs.traf.cd = DetectionGate(bs.traf.cd, plugin)
    if not isinstance(bs.traf.cr, ResolutionGate):
        bs.traf.cr = ResolutionGate(bs.traf.cr, plugin)
    from bluesky.stack.cmdparser import get_commands

    if PLUGIN_NAME in get_commands():  # installed before: BlueSky loads a plugin again on each PLUGIN LOAD
        return {"preupdate": plugin.preupdate, "reset": plugin.reset}
    bs.stack.append_commands(
        {
            "SKYRADAR": [
                "SKYRADAR acid ON/OFF [head ...]",
                "txt,txt,[txt,...]",
                plugin.command_radar,
                "Mount (ON) or remove (OFF) a skyradar radar on an aircraft; heads: mount presets (forward).",
            ],
            "SKYRADARTERRAIN": [
                "SKYRADARTERRAIN NONE/FLAT/FRACTAL/JACKSBORO/FILE [args]",
                "word,[word,word]",
                plugin.command_terrain,
                "The ground under the traffic that the radars see.",
            ],
            "SKYRADARCFG": [
                "SKYRADARCFG RATE/RANGE/RCS/SEED/SURVEILLANCE value",
                "txt,[word]",
                plugin.command_config,
                "Radar frame rate (frames/s), range (m), other aircraft's RCS (m^2), seed, surveillance.",
            ],
        }
    )
    return {"preupdate": plugin.preupdate, "reset": plugin.reset}
