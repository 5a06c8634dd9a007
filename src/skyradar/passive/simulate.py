"""Simulate the IQ a passive receiver records, streamed to a SigMF file chunk by chunk.

The complex baseband at the receiver (centred on the illuminator's carrier, sample value^2 = W at the
antenna port) is the sum of

- the direct path of every pulse (long LFM and short), delayed by ``L / c`` and scaled by the Friis
  equation with the transmit pattern toward the receiver: main-lobe strong once per sweep, sidelobe
  level otherwise (:mod:`skyradar.passive.budget`);
- an echo of every pulse from every static reflector and aircraft, delayed by ``(r_tx + r_rx) / c``,
  scaled by the bistatic radar equation with the pattern toward the reflector, with the carrier phase
  ``-2 pi fc tau(t)`` whose rate is the bistatic Doppler (aircraft: ``tau`` follows the trajectory,
  linearised over each pulse);
- complex white Gaussian noise of power ``k T0 F fs``.

Each pulse is generated analytically at the exact (fractional) delay and only over its own samples. The
far-sidelobe part of the static echoes is the same after every pulse and is computed once (see
:class:`_Synthesiser`); only reflectors near the beam are generated pulse by pulse. The recording is
produced in chunks of ``chunk_samples``: memory is one chunk plus that chunk's pulse list, whatever
the duration. Noise comes from fixed 65536-sample blocks each seeded by (seed, block), so the samples do
not depend on the chunk size.
"""

from __future__ import annotations

import math
from collections import deque
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numba
import numpy as np

from skyradar.errors import InputError
from skyradar.io.sigmf_io import SigmfWriter, sigmf_paths
from skyradar.passive.budget import direct_path_power_w, echo_power_w
from skyradar.passive.illuminator import C_MPS
from skyradar.passive.scene import PassiveScene, bistatic_geometry
from skyradar.units import wrap_angle

__all__ = ["NOISE_BLOCK", "check_sample_rate", "simulate_chunk", "simulate_recording"]

NOISE_BLOCK = 65_536


@numba.njit(cache=True, nogil=True)
def _add_pulses(buf, buf_start, fs, fc, t_emit, tau0, tau_rate, amp, width, f0, k):  # pragma: no cover
    # Pulse j arrives at t_ref = t_emit + tau0 and its delay changes at tau_rate (s/s). With
    # u = t - t_ref the pulse time is tp = u (1 - rate) and the phase
    #   phase0 - 2 pi fc rate u + 2 pi tp (f0 + k tp / 2) = phase0 + a u + b u^2,
    # quadratic in the sample index: two complex products per sample (a phasor recurrence) instead of
    # a cos and a sin; the phase is recomputed exactly at the start of each pulse.
    two_pi = 2.0 * np.pi
    dt = 1.0 / fs
    for j in range(t_emit.size):
        t_ref = t_emit[j] + tau0[j]
        shrink = 1.0 - tau_rate[j]
        first = int(math.ceil(t_ref * fs)) - buf_start
        last = int(math.ceil((t_ref + width[j] / shrink) * fs)) - buf_start
        lo, hi = max(first, 0), min(last, buf.size)
        if lo >= hi:
            continue
        cycles = fc * tau0[j]
        phase0 = -two_pi * (cycles - math.floor(cycles))
        a = -two_pi * fc * tau_rate[j] + two_pi * f0[j] * shrink
        b = np.pi * k[j] * shrink * shrink
        u0 = (buf_start + lo) * dt - t_ref
        ph0 = phase0 + a * u0 + b * u0 * u0
        step_c = b * dt * dt
        step_b = a * dt + 2.0 * b * u0 * dt
        z = amp[j] * complex(math.cos(ph0), math.sin(ph0))
        w = complex(math.cos(step_b + step_c), math.sin(step_b + step_c))
        r = complex(math.cos(2.0 * step_c), math.sin(2.0 * step_c))
        for n in range(lo, hi):
            buf[n] += z
            z *= w
            w *= r


def _noise(seed: int, start: int, stop: int, power_w: float) -> np.ndarray:
    b0, b1 = start // NOISE_BLOCK, (stop - 1) // NOISE_BLOCK + 1
    blocks = [
        np.random.default_rng([seed, 7, b])
        .standard_normal(2 * NOISE_BLOCK, dtype=np.float32)
        .view(np.complex64)
        for b in range(b0, b1)
    ]
    out = np.concatenate(blocks)[start - b0 * NOISE_BLOCK : stop - b0 * NOISE_BLOCK]
    return out.astype(np.complex128) * math.sqrt(power_w / 2.0)


