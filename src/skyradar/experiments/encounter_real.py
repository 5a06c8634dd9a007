"""The real-flight encounter family: recorded own-ship and intruder flights, moved to meet.

Every synthetic encounter flies smooth parametric paths, which hides what real motion does to the
chain. Here the own-ship is a stretch of a real recorded flight (the survey and calibration flights
that ship inside the ``traffic`` package, :mod:`skyradar.scene.sample_flights`) and the intruder a
stretch of another (a glider thermalling, or another GA flight), both built into flyable paths from
their fixes (:func:`skyradar.scene.adsb.read_trajectory`), the intruder turned and moved in time
and space to pass at a drawn miss distance
(:func:`skyradar.scene.encounter_from_tracks.encounter_from_tracks`).
The misses follow the synthetic set's distribution (a third inside the DO-365 volume, the rest
near misses out to three times it). The pair is placed over the terrain of the set at its site's
altitude, written as two flight files and flown by a scenario that reads them as a user's would,
then scored as the synthetic set is, plus whether each warning is held to the closest approach.
"""

from __future__ import annotations

import tempfile
from functools import lru_cache
from pathlib import Path
from typing import Any, Literal

import numpy as np
import pandas as pd

from skyradar.daa.alerting import RADAR_ALERT_CONFIG, AlertConfig
from skyradar.daa.conflict import WellClearVolume
from skyradar.errors import InputError
from skyradar.experiments.encounter_chain import FRAME_RATE_HZ, chain_rows
from skyradar.experiments.encounter_set import T_CPA_S, event_times
from skyradar.experiments.encounter_terrain import mirror_below_ground, own_altitude_m, site
from skyradar.io.atomic import write_csv_atomic
from skyradar.scene.adsb import fit_flight
from skyradar.scene.encounter_from_tracks import encounter_from_tracks, horizontal_cpa, trajectory_table
from skyradar.scene.sample_flights import sample_flight
from skyradar.scene.scenario import Scenario
from skyradar.scene.trajectories import Trajectory

__all__ = ["OWN_FLIGHTS", "INTRUDER_FLIGHTS", "make_real_encounters", "real_pair", "run_real_encounter"]

# Own-ships: GA survey and calibration flights at GA speeds. Intruders: gliders and GA flights.
OWN_FLIGHTS = (
    "surveys/liguria",
    "surveys/mecsek_mountains",
    "surveys/pixair_toulouse",
    "calibration/cardiff",
)
INTRUDER_FLIGHTS = (
    ("gliders/cevennes", "glider"),
    ("gliders/luberon", "glider"),
    ("gliders/oxford_cambridge", "glider"),
    ("gliders/sisteron", "glider"),
    ("surveys/liguria", "ga"),
    ("calibration/cardiff", "ga"),
)
_BEFORE_S, _AFTER_S = T_CPA_S, 10.0  # the stretch of each flight around its meeting time, s
# A table's side of the intruder, as encounter_from_tracks takes it.
_SIDES: dict[str, Literal["right", "left"]] = {"right": "right", "left": "left"}
_OWN_SPEED_MPS = (35.0, 90.0)  # a GA own-ship's speeds over the stretch
_INTRUDER_SPEED_MPS = (15.0, 90.0)
_MAX_FIX_GAP_S = 20.0  # a stretch whose fixes leave a longer gap is a guess there, not a recording
_CANDIDATE_STEP_S = 10.0
_CPA_TOLERANCE_S = 10.0
_MAX_DRAWS = 50


@lru_cache(maxsize=16)
def _flight(name: str, aircraft_class: str):
    """A sample flight's built path and fixes (cached per process: a set reads each a few times)."""
    fit = fit_flight(sample_flight(name), aircraft_class)
    return fit.trajectory.shifted(-fit.trajectory.start_s), fit.fix_time_s - fit.fix_time_s[0]


@lru_cache(maxsize=16)
def _meeting_times(name: str, aircraft_class: str, speeds: tuple[float, float]) -> np.ndarray:
    """Times of a flight (s from its start) whose stretch around them is flown within ``speeds`` and
    covered by fixes without a long gap."""
    traj, fixes = _flight(name, aircraft_class)
    candidates = np.arange(traj.start_s + _BEFORE_S, traj.end_s - _AFTER_S, _CANDIDATE_STEP_S)
    good = []
    for t in candidates:
        grid = np.arange(t - _BEFORE_S, t + _AFTER_S, 1.0)
        speed = np.linalg.norm(traj.sample(grid).velocity_ned_mps, axis=1)
        inside = fixes[(fixes >= t - _BEFORE_S) & (fixes <= t + _AFTER_S)]
        gaps = np.diff(np.concatenate([[t - _BEFORE_S], inside, [t + _AFTER_S]]))
        if speeds[0] <= speed.min() and speed.max() <= speeds[1] and gaps.max() <= _MAX_FIX_GAP_S:
            good.append(t)
    return np.array(good)


