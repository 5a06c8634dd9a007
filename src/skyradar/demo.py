"""The end-to-end demo: one embedded scenario through simulate -> process -> track -> alert -> report.

The scenario (package data ``scenarios/demo_circuit.yaml``) flies own-ship on a left-hand circuit over
seeded fractal terrain with three intruders: ``collision`` (converging, zero miss at t = 40 s),
``fast-jet`` (head-on, its closing speed aliases in Doppler; a near miss that stays outside the
warning volume) and ``glider`` (well clear). The chain:

1. :func:`skyradar.sim.scenario_frames.simulate_frames` in blocks (the whole cube would be ~750 MB);
2. :func:`skyradar.process.pipeline.process_frames` on each block (detections, DoA, ground flags);
3. :func:`skyradar.track.track_table.track_detections` on the detections that are neither ground nor spur,
   with the own-ship state (3-D tracks with covariance and a ``confirmed`` flag);
4. :func:`skyradar.daa.pipeline.alerts_from_tracks` on the confirmed 3-D tracks, with
   :data:`DEMO_ALERT_CONFIG` (default volumes and times plus a velocity-convergence gate);
5. :func:`skyradar.viz.report.write_report`: figures and ``index.html``.
"""

from __future__ import annotations

import time
from importlib.resources import files
from pathlib import Path
from typing import Any

import pandas as pd

from skyradar.chain import label_tracks
from skyradar.chain import run_chain as _run_chain
from skyradar.daa.alerting import RADAR_ALERT_CONFIG
from skyradar.errors import InputError
from skyradar.io.atomic import write_csv_atomic
from skyradar.io.json_results import write_json_atomic
from skyradar.io.tables import write_table
from skyradar.scene.scenario import load_scenario

__all__ = [
    "DEMO_SCENARIO",
    "DEMO_ALERT_CONFIG",
    "LEVEL_NAMES",
    "demo_scenario_path",
    "run_chain",
    "label_tracks",
    "alert_timeline",
    "run_demo",
]

DEMO_SCENARIO = "demo_circuit.yaml"
# Default DO-365-style volumes and times with the radar settings (2 of 4 s persistence, a 6 m/s
# velocity-convergence gate): far DoA tracks converge slowly and their covariance would widen the
# warning volume to kilometres.
DEMO_ALERT_CONFIG = RADAR_ALERT_CONFIG
LEVEL_NAMES = {0: "none", 1: "preventive", 2: "corrective", 3: "WARNING"}


def demo_scenario_path() -> Path:
    """Path of the embedded demo scenario (package data).

    Returns
    -------
    Path
        ``scenarios/demo_circuit.yaml`` inside the installed package.

    Examples
    --------
    >>> path = demo_scenario_path()
    >>> path.name, [i.name for i in load_scenario(path).model.intruders]
    ('demo_circuit.yaml', ['collision', 'fast-jet', 'glider'])
    """
    return Path(str(files("skyradar") / "data" / "scenarios" / DEMO_SCENARIO))


def run_chain(built, keep_frames: tuple[int, ...] = ()) -> dict[str, Any]:
    """:func:`skyradar.chain.run_chain` with :data:`DEMO_ALERT_CONFIG`."""
    return _run_chain(built, DEMO_ALERT_CONFIG, keep_frames)


def alert_timeline(alerts: pd.DataFrame, labels: dict[int, str]) -> pd.DataFrame:
    """One row per change of a track's issued alert level (the first row of each track included).

    Columns ``time_s, track_id, intruder, level, level_name, range_m, bearing_deg, rel_alt_m,
    time_to_impact_s, preferred_heading_deg, preferred_vs_mps, altitude_measured`` (those the alerts
    have).

    Parameters
    ----------
    alerts : DataFrame
        The alerts table: one row per track per frame, with ``time_s`` (s), ``track_id``, ``level``,
        ``range_m`` (m), ``bearing_deg``, ``rel_alt_m`` (m) and ``time_to_impact_s`` (s).
    labels : dict of int to str
        Intruder name per track id (:func:`skyradar.chain.label_tracks`); other tracks are ``clutter``.

    Returns
    -------
    DataFrame
        The level changes in time order; a track that never alerts has no rows.

    Examples
    --------
    Track 1 rises from none to preventive to warning and stays; track 2 never alerts:

    >>> alerts = pd.DataFrame({"time_s": [0.0, 1.0, 2.0, 3.0, 1.0, 2.0], "track_id": [1, 1, 1, 1, 2, 2],
    ...     "level": [0, 1, 3, 3, 0, 0], "range_m": 900.0, "bearing_deg": 0.0, "rel_alt_m": 0.0,
    ...     "time_to_impact_s": 20.0})
    >>> alert_timeline(alerts, {1: "collision"})[["time_s", "intruder", "level_name"]].values.tolist()
    [[1.0, 'collision', 'preventive'], [2.0, 'collision', 'WARNING']]
    """
    cols = ["time_s", "track_id", "level", "range_m", "bearing_deg", "rel_alt_m", "time_to_impact_s"]
    cols += [c for c in ("preferred_heading_deg", "preferred_vs_mps", "altitude_measured") if c in alerts]
    a = alerts.sort_values(["track_id", "time_s"], kind="stable")
    change = a["level"].ne(a.groupby("track_id")["level"].shift())
    out = a.loc[change & (a["level"].gt(0) | a.groupby("track_id")["level"].shift().gt(0)), cols]
    out = out.sort_values(["time_s", "track_id"], kind="stable").reset_index(drop=True)
    out.insert(2, "intruder", [labels.get(int(t), "clutter") for t in out["track_id"]])
    out.insert(4, "level_name", [LEVEL_NAMES.get(int(v), str(v)) for v in out["level"]])
    return out


