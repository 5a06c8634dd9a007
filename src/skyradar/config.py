"""Radar hardware description and every quantity derived from it.

The default is the thesis prototype (Maas 2022): a 9.425 GHz sawtooth FMCW radar sweeping
10 MHz per chirp at 4921 chirps/s, sampled at 10 MHz, 250 chirps per frame, four receive
antennas in a coplanar 2x2 square, processed to 5 km.

Axis conventions (shared by the image-domain simulator and the raw FFT chain, so their frames
are interchangeable): range bin ``k`` is centred at ``k * dR`` (the FFT bin of beat frequency
``k * PRF``), Doppler bin ``j`` at ``(j - nV/2) * dV`` after the FFT shift. Radial velocity is
positive for a receding target; a velocity outside ``[-VLim, VLim)`` wraps around.

Frames: antenna frame has boresight +x, y right, z down. The :class:`Mount` rotates it into
the aircraft body frame (forward, right, down).

Time-division MIMO. A radar may have 1 to :data:`MAX_TX` transmitters (``tx_positions_m``) that
take turns chirp by chirp: chirp ``n`` of a frame is sent by transmitter ``n mod n_tx``. Each
transmitter's chirps are then spaced ``n_tx / PRF`` apart, so its slow time has ``nV / n_tx``
samples, the unambiguous radial velocity shrinks to ``PRF * lambda / (4 n_tx)`` and the Doppler
axis (``doppler_axis_mps``, ``doppler_bin``) has ``nV / n_tx`` bins of the unchanged width
``PRF * lambda / (2 nV)``. Every transmitter-receiver pair is a virtual channel at
``tx + rx`` (``virtual_positions_m``): the far-field two-way phase is
``-(2 pi / lambda) u . (tx + rx)`` plus a common term, which is the one-way receive phase of
:mod:`skyradar.process.doa` for an antenna at ``tx + rx``. A single-transmitter radar is the case
``n_tx = 1``; its fields, serialisation and hash are those of a radar without ``tx_positions_m``.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from skyradar.antenna import AntennaPattern, GainCut
from skyradar.errors import InputError
from skyradar.rx_layouts import MAX_RX, MAX_TX, MIMO_LAYOUTS, mimo_layout_m, rx_layout_m
from skyradar.units import centred_bin, centred_bin_value, nearest_bin

__all__ = ["SPEED_OF_LIGHT", "BOLTZMANN", "Mount", "RadarConfig"]

SPEED_OF_LIGHT = 299_792_458.0  # m/s
BOLTZMANN = 1.380649e-23  # J/K

# name: (position_m = lever arm (forward, right, down) m, yaw_deg, pitch_deg); roll 0.
_MOUNT_PRESETS: dict[str, tuple[tuple[float, float, float], float, float]] = {
    "forward": ((2.0, 0.0, 0.0), 0.0, 0.0),
    "nose": ((2.0, 0.0, 0.0), 0.0, 0.0),
    "forward-down": ((2.0, 0.0, 0.3), 0.0, -30.0),
    "side-right": ((0.0, 5.0, 0.0), 90.0, -30.0),
    "side-left": ((0.0, -5.0, 0.0), -90.0, -30.0),
    # DAA heads: with the nose's +-35 deg, wingtip heads yawed +-75 deg reach +-110 deg (RTCA DO-366).
    "right-wingtip": ((0.5, 5.0, 0.0), 75.0, 0.0),
    "left-wingtip": ((0.5, -5.0, 0.0), -75.0, 0.0),
    "tail": ((-6.0, 0.0, 0.0), 180.0, 0.0),
    "sky": ((0.0, 0.0, 0.0), 0.0, 0.0),
}


_MAX_APERTURE_M = 2.0  # the largest extent of one radar's antennas, m

# The default of a dataclass field that __post_init__ always replaces (None: "derive it").
_SET_BY_POST_INIT: Any = None


@dataclass(frozen=True)
class Mount:
    """Where the antenna sits on the aircraft and how it is turned.

    Parameters
    ----------
    position_m : tuple of float
        Antenna phase centre in the body frame (forward, right, down), metres.
    yaw_deg, pitch_deg, roll_deg : float
        Antenna frame relative to the body frame (ZYX Euler angles, degrees); pitch is
        positive nose-up, so a forward-down radar has negative pitch.

    Examples
    --------
    >>> Mount.preset("forward-down").pitch_deg
    -30.0
    """

    position_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    yaw_deg: float = 0.0
    pitch_deg: float = 0.0
    roll_deg: float = 0.0

    def __post_init__(self) -> None:
        pos = tuple(float(v) for v in self.position_m)
        if len(pos) != 3 or not all(np.isfinite(pos)):
            raise InputError(f"mount.position_m must be 3 finite numbers, got {self.position_m!r}")
        object.__setattr__(self, "position_m", pos)
        for name in ("yaw_deg", "pitch_deg", "roll_deg"):
            if not np.isfinite(getattr(self, name)):
                raise InputError(f"mount.{name} must be finite, got {getattr(self, name)!r}")

    @classmethod
    def preset(cls, name: str) -> Mount:
        """A named placement (the table above): forward = nose, left/right-wingtip, tail, ``side-*``, ..."""
        if name not in _MOUNT_PRESETS:
            raise InputError(f"mount preset {name!r} unknown; choose from {sorted(_MOUNT_PRESETS)}")
        position_m, yaw_deg, pitch_deg = _MOUNT_PRESETS[name]
        return cls(position_m, yaw_deg, pitch_deg, 0.0)

    @property
    def rotation(self) -> np.ndarray:
        """3x3 matrix taking antenna-frame vectors to body-frame vectors."""
        from skyradar.geo import rotation_matrix

        return rotation_matrix(
            np.radians(self.yaw_deg), np.radians(self.pitch_deg), np.radians(self.roll_deg)
        )


@dataclass(frozen=True)
class RadarConfig:
    """FMCW radar hardware parameters and derived axes (SI units throughout).

    Parameters
    ----------
    fc_hz : float
        Carrier frequency, Hz.
    fs_hz : float
        ADC sampling frequency (complex), Hz.
    prf_hz : float
        Chirp repetition frequency, Hz; one sawtooth chirp fills the repetition interval.
    pe_dbm : float
        Emitted power, dBm.
    bandwidth_hz : float
        Sweep bandwidth per chirp, Hz.
    n_doppler : int
        Chirps per frame (= Doppler bins).
    range_limit_m : float
        Processed range (RLim), m.
    rx_positions_m : ndarray, shape (n_rx, 3), or str
        Receive antenna phase centres in the antenna frame, m, or a layout name of
        :func:`skyradar.rx_layouts.rx_layout_m` (``"square"``, ``"kite"``, ``"ura-2x3"``,
        ``"ura-2x4"``, ``"ura-4x2"``); 1 to 32 distinct positions. Default: the 2x2
        square, half-wavelength spacing. A MIMO layout name of
        :func:`skyradar.rx_layouts.mimo_layout_m` (``"mimo-2x4"``) sets the receive antennas and,
        unless ``tx_positions_m`` is given, the transmitters.
    tx_position_m : ndarray, shape (3,)
        Transmit antenna phase centre in the antenna frame, m; set to the first row of
        ``tx_positions_m`` when that is given.
    noise_figure_db : float
        Receiver noise figure, dB.
    temperature_k : float
        Reference noise temperature, K.
    antenna : AntennaPattern
        One-way gain pattern (the same for transmit and receive).
    mount : Mount
        Antenna placement on the aircraft.
    rx_calibration : ndarray, shape (n_rx,), complex
        Per-channel complex gain the measured signal is divided by (1 = uncalibrated).
    tx_positions_m : ndarray, shape (n_tx, 3), optional
        Transmit antenna phase centres, m, for a time-division MIMO radar (1 to :data:`MAX_TX`
        distinct positions, ``n_tx * n_rx`` at most :data:`MAX_RX` virtual channels, ``n_doppler``
        a multiple of ``n_tx``; module docstring). None for one transmitter at ``tx_position_m``;
        a single row is that case too and is stored as None.

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> round(cfg.range_resolution_m, 2), round(cfg.v_lim_mps, 2), cfg.n_range, cfg.n_doppler
    (14.99, 39.13, 333, 250)
    """

    fc_hz: float = 9.425e9
    fs_hz: float = 10e6
    prf_hz: float = 4921.0
    pe_dbm: float = 40.0
    bandwidth_hz: float = 10e6
    n_doppler: int = 250
    range_limit_m: float = 5000.0
    # The three arrays are always arrays once built: __post_init__ turns a layout name or None into
    # one. What the constructor accepts is spelled out in the __init__ below, for the type checker
    # only (the dataclass writes the real one).
    rx_positions_m: np.ndarray = _SET_BY_POST_INIT
    tx_position_m: np.ndarray = _SET_BY_POST_INIT
    noise_figure_db: float = 6.0
    temperature_k: float = 290.0
    antenna: AntennaPattern = field(default_factory=AntennaPattern.default)
    mount: Mount = field(default_factory=Mount)
    rx_calibration: np.ndarray = _SET_BY_POST_INIT
    tx_positions_m: np.ndarray | None = None

    if TYPE_CHECKING:

        def __init__(
            self,
            fc_hz: float = ...,
            fs_hz: float = ...,
            prf_hz: float = ...,
            pe_dbm: float = ...,
            bandwidth_hz: float = ...,
            n_doppler: int = ...,
            range_limit_m: float = ...,
            rx_positions_m: ArrayLike | str | None = ...,
            tx_position_m: ArrayLike | None = ...,
            noise_figure_db: float = ...,
            temperature_k: float = ...,
            antenna: AntennaPattern = ...,
            mount: Mount = ...,
            rx_calibration: ArrayLike | None = ...,
            tx_positions_m: ArrayLike | None = ...,
        ) -> None: ...

    def __post_init__(self) -> None:
        for name in ("fc_hz", "fs_hz", "prf_hz", "bandwidth_hz", "range_limit_m", "temperature_k"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise InputError(f"radar.{name} must be a positive number, got {value!r}")
        for name in ("pe_dbm", "noise_figure_db"):  # powers in dB: 10 ** (1e11 / 10) overflowed mid-run
            value = getattr(self, name)
            if not (np.isfinite(value) and abs(value) <= 300.0):
                raise InputError(f"radar.{name} must be a finite number of dB within +-300, got {value!r}")
        if int(self.n_doppler) != self.n_doppler or self.n_doppler < 2:
            raise InputError(f"radar.n_doppler must be an integer >= 2, got {self.n_doppler!r}")
        if self.prf_hz >= self.fs_hz:
            raise InputError(f"radar.prf_hz ({self.prf_hz}) must be below fs_hz ({self.fs_hz})")
        rx = "square" if self.rx_positions_m is None else self.rx_positions_m
        tx_many = self.tx_positions_m
        if isinstance(rx, str) and rx in MIMO_LAYOUTS:
            layout_tx, rx = mimo_layout_m(rx, self.wavelength_m)
            tx_many = layout_tx if tx_many is None else tx_many
        rx = rx_layout_m(rx, self.wavelength_m) if isinstance(rx, str) else np.array(rx, dtype=float)
        if rx.size == 0:  # [] from a scenario, or (0, 3)
            rx = rx.reshape(0, 3)
        if rx.ndim != 2 or rx.shape[1] != 3:
            raise InputError(
                f"radar.rx_positions_m must be an (n_rx, 3) array of metres, got shape {rx.shape}"
            )
        if not 1 <= rx.shape[0] <= MAX_RX:
            raise InputError(
                f"radar.rx_positions_m: {rx.shape[0]} receive antennas; a radar has 1 to {MAX_RX}"
            )
        if not np.all(np.isfinite(rx)):
            bad = int(np.flatnonzero(~np.all(np.isfinite(rx), axis=1))[0])
            raise InputError(f"radar.rx_positions_m: antenna {bad} is not finite metres: {rx[bad].tolist()}")
        if rx.shape[0] > 1 and np.ptp(rx, axis=0).max() < 1e-6:
            raise InputError(
                "radar.rx_positions_m: all receive antennas are at one point; no baseline for DoA"
            )
        gap = np.linalg.norm(rx[:, None, :] - rx[None, :, :], axis=2) + np.eye(rx.shape[0])
        if np.any(gap < 1e-6):  # two phase centres in one place: one channel counted twice
            i, j = sorted(int(v) for v in np.argwhere(gap < 1e-6)[0])
            raise InputError(f"radar.rx_positions_m: antennas {i} and {j} coincide at {rx[i].tolist()} m")
        # One radar's antennas sit on one aircraft: within 2 m of each other (a wingspan holds several
        # heads, each its own radar); farther apart they are a mistyped unit, not an array.
        span_m = float(np.ptp(rx, axis=0).max())
        if span_m > _MAX_APERTURE_M:
            raise InputError(
                f"radar.rx_positions_m: the receive antennas span {span_m:.4g} m, more than one radar's "
                f"{_MAX_APERTURE_M:g} m (positions are metres in the antenna frame)"
            )
        # Given transmitters set tx_position_m to their first row (a copy with only tx_positions_m
        # changed carries the old tx_position_m along, so it cannot count as a second opinion).
        tx_many = None if tx_many is None else self._checked_transmitters(tx_many, rx.shape[0])
        if tx_many is not None and tx_many.shape[0] == 1:  # one transmitter: the plain radar
            tx, tx_many = tx_many[0].copy(), None
        elif tx_many is not None:
            tx = tx_many[0].copy()
        else:
            tx = np.zeros(3) if self.tx_position_m is None else np.array(self.tx_position_m, dtype=float)
        if tx.shape != (3,) or not np.all(np.isfinite(tx)):
            raise InputError(f"radar.tx_position_m must be 3 finite metres, got {self.tx_position_m!r}")
        if np.abs(tx).max() > _MAX_APERTURE_M:
            raise InputError(
                f"radar.tx_position_m: {np.abs(tx).max():.4g} m from the antenna frame's origin, more than "
                f"one radar's {_MAX_APERTURE_M:g} m"
            )
        cal = (
            np.ones(rx.shape[0], complex)
            if self.rx_calibration is None
            else np.array(self.rx_calibration, complex)
        )
        if cal.shape != (rx.shape[0],) or not np.all(np.isfinite(cal)) or np.any(cal == 0):
            raise InputError(f"radar.rx_calibration must be {rx.shape[0]} finite non-zero complex gains")
        n_tx = 1 if tx_many is None else tx_many.shape[0]
        if self.n_doppler % n_tx or self.n_doppler // n_tx < 2:
            raise InputError(
                f"radar.n_doppler {self.n_doppler} must be a multiple of the {n_tx} transmitters "
                "with at least 2 chirps per transmitter"
            )
        rx.setflags(write=False)
        tx.setflags(write=False)
        cal.setflags(write=False)
        if tx_many is not None:
            tx_many.setflags(write=False)
        object.__setattr__(self, "rx_positions_m", rx)
        object.__setattr__(self, "tx_position_m", tx)
        object.__setattr__(self, "tx_positions_m", tx_many)
        object.__setattr__(self, "rx_calibration", cal)
        object.__setattr__(self, "n_doppler", int(self.n_doppler))
        if self.range_limit_m > self.rmax_m:
            raise InputError(
                f"radar.range_limit_m {self.range_limit_m} exceeds the unambiguous range {self.rmax_m:.0f} m"
            )
        if self.n_range < 2:  # an image needs range bins; 0 bins crashed every stage downstream
            raise InputError(
                f"radar.range_limit_m {self.range_limit_m} gives {self.n_range} range bins of "
                f"{self.range_resolution_m:.2f} m; needs at least 2"
            )

    @staticmethod
    def _checked_transmitters(value: Any, n_rx: int) -> np.ndarray:
        """``tx_positions_m`` as an (n_tx, 3) float array, or one InputError line naming the field."""
        try:
            tx = np.array(value, dtype=float)
        except (TypeError, ValueError):
            raise InputError(
                f"radar.tx_positions_m must be an (n_tx, 3) array of metres, got {value!r}"
            ) from None
        if tx.ndim != 2 or tx.shape[1] != 3 or tx.shape[0] == 0:
            raise InputError(
                f"radar.tx_positions_m must be an (n_tx, 3) array of metres, got shape {tx.shape}"
            )
        if tx.shape[0] > MAX_TX:
            raise InputError(
                f"radar.tx_positions_m: {tx.shape[0]} transmitters; a time-division MIMO radar has "
                f"1 to {MAX_TX}"
            )
        if not np.all(np.isfinite(tx)):
            bad = int(np.flatnonzero(~np.all(np.isfinite(tx), axis=1))[0])
            raise InputError(
                f"radar.tx_positions_m: transmitter {bad} is not finite metres: {tx[bad].tolist()}"
            )
        if np.abs(tx).max() > _MAX_APERTURE_M:
            raise InputError(
                f"radar.tx_positions_m: {np.abs(tx).max():.4g} m from the antenna frame's origin, more "
                f"than one radar's {_MAX_APERTURE_M:g} m"
            )
        gap = np.linalg.norm(tx[:, None, :] - tx[None, :, :], axis=2) + np.eye(tx.shape[0])
        if np.any(gap < 1e-6):  # two transmitters in one place: their virtual channels coincide
            i, j = sorted(int(v) for v in np.argwhere(gap < 1e-6)[0])
            raise InputError(f"radar.tx_positions_m: transmitters {i} and {j} coincide at {tx[i].tolist()} m")
        if tx.shape[0] * n_rx > MAX_RX:
            raise InputError(
                f"radar.tx_positions_m: {tx.shape[0]} transmitters x {n_rx} receivers are "
                f"{tx.shape[0] * n_rx} virtual channels; a radar has at most {MAX_RX}"
            )
        return tx

    @classmethod
    def prototype_2022(cls, **changes: Any) -> RadarConfig:
        """The 2022 thesis prototype (Maas 2022, the X-band FMCW radar flown on a light aircraft), with
        optional field overrides."""
        return cls(**changes)

    def replace(self, **changes: Any) -> RadarConfig:
        """A copy with some fields changed (dataclasses.replace)."""
        return replace(self, **changes)

    # ---- derived quantities -------------------------------------------------------------
    @property
    def wavelength_m(self) -> float:
        return SPEED_OF_LIGHT / self.fc_hz

    @property
    def n_rx(self) -> int:
        return int(self.rx_positions_m.shape[0])

    @property
    def n_tx(self) -> int:
        """Transmitters taking turns chirp by chirp (1 without ``tx_positions_m``)."""
        return 1 if self.tx_positions_m is None else int(self.tx_positions_m.shape[0])

    @property
    def transmitters_m(self) -> np.ndarray:
        """Transmit phase centres (n_tx, 3), m: ``tx_positions_m``, or ``tx_position_m`` as one row."""
        return self.tx_position_m[None, :] if self.tx_positions_m is None else self.tx_positions_m

    @property
    def n_virtual(self) -> int:
        """Virtual channels, ``n_tx * n_rx``."""
        return self.n_tx * self.n_rx

    @cached_property
    def virtual_positions_m(self) -> np.ndarray:
        """Virtual channel positions (n_tx * n_rx, 3), m: ``tx + rx``, transmitter-major.

        Channel ``t * n_rx + r`` is transmitter ``t`` with receiver ``r``; its far-field phase is
        ``-(2 pi / lambda) u . (tx_t + rx_r)`` plus a common term (module docstring).

        >>> cfg = RadarConfig.prototype_2022(rx_positions_m="mimo-2x4")
        >>> cfg.n_tx, cfg.n_rx, cfg.virtual_positions_m.shape
        (2, 4, (8, 3))
        """
        v = (self.transmitters_m[:, None, :] + self.rx_positions_m[None, :, :]).reshape(-1, 3)
        v.setflags(write=False)
        return v

    def terrain_channel_positions_m(self, ground_velocity_mps: ArrayLike) -> np.ndarray:
        """Where each channel of a frame sees static terrain from, in the antenna frame, m (n_virtual, 3).

        One transmitter: the receivers. Time-division MIMO: channel ``t * n_rx + r`` is transmitter
        ``t`` with receiver ``r``, its two-way path ``|P - tx_t| + |P - rx_r|`` plus the slot's
        Doppler path ``2 v_r t / PRF`` (transmitter ``t`` chirps ``t / PRF`` after transmitter 0,
        and each transmitter's slow time starts at its first chirp). In the far field
        ``|P - tx_t| = |P - tx_0| - u . (tx_t - tx_0)``, and a static point's radial velocity is
        ``v_r = u . w`` for the terrain's velocity ``w`` relative to the antenna, so the path is
        that of transmitter 0 with a receiver at ``rx_r + (tx_t - tx_0) - 2 w t / PRF``. Every
        static point of a frame shares these positions (``w`` is one vector), so whatever takes
        one transmitter and any receivers treats the virtual channels exactly to first order in
        the antenna's size over the range: the simulator's terrain kernels, and the predicted
        clutter covariance (:func:`skyradar.process.clutter.clutter_subspace`). Moving targets
        have their own slot phase (:func:`skyradar.sim.targets.target_geometry`).

        Parameters
        ----------
        ground_velocity_mps : array_like, shape (3,)
            Velocity of static terrain relative to the antenna, in the antenna frame (minus the
            antenna's own velocity), m/s.

        Returns
        -------
        ndarray, shape (n_virtual, 3)

        Examples
        --------
        >>> cfg = RadarConfig.prototype_2022(rx_positions_m="mimo-2x4")
        >>> p = cfg.terrain_channel_positions_m([-50.0, 0.0, 0.0])
        >>> p.shape, bool(np.allclose(p[:4], cfg.rx_positions_m))
        ((8, 3), True)
        >>> shift = p[4:] - cfg.rx_positions_m - (cfg.transmitters_m[1] - cfg.transmitters_m[0])
        >>> np.round(shift[0] * 1e3, 2).tolist()  # 2 * 50 m/s / PRF along boresight, mm
        [20.32, 0.0, 0.0]
        """
        if self.n_tx == 1:
            return self.rx_positions_m
        slot_s = np.arange(self.n_tx) / self.prf_hz
        tx = self.transmitters_m
        w = np.asarray(ground_velocity_mps, float)
        offset = (tx - tx[0])[:, None, :] - 2.0 * slot_s[:, None, None] * w
        return (offset + self.rx_positions_m[None]).reshape(-1, 3)

    def require_one_transmitter(self, what: str, instead: str) -> None:
        """InputError naming ``radar.tx_positions_m`` when ``what``, a one-transmitter model, gets several.

        ``instead`` says what handles a time-division MIMO radar.
        """
        if self.n_tx > 1:
            raise InputError(
                f"radar.tx_positions_m: {what} models one transmitter, got {self.n_tx}; {instead}"
            )

    @property
    def n_doppler_per_tx(self) -> int:
        """Chirps of one transmitter per frame, ``n_doppler / n_tx``: the Doppler bins of a frame."""
        return self.n_doppler // self.n_tx

    @property
    def frame_shape(self) -> tuple[int, int, int]:
        """Shape of one range-Doppler frame: ``(n_range, n_doppler_per_tx, n_virtual)``.

        One channel per receiver, or per virtual channel (transmitter-major) for a time-division
        MIMO radar, whose frame has one transmitter's ``nV / n_tx`` Doppler bins.

        >>> RadarConfig.prototype_2022().frame_shape
        (333, 250, 4)
        >>> RadarConfig.prototype_2022(rx_positions_m="mimo-2x4").frame_shape
        (333, 125, 8)
        """
        return self.n_range, self.n_doppler_per_tx, self.n_virtual

    @property
    def rmax_m(self) -> float:
        """Unambiguous range c*Fs / (2*B*PRF), m."""
        return SPEED_OF_LIGHT * self.fs_hz / (2.0 * self.bandwidth_hz * self.prf_hz)

    @property
    def range_resolution_m(self) -> float:
        """dR = c / (2B), m."""
        return SPEED_OF_LIGHT / (2.0 * self.bandwidth_hz)

    @property
    def v_lim_mps(self) -> float:
        """Nyquist radial velocity PRF * lambda / (4 n_tx), m/s (each transmitter chirps every n_tx / PRF)."""
        return self.prf_hz * self.wavelength_m / (4.0 * self.n_tx)

    @property
    def doppler_resolution_mps(self) -> float:
        """dV = 2 VLim / (nV / n_tx), m/s."""
        return 2.0 * self.v_lim_mps / self.n_doppler_per_tx

    @property
    def samples_per_chirp(self) -> int:
        """ADC samples in one chirp, Fs / PRF (rounded down)."""
        return int(self.fs_hz // self.prf_hz)

    @property
    def chirp_slope_hz_per_s(self) -> float:
        return self.bandwidth_hz * self.prf_hz

    @property
    def n_range(self) -> int:
        """Range bins from 0 up to RLim."""
        return int(self.range_limit_m // self.range_resolution_m)

    @property
    def frame_duration_s(self) -> float:
        """Coherent integration time of one frame, nV / PRF, s."""
        return self.n_doppler / self.prf_hz

    @property
    def range_doppler_coupling_s(self) -> float:
        """Apparent range shift per unit radial velocity, fc / (B * PRF), s (m per m/s).

        A sawtooth chirp adds the Doppler shift 2v/lambda to the beat frequency, so the target
        appears ``v * fc / (B * PRF)`` further away (0.19 m per m/s for the prototype).
        """
        return self.fc_hz / self.chirp_slope_hz_per_s

    @cached_property
    def range_axis_m(self) -> np.ndarray:
        """Range bin centres k * dR, m."""
        return np.arange(self.n_range) * self.range_resolution_m

    @cached_property
    def doppler_axis_mps(self) -> np.ndarray:
        """Doppler bin centres (j - nD/2) * dV, m/s (FFT-shifted order), ``nD = n_doppler_per_tx``."""
        n = self.n_doppler_per_tx
        return centred_bin_value(np.arange(n), self.doppler_resolution_mps, n)

    # ---- bin <-> physical units (skyradar.units: ties round up, Doppler wraps) -------------
    def range_bin(self, range_m: ArrayLike, radial_velocity_mps: ArrayLike = 0.0) -> np.ndarray:
        """Range bin (int64, unclipped) where a return at ``range_m`` moving at ``radial_velocity_mps`` shows.

        The sawtooth chirp shifts it by ``v * range_doppler_coupling_s``: ``floor((R + v c) / dR + 0.5)``.

        >>> cfg = RadarConfig.prototype_2022()
        >>> cfg.range_bin([0.0, 1010.0]).tolist(), int(cfg.range_bin(1010.0, 30.0))
        ([0, 67], 68)
        """
        shift_m = np.asarray(radial_velocity_mps, float) * self.range_doppler_coupling_s
        return nearest_bin(np.asarray(range_m, float) + shift_m, self.range_resolution_m)

    def doppler_bin(self, radial_velocity_mps: ArrayLike) -> np.ndarray:
        """Doppler bin (FFT-shifted) of a radial velocity, wrapped into ``[0, n_doppler_per_tx)`` (int64).

        >>> cfg = RadarConfig.prototype_2022()
        >>> cfg.doppler_bin([0.0, -cfg.v_lim_mps, cfg.v_lim_mps]).tolist()
        [125, 0, 0]
        """
        return centred_bin(radial_velocity_mps, self.doppler_resolution_mps, self.n_doppler_per_tx)

    def range_at_bin_m(self, range_bin: ArrayLike) -> np.ndarray:
        """Range ``k * dR`` of a (possibly fractional) range bin, m."""
        return np.asarray(range_bin, float) * self.range_resolution_m

    def radial_velocity_at_bin_mps(self, doppler_bin: ArrayLike) -> np.ndarray:
        """Radial velocity ``(j - nV // 2) * dV`` of a (possibly fractional) Doppler bin, m/s.

        >>> float(RadarConfig.prototype_2022().radial_velocity_at_bin_mps(125.5)) > 0
        True
        """
        return centred_bin_value(doppler_bin, self.doppler_resolution_mps, self.n_doppler_per_tx)

    @property
    def pe_w(self) -> float:
        return 10.0 ** ((self.pe_dbm - 30.0) / 10.0)

    @property
    def noise_bandwidth_hz(self) -> float:
        """Noise bandwidth of one range-Doppler pixel after coherent integration over one
        transmitter's chirps: ``PRF / (nV / n_tx)``, Hz (``PRF / nV`` for one transmitter)."""
        return self.prf_hz / self.n_doppler_per_tx

    @property
    def noise_power_w(self) -> float:
        """Thermal noise power per pixel, k T B_n F, W (pixel units: received power in W)."""
        return BOLTZMANN * self.temperature_k * self.noise_bandwidth_hz * 10 ** (self.noise_figure_db / 10.0)

    # ---- serialisation --------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """JSON-able description, round-trips through :meth:`from_dict`."""
        ant = self.antenna
        out: dict[str, Any] = {
            "fc_hz": self.fc_hz,
            "fs_hz": self.fs_hz,
            "prf_hz": self.prf_hz,
            "pe_dbm": self.pe_dbm,
            "bandwidth_hz": self.bandwidth_hz,
            "n_doppler": self.n_doppler,
            "range_limit_m": self.range_limit_m,
            "rx_positions_m": self.rx_positions_m.tolist(),
            "tx_position_m": self.tx_position_m.tolist(),
            "noise_figure_db": self.noise_figure_db,
            "temperature_k": self.temperature_k,
            "antenna": {
                "combine": ant.combine,
                "azimuth": [ant.azimuth.angle_deg.tolist(), ant.azimuth.gain_db.tolist()],
                "elevation": [ant.elevation.angle_deg.tolist(), ant.elevation.gain_db.tolist()],
            },
            "mount": {"position_m": list(self.mount.position_m)}
            | {k: getattr(self.mount, k) for k in ("yaw_deg", "pitch_deg", "roll_deg")},
            "rx_calibration": [[c.real, c.imag] for c in self.rx_calibration],
        }
        if self.tx_positions_m is not None:  # only MIMO radars carry the key: one-TX hashes stay put
            out["tx_positions_m"] = self.tx_positions_m.tolist()
        return out

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> RadarConfig:
        """Inverse of :meth:`to_dict`."""
        data = dict(data)
        ant = data.pop("antenna", None)
        if ant is not None:
            data["antenna"] = AntennaPattern(
                GainCut(*ant["azimuth"]), GainCut(*ant["elevation"]), ant["combine"]
            )
        mount = data.pop("mount", None)
        if mount is not None:
            data["mount"] = Mount(**mount)
        cal = data.pop("rx_calibration", None)
        if cal is not None:
            data["rx_calibration"] = np.array([complex(re, im) for re, im in cal])
        unknown = set(data) - {f for f in cls.__dataclass_fields__}
        if unknown:
            raise InputError(f"radar: unknown field(s) {sorted(unknown)}")
        return cls(**data)

    def to_json(self) -> str:
        return json.dumps(self.to_dict())

    @classmethod
    def from_json(cls, text: str) -> RadarConfig:
        return cls.from_dict(json.loads(text))

    def __hash__(self) -> int:
        return hash(self.to_json())

    def __eq__(self, other: object) -> bool:
        return isinstance(other, RadarConfig) and self.to_json() == other.to_json()
