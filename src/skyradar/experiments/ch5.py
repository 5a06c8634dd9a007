"""ch5: own-ship flight state from ground returns over terrains of increasing roughness.

One terrain-following flight (radar forward-down, 55 m/s so the far ground aliases, mean height
700 m above ground on every terrain) over flat ground, fractal terrains with local height SD
19.2, 39.9, 63.6, 251.2 and 345.0 m, and matplotlib's Jacksboro DEM, at one frame per second
as in the thesis; the flat and 19.2 m cases also at the 9.4 Hz field rate. Frames come from
:class:`skyradar.sim.image.ImageSimulator` (facets of ``facet_size_m``, default 10 m: coarser
than its 7.5 m default to fit the time budget). Three methods, each followed by the Kalman
filter of :mod:`skyradar.nav.kalman_state`:

- ``thesis``: bin-centre ridge, algebraic least squares, the thesis' 150 m GPS gate;
- ``robust``: bin-edge ridge with coupling removed, RANSAC + Huber fit, GPS-free gating;
- ``terrain``: DoA ground points and terrain memory (:mod:`skyradar.nav.terrain_aware`).

Errors are filtered estimate minus truth after a ``warmup_s`` start (the filter converging);
``h`` is the height of the own-ship reference point above the terrain directly below.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from skyradar.config import Mount, RadarConfig
from skyradar.experiments.ch5_flight import Flight, terrain_following_flight
from skyradar.io.tables import write_json_atomic, write_table
from skyradar.nav.flight_state import estimate_frame, filter_table, mount_height_offset_m
from skyradar.nav.kalman_state import KalmanSettings
from skyradar.nav.ridge import extract_ridge
from skyradar.nav.terrain_aware import TerrainAwareEstimator

__all__ = ["TERRAINS", "THESIS_TABLE", "run"]

# name -> local height SD (m); None = the real DEM.
TERRAINS: dict[str, float | None] = {
    "flat": 0.0,
    "sd19": 19.2,
    "sd40": 39.9,
    "sd64": 63.6,
    "sd251": 251.2,
    "sd345": 345.0,
    "jacksboro": None,
}
# seed-brief.md ch5: height error mean / SD [m] of the thesis, one frame per second.
THESIS_TABLE = {
    "flat": (8.5, 6.5),
    "sd19": (10.3, 13.1),
    "sd40": (11.3, 35.8),
    "sd64": (20.4, 70.5),
    "sd251": (130.0, 451.1),
    "sd345": (381.7, 821.6),
}
METHODS = ("thesis", "robust", "terrain")
FILTERS = {
    "thesis": KalmanSettings(gps_gate_m=150.0),
    "robust": KalmanSettings(),
    # The terrain-aware height follows the relief underneath: let the filter follow it too.
    "terrain": KalmanSettings(terrain_psd=400.0),
}


def _terrain(name: str, size_m: float, seed: int):
    from skyradar.scene.terrain import flat_terrain, fractal_terrain, jacksboro

    sd = TERRAINS[name]
    if sd is None:
        return jacksboro()
    if sd == 0.0:
        return flat_terrain(52.0, 5.0, 0.0, size_m=size_m)
    return fractal_terrain(52.0, 5.0, sd, size_m=size_m, seed=seed)


def _raw_row(fit_like, quality: float, low: bool, h_offset: float) -> dict[str, float]:
    return {
        "vx_raw_mps": fit_like.vx_mps,
        "vz_raw_mps": fit_like.vz_mps,
        "h_raw_m": fit_like.h_m + h_offset,
        "vx_raw_sd_mps": fit_like.vx_sd_mps,
        "vz_raw_sd_mps": fit_like.vz_sd_mps,
        "h_raw_sd_m": fit_like.h_sd_m,
        "quality": quality,
        "low_quality": low,
    }


def _fly(
    terrain, flight: Flight, config: RadarConfig, facet_size_m: float, seed: int
) -> dict[str, pd.DataFrame]:
    """Simulate the flight and run the three per-frame estimators; returns raw tables per method."""
    from skyradar.sim.image import ImageSimulator

    lat0, lon0 = terrain.center_latlon
    sim = ImageSimulator(config, terrain, origin=(lat0, lon0, 0.0), facet_size_m=facet_size_m, seed=seed)
    aware = TerrainAwareEstimator(config)
    rows: dict[str, list] = {m: [] for m in METHODS}
    prior = None
    for i, (t, state) in enumerate(zip(flight.times_s, flight.states, strict=True)):
        cube = sim.frame(state, frame_index=i)
        offset = mount_height_offset_m(config, *flight.attitude_rad[i, 1:])
        # One ridge per frame serves all three methods (the thesis one uses bin-centre ranges).
        ridge = extract_ridge(cube, config, prior_state=prior)
        for method in ("thesis", "robust"):
            est = estimate_frame(cube, config, method=method, ridge=ridge, prior_state=prior)
            if method == "robust" and est.fit.ok:
                prior = (est.fit.vx_mps, est.fit.vz_mps, est.fit.h_m)
            rows[method].append({"time_s": t, **_raw_row(est.fit, est.quality, est.low_quality, offset)})
        ta = aware.update(t, cube, flight.attitude_rad[i], ridge=ridge)
        rows["terrain"].append({"time_s": t, **_raw_row(ta, ta.quality, ta.low_quality, offset)})
    return {m: pd.DataFrame(r) for m, r in rows.items()}


def _stat(values: np.ndarray, fn) -> float:
    finite = values[np.isfinite(values)]
    return float(fn(finite)) if finite.size else float("nan")


def _errors(table: pd.DataFrame, flight: Flight, warmup_s: float) -> dict[str, float]:
    keep = (flight.times_s - flight.times_s[0]) >= warmup_s
    out: dict[str, float] = {}
    for tag, suffix in (("", ""), ("raw_", "_raw")):
        h_err = table[f"h{suffix}_m"].to_numpy() - flight.height_agl_m
        vx_err = table[f"vx{suffix}_mps"].to_numpy() - flight.vx_mps
        vz_err = table[f"vz{suffix}_mps"].to_numpy() - flight.vz_mps
        out[f"{tag}h_err_mean_m"] = _stat(h_err[keep], np.mean)
        out[f"{tag}h_err_sd_m"] = _stat(h_err[keep], np.std)
        out[f"{tag}vx_err_sd_mps"] = _stat(vx_err[keep], np.std)
        out[f"{tag}vz_err_sd_mps"] = _stat(vz_err[keep], np.std)
    out["valid_fraction"] = float(np.mean(np.isfinite(table["h_raw_m"].to_numpy()[keep])))
    return out


def _case(name, rate_hz, duration_s, config, facet_size_m, seed, warmup_s, terrain_cache):
    terrain = terrain_cache.setdefault(name, _terrain(name, 16_000.0, seed))
    times = np.arange(0.0, duration_s + 1e-9, 1.0 / rate_hz)
    flight = terrain_following_flight(
        terrain, (*terrain.center_latlon, 0.0), times, height_m=700.0, smooth_m=800.0
    )
    raw = _fly(terrain, flight, config, facet_size_m, seed)
    tables, result = {}, {}
    for method, table in raw.items():
        ref = flight.height_agl_m if FILTERS[method].gps_gate_m is not None else None
        tables[method] = filter_table(table, FILTERS[method], ref)
        result[method] = _errors(tables[method], flight, warmup_s)
    return flight, tables, result


def run(
    out_dir: Path,
    duration_s: float = 40.0,
    fast_duration_s: float = 6.0,
    terrains: tuple[str, ...] = tuple(TERRAINS),
    fast_terrains: tuple[str, ...] = ("flat", "sd19"),
    facet_size_m: float = 10.0,
    warmup_s: float = 5.0,
    seed: int = 5,
) -> dict[str, Any]:
    """Run the ch5 experiment; writes ``ch5_table.csv``, ``ch5.json``, states and figures to ``out_dir``."""
    from skyradar.experiments.ch5_report import plot_case, summary_table

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    t_start = time.perf_counter()
    config = RadarConfig.seed_prototype(mount=Mount.preset("forward-down"))
    cache: dict[str, Any] = {}
    results: dict[str, Any] = {"rate_1hz": {}, "rate_9p4hz": {}}
    cases = [(n, 1.0, duration_s, "rate_1hz") for n in terrains]
    cases += [(n, 9.4, fast_duration_s, "rate_9p4hz") for n in fast_terrains if fast_duration_s > 0]
    for name, rate, dur, key in cases:
        flight, tables, res = _case(name, rate, dur, config, facet_size_m, seed, warmup_s, cache)
        results[key][name] = res
        tag = f"{name}_{key}"
        for method, table in tables.items():
            table = table.assign(
                truth_h_m=flight.height_agl_m, truth_vx_mps=flight.vx_mps, truth_vz_mps=flight.vz_mps
            )
            write_table(table, out_dir / f"state_{tag}_{method}.parquet")
        plot_case(out_dir / f"ch5_{tag}.png", flight, tables, f"{name} at {rate:g} Hz")
    table = summary_table(results, THESIS_TABLE)
    table.to_csv(out_dir / "ch5_table.csv", index=False)
    results.update(
        {
            "table": table.to_dict(orient="records"),
            "thesis_table": {
                k: {"h_err_mean_m": m, "h_err_sd_m": s} for k, s_m in THESIS_TABLE.items() for m, s in [s_m]
            },
            "facet_size_m": facet_size_m,
            "duration_s": duration_s,
            "runtime_s": time.perf_counter() - t_start,
        }
    )
    write_json_atomic(out_dir / "ch5.json", _finite_or_none(results))
    return results


def _finite_or_none(value: Any) -> Any:
    """NaN (no valid frame) becomes null: strict JSON."""
    if isinstance(value, dict):
        return {k: _finite_or_none(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_finite_or_none(v) for v in value]
    if isinstance(value, float) and not np.isfinite(value):
        return None
    return value
