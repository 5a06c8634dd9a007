"""An S-band air-traffic-control primary surveillance radar (PSR) as the illuminator of a passive receiver.

The model is a rotating, pulsed radar: in every pulse repetition interval (PRI) a long pulse (a linear
FM up-chirp, for range resolution at low peak power) and a short unmodulated pulse (covering the long
pulse's blind range), each at its own offset from the carrier; successive PRIs follow a stagger cycle
(against blind speeds). The antenna turns clockwise at a constant rate; its azimuth pattern is a
Gaussian main lobe of the given 3 dB beamwidth joined to a sidelobe envelope that falls as 1/angle^2
from ``sidelobe_db`` to ``backlobe_db``. The elevation pattern is taken as flat over the low angles of
the scene (a cosec^2 ATC beam covers 0.5-30 deg; the scene's reflectors and aircraft sit within a few
degrees of the horizon).

Typical values: Recommendation ITU-R M.1464-2 (02/2015), "Characteristics of non-meteorological
radiolocation radars, and characteristics and protection criteria for sharing studies for aeronautical
radionavigation and meteorological radars in the radiodetermination service operating in the frequency
band 2 700-2 900 MHz", Annex 1, Table 1 (aeronautical radionavigation radars): 2.7-2.9 GHz, 12-15 rpm,
about 1.4 deg azimuth beamwidth, about 33-34 dBi antenna gain, solid-state transmitters of tens of kW
peak power with short pulses of about 1 us and long, frequency-modulated pulses of about 100 us, PRFs
near 1 kHz with stagger. The defaults below are one representative set within those ranges, not one
column of the table; they were chosen without the table at hand (written offline), so check a value
against the Recommendation before quoting it. 13.5 rpm makes the thesis' 40 s recording 9 sweeps.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, fields, replace

import numpy as np

from skyradar.errors import InputError
from skyradar.units import wrap_angle

__all__ = ["C_MPS", "Pulse", "Illuminator", "lfm_baseband"]

C_MPS = 299_792_458.0
SOURCE = "ITU-R M.1464-2 (02/2015), Annex 1, Table 1 (aeronautical radionavigation radars, 2700-2900 MHz)"


@dataclass(frozen=True)
class Pulse:
    """One pulse of the PRI: ``width_s`` long, starting ``delay_s`` after the PRI start.

    Attributes
    ----------
    width_s : float
        Pulse duration, s.
    bandwidth_hz : float
        Swept bandwidth, Hz: > 0 makes the pulse a linear FM up-chirp centred on ``offset_hz``, 0 an
        unmodulated tone at ``offset_hz``.
    offset_hz : float
        Centre frequency relative to the carrier, Hz.
    delay_s : float
        Start of the pulse after the start of the PRI, s.

    Examples
    --------
    A 1 us tone 1.25 MHz above the carrier sampled at 5 MS/s: 5 samples, a quarter turn apart.

    >>> x = Illuminator(52.0, 5.0, 30.0).pulse_baseband(Pulse(1e-6, 0.0, 1.25e6), 5e6)
    >>> x.shape, round(float(np.angle(x[1] / x[0])), 4)
    ((5,), 1.5708)
    """

    width_s: float
    bandwidth_hz: float = 0.0
    offset_hz: float = 0.0
    delay_s: float = 0.0


def lfm_baseband(t_s: np.ndarray, width_s: float, bandwidth_hz: float, offset_hz: float) -> np.ndarray:
    """Unit-amplitude complex baseband of a pulse at times ``t_s`` from its start (0 outside the pulse).

    Phase ``2 pi (f0 t + k t^2 / 2)`` with ``f0 = offset - B/2`` and ``k = B / T``: the instantaneous
    frequency sweeps from ``offset - B/2`` to ``offset + B/2``.

    Examples
    --------
    >>> t = np.arange(5) * 0.25e-6
    >>> np.round(np.angle(lfm_baseband(t, 1e-6, 0.0, 250e3)), 4).tolist()
    [0.0, 0.3927, 0.7854, 1.1781, 0.0]
    """
    t = np.asarray(t_s, dtype=float)
    f0 = offset_hz - 0.5 * bandwidth_hz
    k = bandwidth_hz / width_s
    phase = 2.0 * np.pi * (f0 * t + 0.5 * k * t * t)
    inside = (t >= 0.0) & (t < width_s)
    return np.where(inside, np.exp(1j * phase), 0.0).astype(np.complex64)


_PULSE_KEYS = ("width_s", "bandwidth_hz", "offset_hz", "delay_s")


def _number(name: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise InputError(f"illuminator: field '{name}' must be a finite number, got {value!r}")
    return float(value)


# Upper bounds of a rotating PSR's fields: far beyond any such radar, and beyond them the sample counts
# and phases computed from them overflow (a PRI of 1e308 s crashed the pulse profile with a traceback).
_MAXIMA = {
    "carrier_frequency_hz": 1e12,
    "peak_power_w": 1e10,
    "beamwidth_az_deg": 360.0,
    "rotation_rpm": 600.0,
    "pri_s": 1.0,
}


def _positive(name: str, value: float) -> float:
    value = float(value)
    top = _MAXIMA.get(name, math.inf)
    if not math.isfinite(value) or value <= 0 or value > top:
        bound = f" up to {top:g}" if math.isfinite(top) else ""
        raise InputError(f"illuminator: field '{name}' must be a positive number{bound}, got {value!r}")
    return value


@dataclass(frozen=True)
class Illuminator:
    """A rotating pulsed S-band PSR at a geodetic site (WGS84 deg, deg, m above the ellipsoid).

    Examples
    --------
    >>> ill = Illuminator(latitude=52.0, longitude=5.0, altitude=30.0)
    >>> round(ill.rotation_period_s, 3), round(ill.mean_pri_s * 1e3, 4)
    (4.444, 1.0125)
    >>> round(float(10 * np.log10(ill.pattern_gain(np.radians(0.7)))), 2)  # half the 1.4 deg beamwidth: -3 dB
    -3.01
    >>> Illuminator.from_metadata(ill.to_metadata()) == ill
    True
    """

    latitude: float
    longitude: float
    altitude: float
    name: str = "S-band ASR"
    carrier_frequency_hz: float = 2.8e9
    peak_power_w: float = 25e3
    antenna_gain_dbi: float = 34.0
    beamwidth_az_deg: float = 1.4
    sidelobe_db: float = -25.0
    backlobe_db: float = -35.0
    rotation_rpm: float = 13.5
    pri_s: tuple[float, ...] = (1.000e-3, 1.075e-3, 0.950e-3, 1.025e-3)
    long_pulse: Pulse = field(default_factory=lambda: Pulse(100e-6, 1.5e6, -0.9e6, 0.0))
    short_pulse: Pulse = field(default_factory=lambda: Pulse(1e-6, 0.0, 1.4e6, 105e-6))

    def __post_init__(self) -> None:
        for name in ("carrier_frequency_hz", "peak_power_w", "beamwidth_az_deg", "rotation_rpm"):
            _positive(name, getattr(self, name))
        pri = tuple(_positive("pri_s", p) for p in np.atleast_1d(self.pri_s))
        object.__setattr__(self, "pri_s", pri)
        for key in ("long_pulse", "short_pulse"):
            pulse = getattr(self, key)
            pulse = pulse if isinstance(pulse, Pulse) else Pulse(**pulse)
            _positive(f"{key}.width_s", pulse.width_s)
            if pulse.delay_s < 0 or pulse.delay_s + pulse.width_s > min(pri):
                raise InputError(
                    f"illuminator: field '{key}' ({pulse.delay_s} + {pulse.width_s} s) must fit the "
                    f"shortest PRI {min(pri)} s"
                )
            object.__setattr__(self, key, pulse)
        if not self.sidelobe_db < 0 or not self.backlobe_db <= self.sidelobe_db:
            raise InputError(
                "illuminator: need backlobe_db <= sidelobe_db < 0, "
                f"got {self.backlobe_db}, {self.sidelobe_db}"
            )

    # ---- metadata --------------------------------------------------------------------------
    def to_metadata(self) -> dict:
        """The ``skyradar:illuminator`` object of a SigMF recording (JSON-ready)."""
        meta = asdict(self)
        meta["pri_s"] = list(self.pri_s)
        meta["rotation_direction"] = "clockwise"
        meta["source"] = SOURCE
        return meta

    @classmethod
    def from_metadata(cls, meta: dict) -> Illuminator:
        """Build from a ``skyradar:illuminator`` object (unknown keys are ignored, missing ones default)."""
        if meta.get("rotation_direction", "clockwise") != "clockwise":
            raise InputError(
                f"illuminator: field 'rotation_direction' is {meta['rotation_direction']!r}; "
                "only 'clockwise' is modelled"
            )
        names = {f.name for f in fields(cls)}
        kwargs = {k: v for k, v in meta.items() if k in names}
        for key in ("long_pulse", "short_pulse"):
            if key in kwargs:
                value = kwargs[key]
                if not isinstance(value, dict):
                    raise InputError(f"illuminator: field '{key}' must be an object, got {value!r}")
                kwargs[key] = Pulse(
                    **{k: _number(f"{key}.{k}", v) for k, v in value.items() if k in _PULSE_KEYS}
                )
        if "pri_s" in kwargs:
            values = kwargs["pri_s"] if isinstance(kwargs["pri_s"], list | tuple) else [kwargs["pri_s"]]
            kwargs["pri_s"] = tuple(_number("pri_s", p) for p in values)
            if not kwargs["pri_s"]:
                raise InputError("illuminator: field 'pri_s' is empty")
        for key in names - {"name", "long_pulse", "short_pulse", "pri_s"}:
            if key in kwargs:
                kwargs[key] = _number(key, kwargs[key])
        return cls(**kwargs)

    @classmethod
    def from_recording(cls, recording) -> Illuminator:
        """From an :class:`~skyradar.io.iq_recording.IqRecording`'s ``illuminator``; errors name its file."""
        try:
            return cls.from_metadata(recording.illuminator)
        except InputError as exc:
            raise InputError(f"{recording.path}: {exc}") from None

    def replaced(self, **changes) -> Illuminator:
        return replace(self, **changes)

    # ---- derived ---------------------------------------------------------------------------
    @property
    def wavelength_m(self) -> float:
        return C_MPS / self.carrier_frequency_hz

    @property
    def rotation_period_s(self) -> float:
        return 60.0 / self.rotation_rpm

    @property
    def rotation_rate_rad_s(self) -> float:
        return 2.0 * np.pi * self.rotation_rpm / 60.0

    @property
    def mean_pri_s(self) -> float:
        return float(np.mean(self.pri_s))

    def pulses(self) -> tuple[Pulse, Pulse]:
        return self.long_pulse, self.short_pulse

    def pulse_baseband(self, pulse: Pulse, sample_rate_hz: float) -> np.ndarray:
        """The transmitted ``pulse`` sampled from its start (unit amplitude, complex64)."""
        n = int(math.ceil(pulse.width_s * sample_rate_hz - 1e-6))  # 100 us at 5 MS/s: 500, not 501
        return lfm_baseband(np.arange(n) / sample_rate_hz, pulse.width_s, pulse.bandwidth_hz, pulse.offset_hz)

    def long_pulse_baseband(self, sample_rate_hz: float) -> np.ndarray:
        """The long (LFM) pulse as a matched-filter template: 500 samples for 100 us at 5 MS/s.

        Examples
        --------
        >>> Illuminator(52.0, 5.0, 30.0).long_pulse_baseband(5e6).shape
        (500,)
        """
        return self.pulse_baseband(self.long_pulse, sample_rate_hz)

    def short_pulse_baseband(self, sample_rate_hz: float) -> np.ndarray:
        """The short (unmodulated) pulse at its offset frequency."""
        return self.pulse_baseband(self.short_pulse, sample_rate_hz)

    # ---- antenna ---------------------------------------------------------------------------
    def beam_azimuth_rad(self, t_s: np.ndarray | float, azimuth_at_t0_rad: float) -> np.ndarray:
        """Main-beam azimuth (clockwise from north, wrapped to [0, 2 pi)) at times ``t_s``."""
        return np.mod(azimuth_at_t0_rad + self.rotation_rate_rad_s * np.asarray(t_s, dtype=float), 2 * np.pi)

    def pattern_gain(self, delta_az_rad: np.ndarray | float) -> np.ndarray:
        """Azimuth power pattern relative to the peak, for the angle off the beam axis (radians).

        Gaussian main lobe ``exp(-4 ln2 (d / bw)^2)``; beyond it the sidelobe envelope
        ``sidelobe * (d1 / d)^2`` (``d1`` where the main lobe meets ``sidelobe``), floored at ``backlobe``.
        """
        d = np.abs(wrap_angle(delta_az_rad))
        bw = np.radians(self.beamwidth_az_deg)
        main = np.exp(-4.0 * np.log(2.0) * (d / bw) ** 2)
        sl, bl = 10.0 ** (self.sidelobe_db / 10.0), 10.0 ** (self.backlobe_db / 10.0)
        d1 = bw * np.sqrt(np.log(1.0 / sl) / (4.0 * np.log(2.0)))
        envelope = np.clip(sl * (d1 / np.maximum(d, 1e-12)) ** 2, bl, sl)
        return np.maximum(main, envelope)

    @property
    def sidelobe_reach_rad(self) -> float:
        """Angle off the beam axis beyond which the pattern is the back-lobe floor (radians)."""
        bw = np.radians(self.beamwidth_az_deg)
        sl, bl = 10.0 ** (self.sidelobe_db / 10.0), 10.0 ** (self.backlobe_db / 10.0)
        d1 = bw * np.sqrt(np.log(1.0 / sl) / (4.0 * np.log(2.0)))
        return float(max(d1 * np.sqrt(sl / bl), bw * np.sqrt(np.log(1.0 / bl) / (4.0 * np.log(2.0)))))

    # ---- timing ----------------------------------------------------------------------------
    def pulse_times_s(
        self, first_pulse_s: float, t_start_s: float, t_end_s: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """Indices and start times of the PRIs that start in ``[t_start_s, t_end_s)``.

        PRI ``k`` starts at ``first_pulse_s + (k // n) * sum(pri) + sum(pri[: k % n])`` with ``n`` the
        stagger length; ``k`` may be negative (PRIs before ``first_pulse_s``). Computed per window, so
        a chunked simulation never holds the whole schedule.

        Examples
        --------
        >>> ill = Illuminator(52.0, 5.0, 30.0, pri_s=(1e-3, 2e-3))
        >>> k, t = ill.pulse_times_s(0.0, -2.5e-3, 5e-3)
        >>> k.tolist(), np.round(t * 1e3, 6).tolist()
        ([-1, 0, 1, 2, 3], [-2.0, 0.0, 1.0, 3.0, 4.0])
        """
        pri = np.asarray(self.pri_s)
        cycle = float(pri.sum())
        offsets = np.concatenate([[0.0], np.cumsum(pri)[:-1]])
        c0 = math.floor((t_start_s - first_pulse_s) / cycle) - 1
        c1 = math.floor((t_end_s - first_pulse_s) / cycle) + 1
        cycles = np.arange(c0, c1 + 1)
        k = (cycles[:, None] * pri.size + np.arange(pri.size)[None, :]).ravel()
        t = (first_pulse_s + cycles[:, None] * cycle + offsets[None, :]).ravel()
        keep = (t >= t_start_s) & (t < t_end_s)
        return k[keep], t[keep]
