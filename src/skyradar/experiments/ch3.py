"""ch3: detection and 3-D direction of arrival with a radar on the ground aimed at the sky.

The thesis' field test in simulation (Maas 2022, ch. 3). The thesis prototype stands 2 m above
the ground near Delft, boresight at bearing -37.7 deg and pitched up ``pitch_deg`` (default
3 deg), so the calibration building (5 deg right, 1 deg below boresight) lies where the thesis
located it: north-west, about 2 deg above the horizon, 15 m above the radar (thesis: 372 m north,
239 m west, 16 m up). Its coplanar 2x2 square array (antenna y-z plane) has unknown per-antenna
phase offsets (uniform in +-180 deg) and 0.5 dB gain errors.

Array spacing ``rx_spacing_wavelengths`` (default 0.6): the Cramer-Rao bound on azimuth and
elevation scales with 1 / spacing, so 0.6 lambda is 17 % tighter than half a wavelength. The price
is ambiguity: with side d, a direction whose direction cosine along either array axis exceeds
lambda / (2 d) gives the same phases as its grating lobe 1 / d away, so directions are unique only
within ``asin(lambda / (2 d))`` of boresight on either axis: 56.4 deg at 0.6 lambda (0.5 lambda:
the whole front hemisphere; 0.7 lambda: 45.6 deg). 56 deg is wider than the beam (3 dB at +-35 deg,
6 dB at +-49.5 deg), so only a strong return far outside the beam can alias into it (a target at
70 deg azimuth is reported at -47 deg); the circuit stays within 30 deg of boresight.
:func:`skyradar.process.doa.estimate_directions` resolves the wrapped phases by a beamforming
search over the 6 dB field of view. The same seed is also flown with every spacing in
``compare_spacings`` (default 0.5 and 0.7 lambda: same scene, same noise), each calibrated on the
building, for a paired comparison (``half_wavelength``, ``spacing_sweep``, ``ch3_spacing.png``).

1. Static scene, ``n_static`` frames: a 1000 m^2 building at 438 m, 5 deg right and 1 deg below
   boresight, six static clutter points, and the thesis' flight-data impairments (six fixed
   spurs, zero-Doppler line, near-range leakage; :func:`skyradar.sim.impairments.thesis_flight_look`).
   Spur maps are learned from every lit pixel (ours, used with CA-CFAR for the results) and, for
   comparison, from Shi-Tomasi corner points as in the thesis (used with the Shi-Tomasi detector,
   detections inside the map dropped), each at thresholds 2/5/10/25 %; the channels are
   calibrated on the building.
2. Flyover of a 1 m^2 aircraft in the same static scene, ``n_frames`` frames. Default
   (``path="circuit"``): one racetrack circuit 300 m above the radar between 500 m and 3000 m
   (legs 300 m either side of boresight, 60 m/s, about 95 s), so the frames are spaced about
   0.3 s rather than the field rate's 0.106 s: 300 frames at 9.4 frames/s (32 s) cannot hold a
   circuit of that size. ``path="approach"``: a curved descending approach at 70 m/s from 3000 m
   to about 900 m at the field rate (faster than 78 m/s it would alias onto the masked
   zero-Doppler line). In the turns the radial velocity passes through zero (and through the
   aliases of zero): there the aircraft sits on the masked zero-Doppler line and is missed.

Every frame is detected (CA-CFAR, spur pixels masked), located (phase least squares) and matched
to the aircraft truth (within one range and one Doppler bin). Errors are estimate minus truth:
3-D distance in the scenario NED frame, azimuth and elevation in the antenna frame; raw and after
a 9-frame Hann filter along the track. The Cramer-Rao bound is evaluated at each detection's
measured SNR and true direction and averaged as an RMS. Frames come from the lead's
:class:`skyradar.sim.image.ImageSimulator` (free space, point targets, noise off) followed by
:func:`skyradar.sim.impairments.apply_impairments` (channel errors, spurs, line, leakage, noise).
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from skyradar.config import RadarConfig
from skyradar.experiments.ch3_scene import (
    BUILDING,
    aircraft_path,
    build_scene,
    square_array_m,
    unambiguous_half_angle_deg,
)
from skyradar.experiments.summary_md import number, page, write_summary
from skyradar.io.atomic import write_csv_atomic
from skyradar.io.json_results import write_json_atomic
from skyradar.io.tables import write_table
from skyradar.process.calibration import calibrate_from_frames, calibration_phase_error_deg
from skyradar.process.detect import integrate_channels
from skyradar.process.doa import doa_crlb
from skyradar.process.pipeline import process_cube
from skyradar.process.smoothing import hann_smooth
from skyradar.process.spurs import THESIS_THRESHOLDS, learn_spur_map
from skyradar.sim.image import PointTarget
from skyradar.sim.impairments import apply_impairments

__all__ = ["THESIS_TABLE", "run", "square_array_m", "summary_markdown", "unambiguous_half_angle_deg"]

HANN_FRAMES = 9
SPUR_THRESHOLD = 0.05
OUTLIER_DEG = 10.0  # a DoA error this large is an ambiguity (wrong wrap), not noise
# Maas 2022, ch. 3: (raw mean, raw SD, Hann mean, Hann SD)
THESIS_TABLE = {
    "dist_m": (46.2, 30.3, 30.7, 16.1),
    "az_deg": (-0.4, 1.8, -0.37, 0.8),
    "el_deg": (-0.5, 2.7, -0.43, 1.6),
}


def _match(out: dict, truth: dict, config: RadarConfig) -> int:
    """Index of the detection on the aircraft's pixel (+-1 bin each way), or -1."""
    dk = np.abs(np.rint(out["range_bin"]) - truth["range_bin"][0])
    n = config.n_doppler
    dj = np.abs((np.rint(out["doppler_bin"]) - truth["doppler_bin"][0] + n // 2) % n - n // 2)
    hit = np.flatnonzero((dk <= 1) & (dj <= 1))
    return int(hit[np.argmax(out["snr_db"][hit])]) if hit.size else -1


def _static_frames(scene: dict, n_static: int) -> list[np.ndarray]:
    cfg, sim, imp = scene["config"], scene["sim"], scene["imp"]
    return [
        apply_impairments(sim.frame(scene["platform"], scene["static"], i), cfg, imp, i)
        for i in range(n_static)
    ]


def _static_phase(scene: dict, n_static: int) -> tuple[RadarConfig, Any, np.ndarray, dict[str, Any]]:
    raw = _static_frames(scene, n_static)
    cal = calibrate_from_frames(np.stack(raw[: min(20, n_static)]), scene["building_ant"], scene["config"])
    powers = [integrate_channels(c, cal.rx_calibration) for c in raw]
    # Ours: every lit pixel; thesis: Shi-Tomasi corner points, both dilated by one pixel.
    corners = learn_spur_map(powers, cal, SPUR_THRESHOLD, "peaks", method="shi-tomasi")
    spur_map = {"hits": learn_spur_map(powers, cal, SPUR_THRESHOLD, "hits"), "corners": corners}
    out = process_cube(raw[0], cal)  # locate the building with the calibrated array, no spur map
    k = int(np.argmin(np.abs(out["range_m"] - BUILDING[0]) + 100 * np.abs(out["radial_velocity_mps"])))
    ned = scene["geom"].origin_ned_m + scene["geom"].rot_ned_to_ant.T @ (out["range_m"][k] * out["u_ant"][k])
    building = {
        "building_north_m": ned[0],
        "building_east_m": ned[1],
        "building_up_m": -ned[2],
        "building_az_err_deg": np.degrees(out["azimuth_rad"][k]) - BUILDING[1],
        "building_el_err_deg": np.degrees(out["elevation_rad"][k]) - BUILDING[2],
    }
    return cal, spur_map, raw[0], building


def _flyover(
    scene: dict, cal: RadarConfig, spur_map, n_frames: int, path: str, all_maps: bool = True
) -> tuple[pd.DataFrame, dict, Any]:
    """Per-frame track table, detection/false-alarm counts per spur map, one frame to show.

    ``all_maps=False`` processes with our map at ``SPUR_THRESHOLD`` only (the array comparisons).
    """
    cfg, sim, imp, geom = scene["config"], scene["sim"], scene["imp"], scene["geom"]
    times, ned, vel = aircraft_path(n_frames, geom, path)
    keys = [(k, t) for k in spur_map for t in THESIS_THRESHOLDS] if all_maps else [("hits", SPUR_THRESHOLD)]
    maps = {key: spur_map[key[0]].with_threshold(key[1]) for key in keys}
    false_alarms = dict.fromkeys(maps, 0)
    detected = dict.fromkeys(maps, 0)
    rows, shown = [], None
    for i in range(n_frames):
        aircraft = PointTarget(ned[i], vel[i], 1.0)
        truth = sim.target_truth(scene["platform"], [aircraft])
        cube = apply_impairments(
            sim.frame(scene["platform"], [*scene["static"], aircraft], 1000 + i), cfg, imp, 1000 + i
        )
        for key, smap in maps.items():
            if key[0] == "hits":  # ours: CA-CFAR with spur pixels masked
                out = process_cube(cube, cal, smap)
            else:  # thesis: Shi-Tomasi corners, detections inside the corner map dropped
                out = process_cube(cube, cal, smap, method="shi-tomasi", spur_mode="flag")
                out = {name: value[~out["spur"]] for name, value in out.items()}
            k = _match(out, truth, cfg)
            detected[key] += k >= 0
            false_alarms[key] += len(out["range_m"]) - (k >= 0)
            if key != ("hits", SPUR_THRESHOLD):
                continue
            if shown is None and k >= 0 and truth["snr_db"][0] > 20:
                shown = (cube, out, truth)
            row = {
                "time_s": times[i],
                "frame": i,
                "true_snr_db": truth["snr_db"][0],
                "detected": k >= 0,
                "true_range_m": truth["range_m"][0],
                "true_az_rad": truth["azimuth_rad"][0],
                "true_el_rad": truth["elevation_rad"][0],
                "true_north_m": ned[i, 0],
                "true_east_m": ned[i, 1],
                "true_down_m": ned[i, 2],
            }
            est = (
                np.full(3, np.nan)
                if k < 0
                else geom.origin_ned_m + geom.rot_ned_to_ant.T @ (out["range_m"][k] * out["u_ant"][k])
            )
            row.update(north_m=est[0], east_m=est[1], down_m=est[2])
            for name in ("range_m", "radial_velocity_mps", "snr_db", "azimuth_rad", "elevation_rad"):
                row[name] = out[name][k] if k >= 0 else np.nan
            rows.append(row)
    stats = {"detected": detected, "false_alarms": false_alarms}
    return pd.DataFrame(rows), stats, shown


def _errors(track: pd.DataFrame, geom) -> pd.DataFrame:
    """Raw and Hann-filtered errors per frame (NaN where not detected)."""
    from skyradar.geo import direction_angles

    est = track[["north_m", "east_m", "down_m"]].to_numpy()
    true = track[["true_north_m", "true_east_m", "true_down_m"]].to_numpy()
    out = pd.DataFrame({"time_s": track.time_s, "true_snr_db": track.true_snr_db})
    for label, pos in (("raw", est), ("hann", hann_smooth(est, HANN_FRAMES))):
        pos = np.where(np.isfinite(est), pos, np.nan)  # compare only frames with a detection
        _, az, el = direction_angles((pos - geom.origin_ned_m) @ geom.rot_ned_to_ant.T)
        out[f"dist_{label}_m"] = np.linalg.norm(pos - true, axis=1)
        out[f"az_{label}_deg"] = np.degrees(az - track.true_az_rad)
        out[f"el_{label}_deg"] = np.degrees(el - track.true_el_rad)
    return out


def _doa_summary(track: pd.DataFrame, err: pd.DataFrame, cal: RadarConfig, spacing: float) -> dict[str, Any]:
    """Raw DoA error SD, Cramer-Rao bound (RMS over detections) and ambiguity outliers of one array."""
    det = track.detected.to_numpy()
    az_err, el_err = err.az_raw_deg[det], err.el_raw_deg[det]
    sd_az, sd_el = doa_crlb(track.snr_db[det], track.true_az_rad[det], track.true_el_rad[det], cal)
    return {
        "rx_spacing_wavelengths": spacing,
        "unambiguous_half_angle_deg": unambiguous_half_angle_deg(spacing),
        "az_sd_deg": float(az_err.std()),
        "el_sd_deg": float(el_err.std()),
        "az_crlb_deg": float(np.degrees(np.sqrt(np.mean(sd_az**2)))),
        "el_crlb_deg": float(np.degrees(np.sqrt(np.mean(sd_el**2)))),
        # error / bound per detection: the bound varies with SNR and direction along the circuit
        "az_sd_over_crlb": float(np.std(np.radians(az_err) / sd_az)),
        "el_sd_over_crlb": float(np.std(np.radians(el_err) / sd_el)),
        "detected_frames": int(det.sum()),
        "doa_outliers": int(np.sum((np.abs(az_err) > OUTLIER_DEG) | (np.abs(el_err) > OUTLIER_DEG))),
    }


def _compare_array(
    spacing: float, pitch_deg: float, seed: int, spur_map, n_frames: int, n_static: int, path: str
) -> dict[str, Any]:
    """The same scene and noise seen by another array: calibrate on the building, fly, summarise.

    The spur map of the main array is reused: it is learned from non-coherent channel power,
    which the antenna layout does not change.
    """
    scene = build_scene(pitch_deg, seed, spacing)
    raw = np.stack(_static_frames(scene, min(20, n_static)))
    cal = calibrate_from_frames(raw, scene["building_ant"], scene["config"])
    track, _, _ = _flyover(scene, cal, spur_map, n_frames, path, all_maps=False)
    summary = _doa_summary(track, _errors(track, scene["geom"]), cal, spacing)
    summary["calib_phase_err_deg"] = calibration_phase_error_deg(cal.rx_calibration, scene["true_gain"])
    return summary


def _error_table(err: pd.DataFrame, det: np.ndarray) -> pd.DataFrame:
    table = []
    for key, (m_raw, s_raw, m_hann, s_hann) in THESIS_TABLE.items():
        name, unit = key.rsplit("_", 1)
        raw, hann = err[f"{name}_raw_{unit}"][det], err[f"{name}_hann_{unit}"][det]
        table.append(
            {
                "quantity": key,
                "raw_mean": raw.mean(),
                "raw_sd": raw.std(),
                "hann_mean": hann.mean(),
                "hann_sd": hann.std(),
                "thesis_raw_mean": m_raw,
                "thesis_raw_sd": s_raw,
                "thesis_hann_mean": m_hann,
                "thesis_hann_sd": s_hann,
            }
        )
    return pd.DataFrame(table).set_index("quantity")


def _summary(track: pd.DataFrame, err: pd.DataFrame, table: pd.DataFrame, stats: dict, n_frames: int) -> dict:
    det = track.detected.to_numpy()
    snr_ok = track.true_snr_db.to_numpy() >= 13.0
    result = {
        "az_mean_deg": table.loc["az_deg", "raw_mean"],
        "el_mean_deg": table.loc["el_deg", "raw_mean"],
        "az_hann_sd_deg": table.loc["az_deg", "hann_sd"],
        "el_hann_sd_deg": table.loc["el_deg", "hann_sd"],
        "az_sd_snr13_deg": float(err.az_raw_deg[det & snr_ok].std()),
        "el_sd_snr13_deg": float(err.el_raw_deg[det & snr_ok].std()),
        "dist_mean_m": table.loc["dist_m", "raw_mean"],
        "dist_sd_m": table.loc["dist_m", "raw_sd"],
        "dist_hann_mean_m": table.loc["dist_m", "hann_mean"],
        "dist_hann_sd_m": table.loc["dist_m", "hann_sd"],
        "frames": n_frames,
        "detected_frames_snr13": int(det[snr_ok].sum()),
        "frames_snr13": int(snr_ok.sum()),
        "false_alarms_per_frame": stats["false_alarms"][("hits", SPUR_THRESHOLD)] / n_frames,
        "frame_interval_s": float(track.time_s.diff().median()) if n_frames > 1 else 0.0,
        "min_range_m": float(track.true_range_m.min()),
        "max_range_m": float(track.true_range_m.max()),
        "max_off_boresight_deg": float(
            np.degrees(np.max(np.arccos(np.cos(track.true_az_rad) * np.cos(track.true_el_rad))))
        ),
    }
    for (kind, thr), n_fa in stats["false_alarms"].items():
        tag = f"{int(thr * 100)}pct" + ("" if kind == "hits" else "_corner_map")
        result[f"false_alarms_per_frame_{tag}"] = n_fa / n_frames
        result[f"detected_frames_{tag}"] = int(stats["detected"][(kind, thr)])
    return result


def _write_outputs(
    out_dir: Path, table: pd.DataFrame, track: pd.DataFrame, err: pd.DataFrame, sweep: list[dict]
) -> None:
    write_table(table.reset_index(), out_dir / "ch3_table.parquet")
    write_csv_atomic(table, out_dir / "ch3_table.csv")
    write_table(
        pd.concat([track, err.drop(columns=["time_s", "true_snr_db"])], axis=1), out_dir / "ch3_track.parquet"
    )
    write_table(pd.DataFrame(sweep), out_dir / "ch3_spacing.parquet")


def _spacings(rx_spacing_wavelengths: float, compare_spacings) -> tuple[float, list[float]]:
    """The flown receive spacing and the further ones to compare, each checked."""
    spacing = float(rx_spacing_wavelengths)
    others = sorted({float(s) for s in compare_spacings} - {spacing})
    for s in (spacing, *others):
        square_array_m(s, 1.0)
    return spacing, others


def _spacing_sweep(arrays: dict[float, dict]) -> dict[str, Any]:
    """``spacing_sweep`` (DoA summary per spacing, ascending) and ``half_wavelength`` when flown."""
    out: dict[str, Any] = {}
    if 0.5 in arrays:
        out["half_wavelength"] = {k: v for k, v in arrays[0.5].items() if k != "rx_spacing_wavelengths"}
    out["spacing_sweep"] = [arrays[s] for s in sorted(arrays)]
    return out


def run(
    out_dir: Path,
    n_frames: int = 300,
    n_static: int = 60,
    pitch_deg: float = 3.0,
    path: str = "circuit",
    seed: int = 0,
    rx_spacing_wavelengths: float = 0.6,
    compare_spacings: tuple[float, ...] = (0.5, 0.7),
) -> dict:
    """Run the ch3 experiment, write table, JSON and figures into ``out_dir``; return the summary.

    Parameters
    ----------
    out_dir : Path
        Output directory (created).
    n_frames, n_static : int
        Flyover and static-scene frames.
    pitch_deg : float
        Boresight elevation above the horizon, deg (3 deg puts the building where the thesis found it).
    path : str
        ``"circuit"`` flies one racetrack circuit between 500 and 3000 m in ``n_frames`` frames;
        ``"approach"`` the 32 s approach at the field frame rate (module docstring).
    rx_spacing_wavelengths : float
        Side of the 2x2 receive square in wavelengths, (0, 1]; unambiguous within
        ``asin(1 / (2 spacing))`` of boresight on either axis (56.4 deg at 0.6).
    compare_spacings : tuple of float
        Further spacings flown with the same seed (DoA summaries under ``spacing_sweep``; 0.5 also
        under ``half_wavelength``).

    Returns
    -------
    dict
        Summary (also written to ``ch3.json``): errors, bounds, detection counts, calibration.
    """
    from skyradar.experiments.ch3_figures import plot_all, plot_spacing

    t0 = time.perf_counter()
    spacing, others = _spacings(rx_spacing_wavelengths, compare_spacings)  # InputError before any work
    (out_dir := Path(out_dir)).mkdir(parents=True, exist_ok=True)
    scene = build_scene(pitch_deg, seed, spacing)
    cal, spur_map, static_frame, building = _static_phase(scene, n_static)
    track, stats, shown = _flyover(scene, cal, spur_map, n_frames, path)
    err = _errors(track, scene["geom"])
    table = _error_table(err, track.detected.to_numpy())
    main = _doa_summary(track, err, cal, spacing)
    main["calib_phase_err_deg"] = calibration_phase_error_deg(cal.rx_calibration, scene["true_gain"])
    compared = {s: _compare_array(s, pitch_deg, seed, spur_map, n_frames, n_static, path) for s in others}
    result = {
        **main,
        **_summary(track, err, table, stats, n_frames),
        "pitch_deg": float(pitch_deg),
        "spur_threshold": SPUR_THRESHOLD,
        "spur_pixels": int(spur_map["hits"].mask.sum()),
        "path": path,
        **building,
    }
    result |= _spacing_sweep({spacing: main} | compared)
    _write_outputs(out_dir, table, track, err, result["spacing_sweep"])
    plot_all(out_dir, static_frame, cal, spur_map["hits"], shown, track, err, scene["geom"])
    if len(result["spacing_sweep"]) > 1:
        plot_spacing(out_dir, result["spacing_sweep"], THESIS_TABLE)
    result["runtime_s"] = time.perf_counter() - t0
    result = {k: (float(v) if isinstance(v, np.floating) else v) for k, v in result.items()}
    write_json_atomic(out_dir / "ch3.json", result)
    write_summary(out_dir, summary_markdown(result, out_dir))
    return result


_FILES = {
    "ch3_range_doppler.png": "the static scene's range-Doppler image, the spur map and one flyover frame",
    "ch3_track_3d.png": "the aircraft's located detections against its true path",
    "ch3_errors.png": "position, azimuth and elevation errors along the flyover, raw and Hann-filtered",
    "ch3_spacing.png": "DoA error and Cramer-Rao bound per receive spacing",
    "ch3_table.csv": "error mean and SD, raw and Hann-filtered, beside the thesis' (also `.parquet`)",
    "ch3_table.parquet": "the same table",
    "ch3_track.parquet": "every flyover frame: truth, detection, location and errors",
    "ch3_spacing.parquet": "the DoA summary of each receive spacing",
    "ch3.json": "every measured value",
}


def summary_markdown(result: dict[str, Any], out_dir: Path | None = None) -> str:
    """``summary.md`` of a ch3 run: detection and direction-of-arrival errors beside the thesis'.

    The thesis' numbers are :data:`THESIS_TABLE` (raw mean, raw SD, Hann mean, Hann SD).

    Parameters
    ----------
    result : dict
        The summary :func:`run` returns (also in ``ch3.json``).
    out_dir : Path, optional
        The run's folder: only the files present there are listed (None: all of them).

    Returns
    -------
    str
        Markdown: title, sentences, a table of ours against the thesis, the files.

    Examples
    --------
    >>> r = {"frames": 300, "path": "circuit", "rx_spacing_wavelengths": 0.6, "detected_frames": 270,
    ...      "detected_frames_snr13": 268, "frames_snr13": 270, "false_alarms_per_frame": 0.0,
    ...      "az_mean_deg": 0.02, "az_sd_deg": 0.61, "az_hann_sd_deg": 0.3, "az_crlb_deg": 0.55,
    ...      "el_mean_deg": -0.03, "el_sd_deg": 0.72, "el_hann_sd_deg": 0.35, "el_crlb_deg": 0.66,
    ...      "dist_mean_m": 20.1, "dist_sd_m": 14.2, "dist_hann_mean_m": 12.0, "dist_hann_sd_m": 7.5,
    ...      "doa_outliers": 0, "calib_phase_err_deg": 0.4, "building_up_m": 15.2,
    ...      "spacing_sweep": [{"rx_spacing_wavelengths": 0.6, "az_sd_deg": 0.61, "el_sd_deg": 0.72}]}
    >>> text = summary_markdown(r)
    >>> print(text.splitlines()[0])
    # ch3: detection and direction of arrival from the ground
    >>> "| azimuth error SD, raw [deg] | 0.61 | 1.80 |" in text, "`ch3_errors.png`" in text
    (True, True)
    >>> "`ch3_spacing.png`" in text  # drawn only when more than one spacing is flown
    False
    """
    r = result
    t = THESIS_TABLE  # (raw mean, raw SD, Hann mean, Hann SD)
    headline = (
        ("3-D position error mean, raw [m]", "dist_mean_m", t["dist_m"][0], 1),
        ("3-D position error SD, raw [m]", "dist_sd_m", t["dist_m"][1], 1),
        ("3-D position error mean, Hann-filtered [m]", "dist_hann_mean_m", t["dist_m"][2], 1),
        ("3-D position error SD, Hann-filtered [m]", "dist_hann_sd_m", t["dist_m"][3], 1),
        ("azimuth error mean, raw [deg]", "az_mean_deg", t["az_deg"][0], 2),
        ("azimuth error SD, raw [deg]", "az_sd_deg", t["az_deg"][1], 2),
        ("azimuth error SD, Hann-filtered [deg]", "az_hann_sd_deg", t["az_deg"][3], 2),
        ("elevation error mean, raw [deg]", "el_mean_deg", t["el_deg"][0], 2),
        ("elevation error SD, raw [deg]", "el_sd_deg", t["el_deg"][1], 2),
        ("elevation error SD, Hann-filtered [deg]", "el_hann_sd_deg", t["el_deg"][3], 2),
    )
    rows = [[label, number(r[key], d), number(thesis, d)] for label, key, thesis, d in headline]
    sweep = r.get("spacing_sweep", [])
    spacing = ", ".join(
        f"{number(s['rx_spacing_wavelengths'], 2)} wavelengths {number(s['az_sd_deg'], 2)} deg in azimuth "
        f"and {number(s['el_sd_deg'], 2)} deg in elevation"
        for s in sweep
    )
    paragraphs = [
        f"A radar on the ground aimed at the sky, calibrated on a building, detects and locates a small "
        f"aircraft on a {r['path']} over {r['frames']} frames with a 2x2 receive square of "
        f"{number(r['rx_spacing_wavelengths'], 2)} wavelengths. It is detected in "
        f"{r['detected_frames_snr13']} of the {r['frames_snr13']} frames where its SNR is at least 13 dB, "
        f"with {number(r['false_alarms_per_frame'], 3)} false alarms per frame.",
        f"Raw direction errors have an SD of {number(r['az_sd_deg'], 2)} deg in azimuth and "
        f"{number(r['el_sd_deg'], 2)} deg in elevation (thesis {number(THESIS_TABLE['az_deg'][1], 2)} and "
        f"{number(THESIS_TABLE['el_deg'][1], 2)} deg), against a Cramer-Rao bound of "
        f"{number(r['az_crlb_deg'], 2)} and {number(r['el_crlb_deg'], 2)} deg; "
        f"{r['doa_outliers']} detections were ambiguity outliers. The 3-D position error is "
        f"{number(r['dist_mean_m'])} +- {number(r['dist_sd_m'])} m raw (thesis "
        f"{number(THESIS_TABLE['dist_m'][0])} +- {number(THESIS_TABLE['dist_m'][1])} m). The channels "
        f"are calibrated to {number(r['calib_phase_err_deg'], 2)} deg of phase; the building is located "
        f"{number(r['building_up_m'])} m above the radar."
        + (f" Per receive spacing the raw SD is: {spacing}." if len(sweep) > 1 else ""),
    ]
    files = {k: v for k, v in _FILES.items() if k != "ch3_spacing.png" or len(sweep) > 1}
    title = "ch3: detection and direction of arrival from the ground"
    return page(title, paragraphs, ["quantity", "measured", "thesis"], rows, files, out_dir)