def _max_delay_s(scene: PassiveScene) -> float:
    tx = scene.illuminator_ned_m
    points = [scene.reflectors.position_ned_m] + [a.trajectory.position_ned_m for a in scene.aircraft]
    pos = np.concatenate(points) if points else np.zeros((1, 3))
    if pos.size == 0:
        return 0.0
    rsum = np.linalg.norm(pos - tx, axis=1) + np.linalg.norm(pos, axis=1)
    return float(rsum.max()) / C_MPS + 1e-5


class _Synthesiser:
    """What does not change from pulse to pulse: static echo amplitudes and delays, far-sidelobe responses.

    A static reflector's echo amplitude is ``A_i sqrt(g)`` (``g`` the power pattern toward it). Split as
    ``A_i sqrt(floor) + A_i (sqrt(g) - sqrt(floor))``: the first term, summed over all reflectors, is the
    same waveform after every pulse (cached per sub-sample emission offset and added as a block); only
    reflectors near the beam, where ``g`` exceeds the backlobe floor, are generated pulse by pulse.
    """

    def __init__(self, scene: PassiveScene, fs: float) -> None:
        self.scene, self.fs = scene, fs
        ill, rx, refl = scene.illuminator, scene.receiver, scene.reflectors
        self.args = (ill.peak_power_w, ill.antenna_gain_dbi)
        g = bistatic_geometry(
            refl.position_ned_m, np.zeros_like(refl.position_ned_m), scene.illuminator_ned_m, 1.0
        )
        self.tau = (g["r_tx_m"] + g["r_rx_m"]) / C_MPS
        self.amp1 = np.sqrt(
            echo_power_w(
                *self.args, 1.0, rx.antenna_gain_dbi, ill.wavelength_m, refl.rcs_m2, g["r_tx_m"], g["r_rx_m"]
            )
        )
        self.az = scene.azimuth_from_tx_rad(refl.position_ned_m)
        self.floor = 10.0 ** (ill.backlobe_db / 20.0)  # amplitude pattern floor
        self.max_delay_s = _max_delay_s(scene)
        self._cache: dict[tuple[int, int], np.ndarray] = {}

    def floor_block(self, pulse_index: int, pulse, frac: float) -> np.ndarray:
        """The summed far-sidelobe echo of every static reflector for a pulse emitted ``frac`` samples
        after a sample instant (samples from that instant on)."""
        key = (pulse_index, int(round(frac * 1e9)))
        block = self._cache.get(key)  # read once: another thread may clear the cache meanwhile
        if block is None:
            if len(self._cache) > 64:  # a stagger that is no multiple of the sample period: no reuse
                self._cache.clear()
            n = int(math.ceil((self.max_delay_s + pulse.width_s) * self.fs)) + 2
            block = np.zeros(n, complex)
            m = self.tau.size
            _add_pulses(
                block,
                0,
                self.fs,
                self.scene.illuminator.carrier_frequency_hz,
                np.full(m, frac / self.fs),
                self.tau,
                np.zeros(m),
                self.amp1 * self.floor,
                np.full(m, pulse.width_s),
                np.full(m, pulse.offset_hz - 0.5 * pulse.bandwidth_hz),
                np.full(m, pulse.bandwidth_hz / pulse.width_s),
            )
            self._cache[key] = block
        return block

    def contributions(self, t_emit: np.ndarray):
        """(t_emit, tau0, tau_rate, amplitude) of the direct path, near-beam static echoes and aircraft."""
        scene, ill, rx = self.scene, self.scene.illuminator, self.scene.receiver
        az_beam = ill.beam_azimuth_rad(t_emit, scene.azimuth_at_t0_rad)
        az_rx = scene.azimuth_from_tx_rad(np.zeros((1, 3)))[0]
        p_direct = direct_path_power_w(
            *self.args,
            ill.pattern_gain(az_rx - az_beam),
            rx.antenna_gain_dbi,
            ill.wavelength_m,
            scene.baseline_m,
        )
        n = t_emit.size
        out = [(t_emit, np.full(n, scene.baseline_m / C_MPS), np.zeros(n), np.sqrt(p_direct))]
        if self.tau.size:
            # Only reflectors within the sidelobe reach of the arc the beam sweeps here rise above the floor.
            sweep = ill.rotation_rate_rad_s * (t_emit[-1] - t_emit[0])
            centre = ill.beam_azimuth_rad(0.5 * (t_emit[0] + t_emit[-1]), scene.azimuth_at_t0_rad)
            off = np.abs(wrap_angle(self.az - centre))
            near = np.nonzero(off <= 0.5 * sweep + ill.sidelobe_reach_rad + 1e-6)[0]
            excess = np.sqrt(ill.pattern_gain(self.az[near][None, :] - az_beam[:, None])) - self.floor
            i_pulse, i_near = np.nonzero(excess > 1e-12 * self.floor)
            i_refl = near[i_near]
            amp = self.amp1[i_refl] * excess[i_pulse, i_near]
            out.append((t_emit[i_pulse], self.tau[i_refl], np.zeros(i_pulse.size), amp))
        for plane in scene.aircraft:
            out.append(self._aircraft(plane, t_emit))
        return [np.concatenate(col) for col in zip(*out, strict=True)]

    def _aircraft(self, plane, t_emit: np.ndarray):
        scene, ill, rx = self.scene, self.scene.illuminator, self.scene.receiver
        present, pos, _ = plane.states(t_emit)
        te = t_emit[present]
        r_tx = np.linalg.norm(pos[present] - scene.illuminator_ned_m, axis=1)
        present2, pos, vel = plane.states(te + r_tx / C_MPS)  # where the pulse meets the aircraft
        te, pos, vel = te[present2], pos[present2], vel[present2]
        g = bistatic_geometry(pos, vel, scene.illuminator_ned_m, ill.wavelength_m)
        gain = ill.pattern_gain(
            scene.azimuth_from_tx_rad(pos) - ill.beam_azimuth_rad(te, scene.azimuth_at_t0_rad)
        )
        power = echo_power_w(
            *self.args, gain, rx.antenna_gain_dbi, ill.wavelength_m, plane.rcs_m2, g["r_tx_m"], g["r_rx_m"]
        )
        rsum = g["r_tx_m"] + g["r_rx_m"]
        return te, rsum / C_MPS, g["range_sum_rate_mps"] / C_MPS, np.sqrt(power)


