"""ch5 table and figures: estimates versus truth over time, error table per terrain and method."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from skyradar.io.atomic import savefig_atomic  # noqa: E402

__all__ = ["plot_case", "summary_table", "acceptance_failures"]

_STYLE = {
    "thesis": ("tab:red", "thesis"),
    "robust": ("tab:blue", "robust"),
    "terrain": ("tab:green", "terrain-aware"),
    "terrain_ahrs": ("tab:olive", "terrain-aware, AHRS attitude"),
}


def plot_case(path: Path, flight, tables: dict[str, pd.DataFrame], title: str) -> Path:
    """Three panels (H, V_X, V_Z) of filtered estimates (lines) and raw estimates (dots) vs truth.

    ``tables`` maps a key of ``_STYLE`` (method, or ``terrain_ahrs``) to its state table.
    """
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
    savefig_atomic(fig, path, dpi=90)
    plt.close(fig)
    return path


def summary_table(
    by_source: dict[str, dict[str, Any]], thesis: dict[str, tuple[float, float]]
) -> pd.DataFrame:
    """One row per (attitude source, rate, terrain, method): errors, valid fractions, thesis numbers.

    ``by_source`` maps the attitude the estimators got (``true``, ``ahrs``) to
    ``{rate: {terrain: {method: errors}}}``.

    Examples
    --------
    >>> err = {"h_err_mean_m": 2.0, "valid_fraction": 1.0}
    >>> t = summary_table({"true": {"rate_1hz": {"flat": {"robust": err}}}}, {"flat": (8.5, 6.5)})
    >>> t[["attitude", "terrain", "method", "valid_fraction"]].to_dict("records")
    [{'attitude': 'true', 'terrain': 'flat', 'method': 'robust', 'valid_fraction': 1.0}]
    """
    rows = []
    for source, results in by_source.items():
        for rate, per_terrain in results.items():
            for terrain, per_method in per_terrain.items():
                for method, err in per_method.items():
                    ref = thesis.get(terrain, (float("nan"), float("nan")))
                    rows.append(
                        {
                            "attitude": source,
                            "rate": rate,
                            "terrain": terrain,
                            "method": method,
                            **err,
                            "thesis_h_err_mean_m": ref[0],
                            "thesis_h_err_sd_m": ref[1],
                        }
                    )
    return pd.DataFrame(rows)


def _number(value: Any) -> float:
    """A table value as a float: None (JSON null) and NaN both mean "no estimate"."""
    return float("nan") if value is None else float(value)


def acceptance_failures(
    by_source: dict[str, dict[str, dict[str, dict[str, Any]]]],
    envelope: dict[tuple[str, str], tuple[float, float] | None],
) -> list[str]:
    """Every (attitude, terrain, method) case that misses its stated bound; empty when all hold.

    ``by_source`` maps the attitude source to ``{terrain: {method: errors}}`` (one rate).
    ``envelope[(terrain, method)]`` is ``(min_valid_fraction, min_raw_valid_fraction)`` for a case
    that must estimate (and then also needs finite errors), or None for a case stated to give no
    estimate (``valid_fraction`` must then be 0). A case missing from ``envelope`` fails: nothing
    is left unjudged.

    Examples
    --------
    >>> ok = {"h_err_mean_m": 2.0, "h_err_sd_m": 0.3, "vx_err_sd_mps": 0.01, "vz_err_sd_mps": 0.03,
    ...       "valid_fraction": 1.0, "raw_valid_fraction": 1.0}
    >>> nothing = {**ok, "h_err_mean_m": float("nan"), "valid_fraction": 0.0, "raw_valid_fraction": 0.0}
    >>> bounds = {("flat", "robust"): (0.9, 0.8)}
    >>> acceptance_failures({"true": {"flat": {"robust": ok}}}, bounds)
    []
    >>> for line in acceptance_failures({"true": {"flat": {"robust": nothing}}}, bounds):
    ...     print(line)
    true/flat/robust: valid_fraction 0 < 0.9
    true/flat/robust: raw_valid_fraction 0 < 0.8
    true/flat/robust: h_err_mean_m is not finite
    """
    failures = []
    for source, per_terrain in by_source.items():
        for terrain, per_method in per_terrain.items():
            for method, err in per_method.items():
                case = f"{source}/{terrain}/{method}"
                if (terrain, method) not in envelope:
                    failures.append(f"{case}: no stated bound")
                    continue
                bound = envelope[(terrain, method)]
                valid = _number(err.get("valid_fraction"))
                if bound is None:
                    if valid != 0.0:
                        failures.append(f"{case}: stated to give no estimate, valid_fraction {valid:g}")
                    continue
                for key, low in zip(("valid_fraction", "raw_valid_fraction"), bound, strict=True):
                    value = _number(err.get(key))
                    if not value >= low:  # NaN fails too
                        failures.append(f"{case}: {key} {value:g} < {low:g}")
                for key in ("h_err_mean_m", "h_err_sd_m", "vx_err_sd_mps", "vz_err_sd_mps"):
                    if not np.isfinite(_number(err.get(key))):
                        failures.append(f"{case}: {key} is not finite")
    return failures
