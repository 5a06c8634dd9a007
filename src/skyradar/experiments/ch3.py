"""ch3: detection and 3-D direction of arrival with a radar on the ground aimed at the sky.

The thesis' field test in simulation (seed-brief.md ch3). The seed prototype stands 2 m above
the ground near Delft, boresight at bearing -37.7 deg (so the calibration building lies where the
thesis found it, north-west) and pitched up ``pitch_deg`` (default 10 deg). Its coplanar 2x2
array has unknown per-antenna phase offsets (uniform in +-180 deg) and 0.5 dB gain errors.

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

from skyradar.config import Mount, RadarConfig
from skyradar.errors import InputError
from skyradar.io.tables import write_json_atomic, write_table
from skyradar.process.calibration import (
    calibrate_from_frames,
    calibration_phase_error_deg,
    reflector_position,
)
from skyradar.process.detect import integrate_channels
from skyradar.process.doa import doa_crlb
from skyradar.process.pipeline import process_cube
from skyradar.process.smoothing import hann_smooth
from skyradar.process.spurs import THESIS_THRESHOLDS, learn_spur_map
from skyradar.sim.image import ImageSimulator, PlatformState, PointTarget
from skyradar.sim.impairments import (
    ChannelErrorsConfig,
    NoiseConfig,
    apply_impairments,
    channel_errors,
    thesis_flight_look,
)

__all__ = ["THESIS_TABLE", "run"]

ORIGIN = (52.0, 4.37, 0.0)
BORESIGHT_BEARING_DEG = -37.7
BUILDING = (438.0, 5.0, -1.0, 1000.0)  # range m, az deg (right +), el deg (up +), RCS m^2
FRAME_RATE_HZ = 300 / 32.0
SPEED_MPS = {"circuit": 60.0, "approach": 70.0}
HANN_FRAMES = 9
SPUR_THRESHOLD = 0.05
# seed-brief.md ch3: (raw mean, raw SD, Hann mean, Hann SD)
THESIS_TABLE = {
    "dist_m": (46.2, 30.3, 30.7, 16.1),
    "az_deg": (-0.4, 1.8, -0.37, 0.8),
    "el_deg": (-0.5, 2.7, -0.43, 1.6),
}


def _scene(pitch_deg: float, seed: int) -> dict[str, Any]:
    config = RadarConfig.seed_prototype(mount=Mount(Mount.preset("sky").position_m, pitch_deg=pitch_deg))
    platform = PlatformState(
        np.array([0.0, 0.0, -2.0]), np.zeros(3), np.array([np.radians(BORESIGHT_BEARING_DEG), 0, 0])
    )
    sim = ImageSimulator(config, None, origin=ORIGIN, noise=False, seed=seed)
    geom = sim.geometry(platform)
    ant_to_ned = geom.rot_ned_to_ant.T
    rng = np.random.default_rng([seed, 3])
    building_ant = reflector_position(BUILDING[0], np.radians(BUILDING[1]), np.radians(BUILDING[2]))
    static = [PointTarget(geom.origin_ned_m + ant_to_ned @ building_ant, np.zeros(3), BUILDING[3])]
    for _ in range(6):  # trees, masts, roofs near the horizon
        p = reflector_position(
            rng.uniform(150, 2000), np.radians(rng.uniform(-25, 25)), np.radians(rng.uniform(-9, -3))
        )
        static.append(PointTarget(geom.origin_ned_m + ant_to_ned @ p, np.zeros(3), rng.uniform(10, 100)))
    phases = np.r_[0.0, rng.uniform(-180, 180, config.n_rx - 1)]
    gains = np.r_[0.0, rng.normal(0, 0.5, config.n_rx - 1)]
    imp = thesis_flight_look(seed).model_copy(
        update={
            "channel_errors": ChannelErrorsConfig(gain_db=gains.tolist(), phase_deg=phases.tolist()),
            "noise": NoiseConfig(),
        }  # fmt: skip
    )
    true_gain = channel_errors(config.n_rx, gains.tolist(), phases.tolist())
    return {"config": config, "platform": platform, "sim": sim, "geom": geom, "static": static, "imp": imp,
            "true_gain": true_gain, "building_ant": building_ant}  # fmt: skip


def _racetrack(n: int = 6000) -> np.ndarray:
    """Dense circuit in (forward, right, down) from the radar: legs at +-300 m, turns reaching 500 and
    3000 m horizontal distance along boresight, 300 m above the radar."""
    near, far, half, down = 800.0, 2700.0, 300.0, -300.0
    leg = np.linspace(near, far, n)
    turn = np.linspace(0.0, np.pi, n)
    parts = [
        np.stack([leg, np.full(n, half)], axis=1),  # outbound, right of boresight
        np.stack([far + half * np.sin(turn), half * np.cos(turn)], axis=1),  # far turn through 3000 m
        np.stack([leg[::-1], np.full(n, -half)], axis=1),  # inbound
        np.stack([near - half * np.sin(turn), -half * np.cos(turn)], axis=1),  # near turn through 500 m
    ]
    fr = np.concatenate([part[1:] for part in parts])  # each part starts where the last ended
    return np.column_stack([fr, np.full(len(fr), down)])


def _approach(n: int = 4001) -> np.ndarray:
    """Dense curved, descending approach from 3000 m (quadratic Bezier) in (forward, right, down)."""
    ctrl = np.array([[2960.0, 450.0, -520.0], [1900.0, 900.0, -380.0], [700.0, -150.0, -160.0]])
    s = np.linspace(0.0, 1.0, n)[:, None]
    return (1 - s) ** 2 * ctrl[0] + 2 * s * (1 - s) * ctrl[1] + s**2 * ctrl[2]


def _aircraft(n_frames: int, geom, path: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Frame times, NED positions and velocities of the aircraft at constant speed along ``path``."""
    if path not in ("circuit", "approach"):
        raise InputError(f"ch3: field 'path' must be 'circuit' or 'approach', got {path!r}")
    curve = _racetrack() if path == "circuit" else _approach()
    speed = SPEED_MPS[path]
    arc = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(curve, axis=0), axis=1))]
    # The circuit is flown once in n_frames; the approach at the field frame rate (thesis: 300 in 32 s).
    dt = arc[-1] / speed / n_frames if path == "circuit" else 1.0 / FRAME_RATE_HZ
    t = np.arange(n_frames) * dt
    dist = np.minimum(speed * t, arc[-1])
    tangent = np.gradient(curve, arc, axis=0)
    local = np.stack([np.interp(dist, arc, curve[:, k]) for k in range(3)], axis=1)
    local_v = speed * np.stack([np.interp(dist, arc, tangent[:, k]) for k in range(3)], axis=1)
    b = np.radians(BORESIGHT_BEARING_DEG)
    to_ned = np.array([[np.cos(b), -np.sin(b), 0.0], [np.sin(b), np.cos(b), 0.0], [0.0, 0.0, 1.0]])
    return t, geom.origin_ned_m + local @ to_ned.T, local_v @ to_ned.T


