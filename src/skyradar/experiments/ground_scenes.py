"""Does the ground filter keep aircraft? Scored scenes over flat ground, hills and the Jacksboro DEM.

Each scene flies the own-ship level at 50 m/s over a terrain and puts three aircraft in front of it:
a glider circling (25 m/s) 150-300 m above the ground, a slow aircraft (25 m/s) crossing 250 m above
the ground, and a fast head-on intruder (70 m/s) at co-altitude. Frames come from
:class:`skyradar.sim.image.ImageSimulator`, detections from :func:`skyradar.process.pipeline.process_frames`
with the scene's terrain. The truth is the simulator's: a detection within two range bins and two
Doppler bins (aliased) of a visible aircraft is that aircraft's; every other detection is ground
clutter (the thermal false alarms at the CFAR's 2e-8 are a handful per run). Scored:

* ``ground_flagged``: fraction of ground clutter detections flagged ``is_ground`` (want high);
* ``aircraft_flagged``: fraction of aircraft detections flagged ``is_ground`` (want 0), per aircraft.

Run ``python -m skyradar.experiments.ground_scenes [n_frames] [n_seeds] [suppression]`` for the
table of every scene (defaults 20 frames 1 s apart, seeds 0 and 1, no suppression); the JSON of the
table is the last line.

Examples
--------
>>> sorted(SCENES)
['clear-sky', 'flat-1000', 'flat-300', 'hills', 'jacksboro']
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np
import pandas as pd

from skyradar.config import RadarConfig
from skyradar.geo import ned_to_geodetic
from skyradar.io.frames import frames_dataset
from skyradar.process.pipeline import process_frames
from skyradar.scene.dem_readers import jacksboro
from skyradar.scene.synthetic_terrain import flat_terrain, fractal_terrain
from skyradar.sim.image import ImageSimulator, PlatformState, PointTarget

__all__ = ["SCENES", "GroundScene", "scene_terrain", "simulate_scene", "score_scene", "ground_scores"]

_SPEED_MPS = 50.0
AIRCRAFT = ("glider", "slow", "head-on")


@dataclass(frozen=True)
class GroundScene:
    """Terrain kind and own-ship height above the ground under it at the start, m."""

    terrain: str
    height_agl_m: float


SCENES = {
    "clear-sky": GroundScene("none", 1000.0),
    "flat-300": GroundScene("flat", 300.0),
    "flat-1000": GroundScene("flat", 1000.0),
    "hills": GroundScene("fractal", 500.0),
    "jacksboro": GroundScene("jacksboro", 500.0),
}


def scene_terrain(kind: str, seed: int = 0):
    """(terrain or None, origin (lat, lon, alt)) of a scene's terrain kind; the origin is on the ground."""
    if kind == "jacksboro":
        t = jacksboro()
        lat, lon = t.center_latlon
        return t, (lat, lon, float(t.height_at(lat, lon)))
    origin = (36.59, -84.25, 0.0)
    if kind == "flat":
        return flat_terrain(origin[0], origin[1], 0.0, size_m=14000.0, spacing_m=60.0), origin
    if kind == "fractal":
        t = fractal_terrain(origin[0], origin[1], 60.0, size_m=14000.0, spacing_m=30.0, seed=seed)
        return t, (origin[0], origin[1], float(t.height_at(origin[0], origin[1])))
    return None, origin


def _aircraft(t: float, own: np.ndarray, ground_at, ahead_m: float = 2500.0) -> list[PointTarget]:
    """The glider, slow and head-on aircraft at time ``t`` (positions relative to the start)."""
    omega = 25.0 / 120.0  # 120 m radius at 25 m/s
    centre = np.array([ahead_m, -300.0])
    ang = omega * t
    g_ne = centre + 120.0 * np.array([np.cos(ang), np.sin(ang)])
    g_v = 25.0 * np.array([-np.sin(ang), np.cos(ang), 0.0])
    s_ne = np.array([0.8 * ahead_m, 600.0 - 25.0 * t])
    h_ne = np.array([1.4 * ahead_m - 70.0 * t, 60.0])
    glider_down = ground_at(g_ne) - (225.0 + 75.0 * np.sin(0.1 * t))  # 150-300 m above the ground
    return [
        PointTarget(np.array([*g_ne, glider_down]), g_v, 1.0),
        PointTarget(np.array([*s_ne, ground_at(s_ne) - 250.0]), np.array([0.0, -25.0, 0.0]), 3.0),
        PointTarget(np.array([*h_ne, own[2]]), np.array([-70.0, 0.0, 0.0]), 5.0),
    ]


