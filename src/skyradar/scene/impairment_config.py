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
    enabled: bool = Field(True, description="Apply this section; false switches it off.")


class Spur(BaseModel):
    """One fixed spur: a bright pixel in every frame (nearest pixel; the velocity wraps).

    Examples
    --------
    >>> spur = Spur(range_m=300.0, velocity_mps=12.5, power_dbm=-125.0)
    >>> spur.range_m, spur.velocity_mps, spur.power_dbm
    (300.0, 12.5, -125.0)
    >>> Spur(range_m=-1.0, velocity_mps=0.0, power_dbm=-125.0)  # a range is never negative
    Traceback (most recent call last):
    ...
    pydantic_core._pydantic_core.ValidationError: 1 validation error for Spur
    ...
    """

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    range_m: float = Field(ge=0.0, description="Range of the spur's pixel, m.")
    velocity_mps: float = Field(description="Radial velocity of the spur's pixel, m/s.")
    power_dbm: float = Field(description="Pixel power, dBm.")


class SpursConfig(_Section):
    """Fixed spurs (self-interference), the same in every frame; each spur's phase per channel is fixed by
    the impairments' ``seed``.

    Examples
    --------
    >>> spur = {"range_m": 750, "velocity_mps": -20, "power_dbm": -128}
    >>> cfg = SpursConfig.model_validate({"spurs": [spur]})
    >>> cfg.spurs[0].range_m, cfg.enabled, cfg.leakage, cfg.map_file, cfg.map_power_dbm
    (750.0, True, True, None, -130.0)
    """

    spurs: list[Spur] = Field(default_factory=list, description="The spurs, one entry each.")
    map_file: str | None = Field(
        None,
        description="A measured spur map: ``.npy`` boolean array (n_range, n_doppler); every true pixel "
        "is a spur.",
    )
    map_power_dbm: float = Field(-130.0, description="Power of the spur map's pixels, dBm.")
    leakage: bool = Field(
        True,
        description="Add the Hann windows' main-lobe neighbours (amplitude -1/2 per bin step in each axis), "
        "as an on-bin tone shows after the default windows.",
    )


class ZeroDopplerConfig(_Section):
    """A bright line on the zero-Doppler bin over all ranges.

    Examples
    --------
    >>> cfg = ZeroDopplerConfig(power_dbm_at_100m=-110.0, falloff_db_per_decade=15.0)
    >>> cfg.power_dbm_at_100m - 2 * cfg.falloff_db_per_decade  # pixel power at 10 km, dBm
    -140.0
    >>> cfg.width_bins, ZeroDopplerConfig(enabled=False).enabled
    (1, False)
    """

    power_dbm_at_100m: float = Field(-115.0, description="Pixel power at 100 m, dBm.")
    falloff_db_per_decade: float = Field(
        20.0, ge=0.0, description="Fall of the pixel power per decade of range, dB."
    )
    width_bins: int = Field(
        1, ge=1, le=9, description="Doppler bins the line covers, 6 dB down per bin away from zero Doppler."
    )


class NearRangeConfig(_Section):
    """Returns at all velocities near the radar: a new random pattern every frame.

    Examples
    --------
    >>> cfg = NearRangeConfig(range_m=50.0)
    >>> cfg.power_dbm, cfg.range_m, cfg.power_dbm - 30.0  # mean pixel power at 0 m and at range_m, dBm
    (-110.0, 50.0, -140.0)
    """

    power_dbm: float = Field(-110.0, description="Mean pixel power at zero range, dBm.")
    range_m: float = Field(
        100.0,
        gt=0.0,
        description="Range where the power has fallen by 30 dB (linearly in dB), m; none beyond.",
    )


