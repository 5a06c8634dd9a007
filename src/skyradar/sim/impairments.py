"""Hardware impairments that make simulated frames look like real ones (seed-brief.md ch2, ch3).

Real flight data differ from the clean simulation by fixed bright spurs (self-interference) in
every frame, a bright line at zero Doppler over all ranges, returns at all velocities near the
radar (up to about 100 m), per-antenna phase and gain errors and receiver noise; the ground return
is also weaker. Each effect is a plain function on a range-Doppler cube (``(..., n_range,
n_doppler, n_rx)``, pixel units: |pixel|^2 in W); spurs, channel errors and noise also exist for
ADC cubes ``(n_rx, n_chirp, n_sample)``. :class:`ImpairmentConfig` switches them on and sets their
parameters (the ``impairments:`` section of a scenario file); :func:`thesis_flight_look` is the
preset that reproduces the look of the thesis' flight data.

Levels are pixel powers in dBm (the prototype's thermal noise is -155 dBm per pixel, a 1 m^2
aircraft at 1 km about -118 dBm). Fixed patterns (spurs, the zero-Doppler line, channel errors)
depend only on ``seed``; frame-varying ones (near-range leakage, noise) on ``(seed, frame)``.
The weaker ground return is a simulator setting (``ImageSimulator(ground_reflectivity_db=...)``),
carried here as ``ground_reflectivity_db`` for the scenario runner.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.sim.impairment_signals import (
    apply_channel_errors,
    channel_errors,
    dbm_to_w,
    near_range_leakage,
    receiver_noise,
    spur_adc,
    spur_cube,
    zero_doppler_line,
)

# fmt: off
__all__ = [
    "Spur", "SpursConfig", "ZeroDopplerConfig", "NearRangeConfig", "ChannelErrorsConfig",
    "NoiseConfig", "ImpairmentConfig", "dbm_to_w", "spur_cube", "spur_adc", "zero_doppler_line",
    "near_range_leakage", "channel_errors", "apply_channel_errors", "receiver_noise",
    "apply_impairments", "apply_impairments_frames", "apply_impairments_adc", "thesis_flight_look",
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

    def _on(self, name: str):
        section = getattr(self, name)
        return section if section is not None and section.enabled else None

    def channel_gains(self, n_rx: int) -> np.ndarray:
        """The per-antenna complex errors of the ``channel_errors`` section (ones when off)."""
        ce = self._on("channel_errors")
        if ce is None:
            return np.ones(n_rx, complex)
        return channel_errors(n_rx, ce.gain_db, ce.phase_deg, ce.gain_sd_db, ce.phase_sd_deg, self.seed)

    def spur_map(self, config: RadarConfig) -> np.ndarray | None:
        s = self._on("spurs")
        if s is None or s.map_file is None:
            return None
        path = Path(s.map_file)
        try:
            return np.load(path, allow_pickle=False).astype(bool)
        except (OSError, ValueError) as exc:
            raise InputError(f"{path}: cannot read spur map ({exc})") from None


def _spur_list(s: SpursConfig) -> list[tuple[float, float, float]]:
    return [(p.range_m, p.velocity_mps, p.power_dbm) for p in s.spurs]


def apply_impairments(
    cube: np.ndarray, config: RadarConfig, imp: ImpairmentConfig, frame_index: int = 0
) -> np.ndarray:
    """Apply the enabled impairments to one range-Doppler cube (n_range, n_doppler, n_rx).

    Order: channel errors on the scene, then spurs, zero-Doppler line, near-range leakage (their
    own fixed channel phases), then receiver noise. Returns a new complex64 cube.
    """
    out = np.array(cube, np.complex64)
    if imp._on("channel_errors") is not None:
        out = apply_channel_errors(out, imp.channel_gains(config.n_rx))
    if (s := imp._on("spurs")) is not None:
        out += spur_cube(config, _spur_list(s), imp.spur_map(config), s.map_power_dbm, s.leakage, imp.seed)
    if (z := imp._on("zero_doppler")) is not None:
        out += zero_doppler_line(config, z.power_dbm_at_100m, z.falloff_db_per_decade, z.width_bins, imp.seed)
    rng = np.random.default_rng([imp.seed, 5, int(frame_index)])
    if (nr := imp._on("near_range")) is not None:
        out += near_range_leakage(config, nr.power_dbm, nr.range_m, rng)
    if (n := imp._on("noise")) is not None:
        out += receiver_noise(config, n.noise_figure_db, rng)
    return out


def apply_impairments_frames(
    iq: np.ndarray, config: RadarConfig, imp: ImpairmentConfig, frame_indices: np.ndarray | None = None
) -> np.ndarray:
    """:func:`apply_impairments` over a (time, n_range, n_doppler, n_rx) block of frames.

    ``frame_indices`` are the frames' indices in the whole run (default 0..n-1), so a chunked run
    gives the same bytes as a single pass.
    """
    indices = np.arange(len(iq)) if frame_indices is None else np.asarray(frame_indices)
    return np.stack(
        [apply_impairments(frame, config, imp, int(i)) for frame, i in zip(iq, indices, strict=True)]
    )


def apply_impairments_adc(
    adc: np.ndarray, config: RadarConfig, imp: ImpairmentConfig, frame_index: int = 0
) -> np.ndarray:
    """Apply the ADC-level impairments (channel errors, listed spurs, noise) to one ADC cube.

    The zero-Doppler line, near-range leakage and spur maps are image-level models; apply them
    to the range-Doppler cube with :func:`apply_impairments` (the other sections switched off).
    """
    from skyradar.sim.raw import adc_noise

    out = np.array(adc, np.complex64)
    if imp._on("channel_errors") is not None:
        out = apply_channel_errors(out, imp.channel_gains(config.n_rx), layout="adc")
    if (s := imp._on("spurs")) is not None and s.spurs:
        out += spur_adc(config, _spur_list(s), imp.seed)
    if (n := imp._on("noise")) is not None:
        noisy = config if n.noise_figure_db is None else config.replace(noise_figure_db=n.noise_figure_db)
        out += adc_noise(noisy, np.random.SeedSequence([imp.seed, 5, int(frame_index)]))
    return out


def thesis_flight_look(seed: int = 0) -> ImpairmentConfig:
    """Preset reproducing the look of the thesis' flight data (seed-brief.md ch2).

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
