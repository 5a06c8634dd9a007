"""The ``impairments:`` section of a scenario as plain validated data (pydantic models).

The models live in the scene layer so a scenario can name its impairments without importing the
simulator; :mod:`skyradar.sim.impairments` applies them (and re-exports these names).
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from skyradar.errors import InputError

# fmt: off
__all__ = [
    "Spur", "SpursConfig", "ZeroDopplerConfig", "NearRangeConfig", "ChannelErrorsConfig",
    "NoiseConfig", "ImpairmentConfig", "thesis_flight_look",
]
# fmt: on


# ---- configuration ------------------------------------------------------------------------------
class _Section(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    enabled: bool = True


class Spur(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    range_m: float = Field(ge=0.0)
    velocity_mps: float
    power_dbm: float


class SpursConfig(_Section):
    spurs: list[Spur] = Field(default_factory=list)
    map_file: str | None = None  # .npy boolean (n_range, n_doppler) spur map
    map_power_dbm: float = -130.0
    leakage: bool = True


class ZeroDopplerConfig(_Section):
    power_dbm_at_100m: float = -115.0
    falloff_db_per_decade: float = Field(20.0, ge=0.0)
    width_bins: int = Field(1, ge=1, le=9)


class NearRangeConfig(_Section):
    power_dbm: float = -110.0
    range_m: float = Field(100.0, gt=0.0)


class ChannelErrorsConfig(_Section):
    gain_db: list[float] | None = None
    phase_deg: list[float] | None = None
    gain_sd_db: float = Field(0.0, ge=0.0)
    phase_sd_deg: float = Field(0.0, ge=0.0)


class NoiseConfig(_Section):
    noise_figure_db: float | None = None  # default: the radar's


class ImpairmentConfig(BaseModel):
    """Which impairments to apply and how (a section absent or ``enabled: false`` is off).

    Examples
    --------
    >>> imp = ImpairmentConfig.from_dict({"zero_doppler": {"power_dbm_at_100m": -120}})
    >>> imp.zero_doppler.power_dbm_at_100m, imp.spurs is None
    (-120.0, True)
    >>> imp = ImpairmentConfig.from_dict({"preset": "thesis_flight_look", "near_range": {"enabled": False}})
    >>> len(imp.spurs.spurs), imp.near_range.enabled, imp.ground_reflectivity_db
    (6, False, -10.0)
    """

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    preset: Literal["thesis_flight_look"] | None = None
    spurs: SpursConfig | None = None
    zero_doppler: ZeroDopplerConfig | None = None
    near_range: NearRangeConfig | None = None
    channel_errors: ChannelErrorsConfig | None = None
    noise: NoiseConfig | None = None
    ground_reflectivity_db: float = 0.0  # applied by the simulator, not by the cube functions
    seed: int = Field(0, ge=0)

    @model_validator(mode="before")
    @classmethod
    def _expand_preset(cls, data: Any) -> Any:
        # ``preset: thesis_flight_look`` gives the preset's sections; sections written beside it
        # replace the preset's one by one.
        if isinstance(data, dict) and data.get("preset") == "thesis_flight_look":
            base = thesis_flight_look(seed=int(data.get("seed", 0))).model_dump(exclude={"preset"})
            return {**base, **data}
        return data

    @classmethod
    def from_dict(cls, data: dict | None, source: str = "impairments") -> ImpairmentConfig:
        """Validate a mapping (e.g. the scenario's ``impairments:`` section); errors name the field."""
        try:
            return cls.model_validate(data or {})
        except ValidationError as exc:
            err = exc.errors()[0]
            where = ".".join(str(p) for p in err["loc"])
            raise InputError(f"{source}: field '{where}' {err['msg']} (got {err.get('input')!r})") from None

    def enabled(self, name: str) -> Any:
        """The section ``name`` if present and enabled, else None."""
        section = getattr(self, name)
        return section if section is not None and section.enabled else None


def thesis_flight_look(seed: int = 0) -> ImpairmentConfig:
    """Preset reproducing the look of the thesis' flight data (Maas 2022, ch. 2).

    Ground 10 dB weaker than simulated; six fixed spurs 25-30 dB above the prototype's noise in
    every frame; returns at all velocities within 100 m; a bright zero-Doppler line (45 dB above
    noise at 100 m, 30 dB at 1 km, 20 dB at 5 km); 0.5 dB / 10 deg channel errors. Thermal noise is left
    to the simulator.
    """
    spurs = [(300.0, 12.5, -125.0), (750.0, -20.0, -128.0), (1200.0, 5.0, -126.0),
             (1950.0, -31.0, -130.0), (2700.0, 25.0, -127.0), (3600.0, -8.0, -129.0)]  # fmt: skip
    return ImpairmentConfig(
        spurs=SpursConfig(spurs=[Spur(range_m=r, velocity_mps=v, power_dbm=p) for r, v, p in spurs]),
        zero_doppler=ZeroDopplerConfig(power_dbm_at_100m=-110.0, falloff_db_per_decade=15.0),
        near_range=NearRangeConfig(power_dbm=-110.0, range_m=100.0),
        channel_errors=ChannelErrorsConfig(gain_sd_db=0.5, phase_sd_deg=10.0),
        ground_reflectivity_db=-10.0,
        seed=seed,
    )
