"""Scenario files: one YAML describing radar, mount, terrain, own-ship, intruders and frame times.

:func:`load_scenario` validates a file into a :class:`Scenario` (pydantic models, unknown keys
rejected); every problem becomes one :class:`~skyradar.errors.InputError` line such as
``bad.yaml: field 'frame_rate_hz': must be > 0 (got -5)``. :meth:`Scenario.build` turns it into
a :class:`BuiltScenario`: a :class:`~skyradar.config.RadarConfig` (mount inside), the terrain,
own-ship and intruder trajectories in the NED frame of the scenario origin, the frame times and
the simulator options. Paths in the file are relative to the file. Heights are metres above the
WGS84 ellipsoid (see :mod:`skyradar.scene.trajectories`).

The origin defaults to the own-ship file's first point, else the centre of a DEM terrain (on
the ground); flat and fractal terrain are centred on the origin at ``height_m`` (default: the
origin's altitude). Parametric flights start at ``start_s`` and last ``duration_s`` unless told.

Example
-------
>>> built = load_scenario(example_scenario("ch2_flat_forward")).build()
>>> len(built.times_s), built.intruders[0].name, built.sim_options["reflectivity"]
(94, 'head-on', 'cosine')
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import ValidationError

from skyradar.config import Mount, RadarConfig
from skyradar.errors import InputError
from skyradar.io.frames_model import parse_start_time
from skyradar.io.safe_yaml import load_yaml
from skyradar.scene.examples import example_scenario, list_example_scenarios
from skyradar.scene.radar_heads import SINGLE_HEAD_NAME, RadarHead, scenario_heads
from skyradar.scene.scenario_errors import validation_error_line
from skyradar.scene.scenario_models import (
    AntennaModel,
    EncounterFlight,
    FileFlight,
    FlatTerrainModel,
    FractalTerrainModel,
    ScenarioModel,
)
from skyradar.scene.scenario_sources import (
    check_flyable,
    check_plausible,
    encounter_flight,
    read_dem_near,
    read_flight,
)
from skyradar.scene.terrain_names import terrain_spec_attr
from skyradar.scene.trajectories import Trajectory

# 10^7 frames is 12 days at the prototype's 9.4 frames/s and about 2.7 PB of frames.
MAX_FRAMES = 10_000_000

__all__ = [
    "Scenario",
    "BuiltScenario",
    "Intruder",
    "load_scenario",
    "example_scenario",
    "list_example_scenarios",
]


@dataclass(frozen=True)
class Intruder:
    """Another aircraft: its trajectory (scenario NED frame) and radar cross-section (m^2).

    Attributes
    ----------
    name : str
        The frames' ``target`` name.
    trajectory : Trajectory
        Its flight in the scenario's NED frame.
    rcs_m2 : float
        Radar cross-section, m^2.

    Examples
    --------
    >>> from skyradar.scene.flights import straight
    >>> b = Intruder("B", straight([2000, 0, -500], 180.0, 40.0, 60.0, origin=(52.0, 4.0, 0.0)), rcs_m2=2.0)
    >>> b.name, b.rcs_m2, np.round(b.trajectory.sample([10.0]).position_ned_m, 6).tolist()
    ('B', 2.0, [[1600.0, 0.0, -500.0]])
    """

    name: str
    trajectory: Trajectory
    rcs_m2: float = 1.0


@dataclass(frozen=True, eq=False)
class BuiltScenario:
    """Everything the simulator needs, in one NED frame at ``origin``.

    ``times_s`` are the frame times (s). Intruders exist only inside their trajectories' spans
    (``intruder.trajectory.covers(times_s)``); own-ship covers every frame. ``sim_options`` keys:
    facet_size_m, reflectivity, occlusion, noise, flat_earth, range_doppler_coupling, seed.

    Examples
    --------
    Built by :meth:`Scenario.build`; a 50 m/s own-ship flying north is 500 m north after 10 s and
    the intruder, 2 km ahead at 40 m/s head-on, 400 m closer:

    >>> data = {"origin": {"lat_deg": 52.0, "lon_deg": 4.0}, "duration_s": 10, "frame_rate_hz": 2,
    ...         "ownship": {"type": "straight", "speed_mps": 50, "start_ned_m": [0, 0, -500]},
    ...         "intruders": [{"name": "B", "type": "straight", "heading_deg": 180, "speed_mps": 40,
    ...                        "start_ned_m": [2000, 0, -500], "rcs_m2": 2}]}
    >>> built = Scenario.from_dict(data).build()
    >>> len(built.times_s), float(built.times_s[-1]), built.origin, built.terrain is None
    (20, 9.5, (52.0, 4.0, 0.0), True)
    >>> np.round(built.ownship.sample([10.0]).position_ned_m, 6).tolist()
    [[500.0, 0.0, -500.0]]
    >>> b = built.intruders[0]
    >>> b.name, b.rcs_m2, np.round(b.trajectory.sample([10.0]).position_ned_m, 6).tolist()
    ('B', 2.0, [[1600.0, 0.0, -500.0]])
    >>> [h.name for h in built.heads]
    ['radar']
    """

    name: str
    origin: tuple[float, float, float]
    radar: RadarConfig
    terrain: Any
    ownship: Trajectory
    intruders: list[Intruder]
    times_s: np.ndarray
    sim_options: dict[str, Any] = field(default_factory=dict)
    source: Path | None = None
    impairments: Any = None  # skyradar.scene.impairment_config.ImpairmentConfig or None
    land_cover: Any = None  # skyradar.scene.ground_map.LandCover (the ground_map section) or None
    start_time: Any = None  # numpy datetime64[ns], UTC of t = 0 s (the start_time field), or None
    navigation: Any = None  # skyradar.scene.navigation_config.NavigationConfig (None: perfect)
    heads: list[RadarHead] = field(default_factory=list)  # the radar heads; [] means one: `radar`
    terrain_spec: str | None = None  # JSON of a built-in terrain section (recorded in the run's attrs)

    def __post_init__(self) -> None:
        if not self.heads:  # built by hand with one radar: that is the one head
            object.__setattr__(self, "heads", [RadarHead(SINGLE_HEAD_NAME, self.radar)])


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a scenario YAML file.

    Raises :class:`InputError` (one line naming the file and the field) on any problem.

    Parameters
    ----------
    path : str or Path
        The YAML file; paths inside it are relative to its folder.

    Returns
    -------
    Scenario
        Validated, not yet built (:meth:`Scenario.build`).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> text = ("origin: {lat_deg: 52.0, lon_deg: 4.0}\\nduration_s: 5\\nframe_rate_hz: 2\\n"
    ...         "ownship: {type: straight, heading_deg: 90, speed_mps: 40, start_ned_m: [0, 0, -300]}\\n")
    >>> with tempfile.TemporaryDirectory() as d:
    ...     f = pathlib.Path(d) / "east.yaml"
    ...     _ = f.write_text(text)
    ...     scenario = load_scenario(f)
    ...     _ = f.write_text(text.replace("frame_rate_hz: 2", "frame_rate_hz: -5"))
    ...     try:
    ...         load_scenario(f)
    ...     except InputError as exc:
    ...         print(str(exc).replace(d, "DIR"))
    DIR/east.yaml: field 'frame_rate_hz': must be > 0 (got -5)
    >>> scenario.frame_times().tolist()
    [0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 4.5]
    >>> np.round(scenario.build().ownship.sample([5.0]).position_ned_m, 6).tolist()  # 40 m/s east for 5 s
    [[0.0, 200.0, -300.0]]
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such scenario file")
    try:
        text = path.read_text()
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read scenario ({type(exc).__name__}: {exc})") from None
    data = load_yaml(text, path)
    if not isinstance(data, dict):
        raise InputError(
            f"{path}: must be a mapping of sections (name, radar, ownship, ...), got {type(data).__name__}"
        )
    return Scenario.from_dict(data, source=path)


class Scenario:
    """A validated scenario file; :meth:`build` makes the trajectories, terrain and radar.

    Parameters
    ----------
    model : ScenarioModel
        The validated file (:meth:`from_dict` validates a mapping).
    source : Path, optional
        The scenario file: relative paths in it are relative to its folder, and messages name it.

    Examples
    --------
    A 50 m/s own-ship circling at 500 m radius is opposite its start after half a turn,
    pi 500 / 50 s, and back after a whole one:

    >>> data = {"origin": {"lat_deg": 52.0, "lon_deg": 4.0}, "duration_s": 63, "frame_rate_hz": 1,
    ...         "ownship": {"type": "circle", "center_ned_m": [0, 0, -500], "radius_m": 500, "speed_mps": 50}}
    >>> scenario = Scenario.from_dict(data)
    >>> scenario.name, len(scenario.frame_times())
    ('scenario', 63)
    >>> own = scenario.build().ownship
    >>> np.round(own.sample([0.0, 10 * np.pi, 20 * np.pi]).position_ned_m, 3).tolist()
    [[500.0, 0.0, -500.0], [-500.0, 0.0, -500.0], [500.0, 0.0, -500.0]]
    """

    def __init__(self, model: ScenarioModel, source: Path | None = None) -> None:
        self.model = model
        self.source = source
        self.base_dir = source.parent if source is not None else Path.cwd()
        self._label = str(source) if source is not None else "scenario"

    @classmethod
    def from_dict(cls, data: dict[str, Any], source: str | Path | None = None) -> Scenario:
        """Validate a parsed scenario mapping; paths are relative to ``source``'s folder."""
        source = Path(source) if source is not None else None
        label = str(source) if source is not None else "scenario"
        try:
            model = ScenarioModel.model_validate(data)
        except ValidationError as exc:
            raise InputError(validation_error_line(label, exc.errors()[0])) from None
        return cls(model, source)

    @property
    def name(self) -> str:
        return self.model.name

    def _path(self, value: str) -> Path:
        p = Path(value).expanduser()
        return p if p.is_absolute() else self.base_dir / p

    def _fail(self, section: str, exc: InputError) -> InputError:
        msg = str(exc)
        prefix = "field '"
        if msg.startswith(prefix):
            return InputError(f"{self._label}: field '{section}.{msg[len(prefix) :]}")
        return InputError(f"{self._label}: field '{section}': {msg}")

    # ---- pieces ---------------------------------------------------------------------------
    def frame_times(self) -> np.ndarray:
        """Frame times start_s + k / frame_rate_hz inside [start_s, start_s + duration_s), s."""
        m = self.model
        frames = m.duration_s * m.frame_rate_hz  # a float: 9e307 s x 2 Hz is infinite, no integer
        n = max(1, int(np.floor(frames + 1e-9))) if frames <= MAX_FRAMES else MAX_FRAMES + 1
        if n > MAX_FRAMES:  # the time axis alone would not fit in memory, let alone the store
            raise InputError(
                f"{self._label}: fields 'duration_s' ({m.duration_s:g}) x 'frame_rate_hz' "
                f"({m.frame_rate_hz:g}) give {frames:.3g} frames; at most {MAX_FRAMES:.0e}"
            )
        return m.start_s + np.arange(n) / m.frame_rate_hz

    def radar_config(self) -> RadarConfig:
        """The (first head's) RadarConfig, mount and overrides applied, without building the rest."""
        return scenario_heads(self)[0].config

    def _radar(self, head=None, mount: Mount | None = None, section: str = "radar") -> RadarConfig:
        """The top-level radar, or a head's (``head``: its RadarModel overrides, ``mount``)."""
        m = self.model
        overrides = m.radar.overrides() | (head.overrides() if head is not None else {})
        mount = self._mount(m.mount) if mount is None else mount
        antenna = head.antenna if head is not None and head.antenna is not None else m.radar.antenna
        if antenna is not None:
            overrides["antenna"] = self._antenna(antenna)
        try:
            radar = RadarConfig.prototype_2022(mount=mount, **overrides)
        except InputError as exc:
            raise self._fail(section, exc) from None
        max_rate = 1.0 / radar.frame_duration_s
        if m.frame_rate_hz > max_rate:
            raise InputError(
                f"{self._label}: field 'frame_rate_hz': must be <= {max_rate:.4g} "
                f"(1 / radar frame duration) (got {m.frame_rate_hz})"
            )
        return radar

    def _antenna(self, a: AntennaModel):
        from skyradar.antenna import AntennaPattern

        if a.cuts_csv is None and a.azimuth_csv is None:
            try:
                return AntennaPattern.default(a.beamwidth_deg or 70.0, a.combine)
            except InputError as exc:
                raise self._fail("radar.antenna", exc) from None
        # Measured cuts: the CSV's own errors name that file, its line and column.
        if a.cuts_csv is not None:
            return AntennaPattern.from_cuts_csv(self._path(a.cuts_csv), a.combine)
        assert a.azimuth_csv is not None and a.elevation_csv is not None  # both or neither (AntennaModel)
        return AntennaPattern.from_csv(self._path(a.azimuth_csv), self._path(a.elevation_csv), a.combine)

    def _mount(self, mm, section: str = "mount") -> Mount:
        if mm is None:
            return Mount()
        try:
            base = Mount.preset(mm.preset) if mm.preset is not None else Mount()
        except InputError as exc:
            raise InputError(f"{self._label}: field '{section}.preset': {exc}") from None
        changes = mm.model_dump(exclude_none=True, exclude={"preset"})
        if "lever_arm_m" in changes:  # another name for position_m
            if "position_m" in changes:
                msg = f"field '{section}': give lever_arm_m or position_m, not both"
                raise InputError(f"{self._label}: {msg}")
            changes["position_m"] = changes.pop("lever_arm_m")
        return Mount(**{**base.__dict__, **changes})

    def _terrain(self, origin: tuple[float, float, float] | None, bounds=None):
        t = self.model.terrain
        if t is None:
            return None
        from skyradar.scene.dem_readers import jacksboro
        from skyradar.scene.synthetic_terrain import flat_terrain, fractal_terrain

        try:
            if t.type == "jacksboro":
                return jacksboro()
            if t.type == "file":
                return read_dem_near(self._path(t.path), bounds, origin)
            if origin is None:
                raise InputError(
                    f"field 'origin': is required for {t.type} terrain (it is centred on the origin)"
                )
            height = origin[2] if t.height_m is None else t.height_m
            if isinstance(t, FlatTerrainModel):
                return flat_terrain(origin[0], origin[1], height, t.size_m, t.spacing_m)
            assert isinstance(t, FractalTerrainModel)
            return fractal_terrain(
                origin[0],
                origin[1],
                t.local_sd_m,
                size_m=t.size_m,
                spacing_m=t.spacing_m,
                seed=t.seed,
                mean_height_m=height,
            )
        except InputError as exc:
            if str(exc).startswith("field 'origin'"):
                raise InputError(f"{self._label}: {exc}") from None
            raise self._fail("terrain", exc) from None

    def _flight(self, spec, section: str, origin, ownship: Trajectory | None, name: str) -> Trajectory:
        m = self.model
        try:
            if isinstance(spec, FileFlight):
                return read_flight(
                    self._path(spec.path), spec.icao24, origin, spec.time_zero_s, spec.aircraft_class
                )
            if isinstance(spec, EncounterFlight):
                params = spec.model_dump(
                    exclude={"type", "name", "rcs_m2", "time_offset_s", "aircraft_class"}
                )
                assert ownship is not None  # an intruder's: the own-ship is never an encounter flight
                return encounter_flight(ownship, params, name)
            from skyradar.scene import flights

            params = spec.model_dump(exclude={"type", "name", "rcs_m2", "time_offset_s", "aircraft_class"})
            params["duration_s"] = params["duration_s"] or m.duration_s
            params["start_time_s"] = m.start_s if params["start_time_s"] is None else params["start_time_s"]
            traj = getattr(flights, spec.type)(origin=origin, name=name, **params)
            check_plausible(traj)
            return traj
        except InputError as exc:
            raise self._fail(section, exc) from None

    def _check_flyable(self, traj: Trajectory, spec, section: str, times: np.ndarray) -> None:
        try:
            check_flyable(traj, spec.aircraft_class, times)
        except InputError as exc:
            where = f" (file {spec.path})" if isinstance(spec, FileFlight) else ""
            raise InputError(f"{self._label}: field '{section}'{where}: {exc}") from None

    def _origin(self) -> tuple[tuple[float, float, float], Trajectory | None, Any]:
        """(origin, own-ship if read to find it, terrain if built to find it)."""
        m = self.model
        if m.origin is not None:
            return (m.origin.lat_deg, m.origin.lon_deg, m.origin.alt_m), None, None
        if isinstance(m.ownship, FileFlight):
            own = self._flight(m.ownship, "ownship", None, None, "ownship")
            if isinstance(m.terrain, FlatTerrainModel | FractalTerrainModel) and m.terrain.height_m is None:
                raise InputError(
                    f"{self._label}: field 'terrain.height_m': is required when the origin comes from "
                    "the own-ship file (its first point is in the air)"
                )
            return own.origin, own, None
        if m.terrain is not None and m.terrain.type in ("jacksboro", "file"):
            terrain = self._terrain(None)
            lat, lon = terrain.center_latlon
            return (lat, lon, float(terrain.height_at(lat, lon))), None, terrain
        if m.ground_map is not None:  # the map's centre, on the ground
            cover = self._land_cover(None)
            return (cover.layers.origin_lat_deg, cover.layers.origin_lon_deg, 0.0), None, None
        raise InputError(
            f"{self._label}: field 'origin': is required when own-ship is parametric and terrain is not a DEM"
        )

    def _land_cover(self, origin):
        """The ground_map section's land cover around ``origin`` (None: the map's centre), read once."""
        from skyradar.extras import require_extra

        require_extra("geo", "a scenario with a ground_map")
        from skyradar.scene.ground_map import land_cover_from_osm, osm_path

        g = self.model.ground_map
        if self.model.terrain is not None:
            raise InputError(f"{self._label}: field 'ground_map': give terrain or ground_map, not both")
        cached = getattr(self, "_cover", None)
        if cached is None or (origin is not None and (origin[0], origin[1]) != cached[0]):
            lat, lon = (None, None) if origin is None else (origin[0], origin[1])
            try:
                cover = land_cover_from_osm(osm_path(g.path, self.base_dir), lat, lon, g.pixel_m)
            except InputError as exc:
                raise self._fail("ground_map", exc) from None
            self._cover = ((cover.layers.origin_lat_deg, cover.layers.origin_lon_deg), cover)
        return self._cover[1]

    def _dem_under_flight(self, terrain, origin, own, radar: RadarConfig):
        """The terrain, a DEM read only where the radar can see from the flight, checked to lie under it."""
        from skyradar.scene.dem_coverage import check_dem_covers, footprint_bounds

        if terrain is None:
            # The simulator crops within the range limit plus a few facets of each position.
            area = footprint_bounds(own.lat_deg, own.lon_deg, radar.range_limit_m + 1000.0)
            terrain = self._terrain(origin, area)
        model_terrain = self.model.terrain
        if terrain is not None and model_terrain is not None and model_terrain.type in ("file", "jacksboro"):
            try:
                check_dem_covers(terrain, own.lat_deg, own.lon_deg, own.time_s, origin)
            except InputError as exc:
                raise self._fail("terrain", exc) from None
        return terrain

    # ---- all together -------------------------------------------------------------------------
    def build(self) -> BuiltScenario:
        """Make the radar, terrain, trajectories and frame times (see :class:`BuiltScenario`)."""
        m = self.model
        heads = scenario_heads(self)
        radar = heads[0].config
        times = self.frame_times()
        origin, ownship, terrain = self._origin()
        if ownship is None:
            ownship = self._flight(m.ownship, "ownship", origin, None, "ownship")
        if not np.all(ownship.covers(times)):
            raise InputError(
                f"{self._label}: field 'ownship': '{ownship.name}' covers "
                f"{ownship.start_s:.6g}..{ownship.end_s:.6g} s but the frames need "
                f"{times[0]:.6g}..{times[-1]:.6g} s (start_s, duration_s)"
            )
        self._check_flyable(ownship, m.ownship, "ownship", times)
        terrain = self._dem_under_flight(terrain, origin, ownship.sample(times), radar)
        land_cover = self._land_cover(origin) if m.ground_map is not None else None
        if land_cover is not None:
            try:
                land_cover.check_under(ownship.sample(times).position_ned_m)
            except InputError as exc:
                raise self._fail("ground_map", exc) from None
        intruders: list[Intruder] = []
        for i, spec in enumerate(m.intruders):
            traj = self._flight(spec, f"intruders.{i}", origin, ownship, spec.name or f"intruder{i}")
            name = spec.name or (traj.name if isinstance(spec, FileFlight) else None) or f"intruder{i}"
            traj = (
                traj.shifted(spec.time_offset_s).renamed(name) if spec.time_offset_s else traj.renamed(name)
            )
            if not np.any(traj.covers(times)):
                raise InputError(
                    f"{self._label}: field 'intruders.{i}.time_offset_s': '{name}' flies "
                    f"{traj.start_s:.6g}..{traj.end_s:.6g} s, outside every frame "
                    f"({times[0]:.6g}..{times[-1]:.6g} s) (got {spec.time_offset_s})"
                )
            self._check_flyable(traj, spec, f"intruders.{i}", times)
            if any(other.name == name for other in intruders):
                raise InputError(f"{self._label}: field 'intruders.{i}.name': '{name}' is used twice")
            intruders.append(Intruder(name, traj, float(spec.rcs_m2)))
        return BuiltScenario(
            name=m.name,
            origin=(float(origin[0]), float(origin[1]), float(origin[2])),
            radar=radar,
            heads=heads,
            terrain=terrain,
            ownship=ownship,
            intruders=intruders,
            times_s=times,
            sim_options=m.simulation.model_dump(),
            source=self.source,
            impairments=m.impairments,
            land_cover=land_cover,
            start_time=None if m.start_time is None else parse_start_time(m.start_time, self._label),
            navigation=m.navigation,
            terrain_spec=terrain_spec_attr(m.terrain),
        )
