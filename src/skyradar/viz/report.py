"""Figures and the static HTML page of the end-to-end demo (:mod:`skyradar.demo`).

No build step: ``index.html`` links PNG files written next to it (matplotlib, Agg backend).
"""

from __future__ import annotations

import html
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

__all__ = [
    "LEVEL_COLOURS",
    "plot_range_doppler",
    "plot_plan_view",
    "plot_alert_timeline",
    "intruder_outcomes",
    "summary_sentences",
    "write_report",
]

LEVEL_COLOURS = {0: "#9e9e9e", 1: "#1e88e5", 2: "#fb8c00", 3: "#e53935"}
_LEVEL_WORDS = {0: "no alert", 1: "preventive", 2: "corrective", 3: "warning"}
_INTRUDER_COLOURS = ("#d81b60", "#1e88e5", "#43a047", "#8e24aa", "#00897b")


def _save(fig, path: Path) -> Path:
    try:
        return savefig_atomic(fig, path, dpi=110, bbox_inches="tight")
    finally:
        plt.close(fig)


def plot_range_doppler(frame, config, detections: pd.DataFrame, title: str, path: Path) -> Path:
    """Strength image of one frame with its detections (ground: white dots, others: red circles).

    Parameters
    ----------
    frame : ndarray
        One frame, (range, doppler, rx), complex.
    config : RadarConfig
        The radar (axes and noise power).
    detections : DataFrame
        The frame's detections: ``range_m`` (m), ``radial_velocity_mps`` (m/s), ``is_ground``, ``spur``.
    title : str
        The figure's title.
    path : Path
        The image to write (format by its suffix).

    Returns
    -------
    Path
        ``path``.

    Examples
    --------
    One detection on the ground, one spur, one kept; the SVG (text kept as text) counts them in
    the legend:

    >>> import re, tempfile
    >>> from skyradar.config import RadarConfig
    >>> cfg = RadarConfig.prototype_2022()
    >>> frame = np.full((cfg.n_range, cfg.n_doppler, cfg.n_rx), np.sqrt(cfg.noise_power_w), complex)
    >>> det = pd.DataFrame({"range_m": [300.0, 900.0, 1200.0], "radial_velocity_mps": [0.0, -5.0, 10.0],
    ...                     "is_ground": [True, False, False], "spur": [False, False, True]})
    >>> with tempfile.TemporaryDirectory() as d, plt.rc_context({"svg.fonttype": "none"}):
    ...     svg = plot_range_doppler(frame, cfg, det, "frame 7", Path(d) / "rd.svg").read_text()
    >>> texts = lambda svg: re.findall(r"<text[^>]*>([^<]*)</text>", svg)
    >>> [t for t in texts(svg) if "(" in t or "frame" in t]
    ['frame 7', 'ground/spur (2)', 'kept for tracking (1)']
    """
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
    """North/east plan view: own-ship and intruder truth, confirmed 3-D tracks, warning points.

    Parameters
    ----------
    truth : xarray.Dataset
        A run's truth: ``own_north_m``, ``own_east_m`` (time), ``tgt_north_m``, ``tgt_east_m``
        (time, target), m, and the frame times.
    tracks : DataFrame
        Tracks table: ``track_id``, ``confirmed``, ``north_m``, ``east_m`` (m).
    labels : dict of int to str
        Intruder name per track id; others are drawn grey as clutter.
    alerts : DataFrame
        Alerts table: ``time_s`` (s), ``level``, ``rel_north_m``, ``rel_east_m`` (m, from the own-ship).
    path : Path
        The image to write (format by its suffix).

    Returns
    -------
    Path
        ``path``.

    Examples
    --------
    The sample encounter of :mod:`skyradar.web.sample`, one confirmed track on ``head-on``:

    >>> import re, tempfile
    >>> from skyradar.web.sample import sample_run_dataset
    >>> truth = sample_run_dataset(n_frames=3)
    >>> tracks = pd.DataFrame({"track_id": [1, 1], "confirmed": True, "east_m": 0.0,
    ...                        "north_m": [6400.0, 6300.0]})
    >>> alerts = pd.DataFrame({"time_s": [1.0], "level": [3], "rel_east_m": [0.0], "rel_north_m": [6300.0]})
    >>> with tempfile.TemporaryDirectory() as d, plt.rc_context({"svg.fonttype": "none"}):
    ...     svg = plot_plan_view(truth, tracks, {1: "head-on"}, alerts, Path(d) / "plan.svg").read_text()
    >>> texts = lambda svg: re.findall(r"<text[^>]*>([^<]*)</text>", svg)
    >>> [t for t in texts(svg) if t in ("T1", "own-ship", "head-on truth", "crossing truth", "north [m]")]
    ['north [m]', 'T1', 'own-ship', 'head-on truth', 'crossing truth']
    """
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
    """Issued alert level of every alerting-capable track over time, one row per track.

    Parameters
    ----------
    alerts : DataFrame
        Alerts table: ``time_s`` (s), ``track_id``, ``level`` (0-3).
    labels : dict of int to str
        Intruder name per track id; other tracks are labelled ``clutter``.
    t_span_s : (float, float)
        The time axis' span, s.
    path : Path
        The image to write (format by its suffix).

    Returns
    -------
    Path
        ``path``.

    Examples
    --------
    Two tracks, one row each, labelled by their intruder:

    >>> import re, tempfile
    >>> alerts = pd.DataFrame({"time_s": [0.0, 1.0, 1.0, 2.0], "track_id": [1, 1, 4, 4],
    ...                        "level": [1, 3, 0, 0]})
    >>> with tempfile.TemporaryDirectory() as d, plt.rc_context({"svg.fonttype": "none"}):
    ...     svg = plot_alert_timeline(alerts, {1: "collision"}, (0.0, 3.0), Path(d) / "t.svg").read_text()
    >>> texts = lambda svg: re.findall(r"<text[^>]*>([^<]*)</text>", svg)
    >>> [t for t in texts(svg) if t.startswith("T")]
    ['T1 (collision)', 'T4 (clutter)']
    """
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