def simulate_chunk(
    scene: PassiveScene,
    sample_rate_hz: float,
    start: int,
    stop: int,
    noise: bool = True,
    synthesiser: _Synthesiser | None = None,
) -> np.ndarray:
    """Samples ``start .. stop`` of the recording (complex128); the same for any chunking.

    Examples
    --------
    >>> from skyradar.passive.scene import thesis_scene
    >>> s = thesis_scene(duration_s=0.01)
    >>> x = simulate_chunk(s, 5e6, 0, 5000)
    >>> # the first direct pulse: emitted at 0.2 ms, arrives 40 us later (12 km)
    >>> x.shape, bool(np.abs(x[1500:1800]).max() > 100 * np.abs(x[:900]).std())
    ((5000,), True)
    """
    fs = float(sample_rate_hz)
    ill = scene.illuminator
    synth = synthesiser or _Synthesiser(scene, fs)
    buf = (
        _noise(scene.seed, start, stop, scene.receiver.noise_power_w(fs))
        if noise
        else np.zeros(stop - start, complex)
    )
    lookback = synth.max_delay_s + max(p.delay_s + p.width_s for p in ill.pulses()) + 1.0 / fs
    _, t_pri = ill.pulse_times_s(scene.first_pulse_s, start / fs - lookback, stop / fs)
    for index, pulse in enumerate(ill.pulses()):
        t_emit = t_pri + pulse.delay_s
        if t_emit.size == 0:
            continue
        te, tau0, rate, amp = synth.contributions(t_emit)
        n = te.size
        f0 = np.full(n, pulse.offset_hz - 0.5 * pulse.bandwidth_hz)
        k = np.full(n, pulse.bandwidth_hz / pulse.width_s)
        fc = ill.carrier_frequency_hz
        _add_pulses(buf, start, fs, fc, te, tau0, rate, amp, np.full(n, pulse.width_s), f0, k)
        if synth.tau.size:
            for t in t_emit:
                n0 = int(math.floor(t * fs))
                block = synth.floor_block(index, pulse, t * fs - n0)
                lo, hi = max(n0, start), min(n0 + block.size, stop)
                if lo < hi:
                    buf[lo - start : hi - start] += block[lo - n0 : hi - n0]
    return buf


def check_sample_rate(scene: PassiveScene, sample_rate_hz: float) -> None:
    """Raise :class:`InputError` when a pulse of the illuminator does not fit in +-fs/2.

    A chirp reaches ``|offset| + B/2`` from the carrier, an unmodulated pulse ``|offset| + 1/width``
    (its spectrum's first null).

    Parameters
    ----------
    scene : PassiveScene
        The scene whose illuminator's pulses are checked.
    sample_rate_hz : float
        The complex sample rate, Hz.

    Examples
    --------
    The default long pulse spans -1.65 to -0.15 MHz (0.9 MHz below the carrier, 1.5 MHz wide):

    >>> from skyradar.passive.scene import thesis_scene
    >>> check_sample_rate(thesis_scene(duration_s=0.01), 5e6)
    >>> check_sample_rate(thesis_scene(duration_s=0.01), 3e6)
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: the illuminator's long_pulse reaches 1.65e+06 Hz from the carrier, ...
    """
    for name, p in zip(("long_pulse", "short_pulse"), scene.illuminator.pulses(), strict=True):
        edge = abs(p.offset_hz) + 0.5 * p.bandwidth_hz + (1.0 / p.width_s if p.bandwidth_hz == 0 else 0.0)
        if edge > sample_rate_hz / 2:
            raise InputError(
                f"the illuminator's {name} reaches {edge:g} Hz from the carrier, beyond the Nyquist limit "
                f"{sample_rate_hz / 2:g} Hz of sample rate {sample_rate_hz:g} Hz"
            )


