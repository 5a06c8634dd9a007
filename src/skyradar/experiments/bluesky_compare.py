"""BlueSky's perfect-state conflict detection against skyradar's radar, on one BlueSky scenario.

:func:`run` plays a BlueSky scenario file (default: the packaged ``skyradar_demo.scn``, see
:func:`demo_scenario`) twice, headless, with the skyradar plugin
(:func:`skyradar.integrations.bluesky.runner.run_scenario`):

- ``truth``: every aircraft's conflict detection and resolution see the true states (BlueSky alone);
- ``radar``: the radar-equipped aircraft's see their radar's tracks.

Detection is compared on the radar run, where both are known for the same states at every
conflict-detection step: for each radar-equipped aircraft and each other aircraft, the first time
BlueSky's detection on the true states finds a conflict and the first time the radar's tracks give
it (:func:`detection_table`). A pair is *found* when both do, *missed* when only the truth does,
*false* when only the radar does; conflicts with false tracks (no aircraft near them) are counted
apart. Losses of separation and the closest approach of every pair come from each run's states
(:func:`separation_table`): what the two kinds of surveillance led the resolution to.

Writes ``conflicts.csv`` (one row per radar-equipped aircraft and other aircraft),
``separation.csv`` (one row per pair of aircraft and run), ``summary.json``, ``bluesky.png`` (the
flights of both runs and the conflict timelines) and ``bluesky.log`` (BlueSky's messages) into the
output folder.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from importlib import resources
from itertools import combinations
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from skyradar.code_version import code_version, provenance
from skyradar.geo import geodetic_to_ned
from skyradar.io.atomic import savefig_atomic, write_csv_atomic, write_text_atomic
from skyradar.io.json_results import write_json_atomic

__all__ = ["demo_scenario", "detection_table", "separation_table", "run", "plot"]

_FT = 0.3048  # metres per foot
_NM = 1852.0  # metres per nautical mile


def demo_scenario() -> Path:
    """The packaged BlueSky scenario ``skyradar_demo.scn`` (radar-equipped light aircraft over hills)."""
    return Path(str(resources.files("skyradar") / "data" / "bluesky" / "skyradar_demo.scn"))


def _intervals(times: list[float], step_s: float) -> list[tuple[float, float]]:
    """Runs of consecutive detection steps as (start, end) times, s."""
    out: list[list[float]] = []
    for t in times:
        if out and t - out[-1][1] <= 1.5 * step_s:
            out[-1][1] = t
        else:
            out.append([t, t])
    return [(a, b) for a, b in out]


def detection_table(records: list[Any]) -> pd.DataFrame:
    """Per radar-equipped aircraft and other aircraft: when each surveillance first saw a conflict.

    Parameters
    ----------
    records : list of DetectionRecord
        The radar run's conflict-detection steps (:attr:`BlueSkyRun.detections`).

    Returns
    -------
    DataFrame
        ``ownship, intruder, truth_first_s, radar_first_s, delay_s`` (radar minus truth, s),
        ``truth_steps, radar_steps`` (detection steps in conflict), ``tracked_first_s`` (first step the
        radar had a confirmed track on the intruder) and ``outcome`` (found, missed, false); pairs
        neither found are left out.

    Examples
    --------
    >>> from skyradar.integrations.bluesky.plugin import DetectionRecord
    >>> r = [DetectionRecord(float(t), frozenset({("A", "B")}), frozenset({("A", "B")} if t > 2 else set()),
    ...      frozenset(), ("A",), {"A": ("B",) if t > 1 else ()}) for t in range(5)]
    >>> columns = ["ownship", "intruder", "truth_first_s", "radar_first_s", "outcome"]
    >>> detection_table(r)[columns].values.tolist()
    [['A', 'B', 0.0, 3.0, 'found']]
    """
    truth: dict[tuple[str, str], list[float]] = {}
    radar: dict[tuple[str, str], list[float]] = {}
    tracked: dict[tuple[str, str], float] = {}
    for rec in records:
        for own in rec.equipped:
            for pair in rec.truth_pairs:
                if pair[0] == own:
                    truth.setdefault(pair, []).append(rec.time_s)
            for pair in rec.used_pairs:
                if pair[0] == own:
                    radar.setdefault(pair, []).append(rec.time_s)
            for other in rec.tracked.get(own, ()):
                tracked.setdefault((own, other), rec.time_s)
    rows = []
    for pair in sorted(set(truth) | set(radar)):
        t, r = truth.get(pair, []), radar.get(pair, [])
        outcome = "found" if t and r else "missed" if t else "false"
        rows.append(
            {
                "ownship": pair[0],
                "intruder": pair[1],
                "truth_first_s": t[0] if t else np.nan,
                "radar_first_s": r[0] if r else np.nan,
                "delay_s": r[0] - t[0] if t and r else np.nan,
                "truth_steps": len(t),
                "radar_steps": len(r),
                "tracked_first_s": tracked.get(pair, np.nan),
                "outcome": outcome,
            }
        )
    columns = [
        "ownship",
        "intruder",
        "truth_first_s",
        "radar_first_s",
        "delay_s",
        "truth_steps",
        "radar_steps",
        "tracked_first_s",
        "outcome",
    ]
    return pd.DataFrame(rows, columns=columns)


def separation_table(states: pd.DataFrame, rpz_m: float, hpz_m: float, run_name: str) -> pd.DataFrame:
    """Per pair of aircraft: closest approach and time in loss of separation, from a run's states.

    Parameters
    ----------
    states : DataFrame
        :attr:`BlueSkyRun.states` (one row per aircraft per sample).
    rpz_m, hpz_m : float
        Horizontal separation (protected-zone radius) and vertical separation (half height), m.
    run_name : str
        The ``run`` column's value.

    Returns
    -------
    DataFrame
        ``run, aircraft_a, aircraft_b, min_horizontal_m, vertical_at_min_m, los_s`` (seconds
        sampled in loss of separation: horizontally within ``rpz_m`` and vertically within ``hpz_m``)
        and ``los`` (any).

    Examples
    --------
    >>> s = pd.DataFrame({"time_s": [0.0, 0.0, 1.0, 1.0], "acid": ["A", "B", "A", "B"],
    ...     "lat_deg": [52.0, 52.01, 52.0, 52.003], "lon_deg": [4.0] * 4, "alt_m": [900.0] * 4})
    >>> t = separation_table(s, 556.0, 91.0, "truth")
    >>> round(float(t.min_horizontal_m[0])), float(t.los_s[0]), bool(t.los[0])
    (334, 1.0, True)
    """
    rows = []
    step = float(np.median(np.diff(np.unique(states["time_s"])))) if states["time_s"].nunique() > 1 else 1.0
    by_id = {acid: g.set_index("time_s") for acid, g in states.groupby("acid")}
    for a, b in combinations(sorted(by_id), 2):
        columns = ["lat_deg", "lon_deg", "alt_m"]
        joined = pd.merge(
            by_id[a][columns], by_id[b][columns], left_index=True, right_index=True, suffixes=("", "_b")
        )
        if joined.empty:
            continue
        lat_a, lon_a, alt_a = (joined[c].to_numpy(float) for c in columns)
        lat_b, lon_b, alt_b = (joined[f"{c}_b"].to_numpy(float) for c in columns)
        rel = geodetic_to_ned(lat_b, lon_b, alt_b, lat_a, lon_a, alt_a, flat_earth=True)  # b seen from a
        horizontal, vertical = np.hypot(rel[:, 0], rel[:, 1]), np.abs(rel[:, 2])
        k = int(np.argmin(horizontal))
        los = (horizontal < rpz_m) & (vertical < hpz_m)
        rows.append(
            {
                "run": run_name,
                "aircraft_a": a,
                "aircraft_b": b,
                "min_horizontal_m": float(horizontal[k]),
                "vertical_at_min_m": float(vertical[k]),
                "los_s": float(los.sum() * step),
                "los": bool(los.any()),
            }
        )
    columns = ["run", "aircraft_a", "aircraft_b", "min_horizontal_m", "vertical_at_min_m", "los_s", "los"]
    return pd.DataFrame(rows, columns=columns)


def _zones(path: Path) -> tuple[float, float]:
    """The scenario's ZONER and ZONEDH (BlueSky's defaults 5 NM and 1000 ft when not given), m."""
    import re

    rpz, hpz = 5.0 * _NM, 1000.0 * _FT
    for line in path.read_text(errors="replace").splitlines():
        match = re.search(
            r">\s*(ZONER|PZR|RPZ|PZRADIUS|ZONEDH|PZDH|DHPZ|PZHEIGHT)\s+([0-9.]+)\s*$",
            line.split("#")[0].upper(),
        )
        if match:
            if match[1] in ("ZONER", "PZR", "RPZ", "PZRADIUS"):
                rpz = float(match[2]) * _NM
            else:
                hpz = float(match[2]) * _FT
    return rpz, hpz


def run(
    out_dir: Path,
    scenario: Path | None = None,
    end_s: float | None = None,
    progress: Callable[[str, float], None] | None = None,
    command: str | None = None,
) -> dict[str, Any]:
    """Compare BlueSky's perfect-state conflict detection with the radars' on ``scenario``.

    Parameters
    ----------
    out_dir : Path
        Output folder (see the module docstring for its files).
    scenario : Path, optional
        A BlueSky scenario file with radar-equipped aircraft (default :func:`demo_scenario`).
    end_s : float, optional
        Simulation time to stop at, s (default: the scenario's ``HOLD``).
    progress : callable, optional
        Called with the run's name and its simulation time, s.
    command : str, optional
        The command line the summary records (default this process'), with the version, UTC date
        and load average (:func:`skyradar.code_version.provenance`).

    Returns
    -------
    dict
        The summary (also ``summary.json``): counts of conflicts found, missed and false, the delays
        of the radar's detections, losses of separation of both runs, the radars' frames and wall times.
    """
    from skyradar.integrations.bluesky.runner import run_scenario

    packaged = scenario is None
    scenario = Path(scenario) if scenario is not None else demo_scenario()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    log_path = out_dir / "bluesky.log"
    write_text_atomic(log_path, "")  # BlueSky's messages are appended to it as the runs go
    t0 = time.perf_counter()
    runs = {}
    for name in ("truth", "radar"):

        def report(time_s: float, name: str = name) -> None:
            if progress is not None:
                progress(name, time_s)

        runs[name] = run_scenario(scenario, name, end_s=end_s, log_path=log_path, progress=report)
    radar_run = runs["radar"]
    detections = detection_table(radar_run.detections)
    rpz, hpz = _zones(scenario)
    separation = pd.concat(
        [separation_table(r.states, rpz, hpz, name) for name, r in runs.items()], ignore_index=True
    )
    write_csv_atomic(detections, out_dir / "conflicts.csv", index=False)
    write_csv_atomic(separation, out_dir / "separation.csv", index=False)
    plot(runs, detections, out_dir / "bluesky.png")
    false_conflicts = {fc for rec in radar_run.detections for fc in rec.false_conflicts}
    delays = detections["delay_s"].dropna()
    los = {name: separation[(separation.run == name) & separation.los] for name in runs}
    summary: dict[str, Any] = {
        "scenario": f"{scenario.name} (packaged)" if packaged else str(scenario),
        "end_s": radar_run.end_s,
        "protected_zone_m": [rpz, hpz],
        "equipped": sorted(radar_run.radars),
        "radars": radar_run.radars,
        "conflicts_truth": int((detections.truth_steps > 0).sum()),
        "conflicts_found": int((detections.outcome == "found").sum()),
        "conflicts_missed": int((detections.outcome == "missed").sum()),
        "conflicts_false": int((detections.outcome == "false").sum()),
        "false_track_conflicts": len(false_conflicts),
        "delay_median_s": float(delays.median()) if len(delays) else None,
        "delay_max_s": float(delays.max()) if len(delays) else None,
        "los_pairs_truth": [f"{a}-{b}" for a, b in los["truth"][["aircraft_a", "aircraft_b"]].values],
        "los_pairs_radar": [f"{a}-{b}" for a, b in los["radar"][["aircraft_a", "aircraft_b"]].values],
        "los_s_truth": float(los["truth"]["los_s"].sum()),
        "los_s_radar": float(los["radar"]["los_s"].sum()),
        "wall_s_truth": round(runs["truth"].wall_s, 2),
        "wall_s_radar": round(radar_run.wall_s, 2),
        "wall_s": round(time.perf_counter() - t0, 2),
        "outputs": ["conflicts.csv", "separation.csv", "summary.json", "bluesky.png", "bluesky.log"],
        **provenance(command, code_version()),
    }
    write_json_atomic(out_dir / "summary.json", summary)
    return summary


def plot(runs: dict[str, Any], detections: pd.DataFrame, path: Path) -> Path:
    """The flights of both runs (left) and each radar-equipped pair's conflict timeline (right)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_map, ax_time) = plt.subplots(1, 2, figsize=(12, 5.2), gridspec_kw={"width_ratios": [1.1, 1]})
    truth_states, radar_states = runs["truth"].states, runs["radar"].states
    lat0 = float(radar_states["lat_deg"].mean()) if len(radar_states) else 0.0
    lon0 = float(radar_states["lon_deg"].mean()) if len(radar_states) else 0.0
    equipped = set(runs["radar"].radars)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for k, (acid, g) in enumerate(radar_states.groupby("acid")):
        colour = colours[k % len(colours)]
        for states, style, label in ((truth_states, "--", None), (radar_states, "-", acid)):
            s = states[states.acid == acid]
            north, east = _north_east_km(s, lat0, lon0)
            width = 2.2 if acid in equipped else 1.2
            ax_map.plot(east, north, style, color=colour, lw=width, label=label)
        ax_map.plot(*_start(g, lat0, lon0), "o", color=colour, ms=4)
    ax_map.set_xlabel("east, km")
    ax_map.set_ylabel("north, km")
    ax_map.set_aspect("equal", "datalim")
    ax_map.legend(fontsize=8, loc="best")
    ax_map.set_title("flights: radar run (solid), perfect-state run (dashed)", fontsize=10)
    records = runs["radar"].detections
    step = float(np.median(np.diff([r.time_s for r in records]))) if len(records) > 1 else 1.0
    labels = []
    for y, row in enumerate(detections.itertuples(index=False)):
        pair = (row.ownship, row.intruder)
        for key, colour, dy in (("truth_pairs", "0.55", -0.25), ("used_pairs", "tab:red", 0.0)):
            times = [r.time_s for r in records if pair in getattr(r, key)]
            for a, b in _intervals(times, step):
                ax_time.plot([a, b + step], [y + dy, y + dy], color=colour, lw=6, solid_capstyle="butt")
        tracked = [r.time_s for r in records if pair[1] in r.tracked.get(pair[0], ())]
        for a, b in _intervals(tracked, step):
            ax_time.plot([a, b + step], [y + 0.25, y + 0.25], color="tab:blue", lw=2)
        labels.append(f"{row.ownship} / {row.intruder}: {row.outcome}")
    ax_time.set_yticks(range(len(labels)), labels, fontsize=8)
    ax_time.set_ylim(-0.8, max(len(labels), 1) - 0.2)
    ax_time.invert_yaxis()
    ax_time.set_xlabel("simulation time, s")
    ax_time.set_title("conflict: perfect state (grey), radar (red); track (blue)", fontsize=10)
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=110)
    plt.close(fig)
    return path


def _north_east_km(states: pd.DataFrame, lat0: float, lon0: float) -> tuple[np.ndarray, np.ndarray]:
    """North and east of the states' positions from (lat0, lon0), km (flat earth: a few km apart)."""
    ned = geodetic_to_ned(
        states["lat_deg"].to_numpy(), states["lon_deg"].to_numpy(), 0.0, lat0, lon0, flat_earth=True
    )
    return ned[..., 0] / 1000.0, ned[..., 1] / 1000.0


def _start(group: pd.DataFrame, lat0: float, lon0: float) -> tuple[float, float]:
    north, east = _north_east_km(group.sort_values("time_s").iloc[:1], lat0, lon0)
    return float(east[0]), float(north[0])
