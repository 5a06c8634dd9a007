"""Real traffic in: ``skyradar flight`` (the flyable path a recorded flight becomes) and
``skyradar make-encounter`` (an encounter scenario from two recorded flights)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from skyradar.cli.app import (
    NON_NEGATIVE,
    POSITIVE,
    JsonOption,
    app,
    check_number,
    console,
    emit_result,
    notes_after_inputs,
)
from skyradar.cli.choices import AircraftClass, Side
from skyradar.errors import InputError
from skyradar.io.outputs import OVERWRITE_HELP

__all__ = ["flight", "make_encounter"]

_Icao = Annotated[str | None, typer.Option(help="Aircraft address to take from a file holding several.")]
_Track = Annotated[Path, typer.Argument(help="Track file (ADS-B/GPS: CSV, JSON, Parquet; .gz too).")]
_Output = Annotated[
    Path,
    typer.Option("-o", "--output", help="Scenario YAML to write (+ NAME.ownship.csv, NAME.intruder.csv)."),
]
_Miss = Annotated[float, typer.Option("--miss-m", callback=NON_NEGATIVE, help="Horizontal miss at CPA, m.")]
_Vertical = Annotated[
    float, typer.Option("--vertical-miss-m", help="Intruder height above the own ship at CPA, m.")
]
_TCpa = Annotated[
    float | None,
    typer.Option("--t-cpa-s", help="CPA time, s after the own ship's first fix (default: middle)."),
]
_TIntruder = Annotated[
    float | None,
    typer.Option(
        "--intruder-time-s", help="Intruder time moved to the CPA, s after its first fix (default: middle)."
    ),
]
_Rotate = Annotated[float, typer.Option("--rotate-deg", help="Turn the intruder's flight, deg clockwise.")]
_Side = Annotated[Side, typer.Option("--side", help="Side of the own ship's track the intruder passes.")]
_Before = Annotated[
    float, typer.Option("--before-s", callback=POSITIVE, help="Scenario start, s before CPA.")
]
_After = Annotated[float, typer.Option("--after-s", callback=POSITIVE, help="Scenario end, s after CPA.")]


def _flight(path: Path, icao24: str | None, aircraft_class: str):
    """The file's flyable path with t = 0 s at its first fix."""
    from skyradar.scene.scenario_sources import read_flight

    traj = read_flight(path, icao24, None, None, aircraft_class)
    return traj.shifted(-traj.start_s)


def _class_option(role: str) -> object:
    return typer.Option(
        f"--{role}-class" if role else "--aircraft-class",
        help=f"Aircraft class whose kinematic limits the {role or 'built'} path keeps to.",
    )