def make_real_encounters(n: int, seed: int = 0) -> pd.DataFrame:
    """``n`` real-flight encounters: which flights meet, when, and at what miss; seeded.

    Columns: ``kind`` ("real"), ``own_flight``, ``own_time_s``, ``intruder_flight``,
    ``intruder_class``, ``intruder_time_s`` (each flight's time, s from its start, that is moved to
    the closest approach), ``horizontal_miss_m``, ``vertical_miss_m``, ``rotate_deg`` (the
    intruder's flight turned about the vertical), ``side``, ``rcs_m2``.

    Real flights turn: moved to pass at a miss at ``T_CPA_S``, two of them may come closer at
    another time. An encounter is what its closest approach is, so a draw whose closest approach
    is more than :data:`_CPA_TOLERANCE_S` from ``T_CPA_S`` (where the frame window cannot hold the
    approach to it) is drawn again.
    """
    rng = np.random.default_rng(seed)
    vol = WellClearVolume.do365_noncoop()
    rows = []
    for k in range(n):
        own = OWN_FLIGHTS[k % len(OWN_FLIGHTS)]
        inside = rng.random() < 1 / 3  # a third inside the volume, the rest near misses out to 3x it
        h = rng.uniform(0, 0.9 * vol.dthr_m) if inside else rng.uniform(0, 3.0 * vol.dthr_m)
        v = rng.uniform(0, 0.9 * vol.zthr_m) if inside else rng.uniform(0, 3.0 * vol.zthr_m)
        if not inside and rng.random() < 0.5:
            v = rng.uniform(0, 0.9 * vol.zthr_m)
        for _draw in range(_MAX_DRAWS):
            intruder, klass = INTRUDER_FLIGHTS[rng.integers(len(INTRUDER_FLIGHTS))]
            row = {
                "kind": "real",
                "own_flight": own,
                "own_time_s": float(rng.choice(_meeting_times(own, "ga", _OWN_SPEED_MPS))),
                "intruder_flight": intruder,
                "intruder_class": klass,
                "intruder_time_s": float(rng.choice(_meeting_times(intruder, klass, _INTRUDER_SPEED_MPS))),
                "horizontal_miss_m": float(max(h, 1.0)),
                "vertical_miss_m": float(v * rng.choice([-1.0, 1.0])),
                "rotate_deg": float(rng.uniform(0.0, 360.0)),
                "side": str(rng.choice(["left", "right"])),
                "rcs_m2": float(np.exp(rng.uniform(np.log(1.0), np.log(5.0)))),
            }
            own_path, intruder_path = real_pair(pd.Series(row))
            t_cpa, _h, _v = horizontal_cpa(own_path, intruder_path, window=(0.0, T_CPA_S + _AFTER_S))
            if abs(t_cpa - T_CPA_S) <= _CPA_TOLERANCE_S:
                break
        else:
            raise InputError(f"real-flight encounter {k}: no draw of {_MAX_DRAWS} meets near {T_CPA_S:g} s")
        rows.append(row)
    return pd.DataFrame(rows)


def real_pair(p: pd.Series) -> tuple[Trajectory, Trajectory]:
    """(own-ship, intruder) of one row, in the NED frame of the own-ship's closest-approach point,
    the closest approach at ``T_CPA_S``."""
    own, _ = _flight(str(p["own_flight"]), "ga")
    intruder, _ = _flight(str(p["intruder_flight"]), str(p["intruder_class"]))
    t_own, t_int = float(p["own_time_s"]), float(p["intruder_time_s"])
    own = own.between(t_own - _BEFORE_S, t_own + _AFTER_S).shifted(T_CPA_S - t_own)
    intruder = intruder.between(t_int - _BEFORE_S - 5.0, t_int + _AFTER_S + 5.0)
    miss = (float(p["horizontal_miss_m"]), float(p["vertical_miss_m"]))
    side = _SIDES.get(str(p["side"]))
    if side is None:
        raise InputError(f"real-flight encounter: side must be 'right' or 'left', got {p['side']!r}")
    return encounter_from_tracks(
        own,
        intruder,
        T_CPA_S,
        *miss,
        intruder_time_s=t_int,
        rotate_deg=float(p["rotate_deg"]),
        side=side,
    )


def _placed(traj: Trajectory, origin: dict, down_m: float) -> Trajectory:
    """The same motion at the set's site: NED positions kept, ``down_m`` added, the site's origin."""
    return Trajectory.from_states(
        traj.time_s,
        traj.position_ned_m + [0.0, 0.0, down_m],
        traj.velocity_ned_mps,
        origin=(origin["lat_deg"], origin["lon_deg"], origin["alt_m"]),
        name=traj.name,
    )