def _write_next(writer: SigmfWriter, pending: deque, progress, total: int) -> None:
    block = pending.popleft().result()
    writer.write(block)
    if progress is not None:
        progress(min(writer.n_samples, total), total)


def simulate_recording(
    scene: PassiveScene,
    path: str | Path,
    sample_rate_hz: float = 5e6,
    chunk_samples: int = 1 << 20,
    overwrite: bool = False,
    progress=None,
    workers: int = 2,
) -> Path:
    """Simulate ``scene`` into ``NAME.sigmf-meta``/``-data`` plus the truth sidecars; return the meta path.

    ``progress``, if given, is called with (samples done, total) after each chunk. ``workers`` threads
    simulate chunks in parallel; the samples do not depend on it.

    Parameters
    ----------
    scene : PassiveScene
        What to simulate.
    path : str or Path
        The recording: ``NAME``, ``NAME.sigmf-meta`` or ``NAME.sigmf-data``.
    sample_rate_hz : float
        Complex sample rate, Hz (the pulses must fit in +-fs/2, :func:`check_sample_rate`).
    chunk_samples : int
        Samples simulated per chunk (memory, not the result).
    overwrite : bool
        Replace an existing recording.
    progress : callable, optional
        ``progress(samples_done, total)`` after each chunk.
    workers : int
        Threads simulating chunks.

    Returns
    -------
    Path
        The ``NAME.sigmf-meta`` written (with ``NAME.sigmf-data`` and the truth sidecars).

    Examples
    --------
    4 ms (20 000 samples at 5 MS/s). The first pulse leaves at 0 s and its direct path arrives 12 km
    later (40 us, sample 200), 100 us long (to sample 700), far above the noise before it:

    >>> import tempfile, pathlib
    >>> from skyradar.geo import ned_to_geodetic
    >>> from skyradar.io.sigmf_io import read_iq_recording
    >>> from skyradar.passive.illuminator import Illuminator
    >>> from skyradar.passive.scene import PassiveScene, Receiver, Reflectors
    >>> rx = Receiver(52.0, 5.0, 40.0)
    >>> ill = Illuminator(*map(float, ned_to_geodetic(np.array([0.0, -12000.0, 0.0]), *rx.geodetic)))
    >>> scene = PassiveScene(rx, ill, Reflectors(np.zeros((0, 3)), [], "building", "none"), duration_s=0.004)
    >>> with tempfile.TemporaryDirectory() as d:
    ...     meta = simulate_recording(scene, pathlib.Path(d) / "rec")
    ...     names = sorted(p.name for p in pathlib.Path(d).iterdir())
    ...     x = read_iq_recording(meta).read(0, 20_000)
    >>> names
    ['rec.sigmf-data', 'rec.sigmf-meta', 'rec.truth.json', 'rec.truth.parquet']
    >>> x.size, bool(np.abs(x[210:690]).min() > 10 * np.abs(x[:190]).max())
    (20000, True)
    """
    from skyradar.passive.truth import write_truth

    if chunk_samples < 1 or workers < 1:
        raise InputError(f"chunk_samples and workers must be >= 1, got {chunk_samples}, {workers}")
    check_sample_rate(scene, sample_rate_hz)
    meta_path, _ = sigmf_paths(path)
    synth = _Synthesiser(scene, float(sample_rate_hz))
    total = int(round(scene.duration_s * sample_rate_hz))
    with SigmfWriter(
        meta_path,
        sample_rate_hz,
        scene.illuminator.carrier_frequency_hz,
        scene.receiver.position_dict(),
        scene.illuminator.to_metadata(),
        receiver_info=scene.receiver.info(),
        start_time=scene.start_time,
        description=scene.description,
        overwrite=overwrite,
    ) as writer:

        def job(start: int) -> np.ndarray:
            stop = min(start + chunk_samples, total)
            return simulate_chunk(scene, sample_rate_hz, start, stop, synthesiser=synth).astype(np.complex64)

        # Chunks are independent: `workers` threads (numba and numpy release the GIL) compute them, at most
        # workers + 1 in memory, written in order.
        with ThreadPoolExecutor(max_workers=workers) as pool:
            pending: deque = deque()
            for start in range(0, total, chunk_samples):
                pending.append(pool.submit(job, start))
                if len(pending) > workers:
                    _write_next(writer, pending, progress, total)
            while pending:
                _write_next(writer, pending, progress, total)
    write_truth(scene, meta_path, sample_rate_hz)
    return meta_path
