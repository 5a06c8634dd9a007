"""Figures and the static HTML page of the end-to-end demo (:mod:`skyradar.demo`).

No build step: ``index.html`` links PNG files written next to it (matplotlib, Agg backend).
"""

from __future__ import annotations

import html
import json
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from skyradar.io.atomic import savefig_atomic, write_text_atomic  # noqa: E402
from skyradar.io.frames import radar_config_of  # noqa: E402
from skyradar.io.frames_model import frame_times_s  # noqa: E402
from skyradar.viz.rangedoppler import plot_strength  # noqa: E402

__all__ = ["LEVEL_COLOURS", "plot_range_doppler", "plot_plan_view", "plot_alert_timeline", "write_report"]

LEVEL_COLOURS = {0: "#9e9e9e", 1: "#1e88e5", 2: "#fb8c00", 3: "#e53935"}
_INTRUDER_COLOURS = ("#d81b60", "#1e88e5", "#43a047", "#8e24aa", "#00897b")


def _save(fig, path: Path) -> Path:
    try:
        return savefig_atomic(fig, path, dpi=110, bbox_inches="tight")
    finally:
        plt.close(fig)


def plot_range_doppler(frame, config, detections: pd.DataFrame, title: str, path: Path) -> Path:
    """Strength image of one frame with its detections (ground: white dots, others: red circles)."""
    fig, ax = plt.subplots(figsize=(7, 5))
    plot_strength(frame, config, ax=ax)
    ground = detections["is_ground"].to_numpy(bool) | detections["spur"].to_numpy(bool)
    ax.plot(
        detections.loc[ground, "radial_velocity_mps"],
        detections.loc[ground, "range_m"],
        ".",
        ms=1.5,
        color="white",
        alpha=0.5,
        label=f"ground/spur ({int(ground.sum())})",
    )
    ax.plot(
        detections.loc[~ground, "radial_velocity_mps"],
        detections.loc[~ground, "range_m"],
        "o",
        mfc="none",
        mec="red",
        ms=7,
        label=f"kept for tracking ({int((~ground).sum())})",
    )
    ax.set_title(title)
    ax.legend(loc="upper right", fontsize=8)
    return _save(fig, path)


