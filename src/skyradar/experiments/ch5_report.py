"""ch5 table, figures and summary: estimates versus truth over time, error table per terrain and method."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from skyradar.experiments.summary_md import counted, number, page  # noqa: E402
from skyradar.io.atomic import savefig_atomic  # noqa: E402

__all__ = ["plot_case", "summary_table", "acceptance_failures", "summary_markdown"]

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


_METHOD_NAMES = {"thesis": "thesis method", "robust": "robust", "terrain": "terrain-aware"}


def _height_error(err: dict[str, Any] | None) -> str:
    """``mean +- SD`` of a case's filtered height error, m (``n/a`` when it gave no estimate)."""
    if err is None or number(err.get("h_err_mean_m")) == "n/a":
        return "no estimate"
    return f"{number(err.get('h_err_mean_m'))} +- {number(err.get('h_err_sd_m'))}"


def summary_markdown(results: dict[str, Any], out_dir: Path | None = None) -> str:
    """``summary.md`` of a ch5 run: each method's height error per terrain beside the thesis'.

    Parameters
    ----------
    results : dict
        The summary ``skyradar.experiments.ch5.run`` returns (also in ``ch5.json``): ``rate_1hz``
        and ``rate_9p4hz`` (``{terrain: {method: errors}}``, true attitude), ``ahrs`` (the same with
        the AHRS attitude, or None), ``thesis_table``, ``acceptance_failures``, ``duration_s``.
    out_dir : Path, optional
        The run's folder: only the files present there are listed (None: all of them).

    Returns
    -------
    str
        Markdown: title, sentences, one table row per terrain at one frame per second, the files.

    Examples
    --------
    >>> e = {"h_err_mean_m": 1.2, "h_err_sd_m": 0.8, "valid_fraction": 1.0}
    >>> res = {"rate_1hz": {"flat": {"thesis": e, "robust": e, "terrain": e}}, "rate_9p4hz": {},
    ...        "ahrs": {"rate_1hz": {"flat": {"terrain": {**e, "h_err_mean_m": 2.5}}}},
    ...        "thesis_table": {"flat": {"h_err_mean_m": 8.5, "h_err_sd_m": 6.5}},
    ...        "acceptance_failures": [], "duration_s": 40.0}
    >>> text = summary_markdown(res)
    >>> print(text.splitlines()[0])
    # ch5: own-ship flight state from ground returns
    >>> "| flat | 1.2 +- 0.8 | 1.2 +- 0.8 | 1.2 +- 0.8 | 2.5 +- 0.8 | 8.5 +- 6.5 |" in text
    True
    >>> "`ch5_flat_rate_1hz.png`" in text
    True
    """
    one_hz, thesis = results["rate_1hz"], results.get("thesis_table", {})
    ahrs = (results.get("ahrs") or {}).get("rate_1hz", {})
    rows = [
        [
            terrain,
            *(_height_error(per.get(m)) for m in _METHOD_NAMES),
            _height_error(ahrs.get(terrain, {}).get("terrain")) if ahrs else "n/a",
            _height_error(thesis.get(terrain)),
        ]
        for terrain, per in one_hz.items()
    ]
    header = [
        "terrain",
        *(f"{name} [m]" for name in _METHOD_NAMES.values()),
        "terrain-aware, AHRS attitude [m]",
        "thesis [m]",
    ]
    best = []
    for terrain, per in one_hz.items():
        rms = {
            m: np.hypot(_number(e.get("h_err_mean_m")), _number(e.get("h_err_sd_m"))) for m, e in per.items()
        }
        scored = {m: e for m, e in per.items() if np.isfinite(rms[m])}
        if scored:
            method, err = min(scored.items(), key=lambda kv: rms[kv[0]])
            ref = thesis.get(terrain)
            best.append(
                f"{terrain}: {_METHOD_NAMES.get(method, method)} {_height_error(err)} m"
                + (f" (thesis {_height_error(ref)} m)" if ref else "")
            )
        else:
            best.append(f"{terrain}: no method estimates")
    failures = results.get("acceptance_failures") or []
    fast = results.get("rate_9p4hz") or {}
    paragraphs = [
        f"A terrain-following flight, {number(results['duration_s'], 0)} s at one frame per second "
        f"over {counted(len(one_hz), 'terrain')}"
        + (f" (and {len(fast)} of them at the 9.4 Hz field rate)" if fast else "")
        + ", its height above ground and velocity estimated from the ground returns by three methods, "
        "each filtered; errors are the filtered estimate minus the truth after the filter's warm-up.",
        "Height error (mean +- SD) of the method with the smallest RMS error per terrain: "
        + "; ".join(best)
        + ". "
        + (
            "Every case meets its stated share of estimated frames."
            if not failures
            else f"{len(failures)} cases miss their stated share of estimated frames (listed in `ch5.json`)."
        )
        + " The figures show each estimate against the truth over the flight.",
    ]
    files = {
        f"ch5_{terrain}_{rate}.png": f"{terrain} at {'1' if rate == 'rate_1hz' else '9.4'} Hz: each "
        "method's height and velocity against the truth"
        for rate in ("rate_1hz", "rate_9p4hz")
        for terrain in results.get(rate) or {}
    }
    files |= {
        "ch5_table.csv": "one row per attitude source, rate, terrain and method: errors and shares of "
        "frames estimated, the thesis' numbers beside them",
        "ch5.json": "every measured value",
        "state_<terrain>_<rate>_<method>.parquet": "each estimated state per frame, with the truth "
        "(`_ahrs`: estimated with the AHRS attitude)",
    }
    title = "ch5: own-ship flight state from ground returns"
    return page(title, paragraphs, header, rows, files, out_dir)
