"""Figures and the summary rows of ``skyradar experiment clutter`` (:mod:`skyradar.experiments.clutter`)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

from skyradar.io.atomic import savefig_atomic  # noqa: E402

__all__ = ["plot_sinr_loss", "plot_track", "summary_rows"]


def plot_sinr_loss(path: Path, curves: pd.DataFrame, threshold_db: float, title: str) -> Path:
    """SINR loss (dB) against radial velocity (m/s) of one terrain case, with and without suppression."""
    fig, ax = plt.subplots(figsize=(8, 3.4))
    ax.plot(curves.radial_velocity_mps, curves.sinr_loss_none_db, color="0.5", label="no suppression")
    v = curves.radial_velocity_mps
    ax.plot(v, curves.sinr_loss_suppressed_db, color="C0", label="knowledge-aided projection")
    ax.axhline(threshold_db, color="C3", lw=0.8, ls="--", label=f"{threshold_db:g} dB")
    ax.set_ylabel("SINR loss, dB")
    ax.set_ylim(min(-45.0, float(curves.sinr_loss_none_db.min()) - 2), 3)
    ax.set_title(f"{title}; 50 m/s, boresight target, 1.3-5 km", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower left")
    ax.set_xlabel("radial velocity (aliased), m/s")
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=90)
    plt.close(fig)
    return path


def plot_track(path: Path, frames: pd.DataFrame, title: str) -> Path:
    """Intruder SNR, the clutter and the improvement factor in its cell and its CFAR window (dB)
    against its range (m) in one terrain case, hits marked."""
    f = frames
    fig, ax = plt.subplots(figsize=(6, 3.8))
    ax.plot(f.range_m, f.snr_db, "k-", lw=1, label="intruder SNR")
    ax.plot(f.range_m, f.window_cnr_db, color="0.6", label="clutter in its CFAR window (CNR)")
    ax.plot(f.range_m, f.window_if_db, color="C0", label="improvement factor there")
    ax.plot(f.range_m, f.cell_cnr_db, color="0.6", ls=":", label="clutter in its cell (CNR)")
    ax.plot(f.range_m, f.cell_if_db, color="C1", ls=":", label="improvement factor in its cell")
    ax.plot(f.range_m[f.hit_plain], f.snr_db[f.hit_plain], "s", mfc="none", color="0.3", label="hit, none")
    extra = f.hit_suppressed_secondary & ~f.hit_suppressed
    ax.plot(f.range_m[extra], f.snr_db[extra], "x", color="C1", label="hit, suppressed (secondary)")
    ax.plot(f.range_m[f.hit_suppressed], f.snr_db[f.hit_suppressed], ".", color="C0", label="hit, suppressed")
    ax.set_xlabel("intruder range, m")
    ax.set_ylabel("dB")
    ax.set_title(f"head-on intruder; {title}", fontsize=9)
    ax.grid(alpha=0.3)
    ax.invert_xaxis()
    ax.legend(fontsize=6)
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=90)
    plt.close(fig)
    return path


def summary_rows(cases: dict[str, dict[str, Any]]) -> list[dict[str, Any]]:
    """One row per terrain case (for the table printed by the CLI and the README); ``cases`` maps
    the terrain to its figures of merit."""
    rows = []
    for terrain, case in cases.items():
        with_secondary = case["detection_fraction_suppressed_with_secondary"]
        rows.append(
            {
                "terrain": terrain,
                "own_agl_m": case["own_agl_m_median"],
                "hits_none": case["intruder_hits_none"],
                "hits_suppressed": case["intruder_hits_suppressed"],
                "frames": case["frames"],
                "visible_frames": case["visible_frames"],
                "detection_fraction_none": case["detection_fraction_none"],
                "detection_fraction_suppressed": case["detection_fraction_suppressed"],
                "detection_fraction_suppressed_with_secondary": with_secondary,
                "intruder_cell_if_db_median": case["intruder_cell_if_db_median"],
                "intruder_cell_if_db_min": case["intruder_cell_if_db_min"],
                "intruder_cell_clutter_frames": case["intruder_cell_clutter_frames"],
                "intruder_cell_if_db_median_clutter": case["intruder_cell_if_db_median_clutter"],
                "if_db_lost_cells_median": case["if_db_lost_cells_median"],
                "if_db_lost_cells_min": case["if_db_lost_cells_min"],
                "lost_frames_with_cells": case["lost_frames_with_cells"],
                "target_gain_db_lost_cells": case["lost_cells_target_gain_db_median"],
                "if_db_where_lost_median": case["lost_window_if_db_median"],
                "if_db_where_lost_min": case["lost_window_if_db_min"],
                "mdv_mps_none": case["mdv_mps_none"],
                "mdv_mps_suppressed": case["mdv_mps_suppressed"],
                "udsf_none": case["usable_doppler_fraction_none"],
                "udsf_suppressed": case["usable_doppler_fraction_suppressed"],
            }
        )
    return rows