def simulate_scene(
    scene: GroundScene, n_frames: int = 8, step_s: float = 2.0, seed: int = 0, ahead_m: float = 2500.0
):
    """Frames Dataset of a scene and the truth table of its aircraft (frame, name, range/doppler bin)."""
    cfg = RadarConfig.prototype_2022()
    terrain, origin = scene_terrain(scene.terrain, seed)

    def ground_down(ne: np.ndarray) -> float:
        if terrain is None:
            return 0.0
        lat, lon, _ = ned_to_geodetic(np.array([ne[0], ne[1], 0.0]), *origin)
        return origin[2] - float(terrain.height_at(lat, lon))

    sim = ImageSimulator(cfg, terrain, origin=origin, seed=seed)
    times = np.arange(n_frames) * step_s
    own = np.array([[_SPEED_MPS * t, 0.0, ground_down(np.zeros(2)) - scene.height_agl_m] for t in times])
    vel = np.array([_SPEED_MPS, 0.0, 0.0])
    cubes, truth = [], []
    for i, t in enumerate(times):
        platform = PlatformState(own[i], vel, np.zeros(3))
        targets = _aircraft(t, own[0], ground_down, ahead_m)
        cubes.append(sim.frame(platform, targets, i))
        g = sim.target_truth(platform, targets)
        keys = ("range_bin", "doppler_bin", "azimuth_rad", "elevation_rad")
        for c, name in enumerate(AIRCRAFT):
            row = {"frame": i, "name": name, "visible": bool(g["visible"][c])}
            truth.append(row | {key: g[key][c] for key in keys})
    lat, lon, alt = ned_to_geodetic(own, *origin)
    # Clear sky as a scenario without terrain stores it: the own-ship height above ground is unknown.
    agl = alt - terrain.height_at(lat, lon) if terrain is not None else np.full(n_frames, np.nan)
    ownship = {f"own_{a}_m": own[:, c] for c, a in enumerate(("north", "east", "down"))}
    ownship |= {f"own_{a}_mps": np.full(n_frames, vel[c]) for c, a in enumerate(("vn", "ve", "vd"))}
    ownship |= {"own_lat_deg": lat, "own_lon_deg": lon, "own_alt_m": alt, "own_height_agl_m": agl}
    attrs = {"origin_lat_deg": origin[0], "origin_lon_deg": origin[1], "origin_alt_m": origin[2]}
    ds = frames_dataset(np.stack(cubes), times, cfg, ownship=ownship, attrs=attrs)
    return ds, pd.DataFrame(truth), terrain


def score_scene(table: pd.DataFrame, truth: pd.DataFrame, n_doppler: int) -> dict:
    """Fractions flagged ground: of ground clutter detections and of each aircraft's detections.

    An aircraft's detection in a frame is the detection nearest its true (range, Doppler) bin
    within two bins whose direction is within 10 deg of the aircraft's (a ground return that
    shares the aircraft's range-Doppler cell is not the aircraft); other detections in the
    two-bin window are left out of both scores (ambiguous).
    """
    owner = np.full(len(table), "", object)
    frame, k, j = (table[c].to_numpy() for c in ("frame", "range_bin", "doppler_bin"))
    az, el = table.azimuth_rad.to_numpy(), table.elevation_rad.to_numpy()
    for row in truth[truth.visible].itertuples():
        wrapped = (j - row.doppler_bin) % n_doppler  # circular distance along the Doppler axis
        dj = np.minimum(wrapped, n_doppler - wrapped)
        near = (frame == row.frame) & (np.abs(k - row.range_bin) <= 2) & (np.abs(dj) <= 2)
        owner[near] = "ambiguous"
        pointing = np.hypot(az - row.azimuth_rad, el - row.elevation_rad) <= np.radians(10.0)
        if (near & pointing).any():
            dist = np.where(near & pointing, np.abs(k - row.range_bin) + np.abs(dj), np.inf)
            owner[int(np.argmin(dist))] = row.name
    flagged = table.is_ground.to_numpy()
    ground = owner == ""
    out: dict[str, float] = {"detections": len(table), "ground": int(ground.sum())}
    out["ground_flagged"] = float(flagged[ground].mean()) if ground.any() else float("nan")
    for name in AIRCRAFT:
        mine = owner == name
        out[f"{name}_detections"] = int(mine.sum())
        out[f"{name}_flagged"] = float(flagged[mine].mean()) if mine.any() else float("nan")
    return out


def ground_scores(
    names=tuple(SCENES), n_frames: int = 8, seeds=(0,), aheads_m=(1500.0, 3000.0), suppression: str = "none"
) -> pd.DataFrame:
    """One row of :func:`score_scene` per scene name, pooled over seeds and aircraft distances.

    ``suppression`` is passed to :func:`process_frames` (ground clutter suppression before detection).
    """
    rows = []
    for name in names:
        tables, truths = [], []
        for run, (seed, ahead) in enumerate((s, a) for s in seeds for a in aheads_m):
            ds, truth, terrain = simulate_scene(SCENES[name], n_frames, 20.0 / n_frames, seed, ahead)
            table = process_frames(ds, terrain=terrain, suppression=suppression)
            tables.append(table.assign(frame=table.frame + run * n_frames))
            truths.append(truth.assign(frame=truth.frame + run * n_frames))
        scores = score_scene(pd.concat(tables), pd.concat(truths), ds.sizes["doppler"])
        rows.append({"scene": name, **scores})
    return pd.DataFrame(rows)


if __name__ == "__main__":  # pragma: no cover - a measurement, not a library path
    import sys

    frames = int(sys.argv[1]) if len(sys.argv) > 1 else 20
    n_seeds = int(sys.argv[2]) if len(sys.argv) > 2 else 2
    suppression = sys.argv[3] if len(sys.argv) > 3 else "none"
    scores = ground_scores(n_frames=frames, seeds=tuple(range(n_seeds)), suppression=suppression)
    print(scores.to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    print(json.dumps(scores.to_dict(orient="records")))
