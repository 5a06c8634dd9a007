"""ch6's table (the thesis' beside ours), figures (poses, similarity surface, ROC, flight) and summary."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from skyradar.experiments.summary_md import beside, number, page  # noqa: E402
from skyradar.io.atomic import savefig_atomic  # noqa: E402
from skyradar.nav.gpscheck.check import DEFAULT_METHOD, RADAR_OPTIONS  # noqa: E402
from skyradar.nav.gpscheck.compare import decoy_poses, score_poses  # noqa: E402
from skyradar.nav.gpscheck.preprocess import METHODS, THESIS_METHOD_NUMBER, preprocess  # noqa: E402
from skyradar.nav.gpscheck.search import similarity_surface  # noqa: E402
from skyradar.scene.ground_grid import sample_at_pose  # noqa: E402

__all__ = ["summary_table", "plot_all", "summary_markdown"]


def _median(values: pd.Series) -> float:
    return float(np.median(values)) if len(values) else float("nan")


def summary_table(frames: pd.DataFrame, thesis: dict, n_frames: int) -> tuple[pd.DataFrame, dict[str, Any]]:
    """One row per method (the thesis' numbers beside ours) and one for the continuous search."""
    rows = []
    decoys = frames[frames["kind"] == "decoys"]
    for method in METHODS:
        d = decoys[decoys["method"] == method]
        t_head, t_pos, t_fp, t_correct = thesis[method]
        rows.append(
            {
                "method": method,
                "thesis_method": THESIS_METHOD_NUMBER.get(method, ""),
                "frames": len(d),
                "correct": int(d["correct"].sum()),
                "heading_error_deg": _median(d["heading_error_deg"]),
                "position_error_m": _median(d["position_error_m"]),
                "false_positive_fraction": float(d["false_positive_fraction"].mean()),
                "thesis_correct": t_correct,
                "thesis_heading_error_deg": t_head,
                "thesis_position_error_m": t_pos,
                "thesis_false_positive_fraction": t_fp,
            }
        )
    search = frames[(frames["kind"] == "search") & (frames["case"] == "0 m")]
    decided = search[search["decided"]]
    correct = (decided["position_error_m"] <= 15.0) & (decided["heading_error_deg"] <= 2.0)
    rows.append(
        {
            "method": f"search ({DEFAULT_METHOD}, NCC)",
            "thesis_method": "",
            "frames": len(decided),
            "correct": int(correct.sum()),
            "heading_error_deg": _median(decided["heading_error_deg"]),
            "position_error_m": _median(decided["position_error_m"]),
            "false_positive_fraction": float("nan"),
            "thesis_correct": None,
            "thesis_heading_error_deg": None,
            "thesis_position_error_m": None,
            "thesis_false_positive_fraction": None,
        }
    )
    table = pd.DataFrame(rows)
    ranked = table.iloc[: len(METHODS)].sort_values(
        ["correct", "false_positive_fraction"], ascending=[False, True]
    )
    best = ranked.iloc[0]
    wing = frames[frames["kind"] == "wing_up"]
    result = {
        "frames": n_frames,
        "best_method": best["method"],
        "best_correct": int(best["correct"]),
        "best_false_positive": float(best["false_positive_fraction"]),
        "search_decided": int(len(decided)),
        "search_correct": int(correct.sum()),
        "search_median_position_m": _median(decided["position_error_m"]),
        "search_median_heading_deg": _median(decided["heading_error_deg"]),
        "search_p90_position_m": float(decided["position_error_m"].quantile(0.9)) if len(decided) else None,
        "wing_up_frames": int(len(wing)),
        "wing_up_all_no_decision": bool(wing["no_decision"].all()) if len(wing) else True,
    }
    return table, result


def _show(ax, image, title):
    ax.imshow(image, origin="lower", cmap="gray")
    ax.set_title(title, fontsize=9)
    ax.set_xticks([])
    ax.set_yticks([])


def plot_poses(path: Path, truth, image, maps, map_grid, at, pose_grid, rng) -> Path:
    """Radar ground image beside the map at the true pose and at the best-scoring false pose.

    ``at`` is the pose grid the map is sampled on (moved by the layover), ``pose_grid`` the radar's.
    """
    mask = np.isfinite(image)
    radar = preprocess(image, DEFAULT_METHOD, mask, **RADAR_OPTIONS)
    poses = decoy_poses(truth, rng)
    both = np.vstack([truth, poses])
    scores = score_poses(radar, mask, maps[DEFAULT_METHOD], map_grid, pose_grid, both, at)
    k = int(np.argmax(scores[1:]))
    fig, axes = plt.subplots(1, 4, figsize=(12, 5))
    _show(axes[0], np.where(mask, 10 * np.log10(np.maximum(image, 1e-30)), np.nan), "radar ground image, dB")
    _show(axes[1], radar, f"radar, {DEFAULT_METHOD}")
    _show(
        axes[2],
        sample_at_pose(maps[DEFAULT_METHOD], map_grid, pose_grid, *truth),
        f"map at true pose\nSSIM {scores[0]:.3f}",
    )
    off = np.hypot(*(poses[k, :2] - truth[:2]))
    head = np.degrees(poses[k, 2] - truth[2])
    _show(
        axes[3],
        sample_at_pose(maps[DEFAULT_METHOD], map_grid, at, *poses[k]),
        f"best false pose ({off:.0f} m, {head:+.1f} deg)\nSSIM {scores[k + 1]:.3f}",
    )
    fig.suptitle("rows: forward (up), columns: right of the aircraft")
    savefig_atomic(fig, path, dpi=90)
    plt.close(fig)
    return path


def plot_surface(path: Path, truth, image, maps, map_grid, at, pose_grid) -> Path:
    """NCC of radar and map over position offsets around the true pose (true heading)."""
    mask = np.isfinite(image)
    radar = preprocess(image, DEFAULT_METHOD, mask, **RADAR_OPTIONS)
    surface, axis = similarity_surface(
        radar, mask, maps[DEFAULT_METHOD], map_grid, pose_grid, truth, map_pose_grid=at
    )
    fig, ax = plt.subplots(figsize=(6, 5))
    extent = (axis[0], axis[-1], axis[0], axis[-1])
    shown = ax.imshow(surface, origin="lower", extent=extent, cmap="viridis")
    ax.plot(0, 0, "r+", ms=14)
    ax.set_xlabel("offset right, m")
    ax.set_ylabel("offset forward, m")
    ax.set_title("similarity (masked NCC) over pose offsets; + = true pose")
    fig.colorbar(shown, ax=ax)
    savefig_atomic(fig, path, dpi=90)
    plt.close(fig)
    return path


def plot_roc(path: Path, roc: pd.DataFrame) -> Path:
    """Detection rate against false-alarm rate, one curve per spoof case."""
    fig, ax = plt.subplots(figsize=(6, 5))
    for case in [c for c in roc.columns if c not in ("threshold", "false_alarm")]:
        # Both rates fall as the threshold rises: walking the thresholds down traces the curve.
        order = np.argsort(roc["threshold"].to_numpy())[::-1]
        ax.plot(
            roc["false_alarm"].to_numpy()[order],
            roc[case].to_numpy()[order],
            drawstyle="steps-post",
            label=case,
        )
    ax.axvline(0.05, color="grey", ls=":")
    ax.set_xlabel("false-alarm rate (unspoofed frames)")
    ax.set_ylabel("detection rate (decided frames)")
    ax.set_title("GPS spoofing: ROC of the pose correction")
    ax.legend()
    savefig_atomic(fig, path, dpi=90)
    plt.close(fig)
    return path


def plot_flight(path: Path, map_image, map_grid, flight, index, n_picked) -> Path:
    """The flight over the map, the scored frames and the wing-up frames."""
    fig, ax = plt.subplots(figsize=(6, 8))
    ax.imshow(map_image, origin="lower", extent=map_grid.extent_m, cmap="gray")
    pos = flight.position_ned_m
    ax.plot(pos[:, 1], pos[:, 0], "b-", lw=1)
    ax.plot(pos[index[:n_picked], 1], pos[index[:n_picked], 0], "go", ms=4, label="scored frames")
    ax.plot(pos[index[n_picked:], 1], pos[index[n_picked:], 0], "rx", ms=5, label="wing up")
    ax.set_xlabel("east, m")
    ax.set_ylabel("north, m")
    ax.legend(loc="lower left")
    savefig_atomic(fig, path, dpi=90)
    plt.close(fig)
    return path


def plot_all(
    out: Path, images, maps, map_grid, at, pose_grid, flight, index, n_picked, roc, rng
) -> list[str]:
    """Every ch6 figure into ``out``; their paths."""
    truth, image = images[0]
    return [
        str(p)
        for p in (
            plot_poses(out / "poses.png", truth, image, maps, map_grid, at, pose_grid, rng),
            plot_surface(out / "surface.png", truth, image, maps, map_grid, at, pose_grid),
            plot_roc(out / "roc.png", roc),
            plot_flight(out / "flight.png", maps["gamma"], map_grid, flight, index, n_picked),
        )
    ]


_FIGURES = {
    "poses.png": "one frame's radar ground image against the map at the true pose and at decoys",
    "surface.png": "the similarity over pose offsets around the true pose",
    "roc.png": "detection of each GPS spoof against the false-alarm rate",
    "flight.png": "the flight over the map, the scored frames marked",
}
_DATA = {
    "table.csv": "one row per method, the thesis' numbers beside ours, and the continuous search",
    "roc.csv": "the ROC: false-alarm and detection rates per threshold",
    "frames.parquet": "every scored frame, method and spoof case",
    "ch6.json": "every measured value",
}


def summary_markdown(result: dict[str, Any], out_dir: Path | None = None) -> str:
    """``summary.md`` of a ch6 run: the GPS check's methods beside the thesis', the search and spoofing.

    Parameters
    ----------
    result : dict
        The summary ``skyradar.experiments.ch6.run`` returns (also in ``ch6.json``), with its
        ``table`` (:func:`summary_table`, as records) and ``figures``.
    out_dir : Path, optional
        The run's folder: only the files present there are listed (None: all of them).

    Returns
    -------
    str
        Markdown: title, sentences, one table row per method, the files.

    Examples
    --------
    >>> row = {"method": "clahe_ridge", "frames": 20, "correct": 20, "heading_error_deg": 0.4,
    ...        "position_error_m": 2.1, "false_positive_fraction": 0.01, "thesis_correct": 17,
    ...        "thesis_heading_error_deg": 1.0, "thesis_position_error_m": 1.0,
    ...        "thesis_false_positive_fraction": 0.14}
    >>> r = {"frames": 20, "best_method": "clahe_ridge", "best_correct": 20, "best_false_positive": 0.01,
    ...      "search_decided": 20, "search_correct": 19, "search_median_position_m": 3.2,
    ...      "search_median_heading_deg": 0.3, "spoof_50m_detection": 1.0, "roc_false_alarm": 0.0,
    ...      "monitor_false_alarm": 0.05, "wing_up_frames": 4, "wing_up_all_no_decision": True,
    ...      "acceptance_failures": [], "table": [row], "figures": ["out/ch6/roc.png"]}
    >>> text = summary_markdown(r)
    >>> print(text.splitlines()[0])
    # ch6: GPS check against an out-of-date map
    >>> "| clahe_ridge | 20 of 20 (17) | 0.4 (1.0) | 2.1 (1.0) | 0.01 (0.14) |" in text
    True
    >>> "`roc.png`" in text, "`poses.png`" in text
    (True, False)
    """
    r = result
    rows = [
        [
            t["method"],
            beside(f"{t['correct']} of {t['frames']}", t.get("thesis_correct")),
            beside(t["heading_error_deg"], t.get("thesis_heading_error_deg"), 1),
            beside(t["position_error_m"], t.get("thesis_position_error_m"), 1),
            beside(t["false_positive_fraction"], t.get("thesis_false_positive_fraction"), 2),
        ]
        for t in r["table"]
    ]
    header = [
        "method",
        "frames correct (thesis)",
        "median heading error [deg] (thesis)",
        "median position error [m] (thesis)",
        "false-positive fraction (thesis)",
    ]
    failures = r.get("acceptance_failures") or []
    wing = "all" if r["wing_up_all_no_decision"] else "not all"
    paragraphs = [
        f"A side-looking radar over central Helsinki checks its GPS pose against an out-of-date "
        f"map, on {r['frames']} random frames with ground in view as in the thesis' experiment B.",
        f"The best method, {r['best_method']}, picks the true pose among decoys in {r['best_correct']} of "
        f"{r['frames']} frames, with a false-positive fraction of {number(r['best_false_positive'], 2)}. "
        f"The continuous search from the GPS pose decides {r['search_decided']} frames and is correct in "
        f"{r['search_correct']}, with a median error of {number(r['search_median_position_m'])} m and "
        f"{number(r['search_median_heading_deg'], 2)} deg. A GPS moved by 50 m is detected in "
        f"{number(100 * r['spoof_50m_detection'], 0)} % of the frames at a false-alarm rate of "
        f"{number(100 * r['roc_false_alarm'], 0)} % (the monitor's own threshold: "
        f"{number(100 * r['monitor_false_alarm'], 0)} % false alarms); {wing} of the "
        f"{r['wing_up_frames']} wing-up frames end in no decision. "
        + (
            "Every acceptance bound holds."
            if not failures
            else f"{len(failures)} acceptance bounds are missed: " + "; ".join(failures) + "."
        ),
    ]
    files = {Path(p).name: _FIGURES.get(Path(p).name, "figure") for p in r.get("figures", [])} | _DATA
    return page("ch6: GPS check against an out-of-date map", paragraphs, header, rows, files, out_dir)