def intruder_outcomes(summary: dict[str, Any], timeline: pd.DataFrame) -> pd.DataFrame:
    """One row per intruder of a demo run (and ``clutter``): its tracks, highest issued level, and
    when its first alert and its highest level came (s; NaN: never).

    Parameters
    ----------
    summary : dict
        :func:`skyradar.demo.run_demo`'s summary (``intruders``: tracks, max_level per name).
    timeline : DataFrame
        :func:`skyradar.demo.alert_timeline` (``time_s``, ``intruder``, ``level``).

    Returns
    -------
    DataFrame
        Columns ``intruder``, ``tracks``, ``highest_level``, ``highest_level_s``, ``first_alert``,
        ``first_alert_s`` (levels in words).

    Examples
    --------
    >>> summary = {"intruders": {"a": {"tracks": 1, "max_level": 3}, "b": {"tracks": 2, "max_level": 0}}}
    >>> timeline = pd.DataFrame({"time_s": [20.0, 24.5], "intruder": ["a", "a"], "level": [1, 3]})
    >>> intruder_outcomes(summary, timeline)
      intruder  tracks highest_level  highest_level_s first_alert  first_alert_s
    0        a       1       warning             24.5  preventive           20.0
    1        b       2      no alert              NaN    no alert            NaN
    """
    rows = []
    for name, outcome in summary["intruders"].items():
        mine = timeline[(timeline["intruder"] == name) & (timeline["level"] > 0)].sort_values("time_s")
        top = int(outcome["max_level"])
        reached = mine.loc[mine["level"] == top, "time_s"]
        first = int(mine["level"].iloc[0]) if len(mine) else 0
        rows.append(
            {
                "intruder": name,
                "tracks": int(outcome["tracks"]),
                "highest_level": _LEVEL_WORDS.get(top, str(top)),
                "highest_level_s": float(reached.min()) if top > 0 and len(reached) else float("nan"),
                "first_alert": _LEVEL_WORDS.get(first, str(first)),
                "first_alert_s": float(mine["time_s"].iloc[0]) if len(mine) else float("nan"),
            }
        )
    return pd.DataFrame(rows)


