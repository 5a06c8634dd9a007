"""Tracking commands: ``track``, ``evaluate``, ``experiment ch4`` and ``bench track``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from skyradar.cli.app import (
    COUNT,
    NON_NEGATIVE,
    POSITIVE,
    JsonOption,
    app,
    bench_app,
    check_number,
    console,
    emit_measurement,
    emit_result,
    experiment_app,
    number_in,
)
from skyradar.cli.choices import Ch4Chain, TrackerModel, TruthMode
from skyradar.io.outputs import OVERWRITE_HELP

__all__ = ["track", "evaluate", "experiment_ch4", "bench_track"]


def _origin(text: str | None) -> tuple[float, float, float] | None:
    from skyradar.errors import InputError

    if text is None:
        return None
    try:
        lat, lon, alt = (float(v) for v in text.split(","))
    except ValueError as exc:
        raise InputError(f"--origin: expected 'lat_deg,lon_deg,alt_m', got {text!r}") from exc
    check_number("--origin: field 'lat_deg'", lat, -90.0, 90.0)
    check_number("--origin: field 'lon_deg'", lon, -180.0, 180.0)
    check_number("--origin: field 'alt_m'", alt, -500.0, 30_000.0)
    return lat, lon, alt


_FINITE_DB = number_in(-100.0, 100.0)  # an SNR in dB: finite, and a typo like 1e9 is refused

_ModelOpt = Annotated[
    TrackerModel,
    typer.Option("--model", help="'radar' (aliasing-aware, coupled) or 'traditional' (image tracker)."),
]
_OriginOpt = Annotated[
    str | None,
    typer.Option(
        "--origin",
        help="Override the origin 'lat,lon,alt' (default: --ownship's store, else the detections' run).",
    ),
]
_OwnshipOpt = Annotated[
    Path | None,
    typer.Option(
        "--ownship",
        help="Own-ship state: the frames run (Zarr) or a table (Parquet/CSV, e.g. `skyradar export`'s "
        "ownship.parquet; time_s, nav_* or own_*): its navigation solution (nav_*) is used, never the "
        "truth. The radial velocity then updates the 3-D velocity and the DoA error is split along/across "
        "the line of sight.",
    ),
]


_TerrainOpt = Annotated[
    str | None,
    typer.Option(
        "--terrain",
        help="Ground for the track-level ground test: a DEM file (.hgt/.tif/.npz) or flat, fractal, "
        "jacksboro, none (default: the terrain the --ownship run records, if any).",
    ),
]


def _ownship_and_origin(ownship: Path | None, table, origin: str | None):
    """(own-ship navigation table or None, origin or None, where the origin came from)."""
    import json

    import pandas as pd

    from skyradar.io.navigation import navigation_state
    from skyradar.io.ownship_input import open_ownship
    from skyradar.io.run_origin import scenario_origin
    from skyradar.track.io import validate_ownship
    from skyradar.track.track_table import OWNSHIP_COLUMNS

    own, found, where, run = None, None, None, None
    if ownship is not None:
        run = open_ownship(ownship)
        own = navigation_state(run, f"--ownship {ownship}")
        if own is None:  # no own-ship variable at all: validate_ownship names the missing ones
            own = pd.DataFrame({"time_s": run["time_s"].values if "time_s" in run else []})
        own = validate_ownship(own, OWNSHIP_COLUMNS, f"--ownship {ownship}")
        found, where = scenario_origin(run), f"--ownship {ownship}"
    if found is None and table.attrs.get("ownship_signature"):  # `process` signs the run it read
        sig = json.loads(table.attrs["ownship_signature"])
        found, where = (tuple(sig["origin"]), f"run {sig.get('run')}") if sig.get("origin") else (None, None)
    if origin is not None:
        return own, _origin(origin), "--origin", run
    return own, found, where, run


def _ground_test(terrain: str | None, run, ownship: Path | None, own, origin_lla, config):
    """The track-level ground test over ``--terrain`` (default: the terrain the run records)."""
    from skyradar.cli.commands_process import terrain_window
    from skyradar.errors import InputError
    from skyradar.track.ground_tracks import default_ground_test, median_ground_down_m, terrain_surface

    if run is None:
        if terrain is not None and terrain.strip().lower() != "none":
            raise InputError(f"--terrain {terrain}: needs --ownship (the run or own-ship table) to place it")
        return True
    assert ownship is not None  # the run is the one opened from --ownship
    dem = terrain_window(terrain, run, config, ownship)
    if dem is None or not hasattr(dem, "height_at") or origin_lla is None:
        return True  # level ground at the own-ship's height above ground, where it has one
    return default_ground_test(config, terrain_surface(dem, origin_lla, median_ground_down_m(own)))


@app.command()
def track(
    detections: Annotated[
        Path, typer.Argument(help="Detections table (Parquet or CSV) from `skyradar process`.")
    ],
    output: Annotated[Path, typer.Option("-o", "--output", help="Tracks table to write (Parquet).")],
    model: _ModelOpt = TrackerModel.radar,
    origin: _OriginOpt = None,
    ownship: _OwnshipOpt = None,
    terrain: _TerrainOpt = None,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """Link detections into tracks: one row per confirmed track per frame.

    Needs columns time_s, range_m, radial_velocity_mps (time never decreasing); with north_m,
    east_m, down_m each track also gets a 3-D position, velocity and position covariance.
    Detections flagged is_ground or spur are left out. The tracker steps on every frame (the
    --ownship run's times, else the detections' frame column), so a track keeps its rows while it
    coasts through frames without a detection (column coasted). A track stays unconfirmed while
    one static point on the ground explains it (the --terrain surface, else level ground).
    """
    import json

    import numpy as np

    from skyradar.io.outputs import check_output
    from skyradar.io.tables import write_table
    from skyradar.track.io import radar_config_from_attrs, read_detections
    from skyradar.track.track_table import track_air_detections

    check_output(output, [detections, ownship], overwrite, kind="table")
    _origin(origin)  # a bad --origin is named before any reading
    table = read_detections(detections)
    config = radar_config_from_attrs(table)
    own, origin_lla, origin_from, run = _ownship_and_origin(ownship, table, origin)
    ground_test = _ground_test(terrain, run, ownship, own, origin_lla, config)
    # The own-ship state of a run has every frame's time: the tracker steps on frames without detections.
    run_times = None if own is None else own["time_s"].to_numpy(float)
    tracks, n_used = track_air_detections(table, model.value, config, origin_lla, own, run_times, ground_test)
    meta = {"radar_config": config.to_json(), "source": str(detections), "model": model.value}
    if origin_lla is not None:
        meta["origin_lla"] = json.dumps([float(v) for v in origin_lla])
    if table.attrs.get("ownship_signature"):  # carried on for `alert` (see skyradar.daa.provenance)
        meta["ownship_signature"] = table.attrs["ownship_signature"]
    write_table(tracks, output, metadata=meta)
    if tracks.empty:
        # A clear sky (no detections, or only ground and spurs) is a normal outcome, not an error.
        console.print(
            f"no tracks: {n_used} of {len(table)} detections left after dropping ground and "
            f"spurs; wrote an empty tracks table to {output}",
            soft_wrap=True,
        )
    n_frames = int(np.unique(table["time_s"].to_numpy(float)).size)
    result: dict[str, Any] = {
        "frames": n_frames,
        "detections": n_used,
        "tracks": int(tracks["track_id"].nunique()),
    }
    result |= {"rows": len(tracks), "model": model.value, "output": str(output), "origin_from": origin_from}
    emit_result(result, as_json, "tracks")


@app.command()
def evaluate(
    run: Annotated[Path, typer.Argument(help="Simulated frames run (Zarr) holding intruder truth.")],
    tracks: Annotated[Path, typer.Argument(help="Tracks table from `skyradar track`.")],
    threshold_px: Annotated[
        float, typer.Option("--threshold-px", callback=POSITIVE, help="Track-truth match distance, pixels.")
    ] = 5.0,
    gospa_c_px: Annotated[
        float, typer.Option("--gospa-c", callback=POSITIVE, help="GOSPA cut-off distance, pixels.")
    ] = 10.0,
    truth: Annotated[
        TruthMode,
        typer.Option(
            "--truth",
            help="'detectable': frames in a beam with expected SNR >= --min-snr-db; 'beam': every "
            "in-beam frame.",
        ),
    ] = TruthMode.detectable,
    min_snr_db: Annotated[
        float | None,
        typer.Option(
            "--min-snr-db",
            callback=_FINITE_DB,
            help="Detection threshold of the truth (default: the CA-CFAR's 50 % detection SNR, 7.5 dB "
            "for the prototype).",
        ),
    ] = None,
    coasting: Annotated[
        bool,
        typer.Option(
            "--coasting/--confirmed-only",
            help="Match a confirmed track's coasted (predicted) rows too, until it is closed.",
        ),
    ] = True,
    as_json: JsonOption = False,
) -> None:
    """Score tracks against the run's truth: track and truth counts, tracks per target, fragmentation,
    identity switches, completeness, GOSPA mean, innovation mean and 95th percentile (pixels and SI).
    The truth is what the radar could see (in a beam and at the detection SNR), from the scenario
    alone; several radar heads are combined."""
    from skyradar.io.tables import read_table
    from skyradar.track.evaluate import evaluate_run

    table = read_table(
        tracks,
        required=[
            "time_s",
            "track_id",
            "range_m",
            "radial_velocity_mps",
            "innovation_range_m",
            "innovation_radial_velocity_mps",
        ],
        sort_by="time_s",
        finite=["time_s", "track_id", "range_m", "radial_velocity_mps"],  # NaN would otherwise crash scipy
    )
    _check_tracks_of_run(table, tracks, run)
    result = evaluate_run(run, table, threshold_px, gospa_c_px, truth.value, min_snr_db, coasting)
    # The table shows no lists: one readable row for the per-target counts (1 = one track per aircraft).
    pairs = zip(result["targets"], result["tracks_per_target"], strict=True)
    result["tracks_by_target"] = ", ".join(f"{name} {n}" for name, n in pairs)
    result["held_rows_by_reason"] = ", ".join(f"{k} {v}" for k, v in result["held_rows"].items()) or "none"
    emit_result(result, as_json, "track evaluation")


def _check_tracks_of_run(table, tracks: Path, run: Path) -> None:
    """Tracks are scored only against the run they were made from: the same own-ship (the
    signature :mod:`skyradar.daa.provenance` carries, as ``alert`` checks it) and times inside the
    run's frames (one frame of slack). Scored against another run they would count every aircraft
    as missed, or match by chance."""
    import numpy as np

    from skyradar.daa.provenance import check_tracks_match_run
    from skyradar.errors import InputError
    from skyradar.io.frames import open_frames
    from skyradar.io.frames_model import frame_times_s

    ds = open_frames(run)
    check_tracks_match_run(table.attrs, str(tracks), ds, str(run), option="the run")
    t = frame_times_s(ds)
    times = table["time_s"].to_numpy(float)
    if t.size and times.size:
        slack = float(np.median(np.diff(t))) if t.size > 1 else 1.0
        if times.min() < t[0] - slack or times.max() > t[-1] + slack:
            raise InputError(
                f"{tracks}: field 'time_s' ({times.min():.6g}..{times.max():.6g} s) is outside the frames "
                f"of {run} ({t[0]:.6g}..{t[-1]:.6g} s): tracks of another run? score them against their own"
            )


@experiment_app.command("ch4")
def experiment_ch4(
    out: Annotated[
        Path, typer.Option("-o", "--output", help="Output directory for tables and figures.")
    ] = Path("out/ch4"),
    chain: Annotated[
        Ch4Chain,
        typer.Option(
            "--chain", help="'full' (simulate frames, detect, track) or 'geometry' (detections from truth)."
        ),
    ] = Ch4Chain.full,
    seed: Annotated[
        int,
        typer.Option(
            "--seed",
            callback=NON_NEGATIVE,
            help="Noise seed of the simulator (full chain) or synthetic detections.",
        ),
    ] = 0,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """Thesis ch4: radar-aware vs traditional tracker around an airfield (Circuit, Zulu, Free)."""
    from skyradar.experiments.ch4 import run as run_ch4
    from skyradar.io.outputs import check_output, mark_folder

    check_output(out, (), overwrite, kind="folder", option="--output")
    result = run_ch4(mark_folder(out), chain=chain.value, seed=seed)
    emit_result(result, as_json, "ch4 tracking")


@bench_app.command("track")
def bench_track(
    frames: Annotated[int, typer.Option("--frames", callback=COUNT, help="Frames to track.")] = 600,
    detections: Annotated[
        int,
        typer.Option("--detections", callback=NON_NEGATIVE, help="Detections per frame (clutter included)."),
    ] = 200,
    as_json: JsonOption = False,
) -> None:
    """Tracker frames per second at ~200 detections per frame, against a per-pair-loop baseline."""
    from skyradar.benchmarks.track import run as run_bench

    emit_measurement(run_bench(n_frames=frames, detections_per_frame=detections), as_json, "bench track")