class ChannelErrorsConfig(_Section):
    """Per-antenna gain and phase errors; channel 0 is the reference.

    Examples
    --------
    Given errors per channel, or standard deviations to draw them with:

    >>> given = ChannelErrorsConfig(gain_db=[0.0, 0.5, -0.3, 0.2], phase_deg=[0.0, 10.0, -5.0, 3.0])
    >>> given.gain_db[1], given.phase_deg[1], given.gain_sd_db
    (0.5, 10.0, 0.0)
    >>> ChannelErrorsConfig(gain_sd_db=0.5, phase_sd_deg=10.0).gain_db is None
    True
    """

    gain_db: list[float] | None = Field(
        None, description="Gain error of each receive channel, dB; unset: drawn with ``gain_sd_db``."
    )
    phase_deg: list[float] | None = Field(
        None, description="Phase error of each receive channel, degrees; unset: drawn with ``phase_sd_deg``."
    )
    gain_sd_db: float = Field(0.0, ge=0.0, description="Standard deviation of the drawn gain errors, dB.")
    phase_sd_deg: float = Field(
        0.0, ge=0.0, description="Standard deviation of the drawn phase errors, degrees."
    )


class NoiseConfig(_Section):
    """Thermal receiver noise added with the impairments.

    Examples
    --------
    >>> NoiseConfig().noise_figure_db is None, NoiseConfig(noise_figure_db=8.0).noise_figure_db
    (True, 8.0)
    """

    noise_figure_db: float | None = Field(None, description="Receiver noise figure, dB; unset: the radar's.")


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
    preset: Literal["thesis_flight_look"] | None = Field(
        None,
        description="Start from a preset's sections "
        "(:func:`skyradar.scene.impairment_config.thesis_flight_look`); sections written beside it "
        "replace the preset's one by one.",
    )
    spurs: SpursConfig | None = Field(None, description="Fixed spurs.")
    zero_doppler: ZeroDopplerConfig | None = Field(None, description="The zero-Doppler line.")
    near_range: NearRangeConfig | None = Field(None, description="Near-range leakage.")
    channel_errors: ChannelErrorsConfig | None = Field(None, description="Per-antenna gain and phase errors.")
    noise: NoiseConfig | None = Field(None, description="Receiver noise.")
    ground_reflectivity_db: float = Field(
        0.0, description="Extra gain of the terrain returns, dB (-10: the weaker ground seen in flight)."
    )  # applied by the simulator, not by the cube functions
    seed: int = Field(
        0,
        ge=0,
        description="Seed: the fixed patterns (spurs, zero-Doppler line, channel errors) depend on it "
        "alone, the frame-varying ones (near-range leakage, noise) on it and the frame.",
    )

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

    Parameters
    ----------
    seed : int
        Seed of the fixed patterns (spur phases, zero-Doppler line, channel errors).

    Returns
    -------
    ImpairmentConfig

    Examples
    --------
    The zero-Doppler line falls 15 dB per decade of range, 15 dB from 100 m to 1 km:

    >>> imp = thesis_flight_look(seed=3)
    >>> [s.range_m for s in imp.spurs.spurs]
    [300.0, 750.0, 1200.0, 1950.0, 2700.0, 3600.0]
    >>> imp.zero_doppler.power_dbm_at_100m - imp.zero_doppler.falloff_db_per_decade, imp.seed
    (-125.0, 3)
    >>> imp.ground_reflectivity_db, imp.channel_errors.phase_sd_deg, imp.noise is None
    (-10.0, 10.0, True)
    """
    spurs = [
        (300.0, 12.5, -125.0),
        (750.0, -20.0, -128.0),
        (1200.0, 5.0, -126.0),
        (1950.0, -31.0, -130.0),
        (2700.0, 25.0, -127.0),
        (3600.0, -8.0, -129.0),
    ]
    return ImpairmentConfig(
        spurs=SpursConfig(spurs=[Spur(range_m=r, velocity_mps=v, power_dbm=p) for r, v, p in spurs]),
        zero_doppler=ZeroDopplerConfig(power_dbm_at_100m=-110.0, falloff_db_per_decade=15.0),
        near_range=NearRangeConfig(power_dbm=-110.0, range_m=100.0),
        channel_errors=ChannelErrorsConfig(gain_sd_db=0.5, phase_sd_deg=10.0),
        ground_reflectivity_db=-10.0,
        seed=seed,
    )
