"""Tables, figures and the summary of ``skyradar experiment encounters``.

Writes ``summary.md`` first: the run in a few sentences and one table row per terrain and layout,
generated from the measured rows, with the figures and data files it comes from; then
``encounters.parquet`` and ``encounters.csv`` (one row per terrain, encounter and layout),
``summary_rows.csv`` (one row per terrain and layout), ``encounters.png`` (the first terrain's
last layout), ``encounters_<terrain>_<layout>.png`` for every other row and ``causes.png`` (every
conflict of each row: warned before its loss of well clear, or the cause it was not).
"""

from __future__ import annotations

import textwrap
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from skyradar.experiments.encounter_score import CAUSES, summarise_layout
from skyradar.experiments.encounter_set import plot_encounters
from skyradar.experiments.sensor_figures import plot_sensor_figures
from skyradar.io.atomic import savefig_atomic, write_csv_atomic, write_text_atomic
from skyradar.io.tables import write_table

__all__ = [
    "summary_rows",
    "lead_against_clear_sky",
    "cost_ms_per_frame",
    "summary_markdown",
    "write_report",
    "plot_causes",
]

_STAGES = ("simulate", "process", "track", "alert")
_CAUSE_NAMES = {"missed": "missed (observable)", "below_13db": "below 13 dB SNR"}


def _cause_name(cause: str) -> str:
    return _CAUSE_NAMES.get(cause, cause.replace("_", " "))


def summary_rows(res: pd.DataFrame, late_lead_s: float) -> list[dict[str, Any]]:
    """One summary per terrain and layout, in the table's order.

    When the run has clear sky (terrain ``none``) too, each terrain's row compares its warning
    lead with clear sky's on the same encounters and layout (:func:`lead_against_clear_sky`).
    """
    rows = []
    for (terrain, layout), g in res.groupby(["terrain", "layout"], sort=False):
        row = {"terrain": terrain, "layout": layout, **summarise_layout(g, late_lead_s)}
        if terrain != "none" and "none" in set(res["terrain"]):
            clear = res[(res["terrain"] == "none") & (res["layout"] == layout)]
            row["lead_against_clear_sky"] = lead_against_clear_sky(g, clear)
        rows.append(row)
    return rows


def lead_against_clear_sky(terrain: pd.DataFrame, clear: pd.DataFrame) -> dict[str, Any]:
    """Warning lead over a terrain against clear sky's on the same encounters (one layout each).

    Over the conflicts observable in both that both warned: the median lead of each, and the median
    of the per-encounter difference (terrain minus clear sky, s; negative: the ground cost time).

    Examples
    --------
    >>> clear = pd.DataFrame({"encounter": [0, 1, 2], "observable": True, "t_lowc_s": 100.0,
    ...                       "t_warning_s": [80.0, 85.0, np.nan]})
    >>> hills = clear.assign(t_warning_s=[84.0, 86.0, 90.0])
    >>> lead_against_clear_sky(hills, clear)["median_difference_s"]
    -2.5
    """
    both = terrain.merge(clear, on="encounter", suffixes=("", "_clear"))
    lead = both["t_lowc_s"] - both["t_warning_s"]
    lead_clear = both["t_lowc_s_clear"] - both["t_warning_s_clear"]
    ok = both["observable"] & both["observable_clear"] & lead.notna() & lead_clear.notna()
    ok &= both["t_lowc_s"].notna()
    if not ok.any():
        nan = float("nan")
        return {
            "encounters": 0,
            "median_lead_s": nan,
            "median_lead_clear_sky_s": nan,
            "median_difference_s": nan,
        }
    return {
        "encounters": int(ok.sum()),
        "median_lead_s": float(np.median(lead[ok])),
        "median_lead_clear_sky_s": float(np.median(lead_clear[ok])),
        "median_difference_s": float(np.median((lead - lead_clear)[ok])),
    }


def cost_ms_per_frame(res: pd.DataFrame) -> dict[str, float]:
    """Mean CPU time per frame of each stage, ms (simulate and process: every head of the run,
    counted once per encounter; track and alert: per layout, named ``track_<layout>``).

    Examples
    --------
    >>> res = pd.DataFrame({"terrain": "none", "encounter": [0, 0], "layout": ["single", "three-head"],
    ...     "frames": 100, "simulate_s": 1.0, "process_s": 2.0, "track_s": [0.1, 0.3], "alert_s": 0.0})
    >>> cost_ms_per_frame(res)["process"], cost_ms_per_frame(res)["track_three-head"]
    (20.0, 3.0)
    """
    once = res.drop_duplicates(["terrain", "encounter"])
    frames = float(once["frames"].sum())
    out = {s: round(1000.0 * float(once[f"{s}_s"].sum()) / frames, 2) for s in _STAGES[:2]}
    for layout, g in res.groupby("layout", sort=False):
        for s in _STAGES[2:]:
            out[f"{s}_{layout}"] = round(1000.0 * float(g[f"{s}_s"].sum()) / float(g["frames"].sum()), 2)
    return out


