"""Processing commands: ``process``, ``calibrate``, ``spur-map``, ``experiment ch3``, ``bench process``."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer

from skyradar.cli.app import (
    COUNT,
    NON_NEGATIVE,
    POSITIVE,
    PROBABILITY,
    SCHEDULER,
    WORKERS,
    BenchSecondsOption,
    HeadOption,
    JsonOption,
    app,
    bench_app,
    check_number,
    console,
    emit_measurement,
    emit_result,
    experiment_app,
    number_in,
    open_one_head,
)
from skyradar.cli.choices import Ch3Path, Detector, SpurMode, SpurPixels, Suppression
from skyradar.io.outputs import OVERWRITE_HELP

__all__ = ["process", "calibrate", "spur_map", "experiment_ch3", "bench_process", "bench_realtime"]


def _progress(total: int, label: str):
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeRemainingColumn

    bar = Progress(
        "[progress.description]{task.description}",
        BarColumn(),
        MofNCompleteColumn(),
        TimeRemainingColumn(),
        console=console,
        transient=True,
    )
    return bar, bar.add_task(label, total=total)


# The options of `process`, named once so that the command reads as: parse, call, write, print.
_SpurMapOpt = Annotated[
    Path | None, typer.Option("--spur-map", help="Spur map (.npz from `skyradar spur-map`).")
]
_SpurModeOpt = Annotated[
    SpurMode,
    typer.Option("--spur-mode", help="'mask' spur pixels before detection or 'flag' detections in them."),
]
_MethodOpt = Annotated[
    Detector,
    typer.Option(
        "--method", help="Detector: cfar (CA-CFAR), os-cfar (ordered-statistic CFAR) or shi-tomasi (corners)."
    ),
]
_PfaOpt = Annotated[
    float,
    typer.Option("--pfa", callback=PROBABILITY, help="CFAR false-alarm probability per pixel, in (0, 1)."),
]
_PfaSecondaryOpt = Annotated[
    float,
    typer.Option(
        "--pfa-secondary",
        callback=number_in(0.0, 1.0, high_open=True),
        help="False-alarm probability of the secondary threshold in clutter-nulled cells, in [0, 1): "
        "detections that pass it but not --pfa are flagged 'secondary' and only update a confirmed "
        "track inside its gate. 0, or not above --pfa: none.",
    ),
]
_TerrainOpt = Annotated[
    str | None,
    typer.Option(
        "--terrain",
        help="Ground for the ground filter: a DEM file (.hgt/.tif/.npz) or flat, fractal, jacksboro, none "
        "(default: the scenario terrain the run records, if any).",
    ),
]
_RadarConfigOpt = Annotated[
    Path | None, typer.Option("--radar-config", help="RadarConfig JSON (e.g. from `skyradar calibrate`).")
]
_SuppressionOpt = Annotated[
    Suppression,
    typer.Option(
        "--suppression",
        help="Ground clutter suppression before detection: auto (where the run has own-ship velocity, "
        "attitude and height above ground), knowledge-aided (required), none.",
    ),
]
_SchedulerOpt = Annotated[
    str | None, typer.Option(callback=SCHEDULER, help="Address of an existing Dask scheduler.")
]
_WorkersOpt = Annotated[
    int | None, typer.Option(callback=WORKERS, help="Run on a local Dask cluster of this many workers.")
]
_ChunkFramesOpt = Annotated[
    int, typer.Option(callback=COUNT, help="Frames per Dask task (with --scheduler/--workers).")
]


@app.command()
def process(
    run: Annotated[Path, typer.Argument(help="Frames run (Zarr directory).")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Detections table to write (Parquet).")],
    spur_map: _SpurMapOpt = None,
    spur_mode: _SpurModeOpt = SpurMode.mask,
    method: _MethodOpt = Detector.cfar,
    pfa: _PfaOpt = 2e-8,
    pfa_secondary: _PfaSecondaryOpt = 1e-4,
    terrain: _TerrainOpt = None,
    radar_config: _RadarConfigOpt = None,
    suppression: _SuppressionOpt = Suppression.auto,
    scheduler: _SchedulerOpt = None,
    workers: _WorkersOpt = None,
    chunk_frames: _ChunkFramesOpt = 64,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    realtime: Annotated[
        bool,
        typer.Option(
            "--realtime",
            help="Time every frame here, on one processor, as if the frames arrived at their recorded "
            "times: the summary's realtime_* keys give deadline misses (a frame not done before its "
            "head's next one arrives) and latency percentiles; the table's metadata 'frame_timing' "
            "holds each frame's processing time, latency and whether it kept up.",
        ),
    ] = False,
    as_json: JsonOption = False,
) -> None:
    """Detect objects in every frame and locate them in 3-D: one row per detection per frame.

    Columns: time_s, frame, range_m, radial_velocity_mps, range/doppler_bin, snr_db, power_db,
    azimuth/elevation_rad (antenna frame), x/y/z_body_m, north/east/down_m, lat/lon/alt, is_ground, spur,
    secondary.
    """
    import pandas as pd

    from skyradar.daa.provenance import ownship_signature
    from skyradar.errors import InputError
    from skyradar.io.frames import open_frames, radar_config_of
    from skyradar.io.frames_heads import store_heads
    from skyradar.io.navigation import navigation_source
    from skyradar.io.outputs import check_output
    from skyradar.io.tables import write_table

    if realtime and (scheduler is not None or workers):
        raise InputError("--realtime times frames on one processor: leave out --scheduler and --workers")
    dem_path = Path(terrain) if terrain is not None and Path(terrain).exists() else None
    check_output(output, [run, spur_map, dem_path, radar_config], overwrite, kind="table")
    ds = open_frames(run)
    config = _read_config(radar_config) if radar_config is not None else radar_config_of(ds, str(run))
    # The pipeline's imports (about 1.5 s) come after the run is read: a bad run fails fast.
    from skyradar.process.detect_run import detect_run_heads, detection_summary
    from skyradar.process.realtime import frame_latencies, realtime_summary
    from skyradar.process.spurs import SpurMap

    spurs = SpurMap.load(spur_map, config) if spur_map is not None else None
    dem = terrain_window(terrain, ds, config, run)
    bar, task = _progress(ds.sizes["time"] * len(store_heads(run) or [run]), "frames")
    frame_costs: dict[str, list] | None = {} if realtime else None
    with bar:  # every radar head of the run, one table with a `radar` column (skyradar.io.frames_heads)
        table, configs = detect_run_heads(
            run,
            None if radar_config is None else config,
            lambda n: bar.update(task, completed=n),
            spurs=spurs,
            terrain=dem,
            method=method.value,
            spur_mode=spur_mode.value,
            pfa=pfa,
            scheduler=scheduler,
            workers=workers,
            chunk_frames=chunk_frames,
            suppression=suppression.value,
            frame_costs=frame_costs,
            pfa_secondary=pfa_secondary or None,
        )
    # The own-ship signature lets `alert` check that the tracks and its --ownship run belong together.
    meta = {"radar_config": config.to_json(), "source": str(run)}
    if len(configs) > 1:  # each head's RadarConfig (mount, lever arm); radar_config is the first's
        meta["radar_heads"] = json.dumps({name: c.to_dict() for name, c in configs.items()})
    meta.update({"ownship_signature": sig} if (sig := ownship_signature(ds, str(run))) else {})
    # Which own-ship state placed the detections: nav_* (GNSS/AHRS with errors), or an old store's truth.
    meta["navigation"] = navigation_source(ds) or "none"
    if frame_costs is not None:
        timed = frame_latencies(
            pd.DataFrame(
                [(name, *cost) for name, costs in frame_costs.items() for cost in costs],
                columns=["radar", "frame", "time_s", "processing_s"],
            )
        )
        meta["frame_timing"] = timed.to_json(orient="records")
    write_table(table, output, metadata=meta)
    result = detection_summary(table, ds.sizes["time"]) | {"navigation": meta["navigation"]}
    if frame_costs is not None:
        result.update({f"realtime_{key}": value for key, value in realtime_summary(timed).items()})
    result["output"] = str(output)
    emit_result(result, as_json, "detections")


def terrain_window(terrain: str | None, ds, config, run: Path):
    from skyradar.scene.terrain_names import recorded_terrain, terrain_for_run

    if terrain is None:  # the scenario terrain the run was simulated over, if it records one
        return recorded_terrain(ds, str(run))
    if terrain.strip().lower() == "none":
        return None
    # Only the window the own-ship can see is read; a terrain away from the track is refused.
    return terrain_for_run(terrain, ds, config.range_limit_m, str(run))


def _read_config(path: Path):
    from skyradar.config import RadarConfig
    from skyradar.errors import InputError

    try:
        return RadarConfig.from_json(path.read_text())
    except OSError as exc:
        raise InputError(f"{path}: cannot read radar config ({exc.strerror})") from None
    except (ValueError, KeyError, TypeError) as exc:
        raise InputError(f"{path}: not a radar config ({type(exc).__name__}: {exc})") from None
    except RecursionError:  # JSON nested deeper than the parser's stack
        raise InputError(f"{path}: not a radar config (JSON nested too deeply)") from None


@app.command()
def calibrate(
    run: Annotated[Path, typer.Argument(help="Frames run (Zarr) with a reflector at a known position.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Calibrated RadarConfig to write (JSON).")],
    range_m: Annotated[float, typer.Option("--range-m", callback=POSITIVE, help="Reflector range, m.")],
    azimuth_deg: Annotated[
        float,
        typer.Option(
            "--azimuth-deg",
            callback=number_in(-180.0, 180.0),
            help="Reflector azimuth, deg (antenna frame, right +).",
        ),
    ],
    elevation_deg: Annotated[
        float,
        typer.Option(
            "--elevation-deg",
            callback=number_in(-90.0, 90.0),
            help="Reflector elevation, deg (antenna frame, up +).",
        ),
    ],
    frames: Annotated[
        int, typer.Option("--frames", callback=COUNT, help="Frames to average (from the start).")
    ] = 20,
    phase_only: Annotated[
        bool, typer.Option("--phase-only", help="Calibrate phases only, not gains.")
    ] = False,
    head: HeadOption = None,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """Per-antenna phase/gain calibration from a reflector at a known position (thesis: a building)."""
    import numpy as np

    from skyradar.errors import InputError
    from skyradar.io.checks import check_finite_frames
    from skyradar.io.frames import radar_config_of
    from skyradar.io.json_results import write_json_atomic
    from skyradar.io.outputs import check_output
    from skyradar.process.calibration import calibrate_from_frames, reflector_position

    check_output(output, [run], overwrite, kind="file")
    ds = open_one_head(run, head, "skyradar calibrate")
    config = radar_config_of(ds, str(run))
    if range_m >= config.range_limit_m:
        raise InputError(
            f"--range-m: {range_m:g} m is beyond {run}'s processed range ({config.range_limit_m:g} m)"
        )
    p = reflector_position(range_m, np.radians(azimuth_deg), np.radians(elevation_deg))
    cube = np.asarray(ds["iq"].isel(time=slice(0, max(frames, 1))).values)
    check_finite_frames(cube, 0, run)
    calibrated = calibrate_from_frames(cube, p, config, gain=not phase_only)
    write_json_atomic(output, calibrated.to_dict())
    phases = np.degrees(np.angle(calibrated.rx_calibration))
    result = {
        "frames": int(cube.shape[0]),
        "output": str(output),
        "phase_deg": phases.round(3).tolist(),
        "gain_db": (20 * np.log10(np.abs(calibrated.rx_calibration))).round(3).tolist(),
    }
    emit_result(result, as_json, "calibration")


@app.command("spur-map")
def spur_map(
    run: Annotated[Path, typer.Argument(help="Frames of a static scene (Zarr directory).")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Spur map to write (.npz).")],
    threshold: Annotated[
        float,
        typer.Option(
            "--threshold",
            callback=PROBABILITY,
            help="Hit frequency above which a pixel is a spur, in (0, 1).",
        ),
    ] = 0.05,
    pixels: Annotated[
        SpurPixels,
        typer.Option("--pixels", help="'peaks' (detector points, thesis) or 'hits' (every lit pixel)."),
    ] = SpurPixels.hits,
    head: HeadOption = None,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """Learn a spur map from frames of a static scene (every fixed bright pixel is a spur)."""
    import numpy as np

    from skyradar.io.checks import check_finite_frames
    from skyradar.io.frames import radar_config_of
    from skyradar.io.outputs import check_output
    from skyradar.process.detect import integrate_channels
    from skyradar.process.spurs import learn_spur_map

    check_output(output, [run], overwrite, kind="file")
    ds = open_one_head(run, head, "skyradar spur-map")
    config = radar_config_of(ds, str(run))

    def frames():
        for i in range(ds.sizes["time"]):
            cube = np.asarray(ds["iq"][i].values)
            check_finite_frames(cube[None], i, run)  # a NaN frame would silently mark no spurs
            yield integrate_channels(cube, config.rx_calibration)

    learned = learn_spur_map(frames(), config, threshold, pixels.value)
    learned.save(output)
    result = {
        "frames": learned.n_frames,
        "spur_pixels": int(learned.mask.sum()),
        "threshold": threshold,
        "output": str(output),
    }
    emit_result(result, as_json, "spur map")


@experiment_app.command("ch3")
def experiment_ch3(
    out: Annotated[
        Path, typer.Option("-o", "--output", help="Output directory for figures and tables.")
    ] = Path("out/ch3"),
    frames: Annotated[
        int, typer.Option("--frames", callback=COUNT, help="Flyover frames (thesis: 300).")
    ] = 300,
    path: Annotated[
        Ch3Path,
        typer.Option("--path", help="'circuit' (500-3000 m racetrack) or 'approach' (32 s at 9.4 fps)."),
    ] = Ch3Path.circuit,
    seed: Annotated[int, typer.Option("--seed", callback=NON_NEGATIVE, help="Random seed.")] = 0,
    rx_spacing: Annotated[
        float,
        typer.Option(
            "--rx-spacing",
            callback=number_in(0.0, 1.0, low_open=True),
            help="Side of the 2x2 receive square, wavelengths, in (0, 1]. 0.6: CRLB 17 % below 0.5's, "
            "unambiguous within +-56 deg of boresight (0.5: whole front hemisphere).",
        ),
    ] = 0.6,
    compare: Annotated[
        str,
        typer.Option(
            "--compare", help="Comma-separated further spacings flown with the same seed ('' for none)."
        ),
    ] = "0.5,0.7",
    pitch: Annotated[
        float,
        typer.Option(
            "--pitch-deg", callback=number_in(-90.0, 90.0), help="Boresight elevation above the horizon, deg."
        ),
    ] = 3.0,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """ch3: radar on the ground aimed at the sky: spur map, calibration on a building, aircraft flyover."""
    from skyradar.errors import InputError
    from skyradar.experiments.ch3 import run as run_ch3
    from skyradar.io.outputs import check_output, mark_folder

    check_output(out, (), overwrite, kind="folder", option="--output")

    try:
        others = tuple(float(s) for s in compare.split(",") if s.strip())
    except ValueError:
        raise InputError(
            f"experiment ch3: option '--compare' must be comma-separated numbers, got {compare!r}"
        ) from None
    for spacing in others:
        check_number("--compare", spacing, 0.0, 1.0, low_open=True)
    mark_folder(out)
    result = run_ch3(
        out,
        n_frames=frames,
        path=path.value,
        seed=seed,
        pitch_deg=pitch,
        rx_spacing_wavelengths=rx_spacing,
        compare_spacings=others,
    )
    emit_result(result, as_json, "ch3: detection and direction of arrival")


@bench_app.command("process")
def bench_process(
    seconds: BenchSecondsOption = 2.0,
    as_json: JsonOption = False,
) -> None:
    """Detection + DoA frames per second (333 x 250 x 4), ours vs a baseline; suppressed_*: terrain cubes;
    rx1_*, rx6_*, rx8_*: 1-, 6- and 8-channel arrays."""
    from skyradar.benchmarks.process import run as run_bench

    emit_measurement(run_bench(min_time_s=seconds), as_json, "bench process")


@bench_app.command("realtime")
def bench_realtime(
    seconds: Annotated[
        float,
        typer.Option(
            "--duration-s",
            callback=number_in(5.0, 600.0),
            help="Wall time of frames fed in real time, s (5-600).",
        ),
    ] = 60.0,
    frame_rate: Annotated[
        float,
        typer.Option(
            "--frame-rate-hz", callback=number_in(0.5, 100.0), help="Frames per second of each head, Hz."
        ),
    ] = 9.4,
    as_json: JsonOption = False,
) -> None:
    """Three heads over hills processed as their frames arrive, on one core: deadline misses, latency."""
    from skyradar.benchmarks.realtime import run_realtime

    emit_measurement(run_realtime(seconds=seconds, frame_rate_hz=frame_rate), as_json, "bench realtime")
