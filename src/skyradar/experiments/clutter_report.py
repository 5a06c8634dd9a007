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


def plot_sinr_loss(path: Path, curves: pd.DataFrame, threshold_db: float) -> Path:
    """SINR loss against radial velocity, with and without suppression, one panel per height."""
    heights = sorted(curves.height_m.unique(), reverse=True)
    fig, axes = plt.subplots(len(heights), 1, figsize=(8, 3.2 * len(heights)), sharex=True, squeeze=False)
    for ax, height in zip(axes[:, 0], heights, strict=True):
        c = curves[curves.height_m == height]
        ax.plot(c.radial_velocity_mps, c.sinr_loss_none_db, color="0.5", label="no suppression")
        ax.plot(
            c.radial_velocity_mps, c.sinr_loss_suppressed_db, color="C0", label="knowledge-aided projection"
        )
        ax.axhline(threshold_db, color="C3", lw=0.8, ls="--", label=f"{threshold_db:g} dB")
        ax.set_ylabel("SINR loss, dB")
        ax.set_ylim(min(-45.0, float(c.sinr_loss_none_db.min()) - 2), 3)
        ax.set_title(f"flat ground {height:g} m below, 50 m/s, boresight target, 1.3-5 km", fontsize=9)
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=8, loc="lower left")
    axes[-1, 0].set_xlabel("radial velocity (aliased), m/s")
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=90)
    plt.close(fig)
    return path


def plot_track(path: Path, frames: pd.DataFrame) -> Path:
    """Intruder SNR and clutter in its CFAR window against range, hits marked, per height."""
    heights = sorted(frames.height_m.unique(), reverse=True)
    fig, axes = plt.subplots(1, len(heights), figsize=(5 * len(heights), 3.4), squeeze=False)
    for ax, height in zip(axes[0], heights, strict=True):
        f = frames[frames.height_m == height]
        ax.plot(f.range_m, f.snr_db, "k-", lw=1, label="intruder SNR")
        ax.plot(f.range_m, f.window_cnr_db, color="0.6", label="clutter in its CFAR window (CNR)")
        ax.plot(f.range_m, f.window_if_db, color="C0", label="improvement factor there")
        ax.plot(
            f.range_m[f.hit_plain], f.snr_db[f.hit_plain], "s", mfc="none", color="0.3", label="hit, none"
        )
        ax.plot(
            f.range_m[f.hit_suppressed], f.snr_db[f.hit_suppressed], ".", color="C0", label="hit, suppressed"
        )
        ax.set_xlabel("intruder range, m")
        ax.set_ylabel("dB")
        ax.set_title(f"head-on intruder, ground {height:g} m below", fontsize=9)
        ax.grid(alpha=0.3)
        ax.invert_xaxis()
    axes[0, 0].legend(fontsize=7)
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=90)
    plt.close(fig)
    return path


def summary_rows(result: dict[str, Any], heights_m) -> list[dict[str, Any]]:
    """One row per height (for the table printed by the CLI and the README)."""
    rows = []
    for height in heights_m:
        key = f"h{float(height):g}"
        rows.append({
            "height_m": float(height),
            "hits_none": result[f"{key}_intruder_hits_none"],
            "hits_suppressed": result[f"{key}_intruder_hits_suppressed"],
            "frames": result[f"{key}_frames"],
            "if_db_lost_cells_median": result[f"{key}_if_db_lost_cells_median"],
            "if_db_lost_cells_min": result[f"{key}_if_db_lost_cells_min"],
            "lost_frames_with_cells": result[f"{key}_lost_frames_with_cells"],
            "target_gain_db_lost_cells": result[f"{key}_lost_cells_target_gain_db_median"],
            "if_db_where_lost_median": result[f"{key}_lost_window_if_db_median"],
            "if_db_where_lost_min": result[f"{key}_lost_window_if_db_min"],
            "mdv_mps_none": result[f"{key}_mdv_mps_none"],
            "mdv_mps_suppressed": result[f"{key}_mdv_mps_suppressed"],
            "udsf_none": result[f"{key}_usable_doppler_fraction_none"],
            "udsf_suppressed": result[f"{key}_usable_doppler_fraction_suppressed"],
        })  # fmt: skip
    return rows