def plot_causes(rows: list[dict[str, Any]], path: Path) -> None:
    """Stacked bars per terrain and layout: conflicts warned before LoWC, and the rest by cause."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(max(5.0, 1.3 * len(rows) + 2.0), 4.5))
    x = np.arange(len(rows))
    bottom = np.zeros(len(rows))
    parts = [("warned before LoWC", "tab:blue", [r["warned_before_lowc"] for r in rows])]
    colours = dict(zip(CAUSES, ("tab:red", "0.3", "0.55", "tab:brown", "0.8"), strict=True))
    parts += [(_cause_name(c), colours[c], [r["unwarned_by_cause"][c] for r in rows]) for c in CAUSES]
    for label, colour, values in parts:
        ax.bar(x, values, bottom=bottom, color=colour, label=label)
        bottom += np.asarray(values, float)
    ax.set_xticks(x, [f"{r['terrain']}\n{r['layout']}" for r in rows], fontsize=8)
    ax.set(ylabel="conflicts")
    fig.suptitle("every conflict: warned before LoWC, or why not", fontsize=10)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=110)
    plt.close(fig)


def _percent(x: float) -> str:
    return "n/a" if not np.isfinite(x) else f"{100.0 * x:.0f} %"


def _number(x: float, decimals: int) -> str:
    return "n/a" if not np.isfinite(x) else f"{x:.{decimals}f}"


def _row_sentence(r: dict[str, Any]) -> str:
    """One terrain and layout's outcome in words."""
    lo, hi = r["warned_before_lowc_fraction_ci95"]
    lead = r["median_warning_lead_s"]
    causes = [f"{n} {_cause_name(c)}" for c, n in r["unwarned_by_cause"].items() if n]
    clutter = int(r["clutter_warnings"])
    where = "In clear sky" if r["terrain"] == "none" else f"Over {r['terrain']}"
    return (
        f"{where} with the {r['layout']} layout, {r['warned_before_lowc']} of "
        f"{r['conflicts']} conflicts were warned before the loss of well clear "
        f"({_percent(r['warned_before_lowc_fraction'])}, 95 % interval {_percent(lo)} to {_percent(hi)})"
        + (f", the median warning {lead:.1f} s before it" if np.isfinite(lead) else "")
        + f"; unwarned: {', '.join(causes) or 'none'}. A warning came in {r['false_warnings']} of the "
        f"{r['must_not_alert_encounters']} encounters that must not alert"
        + _alerter_share(r)
        + f", and {clutter} clutter track{'' if clutter == 1 else 's'} reached a warning"
        + _heard(r)
        + "."
    )


def _heard(r: dict[str, Any]) -> str:
    """How many must-not-alert encounters heard a warning on any track (empty without the count)."""
    heard = r.get("false_warnings_any_track", float("nan"))
    if not isinstance(heard, int):
        return ""
    return f" ({heard} of the encounters that must not alert heard a warning on some track)"


def _alerter_share(r: dict[str, Any]) -> str:
    """How many false warnings perfect surveillance gives too, and how many were first warned on a
    co-altitude prior (empty without the counts)."""
    alerter = r.get("false_warnings_alerter", float("nan"))
    if not isinstance(alerter, int) or not r["false_warnings"]:
        return ""
    prior = r.get("false_warnings_altitude_prior", float("nan"))
    on_prior = f"; {prior} first warned on a co-altitude prior" if isinstance(prior, int) and prior else ""
    return f" ({alerter} of them warned on the true states too: the alerter's, not the sensor's{on_prior})"


