"""``skyradar experiment clutter``: what knowledge-aided suppression buys over flat ground.

The named scene (:mod:`skyradar.experiments.clutter_scene`): prototype radar facing forward,
own-ship level at 50 m/s, flat ground 1000 m and 300 m below, a head-on intruder (1 m^2) closing
at 100 m/s from 5 km to 1.3 km. Each case simulates three runs of the same geometry with the
image simulator: the full frames (ground, intruder, noise) that are processed with and without
suppression, the ground alone without noise and the intruder alone without noise. The last two
are the truth the figures of merit are computed from; the suppression never sees them (the
nulls applied to them are the ones chosen on the full frames).

Figures of merit (Ward, "Space-time adaptive processing for airborne radar", MIT Lincoln
Laboratory TR-1015, 1994; the standard STAP metrics), for a target in the head-on direction
(antenna boresight), per Doppler bin, averaged over the range bins from 1.3 to 5 km:

* SINR loss: output SINR over the noise-only SNR of the same processor, ``L_s = SINR / SNR_0``.
  Without suppression (the non-coherent channel mean) ``L_s = N / (C + N)``; with the projection
  ``P`` of rank ``L`` it is ``g N / (C_out + N)`` with ``g = |P s|^2 / L`` (per-channel target
  power kept) and ``C_out = |P c|^2 / L`` (clutter left), ``N`` the thermal noise per pixel.
* Improvement factor: ``IF = SINR_out / SINR_in`` with ``SINR_in`` per channel:
  ``IF = g (C + N) / (C_out + N)`` (0 dB without suppression).
* Minimum detectable velocity: the smallest radial-velocity separation (aliased) from the
  main-beam clutter Doppler ``-V sqrt(1 - (H / R)^2)`` at which the SINR loss is at least -5 dB.
* Usable Doppler space fraction: the fraction of Doppler bins whose SINR loss is at least -5 dB.

And in the intruder's own cells: the improvement factor over its CFAR window (the cells whose
clutter raised the threshold) in the frames where it was missed without suppression.

The IF "in the cells where the head-on intruder was lost" (``h{H}_if_db_lost_cells_median`` and
``_min``, the acceptance figure, >= 25 dB required): lost frames are those where the
intruder is a hit in the clear-sky twin but not in the no-suppression run (detections within 2
range and 3 Doppler bins of its truth cell, the brightest cell of the noise-free intruder-only
run; the suppressed run plays no part in choosing them); lost cells are the CA-CFAR training
cells around its truth cell whose clutter-to-noise ratio is at least ``IF_CELL_CNR_DB`` (25 dB:
the per-cell IF ``g (C + N) / (C_out + N)`` cannot exceed the CNR plus the target gain, so a
dimmer cell cannot show 25 dB whatever the processing). Per frame the median IF over those
cells; the keys give the median and the minimum over the lost frames that have such cells
(``_lost_frames_with_cells`` of them, ``_lost_cells`` cells in all; at long range the window's
clutter is dimmer than 25 dB). ``_lost_cells_cnr_db_median`` and
``_lost_cells_target_gain_db_median`` (the intruder's power kept by its own cell's nulls) show
what bounds it: with the clutter nulled, ``IF ~ g CNR``.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from skyradar.config import RadarConfig
from skyradar.experiments.clutter_report import plot_sinr_loss, plot_track, summary_rows
from skyradar.experiments.clutter_scene import OWN_SPEED_MPS, scene_dict, scene_frames
from skyradar.io.atomic import write_csv_atomic
from skyradar.io.frames import radar_config_of
from skyradar.io.tables import write_json_atomic
from skyradar.process.clutter_frames import frame_subspace
from skyradar.process.clutter_suppress import projected_power, suppress_clutter
from skyradar.process.doa import steering_vector
from skyradar.process.pipeline import navigated_own_state, process_frames
from skyradar.process.power import power_image
from skyradar.units import wrap

__all__ = ["run", "doppler_metrics", "LOSS_THRESHOLD_DB"]

LOSS_THRESHOLD_DB = -5.0
START_M, END_M, CLOSING_MPS = 5000.0, 1300.0, 100.0
_CFAR_HALF = (6, 10)  # guard + training cells each side (range, Doppler) of the default CA-CFAR
_CFAR_GUARD = (2, 2)
IF_CELL_CNR_DB = 25.0  # per-cell IF is bounded by the cell's CNR: judged where 25 dB is possible
RCS_M2 = 2.0  # inside the encounter set's 1-5 m^2 (light aircraft at X band)


def _db(x: np.ndarray | float) -> np.ndarray:
    return 10.0 * np.log10(np.maximum(np.asarray(x, float), 1e-30))


def doppler_metrics(
    loss_db: np.ndarray, velocity_mps: np.ndarray, v_mbc_mps: float, v_lim_mps: float
) -> dict:
    """Minimum detectable velocity and usable Doppler space fraction of a SINR-loss curve.

    Examples
    --------
    >>> v = np.linspace(-40, 40, 81)
    >>> m = doppler_metrics(np.where(np.abs(v + 30) < 4, -20.0, 0.0), v, -30.0, 40.0)
    >>> m["mdv_mps"], round(m["usable_doppler_fraction"], 3)
    (4.0, 0.914)
    """
    usable = np.asarray(loss_db) >= LOSS_THRESHOLD_DB
    sep = np.abs(wrap(np.asarray(velocity_mps) - v_mbc_mps, 2.0 * v_lim_mps))
    return {
        "mdv_mps": float(sep[usable].min()) if usable.any() else float("nan"),
        "usable_doppler_fraction": float(usable.mean()),
    }


def _hit(table: pd.DataFrame, frame: int, k: int, j: int, config: RadarConfig) -> bool:
    rows = table[table.frame == frame]
    dj = (rows.doppler_bin - j + config.n_doppler / 2) % config.n_doppler - config.n_doppler / 2
    return bool(((np.abs(rows.range_bin - k) <= 2) & (np.abs(dj) <= 3)).any())


def _window(k: int, j: int, config: RadarConfig) -> tuple[np.ndarray, np.ndarray]:
    """Indices of the CA-CFAR training cells around (k, j) (Doppler wraps)."""
    (hr, hd), (gr, gd) = _CFAR_HALF, _CFAR_GUARD
    dr, dd = np.meshgrid(np.arange(-hr, hr + 1), np.arange(-hd, hd + 1), indexing="ij")
    train = (np.abs(dr) > gr) | (np.abs(dd) > gd)
    r = np.clip(k + dr[train], 0, config.n_range - 1)
    return r, (j + dd[train]) % config.n_doppler


def _median_db(x: np.ndarray) -> float:
    return float(np.median(_db(x))) if x.size else float("nan")


def _attenuation_db(before: np.ndarray, after: np.ndarray) -> float:
    """Clutter power before over after the projection (NaN for no cells)."""
    return float(_db(before.sum() / max(after.sum(), 1e-300))) if before.size else float("nan")


def _stat(values: pd.Series, how: str) -> float:
    return float(getattr(values, how)()) if len(values) else float("nan")


def _frame_measures(i, full, clutter, target, sub, config, tables) -> dict[str, Any]:
    """Hits (clear sky; ground without, with suppression) and the improvement factor around the intruder."""
    noise = config.noise_power_w
    t_raw = power_image(target, config.rx_calibration)
    k, j = np.unravel_index(np.argmax(t_raw), t_raw.shape)
    sup = suppress_clutter(full, sub, config)  # the nulls the processing chose on the real frame
    c_in = power_image(clutter, config.rx_calibration)
    vectors = sup.applied_vectors(sub)  # adaptive cells' own nulls where the prediction was not kept
    c_out = projected_power(clutter / config.rx_calibration, vectors, sup.nulls)
    t_out = projected_power(target / config.rx_calibration, vectors, sup.nulls)
    gain = float(t_out[k, j] / max(t_raw[k, j], 1e-300))
    wr, wd = _window(k, j, config)
    cell_if = _db(gain * (c_in[wr, wd] + noise) / (c_out[wr, wd] + noise))
    bright = c_in[wr, wd] >= noise * 10 ** (IF_CELL_CNR_DB / 10)
    return {
        "frame": i, "range_bin": int(k), "doppler_bin": int(j),
        "snr_db": float(_db(t_raw[k, j] / noise)),
        "window_cnr_db": float(_db(c_in[wr, wd].mean() / noise)),
        "window_if_db": float(_db(gain * (c_in[wr, wd].mean() + noise) / (c_out[wr, wd].mean() + noise))),
        "target_gain_db": float(_db(gain)),
        "window_bright_cells": int(bright.sum()),
        "window_bright_if_db": float(np.median(cell_if[bright])) if bright.any() else float("nan"),
        "window_bright_cnr_db": _median_db(c_in[wr, wd][bright] / noise),
        "window_bright_attenuation_db": _attenuation_db(c_in[wr, wd][bright], c_out[wr, wd][bright]),
        "nulls": int(sup.nulls[k, j]),
        "hit_clear": _hit(tables["clear"], i, k, j, config),
        "hit_plain": _hit(tables["none"], i, k, j, config),
        "hit_suppressed": _hit(tables["suppressed"], i, k, j, config),
    }  # fmt: skip


def _curves(clutter_cubes, full_cubes, sub, config, height_m) -> pd.DataFrame:
    """SINR loss and IF against Doppler for a boresight target, averaged over frames and 1.3-5 km."""
    noise = config.noise_power_w
    rows = (config.range_axis_m >= END_M) & (config.range_axis_m <= START_M)
    boresight = np.broadcast_to(steering_vector(np.array([1.0, 0.0, 0.0]), config), full_cubes[0].shape)
    c_in = np.zeros(config.n_doppler)
    c_out = np.zeros(config.n_doppler)
    gain = np.zeros(config.n_doppler)
    for clutter, full in zip(clutter_cubes, full_cubes, strict=True):
        sup = suppress_clutter(full, sub, config)
        nulls, vectors = sup.nulls, sup.applied_vectors(sub)
        c_in += power_image(clutter, config.rx_calibration)[rows].mean(axis=0)
        c_out += projected_power(clutter / config.rx_calibration, vectors, nulls)[rows].mean(axis=0)
        gain += projected_power(boresight, vectors, nulls)[rows].mean(axis=0)
    c_in, c_out, gain = (x / len(full_cubes) for x in (c_in, c_out, gain))
    return pd.DataFrame({
        "height_m": height_m, "radial_velocity_mps": config.doppler_axis_mps,
        "clutter_to_noise_db": _db(c_in / noise),
        "sinr_loss_none_db": _db(noise / (c_in + noise)),
        "sinr_loss_suppressed_db": _db(gain * noise / (c_out + noise)),
        "improvement_factor_db": _db(gain * (c_in + noise) / (c_out + noise)),
    })  # fmt: skip


def _case(height_m: float, n_frames: int, seed: int) -> tuple[pd.DataFrame, pd.DataFrame, dict]:
    duration = (START_M - END_M) / CLOSING_MPS
    common = dict(n_frames=n_frames, frame_rate_hz=n_frames / duration, closing_mps=CLOSING_MPS,
                  start_range_m=START_M, seed=seed, rcs_m2=RCS_M2)  # fmt: skip
    full = scene_frames(scene_dict(height_m, **common))
    clear = process_frames(scene_frames(scene_dict(height_m, ground=False, **common)), suppression="none")
    clutter = np.asarray(scene_frames(scene_dict(height_m, noise=False, intruder=False, **common))["iq"])
    target = np.asarray(scene_frames(scene_dict(height_m, noise=False, ground=False, **common))["iq"])
    t0 = time.perf_counter()
    plain = process_frames(full, suppression="none")
    t1 = time.perf_counter()
    suppressed = process_frames(full, suppression="knowledge-aided")
    t2 = time.perf_counter()
    config = radar_config_of(full, "clutter scene")
    sub = frame_subspace(navigated_own_state(full, "clutter scene"), 0, config)
    cubes = np.asarray(full["iq"])
    tables = {"clear": clear, "none": plain, "suppressed": suppressed}
    frames = pd.DataFrame([_frame_measures(i, cubes[i], clutter[i], target[i], sub, config, tables)
                           for i in range(n_frames)])  # fmt: skip
    frames.insert(0, "height_m", height_m)
    frames["range_m"] = np.asarray(full["tgt_range_m"])[:, 0]
    curves = _curves(clutter, cubes, sub, config, height_m)
    timing = {"process_s_per_frame_none": (t1 - t0) / n_frames,
              "process_s_per_frame_suppressed": (t2 - t1) / n_frames,
              "detections_per_frame_none": len(plain) / n_frames,
              "detections_per_frame_suppressed": len(suppressed) / n_frames}  # fmt: skip
    return frames, curves, timing


def _case_summary(height_m: float, frames: pd.DataFrame, curves: pd.DataFrame, timing: dict) -> dict:
    v = curves["radial_velocity_mps"].to_numpy()
    r = np.linspace(END_M, START_M, 64)
    v_mbc = float(np.mean(-OWN_SPEED_MPS * np.sqrt(1.0 - (height_m / r) ** 2)))
    v_lim = float(np.max(np.abs(v)))
    none = doppler_metrics(curves["sinr_loss_none_db"].to_numpy(), v, v_mbc, v_lim)
    supp = doppler_metrics(curves["sinr_loss_suppressed_db"].to_numpy(), v, v_mbc, v_lim)
    lost = frames[frames.hit_clear & ~frames.hit_plain]  # lost to the clutter, not to the range
    cells = lost[lost.window_bright_cells > 0]  # lost frames with window cells where 25 dB is possible
    key = f"h{height_m:g}"
    return {
        f"{key}_intruder_hits_clear_sky": int(frames.hit_clear.sum()),
        f"{key}_intruder_hits_none": int(frames.hit_plain.sum()),
        f"{key}_intruder_hits_suppressed": int(frames.hit_suppressed.sum()),
        f"{key}_frames": len(frames),
        f"{key}_lost_frames_none": len(lost),
        f"{key}_lost_window_if_db_median": _stat(lost.window_if_db, "median"),
        f"{key}_lost_window_if_db_min": _stat(lost.window_if_db, "min"),
        f"{key}_lost_window_cnr_db_median": _stat(lost.window_cnr_db, "median"),
        # The acceptance figure: IF in the cells where the intruder was lost (see the module docstring).
        f"{key}_if_db_lost_cells_median": _stat(cells.window_bright_if_db, "median"),
        f"{key}_if_db_lost_cells_min": _stat(cells.window_bright_if_db, "min"),
        f"{key}_lost_frames_with_cells": len(cells),
        f"{key}_lost_cells": int(cells.window_bright_cells.sum()),
        # What bounds it: IF = g (C + N) / (C_out + N) <= g (CNR + 1) once the clutter is nulled.
        f"{key}_lost_cells_cnr_db_median": _stat(cells.window_bright_cnr_db, "median"),
        f"{key}_lost_cells_target_gain_db_median": _stat(cells.target_gain_db, "median"),
        f"{key}_lost_bright_cell_if_db_median": _stat(lost.window_bright_if_db, "median"),
        f"{key}_lost_bright_cell_if_db_min": _stat(lost.window_bright_if_db, "min"),
        f"{key}_lost_bright_attenuation_db_median": _stat(lost.window_bright_attenuation_db, "median"),
        f"{key}_lost_hits_suppressed": int(lost.hit_suppressed.sum()),
        f"{key}_mdv_mps_none": none["mdv_mps"], f"{key}_mdv_mps_suppressed": supp["mdv_mps"],
        f"{key}_usable_doppler_fraction_none": none["usable_doppler_fraction"],
        f"{key}_usable_doppler_fraction_suppressed": supp["usable_doppler_fraction"],
        f"{key}_if_db_median_over_doppler": float(np.median(curves["improvement_factor_db"])),
        f"{key}_main_beam_clutter_mps": v_mbc,
        **{f"{key}_{name}": value for name, value in timing.items()},
    }  # fmt: skip


def run(out: Path, n_frames: int = 24, heights_m: tuple[float, ...] = (1000.0, 300.0), seed: int = 0) -> dict:
    """Run both cases; write ``frames.csv``, ``sinr_loss.csv``, ``summary.json`` and PNG figures."""
    out = Path(out)
    start = time.perf_counter()
    all_frames, all_curves, result = [], [], {"frames_per_case": n_frames, "seed": seed}
    for height in heights_m:
        frames, curves, timing = _case(float(height), int(n_frames), int(seed))
        result |= _case_summary(float(height), frames, curves, timing)
        all_frames.append(frames)
        all_curves.append(curves)
    frames, curves = pd.concat(all_frames, ignore_index=True), pd.concat(all_curves, ignore_index=True)
    write_csv_atomic(frames, out / "frames.csv", index=False)
    write_csv_atomic(curves, out / "sinr_loss.csv", index=False)
    figures = [
        plot_sinr_loss(out / "sinr_loss.png", curves, LOSS_THRESHOLD_DB),
        plot_track(out / "intruder.png", frames),
    ]
    result["figures"] = [str(p) for p in figures]
    result["rows"] = summary_rows(result, heights_m)
    result["runtime_s"] = time.perf_counter() - start
    write_json_atomic(out / "summary.json", result)
    return result
