"""ch7 experiment: passive bistatic radar with a rotating ATC radar as illuminator (Maas 2022, ch. 7).

1. The thesis' test pulse through the matched filter, with and without the Hann window.
2. The thesis geometry (:func:`skyradar.passive.scene.thesis_scene`: receiver on a tower 12 km from an
   S-band PSR, five towns 14.5-19.5 km from the receiver, ground clutter, a 1 m^2 aircraft 1.6-2.8 km
   from the receiver) simulated for 40 s (9 rotations) at 5 MS/s into a SigMF recording.
3. That recording processed by :func:`skyradar.passive.pipeline.process_recording` (it sees only the
   recording and its metadata) and scored against the simulator's truth tables
   (:mod:`skyradar.experiments.ch7_score`).

Writes ``ch7_testpulse.png``, ``ch7_sweeps.png``, ``ch7_aircraft.png``, ``ch7_table.csv`` (thesis
beside ours), ``ch7_detections.parquet`` and ``ch7.json`` into ``out_dir`` (and, with
``keep_recording``, the SigMF recording and its truth tables), then ``summary.md``.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from skyradar.experiments.summary_md import number, page, write_summary
from skyradar.io.atomic import write_csv_atomic
from skyradar.io.json_results import write_json_atomic
from skyradar.io.tables import write_table

__all__ = ["run", "THESIS", "summary_markdown"]

THESIS = {
    "clusters_seen": "9/9 sweeps (Vianen, Utrecht, Amersfoort, Hoevelaken at R2 14-20 km); 7/9 at 20.7 km",
    "aircraft_seen": "'possibly' 3/9 sweeps (R2 1.1-2.6 km)",
    "aircraft_error_m": "not measured (no truth)",
    "false_per_sweep": "not measured",
    "method": "matched filter (Hann), no CFAR, no MTI",
}


def _simulate(out_dir: Path, seconds: float, seed: int, progress) -> Path:
    from skyradar.passive.scene import thesis_scene
    from skyradar.passive.simulate import simulate_recording

    scene = thesis_scene(duration_s=seconds, seed=seed)
    return simulate_recording(
        scene, out_dir / "ch7_recording.sigmf-meta", 5e6, overwrite=True, progress=progress
    )


def run(
    out_dir: Path, seconds: float = 40.0, seed: int = 0, progress=None, keep_recording: bool = False
) -> dict[str, Any]:
    """Run ch7; ``progress(stage, done, total)`` is called while simulating and processing.

    The recording (1.6 GB for 40 s) is simulated into a temporary folder inside ``out_dir`` and
    deleted at the end unless ``keep_recording`` (then it and its truth tables move into ``out_dir``).
    """
    import shutil
    import tempfile

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=out_dir, prefix=".ch7-recording-") as tmp:
        result = _run(out_dir, Path(tmp), seconds, seed, progress)
        if keep_recording:
            for path in Path(tmp).iterdir():
                shutil.move(str(path), out_dir / path.name)
    write_summary(out_dir, summary_markdown(result, out_dir))
    return result


def _run(out_dir: Path, tmp: Path, seconds: float, seed: int, progress) -> dict[str, Any]:
    from skyradar.experiments.ch7_figures import (
        aircraft_figure,
        plan_view_figure,
        thesis_pulse_figure,
        thesis_pulse_numbers,
    )
    from skyradar.experiments.ch7_score import score
    from skyradar.io.sigmf_io import read_iq_recording
    from skyradar.passive.pipeline import process_recording, receiver_geometry

    t0 = time.perf_counter()
    thesis_pulse_figure(out_dir / "ch7_testpulse.png")
    pulse = thesis_pulse_numbers()
    meta = _simulate(tmp, seconds, seed, (lambda d, n: progress("simulate", d, n)) if progress else None)
    t_sim = time.perf_counter() - t0
    rec = read_iq_recording(meta)
    t1 = time.perf_counter()
    res = process_recording(rec, progress=(lambda d, n: progress("process", d, n)) if progress else None)
    t_proc = time.perf_counter() - t1
    det = res.detections
    write_table(det, out_dir / "ch7_detections.parquet", metadata={"source": meta.name})
    truth = pd.read_parquet(rec.truth_table_path)
    s = score(det, truth, res.scan_period_s, seconds)
    n_rot = s["rotations"]
    tx_en, _ = receiver_geometry(rec)
    plan_view_figure(out_dir / "ch7_sweeps.png", det, truth, tx_en, res.scan_period_s, n_rot)
    aircraft_figure(out_dir / "ch7_aircraft.png", det, truth)
    result = _summary(s, pulse, res, t_sim, t_proc, time.perf_counter() - t0)
    write_csv_atomic(_table(result), out_dir / "ch7_table.csv", index=False)
    write_json_atomic(out_dir / "ch7.json", {**result, "score": s})
    return result


def _summary(s: dict, pulse: dict, res, t_sim: float, t_proc: float, t_total: float) -> dict[str, Any]:
    clusters_all = sum(1 for seen in s["clusters"].values() if all(seen))
    errors = s["aircraft_error_m"]
    median = float(np.median(errors)) if errors else float("nan")
    per_rot = s["false_per_rotation"]
    out = {
        "rotations": s["rotations"],
        "clusters": len(s["clusters"]),
        "clusters_seen_every_rotation": clusters_all,
        "cluster_rotations": {k: int(sum(v)) for k, v in s["clusters"].items()},
        "aircraft_seen": s["aircraft_seen"],
        "aircraft_passes": s["aircraft_passes"],
        "aircraft_median_error_m": round(median, 1),
        "false_total": s["false_total"],
        "false_max_per_rotation": int(max(per_rot)) if per_rot else 0,
        "false_mean_per_rotation": round(float(np.mean(per_rot)), 2) if per_rot else 0.0,
        "false_by_channel": s["false_by_channel"],
        "false_total_300m_match": s["strict_false_total"],
        "detections": len(res.detections),
        "blind_zone_dropped": res.masked,
        "scan_period_s": round(res.scan_period_s, 4),
        **pulse,
        "simulate_s": round(t_sim, 1),
        "process_s": round(t_proc, 1),
        "total_s": round(t_total, 1),
    }
    out["acceptance"] = {
        "clusters_9_of_9": clusters_all == len(s["clusters"]) and s["rotations"] >= 9,
        "aircraft_8_of_9": s["aircraft_seen"] >= 8,
        "median_error_le_150m": bool(median <= 150.0),
        "false_le_1_per_sweep": out["false_max_per_rotation"] <= 1,
        "test_pulse": pulse["hann_echo_visible"] and not pulse["plain_echo_visible"],
        "under_5_min": t_total < 300.0,
    }
    return out


def _table(r: dict) -> pd.DataFrame:
    cl = f"{r['clusters_seen_every_rotation']}/{r['clusters']} towns in all {r['rotations']} rotations"
    rows = [
        ("urban clusters", THESIS["clusters_seen"], cl),
        (
            "small aircraft seen",
            THESIS["aircraft_seen"],
            f"{r['aircraft_seen']}/{r['aircraft_passes']} passes",
        ),
        ("aircraft median position error", THESIS["aircraft_error_m"], f"{r['aircraft_median_error_m']} m"),
        (
            "false detections per sweep",
            THESIS["false_per_sweep"],
            f"max {r['false_max_per_rotation']}, mean {r['false_mean_per_rotation']}",
        ),
        ("test pulse peak", "0.15 ms", f"{r['hann_peak_ms']} ms (Hann), {r['plain_peak_ms']} ms (plain)"),
        (
            "0.01 echo 0.02 ms later",
            "visible only with Hann",
            f"Hann: {r['hann_echo_visible']}, plain: {r['plain_echo_visible']}",
        ),
        (
            "processing",
            THESIS["method"],
            "matched filter (Hann), direct-path removal, MTI, dwell Doppler, CFAR",
        ),
    ]
    return pd.DataFrame(rows, columns=["quantity", "thesis", "ours"])


_FILES = {
    "ch7_testpulse.png": "the thesis' test pulse and its echo through the matched filter, plain and Hann",
    "ch7_sweeps.png": "the detections of each rotation in plan view, static and moving, over the truth",
    "ch7_aircraft.png": "the small aircraft's detections against its true path",
    "ch7_table.csv": "the thesis' findings beside ours, one row per quantity",
    "ch7_detections.parquet": "every detection of the processed recording",
    "ch7.json": "every measured value, with the score against the truth",
    "ch7_recording.<...>": "the simulated SigMF recording and its truth tables (kept on request)",
}


def summary_markdown(result: dict[str, Any], out_dir: Path | None = None) -> str:
    """``summary.md`` of a ch7 run: towns, the small aircraft and false detections beside the thesis.

    The table is the run's ``ch7_table.csv`` (the thesis' findings, :data:`THESIS`, beside ours).

    Parameters
    ----------
    result : dict
        The summary :func:`run` returns (also in ``ch7.json``).
    out_dir : Path, optional
        The run's folder: only the files present there are listed (None: all of them).

    Returns
    -------
    str
        Markdown: title, sentences, the table, the files.

    Examples
    --------
    >>> r = {"rotations": 9, "clusters": 5, "clusters_seen_every_rotation": 5, "aircraft_seen": 9,
    ...      "aircraft_passes": 9, "aircraft_median_error_m": 61.5, "false_total": 3,
    ...      "false_max_per_rotation": 1, "false_mean_per_rotation": 0.33, "detections": 812,
    ...      "scan_period_s": 4.4, "hann_peak_ms": 0.15, "plain_peak_ms": 0.15, "hann_echo_visible": True,
    ...      "plain_echo_visible": False, "total_s": 140.2,
    ...      "acceptance": {"clusters_9_of_9": True, "aircraft_8_of_9": True}}
    >>> text = summary_markdown(r)
    >>> print(text.splitlines()[0])
    # ch7: passive radar with an air-traffic-control radar as illuminator
    >>> "| small aircraft seen | 'possibly' 3/9 sweeps (R2 1.1-2.6 km) | 9/9 passes |" in text
    True
    >>> "`ch7_sweeps.png`" in text
    True
    """
    r = result
    missed = [name.replace("_", " ") for name, ok in r.get("acceptance", {}).items() if not ok]
    paragraphs = [
        f"A receiver on a tower listens to a rotating S-band air-traffic-control radar for {r['rotations']} "
        "rotations; the simulated recording is processed as a real one would be and scored against the "
        f"simulator's truth ({r['detections']} detections, {number(r['total_s'])} s in all).",
        f"{r['clusters_seen_every_rotation']} of {r['clusters']} towns are seen in every rotation, and the "
        f"small aircraft in {r['aircraft_seen']} of its {r['aircraft_passes']} passes with a median "
        f"position error of {number(r['aircraft_median_error_m'])} m (thesis: "
        f"{THESIS['aircraft_seen']}). False detections: {r['false_total']} in all, at most "
        f"{r['false_max_per_rotation']} per rotation. With the Hann window the test pulse's weak echo is "
        f"{'visible' if r['hann_echo_visible'] else 'not visible'}, without it "
        f"{'visible' if r['plain_echo_visible'] else 'not visible'}. "
        + (
            "Every acceptance bound holds."
            if not missed
            else f"Acceptance bounds missed: {', '.join(missed)}."
        ),
    ]
    table = _table(r)
    rows = table.to_numpy().tolist()
    title = "ch7: passive radar with an air-traffic-control radar as illuminator"
    return page(title, paragraphs, list(table.columns), rows, _FILES, out_dir)