def _spec(p, where, folder: Path, own, intruder, start, duration, frame_rate_hz, seed, radars, navigation):
    write_csv_atomic(trajectory_table(own), folder / "own.csv", index=False)
    write_csv_atomic(trajectory_table(intruder), folder / "intruder.csv", index=False)
    spec = {
        "name": f"real: {p['own_flight']} meets {p['intruder_flight']}",
        "origin": where["origin"],
        "ownship": {"type": "file", "path": str(folder / "own.csv"), "time_zero_s": 0.0},
        "intruders": [
            {
                "name": "intruder",
                "type": "file",
                "path": str(folder / "intruder.csv"),
                "time_zero_s": 0.0,
                "aircraft_class": str(p["intruder_class"]),
                "rcs_m2": float(p["rcs_m2"]),
            }
        ],
        "frame_rate_hz": frame_rate_hz,
        "start_s": float(start),
        "duration_s": float(duration),
        "simulation": {"noise": True, "seed": int(seed), "psf": True, "speckle": True, "swerling": 1},
    }
    if radars is None:
        spec["mount"] = "forward"
    else:
        spec["radars"] = [dict(r) for r in radars]
    if navigation is not None:
        spec["navigation"] = navigation
    if where["terrain"] is not None:
        spec["terrain"] = where["terrain"]
    return spec


def run_real_encounter(
    p: pd.Series,
    seed: int = 0,
    frame_rate_hz: float = FRAME_RATE_HZ,
    lookback_s: float = 40.0,
    buffer: float = 1.5,
    fov_deg: float = 70.0,
    min_snr_db: float = 13.0,
    observe_window_s: float = 12.5,
    alert_config: AlertConfig | None = None,
    terrain: str | None = None,
    layouts: tuple[str, ...] = ("single",),
    navigation: str | dict | None = None,
    **_ignored: Any,
) -> list[dict[str, Any]]:
    """One real-flight encounter through the full chain; one result row per layout (as
    :func:`skyradar.experiments.encounter_chain.run_encounter`)."""
    from skyradar.scene.examples import THREE_HEAD_RADARS

    cfg = alert_config or RADAR_ALERT_CONFIG
    own, intruder = real_pair(p)
    where = site(terrain, seed)
    t = np.arange(own.start_s, min(own.end_s, intruder.end_s), 0.05)
    t = t[t >= intruder.start_s]
    rel = intruder.sample(t).position_ned_m - own.sample(t).position_ned_m
    t_lowc, t_cpa = event_times(t, rel)
    t_event = t_lowc if np.isfinite(t_lowc) else t_cpa
    start = max(t_event - lookback_s, float(t[0]))
    duration = min(t_event + 2.0, float(t[-1])) - start
    alt = where["own_altitude_m"]
    radars = THREE_HEAD_RADARS if "three-head" in layouts else None
    with tempfile.TemporaryDirectory(prefix="skyradar-real-") as tmp:
        folder = Path(tmp)
        args = (start, duration, frame_rate_hz, seed, radars, navigation)
        if where["terrain"] is not None and terrain in ("hills", "jacksboro"):
            # The own-ship's altitude from the ground under its track, as the synthetic set does.
            first = _spec(
                p,
                where,
                folder,
                _placed(own, where["origin"], -alt),
                _placed(intruder, where["origin"], -alt),
                *args,
            )
            ground = Scenario.from_dict(first).build().terrain
            times = np.linspace(start, start + duration, 64)
            s_own = _placed(own, where["origin"], -alt).sample(times)
            alt = own_altitude_m(ground.height_at(s_own.lat_deg, s_own.lon_deg))
        own_at, intruder_at = _placed(own, where["origin"], -alt), _placed(intruder, where["origin"], -alt)
        mirrored = False
        if where["terrain"] is not None:
            built0 = Scenario.from_dict(_spec(p, where, folder, own_at, intruder_at, *args)).build()
            times = np.linspace(start, start + duration, 64)
            s_int = intruder_at.sample(times)
            ground_int = built0.terrain.height_at(s_int.lat_deg, s_int.lon_deg)
            if mirror_below_ground(s_int.alt_m, ground_int, alt):  # the intruder's mirror image above
                mirrored = True
                flipped = intruder.position_ned_m * [1.0, 1.0, -1.0]
                intruder = Trajectory.from_states(
                    intruder.time_s,
                    flipped,
                    intruder.velocity_ned_mps * [1.0, 1.0, -1.0],
                    origin=intruder.origin,
                    name=intruder.name,
                )
                intruder_at = _placed(intruder, where["origin"], -alt)
                rel = rel * [1.0, 1.0, -1.0]
        built = Scenario.from_dict(_spec(p, where, folder, own_at, intruder_at, *args)).build()
    shared = {
        "frames": int(built.times_s.size),
        "t_start_s": start,
        "flight_s": float(duration),
        "mirrored": mirrored,
        "vertical_miss_flown_m": float(-rel[np.argmin(np.linalg.norm(rel, axis=1)), 2]),
        "own_altitude_m": float(alt),
    }
    opts = {
        "fov_deg": fov_deg,
        "min_snr_db": min_snr_db,
        "observe_window_s": observe_window_s,
        "buffer": buffer,
    }
    return chain_rows(built, t, rel, shared, layouts, cfg, opts)
