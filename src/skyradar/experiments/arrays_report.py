"""The receive-array study's report (:mod:`skyradar.experiments.arrays`): ``summary.md`` and the figures.

Every number comes from the study's result: warning rates with their intervals per array and
terrain, DoA error against its bound, SINR loss against Doppler, frames per second.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from skyradar.experiments.arrays import LOSS_THRESHOLD_DB
from skyradar.experiments.summary_md import counted, markdown_table, number, page
from skyradar.io.atomic import savefig_atomic
from skyradar.units import wrap

__all__ = ["summary_markdown", "plot_warnings", "plot_doa", "plot_doppler", "plot_frames_per_s"]


def _interval(ci: Sequence[float]) -> str:
    lo, hi = ci  # None where the JSON holds a NaN (no trials)
    return "n/a" if lo is None or not np.isfinite(lo) else f"{100 * lo:.0f}-{100 * hi:.0f} %"


def summary_markdown(result: dict[str, Any], out_dir: Path | None = None) -> str:
    """``summary.md`` of a study: the run in sentences, one table row per array and terrain, and
    one per array of the sensor's own figures; every number from ``result``."""
    rows, per_array = result["rows"], result["per_array"]
    intro = (
        f"{counted(result['n'], 'encounter')} (seed {result['seed']}, {result['split']} split) per array "
        "and terrain, "
        f"the same encounters for every array, each simulated with its own receive channels and flown "
        f"through the whole chain with the single forward head at {result['frame_rate_hz']:g} frames per "
        "second. Intervals are 95 % Wilson intervals; with a handful of encounters they are wide."
    )
    sensor = (
        f"Per array: minimum detectable velocity (MDV) and usable Doppler fraction of a boresight target "
        f"after the processing's clutter nulls over flat ground {result['notch_height_m']:g} m below "
        f"(SINR loss at least {LOSS_THRESHOLD_DB:g} dB); RMS DoA error of {result['doa_trials']} "
        f"pixels at {', '.join(f'{s:g}' for s in result['doa_snrs_db'])} dB per-channel SNR over its "
        "Cramer-Rao bound; detection and DoA frames per second of one head (measured in this run)."
    )
    header = [
        "array",
        "terrain",
        "missed",
        "late",
        "false warnings",
        "median lead [s]",
        "ground tracks/min",
        "clutter tracks/min",
        "fragments/intruder",
    ]
    table = [
        [
            r["array"],
            r["terrain"],
            f"{r['missed_warnings']} of {r['observable_conflicts']} "
            f"({_interval(r['missed_warning_rate_ci95'])})",
            f"{r['late_warnings']} of {r['observable_conflicts']} ({_interval(r['late_warning_rate_ci95'])})",
            f"{r['false_warnings']} of {r['must_not_alert_encounters']} "
            f"({_interval(r['false_warning_rate_ci95'])})",
            number(r["median_warning_lead_s"]),
            number(r["ground_tracks_per_min"], 2),
            number(r["clutter_tracks_per_min"], 2),
            number(r["fragments_per_intruder_median"]),
        ]
        for r in rows
    ]
    files = {
        "arrays.parquet": "one row per array and terrain (also `arrays.csv`)",
        "doa.csv": "DoA error and bound per array and SNR",
        "doppler.csv": "SINR loss per array and Doppler bin",
        "arrays_warnings.png": "missed, late and false warning rates with their intervals",
        "arrays_doa.png": "DoA error against the Cramer-Rao bound per array",
        "arrays_doppler.png": "SINR loss against Doppler per array, MDV marked",
        "arrays_frames_per_s.png": "processing frames per second per array",
        "encounters_<array>/summary.md": "each array's encounter run (its own summary, tables, figures)",
        "summary.json": "every number, with the command, version and machine load",
    }
    text = page(
        f"Receive arrays: {', '.join(result['arrays'])}", [intro, sensor], header, table, files, out_dir
    )
    snr_hi = max(result["doa_snrs_db"])
    sensor_table = markdown_table(
        [
            "array",
            "channels",
            "MDV [m/s]",
            "MDV into ground band [m/s]",
            "usable Doppler",
            f"az error / bound at {snr_hi:g} dB",
            f"el error / bound at {snr_hi:g} dB",
            "frames/s",
        ],
        [
            [
                a["array"],
                a["channels"],
                number(a["mdv_mps"], 2),
                number(a["mdv_into_ground_band_mps"], 1),
                number(a["usable_doppler_fraction"], 2),
                number(a["doa"][-1]["azimuth_over_bound"], 2),
                number(a["doa"][-1]["elevation_over_bound"], 2),
                number(a["frames_per_s"]),
            ]
            for a in per_array
        ],
    )
    head, sep, tail = text.partition("Files in this folder:")
    return f"{head}{sensor_table}\n\n{sep}{tail}" if sep else f"{text}\n{sensor_table}\n"


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_warnings(rows: list[dict], path: Path) -> None:
    """Missed, late and false warning rates per array and terrain with their 95 % intervals (PNG)."""
    plt = _plt()
    fig, axes = plt.subplots(1, 3, figsize=(max(9.0, 1.2 * len(rows) * 3), 4.0), sharey=True)
    x = np.arange(len(rows))
    labels = [f"{r['array']}\n{r['terrain']}" for r in rows]
    for ax, (key, title) in zip(
        axes,
        (
            ("missed_warning", "missed (observable conflicts)"),
            ("late_warning", "late"),
            ("false_warning", "false (must not alert)"),
        ),
        strict=True,
    ):
        ci = np.array([r[f"{key}_rate_ci95"] for r in rows], float)
        # No trials (an interval of NaN): no rate to show, rather than the 0 of 0 the count gives.
        rate = np.where(np.isnan(ci[:, 0]), np.nan, np.array([r[f"{key}_rate"] for r in rows], float))
        for i in np.flatnonzero(np.isnan(rate)):
            ax.annotate("no trials", (x[i], 2.0), ha="center", fontsize=7, color="0.4")
        ax.set_xlim(-0.5, len(rows) - 0.5)
        err = np.abs(np.vstack([rate - ci[:, 0], ci[:, 1] - rate]))
        ax.errorbar(x, 100 * rate, yerr=100 * np.nan_to_num(err), fmt="o", capsize=4)
        ax.set_xticks(x, labels, fontsize=7)
        ax.set_title(title, fontsize=9)
        ax.set_ylim(-2, 102)
    axes[0].set_ylabel("rate [%] (95 % interval)")
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=110)
    plt.close(fig)