def _summary(chain: dict[str, Any], labels: dict[int, str], timeline: pd.DataFrame) -> dict[str, Any]:
    alerts, det = chain["alerts"], chain["detections"]
    names = [str(x) for x in chain["truth"]["target"].values]
    max_level = alerts.groupby("track_id")["level"].max() if len(alerts) else pd.Series(dtype=int)
    per: dict[str, dict[str, Any]] = {}
    for name in names + ["clutter"]:
        ids = [t for t, lab in labels.items() if lab == name]
        lv = max_level.reindex(ids).fillna(0)
        warn = alerts[alerts["track_id"].isin(ids) & (alerts["level"] >= 3)]["time_s"]
        per[name] = {
            "tracks": len(ids),
            "max_level": int(lv.max()) if len(lv) else 0,
            "first_warning_s": float(warn.min()) if len(warn) else None,
        }
    others_warn = any(v["max_level"] >= 3 for k, v in per.items() if k != "collision")
    return {
        "scenario": DEMO_SCENARIO,
        "frames": int(chain["truth"].sizes["time"]),
        "detections": len(det),
        "detections_ground": int(det["is_ground"].sum()),
        "detections_spur": int(det["spur"].sum()),
        "tracks": int(chain["tracks"]["track_id"].nunique()),
        "intruders": per,
        "alert_changes": len(timeline),
        "acceptance": bool(per.get("collision", {}).get("max_level", 0) >= 3 and not others_warn),
        "timings_s": {k: round(v, 2) for k, v in chain["timings_s"].items()},
    }


def run_demo(out_dir: Path, scenario: str | Path | None = None) -> dict[str, Any]:
    """Run the demo chain and write the report folder ``out_dir``.

    Writes ``index.html`` and its PNG figures, ``detections.parquet``, ``tracks.parquet``,
    ``alerts.parquet``, ``alert_timeline.csv`` and ``summary.json``.

    Returns
    -------
    dict
        Summary: frames, detections (ground/spur), tracks, per intruder (and ``clutter``) the
        number of tracks, highest issued alert level and first warning time, ``acceptance`` (warning
        for the collision intruder, none for anything else), stage timings and ``runtime_s``.
    """
    from skyradar.viz.report import write_report

    t_start = time.perf_counter()
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise InputError(f"{out_dir}: --output must be a directory, this is a file")
    out_dir.mkdir(parents=True, exist_ok=True)
    built = load_scenario(scenario or demo_scenario_path()).build()
    rd_frame = built.times_s.size // 2  # mid-run: the collision intruder is tracked then
    chain = run_chain(built, keep_frames=(rd_frame,))
    labels = label_tracks(chain["tracks"], chain["truth"])
    timeline = alert_timeline(chain["alerts"], labels)
    summary = _summary(chain, labels, timeline)
    write_table(chain["detections"], out_dir / "detections.parquet")
    write_table(chain["tracks"], out_dir / "tracks.parquet")
    write_table(chain["alerts"], out_dir / "alerts.parquet")
    write_csv_atomic(timeline, out_dir / "alert_timeline.csv", index=False)
    write_report(out_dir, chain, labels, timeline, summary, rd_frame)
    summary["runtime_s"] = round(time.perf_counter() - t_start, 1)
    write_json_atomic(out_dir / "summary.json", summary)
    return summary
