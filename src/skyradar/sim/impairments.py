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

from skyradar.config import BOLTZMANN, RadarConfig
from skyradar.errors import InputError

# fmt: off
__all__ = [
    "Spur", "SpursConfig", "ZeroDopplerConfig", "NearRangeConfig", "ChannelErrorsConfig",
    "NoiseConfig", "ImpairmentConfig", "dbm_to_w", "spur_cube", "spur_adc", "zero_doppler_line",
    "near_range_leakage", "channel_errors", "apply_channel_errors", "receiver_noise",
    "apply_impairments", "apply_impairments_frames", "apply_impairments_adc", "thesis_flight_look",
]
# fmt: on


def dbm_to_w(power_dbm: float | np.ndarray) -> float | np.ndarray:
    """Power in dBm to W."""
    return 10.0 ** ((np.asarray(power_dbm, float) - 30.0) / 10.0)


def _phasors(rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    return np.exp(2j * np.pi * rng.random(shape))


def _doppler_bin(config: RadarConfig, velocity_mps: float) -> int:
    return (
        int(np.floor(velocity_mps / config.doppler_resolution_mps + 0.5)) + config.n_doppler // 2
    ) % config.n_doppler


# ---- spurs --------------------------------------------------------------------------------------
def _spur_pixels(config, spurs, spur_map, map_power_dbm) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rows, cols, power = [], [], []
    for r_m, v_mps, p_dbm in spurs:
        k = int(np.floor(r_m / config.range_resolution_m + 0.5))
        if not 0 <= k < config.n_range:
            raise InputError(f"impairments.spurs: range_m {r_m} is outside 0..{config.range_limit_m} m")
        rows.append(k)
        cols.append(_doppler_bin(config, v_mps))
        power.append(dbm_to_w(p_dbm))
    if spur_map is not None:
        spur_map = np.asarray(spur_map, bool)
        if spur_map.shape != (config.n_range, config.n_doppler):
            expected = (config.n_range, config.n_doppler)
            raise InputError(f"impairments.spurs: spur map shape {spur_map.shape}, expected {expected}")
        k, j = np.nonzero(spur_map)
        rows += list(k)
        cols += list(j)
        power += [dbm_to_w(map_power_dbm)] * k.size
    return np.array(rows, int), np.array(cols, int), np.array(power, float)


def spur_cube(
    config: RadarConfig,
    spurs: list[tuple[float, float, float]] = (),
    spur_map: np.ndarray | None = None,
    map_power_dbm: float = -130.0,
    leakage: bool = True,
    seed: int = 0,
) -> np.ndarray:
    """Fixed spurs as an additive (n_range, n_doppler, n_rx) complex64 cube, the same every frame.

    Parameters
    ----------
    config : RadarConfig
    spurs : list of (range_m, velocity_mps, power_dbm)
        Spur positions (nearest pixel; velocity wraps) and pixel powers.
    spur_map : ndarray of bool, shape (n_range, n_doppler), optional
        A measured spur map (e.g. from the ch3 spur learner); every True pixel is a spur.
    map_power_dbm : float
        Power of the spur-map pixels.
    leakage : bool
        Add the Hann main-lobe neighbours (amplitude -1/2 per bin step in each axis), exactly what
        an on-bin tone in the ADC shows after the default Hann windows.
    seed : int
        Fixes each spur's phase per channel.

    Examples
    --------
    >>> cfg = RadarConfig.seed_prototype()
    >>> cube = spur_cube(cfg, [(600.0, 10.0, -120.0)], leakage=False)
    >>> k, j, _ = np.unravel_index(np.abs(cube).argmax(), cube.shape)
    >>> round(float(cfg.range_axis_m[k])), round(float(cfg.doppler_axis_mps[j]), 1)
    (600, 10.0)
    """
    rows, cols, power = _spur_pixels(config, spurs, spur_map, map_power_dbm)
    cube = np.zeros((config.n_range, config.n_doppler, config.n_rx), np.complex128)
    if rows.size == 0:
        return cube.astype(np.complex64)
    values = np.sqrt(power)[:, None] * _phasors(np.random.default_rng([seed, 1]), (rows.size, config.n_rx))
    taps = [(0, 0, 1.0)]
    if leakage:
        taps += [
            (dk, dj, (-0.5) ** (abs(dk) + abs(dj))) for dk in (-1, 0, 1) for dj in (-1, 0, 1) if dk or dj
        ]
    for dk, dj, gain in taps:
        k = rows + dk
        ok = (k >= 0) & (k < config.n_range)
        np.add.at(cube, (k[ok], (cols[ok] + dj) % config.n_doppler), gain * values[ok])
    return cube.astype(np.complex64)


def spur_adc(config: RadarConfig, spurs: list[tuple[float, float, float]], seed: int = 0) -> np.ndarray:
    """Spurs as ADC tones, (n_rx, n_doppler, samples_per_chirp) complex64.

    Each spur is a tone on its pixel's beat and Doppler frequency with amplitude sqrt(P): after
    :func:`~skyradar.process.rangedoppler.range_doppler` its pixel power is ``P`` times the windows'
    coherent gain, like a target's. Phases as in :func:`spur_cube` with the same seed.
    """
    rows, cols, power = _spur_pixels(config, spurs, None, 0.0)
    values = np.sqrt(power)[:, None] * _phasors(np.random.default_rng([seed, 1]), (rows.size, config.n_rx))
    t = np.arange(config.samples_per_chirp) / config.fs_hz
    n = np.arange(config.n_doppler)
    adc = np.zeros((config.n_rx, config.n_doppler, t.size), np.complex128)
    bin_hz = config.fs_hz / config.samples_per_chirp
    for k, j, val in zip(rows, cols, values, strict=True):
        slow = np.exp(2j * np.pi * (j - config.n_doppler // 2) * n / config.n_doppler)
        fast = np.exp(2j * np.pi * k * bin_hz * t)
        adc += val[:, None, None] * (slow[:, None] * fast[None, :])[None]
    return adc.astype(np.complex64)


# ---- zero-Doppler line and near-range leakage ---------------------------------------------------
def zero_doppler_line(
    config: RadarConfig,
    power_dbm_at_100m: float = -115.0,
    falloff_db_per_decade: float = 20.0,
    width_bins: int = 1,
    seed: int = 0,
) -> np.ndarray:
    """Bright line at V = 0 over all ranges, power falling with range; fixed (n_range, n_doppler, n_rx).

    Pixel power ``P(R) = P_100 - falloff * log10(max(R, dR) / 100 m)`` dB on the zero-Doppler bin;
    ``width_bins`` > 1 spreads it over that many bins (each neighbour 6 dB down per bin).
    """
    cube = np.zeros((config.n_range, config.n_doppler, config.n_rx), np.complex64)
    r = np.maximum(config.range_axis_m, config.range_resolution_m)
    p_dbm = power_dbm_at_100m - falloff_db_per_decade * np.log10(r / 100.0)
    amp = np.sqrt(dbm_to_w(p_dbm))
    rng = np.random.default_rng([seed, 2])
    centre = config.n_doppler // 2
    for offset in range(-(int(width_bins) // 2), int(width_bins) // 2 + 1):
        phase = _phasors(rng, (config.n_range, config.n_rx))
        cube[:, (centre + offset) % config.n_doppler, :] = (0.5 ** abs(offset)) * amp[:, None] * phase
    return cube


def near_range_leakage(
    config: RadarConfig,
    power_dbm: float = -110.0,
    range_m: float = 100.0,
    rng: np.random.Generator | None = None,
) -> np.ndarray:
    """Returns at all velocities near the radar: (n_range, n_doppler, n_rx) complex64, new each frame.

    Complex Gaussian pixels of mean power ``power_dbm`` at zero range, falling linearly in dB to
    30 dB down at ``range_m`` and absent beyond; one random pattern per frame, coupled into every
    channel with a fixed phase (a single leakage source).
    """
    rng = rng or np.random.default_rng()
    r = config.range_axis_m
    inside = np.flatnonzero(r <= range_m)
    cube = np.zeros((config.n_range, config.n_doppler, config.n_rx), np.complex64)
    if inside.size == 0:
        return cube
    amp = np.sqrt(dbm_to_w(power_dbm - 30.0 * r[inside] / range_m))
    field = rng.standard_normal((inside.size, config.n_doppler)) + 1j * rng.standard_normal(
        (inside.size, config.n_doppler)
    )
    channel = _phasors(np.random.default_rng([0, 3]), (config.n_rx,))
    cube[inside] = (amp[:, None] * field / np.sqrt(2.0))[..., None] * channel
    return cube


# ---- channel errors and noise -------------------------------------------------------------------
def channel_errors(
    n_rx: int,
    gain_db: list[float] | None = None,
    phase_deg: list[float] | None = None,
    gain_sd_db: float = 0.0,
    phase_sd_deg: float = 0.0,
    seed: int = 0,
) -> np.ndarray:
    """Per-antenna complex gain errors ``10**(g/20) * exp(1j * phi)``, channel 0 the reference.

    Given values are used as they are; otherwise drawn from N(0, sd) with ``seed`` (channel 0 gets
    0 dB and 0 deg). A measured channel is ``true * errors[k]``; dividing by the same values (as
    ``RadarConfig.rx_calibration``) undoes it.

    Examples
    --------
    >>> g = channel_errors(4, phase_deg=[0, 10, -5, 30])
    >>> np.round(np.degrees(np.angle(g)), 6).tolist()
    [0.0, 10.0, -5.0, 30.0]
    """
    rng = np.random.default_rng([seed, 4])
    g = np.asarray(gain_db, float) if gain_db is not None else np.r_[0.0, rng.normal(0, gain_sd_db, n_rx - 1)]
    p = (
        np.asarray(phase_deg, float)
        if phase_deg is not None
        else np.r_[0.0, rng.normal(0, phase_sd_deg, n_rx - 1)]
    )
    if g.shape != (n_rx,) or p.shape != (n_rx,):
        raise InputError(
            f"impairments.channel_errors: need {n_rx} gains and phases, got {g.size} and {p.size}"
        )
    return 10.0 ** (g / 20.0) * np.exp(1j * np.radians(p))


def apply_channel_errors(data: np.ndarray, errors: np.ndarray, layout: str = "rd") -> np.ndarray:
    """Multiply each channel by its error: rx is the last axis (``'rd'``) or axis -3 (``'adc'``)."""
    e = np.asarray(errors, np.complex64)
    return data * (e if layout == "rd" else e[:, None, None])


def receiver_noise(
    config: RadarConfig, noise_figure_db: float | None = None, rng: np.random.Generator | None = None
) -> np.ndarray:
    """Thermal receiver noise per range-Doppler pixel, k T (PRF/nV) F; (n_range, n_doppler, n_rx)."""
    nf = config.noise_figure_db if noise_figure_db is None else noise_figure_db
    power = BOLTZMANN * config.temperature_k * config.noise_bandwidth_hz * 10 ** (nf / 10.0)
    rng = rng or np.random.default_rng()
    shape = (config.n_range, config.n_doppler, config.n_rx, 2)
    return (rng.standard_normal(shape, dtype=np.float32) * np.float32(np.sqrt(power / 2))).view(np.complex64)[
        ..., 0
    ]


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
