"""Closed-loop encounter set (``skyradar experiment closed-loop``): does a pilot flying the advice stay clear?

Each encounter of the encounter set (:mod:`skyradar.experiments.encounter_set`) is flown three
ways from the same start, 40 s before the loss of well clear (or the CPA), to the own-ship's last
time, 10 s after the planned CPA (:mod:`skyradar.closed_loop`): unequipped (the plan), with
perfect surveillance (true states through the alerting, the same pilot) and with the radar chain
in the loop (one run per layout: the nose head, or nose and wingtips). The pilot
(:class:`~skyradar.pilot.PilotConfig`) acts on corrective alerts and warnings after a reaction
delay, flies the preferred heading at 3 deg/s and returns to the plan when clear; the intruder
keeps its path (non-cooperative).

Scored per terrain and case, as DO-365's closed-loop studies are: the rates of loss of well clear
(DO-365 non-cooperative volume, 2200 ft / 450 ft) and of near mid-air collision (500 ft / 100 ft)
with their 95 % Wilson intervals; the risk ratios (rate equipped / rate unequipped) with paired
bootstrap intervals over the encounters; induced losses (equipped loses well clear where the
unequipped own-ship did not) and resolved ones; the separation at the closest approach; the time
the pilot spent off the plan.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from skyradar.closed_loop import (
    ClosedLoopRun,
    fly_perfect_surveillance,
    fly_radar,
    fly_unequipped,
    separation,
)
from skyradar.code_version import code_version, provenance
from skyradar.daa.alert_config import WARNING_LEVEL
from skyradar.daa.alerting import RADAR_ALERT_CONFIG, AlertConfig
from skyradar.errors import InputError
from skyradar.experiments.encounter_chain import (
    FRAME_RATE_HZ,
    LAYOUTS,
    SUPPRESSION,
    build_encounter,
    layout_heads,
)
from skyradar.experiments.encounter_set import T_CPA_S, make_encounters, make_fast_closures, rate_interval
from skyradar.experiments.summary_md import markdown_table, number
from skyradar.io.atomic import savefig_atomic, write_csv_atomic, write_text_atomic
from skyradar.io.json_results import write_json_atomic
from skyradar.io.tables import write_table
from skyradar.pilot import PilotConfig

__all__ = [
    "CLOSED_LOOP_FAMILIES",
    "DEFAULT_CLOSED_LOOP_ENCOUNTERS",
    "run_closed_loop_encounter",
    "summarise_closed_loop",
    "risk_ratio",
    "run",
]

CLOSED_LOOP_FAMILIES = ("synthetic", "fast-closures")
# One clear-sky encounter flown three ways costs about 35 CPU-s (the radar run ~25 s for ~470 frames,
# perfect surveillance ~7 s; measured on 2 busy cores): 6 on 2 workers fit 5 minutes with room.
DEFAULT_CLOSED_LOOP_ENCOUNTERS = 6
_END_AFTER_CPA_S = 10.0  # the own-ship's plan ends here: the frames run to it
_BOOTSTRAP = 2000
_PARTIAL = "closed-loop.partial.parquet"


def _first_time(alerts: pd.DataFrame, level: int) -> float:
    if len(alerts) == 0:
        return float("nan")
    times = alerts.loc[alerts["level"].to_numpy() >= level, "time_s"]
    return float(times.min()) if len(times) else float("nan")


def _row(condition: str, layout: str, run: ClosedLoopRun, built, pilot: PilotConfig, seconds: float) -> dict:
    row: dict[str, Any] = {"condition": condition, "layout": layout}
    row.update(separation(run.flown, built.intruders[0].trajectory))
    row.update(
        first_alert_s=_first_time(run.alerts, pilot.respond_level),
        first_warning_s=_first_time(run.alerts, WARNING_LEVEL),
        first_action_s=float(run.first_action_s),
        manoeuvre_s=float(run.manoeuvre_s),
        runtime_s=round(seconds, 2),
    )
    return row


def run_closed_loop_encounter(
    p: pd.Series,
    seed: int = 0,
    terrain: str | None = None,
    layouts: tuple[str, ...] = ("single",),
    frame_rate_hz: float = FRAME_RATE_HZ,
    lookback_s: float = 40.0,
    alert_config: AlertConfig | None = None,
    navigation: str | dict | None = "ga-typical",
    simulation: dict[str, Any] | None = None,
    rx_layout: str = "square",
    pilot: PilotConfig | None = None,
) -> list[dict[str, Any]]:
    """One encounter row flown unequipped, with perfect surveillance and with the radar of each layout.

    Returns one result row per way it was flown (``condition`` ``unequipped``, ``perfect`` or
    ``radar`` with its ``layout``): :func:`skyradar.closed_loop.separation`'s columns, the first
    alert the pilot acts on and the first warning (s, NaN: none), the pilot's first action (s) and
    time off the plan (s), the run's wall time (s) and the encounter's shared columns (its frames,
    start, own-ship altitude).
    """
    cfg = alert_config or RADAR_ALERT_CONFIG
    pilot = pilot or PilotConfig()
    end_s = T_CPA_S + _END_AFTER_CPA_S
    args = (p, seed, frame_rate_hz, lookback_s, terrain, layouts, navigation, simulation, rx_layout)
    built, _, shared = build_encounter(*args, end_s=end_s)
    rows = []
    t0 = time.perf_counter()
    rows.append(_row("unequipped", "", fly_unequipped(built), built, pilot, time.perf_counter() - t0))
    t0 = time.perf_counter()
    perfect = fly_perfect_surveillance(built, pilot, cfg)
    rows.append(_row("perfect", "", perfect, built, pilot, time.perf_counter() - t0))
    for layout in layouts:
        t0 = time.perf_counter()
        options = {"suppression": SUPPRESSION}
        run = fly_radar(built, pilot, cfg, options, layout_heads(built, layout))
        rows.append(_row("radar", layout, run, built, pilot, time.perf_counter() - t0))
    return [row | shared for row in rows]


def risk_ratio(equipped: np.ndarray, unequipped: np.ndarray, seed: int = 0) -> tuple[float, list[float]]:
    """Risk ratio (events equipped / events unequipped over the same encounters) and its 95 % paired
    bootstrap interval (encounters resampled with replacement; NaN when no unequipped event).

    Examples
    --------
    >>> ratio, interval = risk_ratio(np.array([0, 0, 1, 0]), np.array([1, 1, 1, 0]))
    >>> round(ratio, 3), 0.0 <= interval[0] <= ratio <= interval[1] <= 1.0
    (0.333, True)
    >>> risk_ratio(np.array([1, 0]), np.array([0, 0]))[0]
    nan
    """
    eq, base = np.asarray(equipped, float), np.asarray(unequipped, float)
    if base.sum() == 0:
        return float("nan"), [float("nan"), float("nan")]
    ratio = float(eq.sum() / base.sum())
    rng = np.random.default_rng(seed)
    idx = rng.integers(0, base.size, (_BOOTSTRAP, base.size))
    den = base[idx].sum(axis=1)
    ratios = eq[idx].sum(axis=1)[den > 0] / den[den > 0]
    return ratio, [float(np.percentile(ratios, 2.5)), float(np.percentile(ratios, 97.5))]


def _case(sub: pd.DataFrame, base: pd.DataFrame, condition: str, layout: str) -> dict[str, Any]:
    eq = sub[(sub["condition"] == condition) & (sub["layout"] == layout)].set_index("encounter")
    eq = eq.loc[base.index]
    n = len(base)
    row: dict[str, Any] = {"condition": condition, "layout": layout, "encounters": n}
    for event in ("lowc", "nmac"):
        b, e = base[event].to_numpy(bool), eq[event].to_numpy(bool)
        ratio, interval = risk_ratio(e, b)
        row.update(
            {
                f"{event}_unequipped": int(b.sum()),
                f"{event}_equipped": int(e.sum()),
                f"{event}_rate_unequipped": float(b.mean()),
                f"{event}_rate_equipped": float(e.mean()),
                f"{event}_rate_unequipped_interval": rate_interval(int(b.sum()), n),
                f"{event}_rate_equipped_interval": rate_interval(int(e.sum()), n),
                f"{event}_risk_ratio": ratio,
                f"{event}_risk_ratio_interval": interval,
                f"{event}_induced": int((e & ~b).sum()),
                f"{event}_resolved": int((b & ~e).sum()),
            }
        )
    conflicts = base["lowc"].to_numpy(bool)
    manoeuvred = np.isfinite(eq["first_action_s"].to_numpy(float))
    row.update(
        median_min_horizontal_unequipped_conflicts_m=float(np.median(base["min_horizontal_m"][conflicts]))
        if conflicts.any()
        else float("nan"),
        median_min_horizontal_equipped_conflicts_m=float(np.median(eq["min_horizontal_m"][conflicts]))
        if conflicts.any()
        else float("nan"),
        manoeuvred_encounters=int(manoeuvred.sum()),
        manoeuvre_s_mean=float(eq["manoeuvre_s"].mean()),
        manoeuvre_s_total=float(eq["manoeuvre_s"].sum()),
        runtime_s_mean=float(eq["runtime_s"].mean()),
    )
    return row


def summarise_closed_loop(res: pd.DataFrame) -> list[dict[str, Any]]:
    """One summary row per terrain and equipped case (perfect surveillance, radar per layout) of the
    long table of :func:`run_closed_loop_encounter` rows (columns ``terrain``, ``encounter``)."""
    rows = []
    for terrain, sub in res.groupby("terrain", sort=False):
        base = sub[sub["condition"] == "unequipped"].set_index("encounter")
        cases = [("perfect", "")] + [
            ("radar", str(x)) for x in sub.loc[sub["condition"] == "radar", "layout"].unique()
        ]
        for condition, layout in cases:
            rows.append({"terrain": str(terrain), **_case(sub, base, condition, layout)})
    return rows


def _case_name(row: dict) -> str:
    return "perfect surveillance" if row["condition"] == "perfect" else f"radar, {row['layout']}"


def plot_closed_loop(res: pd.DataFrame, rows: list[dict], path: Path) -> None:
    """Separation at the closest approach unequipped against equipped (one panel per terrain), and the
    rates of loss of well clear and NMAC per case with their 95 % intervals."""
    import matplotlib.pyplot as plt

    terrains = list(dict.fromkeys(res["terrain"]))
    fig, axes = plt.subplots(2, len(terrains), figsize=(5.2 * len(terrains), 9.0), squeeze=False)
    for k, terrain in enumerate(terrains):
        sub = res[res["terrain"] == terrain]
        base = sub[sub["condition"] == "unequipped"].set_index("encounter")
        ax = axes[0, k]
        for (condition, layout), g in sub[sub["condition"] != "unequipped"].groupby(["condition", "layout"]):
            g = g.set_index("encounter").loc[base.index]
            label = "perfect surveillance" if condition == "perfect" else f"radar, {layout}"
            ax.scatter(base["min_horizontal_m"], g["min_horizontal_m"], s=18, label=label, alpha=0.8)
        lim = float(np.nanmax(sub["min_horizontal_m"])) * 1.05 + 1.0
        ax.plot([0, lim], [0, lim], color="grey", lw=0.8, label="no change")
        ax.axhline(670.56, color="tab:red", lw=0.8, ls="--", label="well clear, 2200 ft")
        ax.axvline(670.56, color="tab:red", lw=0.8, ls="--")
        ax.set(
            xlabel="unequipped: smallest horizontal separation, m",
            ylabel="equipped: smallest horizontal separation, m",
            title=f"{terrain}: separation with and without DAA",
            xlim=(0, lim),
            ylim=(0, lim),
        )
        ax.legend(fontsize=7)
        ax = axes[1, k]
        cases = [r for r in rows if r["terrain"] == terrain]
        labels = ["unequipped"] + [_case_name(r) for r in cases]
        for j, event in enumerate(("lowc", "nmac")):
            rates = [cases[0][f"{event}_rate_unequipped"]] + [r[f"{event}_rate_equipped"] for r in cases]
            lows = [cases[0][f"{event}_rate_unequipped_interval"]] + [
                r[f"{event}_rate_equipped_interval"] for r in cases
            ]
            x = np.arange(len(labels)) + (j - 0.5) * 0.35
            err = np.abs(np.array(lows, float).T - np.array(rates, float))
            ax.bar(
                x, rates, width=0.35, yerr=err, capsize=3, label="loss of well clear" if j == 0 else "NMAC"
            )
        ax.set_xticks(np.arange(len(labels)), labels, rotation=15, fontsize=8)
        ax.set(ylabel="rate over the encounters", title=f"{terrain}: rates with 95 % intervals", ylim=(0, 1))
        ax.legend(fontsize=8)
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=110)
    plt.close(fig)


def _summary_md(rows: list[dict], settings: dict) -> str:
    """The human summary leading the report: one paragraph per terrain and case, from the measured rows."""
    lines = [
        "# Closed-loop encounters",
        "",
        f"{settings['n']} encounters ({settings['family']}, seed {settings['seed']}, "
        f"{settings['split']} split), "
        "each flown unequipped, with perfect surveillance and with the radar in the loop; the pilot acts on "
        f"corrective alerts after {settings['pilot']['corrective_delay_s']:g} s and on warnings after "
        f"{settings['pilot']['warning_delay_s']:g} s, flying the preferred {settings['pilot']['manoeuvre']} "
        "manoeuvre.",
        "",
    ]
    header = [
        "terrain",
        "case",
        "LoWC unequipped",
        "LoWC equipped",
        "risk ratio LoWC (95 %)",
        "NMAC unequipped",
        "NMAC equipped",
        "induced LoWC",
        "mean time manoeuvring, s",
    ]
    table = []
    for r in rows:
        lo, hi = r["lowc_risk_ratio_interval"]
        ratio = f"{number(r['lowc_risk_ratio'], 2)} ({number(lo, 2)}-{number(hi, 2)})"
        n = r["encounters"]
        table.append(
            [
                r["terrain"],
                _case_name(r),
                f"{r['lowc_unequipped']}/{n}",
                f"{r['lowc_equipped']}/{n}",
                ratio,
                str(r["nmac_unequipped"]),
                str(r["nmac_equipped"]),
                str(r["lowc_induced"]),
                r["manoeuvre_s_mean"],
            ]
        )
    lines.append(markdown_table(header, table))
    lines += [
        "",
        "The risk ratio is the rate equipped over the rate unequipped on the same encounters (NaN: no "
        "loss unequipped); its interval is a paired bootstrap over the encounters. Figures: "
        "`closed_loop.png`; every encounter and way flown: `closed_loop.csv`; every number: `summary.json`.",
        "",
    ]
    return "\n".join(lines)


def run(
    out_dir: Path,
    n_encounters: int = DEFAULT_CLOSED_LOOP_ENCOUNTERS,
    seed: int = 0,
    terrains: tuple[str, ...] = ("none",),
    layouts: tuple[str, ...] = ("single",),
    family: str = "synthetic",
    pilot: PilotConfig | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: Callable[[int], None] | None = None,
    command: str | None = None,
) -> dict[str, Any]:
    """Fly the encounter set closed-loop; write ``closed_loop.parquet``/``.csv`` (one row per terrain,
    encounter and way flown), ``summary.json``, ``summary_rows.csv``, ``summary.md`` and
    ``closed_loop.png`` into ``out_dir``; return the summary.

    The encounters run where :func:`skyradar.experiments.encounters.run_encounters` runs them
    (``workers`` local Dask processes, or the cluster at ``scheduler``); finished ones are kept in
    ``closed-loop.partial.parquet`` and a run interrupted resumes from them when started again with
    the same settings. Seeds from :data:`~skyradar.experiments.encounters.EVALUATION_SEEDS_FROM` are
    the evaluation split.
    """
    from skyradar.experiments.encounters import (
        EVALUATION_SEEDS_FROM,
        check_encounter_set,
        partial_store,
        run_encounters,
    )

    terrains = tuple(terrains)
    layouts = tuple(x for x in LAYOUTS if x in layouts) or tuple(layouts)
    check_encounter_set(n_encounters, terrains, layouts)
    if family not in CLOSED_LOOP_FAMILIES:
        raise InputError(f"--family: must be one of {', '.join(CLOSED_LOOP_FAMILIES)}, got {family!r}")
    pilot = pilot or PilotConfig()
    t0 = time.perf_counter()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    enc = (
        make_fast_closures(n_encounters, seed)
        if family == "fast-closures"
        else make_encounters(n_encounters, seed)
    )
    settings = {
        "n": n_encounters,
        "seed": seed,
        "family": family,
        "terrains": list(terrains),
        "layouts": list(layouts),
        "pilot": {k: getattr(pilot, k) for k in pilot.__dataclass_fields__},
        "alert_config": "radar",
        "suppression": SUPPRESSION,
        "split": "evaluation" if seed >= EVALUATION_SEEDS_FROM else "development",
    }
    version = code_version()
    done, save = partial_store(out_dir, {**settings, "version": version}, _PARTIAL)
    res = run_encounters(
        enc,
        seed,
        workers,
        progress,
        done,
        save,
        terrains=terrains,
        family=family,
        scheduler=scheduler,
        loop="closed",
        layouts=layouts,
        pilot=pilot,
    )
    write_table(res, out_dir / "closed_loop.parquet")
    write_csv_atomic(res, out_dir / "closed_loop.csv", index=False)
    rows = summarise_closed_loop(res)
    write_csv_atomic(pd.DataFrame(rows), out_dir / "summary_rows.csv", index=False)
    plot_closed_loop(res, rows, out_dir / "closed_loop.png")
    first = rows[-1] if rows else {}
    summary: dict[str, Any] = {
        **{k: v for k, v in first.items() if not isinstance(v, list)},
        "settings": settings,
        "rows": rows,
        "resumed_encounters": len(done),
        "scheduler": scheduler,
        "runtime_s": round(time.perf_counter() - t0, 1),
        **provenance(command, version),
    }
    write_json_atomic(out_dir / "summary.json", summary)
    write_text_atomic(out_dir / "summary.md", _summary_md(rows, settings))
    for name in (_PARTIAL, _PARTIAL + ".json"):
        (out_dir / name).unlink(missing_ok=True)
    return summary
