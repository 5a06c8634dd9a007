"""``skyradar experiment clutter``: what knowledge-aided suppression buys over flat ground and relief.

The named scene (:mod:`skyradar.experiments.clutter_scene`): prototype radar facing forward,
own-ship level at 50 m/s, a head-on intruder (2 m^2) from 5 km to 1.3 km. The terrain cases
(:data:`TERRAINS`, ``--terrain``):

``flat-1000``, ``flat-300``
    Flat ground 1000 m or 300 m below, the intruder closing at 100 m/s (aliased to -21.7 m/s).
``hills``, ``jacksboro``
    The encounter set's relief (:func:`skyradar.experiments.encounter_terrain.site`: fractal hills
    of 60 m median local height SD, or the Jacksboro DEM), in the fast-closure geometry
    (:func:`skyradar.experiments.encounter_set.make_fast_closures`): own-ship 300-700 m above the
    ground under its track (:func:`~skyradar.experiments.clutter_scene.relief_altitude_m`), the
    intruder closing at :data:`RELIEF_CLOSING_MPS` (106.7 m/s, aliased to -28.4 m/s into the
    ground's Doppler band). The seed picks the hills surface and the point over Jacksboro.

Each case simulates four runs of the same geometry with the image simulator: the full frames
(ground, intruder, noise) that are processed with and without suppression, the clear-sky twin
(intruder and noise), the ground alone without noise and the intruder alone without noise. The
last two are the truth the figures of merit are computed from; the suppression never sees them
(the nulls applied to them are the ones chosen on the full frames, with each frame's own clutter
prediction).

Figures of merit (Ward, "Space-time adaptive processing for airborne radar", MIT Lincoln
Laboratory TR-1015, 1994; the standard STAP metrics), for a target in the head-on direction
(antenna boresight), per Doppler bin, averaged over the frames and the range bins from 1.3 to 5 km:

* SINR loss: output SINR over the noise-only SNR of the same processor, ``L_s = SINR / SNR_0``.
  Without suppression (the non-coherent channel mean) ``L_s = N / (C + N)``; with the projection
  ``P`` of rank ``L`` it is ``g N / (C_out + N)`` with ``g = |P s|^2 / L`` (per-channel target
  power kept) and ``C_out = |P c|^2 / L`` (clutter left), ``N`` the thermal noise per pixel.
* Improvement factor: ``IF = SINR_out / SINR_in`` with ``SINR_in`` per channel:
  ``IF = g (C + N) / (C_out + N)`` (0 dB without suppression).
* Minimum detectable velocity: the smallest radial-velocity separation (aliased) from the
  main-beam clutter Doppler ``-V sqrt(1 - (H / R)^2)`` at which the SINR loss is at least -5 dB
  (``H`` the own-ship's median height above the ground under it).
* Usable Doppler space fraction: the fraction of Doppler bins whose SINR loss is at least -5 dB.

In the intruder's own range-Doppler cell (its truth cell, the brightest cell of the noise-free
intruder-only run), in the frames where it is visible (a hit in the clear-sky twin):

* ``intruder_cell_if_db_median`` and ``_min``: the IF ``g (C + N) / (C_out + N)`` of that cell,
  before against after suppression, with ``g`` the intruder's power its nulls keep;
  ``intruder_cell_cnr_db_median`` the clutter-to-noise ratio there before suppression (-300 dB
  in ``frames.csv``: no ground return in the cell). ``intruder_cell_if_db_median_clutter``: the
  median IF over the ``intruder_cell_clutter_frames`` of them whose cell holds clutter at least
  as strong as the noise (over relief shadowed ground leaves the cell empty in about half the
  frames, where the IF is ``g``, at most 0 dB, and the intruder is lost to the clutter in its
  CFAR window instead).
* ``detection_fraction_none``, ``detection_fraction_suppressed`` and
  ``detection_fraction_suppressed_with_secondary``: the share of those frames with a detection
  within 2 range and 3 Doppler bins of the truth cell, without suppression, with suppression
  (primary detections) and with suppression counting the rows flagged ``secondary`` (the lower
  threshold of nulled cells; a table without that column has primary rows only).

And in the intruder's CFAR window: the IF "in the cells where the head-on intruder is lost"
(``if_db_lost_cells_median`` and ``_min``, the acceptance figure, >= 25 dB required over flat
ground): lost frames are those where the intruder is a hit in the clear-sky twin but not in the
no-suppression run (the suppressed run plays no part in choosing them); lost cells are the CA-CFAR
training cells around its truth cell whose clutter-to-noise ratio is at least ``IF_CELL_CNR_DB``
(25 dB: the per-cell IF cannot exceed the CNR plus the target gain, so a dimmer cell cannot show
25 dB whatever the processing). Per frame the median IF over those cells; the keys give the median
and the minimum over the lost frames that have such cells (``lost_frames_with_cells`` of them,
``lost_cells`` cells in all; at long range the window's clutter is dimmer than 25 dB).
``lost_cells_cnr_db_median`` and ``lost_cells_target_gain_db_median`` (the intruder's power kept
by its own cell's nulls) show what bounds it: with the clutter nulled, ``IF ~ g CNR``.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from skyradar.code_version import code_version, provenance
from skyradar.config import RadarConfig
from skyradar.experiments import encounter_terrain
from skyradar.experiments.clutter_report import plot_sinr_loss, plot_track, summary_markdown, summary_rows
from skyradar.experiments.clutter_scene import OWN_SPEED_MPS, relief_altitude_m, scene_dict, scene_frames
from skyradar.experiments.encounter_set import FAST_CLOSURE_AGL_M
from skyradar.experiments.summary_md import write_summary
from skyradar.io.atomic import write_csv_atomic
from skyradar.io.frames import radar_config_of
from skyradar.io.json_results import write_json_atomic
from skyradar.process.clutter_anchors import prediction_anchors
from skyradar.process.clutter_frames import frame_subspace
from skyradar.process.clutter_suppress import projected_power, suppress_clutter
from skyradar.process.doa import steering_vector
from skyradar.process.pipeline import navigated_own_state, process_frames
from skyradar.process.power import power_image
from skyradar.units import wrap

__all__ = [
    "run",
    "doppler_metrics",
    "parse_terrains",
    "LOSS_THRESHOLD_DB",
    "TERRAINS",
    "DEFAULT_TERRAINS",
    "RELIEF_CLOSING_MPS",
]

LOSS_THRESHOLD_DB = -5.0
START_M, END_M, CLOSING_MPS = 5000.0, 1300.0, 100.0
# Over relief the fast-closure head-on encounter: an intruder at 56.7 m/s (inside make_fast_closures'
# 30-70 m/s) closes at 106.7 m/s, aliased (image width 78.3 m/s) to -28.4 m/s, inside the ground's band.
RELIEF_CLOSING_MPS = 106.7
TERRAINS = ("flat-1000", "flat-300", "hills", "jacksboro")
DEFAULT_TERRAINS = TERRAINS  # all four: about 35 s on 2 cores
_CFAR_HALF = (6, 10)  # guard + training cells each side (range, Doppler) of the default CA-CFAR
_CFAR_GUARD = (2, 2)
IF_CELL_CNR_DB = 25.0  # per-cell IF is bounded by the cell's CNR: judged where 25 dB is possible
RCS_M2 = 2.0  # inside the encounter set's 1-5 m^2 (light aircraft at X band)


def parse_terrains(value: str, option: str = "--terrain") -> list[str]:
    """Terrain cases from a comma-separated list of :data:`TERRAINS` (``all``: every one), in order.

    Examples
    --------
    >>> parse_terrains("hills, flat-300,hills")
    ['hills', 'flat-300']
    >>> parse_terrains("flat")
    ['flat-1000']
    """
    return encounter_terrain.parse_terrains(value, TERRAINS, option)


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


def _hit(
    table: pd.DataFrame, frame: int, k: int, j: int, config: RadarConfig, secondary: bool = False
) -> bool:
    """A detection of frame ``frame`` within 2 range and 3 Doppler bins of (k, j); rows flagged
    ``secondary`` count only with ``secondary`` (a table without the column has primary rows only)."""
    rows = table[table.frame == frame]
    if not secondary and "secondary" in rows:
        rows = rows[~rows["secondary"].astype(bool)]
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
    """Hits (clear sky; ground without, with suppression) and the improvement factor at the intruder."""
    noise = config.noise_power_w
    t_raw = power_image(target, config.rx_calibration)
    k, j = (int(v) for v in np.unravel_index(np.argmax(t_raw), t_raw.shape))
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
        "frame": i,
        "range_bin": int(k),
        "doppler_bin": int(j),
        "snr_db": float(_db(t_raw[k, j] / noise)),
        "cell_cnr_db": float(_db(c_in[k, j] / noise)),
        "cell_if_db": float(_db(gain * (c_in[k, j] + noise) / (c_out[k, j] + noise))),
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
        "hit_suppressed_secondary": _hit(tables["suppressed"], i, k, j, config, secondary=True),
    }


def _curves(clutter_cubes, full_cubes, subs, config) -> pd.DataFrame:
    """SINR loss and IF against Doppler for a boresight target, averaged over frames and 1.3-5 km."""
    noise = config.noise_power_w
    rows = (config.range_axis_m >= END_M) & (config.range_axis_m <= START_M)
    boresight = np.broadcast_to(steering_vector(np.array([1.0, 0.0, 0.0]), config), full_cubes[0].shape)
    c_in = np.zeros(config.n_doppler)
    c_out = np.zeros(config.n_doppler)
    gain = np.zeros(config.n_doppler)
    for clutter, full, sub in zip(clutter_cubes, full_cubes, subs, strict=True):
        sup = suppress_clutter(full, sub, config)
        nulls, vectors = sup.nulls, sup.applied_vectors(sub)
        c_in += power_image(clutter, config.rx_calibration)[rows].mean(axis=0)
        c_out += projected_power(clutter / config.rx_calibration, vectors, nulls)[rows].mean(axis=0)
        gain += projected_power(boresight, vectors, nulls)[rows].mean(axis=0)
    c_in, c_out, gain = (x / len(full_cubes) for x in (c_in, c_out, gain))
    return pd.DataFrame(
        {
            "radial_velocity_mps": config.doppler_axis_mps,
            "clutter_to_noise_db": _db(c_in / noise),
            "sinr_loss_none_db": _db(noise / (c_in + noise)),
            "sinr_loss_suppressed_db": _db(gain * noise / (c_out + noise)),
            "improvement_factor_db": _db(gain * (c_in + noise) / (c_out + noise)),
        }
    )


def _geometry(terrain: str, n_frames: int, seed: int) -> tuple[dict[str, Any], float]:
    """Scene arguments (:func:`~skyradar.experiments.clutter_scene.scene_dict`) of a terrain case
    and its own-ship height (m: above flat ground, or above the origin's datum over relief)."""
    relief = not terrain.startswith("flat-")
    closing = RELIEF_CLOSING_MPS if relief else CLOSING_MPS
    duration = (START_M - END_M) / closing
    common: dict[str, Any] = dict(
        n_frames=n_frames,
        frame_rate_hz=n_frames / duration,
        closing_mps=closing,
        start_range_m=START_M,
        seed=seed,
        rcs_m2=RCS_M2,
    )
    if not relief:
        return common, float(terrain[5:])
    common |= {"terrain": terrain, "terrain_seed": seed}
    track = {k: v for k, v in common.items() if k not in ("seed", "rcs_m2", "terrain")}
    return common, relief_altitude_m(terrain, FAST_CLOSURE_AGL_M, **track)


def _case(terrain: str, n_frames: int, seed: int) -> tuple[pd.DataFrame, pd.DataFrame, dict]:
    common, height_m = _geometry(terrain, n_frames, seed)
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
    own = navigated_own_state(full, "clutter scene")
    assert own is not None  # the scene records the own-ship's navigation
    anchors = prediction_anchors(own)  # as the processing walks them: each frame's own prediction
    subs = [frame_subspace(own, i, config, None, anchors) for i in range(n_frames)]
    cubes = np.asarray(full["iq"])
    tables = {"clear": clear, "none": plain, "suppressed": suppressed}
    frames = pd.DataFrame(
        [
            _frame_measures(i, cubes[i], clutter[i], target[i], subs[i], config, tables)
            for i in range(n_frames)
        ]
    )
    frames.insert(0, "terrain", terrain)
    frames.insert(1, "own_agl_m", np.asarray(full["own_height_agl_m"], float))
    frames["range_m"] = np.asarray(full["tgt_range_m"])[:, 0]
    curves = _curves(clutter, cubes, subs, config)
    curves.insert(0, "terrain", terrain)
    timing = {
        "process_s_per_frame_none": (t1 - t0) / n_frames,
        "process_s_per_frame_suppressed": (t2 - t1) / n_frames,
        "detections_per_frame_none": len(plain) / n_frames,
        "detections_per_frame_suppressed": len(suppressed) / n_frames,
        "closing_mps": float(common["closing_mps"]),
    }
    return frames, curves, timing


def _fraction(hits: pd.Series) -> float:
    return float(hits.mean()) if len(hits) else float("nan")


def _case_summary(frames: pd.DataFrame, curves: pd.DataFrame, timing: dict) -> dict:
    """One terrain case's figures of merit (see the module docstring)."""
    v = curves["radial_velocity_mps"].to_numpy()
    r = np.linspace(END_M, START_M, 64)
    height_m = float(frames.own_agl_m.median())
    v_mbc = float(np.mean(-OWN_SPEED_MPS * np.sqrt(1.0 - np.minimum(height_m / r, 1.0) ** 2)))
    v_lim = float(np.max(np.abs(v)))
    none = doppler_metrics(curves["sinr_loss_none_db"].to_numpy(), v, v_mbc, v_lim)
    supp = doppler_metrics(curves["sinr_loss_suppressed_db"].to_numpy(), v, v_mbc, v_lim)
    visible = frames[frames.hit_clear]  # the intruder is a hit without the ground
    cluttered = visible[visible.cell_cnr_db >= 0.0]  # ... and its own cell holds clutter over the noise
    lost = frames[frames.hit_clear & ~frames.hit_plain]  # lost to the clutter, not to the range
    cells = lost[lost.window_bright_cells > 0]  # lost frames with window cells where 25 dB is possible
    return {
        "own_agl_m_median": height_m,
        "own_agl_m_min": float(frames.own_agl_m.min()),
        "own_agl_m_max": float(frames.own_agl_m.max()),
        "intruder_hits_clear_sky": int(frames.hit_clear.sum()),
        "intruder_hits_none": int(frames.hit_plain.sum()),
        "intruder_hits_suppressed": int(frames.hit_suppressed.sum()),
        "intruder_hits_suppressed_with_secondary": int(frames.hit_suppressed_secondary.sum()),
        "frames": len(frames),
        # In the intruder's own cell, in the frames where it is visible (see the module docstring).
        "visible_frames": len(visible),
        "intruder_cell_if_db_median": _stat(visible.cell_if_db, "median"),
        "intruder_cell_if_db_min": _stat(visible.cell_if_db, "min"),
        "intruder_cell_cnr_db_median": _stat(visible.cell_cnr_db, "median"),
        "intruder_cell_clutter_frames": len(cluttered),
        "intruder_cell_if_db_median_clutter": _stat(cluttered.cell_if_db, "median"),
        "detection_fraction_none": _fraction(visible.hit_plain),
        "detection_fraction_suppressed": _fraction(visible.hit_suppressed),
        "detection_fraction_suppressed_with_secondary": _fraction(visible.hit_suppressed_secondary),
        "lost_frames_none": len(lost),
        "lost_window_if_db_median": _stat(lost.window_if_db, "median"),
        "lost_window_if_db_min": _stat(lost.window_if_db, "min"),
        "lost_window_cnr_db_median": _stat(lost.window_cnr_db, "median"),
        # The acceptance figure: IF in the cells where the intruder is lost (see the module docstring).
        "if_db_lost_cells_median": _stat(cells.window_bright_if_db, "median"),
        "if_db_lost_cells_min": _stat(cells.window_bright_if_db, "min"),
        "lost_frames_with_cells": len(cells),
        "lost_cells": int(cells.window_bright_cells.sum()),
        # What bounds it: IF = g (C + N) / (C_out + N) <= g (CNR + 1) once the clutter is nulled.
        "lost_cells_cnr_db_median": _stat(cells.window_bright_cnr_db, "median"),
        "lost_cells_target_gain_db_median": _stat(cells.target_gain_db, "median"),
        "lost_bright_cell_if_db_median": _stat(lost.window_bright_if_db, "median"),
        "lost_bright_cell_if_db_min": _stat(lost.window_bright_if_db, "min"),
        "lost_bright_attenuation_db_median": _stat(lost.window_bright_attenuation_db, "median"),
        "lost_hits_suppressed": int(lost.hit_suppressed.sum()),
        "mdv_mps_none": none["mdv_mps"],
        "mdv_mps_suppressed": supp["mdv_mps"],
        "usable_doppler_fraction_none": none["usable_doppler_fraction"],
        "usable_doppler_fraction_suppressed": supp["usable_doppler_fraction"],
        "if_db_median_over_doppler": float(np.median(curves["improvement_factor_db"])),
        "main_beam_clutter_mps": v_mbc,
        **timing,
    }


def _title(terrain: str, summary: dict) -> str:
    low, high = summary["own_agl_m_min"], summary["own_agl_m_max"]
    ground = f"{terrain}, {low:.0f}-{high:.0f} m above the ground"
    if terrain.startswith("flat-"):
        ground = f"flat ground {terrain[5:]} m below"
    return f"{ground}, closing {summary['closing_mps']:g} m/s"


def run(
    out: Path,
    n_frames: int = 24,
    terrains: tuple[str, ...] = DEFAULT_TERRAINS,
    seed: int = 0,
    command: str | None = None,
) -> dict[str, Any]:
    """Run the terrain cases; write ``frames.csv``, ``sinr_loss.csv``, ``summary.json``, ``summary.md``
    and PNG figures.

    Parameters
    ----------
    out : Path
        Output folder.
    n_frames : int
        Frames per case, spread over the intruder's 5 to 1.3 km.
    terrains : tuple of str
        Terrain cases, names of :data:`TERRAINS`.
    seed : int
        Noise seed; over relief it also picks the hills surface and the point over Jacksboro.
    command : str, optional
        The command the summary records (default: this process' command line).

    Returns
    -------
    dict
        ``terrains``: one entry of figures of merit per terrain case (see the module docstring;
        heights in m, velocities in m/s, times in s); ``rows``: the summary table, one row per
        terrain (column ``terrain``); ``figures``: the PNG paths (``sinr_loss_<terrain>.png``,
        ``intruder_<terrain>.png``); ``runtime_s``; and the provenance every measured result
        records (:func:`skyradar.code_version.provenance`: ``version``, the code version when the
        run started, ``command``, ``date_utc``, ``load_average_1min``).
    """
    out = Path(out)
    start, version = time.perf_counter(), code_version()
    terrains = tuple(parse_terrains(",".join(terrains)))
    result: dict[str, Any] = {"frames_per_case": n_frames, "seed": seed, "terrains": {}}
    all_frames, all_curves, figures = [], [], []
    for terrain in terrains:
        began = time.perf_counter()
        frames, curves, timing = _case(terrain, int(n_frames), int(seed))
        summary = _case_summary(frames, curves, timing)
        title = _title(terrain, summary)
        figures += [
            plot_sinr_loss(out / f"sinr_loss_{terrain}.png", curves, LOSS_THRESHOLD_DB, title),
            plot_track(out / f"intruder_{terrain}.png", frames, title),
        ]
        result["terrains"][terrain] = summary | {"runtime_s": time.perf_counter() - began}
        all_frames.append(frames)
        all_curves.append(curves)
    write_csv_atomic(pd.concat(all_frames, ignore_index=True), out / "frames.csv", index=False)
    write_csv_atomic(pd.concat(all_curves, ignore_index=True), out / "sinr_loss.csv", index=False)
    result["figures"] = [str(p) for p in figures]
    result["rows"] = summary_rows(result["terrains"])
    result["runtime_s"] = time.perf_counter() - start
    result |= provenance(command, version)
    write_json_atomic(out / "summary.json", result)
    write_summary(out, summary_markdown(result, out))
    return result
