"""GPS integrity commands: ``skyradar gpscheck``, ``skyradar experiment ch6``, ``skyradar bench gpscheck``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from skyradar.cli.app import (
    COUNT,
    NON_NEGATIVE,
    BenchSecondsOption,
    JsonOption,
    app,
    bench_app,
    console,
    emit_measurement,
    emit_result,
    experiment_app,
    number_in,
)
from skyradar.cli.choices import GpsCheckMethod
from skyradar.io.outputs import OVERWRITE_HELP

__all__ = ["gpscheck", "experiment_ch6", "bench_gpscheck", "parse_frames"]


def parse_frames(text: str | None, n_frames: int) -> list[int]:
    """Frame indices from ``--frames``: ``START:STOP`` (Python slice) or a comma list; all if None.

    Examples
    --------
    >>> parse_frames("2:5", 10), parse_frames("0,9", 10), len(parse_frames(None, 4))
    ([2, 3, 4], [0, 9], 4)
    """
    from skyradar.errors import InputError

    if text is None:
        return list(range(n_frames))
    try:
        if ":" in text:
            start, stop = (int(v) if v.strip() else None for v in text.split(":", 1))
            picked = list(range(n_frames))[slice(start, stop)]
        else:
            picked = [int(v) for v in text.split(",")]
    except ValueError:
        raise InputError(
            f"--frames: must be START:STOP or a comma list of frame numbers, got {text!r}"
        ) from None
    bad = [i for i in picked if not 0 <= i < n_frames]
    if bad or not picked:
        raise InputError(
            f"--frames: {text!r} selects no frame or frames outside 0..{n_frames - 1} of the run"
        )
    return picked


def _load_map(path: Path, ds, pixel_m: float, covers, run: Path):
    """(map image, grid, building height) from .osm.pbf or GeoTIFF; ``covers(extent, image)`` checks the
    footprints against the map (a raster's: against its data) before it is rendered."""
    from skyradar.errors import InputError
    from skyradar.extras import require_extra

    require_extra("geo", "skyradar gpscheck --map")
    from skyradar.nav.gpscheck.check import building_height_m, render_map

    origin = (ds.attrs.get("origin_lat_deg"), ds.attrs.get("origin_lon_deg"))
    if None in origin:  # own_north_m/own_east_m mean nothing on a map without the frame's origin
        raise InputError(f"{run}: no origin_lat_deg/origin_lon_deg attributes to put the run on the map")
    name = path.name.lower()
    if name.endswith(".pbf"):
        from skyradar.scene.osm_map import read_osm_map

        layers = read_osm_map(path, *origin)
        covers(layers)
        grid = layers.grid(pixel_m, margin_m=300.0)
        return render_map(layers, grid), grid, building_height_m(layers)
    if name.endswith((".tif", ".tiff")):
        from skyradar.scene.map_raster import read_map_raster

        raster = read_map_raster(path, None, *origin)
        covers(raster.grid, raster.image)  # the footprints on the map's data, not only its extent
        return raster.image, raster.grid, 0.0
    raise InputError(
        f"--map: {path} must be an OpenStreetMap .osm.pbf extract or a GeoTIFF (.tif), by its name"
    )


_OffsetNorth = Annotated[
    float, typer.Option("--gps-offset-north-m", callback=number_in(-1e4, 1e4), help="Add to GPS north, m.")
]
_OffsetEast = Annotated[
    float, typer.Option("--gps-offset-east-m", callback=number_in(-1e4, 1e4), help="Add to GPS east, m.")
]
_OffsetHeading = Annotated[
    float,
    typer.Option("--gps-offset-heading-deg", callback=number_in(-180, 180), help="Add to heading, deg."),
]
_Buildings = Annotated[
    float | None,
    typer.Option(
        "--building-height-m",
        callback=number_in(0.0, 500.0),
        help="Typical building height for the layover correction (default: the OSM map's; 0 for a raster).",
    ),
]
_Frames = Annotated[
    str | None, typer.Option("--frames", help="Frames to check: START:STOP or a comma list (default all).")
]
_Run = Annotated[Path, typer.Argument(help="Frames run (Zarr) of a side-looking (wingtip) radar.")]
_Map = Annotated[Path, typer.Option("--map", help="Reference map: OpenStreetMap .osm.pbf or GeoTIFF.")]
_Method = Annotated[
    GpsCheckMethod,
    typer.Option("--method", help="Pre-processing of the radar and map images before they are compared."),
]


@app.command()
def gpscheck(
    run: _Run,
    map_path: _Map,
    output: Annotated[Path, typer.Option("-o", "--output", help="Per-frame check table to write (Parquet).")],
    method: _Method = GpsCheckMethod.clahe_ridge,
    frames: _Frames = None,
    offset_north_m: _OffsetNorth = 0.0,
    offset_east_m: _OffsetEast = 0.0,
    offset_heading_deg: _OffsetHeading = 0.0,
    building_height: _Buildings = None,
    alert_frames: Annotated[
        int, typer.Option("--alert-frames", callback=COUNT, help="Alert after this many inconsistent frames.")
    ] = 3,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """GPS integrity: each frame's radar ground image against the map at the GPS pose (ch6).

    Per frame: the GPS pose's SSIM, the correction (d_north_m, d_east_m, d_heading_deg) that best aligns
    radar and map with its confidence (psr), and a verdict: consistent, inconsistent, or no decision
    (wing up; too little structure). An alert when GPS is inconsistent for --alert-frames decided
    frames in a row. The --gps-offset-* options move the run's GPS pose, to try a spoofed GPS.
    """
    from skyradar.io.frames import open_frames, radar_config_of
    from skyradar.io.outputs import check_output
    from skyradar.io.tables import write_table
    from skyradar.nav.gpscheck.check import PIXEL_M, check_coverage, check_run, prepare_map, radar_side
    from skyradar.nav.gpscheck.monitor import MonitorSettings

    check_output(output, [run, map_path], overwrite, kind="table")
    ds = open_frames(run)
    config = radar_config_of(ds, str(run))
    radar_side(config, str(run))  # a forward mount is refused before the map is read
    picked = parse_frames(frames, ds.sizes["time"])
    gps_offset = (offset_north_m, offset_east_m, offset_heading_deg)

    def covers(extent, image=None) -> None:
        check_coverage(
            ds,
            config,
            extent,
            frames=picked,
            gps_offset=gps_offset,
            source=str(run),
            map_source=str(map_path),
            map_image=image,
        )

    image, grid, building_m = _load_map(map_path, ds, PIXEL_M, covers, run)
    building_m = building_m if building_height is None else building_height
    maps = prepare_map(image, [method.value])
    settings = MonitorSettings(alert_frames=alert_frames)
    table = check_run(
        ds,
        config,
        maps[method.value],
        grid,
        frames=picked,
        method=method.value,
        settings=settings,
        source=str(run),
        gps_offset=gps_offset,
        building_m=building_m,
    )
    write_table(
        table,
        output,
        metadata={
            "radar_config": config.to_json(),
            "source": str(run),
            "map": str(map_path),
            "method": method.value,
        },
    )
    result = _summary(table, output)
    _print_summary(result, table, alert_frames)
    emit_result(result, as_json, "gpscheck")


def _summary(table, output: Path) -> dict:
    counts = table["verdict"].value_counts().to_dict()
    decided = table["verdict"].isin(["consistent", "inconsistent"])
    alert_rows = table[table["alert"]]
    return {
        "frames": len(table),
        "consistent": counts.get("consistent", 0),
        "inconsistent": counts.get("inconsistent", 0),
        "no_decision_wing_up": counts.get("no decision: wing up", 0),
        "no_decision_structure": counts.get("no decision: too little structure", 0),
        "median_correction_m": float(table.loc[decided, "correction_m"].median()) if decided.any() else None,
        "alert": bool(len(alert_rows)),
        "alert_frame": int(alert_rows["frame"].iloc[0]) if len(alert_rows) else None,
        "output": str(output),
    }


def _print_summary(result: dict, table, alert_frames: int) -> None:
    """The one-line summary, and the alert line when there is one."""
    console.print(
        f"gpscheck: {result['frames']} frames: {result['consistent']} consistent, {result['inconsistent']}"
        f" inconsistent, {result['no_decision_wing_up']} no decision (wing up),"
        f" {result['no_decision_structure']} no decision (too little structure)",
        soft_wrap=True,  # one line whatever the terminal width
    )
    alert_rows = table[table["alert"]]
    if len(alert_rows):
        first = alert_rows.iloc[0]
        console.print(
            f"ALERT at frame {int(first['frame'])} (t = {first['time_s']:.1f} s): GPS inconsistent with the"
            f" radar for {alert_frames} decided frames in a row; correction {first['correction_m']:.0f} m,"
            f" {first['d_heading_deg']:+.1f} deg",
            soft_wrap=True,
        )


@experiment_app.command("ch6")
def experiment_ch6(
    out: Annotated[
        Path, typer.Option("-o", "--output", help="Output directory for table, JSON and figures.")
    ] = Path("out/ch6"),
    seed: Annotated[
        int, typer.Option("--seed", callback=NON_NEGATIVE, help="Speckle, map and frames seed.")
    ] = 6,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """ch6: GPS check over Helsinki's OpenStreetMap: thesis methods 5/8/9 vs the continuous search, spoofing.

    Prints the thesis' table (17/20 correct, 14 % false positives for method 8) beside ours, the
    continuous search's errors and the spoofing detection rates; writes figures and ch6.json.
    """
    from rich.progress import Progress

    from skyradar.experiments.ch6 import N_FRAMES, run
    from skyradar.io.outputs import check_output, mark_folder

    check_output(out, (), overwrite, kind="folder", option="--output")
    mark_folder(out)
    with Progress(console=console) as progress:
        task = progress.add_task("ch6 frames", total=N_FRAMES + 6)
        result = run(out, seed=seed, progress=lambda: progress.advance(task))
    _print_ch6(result["table"])
    missed = result["acceptance_failures"]
    console.print(
        f"acceptance: {len(missed)} bound(s) missed: {missed}" if missed else "acceptance: every bound met"
    )
    emit_result({k: v for k, v in result.items() if k != "table"}, as_json, "ch6")


def _print_ch6(rows: list[dict]) -> None:
    from rich.table import Table

    view = Table(title="ch6: 20 random frames, 300 decoys each; thesis in brackets")
    for col in ("method", "correct", "heading err deg", "position err m", "false positives"):
        view.add_column(col)

    def ref(value, fmt):
        return "" if value is None or value != value else f" [{format(value, fmt)}]"

    for r in rows:
        fp, t_fp = r["false_positive_fraction"], r["thesis_false_positive_fraction"]
        number = f" ({r['thesis_method']})" if r["thesis_method"] else ""
        view.add_row(
            f"{r['method']}{number}",
            f"{r['correct']}/{r['frames']}{ref(r['thesis_correct'], '.0f')}",
            f"{r['heading_error_deg']:.1f}{ref(r['thesis_heading_error_deg'], '.0f')}",
            f"{r['position_error_m']:.1f}{ref(r['thesis_position_error_m'], '.0f')}",
            ("-" if fp != fp else f"{100 * fp:.1f}%") + ref(None if t_fp is None else 100 * t_fp, ".0f"),
        )
    console.print(view)


@bench_app.command("gpscheck")
def bench_gpscheck(
    seconds: BenchSecondsOption = 2.0,
    as_json: JsonOption = False,
) -> None:
    """One GPS-check frame (300 poses by SSIM; the continuous search) vs a straightforward baseline."""
    from skyradar.benchmarks.gpscheck import run as run_bench

    emit_measurement(run_bench(min_time_s=seconds), as_json, "bench gpscheck")
