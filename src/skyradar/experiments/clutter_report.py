"""Figures, summary rows and ``summary.md`` of ``skyradar experiment clutter``.

The experiment itself is :mod:`skyradar.experiments.clutter`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

from skyradar.experiments.summary_md import number, page  # noqa: E402
from skyradar.io.atomic import savefig_atomic  # noqa: E402

__all__ = ["plot_sinr_loss", "plot_track", "summary_rows", "summary_markdown"]


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


def _percent(fraction: Any) -> str:
    return "n/a" if number(fraction) == "n/a" else f"{number(100.0 * float(fraction), 0)} %"


def _figure_note(name: str) -> str:
    terrain = name.rsplit("_", 1)[-1].removesuffix(".png")
    if name.startswith("sinr_loss_"):
        return f"{terrain}: SINR loss against Doppler without and with suppression"
    return f"{terrain}: the intruder's detections along its approach, without and with suppression"


def summary_markdown(result: dict[str, Any], out_dir: Path | None = None) -> str:
    """``summary.md`` of a clutter run: per terrain, what suppression buys at the head-on intruder.

    Parameters
    ----------
    result : dict
        The summary ``skyradar.experiments.clutter.run`` returns (also in ``summary.json``): ``rows``
        (:func:`summary_rows`), ``figures``, ``frames_per_case``, ``seed``.
    out_dir : Path, optional
        The run's folder: only the files present there are listed (None: all of them).

    Returns
    -------
    str
        Markdown: title, one sentence per terrain, one table row per terrain, the files.

    Examples
    --------
    >>> row = {"terrain": "flat-1000", "own_agl_m": 1000.1, "visible_frames": 20,
    ...        "detection_fraction_none": 0.0, "detection_fraction_suppressed": 0.6,
    ...        "detection_fraction_suppressed_with_secondary": 0.8, "if_db_lost_cells_median": 27.4,
    ...        "lost_frames_with_cells": 5, "intruder_cell_if_db_median": 12.2,
    ...        "mdv_mps_none": 3.4, "mdv_mps_suppressed": 0.04, "udsf_none": 0.456, "udsf_suppressed": 1.0}
    >>> r = {"rows": [row], "frames_per_case": 24, "seed": 0,
    ...      "figures": ["out/sinr_loss_flat-1000.png", "out/intruder_flat-1000.png"]}
    >>> text = summary_markdown(r)
    >>> print(text.splitlines()[0])
    # clutter: knowledge-aided suppression under a head-on intruder
    >>> "| flat-1000 | 1000 | 0 % / 60 % / 80 % | 27.4 | 12.2 | 3.40 / 0.04 | 46 % / 100 % |" in text
    True
    >>> "`sinr_loss_flat-1000.png`" in text
    True
    """
    rows, table = result["rows"], []
    sentences = []
    for r in rows:
        detected = (
            f"{_percent(r['detection_fraction_none'])} / {_percent(r['detection_fraction_suppressed'])} / "
            f"{_percent(r['detection_fraction_suppressed_with_secondary'])}"
        )
        table.append(
            [
                r["terrain"],
                number(r["own_agl_m"], 0),
                detected,
                number(r["if_db_lost_cells_median"]),
                number(r["intruder_cell_if_db_median"]),
                f"{number(r['mdv_mps_none'], 2)} / {number(r['mdv_mps_suppressed'], 2)}",
                f"{_percent(r['udsf_none'])} / {_percent(r['udsf_suppressed'])}",
            ]
        )
        sentences.append(
            f"Over {r['terrain']} the intruder is detected in {_percent(r['detection_fraction_none'])} of "
            f"its {r['visible_frames']} visible frames without suppression and in "
            f"{_percent(r['detection_fraction_suppressed'])} with it."
        )
    header = [
        "terrain",
        "own-ship above ground [m]",
        "intruder detected: none / suppressed / with secondary",
        "IF where lost [dB]",
        "IF in the intruder's cell [dB]",
        "MDV none / suppressed [m/s]",
        "usable Doppler none / suppressed",
    ]
    paragraphs = [
        f"A head-on intruder closes on the prototype radar, {result['frames_per_case']} "
        f"frames per terrain (seed {result['seed']}), each processed without and with knowledge-aided "
        "clutter suppression; the figures of merit are computed from noise-free ground and intruder "
        "runs the suppression never sees. Detection shares are of the frames where the intruder is "
        "visible without the ground; IF is the improvement factor, MDV the minimum detectable velocity.",
        " ".join(sentences) + " Look at the SINR-loss figures for where in Doppler the ground is "
        "suppressed, and at the intruder figures for the frames it is found in.",
    ]
    figures = [Path(p).name for p in result.get("figures", [])]
    files = {name: _figure_note(name) for name in figures} | {
        "frames.csv": "every frame of every terrain: hits, improvement factors, clutter-to-noise ratios",
        "sinr_loss.csv": "SINR loss and improvement factor per Doppler bin and terrain",
        "summary.json": "every figure of merit per terrain, with the command, version and machine load",
    }
    title = "clutter: knowledge-aided suppression under a head-on intruder"
    return page(title, paragraphs, header, table, files, out_dir)
