"""One aircraft's skyradar radar over the traffic a simulator flies, frame by frame.

:class:`AirborneRadar` is the radar of one aircraft. At its frame rate it simulates the frame of
every head from the states of the aircraft at that moment (:class:`TrafficState`: the own-ship's
and every other aircraft's within reach), processes it, steps its tracker and keeps the confirmed
tracks as :class:`TrackEstimate`. The stages are skyradar's own per-frame code:
:func:`skyradar.sim.scenario_frames.simulate_frames` (over the terrain of a :class:`TerrainSpec`),
:func:`skyradar.process.pipeline.process_frames` and
:class:`skyradar.track.track_table.TrackTableStream`; the navigation solution is perfect.

The traffic comes one state at a time: each frame's other aircraft are straight lines through
their state at the frame's time (their positions and velocities are all the simulator needs), and
the own-ship's attitude follows from its heading, climb and turn (pitch: the flight-path angle;
roll: the bank of a coordinated turn at the heading's rate of change).

A track names the aircraft it follows (:attr:`TrackEstimate.acid`) when one is within
:data:`ASSOCIATION_GATE_M` of its position: the simulator keys its conflicts by aircraft, while
every state a track hands on is the track's own estimate. A track with no aircraft near it is a
false track (``acid`` empty).

Only light aircraft carry the radar (:data:`MOUNTABLE_TYPES`, :func:`check_mountable`): the
prototype is sized for a General Aviation airframe.

Examples
--------
>>> radar = AirborneRadar("OWN", origin=(52.0, 4.36), frame_rate_hz=2.0)
>>> traffic = TrafficState(0.0, ("OWN", "INT"), np.array([52.0, 52.018]), np.array([4.36, 4.36]),
...     np.array([1000.0, 1000.0]), np.array([60.0, -60.0]), np.zeros(2), np.zeros(2), np.array([0.0, 180.0]))
>>> for k in range(8):
...     _ = radar.advance(traffic.moved(0.5 * k))
>>> [(t.acid, round(t.vn_mps)) for t in radar.estimates]  # the intruder ahead, closing
[('INT', -60)]
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

import numpy as np
import pandas as pd

from skyradar.chain import run_attrs, scenario_surface
from skyradar.config import Mount, RadarConfig
from skyradar.daa.run_tables import ownship_from_frames
from skyradar.errors import InputError
from skyradar.geo import geodetic_to_ned, ned_rotation_to, ned_to_geodetic
from skyradar.io.frames import frames_dataset
from skyradar.process.detect_run import merge_head_tables
from skyradar.process.pipeline import process_frames
from skyradar.scene.radar_heads import RadarHead
from skyradar.scene.scenario import BuiltScenario, Intruder
from skyradar.scene.trajectories import GRAVITY_MPS2, Trajectory, TrajectorySample
from skyradar.sim.navigation import navigation_variables
from skyradar.sim.scenario_frames import frames_truth, make_simulator, simulate_frames
from skyradar.track.ground_tracks import default_ground_test
from skyradar.track.track_table import TrackTableStream, tracker_detections
from skyradar.units import wrap_angle

__all__ = [
    "ASSOCIATION_GATE_M",
    "DEFAULT_FRAME_RATE_HZ",
    "DEFAULT_RANGE_LIMIT_M",
    "DEFAULT_RCS_M2",
    "MOUNTABLE_TYPES",
    "AirborneRadar",
    "TerrainSpec",
    "TrackEstimate",
    "TrafficState",
    "check_mountable",
]

DEFAULT_FRAME_RATE_HZ = 2.0  # radar frames per second (the prototype runs at 9.4; 2 keeps runs short)
DEFAULT_RANGE_LIMIT_M = 3000.0  # the radar's instrumented range, m
DEFAULT_RCS_M2 = 1.0  # radar cross-section of every other aircraft, m^2 (a light aircraft's)
ASSOCIATION_GATE_M = 750.0  # a track follows the nearest aircraft within this 3-D distance, m
_REACH_MARGIN_M = 500.0  # aircraft this far beyond the range limit are left out of a frame, m
_MAX_FRAMES = 10_000_000  # frames one radar may take (the scenario files' limit)
_SURFACE_FRAMES = 50  # the ground test's level ground: the median ground under the last frames' own-ship

# ICAO type designators of the light aircraft the radar mounts on (single and light twin pistons,
# light turboprops), with their names.
MOUNTABLE_TYPES: dict[str, str] = {
    "C150": "Cessna 150",
    "C152": "Cessna 152",
    "C162": "Cessna 162 Skycatcher",
    "C170": "Cessna 170",
    "C172": "Cessna 172 Skyhawk",
    "C177": "Cessna 177 Cardinal",
    "C182": "Cessna 182 Skylane",
    "C206": "Cessna 206 Stationair",
    "C208": "Cessna 208 Caravan",
    "C210": "Cessna 210 Centurion",
    "P28A": "Piper PA-28 Cherokee/Warrior/Archer",
    "P28R": "Piper PA-28R Arrow",
    "PA28": "Piper PA-28",
    "PA32": "Piper PA-32 Saratoga",
    "PA34": "Piper PA-34 Seneca",
    "PA44": "Piper PA-44 Seminole",
    "PA46": "Piper PA-46 Malibu",
    "SR20": "Cirrus SR20",
    "SR22": "Cirrus SR22",
    "DA20": "Diamond DA20 Katana",
    "DA40": "Diamond DA40 Diamond Star",
    "DA42": "Diamond DA42 Twin Star",
    "DA62": "Diamond DA62",
    "BE33": "Beechcraft Bonanza 33",
    "BE35": "Beechcraft Bonanza 35",
    "BE36": "Beechcraft Bonanza 36",
    "BE58": "Beechcraft Baron 58",
    "M20P": "Mooney M20",
    "TB20": "Socata TB-20 Trinidad",
    "RV7": "Van's RV-7",
    "AT3": "Aquila A210",
    "GLID": "glider",
}


def check_mountable(acid: str, actype: str) -> None:
    """Raise :class:`InputError` unless aircraft ``acid`` of ICAO type ``actype`` can carry the radar.

    The radar mounts on the light aircraft of :data:`MOUNTABLE_TYPES`; any other type (an airliner,
    a helicopter, a type BlueSky does not know) is refused.

    Examples
    --------
    >>> check_mountable("PH-ABC", "c172")
    >>> check_mountable("KL204", "B744")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: SKYRADAR KL204: aircraft type B744 cannot carry the radar; ...
    """
    if actype.upper() not in MOUNTABLE_TYPES:
        raise InputError(
            f"SKYRADAR {acid}: aircraft type {actype.upper() or '(none)'} cannot carry the radar; it mounts "
            f"on light aircraft: {', '.join(sorted(MOUNTABLE_TYPES))}"
        )


@dataclass(frozen=True)
class TerrainSpec:
    """The ground under the traffic: what each radar's frames see below.

    Parameters
    ----------
    kind : {"none", "flat", "fractal", "jacksboro", "file"}
        ``none``: clear sky (no ground in range); ``flat``: level ground at ``height_m``; ``fractal``:
        seeded hills of local height standard deviation ``local_sd_m`` around ``height_m``;
        ``jacksboro``: the Jacksboro fault DEM (Tennessee); ``file``: a DEM file (``path``: ``.hgt``,
        GeoTIFF, ``.npz``).
    height_m : float
        Mean ground height above the WGS84 ellipsoid (flat, fractal), m.
    local_sd_m : float
        Local standard deviation of the hills (fractal), m.
    size_m, spacing_m : float
        Side and grid spacing of the square synthetic ground centred where the radar is switched on, m.
    path : str, optional
        The DEM file (``file``).
    seed : int
        Seed of the fractal hills.

    Examples
    --------
    >>> flat = TerrainSpec("flat", height_m=300.0).build(52.0, 4.36)
    >>> float(np.asarray(flat.height_at(np.array([52.01]), np.array([4.37])))[0])
    300.0
    >>> TerrainSpec().build(52.0, 4.36) is None  # clear sky
    True
    """

    kind: Literal["none", "flat", "fractal", "jacksboro", "file"] = "none"
    height_m: float = 0.0
    local_sd_m: float = 60.0
    size_m: float = 40_000.0
    spacing_m: float = 60.0
    path: str | None = None
    seed: int = 0

    @classmethod
    def parse(cls, words: list[str], base_dir: Path | None = None) -> TerrainSpec:
        """The spec of the ``SKYRADARTERRAIN`` stack command's arguments.

        ``NONE``, ``FLAT [height_m]``, ``FRACTAL [local_sd_m] [height_m]``, ``JACKSBORO`` or
        ``FILE path``; a relative path is taken from ``base_dir``.

        Examples
        --------
        >>> spec = TerrainSpec.parse(["FRACTAL", "40", "300"])
        >>> spec.kind, spec.local_sd_m, spec.height_m
        ('fractal', 40.0, 300.0)
        >>> TerrainSpec.parse(["LAVA"])
        Traceback (most recent call last):
        ...
        skyradar.errors.InputError: SKYRADARTERRAIN: unknown terrain 'LAVA'; give NONE, FLAT [height_m], ...
        """
        usage = "give NONE, FLAT [height_m], FRACTAL [local_sd_m] [height_m], JACKSBORO or FILE path"
        if not words:
            raise InputError(f"SKYRADARTERRAIN: no terrain given; {usage}")
        kind, args = words[0].lower(), words[1:]
        try:
            numbers = [float(a) for a in args] if kind != "file" else []
        except ValueError:
            raise InputError(f"SKYRADARTERRAIN {' '.join(words)}: not numbers: {' '.join(args)}") from None
        if any(not math.isfinite(v) for v in numbers):
            raise InputError(f"SKYRADARTERRAIN {' '.join(words)}: the numbers must be finite")
        if kind in ("none", "jacksboro") and not args:
            return cls(kind)  # type: ignore[arg-type]
        if kind == "flat" and len(args) <= 1:
            return cls("flat", height_m=numbers[0] if numbers else 0.0)
        if kind == "fractal" and len(args) <= 2:
            sd = numbers[0] if numbers else 60.0
            if not sd > 0:
                raise InputError(f"SKYRADARTERRAIN {' '.join(words)}: local_sd_m must be > 0")
            return cls("fractal", local_sd_m=sd, height_m=numbers[1] if len(numbers) > 1 else 0.0)
        if kind == "file" and len(args) == 1:
            path = Path(args[0]).expanduser()
            if not path.is_absolute() and base_dir is not None:
                path = base_dir / path
            return cls("file", path=str(path))
        if kind in ("none", "flat", "fractal", "jacksboro", "file"):
            raise InputError(f"SKYRADARTERRAIN {' '.join(words)}: wrong arguments; {usage}")
        raise InputError(f"SKYRADARTERRAIN: unknown terrain '{words[0]}'; {usage}")

    def build(self, lat_deg: float, lon_deg: float, what: str = "the radar") -> Any:
        """The terrain (a :class:`skyradar.scene.terrain.Terrain`) around (lat, lon), deg; None for clear sky.

        Raises :class:`InputError` when the DEM file cannot be read or does not lie under (lat, lon)
        (the message names ``what`` stands there).
        """
        from skyradar.scene.dem_coverage import check_dem_covers
        from skyradar.scene.dem_readers import jacksboro, read_dem
        from skyradar.scene.synthetic_terrain import flat_terrain, fractal_terrain

        if self.kind == "none":
            return None
        if self.kind == "flat":
            return flat_terrain(lat_deg, lon_deg, self.height_m, self.size_m, self.spacing_m)
        if self.kind == "fractal":
            return fractal_terrain(
                lat_deg, lon_deg, self.local_sd_m, self.size_m, self.spacing_m, self.seed, self.height_m
            )
        if self.kind == "jacksboro":
            terrain = jacksboro()
        else:
            assert self.path is not None
            if not Path(self.path).is_file():
                raise InputError(f"SKYRADARTERRAIN FILE {self.path}: no such DEM file")
            terrain = read_dem(self.path)
        check_dem_covers(terrain, np.array([lat_deg]), np.array([lon_deg]), np.zeros(1), None, what=what)
        return terrain


@dataclass(frozen=True)
class TrafficState:
    """The states of the aircraft a simulator flies, at one time (arrays of one entry per aircraft).

    Parameters
    ----------
    time_s : float
        Simulation time, s.
    ids : tuple of str
        Aircraft identifiers.
    lat_deg, lon_deg : ndarray
        WGS84 position, deg.
    alt_m : ndarray
        Altitude, m (taken as height above the WGS84 ellipsoid, as skyradar's trajectories are).
    vn_mps, ve_mps : ndarray
        Ground velocity north and east, m/s.
    vs_mps : ndarray
        Vertical speed, m/s, positive up.
    heading_deg : ndarray
        Heading, deg clockwise from north.

    Examples
    --------
    East at 100 m/s, descending at 5 m/s, flown on 10 s: 1000 m east, 50 m lower.

    >>> from skyradar.geo import geodetic_to_ned
    >>> lat, lon, alt, vn, ve, vs, hdg = ([v] for v in (52.0, 4.0, 1000.0, 0.0, 100.0, -5.0, 90.0))
    >>> later = TrafficState(0.0, ("A",), *map(np.array, (lat, lon, alt, vn, ve, vs, hdg))).moved(10.0)
    >>> ned = geodetic_to_ned(later.lat_deg, later.lon_deg, later.alt_m, 52.0, 4.0, 1000.0)
    >>> later.time_s, (np.round(ned, 3) + 0.0).tolist()
    (10.0, [[0.0, 1000.0, 50.0]])
    """

    time_s: float
    ids: tuple[str, ...]
    lat_deg: np.ndarray
    lon_deg: np.ndarray
    alt_m: np.ndarray
    vn_mps: np.ndarray
    ve_mps: np.ndarray
    vs_mps: np.ndarray
    heading_deg: np.ndarray

    @classmethod
    def from_traffic(cls, traffic: Any, time_s: float) -> TrafficState:
        """The state of a BlueSky ``Traffic`` object (its ``id, lat, lon, alt, gsnorth, gseast, vs, hdg``)."""
        return cls(
            float(time_s),
            tuple(traffic.id),
            lat_deg=np.array(traffic.lat, float),
            lon_deg=np.array(traffic.lon, float),
            alt_m=np.array(traffic.alt, float),
            vn_mps=np.array(traffic.gsnorth, float),
            ve_mps=np.array(traffic.gseast, float),
            vs_mps=np.array(traffic.vs, float),
            heading_deg=np.array(traffic.hdg, float),
        )

    def moved(self, time_s: float) -> TrafficState:
        """Every aircraft flown straight on to ``time_s`` (s): a test's traffic, or a state a moment off."""
        dt = float(time_s) - self.time_s
        ned = np.column_stack([self.vn_mps, self.ve_mps, -self.vs_mps]) * dt
        moved = np.zeros((len(self.ids), 3))
        for k, (n, la, lo, al) in enumerate(zip(ned, self.lat_deg, self.lon_deg, self.alt_m, strict=True)):
            moved[k] = [float(v) for v in ned_to_geodetic(n, la, lo, al)]
        return replace(
            self, time_s=float(time_s), lat_deg=moved[:, 0], lon_deg=moved[:, 1], alt_m=moved[:, 2]
        )


@dataclass(frozen=True)
class TrackEstimate:
    """A confirmed track's state at its frame: what the radar knows of another aircraft.

    Attributes
    ----------
    track_id : int
        The tracker's id of the track.
    time_s : float
        Time of the frame the estimate is of, s.
    lat_deg, lon_deg : float
        Estimated WGS84 position, deg.
    alt_m : float
        Estimated altitude, m.
    vn_mps, ve_mps : float
        Estimated ground velocity north and east (local frame at the track), m/s.
    vs_mps : float
        Estimated vertical speed, m/s, positive up.
    acid : str
        The aircraft the track follows (the nearest within :data:`ASSOCIATION_GATE_M`); empty: none
        (a false track).
    error_m : float
        3-D distance from the track to that aircraft at the frame, m (NaN when ``acid`` is empty).

    Examples
    --------
    South at 55 m/s, climbing at 2 m/s; 10 s later the prediction is 550 m south and 20 m higher:

    >>> from skyradar.geo import geodetic_to_ned
    >>> estimate = TrackEstimate(7, 10.0, 52.0, 4.0, 1000.0, -55.0, 0.0, 2.0, acid="B")
    >>> later = estimate.at(20.0)
    >>> ned = geodetic_to_ned(later.lat_deg, later.lon_deg, later.alt_m, 52.0, 4.0, 1000.0)
    >>> later.time_s, later.acid, (np.round(ned, 3) + 0.0).tolist()
    (20.0, 'B', [-550.0, 0.0, -20.0])
    """

    track_id: int
    time_s: float
    lat_deg: float
    lon_deg: float
    alt_m: float
    vn_mps: float
    ve_mps: float
    vs_mps: float
    acid: str = ""
    error_m: float = float("nan")

    def at(self, time_s: float) -> TrackEstimate:
        """The estimate flown straight on to ``time_s`` (s): the track's prediction."""
        dt = float(time_s) - self.time_s
        lat, lon, alt = ned_to_geodetic(
            np.array([self.vn_mps * dt, self.ve_mps * dt, -self.vs_mps * dt]),
            self.lat_deg,
            self.lon_deg,
            self.alt_m,
        )
        return replace(self, time_s=float(time_s), lat_deg=float(lat), lon_deg=float(lon), alt_m=float(alt))


@dataclass
class AirborneRadar:
    """The skyradar radar of one aircraft, stepped at its frame rate over the traffic it flies among.

    Parameters
    ----------
    acid : str
        The aircraft carrying the radar.
    mounts : tuple of str
        Its radar heads, each a :meth:`skyradar.config.Mount.preset` name (``forward``,
        ``left-wingtip``, ``right-wingtip``, ``tail``, ...); several heads are fused by one tracker.
    origin : tuple of float
        (lat_deg, lon_deg) of the radar's local NED frame (where it is switched on), deg.
    terrain : Terrain, optional
        The ground below (None: clear sky).
    frame_rate_hz : float
        Radar frames per second.
    range_limit_m : float
        The radar's instrumented range, m.
    rcs_m2 : float
        Radar cross-section of every other aircraft, m^2.
    seed : int
        Seed of the receiver noise (each frame's noise is seeded by this and the frame number).
    start_s : float
        Simulation time of the radar's first frame, s.
    name : str
        Run name in the frames' attributes and the tables' ``source``.

    Attributes
    ----------
    estimates : list of TrackEstimate
        The confirmed tracks of the last frame.
    n_frames : int
        Frames simulated so far.
    false_tracks : int
        Confirmed track rows with no aircraft near them, so far.

    Examples
    --------
    The module's example flies one through a head-on encounter. Switched on at 30 s, its first frame
    is due then; settings the prototype cannot fly are refused:

    >>> radar = AirborneRadar("OWN", origin=(52.0, 4.36), frame_rate_hz=2.0, start_s=30.0)
    >>> radar.next_frame_s, radar.n_frames, radar.estimates
    (30.0, 0, [])
    >>> AirborneRadar("OWN", mounts=("forward", "forward"))
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: SKYRADAR OWN: a head is given twice: forward forward
    """

    acid: str
    mounts: tuple[str, ...] = ("forward",)
    origin: tuple[float, float] = (0.0, 0.0)
    terrain: Any = None
    frame_rate_hz: float = DEFAULT_FRAME_RATE_HZ
    range_limit_m: float = DEFAULT_RANGE_LIMIT_M
    rcs_m2: float = DEFAULT_RCS_M2
    seed: int = 0
    start_s: float = 0.0
    name: str = "bluesky"
    estimates: list[TrackEstimate] = field(default_factory=list, init=False)
    n_frames: int = field(default=0, init=False)
    false_tracks: int = field(default=0, init=False)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.frame_rate_hz) and self.frame_rate_hz > 0):
            raise InputError(
                f"SKYRADAR {self.acid}: frame rate must be > 0 frames/s, got {self.frame_rate_hz}"
            )
        if not self.mounts:
            raise InputError(f"SKYRADAR {self.acid}: no radar head given")
        if len(set(self.mounts)) != len(self.mounts):
            raise InputError(f"SKYRADAR {self.acid}: a head is given twice: {' '.join(self.mounts)}")
        heads = []
        for mount in self.mounts:
            try:
                config = RadarConfig.prototype_2022(
                    mount=Mount.preset(mount), range_limit_m=self.range_limit_m
                )
            except InputError as exc:
                raise InputError(f"SKYRADAR {self.acid}: {exc}") from None
            if self.frame_rate_hz > 1.0 / config.frame_duration_s:
                raise InputError(
                    f"SKYRADAR {self.acid}: frame rate {self.frame_rate_hz:g} frames/s exceeds "
                    f"1 / frame duration ({1.0 / config.frame_duration_s:.4g})"
                )
            heads.append(RadarHead(mount, config))
        origin = (float(self.origin[0]), float(self.origin[1]), 0.0)
        placeholder = Trajectory(
            np.array([0.0, 1.0]), np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 3)), origin, self.acid
        )
        self._built = BuiltScenario(
            name=self.name,
            origin=origin,
            radar=heads[0].config,
            terrain=self.terrain,
            ownship=placeholder,  # every frame's own-ship state is given (simulate_frames' ownship)
            intruders=[],
            times_s=self.start_s + np.arange(1) / self.frame_rate_hz,
            sim_options={"seed": int(self.seed), "noise": True, "reflectivity": "cosine", "occlusion": True},
            heads=heads,
        )
        self._simulators = {h.name: make_simulator(self._built, h.name) for h in heads}
        self._attrs = run_attrs(self._built)
        self._tracker = TrackTableStream(
            "radar",
            heads[0].config,
            origin=origin,
            ground_test=default_ground_test(heads[0].config),
            several_heads=len(heads) > 1,
        )
        self._own_rows: list[pd.DataFrame] = []
        self._last_heading: tuple[float, float] | None = None  # (time_s, heading_rad)

    @property
    def next_frame_s(self) -> float:
        """Simulation time of the next frame, s."""
        return self.start_s + self.n_frames / self.frame_rate_hz

    def advance(self, traffic: TrafficState) -> list[TrackEstimate] | None:
        """Simulate, process and track every frame due by ``traffic.time_s``; their last estimates.

        Each frame's states are ``traffic`` flown straight to the frame's time (a frame is never more
        than one simulation step before the state). None when no frame is due.

        Raises :class:`InputError` when the carrying aircraft is not in ``traffic`` or flies beyond
        the terrain's data.
        """
        done = None
        while self.next_frame_s <= traffic.time_s + 1e-9:
            if self.n_frames >= _MAX_FRAMES:
                raise InputError(f"SKYRADAR {self.acid}: more than {_MAX_FRAMES} radar frames")
            done = self._frame(traffic)
        return done

    def _frame(self, traffic: TrafficState) -> list[TrackEstimate]:
        k, time_s = self.n_frames, self.next_frame_s
        if self.acid not in traffic.ids:
            raise InputError(f"SKYRADAR {self.acid}: no such aircraft in the traffic")
        state = traffic.moved(time_s) if abs(time_s - traffic.time_s) > 1e-9 else traffic
        i = state.ids.index(self.acid)
        self._check_over_terrain(state, i, time_s)
        own = self._own_sample(state, i, time_s)
        others = self._others(state, i, own, time_s)
        times = np.full(k + 1, time_s)  # frame k's time at index k: its noise is seeded by k
        built = replace(self._built, intruders=others, times_s=times)
        tables, own_row = {}, None
        navigation = None
        for name, simulator in self._simulators.items():
            iq = simulate_frames(built, np.array([k]), simulator, own)
            own_truth, targets, names = frames_truth(built, np.array([k]), simulator, own)
            if navigation is None:
                navigation = navigation_variables(replace(built, times_s=times[k:]), own_truth)
            ds = frames_dataset(
                iq, times[k:], simulator.config, own_truth | navigation, targets, names, self._attrs
            )
            det = process_frames(ds, terrain=self.terrain, source=self.name)
            det["frame"] += k
            tables[name] = det
            if own_row is None:
                own_row = ownship_from_frames(ds, self.name)
        assert own_row is not None
        self._own_rows = [*self._own_rows, own_row][-_SURFACE_FRAMES:]
        air, _ = tracker_detections(merge_head_tables(tables))
        self._tracker.set_surface(scenario_surface(self._built, pd.concat(self._own_rows, ignore_index=True)))
        rows = self._tracker.step(time_s, k, air, own_row)
        confirmed = rows[rows["confirmed"].to_numpy(bool)] if len(rows) else rows
        self.estimates = self._estimates(confirmed, state, i, time_s)
        self.false_tracks += sum(not e.acid for e in self.estimates)
        self.n_frames += 1
        return self.estimates

    def _check_over_terrain(self, state: TrafficState, i: int, time_s: float) -> None:
        if self.terrain is None or not hasattr(self.terrain, "index_of"):
            return
        from skyradar.scene.dem_coverage import check_dem_covers

        try:
            check_dem_covers(
                self.terrain,
                state.lat_deg[i : i + 1],
                state.lon_deg[i : i + 1],
                np.array([time_s]),
                None,
                what=f"aircraft {self.acid}",
            )
        except InputError as exc:
            raise InputError(f"SKYRADAR {self.acid}: no terrain data under the radar: {exc}") from None

    def _own_sample(self, state: TrafficState, i: int, time_s: float) -> TrajectorySample:
        """The carrying aircraft's state in the radar's NED frame, with its attitude."""
        origin = self._built.origin
        pos = geodetic_to_ned(state.lat_deg[i], state.lon_deg[i], state.alt_m[i], *origin)
        local = np.array([state.vn_mps[i], state.ve_mps[i], -state.vs_mps[i]])
        rot = ned_rotation_to(origin[0], origin[1], float(state.lat_deg[i]), float(state.lon_deg[i]))
        vel = rot.T @ local
        heading = math.radians(float(state.heading_deg[i]))
        ground_speed = math.hypot(local[0], local[1])
        turn_rate = 0.0
        if self._last_heading is not None and time_s > self._last_heading[0]:
            change = float(wrap_angle(heading - self._last_heading[1]))
            turn_rate = change / (time_s - self._last_heading[0])
        self._last_heading = (time_s, heading)
        roll = math.atan(ground_speed * turn_rate / GRAVITY_MPS2)
        pitch = math.atan2(float(state.vs_mps[i]), max(ground_speed, 1e-3))
        att = np.array([[float(wrap_angle(heading)), pitch, roll]])
        return TrajectorySample(
            np.array([time_s]),
            pos.reshape(1, 3),
            vel.reshape(1, 3),
            att,
            np.array([state.lat_deg[i]]),
            np.array([state.lon_deg[i]]),
            np.array([state.alt_m[i]]),
        )

    def _others(self, state: TrafficState, i: int, own: TrajectorySample, time_s: float) -> list[Intruder]:
        """The other aircraft within the radar's reach, each a straight line through its state."""
        origin = self._built.origin
        out = []
        reach = self.range_limit_m + _REACH_MARGIN_M
        for j, acid in enumerate(state.ids):
            if j == i:
                continue
            pos = geodetic_to_ned(state.lat_deg[j], state.lon_deg[j], state.alt_m[j], *origin)
            if np.linalg.norm(pos - own.position_ned_m[0]) > reach:
                continue
            local = np.array([state.vn_mps[j], state.ve_mps[j], -state.vs_mps[j]])
            rot = ned_rotation_to(origin[0], origin[1], float(state.lat_deg[j]), float(state.lon_deg[j]))
            vel = rot.T @ local
            yaw = math.atan2(local[1], local[0])
            trajectory = Trajectory(
                np.array([time_s - 1.0, time_s + 1.0]),
                np.array([pos - vel, pos + vel]),
                np.array([vel, vel]),
                np.array([[yaw, 0.0, 0.0], [yaw, 0.0, 0.0]]),
                origin,
                acid,
            )
            out.append(Intruder(acid, trajectory, self.rcs_m2))
        return out

    def _estimates(
        self, confirmed: pd.DataFrame, state: TrafficState, i: int, time_s: float
    ) -> list[TrackEstimate]:
        """The confirmed tracks with a 3-D position, each named after the aircraft it follows."""
        if not len(confirmed):
            return []
        origin = self._built.origin
        others = [j for j in range(len(state.ids)) if j != i]
        truth = (
            geodetic_to_ned(state.lat_deg[others], state.lon_deg[others], state.alt_m[others], *origin)
            if others
            else np.zeros((0, 3))
        )
        out = []
        for row in confirmed.itertuples(index=False):
            ned = np.array([row.north_m, row.east_m, row.down_m], float)
            vel = np.array([row.vn_mps, row.ve_mps, row.vd_mps], float)
            if not (np.all(np.isfinite(ned)) and np.all(np.isfinite(vel))):
                continue  # no 3-D position: nothing to place in the traffic
            lat, lon, alt = (float(v) for v in ned_to_geodetic(ned, *origin))
            local = ned_rotation_to(origin[0], origin[1], lat, lon) @ vel
            acid, error = "", float("nan")
            if len(truth):
                distance = np.linalg.norm(truth - ned, axis=1)
                nearest = int(np.argmin(distance))
                if distance[nearest] <= ASSOCIATION_GATE_M:
                    acid, error = state.ids[others[nearest]], float(distance[nearest])
            out.append(
                TrackEstimate(
                    int(row.track_id),
                    time_s,
                    lat,
                    lon,
                    alt,
                    float(local[0]),
                    float(local[1]),
                    float(-local[2]),
                    acid,
                    error,
                )
            )
        # One track per aircraft: the nearest, when a second track follows the same one.
        best: dict[str, TrackEstimate] = {}
        for e in out:
            if e.acid and (e.acid not in best or e.error_m < best[e.acid].error_m):
                best[e.acid] = e
        return [e for e in out if not e.acid or best[e.acid] is e]
