"""Passive processing of a whole recording, streamed in chunks: IQ -> detections table.

Pass over the recording chunk by chunk (:class:`~skyradar.passive.profiles.ProfileExtractor`): pulse
profiles go into a rolling buffer one dwell long; each dwell (hop about a third of a dwell) is searched by
:func:`~skyradar.passive.dwell.detect_dwell`. Memory is one chunk plus one dwell of profiles, plus a
few numbers per pulse (time and direct-path amplitude) for the scan phase. At the end the scan phase
(:func:`~skyradar.passive.pulses.scan_phase`) gives each candidate its beam azimuth; candidates of one
target in overlapping dwells merge into one detection (azimuth the SNR-weighted mean); the bistatic
ellipse gives east/north; the blind zone is dropped.

Output columns: :data:`COLUMNS` (``time_s, sweep, channel, bistatic_range_m, doppler_hz, snr_db,
azimuth_deg, east_m, north_m, r_tx_m, r_rx_m``; east/north in metres from the receiver, in its
horizontal plane), each one's unit and meaning in :data:`PASSIVE_TABLE_COLUMNS`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from skyradar.errors import InputError
from skyradar.geo import geodetic_to_ned
from skyradar.passive.bistatic import C_MPS, ellipse_point, in_blind_zone
from skyradar.passive.dwell import DwellSettings, detect_dwells
from skyradar.passive.illuminator import Illuminator, lfm_baseband
from skyradar.passive.mti import dwell_pulses
from skyradar.passive.profiles import ProfileExtractor, read_chunks
from skyradar.passive.pulses import estimate_pulse, scan_phase

__all__ = [
    "PassiveSettings",
    "PassiveResult",
    "process_recording",
    "merge_candidates",
    "drop_sidelobes",
    "COLUMNS",
    "PASSIVE_TABLE_COLUMNS",
]

# The passive detections table (``skyradar passive``), column -> "unit; meaning" (skyradar.io.table_columns).
PASSIVE_TABLE_COLUMNS: dict[str, str] = {
    "time_s": "s; time of the detection's strongest look, from the recording's first sample",
    "sweep": "-; the illuminator's rotation: one rotation centred on a main-beam crossing of the receiver",
    "channel": "-; static (the zero-Doppler channel) or moving (the moving-target channel)",
    "bistatic_range_m": "m; extra path of the echo over the direct path, R1 + R2 - L",
    "doppler_hz": "Hz; bistatic Doppler shift (0 in the static channel)",
    "snr_db": "dB; signal-to-noise ratio against the CFAR's local noise estimate",
    "azimuth_deg": "deg; the illuminator's beam azimuth at the detection, clockwise from north",
    "east_m": "m; position east of the receiver, in its horizontal plane",
    "north_m": "m; position north of the receiver, in its horizontal plane",
    "r_tx_m": "m; range from the transmitter to the echo, R1",
    "r_rx_m": "m; range from the echo to the receiver, R2",
}
COLUMNS = list(PASSIVE_TABLE_COLUMNS)


@dataclass(frozen=True)
class PassiveSettings:
    """Processing choices. ``pulse``: ``"metadata"`` (the illuminator's long pulse as the operator
    gives it) or ``"recording"`` (the strongest direct-path pulse of the first rotation).

    Attributes
    ----------
    max_bistatic_range_m : float
        Longest bistatic range searched, m: sets the lags per profile.
    pulse : str
        Matched-filter template: ``"metadata"`` or ``"recording"``.
    window : str or None
        Matched-filter taper (``"hann"`` or None).
    chunk_samples : int
        Samples read and filtered per chunk.
    hop_fraction : float
        Hop between dwells as a fraction of a dwell.
    blind_half_width_deg : float
        Half-width of the blind zone around the receiver's bearing from the illuminator, deg.
    min_bistatic_range_m : float or None
        Shortest bistatic range kept, m; None: three range resolutions of the long pulse.
    sidelobe_margin_db, static_sidelobe_margin_db : float
        Margin below a stronger detection at the same range and Doppler under which a detection of the
        moving (static) channel counts as a sidelobe look, dB.
    merge_time_dwells : float
        Time tolerance of merging candidates of overlapping dwells, in dwells.
    max_clutter_to_signal_db : float
        A moving candidate near zero Doppler this much weaker than the static return at its lag is
        that return's cancellation residue, dB.
    dwell : DwellSettings
        CFAR and cancellation settings of each dwell.

    Examples
    --------
    A profile covers the bistatic ranges up to ``max_bistatic_range_m``: 45 km at 5 MS/s is
    ``ceil(45 km / c * fs) + 1`` = 752 lags.

    >>> s = PassiveSettings(window=None)
    >>> s.pulse, s.window, int(np.ceil(s.max_bistatic_range_m / C_MPS * 5e6)) + 1
    ('metadata', None, 752)
    """

    max_bistatic_range_m: float = 45_000.0
    pulse: str = "metadata"
    window: str | None = "hann"
    chunk_samples: int = 1 << 20
    hop_fraction: float = 0.35
    blind_half_width_deg: float = 2.5
    min_bistatic_range_m: float | None = None
    sidelobe_margin_db: float = 15.0  # moving channel: a mover's main looks vary more from sweep to sweep
    static_sidelobe_margin_db: float = 10.0
    merge_time_dwells: float = 1.5
    max_clutter_to_signal_db: float = 20.0
    dwell: DwellSettings = field(default_factory=DwellSettings)


@dataclass
class PassiveResult:
    """What :func:`process_recording` gives.

    Attributes
    ----------
    detections : DataFrame
        The detections table: :data:`COLUMNS`, units in :data:`PASSIVE_TABLE_COLUMNS`.
    n_pulses : int
        Direct-path pulses found.
    n_dwells : int
        Dwells searched.
    scan_period_s : float
        The illuminator's rotation period found from the direct path, s.
    crossings_s : ndarray
        Times the main beam swept the receiver, s from the first sample.
    masked : int
        Detections dropped in the blind zone.
    pulse_source : str
        Where the matched-filter template came from (``metadata`` or ``recording``).
    """

    detections: pd.DataFrame
    n_pulses: int
    n_dwells: int
    scan_period_s: float
    crossings_s: np.ndarray
    masked: int
    pulse_source: str


def receiver_geometry(recording) -> tuple[np.ndarray, float]:
    rx = recording.receiver_geodetic
    ned = geodetic_to_ned(*recording.illuminator_geodetic, *rx)
    tx_en = np.array([ned[1], ned[0]])
    return tx_en, float(np.mod(np.arctan2(-tx_en[0], -tx_en[1]), 2 * np.pi))


def _pulse_models(ill: Illuminator, settings: PassiveSettings) -> dict:
    """The long pulse's formula (sampled at fractional delays) and the short pulse's delay and width."""
    lp, sp = ill.long_pulse, ill.short_pulse
    out: dict = {"companion": (sp.delay_s - lp.delay_s, sp.width_s)}
    if settings.pulse == "metadata":
        out["pulse_at"] = lambda t: lfm_baseband(t, lp.width_s, lp.bandwidth_hz, lp.offset_hz)
    return out


def _template(recording, ill: Illuminator, settings: PassiveSettings) -> np.ndarray:
    fs = recording.sample_rate_hz
    if settings.pulse == "metadata":
        lp = ill.long_pulse
        n = int(round(lp.width_s * fs))
        return np.asarray(
            lfm_baseband(np.arange(n) / fs, lp.width_s, lp.bandwidth_hz, lp.offset_hz), np.complex128
        )
    if settings.pulse != "recording":
        raise InputError(f"passive: pulse source must be 'metadata' or 'recording', got {settings.pulse!r}")
    width = int(round(ill.long_pulse.width_s * fs))
    best, best_energy = 0, -1.0
    stop = min(recording.n_samples, int((ill.rotation_period_s + 0.1) * fs))
    for start in range(0, stop, settings.chunk_samples):
        x = recording.read(start, settings.chunk_samples)
        energy = float(np.max(np.abs(x))) if x.size else 0.0
        if energy > best_energy:
            best, best_energy = start + int(np.argmax(np.abs(x))), energy
    block = recording.read(max(best - 4 * width, 0), 8 * width)
    return estimate_pulse(block, width)


def process_recording(
    recording, settings: PassiveSettings | None = None, progress: Callable[[int, int], None] | None = None
) -> PassiveResult:
    """Detections of a passive recording (an :class:`skyradar.io.sigmf_io.IqRecording`).

    Parameters
    ----------
    recording : IqRecording
        The recording, with its illuminator's metadata.
    settings : PassiveSettings, optional
        Processing choices (default :class:`PassiveSettings`).
    progress : callable, optional
        ``progress(samples_done, total)`` after each chunk.

    Returns
    -------
    PassiveResult
        The detections and what the processing found of the scan.
    """
    from threadpoolctl import threadpool_limits

    # The dwell products are small (tens x hundreds): threaded BLAS only spins on them.
    with threadpool_limits(limits=1, user_api="blas"):
        return _process(recording, settings, progress)


def _process(recording, settings: PassiveSettings | None, progress) -> PassiveResult:
    s = settings or PassiveSettings()
    ill = Illuminator.from_recording(recording)  # an error names the recording
    fs = recording.sample_rate_hz
    tx_en, bearing = receiver_geometry(recording)
    template = _template(recording, ill, s)
    n_lags = int(np.ceil(s.max_bistatic_range_m / C_MPS * fs)) + 1
    extractor = ProfileExtractor(
        template, fs, n_lags, min(ill.pri_s), window=s.window, **_pulse_models(ill, s)
    )
    pri = ill.mean_pri_s
    n_dwell = dwell_pulses(np.radians(ill.beamwidth_az_deg), ill.rotation_rate_rad_s, pri)
    hop = max(1, int(round(n_dwell * s.hop_fraction)))
    bandwidth = max(ill.long_pulse.bandwidth_hz, 1.0 / ill.long_pulse.width_s)
    min_range = s.min_bistatic_range_m if s.min_bistatic_range_m is not None else 3.0 * C_MPS / bandwidth
    # The guard covers the Hann-weighted compressed pulse (about 2 fs/B lags each side).
    dwell = replace(
        s.dwell,
        min_lag=max(s.dwell.min_lag, int(np.ceil(min_range / C_MPS * fs))),
        guard_lags=max(s.dwell.guard_lags, int(np.ceil(2 * fs / bandwidth))),
        lags_per_independent=max(s.dwell.lags_per_independent, 1.5 * fs / bandwidth),  # Hann widens 1.5x
    )
    if dwell.zero_doppler_guard_hz == 0.0:
        dwell = replace(dwell, zero_doppler_guard_hz=1.5 / (n_dwell * pri))

    times, amps, candidates, n_dwells = _stream(
        recording, s, extractor, n_dwell, hop, 1.0 / pri, dwell, progress
    )
    times_all = np.concatenate(times) if times else np.zeros(0)
    if times_all.size == 0:
        raise InputError(
            f"{recording.path}: no direct-path pulse found (no matched-filter peak 30 dB above the median)"
        )
    scan = scan_phase(
        times_all,
        np.concatenate(amps),
        ill.rotation_period_s,
        bearing,
        1,
        source=str(recording.path),
    )
    dwell_s = n_dwell * pri
    merged = _looks(candidates, s, scan, fs, C_MPS / bandwidth, dwell_s)
    blind = in_blind_zone(
        merged["bistatic_range_m"].to_numpy(),
        merged["azimuth_rad"].to_numpy(),
        bearing,
        min_range,
        np.radians(s.blind_half_width_deg),
    )
    merged = merged[~blind].reset_index(drop=True)
    det = _positions(merged, tx_en, scan)
    n_pulses, n_masked = int(times_all.size), int(blind.sum())
    return PassiveResult(det, n_pulses, n_dwells, scan.period_s, scan.crossings_s, n_masked, s.pulse)


def _looks(candidates: list[dict], s: PassiveSettings, scan, fs: float, resolution_m: float, dwell_s: float):
    """Candidates -> one detection per look: residue dropped, overlapping dwells merged, sidelobe looks
    dropped; with bistatic range, beam azimuth and sweep."""
    cols = ["channel", "lag", "doppler_hz", "snr_db", "time_s", "power_db", "static_db"]
    table = pd.DataFrame(candidates, columns=cols)
    # Next to zero Doppler, a weak moving detection beside a much stronger static return at the same
    # lag is that return's cancellation residue (the beam's sweep modulates it), not a mover.
    near_zero = table["doppler_hz"].abs() < 2.0 / dwell_s
    residue = near_zero & (table["static_db"] - table["power_db"] > s.max_clutter_to_signal_db)
    table = table[~residue].reset_index(drop=True)
    table["bistatic_range_m"] = table["lag"] * C_MPS / fs
    table["azimuth_rad"] = scan.azimuth_rad(table["time_s"].to_numpy())
    merged = merge_candidates(table, resolution_m, s.merge_time_dwells * dwell_s, 2.0 / dwell_s)
    merged["sweep"] = scan.sweep(merged["time_s"].to_numpy()) if len(merged) else []
    tols = (1.5 * resolution_m, 2.0 / dwell_s)
    is_static = merged["channel"] == "static" if len(merged) else pd.Series(dtype=bool)
    merged = pd.concat(
        [
            drop_sidelobes(merged[is_static], *tols, s.static_sidelobe_margin_db, dwell_s, scan.period_s),
            drop_sidelobes(merged[~is_static], *tols, s.sidelobe_margin_db, dwell_s, scan.period_s),
        ]
    )
    return merged


def _stream(recording, s: PassiveSettings, extractor, n_dwell: int, hop: int, prf: float, dwell, progress):
    """Chunks -> pulse profiles -> dwells (every ``hop`` pulses) -> candidates; pulse times, amplitudes."""
    times, amps, candidates = [], [], []
    buf_p: list[np.ndarray] = []
    buf_t: list[np.ndarray] = []
    n_dwells = 0
    for start, chunk, out in _profiles_ahead(
        extractor, read_chunks(recording, s.chunk_samples, extractor.overlap, extractor.front)
    ):
        times.append(out.times_s)
        amps.append(np.abs(out.amplitude).astype(np.float32))
        buf_p.append(out.profiles)
        buf_t.append(out.times_s)
        prof, tim = np.concatenate(buf_p), np.concatenate(buf_t)
        starts = np.arange(0, tim.size - n_dwell + 1, hop)
        if starts.size:
            idx = starts[:, None] + np.arange(n_dwell)[None, :]
            candidates += detect_dwells(prof[idx], tim[idx], prf, dwell)
            n_dwells += starts.size
        i = int(starts[-1] + hop) if starts.size else 0
        buf_p, buf_t = [prof[i:]], [tim[i:]]
        if progress is not None:
            progress(start + chunk, recording.n_samples)
    return times, amps, candidates, n_dwells


def _profiles_ahead(extractor: ProfileExtractor, chunks):
    """``(start, chunk, profiles)`` per chunk, the next chunk's profiles computed in a second thread.

    The matched filter and FFTs release the GIL, so the filtering of chunk k+1 overlaps the dwell
    detection of chunk k on a second core; at most two chunks are in memory.
    """
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(max_workers=1) as pool:
        pending = None
        for start, x, chunk in chunks:
            future = pool.submit(extractor.process, start, x, chunk)
            if pending is not None:
                yield pending[0], pending[1], pending[2].result()
            pending = (start, chunk, future)
        if pending is not None:
            yield pending[0], pending[1], pending[2].result()


def _positions(merged: pd.DataFrame, tx_en: np.ndarray, scan) -> pd.DataFrame:
    point, r1, r2 = ellipse_point(
        merged["bistatic_range_m"].to_numpy(), merged["azimuth_rad"].to_numpy(), tx_en, np.zeros(2)
    )
    det = merged.assign(
        sweep=scan.sweep(merged["time_s"].to_numpy()).astype(np.int64),
        azimuth_deg=np.degrees(merged["azimuth_rad"]),
        east_m=point[:, 0],
        north_m=point[:, 1],
        r_tx_m=r1,
        r_rx_m=r2,
    )
    return det[COLUMNS].sort_values(["time_s", "bistatic_range_m"]).reset_index(drop=True)


def merge_candidates(
    table: pd.DataFrame, range_tol_m: float, time_tol_s: float, doppler_tol_hz: float
) -> pd.DataFrame:
    """One detection per target from the candidates of overlapping dwells.

    Strongest (``power_db``, else ``snr_db``) first, each candidate absorbs the unassigned ones of its
    channel within the range, time and (moving channel) Doppler tolerances; the azimuth is the
    power-weighted circular mean of the group (the power follows the beam's pattern across the
    overlapping dwells), everything else the strongest candidate's.

    Examples
    --------
    >>> t = pd.DataFrame({"channel": ["static"] * 3, "doppler_hz": 0.0, "snr_db": [20.0, 20.0, 10.0],
    ...                   "time_s": [1.0, 1.01, 1.0], "bistatic_range_m": [5000.0, 5010.0, 9000.0],
    ...                   "azimuth_rad": [0.10, 0.12, 0.5]})
    >>> m = merge_candidates(t, 100.0, 0.05, 50.0)
    >>> len(m), round(float(m["azimuth_rad"].iloc[0]), 3)
    (2, 0.11)
    """
    if table.empty:
        return table.assign(azimuth_rad=pd.Series(dtype=float))
    key = "power_db" if "power_db" in table else "snr_db"
    t = table.sort_values(key, ascending=False).reset_index(drop=True)
    free = np.ones(len(t), bool)
    rows = []
    rng, tim, dop = (t[c].to_numpy() for c in ("bistatic_range_m", "time_s", "doppler_hz"))
    chan, az, w = t["channel"].to_numpy(), t["azimuth_rad"].to_numpy(), 10 ** (t[key].to_numpy() / 10)
    for i in range(len(t)):
        if not free[i]:
            continue
        near = (
            free
            & (chan == chan[i])
            & (np.abs(rng - rng[i]) <= range_tol_m)
            & (np.abs(tim - tim[i]) <= time_tol_s)
        )
        if chan[i] == "moving":
            near &= np.abs(dop - dop[i]) <= doppler_tol_hz
        free &= ~near
        row = t.iloc[i].to_dict()
        row["azimuth_rad"] = float(np.mod(np.angle(np.sum(w[near] * np.exp(1j * az[near]))), 2 * np.pi))
        rows.append(row)
    return pd.DataFrame(rows)


def drop_sidelobes(
    table: pd.DataFrame,
    range_tol_m: float,
    doppler_tol_hz: float,
    margin_db: float,
    time_tol_s: float = 0.0,
    period_s: float = np.inf,
) -> pd.DataFrame:
    """Drop detections seen through the illuminator's sidelobes or the Doppler taper's sidelobes.

    A strong reflector is lit by the sidelobes at every beam azimuth; each such look would be placed on
    the ellipse in the wrong direction. Within one sweep and channel, a detection at least ``margin_db``
    weaker (``power_db``, else ``snr_db``) than another at the same bistatic range and Doppler is such a
    look and is dropped (the main beam's is the strongest), compared within one rotation ``period_s``
    either way (so the first and last partial sweeps are judged too); so is one at the same range within
    ``time_tol_s`` of a stronger one at another Doppler (the Doppler sidelobes of the same echo).

    Examples
    --------
    >>> t = pd.DataFrame({"channel": "moving", "doppler_hz": 100.0, "time_s": [1.0, 2.0, 2.0, 9.0],
    ...                   "bistatic_range_m": [2600.0, 2610.0, 9000.0, 2600.0], "snr_db": [40.0, 15, 15, 15]})
    >>> drop_sidelobes(t, 300.0, 50.0, 10.0, period_s=4.4).index.tolist()
    [0, 2, 3]
    """
    if table.empty:
        return table
    key = "power_db" if "power_db" in table else "snr_db"
    keep = np.ones(len(table), bool)
    for _, group in table.groupby("channel"):
        rng, dop, pwr, tim = (group[c].to_numpy() for c in ("bistatic_range_m", "doppler_hz", key, "time_s"))
        same_range = np.abs(rng[:, None] - rng[None, :]) <= range_tol_m
        dt = np.abs(tim[:, None] - tim[None, :])
        same = ((np.abs(dop[:, None] - dop[None, :]) <= doppler_tol_hz) & (dt <= period_s)) | (
            dt <= time_tol_s
        )
        louder = same_range & same & (pwr[None, :] >= pwr[:, None] + margin_db)
        keep[table.index.get_indexer(group.index)] = ~louder.any(axis=1)
    return table[keep]