def summary_markdown(rows: list[dict[str, Any]], settings: dict[str, Any]) -> str:
    """``summary.md``: the run in sentences and a table, every number from ``rows``.

    Parameters
    ----------
    rows : list of dict
        :func:`summary_rows` of the run.
    settings : dict
        The run's settings (``seed``, ``family``, ``split``, ``frame_rate_hz``), or its
        ``summary.json``, which holds them.

    Returns
    -------
    str
        Markdown: a title, one paragraph per terrain and layout, a table, the figures and data files.

    Examples
    --------
    >>> row = {"terrain": "none", "layout": "single", "encounters": 30, "conflicts": 10,
    ...        "warned_before_lowc": 9, "warned_before_lowc_fraction": 0.9,
    ...        "warned_before_lowc_fraction_ci95": [0.6, 0.98],
    ...        "median_warning_lead_s": 21.5, "unwarned_by_cause": {"missed": 0, "behind": 1},
    ...        "false_warnings": 0, "must_not_alert_encounters": 12, "clutter_warnings": 0,
    ...        "clutter_tracks_per_min": 0.0}
    >>> settings = {"seed": 7, "family": "synthetic", "split": "development", "frame_rate_hz": 4.7}
    >>> print(summary_markdown([row], settings).split("\\n\\n")[2])
    In clear sky with the single layout, 9 of 10 conflicts were warned before the loss of well
    clear (90 %, 95 % interval 60 % to 98 %), the median warning 21.5 s before it; unwarned: 1
    behind. A warning came in 0 of the 12 encounters that must not alert, and 0 clutter tracks
    reached a warning.
    """
    intro = (
        f"{rows[0]['encounters']} encounters per terrain and layout, at {settings['frame_rate_hz']:g} "
        "frames per second, each flown through the whole chain (simulate, process, track, alert)."
    )
    figures = (
        "Figures: `encounters.png` (each encounter's miss distances coloured by outcome, and the "
        "warning lead), `causes.png` (every conflict: warned before its loss of well clear, or why "
        "not), `sensor_<terrain>_<layout>.png` (what the radar saw of each intruder)."
    )
    data = (
        "Data: `summary.json` (every number, with the command, version and machine load), "
        "`summary_rows.csv` (one row per terrain and layout), `encounters.parquet` and "
        "`encounters.csv` (one row per encounter)."
    )
    title = f"# Encounters: {settings['family']}, seed {settings['seed']} ({settings['split']} set)"
    paragraphs = [title, intro, *(_row_sentence(r) for r in rows)]
    lines = [line for text in paragraphs for line in (textwrap.fill(text, 100), "")]
    lines += [
        "| terrain | layout | conflicts | warned before LoWC | 95 % interval | median lead [s] | false "
        "warnings | clutter tracks per minute |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lo, hi = r["warned_before_lowc_fraction_ci95"]
        lines.append(
            f"| {r['terrain']} | {r['layout']} | {r['conflicts']} | {r['warned_before_lowc']} "
            f"({_percent(r['warned_before_lowc_fraction'])}) | {_percent(lo)} to {_percent(hi)} | "
            f"{_number(r['median_warning_lead_s'], 1)} | {r['false_warnings']} of "
            f"{r['must_not_alert_encounters']} | {_number(r['clutter_tracks_per_min'], 2)} |"
        )
    lines += ["", textwrap.fill(figures, 100), "", textwrap.fill(data, 100), ""]
    return "\n".join(lines)


def write_report(
    res: pd.DataFrame, out_dir: Path, settings: dict, late_lead_s: float, warning_time_s: float
) -> dict[str, Any]:
    """Write the tables and figures of a finished run into ``out_dir``; return the summary (without
    runtime): the first terrain's last layout at the top level, every row under ``rows``."""
    rows = summary_rows(res, late_lead_s)
    write_text_atomic(out_dir / "summary.md", summary_markdown(rows, settings))
    buffer = settings["buffer"]
    write_table(res, out_dir / "encounters.parquet")
    # The per-encounter track-error samples stay in the Parquet table (lists do not fit a CSV cell).
    write_csv_atomic(
        res.drop(columns=["track_errors"], errors="ignore"), out_dir / "encounters.csv", index=False
    )
    flat = [{k: v for k, v in r.items() if not isinstance(v, dict)} for r in rows]
    write_csv_atomic(pd.DataFrame(flat), out_dir / "summary_rows.csv", index=False)
    first = res["terrain"].iloc[0]
    primary = [r for r in rows if r["terrain"] == first][-1]
    for r in rows:
        g = res[(res["terrain"] == r["terrain"]) & (res["layout"] == r["layout"])]
        name = "encounters.png" if r is primary else f"encounters_{r['terrain']}_{r['layout']}.png"
        plot_encounters(g, out_dir / name, buffer, warning_time_s)
        plot_sensor_figures(
            g, out_dir / f"sensor_{r['terrain']}_{r['layout']}.png", f"{r['terrain']}, {r['layout']}"
        )
    plot_causes(rows, out_dir / "causes.png")
    once = res.drop_duplicates(["terrain", "encounter"])
    mine = res[(res["terrain"] == first) & (res["layout"] == primary["layout"])]
    return {
        **primary,
        "chain": "full",
        **{k: v for k, v in settings.items() if k not in ("n",)},
        "frames": int(once["frames"].sum()),
        "cost_ms_per_frame": cost_ms_per_frame(res),
        "other_track_warnings": int(mine["t_other_warning_s"].notna().sum()),
        "rows": rows,
    }
