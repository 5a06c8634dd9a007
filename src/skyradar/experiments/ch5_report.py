"""ch5 table and figures: estimates versus truth over time, error table per terrain and method."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

__all__ = ["plot_case", "summary_table"]

_STYLE = {
    "thesis": ("tab:red", "thesis"),
    "robust": ("tab:blue", "robust"),
    "terrain": ("tab:green", "terrain-aware"),
}


def plot_case(path: Path, flight, tables: dict[str, pd.DataFrame], title: str) -> Path:
    """Three panels (H, V_X, V_Z) of filtered estimates (lines) and raw estimates (dots) vs truth."""
    fig, axes = plt.subplots(3, 1, figsize=(9, 9), sharex=True)
    truth = (flight.height_agl_m, flight.vx_mps, flight.vz_mps)
    names = (
        ("h_m", "h_raw_m", "height above ground [m]"),
        ("vx_mps", "vx_raw_mps", "V_X [m/s]"),
        ("vz_mps", "vz_raw_mps", "V_Z (down) [m/s]"),
    )
    for ax, (col, raw, label), true in zip(axes, names, truth, strict=True):
        ax.plot(flight.times_s, true, "k-", lw=2, label="truth")
        for method, table in tables.items():
            color, name = _STYLE[method]
            ax.plot(table["time_s"], table[raw], ".", color=color, ms=3, alpha=0.5)
            ax.plot(table["time_s"], table[col], "-", color=color, lw=1.2, label=f"{name} (filtered)")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    lo, hi = flight.height_agl_m.min(), flight.height_agl_m.max()
    axes[0].set_ylim(lo - 150, hi + 150)
    axes[0].legend(fontsize=8, ncol=4, loc="upper right")
    axes[-1].set_xlabel("time [s]")
    fig.suptitle(f"ch5 own-ship state from ground returns: {title} (dots raw, lines filtered)")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def summary_table(results: dict[str, Any], thesis: dict[str, tuple[float, float]]) -> pd.DataFrame:
    """One row per (rate, terrain, method) with the filtered and raw errors and the thesis' numbers."""
    rows = []
    for rate, per_terrain in results.items():
        for terrain, per_method in per_terrain.items():
            for method, err in per_method.items():
                ref = thesis.get(terrain, (float("nan"), float("nan")))
                rows.append(
                    {
                        "rate": rate,
                        "terrain": terrain,
                        "method": method,
                        **err,
                        "thesis_h_err_mean_m": ref[0],
                        "thesis_h_err_sd_m": ref[1],
                    }
                )
    return pd.DataFrame(rows)