def summary_sentences(summary: dict[str, Any], outcomes: pd.DataFrame, duration_s: float) -> list[str]:
    """The demo report's opening, in words: what the chain measured and when each alert came.

    Every number comes from the run's ``summary`` and ``outcomes`` (:func:`intruder_outcomes`).

    Parameters
    ----------
    summary : dict
        :func:`skyradar.demo.run_demo`'s summary.
    outcomes : DataFrame
        :func:`intruder_outcomes` of the run.
    duration_s : float
        Time from the first frame to the last, s.

    Returns
    -------
    list of str
        The run, one sentence per intruder, the clutter, the acceptance check.

    Examples
    --------
    >>> summary = {"frames": 10, "detections": 50, "detections_ground": 30, "detections_spur": 0,
    ...            "tracks": 3, "acceptance": True, "intruders": {"a": {"tracks": 1, "max_level": 3},
    ...                                                           "clutter": {"tracks": 1, "max_level": 0}}}
    >>> timeline = pd.DataFrame({"time_s": [20.0, 24.5], "intruder": ["a", "a"], "level": [1, 3]})
    >>> for line in summary_sentences(summary, intruder_outcomes(summary, timeline), 40.0):
    ...     print(line)
    10 frames over 40 s: 50 detections (30 on the ground, 0 on radar spurs), 3 tracks.
    a: warning at 24.5 s (first alert, preventive, at 20.0 s), from 1 track.
    1 track follows no intruder (clutter); none alerted.
    Acceptance (a warning for the collision intruder, none for anything else): PASS.
    """

    def tracks(n: int) -> str:
        return f"{n} track" + ("" if n == 1 else "s")

    lines = [
        f"{summary['frames']} frames over {duration_s:.0f} s: {summary['detections']} detections "
        f"({summary['detections_ground']} on the ground, {summary['detections_spur']} on radar spurs), "
        f"{tracks(summary['tracks'])}."
    ]
    for row in outcomes.itertuples(index=False):
        n = int(row.tracks)
        if row.intruder == "clutter":
            alerted = (
                "none alerted" if row.highest_level == "no alert" else f"highest level {row.highest_level}"
            )
            follows = "follows" if n == 1 else "follow"
            lines.append(f"{tracks(n)} {follows} no intruder (clutter); {alerted}.")
        elif n == 0:
            lines.append(f"{row.intruder}: never tracked.")
        elif np.isnan(row.highest_level_s):
            lines.append(f"{row.intruder}: tracked ({tracks(n)}), no alert.")
        else:
            earlier = ""
            if row.first_alert_s < row.highest_level_s:
                earlier = f" (first alert, {row.first_alert}, at {row.first_alert_s:.1f} s)"
            when = f"{row.highest_level} at {row.highest_level_s:.1f} s"
            lines.append(f"{row.intruder}: {when}{earlier}, from {tracks(n)}.")
    verdict = "PASS" if summary["acceptance"] else "FAIL"
    lines.append(f"Acceptance (a warning for the collision intruder, none for anything else): {verdict}.")
    return lines


def _summary_html(summary: dict[str, Any], timeline: pd.DataFrame, duration_s: float) -> str:
    """The report's opening section: the run in sentences, the intruders' outcomes, what to look at."""
    outcomes = intruder_outcomes(summary, timeline)
    run, *per_intruder, verdict = summary_sentences(summary, outcomes, duration_s)
    items = "".join(f"<li>{html.escape(line)}</li>" for line in per_intruder)
    table = outcomes.rename(
        columns={
            "highest_level": "highest level",
            "highest_level_s": "at [s]",
            "first_alert": "first alert",
            "first_alert_s": "first alert at [s]",
        }
    ).to_html(index=False, na_rep="", float_format="{:.1f}".format)
    files = ("summary.json", "detections.parquet", "tracks.parquet", "alerts.parquet", "alert_timeline.csv")
    links = ", ".join(f'<a href="{f}">{f}</a>' for f in files)
    return f"""<h2>Summary</h2>
<p>{html.escape(run)}</p>
<ul>{items}</ul>
<p><b>{html.escape(verdict)}</b></p>
{table}
<p>The chain: simulate, process (detections, directions, ground flags), track (3-D, from the detections
that are neither ground nor spur), alert (confirmed tracks). What to look at: the plan view shows
each confirmed track against the truth and where warnings were issued; the alert timeline each
track's level over time, with every change listed below it; the advice table the bands and the
preferred manoeuvre at the start of each corrective or warning episode.</p>
<p>Data: {links} (the numbers above, the stage timings and every table).</p>"""


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
    name = str(truth.attrs.get("scenario", "")) or "skyradar demo"
    title = html.escape(name if name.lower().startswith("skyradar") else f"skyradar demo: {name}")
    page = f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<style>body{{font-family:sans-serif;max-width:1000px;margin:auto}}
table{{border-collapse:collapse;font-size:13px}} td,th{{border:1px solid #ccc;padding:2px 6px}}
img{{max-width:100%}}</style></head><body>
<h1>{title}</h1>
{_summary_html(summary, timeline, float(times[-1] - times[0]))}
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