def _match(out: dict, truth: dict, config: RadarConfig) -> int:
    """Index of the detection on the aircraft's pixel (+-1 bin each way), or -1."""
    dk = np.abs(np.rint(out["range_bin"]) - truth["range_bin"][0])
    n = config.n_doppler
    dj = np.abs((np.rint(out["doppler_bin"]) - truth["doppler_bin"][0] + n // 2) % n - n // 2)
    hit = np.flatnonzero((dk <= 1) & (dj <= 1))
    return int(hit[np.argmax(out["snr_db"][hit])]) if hit.size else -1


def _static_phase(scene: dict, n_static: int) -> tuple[RadarConfig, Any, np.ndarray, dict[str, Any]]:
    cfg, sim, imp = scene["config"], scene["sim"], scene["imp"]
    raw = [
        apply_impairments(sim.frame(scene["platform"], scene["static"], i), cfg, imp, i)
        for i in range(n_static)
    ]
    cal = calibrate_from_frames(np.stack(raw[: min(20, n_static)]), scene["building_ant"], cfg)
    powers = [integrate_channels(c, cal.rx_calibration) for c in raw]
    # Ours: every lit pixel; thesis: Shi-Tomasi corner points, both dilated by one pixel.
    corners = learn_spur_map(powers, cal, SPUR_THRESHOLD, "peaks", method="shi-tomasi")
    spur_map = {"hits": learn_spur_map(powers, cal, SPUR_THRESHOLD, "hits"), "corners": corners}
    out = process_cube(raw[0], cal)  # locate the building with the calibrated array, no spur map
    k = int(np.argmin(np.abs(out["range_m"] - BUILDING[0]) + 100 * np.abs(out["radial_velocity_mps"])))
    ned = scene["geom"].origin_ned_m + scene["geom"].rot_ned_to_ant.T @ (out["range_m"][k] * out["u_ant"][k])
    building = {"building_north_m": ned[0], "building_east_m": ned[1], "building_up_m": -ned[2],
                "building_az_err_deg": np.degrees(out["azimuth_rad"][k]) - BUILDING[1],
                "building_el_err_deg": np.degrees(out["elevation_rad"][k]) - BUILDING[2]}  # fmt: skip
    return cal, spur_map, raw[0], building


def _flyover(
    scene: dict, cal: RadarConfig, spur_map, n_frames: int, path: str
) -> tuple[pd.DataFrame, dict, Any]:
    cfg, sim, imp, geom = scene["config"], scene["sim"], scene["imp"], scene["geom"]
    times, ned, vel = _aircraft(n_frames, geom, path)
    maps = {(kind, t): spur_map[kind].with_threshold(t) for kind in spur_map for t in THESIS_THRESHOLDS}
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
            row = {"time_s": times[i], "frame": i, "true_snr_db": truth["snr_db"][0], "detected": k >= 0,
                   "true_range_m": truth["range_m"][0], "true_az_rad": truth["azimuth_rad"][0],
                   "true_el_rad": truth["elevation_rad"][0], "true_north_m": ned[i, 0],
                   "true_east_m": ned[i, 1], "true_down_m": ned[i, 2]}  # fmt: skip
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


def run(
    out_dir: Path,
    n_frames: int = 300,
    n_static: int = 60,
    pitch_deg: float = 10.0,
    path: str = "circuit",
    seed: int = 0,
) -> dict:
    """Run the ch3 experiment, write table, JSON and figures into ``out_dir``; return the summary.

    ``path="circuit"`` flies one racetrack circuit between 500 and 3000 m in ``n_frames`` frames;
    ``"approach"`` the 32 s approach at the field frame rate (module docstring).
    """
    from skyradar.experiments.ch3_figures import plot_all

    t0 = time.perf_counter()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    scene = _scene(pitch_deg, seed)
    cal, spur_map, static_frame, building = _static_phase(scene, n_static)
    track, stats, shown = _flyover(scene, cal, spur_map, n_frames, path)
    err = _errors(track, scene["geom"])
    det = track.detected.to_numpy()
    snr_ok = track.true_snr_db.to_numpy() >= 13.0
    sd_az, sd_el = doa_crlb(track.snr_db[det], track.true_az_rad[det], track.true_el_rad[det], cal)
    table = []
    for key, (m_raw, s_raw, m_hann, s_hann) in THESIS_TABLE.items():
        name = key.rsplit("_", 1)[0]
        raw, hann = (
            err[f"{name}_raw_{key.rsplit('_', 1)[1]}"][det],
            err[f"{name}_hann_{key.rsplit('_', 1)[1]}"][det],
        )
        table.append({"quantity": key, "raw_mean": raw.mean(), "raw_sd": raw.std(), "hann_mean": hann.mean(),
                      "hann_sd": hann.std(), "thesis_raw_mean": m_raw, "thesis_raw_sd": s_raw,
                      "thesis_hann_mean": m_hann, "thesis_hann_sd": s_hann})  # fmt: skip
    table = pd.DataFrame(table).set_index("quantity")
    result = {
        "az_sd_deg": table.loc["az_deg", "raw_sd"], "el_sd_deg": table.loc["el_deg", "raw_sd"],
        "az_mean_deg": table.loc["az_deg", "raw_mean"], "el_mean_deg": table.loc["el_deg", "raw_mean"],
        "az_hann_sd_deg": table.loc["az_deg", "hann_sd"], "el_hann_sd_deg": table.loc["el_deg", "hann_sd"],
        "az_sd_snr13_deg": float(err.az_raw_deg[det & snr_ok].std()),
        "el_sd_snr13_deg": float(err.el_raw_deg[det & snr_ok].std()),
        "az_crlb_deg": float(np.degrees(np.sqrt(np.mean(sd_az**2)))),
        "el_crlb_deg": float(np.degrees(np.sqrt(np.mean(sd_el**2)))),
        "dist_mean_m": table.loc["dist_m", "raw_mean"], "dist_sd_m": table.loc["dist_m", "raw_sd"],
        "dist_hann_mean_m": table.loc["dist_m", "hann_mean"],
        "dist_hann_sd_m": table.loc["dist_m", "hann_sd"],
        "calib_phase_err_deg": calibration_phase_error_deg(cal.rx_calibration, scene["true_gain"]),
        "detected_frames": int(det.sum()), "frames": n_frames,
        "detected_frames_snr13": int(det[snr_ok].sum()), "frames_snr13": int(snr_ok.sum()),
        "false_alarms_per_frame": stats["false_alarms"][("hits", SPUR_THRESHOLD)] / n_frames,
        "spur_threshold": SPUR_THRESHOLD, "spur_pixels": int(spur_map["hits"].mask.sum()), "path": path,
        "frame_interval_s": float(track.time_s.diff().median()) if n_frames > 1 else 0.0,
        "min_range_m": float(track.true_range_m.min()), "max_range_m": float(track.true_range_m.max()),
        **building,
    }  # fmt: skip
    for (kind, thr), n_fa in stats["false_alarms"].items():
        tag = f"{int(thr * 100)}pct" + ("" if kind == "hits" else "_corner_map")
        result[f"false_alarms_per_frame_{tag}"] = n_fa / n_frames
        result[f"detected_frames_{tag}"] = int(stats["detected"][(kind, thr)])
    write_table(table.reset_index(), out_dir / "ch3_table.parquet")
    table.to_csv(out_dir / "ch3_table.csv")
    write_table(
        pd.concat([track, err.drop(columns=["time_s", "true_snr_db"])], axis=1), out_dir / "ch3_track.parquet"
    )
    plot_all(out_dir, static_frame, cal, spur_map["hits"], shown, track, err, scene["geom"])
    result["runtime_s"] = time.perf_counter() - t0
    result = {k: (float(v) if isinstance(v, np.floating) else v) for k, v in result.items()}
    write_json_atomic(out_dir / "ch3.json", result)
    return result
