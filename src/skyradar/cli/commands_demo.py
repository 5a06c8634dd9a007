"""``skyradar demo``: the embedded end-to-end scenario and its report folder."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer

from skyradar.cli.app import JsonOption, app, emit_result
from skyradar.io.outputs import OVERWRITE_HELP

__all__ = ["demo", "format_timeline"]


def format_timeline(timeline) -> str:
    """The alert timeline as plain text lines (one per change of a track's issued level)."""
    if len(timeline) == 0:
        return "alert timeline: no alerts"
    lines = ["alert timeline (time, track, intruder, level, range, bearing, relative altitude, advice):"]
    for r in timeline.itertuples(index=False):
        heading = float(getattr(r, "preferred_heading_deg", float("nan")))
        advice = "" if getattr(r, "altitude_measured", True) else " (not measured)"
        if r.level > 0 and math.isfinite(heading):
            advice += f"  advice: heading {heading:.0f} deg, vs {r.preferred_vs_mps:+.1f} m/s"
        # A track without a direction (a one-channel radar) has a range but no bearing or height.
        bearing = f"{r.bearing_deg:+5.0f} deg" if math.isfinite(r.bearing_deg) else "no bearing"
        height = f"{r.rel_alt_m:+5.0f} m" if math.isfinite(r.rel_alt_m) else "unknown"
        lines.append(
            f"  t={r.time_s:6.1f} s  T{r.track_id:<4d} {r.intruder:<10s} {r.level} {r.level_name:<10s} "
            f"range {r.range_m:6.0f} m  bearing {bearing}  rel alt {height}{advice}"
        )
    return "\n".join(lines)


@app.command()
def demo(
    out: Annotated[Path, typer.Option("-o", "--output", help="Report folder to write.")] = Path("out/demo"),
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """Run the embedded demo end to end and write a report folder (index.html + figures + tables).

    Own-ship on a circuit over synthetic fractal terrain with three intruders (a collision course
    from the left, a head-on jet whose Doppler aliases, a glider well clear): simulate, process,
    track (3-D, non-ground detections), alert (confirmed tracks), advice. Prints the alert timeline.
    """
    import pandas as pd

    from skyradar.demo import run_demo
    from skyradar.io.outputs import check_output, mark_folder

    check_output(out, (), overwrite, kind="folder", option="--output")
    summary = run_demo(mark_folder(out))
    timeline = pd.read_csv(out / "alert_timeline.csv")
    print(format_timeline(timeline), flush=True)
    print(f"report: {out / 'index.html'}  ({summary['runtime_s']:.1f} s)", flush=True)
    flat = {k: v for k, v in summary.items() if not isinstance(v, dict)}
    flat |= {f"{k}_max_level": v["max_level"] for k, v in summary["intruders"].items()}
    emit_result(summary if as_json else flat, as_json, "skyradar demo")