@app.command("flight")
def flight(
    track: _Track,
    output: Annotated[
        Path,
        typer.Option("-o", "--output", help="The built path as a table (CSV or Parquet) a scenario flies."),
    ],
    figure: Annotated[
        Path | None,
        typer.Option("--figure", help="The built path drawn against the fixes (PNG, SVG or PDF)."),
    ] = None,
    aircraft_class: Annotated[AircraftClass, _class_option("")] = AircraftClass.ga,
    icao24: _Icao = None,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """Build the flyable path of a recorded flight (ADS-B, GPS log) within its aircraft class's kinematic
    limits, as every scenario does with a flight file, and write it with a figure against the fixes.
    The one line on stderr names every fix repaired."""
    import numpy as np

    from skyradar.io.atomic import write_csv_atomic, write_with
    from skyradar.io.outputs import check_output
    from skyradar.scene.adsb import fit_flight
    from skyradar.scene.encounter_from_tracks import trajectory_table
    from skyradar.scene.flyable import hermite_accelerations

    if output.suffix.lower() not in (".csv", ".parquet"):
        raise InputError(f"--output: {output} must end in .csv or .parquet")
    check_output(output, [track], overwrite, kind="file")
    if figure is not None:
        if figure.suffix.lower() not in (".png", ".svg", ".pdf"):
            raise InputError(f"--figure: {figure} must end in .png, .svg or .pdf")
        check_output(figure, [track], overwrite, kind="file", option="--figure")
    fit = fit_flight(track, aircraft_class.value, icao24)
    table = trajectory_table(fit.trajectory)
    if output.suffix.lower() == ".csv":
        write_csv_atomic(table, output, index=False)
    else:
        write_with(output, lambda tmp: table.to_parquet(tmp, index=False))
    if figure is not None:
        from skyradar.viz.flight import flight_fit_figure

        flight_fit_figure(fit, figure)
    traj = fit.trajectory
    start, end = hermite_accelerations(traj.time_s, traj.position_ned_m, traj.velocity_ned_mps)
    both = np.concatenate([start, end])
    speed = np.linalg.norm(traj.velocity_ned_mps, axis=1)
    result = {
        "output": str(output),
        "figure": None if figure is None else str(figure),
        "name": traj.name,
        "aircraft_class": aircraft_class.value,
        "fixes": int(fit.fix_time_s.size),
        "fixes_used": int(fit.path.kept.sum()),
        "position_lag_s": fit.path.lag_s,
        "duration_s": traj.duration_s,
        "speed_min_mps": float(speed.min()),
        "speed_max_mps": float(speed.max()),
        "horizontal_accel_max_mps2": float(np.hypot(both[:, 0], both[:, 1]).max()),
        "vertical_accel_max_mps2": float(np.abs(both[:, 2]).max()),
        "repairs": "; ".join(fit.notes) or "none",
    }
    emit_result(result, as_json, "flight")


def _side_files(output: Path) -> tuple[Path, Path]:
    stem = output.name[: -len(output.suffix)] if output.suffix else output.name
    return output.with_name(f"{stem}.ownship.csv"), output.with_name(f"{stem}.intruder.csv")


def _write(
    output: Path, own, intr, t_cpa: float, window_s: tuple[float, float], name: str, classes: tuple[str, str]
) -> dict:
    """Write the scenario and its two tracks (atomically); the files written and the real CPA."""
    import yaml

    from skyradar.io.atomic import write_csv_atomic, write_text_atomic
    from skyradar.scene.encounter_from_tracks import encounter_scenario, horizontal_cpa, trajectory_table

    own_csv, intr_csv = _side_files(output)
    scenario = encounter_scenario(own, intr, own_csv.name, intr_csv.name, t_cpa, *window_s, name=name)
    scenario["ownship"]["aircraft_class"], scenario["intruders"][0]["aircraft_class"] = classes
    write_csv_atomic(trajectory_table(own), own_csv, index=False)
    write_csv_atomic(trajectory_table(intr), intr_csv, index=False)
    write_text_atomic(output, yaml.safe_dump(scenario, sort_keys=False))
    window = (scenario["start_s"], scenario["start_s"] + scenario["duration_s"])
    t, h_m, v_m = horizontal_cpa(own, intr, window=window)  # what the scenario really flies
    result: dict[str, Any] = {"output": str(output), "ownship": str(own_csv), "intruder": str(intr_csv)}
    result |= {"t_cpa_s": t, "horizontal_miss_m": h_m, "vertical_miss_m": v_m}
    return result | {"start_s": scenario["start_s"], "duration_s": scenario["duration_s"]}


@app.command("make-encounter")
def make_encounter(
    ownship: _Track,
    intruder: _Track,
    output: _Output,
    miss_m: _Miss = 150.0,
    vertical_miss_m: _Vertical = 0.0,
    t_cpa: _TCpa = None,
    intruder_time: _TIntruder = None,
    rotate_deg: _Rotate = 0.0,
    side: _Side = Side.right,
    before_s: _Before = 60.0,
    after_s: _After = 20.0,
    ownship_icao24: _Icao = None,
    intruder_icao24: _Icao = None,
    ownship_class: Annotated[AircraftClass, _class_option("ownship")] = AircraftClass.ga,
    intruder_class: Annotated[AircraftClass, _class_option("intruder")] = AircraftClass.ga,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """Make an encounter from two recorded flights (OWNSHIP, INTRUDER): the intruder's track is
    shifted in time and space (and optionally turned) so that it passes the own ship at the given
    miss distances at the given time. Writes a scenario for `skyradar simulate` and the two tracks
    it flies; the files are cleaned on the way (one line on stderr says how)."""
    from skyradar.io.outputs import check_output
    from skyradar.scene.encounter_from_tracks import encounter_from_tracks

    check_number("--vertical-miss-m", vertical_miss_m, -10_000.0, 10_000.0)
    check_number("--rotate-deg", rotate_deg, -360.0, 360.0)
    for path in (output, *_side_files(output)):
        check_output(path, [ownship, intruder], overwrite, kind="file")
    classes = (ownship_class.value, intruder_class.value)
    with notes_after_inputs():  # a refused intruder file is the one line, not the own-ship file's note
        a, b = _flight(ownship, ownship_icao24, classes[0]), _flight(intruder, intruder_icao24, classes[1])
    t_cpa = 0.5 * a.end_s if t_cpa is None else t_cpa
    own, intr = encounter_from_tracks(
        a, b, t_cpa, miss_m, vertical_miss_m, intruder_time, rotate_deg, side.value
    )
    result = _write(output, own, intr, t_cpa, (before_s, after_s), f"{a.name} meets {b.name}", classes)
    t, h_m = result["t_cpa_s"], result["horizontal_miss_m"]
    if abs(t - t_cpa) > 0.1 or abs(h_m - miss_m) > 1.0:  # manoeuvring flights: say what they really do
        console.print(
            f"note: the flights manoeuvre near the meeting: closest approach {h_m:.0f} m at {t:.2f} s "
            f"(asked {miss_m:g} m at {t_cpa:g} s); try another --t-cpa-s or --intruder-time-s",
            soft_wrap=True,
        )
    emit_result(result, as_json, "encounter")
