"""Receive-array trade study: what each array buys a pilot over each terrain, and what it costs.

Every array of the study (a name of :data:`skyradar.rx_layouts.RX_LAYOUTS`, or of
:data:`~skyradar.rx_layouts.MIMO_LAYOUTS` for transmitters taking turns; a further array is one
more name there) flies the same encounter set (same seed, same geometry,
:func:`skyradar.experiments.encounter_set.make_encounters`) over every terrain asked for, each
simulated with its own receive channels, through the whole chain of ``skyradar experiment
encounters`` (:func:`skyradar.experiments.encounters.run`, the single forward head; its folder
``encounters_<array>/`` holds that run's own tables, figures and summary). Per array and terrain:
missed, late and false warnings with their counts and 95 % Wilson intervals, the median warning
lead, ground and clutter tracks per flight minute and track fragments per intruder
(:func:`~skyradar.experiments.encounter_score.summarise_layout`).

Per array, three properties of the sensor itself:

Minimum detectable velocity and usable Doppler fraction (:func:`doppler_notch`)
    The processing nulls, cell by cell, the directions its clutter prediction puts the ground in
    (:func:`skyradar.process.clutter_suppress.suppress_clutter` on the prediction of
    :func:`skyradar.process.clutter.clutter_subspace`); a target whose steering vector lies near
    those directions loses its power with them. Over flat ground :data:`NOTCH_HEIGHT_M` below,
    own-ship level at 50 m/s, the clutter scene's frames (ground and noise, and the ground alone
    without noise, :mod:`skyradar.experiments.clutter_scene`) are simulated with the array's channels
    and suppressed as the processing does; the SINR loss of a boresight target per Doppler bin,
    averaged over the frames and 1.3-5 km, is ``g N / (C_out + N)`` (``g`` the target power the
    nulls keep, ``C_out`` the clutter they leave, ``N`` the noise per pixel), as in ``skyradar
    experiment clutter``. The minimum detectable velocity is the smallest (aliased) separation from
    the main-beam clutter Doppler ``-V sqrt(1 - (H / R)^2)`` at which the loss is at least -5 dB;
    the usable Doppler fraction is the share of Doppler bins where it is
    (:func:`skyradar.experiments.clutter.doppler_metrics`). A forward-looking head sees its
    main-beam clutter at the edge of the ground's Doppler band (the ground straight ahead closes
    fastest), so that MDV is set on the clutter-free side and is the same for every array;
    ``mdv_into_ground_band_mps`` is the separation on the other side, into the band of sidelobe
    ground, where the arrays differ: more channels keep more of a target whose direction is near
    the nulled ground directions, so the notch narrows and the usable fraction grows. A
    time-division MIMO array's target pixels carry the slot phase of the bin's velocity and of the
    alias residue, which the nulls do not know: its gain is averaged over the ``n_tx`` residues,
    and its fraction is of its own image, ``n_tx`` times narrower than one transmitter's.
DoA error against its Cramer-Rao bound (:func:`doa_against_bound`)
    A Monte-Carlo of the array's estimator (:func:`skyradar.process.doa.estimate_directions`) on a
    point target at a known direction (:data:`DOA_DIRECTION_DEG`), one pixel per trial with
    per-channel SNR ``A^2 / sigma^2`` and a random common phase, at each of :data:`DOA_SNRS_DB`: the
    RMS azimuth and elevation errors against the bound the tracker uses
    (:func:`skyradar.process.doa.doa_crlb`).
Processing frames per second (:func:`processing_rate`)
    Detection and DoA (:func:`skyradar.process.pipeline.process_cube`) of prototype-size frames of
    the array's channel count with five targets each, timed for a fraction of a second: wall clock
    and per process-CPU second, measured, never a pass/fail figure.

Writes ``arrays.parquet`` and ``arrays.csv`` (one row per array and terrain), ``doa.csv`` (one row
per array and SNR), ``doppler.csv`` (SINR loss per array and Doppler bin), ``summary.json``,
``summary.md`` and the figures ``arrays_warnings.png``, ``arrays_doa.png``, ``arrays_doppler.png``
and ``arrays_frames_per_s.png``.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from skyradar.code_version import code_version, provenance
from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.experiments.encounter_chain import FRAME_RATE_HZ
from skyradar.experiments.encounter_set import make_encounters, rate_interval
from skyradar.experiments.encounter_terrain import TERRAINS
from skyradar.experiments.encounters import EVALUATION_SEEDS_FROM, MAX_ENCOUNTERS
from skyradar.experiments.summary_md import write_summary
from skyradar.io.atomic import write_csv_atomic
from skyradar.io.json_results import write_json_atomic
from skyradar.io.tables import write_table
from skyradar.rx_layouts import MIMO_LAYOUTS, RX_LAYOUTS, check_rx_layout

__all__ = [
    "run",
    "parse_arrays",
    "array_config",
    "doa_against_bound",
    "doppler_notch",
    "processing_rate",
    "array_rows",
    "DEFAULT_ARRAYS",
    "DEFAULT_TERRAINS",
    "DEFAULT_ENCOUNTERS",
    "DOA_SNRS_DB",
    "DOA_DIRECTION_DEG",
    "NOTCH_HEIGHT_M",
    "LOSS_THRESHOLD_DB",
]

DEFAULT_ARRAYS = ("square", "ura-2x3")  # the prototype's 2x2 against the smallest larger array
DEFAULT_TERRAINS = ("none", "flat-300")
# Per array and terrain. The defaults (2 arrays, clear sky and flat-300) took 3 min 16 s of wall clock and
# 254 CPU-s (user + system), measured on 2 cores at load 3-4: within 5 minutes.
DEFAULT_ENCOUNTERS = 2
DOA_SNRS_DB = (10.0, 20.0, 30.0)  # per channel and pixel: near the detection threshold, mid, strong
DOA_DIRECTION_DEG = (10.0, 5.0)  # azimuth right, elevation up, deg: off both axes of every array
DOA_TRIALS = 2000
NOTCH_HEIGHT_M = 300.0  # flat ground below, m: the encounter set's flat-300 terrain
NOTCH_FRAMES = 3
_NOTCH_RANGE_M = (1300.0, 5000.0)  # range bins the SINR loss is averaged over (the clutter scene's)
_NOTCH_CLOSING_MPS = 100.0
LOSS_THRESHOLD_DB = -5.0  # SINR loss a usable Doppler bin keeps, dB
_SUBFOLDER = "encounters_{}"


def parse_arrays(value: str | Sequence[str], option: str = "--arrays") -> list[str]:
    """Array names from a comma-separated list (or a sequence), each a layout of
    :data:`~skyradar.rx_layouts.RX_LAYOUTS` or :data:`~skyradar.rx_layouts.MIMO_LAYOUTS`, in the
    given order, each once.

    Examples
    --------
    >>> parse_arrays("ura-2x3, square,ura-2x3")
    ['ura-2x3', 'square']
    >>> parse_arrays("ring")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: --arrays: must be a comma-separated list of square, kite, ..., got 'ring'
    """
    names = [v.strip() for v in (value.split(",") if isinstance(value, str) else value)]
    known = RX_LAYOUTS + MIMO_LAYOUTS
    if not names or any(n not in known for n in names):
        shown = value if isinstance(value, str) else ",".join(value)
        raise InputError(f"{option}: must be a comma-separated list of {', '.join(known)}, got {shown!r}")
    return list(dict.fromkeys(names))


def array_config(array: str) -> RadarConfig:
    """The prototype radar with the receive array ``array`` (:data:`~skyradar.rx_layouts.RX_LAYOUTS`),
    or the transmitters and receivers of a time-division MIMO one
    (:data:`~skyradar.rx_layouts.MIMO_LAYOUTS`)."""
    check_rx_layout(array, "--arrays:", mimo=True)
    return RadarConfig.prototype_2022(rx_positions_m=array)


def doa_against_bound(
    array: str,
    snrs_db: Sequence[float] = DOA_SNRS_DB,
    trials: int = DOA_TRIALS,
    direction_deg: tuple[float, float] = DOA_DIRECTION_DEG,
    seed: int = 0,
) -> list[dict[str, Any]]:
    """RMS DoA error of the array's estimator against its Cramer-Rao bound, one dict per SNR.

    Parameters
    ----------
    array : str
        A receive-array name (:data:`~skyradar.rx_layouts.RX_LAYOUTS`).
    snrs_db : sequence of float
        Per-channel, per-pixel SNR ``A^2 / sigma^2``, dB.
    trials : int
        Monte-Carlo pixels per SNR.
    direction_deg : (float, float)
        True azimuth (right) and elevation (up), deg, antenna frame.
    seed : int
        Random seed.

    Returns
    -------
    list of dict
        ``snr_db``, ``rms_azimuth_deg``, ``rms_elevation_deg`` (errors of the estimates, deg),
        ``bound_azimuth_deg``, ``bound_elevation_deg`` (:func:`skyradar.process.doa.doa_crlb`, deg)
        and their ratios ``azimuth_over_bound``, ``elevation_over_bound``.
    """
    from skyradar.process.doa import (
        angles_from_direction,
        direction_from_angles,
        doa_crlb,
        estimate_directions,
        steering_vector,
    )
    from skyradar.units import wrap_angle

    config = array_config(array)
    rng = np.random.default_rng(seed)
    az, el = np.radians(direction_deg[0]), np.radians(direction_deg[1])
    steer = steering_vector(direction_from_angles(az, el), config)
    out = []
    for snr_db in snrs_db:
        phase = np.exp(1j * rng.uniform(0.0, 2.0 * np.pi, trials))
        noise = (
            rng.standard_normal((trials, config.n_virtual))
            + 1j * rng.standard_normal((trials, config.n_virtual))
        ) / np.sqrt(2.0)
        pixels = 10.0 ** (snr_db / 20.0) * phase[:, None] * steer[None, :] + noise
        est_az, est_el = angles_from_direction(estimate_directions(pixels, config, calibrated=True))
        rms_az = float(np.sqrt(np.mean(wrap_angle(est_az - az) ** 2)))
        rms_el = float(np.sqrt(np.mean((est_el - el) ** 2)))
        sd_az, sd_el = (float(x) for x in doa_crlb(snr_db, az, el, config))
        out.append(
            {
                "snr_db": float(snr_db),
                "rms_azimuth_deg": float(np.degrees(rms_az)),
                "rms_elevation_deg": float(np.degrees(rms_el)),
                "bound_azimuth_deg": float(np.degrees(sd_az)),
                "bound_elevation_deg": float(np.degrees(sd_el)),
                "azimuth_over_bound": rms_az / sd_az,
                "elevation_over_bound": rms_el / sd_el,
            }
        )
    return out


def doppler_notch(
    array: str, height_m: float = NOTCH_HEIGHT_M, n_frames: int = NOTCH_FRAMES, seed: int = 0
) -> tuple[dict[str, float], pd.DataFrame]:
    """Minimum detectable velocity and usable Doppler fraction of the array over flat ground.

    Parameters
    ----------
    array : str
        A receive-array name (:data:`~skyradar.rx_layouts.RX_LAYOUTS`).
    height_m : float
        Flat ground this far below own-ship, m.
    n_frames : int
        Simulated frames the loss is averaged over.
    seed : int
        Simulator seed (noise and ground speckle).

    Returns
    -------
    figures : dict
        ``mdv_mps`` (m/s) and ``usable_doppler_fraction`` with suppression, ``..._none`` without,
        and ``main_beam_clutter_mps`` (the module docstring gives the physics).
    curve : DataFrame
        Per Doppler bin: ``radial_velocity_mps``, ``clutter_to_noise_db``, ``sinr_loss_none_db``,
        ``sinr_loss_suppressed_db``.
    """
    from skyradar.experiments.clutter import doppler_metrics
    from skyradar.experiments.clutter_scene import OWN_SPEED_MPS, scene_dict, scene_frames
    from skyradar.io.frames import radar_config_of
    from skyradar.process.clutter_anchors import prediction_anchors
    from skyradar.process.clutter_frames import frame_subspace
    from skyradar.process.clutter_suppress import projected_power, suppress_clutter
    from skyradar.process.doa import channel_calibration, steering_vector
    from skyradar.process.mimo import slot_phase
    from skyradar.process.pipeline import navigated_own_state
    from skyradar.process.power import power_image
    from skyradar.units import wrap

    check_rx_layout(array, "--arrays:", mimo=True)
    far, near = _NOTCH_RANGE_M[1], _NOTCH_RANGE_M[0]
    common: dict[str, Any] = dict(
        n_frames=n_frames,
        frame_rate_hz=n_frames * _NOTCH_CLOSING_MPS / (far - near),
        closing_mps=_NOTCH_CLOSING_MPS,
        start_range_m=far,
        seed=seed,
        intruder=False,
    )

    def frames(**kw: Any):
        data = scene_dict(height_m, **common, **kw)
        data["radar"]["rx_layout"] = array
        return scene_frames(data)

    full = frames()
    clutter = np.asarray(frames(noise=False)["iq"])
    config = radar_config_of(full, "arrays scene")
    own = navigated_own_state(full, "arrays scene")
    assert own is not None  # the scene records the own-ship's navigation
    anchors = prediction_anchors(own)
    rows = (config.range_axis_m >= near) & (config.range_axis_m <= far)
    cubes = np.asarray(full["iq"])
    calibration = channel_calibration(config)
    n_bins = config.frame_shape[1]
    # A boresight target in each Doppler bin, as its pixels arrive: a MIMO radar's carry the slot
    # phase of the bin's velocity and of its alias residue, which the nulls do not know; the gain
    # is averaged over the n_tx residues (the aliases a bin holds, equally likely).
    steer = steering_vector(np.array([1.0, 0.0, 0.0]), config)
    slots = np.repeat(np.arange(config.n_tx), config.n_rx)
    residues = np.exp(2j * np.pi * np.outer(np.arange(config.n_tx), slots) / config.n_tx)
    slot = slot_phase(np.asarray(config.doppler_axis_mps, float), config)  # (n_bins, channels)
    c_in, c_out, gain = (np.zeros(n_bins) for _ in range(3))
    for i in range(n_frames):
        sub = frame_subspace(own, i, config, None, anchors)
        assert sub is not None  # flat ground: the height above it is known
        sup = suppress_clutter(cubes[i], sub, config)
        vectors = sup.applied_vectors(sub)
        c_in += power_image(clutter[i], calibration)[rows].mean(axis=0)
        c_out += projected_power(clutter[i] / calibration, vectors, sup.nulls)[rows].mean(axis=0)
        for residue in residues:
            target = np.broadcast_to(steer * slot * residue, cubes[0].shape)
            gain += projected_power(target, vectors, sup.nulls)[rows].mean(axis=0) / config.n_tx
    c_in, c_out, gain = (x / n_frames for x in (c_in, c_out, gain))
    noise = config.noise_power_w
    loss_none = 10.0 * np.log10(noise / (c_in + noise))
    loss_supp = 10.0 * np.log10(np.maximum(gain * noise / (c_out + noise), 1e-30))
    v = np.asarray(config.doppler_axis_mps, float)
    r = np.linspace(near, far, 64)
    v_mbc = float(np.mean(-OWN_SPEED_MPS * np.sqrt(1.0 - np.minimum(height_m / r, 1.0) ** 2)))
    v_lim = float(np.max(np.abs(v)))
    none = doppler_metrics(loss_none, v, v_mbc, v_lim)
    supp = doppler_metrics(loss_supp, v, v_mbc, v_lim)
    # Signed (aliased) separation from the main-beam clutter: positive is into the ground's band.
    into = wrap(v - v_mbc, 2.0 * v_lim)
    usable = (loss_supp >= LOSS_THRESHOLD_DB) & (into > 0.0)
    into_band = float(into[usable].min()) if usable.any() else float("nan")
    curve = pd.DataFrame(
        {
            "radial_velocity_mps": v,
            "clutter_to_noise_db": 10.0 * np.log10(np.maximum(c_in / noise, 1e-30)),
            "sinr_loss_none_db": loss_none,
            "sinr_loss_suppressed_db": loss_supp,
        }
    )
    figures = {
        "mdv_mps": supp["mdv_mps"],
        "usable_doppler_fraction": supp["usable_doppler_fraction"],
        "mdv_into_ground_band_mps": into_band,
        "mdv_mps_none": none["mdv_mps"],
        "usable_doppler_fraction_none": none["usable_doppler_fraction"],
        "main_beam_clutter_mps": v_mbc,
    }
    return figures, curve


def processing_rate(array: str, seconds: float = 0.5, n_cubes: int = 3, seed: int = 0) -> dict[str, float]:
    """Detection and DoA frames per second of one radar head with the array (wall clock and CPU).

    Parameters
    ----------
    array : str
        A receive-array name (:data:`~skyradar.rx_layouts.RX_LAYOUTS`).
    seconds : float
        Least wall time timed, s (after one warm-up frame).
    n_cubes : int
        Prototype-size frames cycled through: thermal noise and five point targets at 25 dB
        per-channel SNR, each in one pixel with its far-field steering vector.
    seed : int
        Random seed of the frames.

    Returns
    -------
    dict
        ``frames_per_s`` (wall clock) and ``cpu_frames_per_s`` (per process-CPU second), measured.
    """
    from skyradar.process.doa import channel_calibration, direction_from_angles, steering_vector
    from skyradar.process.pipeline import process_cube

    if not 0.0 < seconds < float("inf"):
        raise InputError(f"arrays: timing seconds must be finite and > 0, got {seconds}")
    config = array_config(array)
    rng = np.random.default_rng(seed)
    shape, calibration = config.frame_shape, channel_calibration(config)
    speed_mps = min(35.0, 0.9 * config.v_lim_mps)  # radial speeds inside the Doppler image
    sigma = np.sqrt(config.noise_power_w / 2.0)
    cubes = []
    for _ in range(n_cubes):
        cube = (sigma * (rng.standard_normal(shape) + 1j * rng.standard_normal(shape))).astype(np.complex64)
        for _ in range(5):
            u = direction_from_angles(rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5))
            k = int(config.range_bin(rng.uniform(300.0, 4500.0)))
            j = int(config.doppler_bin(rng.uniform(-speed_mps, speed_mps)))
            amp = np.sqrt(config.noise_power_w * 10**2.5) * np.exp(1j * rng.uniform(0.0, 2.0 * np.pi))
            cube[k, j] += (amp * steering_vector(u, config) * calibration).astype(np.complex64)
        cubes.append(cube)
    process_cube(cubes[0], config)  # warm-up: compiled kernels, caches
    n, t0, c0 = 0, time.perf_counter(), time.process_time()
    while True:
        process_cube(cubes[n % n_cubes], config)
        n += 1
        wall = time.perf_counter() - t0
        if wall >= seconds and n >= n_cubes:
            return {"frames_per_s": n / wall, "cpu_frames_per_s": n / max(time.process_time() - c0, 1e-9)}


def _channels(array: str) -> dict[str, int]:
    """Receivers ``n_rx``, transmitters ``n_tx`` and the ``channels`` the processing works on (the
    receivers, or a MIMO array's virtual channels)."""
    config = array_config(array)
    return {"n_rx": config.n_rx, "n_tx": config.n_tx, "channels": config.n_virtual}


def _encounter_digest(table: pd.DataFrame, terrain: str, columns: list[str]) -> str:
    """Digest of the encounters' parameters flown over ``terrain`` (equal digests: the same encounters)."""
    rows = table[table["terrain"] == terrain].drop_duplicates("encounter").sort_values("encounter")
    values = pd.util.hash_pandas_object(rows[["encounter", *columns]].reset_index(drop=True), index=False)
    return hashlib.sha256(values.to_numpy().tobytes()).hexdigest()[:16]


def array_rows(array: str, summary: dict[str, Any], table: pd.DataFrame, columns: list[str]) -> list[dict]:
    """One row per terrain of an array's encounter run (its ``summary.json`` and ``encounters.parquet``).

    ``columns`` are the encounter parameters; ``encounter_set`` is their digest per terrain, equal
    for every array flown on the same encounters.
    """
    out = []
    for r in summary["rows"]:
        late_trials = int(r["observable_conflicts"])
        frag = r["track_fragments_per_intruder"]
        out.append(
            {
                "array": array,
                **_channels(array),
                "terrain": r["terrain"],
                "encounters": int(r["encounters"]),
                "encounter_set": _encounter_digest(table, r["terrain"], columns),
                "conflicts": int(r["conflicts"]),
                "observable_conflicts": late_trials,
                "missed_warnings": int(r["missed_warnings"]),
                "missed_warning_rate": float(r["missed_warning_rate"]),
                "missed_warning_rate_ci95": list(r["missed_warning_rate_ci95"]),
                "late_warnings": int(r["late_warnings"]),
                "late_warning_rate": float(r["late_warnings"] / max(late_trials, 1)),
                "late_warning_rate_ci95": rate_interval(int(r["late_warnings"]), late_trials),
                "must_not_alert_encounters": int(r["must_not_alert_encounters"]),
                "false_warnings": int(r["false_warnings"]),
                "false_warning_rate": float(r["false_warning_rate"]),
                "false_warning_rate_ci95": list(r["false_warning_rate_ci95"]),
                "median_warning_lead_s": float(r["median_warning_lead_s"]),
                "ground_tracks_per_min": float(r["ground_tracks_per_min"]),
                "ground_track_warnings": int(r["ground_track_warnings"]),
                "clutter_tracks_per_min": float(r["clutter_tracks_per_min"]),
                "fragments_per_intruder_median": float(frag["median"]),
                "fragments_per_intruder_mean": float(frag["mean"]),
                "flight_minutes": float(r["flight_minutes"]),
            }
        )
    return out


def _flat(rows: list[dict]) -> pd.DataFrame:
    """The rows with each ``[low, high]`` interval as two columns (``_low``, ``_high``)."""
    flat = []
    for r in rows:
        f: dict[str, Any] = {}
        for k, v in r.items():
            if isinstance(v, list):
                f[k.replace("_ci95", "_ci95_low")], f[k.replace("_ci95", "_ci95_high")] = v
            else:
                f[k] = v
        flat.append(f)
    return pd.DataFrame(flat)


def _encounter_run(
    out_dir: Path, array: str, settings: dict, version: str, progress, kw: dict
) -> tuple[dict, pd.DataFrame]:
    """The array's encounter run in its own folder; a finished one with the same settings and code is
    read back instead of flown again (an interrupted study resumes there)."""
    from skyradar.experiments import encounters

    sub = out_dir / _SUBFOLDER.format(array)
    done = sub / "summary.json"
    key = {k: settings[k] for k in ("n", "seed", "terrains", "frame_rate_hz")}
    if done.is_file() and (sub / "encounters.parquet").is_file():
        old = json.loads(done.read_text())
        same = {k: old.get(k) for k in key} == key and old.get("rx_layout") == array
        if same and old.get("version") == version and old.get("layouts") == ["single"]:
            return old, pd.read_parquet(sub / "encounters.parquet")
    summary = encounters.run(
        sub,
        n_encounters=settings["n"],
        seed=settings["seed"],
        frame_rate_hz=settings["frame_rate_hz"],
        terrains=tuple(settings["terrains"]),
        layouts=("single",),
        rx_layout=array,
        progress=progress,
        **kw,
    )
    return summary, pd.read_parquet(sub / "encounters.parquet")


def run(
    out_dir: Path,
    arrays: Sequence[str] = DEFAULT_ARRAYS,
    terrains: Sequence[str] = DEFAULT_TERRAINS,
    n_encounters: int = DEFAULT_ENCOUNTERS,
    seed: int = 0,
    frame_rate_hz: float = FRAME_RATE_HZ,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: Callable[[int], None] | None = None,
    command: str | None = None,
    doa_trials: int = DOA_TRIALS,
    timing_s: float = 0.5,
) -> dict[str, Any]:
    """Run the receive-array trade study into ``out_dir``; return the summary.

    Parameters
    ----------
    out_dir : Path
        Output folder (created; files of the same names are replaced, others kept).
    arrays : sequence of str
        Receive arrays (:data:`~skyradar.rx_layouts.RX_LAYOUTS`), each simulated with its channels.
    terrains : sequence of str
        Terrains (:data:`~skyradar.experiments.encounter_terrain.TERRAINS`), each flown by every array.
    n_encounters : int
        Encounters per array and terrain (the same for every array: same seed, same geometry).
    seed : int
        Encounter-set seed; seeds from :data:`~skyradar.experiments.encounters.EVALUATION_SEEDS_FROM`
        are the evaluation split (recorded as ``split``).
    frame_rate_hz : float
        Radar frame rate, frames/s.
    workers, scheduler
        Where the encounters run (:func:`skyradar.experiments.encounters.run_encounters`).
    progress : callable, optional
        Called with the number of (array, terrain, encounter) runs finished.
    command : str, optional
        The command as the caller ran it (recorded in the provenance).
    doa_trials : int
        Monte-Carlo pixels per array and SNR of the DoA error.
    timing_s : float
        Least wall time of each array's frames-per-second timing, s.

    Returns
    -------
    dict
        Settings, ``rows`` (one per array and terrain), ``arrays`` (per array: channels, MDV, usable
        Doppler fraction, DoA error against its bound, frames per second), runtime and provenance.
    """
    t0 = time.perf_counter()
    arrays, terrains = parse_arrays(list(arrays)), list(terrains)
    if not 1 <= int(n_encounters) <= MAX_ENCOUNTERS:
        raise InputError(f"--n: must be an integer >= 1 and <= {MAX_ENCOUNTERS}, got {n_encounters!r}")
    if not terrains or any(t not in TERRAINS for t in terrains):
        raise InputError(f"--terrain: must be among {', '.join(TERRAINS)}, got {','.join(terrains)!r}")
    if doa_trials < 1:
        raise InputError(f"arrays: doa_trials must be >= 1, got {doa_trials}")
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    settings = {
        "arrays": arrays,
        "terrains": terrains,
        "n": int(n_encounters),
        "seed": int(seed),
        "frame_rate_hz": float(frame_rate_hz),
        "layout": "single",
        "split": "evaluation" if seed >= EVALUATION_SEEDS_FROM else "development",
        "doa_snrs_db": list(DOA_SNRS_DB),
        "doa_direction_deg": list(DOA_DIRECTION_DEG),
        "doa_trials": int(doa_trials),
        "notch_height_m": NOTCH_HEIGHT_M,
    }
    version = code_version()
    columns = list(make_encounters(int(n_encounters), int(seed)).columns)
    per_run = int(n_encounters) * len(terrains)
    rows: list[dict] = []
    per_array: list[dict] = []
    curves, doa_rows = [], []
    kw = {"workers": workers, "scheduler": scheduler, "command": command}
    for k, array in enumerate(arrays):
        step = (lambda n, k=k: progress(k * per_run + n)) if progress else None
        summary, table = _encounter_run(out_dir, array, settings, version, step, kw)
        if progress:
            progress((k + 1) * per_run)
        rows += array_rows(array, summary, table, columns)
        notch, curve = doppler_notch(array, seed=seed)
        doa = doa_against_bound(array, trials=doa_trials, seed=seed)
        rate = processing_rate(array, timing_s, seed=seed)
        curves.append(curve.assign(array=array))
        doa_rows += [{"array": array, **d} for d in doa]
        per_array.append(
            {
                "array": array,
                **_channels(array),
                **notch,
                "doa": doa,
                **rate,
                "encounters_folder": _SUBFOLDER.format(array),
            }
        )
    table = _flat(rows)
    write_table(table, out_dir / "arrays.parquet")
    write_csv_atomic(table, out_dir / "arrays.csv", index=False)
    write_csv_atomic(pd.DataFrame(doa_rows), out_dir / "doa.csv", index=False)
    write_csv_atomic(pd.concat(curves, ignore_index=True), out_dir / "doppler.csv", index=False)
    from skyradar.experiments.arrays_report import (
        plot_doa,
        plot_doppler,
        plot_frames_per_s,
        plot_warnings,
        summary_markdown,
    )

    plot_warnings(rows, out_dir / "arrays_warnings.png")
    plot_doa(per_array, out_dir / "arrays_doa.png")
    plot_doppler(curves, per_array, out_dir / "arrays_doppler.png")
    plot_frames_per_s(per_array, out_dir / "arrays_frames_per_s.png")
    result = {
        **settings,
        "rows": rows,
        "per_array": per_array,
        "runtime_s": round(time.perf_counter() - t0, 1),
        "workers": workers if scheduler is None else None,
        "scheduler": scheduler,
        "cpu_count": os.cpu_count(),
        **provenance(command, version),
    }
    write_json_atomic(out_dir / "summary.json", result)
    write_summary(out_dir, summary_markdown(result, out_dir))
    return result