def plot_doa(per_array: list[dict], path: Path) -> None:
    """RMS DoA error (markers) and its Cramer-Rao bound (lines) against SNR per array (PNG)."""
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(9.0, 4.0))
    for k, a in enumerate(per_array):
        colour = f"C{k}"
        snr = [d["snr_db"] for d in a["doa"]]
        for ax, angle in zip(axes, ("azimuth", "elevation"), strict=True):
            ax.semilogy(snr, [d[f"rms_{angle}_deg"] for d in a["doa"]], "o", color=colour, label=a["array"])
            ax.semilogy(snr, [d[f"bound_{angle}_deg"] for d in a["doa"]], "-", color=colour)
    for ax, angle in zip(axes, ("azimuth", "elevation"), strict=True):
        ax.set(
            xlabel="per-channel SNR [dB]",
            ylabel=f"{angle} error [deg]",
            title=f"{angle}: RMS (o), bound (line)",
        )
        ax.legend(fontsize=8)
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=110)
    plt.close(fig)


def plot_doppler(curves: list[pd.DataFrame], per_array: list[dict], path: Path) -> None:
    """SINR loss of a boresight target against Doppler after the processing's nulls, per array (PNG)."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8.0, 4.0))
    for k, (curve, a) in enumerate(zip(curves, per_array, strict=True)):
        into, usable = number(a["mdv_into_ground_band_mps"], 1), number(a["usable_doppler_fraction"], 2)
        label = f"{a['array']} (MDV into the ground band {into} m/s, usable {usable})"
        ax.plot(curve["radial_velocity_mps"], curve["sinr_loss_suppressed_db"], color=f"C{k}", label=label)
    ax.axhline(LOSS_THRESHOLD_DB, color="k", ls="--", lw=0.8)
    v_lim = float(np.max(np.abs(curves[0]["radial_velocity_mps"])))
    ax.axvline(float(wrap(per_array[0]["main_beam_clutter_mps"], 2.0 * v_lim)), color="0.5", ls=":", lw=0.8)
    ax.set(xlabel="radial velocity [m/s]", ylabel="SINR loss [dB]", ylim=(-40, 2))
    ax.set_title("boresight target after clutter suppression (dotted: main-beam clutter)", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=110)
    plt.close(fig)


def plot_frames_per_s(per_array: list[dict], path: Path) -> None:
    """Detection and DoA frames per second of one head per array, wall clock and per CPU second (PNG)."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(max(4.0, 1.5 * len(per_array) + 1.5), 3.5))
    x = np.arange(len(per_array))
    ax.bar(x - 0.2, [a["frames_per_s"] for a in per_array], 0.4, label="wall clock")
    ax.bar(x + 0.2, [a["cpu_frames_per_s"] for a in per_array], 0.4, label="per CPU second")
    ax.set_xticks(x, [f"{a['array']}\n{a['channels']} ch" for a in per_array], fontsize=8)
    ax.set(ylabel="frames/s")
    ax.set_title("detection + DoA, one head (measured)", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=110)
    plt.close(fig)