def plot_plan_view(
    truth, tracks: pd.DataFrame, labels: dict[int, str], alerts: pd.DataFrame, path: Path
) -> Path:
    """North/east plan view: own-ship and intruder truth, confirmed 3-D tracks, warning points."""
    fig, ax = plt.subplots(figsize=(7, 7))
    ax.plot(truth["own_east_m"], truth["own_north_m"], "k-", lw=2, label="own-ship")
    ax.plot(truth["own_east_m"][0], truth["own_north_m"][0], "k>", ms=8)
    names = [str(x) for x in truth["target"].values]
    for k, name in enumerate(names):
        c = _INTRUDER_COLOURS[k % len(_INTRUDER_COLOURS)]
        ax.plot(
            truth["tgt_east_m"][:, k], truth["tgt_north_m"][:, k], "--", color=c, lw=1, label=f"{name} truth"
        )
    conf = tracks[tracks["confirmed"].astype(bool)]
    for tid, g in conf.groupby("track_id"):
        name = labels.get(int(tid), "clutter")
        c = _INTRUDER_COLOURS[names.index(name) % len(_INTRUDER_COLOURS)] if name in names else "0.5"
        ax.plot(g["east_m"], g["north_m"], "-", color=c, lw=2.5, alpha=0.7)
        ax.annotate(f"T{tid}", (g["east_m"].iloc[-1], g["north_m"].iloc[-1]), fontsize=7, color=c)
    warn = alerts[alerts["level"] >= 3]
    t = frame_times_s(truth)
    ax.plot(
        warn["rel_east_m"] + np.interp(warn["time_s"], t, truth["own_east_m"]),
        warn["rel_north_m"] + np.interp(warn["time_s"], t, truth["own_north_m"]),
        "x",
        color=LEVEL_COLOURS[3],
        ms=6,
        label="track position at warning",
    )
    ax.set_xlabel("east [m]")
    ax.set_ylabel("north [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title("plan view: truth (dashed), confirmed 3-D tracks (solid)")
    ax.legend(fontsize=7, loc="best")
    return _save(fig, path)


def plot_alert_timeline(alerts: pd.DataFrame, labels: dict[int, str], t_span_s, path: Path) -> Path:
    """Issued alert level of every alerting-capable track over time, one row per track."""
    ids = sorted(alerts["track_id"].unique()) if len(alerts) else []
    fig, ax = plt.subplots(figsize=(8, 0.5 * max(len(ids), 2) + 1.5))
    for row, tid in enumerate(ids):
        g = alerts[alerts["track_id"] == tid]
        ax.scatter(
            g["time_s"], np.full(len(g), row), c=[LEVEL_COLOURS[int(v)] for v in g["level"]], s=12, marker="s"
        )
    ax.set_yticks(range(len(ids)), [f"T{t} ({labels.get(int(t), 'clutter')})" for t in ids])
    ax.set_xlim(*t_span_s)
    ax.set_xlabel("time [s]")
    for level, c in LEVEL_COLOURS.items():
        ax.scatter([], [], c=c, marker="s", label=["none", "preventive", "corrective", "warning"][level])
    ax.legend(fontsize=7, ncol=4, loc="upper left", bbox_to_anchor=(0, -0.25))
    ax.set_title("issued alert level per confirmed track")
    return _save(fig, path)


def _advice_rows(alerts: pd.DataFrame) -> pd.DataFrame:
    """First frame of each warning episode with its advice (bands and preferred manoeuvre)."""
    cols = ["time_s", "heading_bands_deg", "vs_bands_mps", "preferred_heading_deg", "preferred_vs_mps"]
    if "preferred_heading_deg" not in alerts or not (alerts["level"] >= 2).any():
        return pd.DataFrame(columns=cols)
    a = alerts[alerts["level"] >= 2].drop_duplicates("time_s")
    pick = np.r_[True, np.diff(a["time_s"].to_numpy()) > 1.0]
    out = a.loc[pick, cols].copy()
    for c in ("heading_bands_deg", "vs_bands_mps"):
        out[c] = [
            ", ".join(f"[{lo:.0f}, {hi:.0f}]" for lo, hi in zip(v[::2], v[1::2], strict=False))
            for v in out[c]
        ]
    return out.round(1)


def write_report(
    out_dir: Path, chain: dict[str, Any], labels, timeline: pd.DataFrame, summary, rd_frame: int
) -> Path:
    """Write the figures and ``index.html`` of a demo run into ``out_dir``; returns the page path."""
    out_dir = Path(out_dir)
    truth, det, alerts = chain["truth"], chain["detections"], chain["alerts"]
    config = radar_config_of(truth)
    t = float(frame_times_s(truth)[rd_frame])
    title = f"range-Doppler, frame {rd_frame} (t = {t:.1f} s)"
    rd_det = det[det["frame"] == rd_frame]
    plot_range_doppler(chain["rd_frames"][rd_frame], config, rd_det, title, out_dir / "range_doppler.png")
    plot_plan_view(truth, chain["tracks"], labels, alerts, out_dir / "plan_view.png")
    times = frame_times_s(truth)
    plot_alert_timeline(alerts, labels, (float(times[0]), float(times[-1])), out_dir / "alert_timeline.png")
    advice = _advice_rows(alerts)
    no_advice = "<p>no advice (no corrective or warning alert)</p>"
    advice_html = advice.to_html(index=False, na_rep="") if len(advice) else no_advice
    page = f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>skyradar demo</title>
<style>body{{font-family:sans-serif;max-width:1000px;margin:auto}}
table{{border-collapse:collapse;font-size:13px}} td,th{{border:1px solid #ccc;padding:2px 6px}}
img{{max-width:100%}}</style></head><body>
<h1>skyradar demo: {html.escape(str(truth.attrs.get("scenario", "")))}</h1>
<p>Simulate &rarr; process &rarr; track (3-D, non-ground non-spur detections) &rarr; alert (confirmed
tracks). Acceptance (warning for the collision intruder, none for anything else):
<b>{"PASS" if summary["acceptance"] else "FAIL"}</b></p>
<h2>Summary</h2><pre>{html.escape(json.dumps(summary, indent=1))}</pre>
<h2>Range-Doppler with detections</h2><img src="range_doppler.png" alt="range-Doppler">
<h2>Plan view: tracks and truth</h2><img src="plan_view.png" alt="plan view">
<h2>Alert timeline</h2><img src="alert_timeline.png" alt="alert timeline">
{timeline.round(1).to_html(index=False, na_rep="")}
<h2>Advice (first frame of each corrective/warning episode)</h2>
<p>Heading bands: conflict headings [deg]; vertical-speed bands: conflict vertical speeds [m/s].</p>
{advice_html}
</body></html>
"""
    return write_text_atomic(out_dir / "index.html", page)
