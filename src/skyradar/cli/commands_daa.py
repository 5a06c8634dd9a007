"""Detect-and-avoid commands: ``skyradar alert``, ``skyradar serve`` and ``skyradar bench alert``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from skyradar.cli.app import COUNT, JsonOption, app, bench_app, emit_measurement, emit_result
from skyradar.io.outputs import OVERWRITE_HELP

__all__ = ["alert", "serve", "bench_alert"]  # experiment encounters: skyradar.cli.commands_encounters


@app.command()
def alert(
    tracks: Annotated[
        Path, typer.Argument(help="Tracks table (Parquet or CSV) with 3-D NED position and velocity.")
    ],
    ownship: Annotated[
        Path,
        typer.Option(
            "--ownship",
            help="Own-ship state: the frames run (Zarr) or a table (Parquet/CSV, e.g. `skyradar export`'s "
            "ownship.parquet); its navigation solution (nav_*) is used, never the truth.",
        ),
    ],
    output: Annotated[Path, typer.Option("-o", "--output", help="Alerts table to write (Parquet).")],
    config: Annotated[
        str,
        typer.Option(
            "--config",
            help="Alert settings: radar (every result of the docs; default), do365b (DAIDALUS' DO-365B "
            "non-cooperative alerter: early alerting times 110/110/90 s, 2 of 4, reset after a 5 s gap), "
            "default (AlertConfig's own defaults) or FILE.yaml (fields of skyradar.daa.alert_config).",
        ),
    ] = "radar",
    no_advice: Annotated[
        bool, typer.Option("--no-advice", help="Skip the resolution bands and manoeuvre.")
    ] = False,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    as_json: JsonOption = False,
) -> None:
    """Turn tracks into DO-365-style alert levels, FLARM-style alarms and resolution advice.

    Levels: 0 none, 1 preventive, 2 corrective, 3 warning (non-cooperative well clear: 2200 ft,
    450 ft; alerting times 55/55/25 s; with --config radar 2 of 4 one-second periods, 5 s
    hysteresis, no alert from a track whose velocity is known worse than 6 m/s).
    """
    from skyradar.daa.alert_config import alert_config
    from skyradar.daa.pipeline import TRACK_COLUMNS, alert_summary, alerts_for_run
    from skyradar.io.outputs import check_output
    from skyradar.io.ownship_input import open_ownship
    from skyradar.io.tables import read_table, write_table

    settings = alert_config(config)  # a bad --config is named before anything is read
    config_file = None if config in ("radar", "default") else Path(config)
    check_output(output, [tracks, ownship, config_file], overwrite, kind="table")
    table = read_table(tracks, required=TRACK_COLUMNS, sort_by="time_s")
    run_ds = open_ownship(ownship)
    alerts = alerts_for_run(
        run_ds,
        table,
        settings,
        with_advice=not no_advice,
        run_name=str(ownship),
        tracks_name=str(tracks),
    )
    write_table(alerts, output)
    summary = alert_summary(alerts)
    levels = {key: summary.pop(key) for key in ("rows_level_1", "rows_level_2", "rows_level_3")}
    emit_result(summary | {"output": str(output), "config": config} | levels, as_json, "alerts")


@app.command()
def serve(
    run: Annotated[
        Path, typer.Argument(help="Frames run (Zarr); RUN.partial is followed while being written.")
    ],
    port: Annotated[int, typer.Option("--port", help="TCP port (0: any free port).")] = 8765,
    host: Annotated[
        str,
        typer.Option(
            "--host", help="Address to bind (default: this machine only; others get a warning: no login)."
        ),
    ] = "127.0.0.1",
    tracks: Annotated[
        Path | None, typer.Option("--tracks", help="Tracks table to alert on and display.")
    ] = None,
    alerts: Annotated[
        Path | None, typer.Option("--alerts", help="Alerts table (from `skyradar alert`).")
    ] = None,
    speed: Annotated[float, typer.Option("--speed", help="Replay speed, 0.1 to 100 (1 = real time).")] = 1.0,
) -> None:
    """Live traffic display of a run in the browser: plan view, alerts, bands, range-Doppler image.

    Without --alerts or --tracks a simulated run's intruder truth is alerted and shown. Only the
    page, the run's frames and the given tables are served, to pages from this server only.
    """
    import sys

    from skyradar.extras import require_extra

    require_extra("web", "skyradar serve")  # before anything: one line naming the extra, not a traceback
    import uvicorn

    from skyradar.web.net import LoopbackHostOnly, bind_socket, is_loopback
    from skyradar.web.server import check_speed, create_app

    check_speed(speed)
    local = is_loopback(host)
    sock = bind_socket(host, port)  # a taken port or a bad --host is one clear line here, not a server log
    try:
        web_app = create_app(run, tracks_path=tracks, alerts_path=alerts, speed=speed)
    except BaseException:
        sock.close()
        raise
    if not local:  # warned once the server is about to start, so that any error stays one line
        print(
            f"warning: --host {host} is not a loopback address: anyone who can reach it can watch this run",
            file=sys.stderr,
        )
    where = f"[{host}]" if ":" in host else host
    print(f"serving {run} at http://{where}:{sock.getsockname()[1]}/  (Ctrl-C to stop)", file=sys.stderr)
    # On loopback, refuse requests addressed to other names (DNS rebinding from a web page).
    asgi = LoopbackHostOnly(web_app) if local else web_app
    server = uvicorn.Server(uvicorn.Config(asgi, host=host, port=port, log_level="warning"))
    try:
        server.run(sockets=[sock])
    finally:
        sock.close()  # uvicorn closes it on shutdown; not when it fails to start


@bench_app.command("alert")
def bench_alert(
    tracks: Annotated[int, typer.Option("--tracks", callback=COUNT, help="Intruder tracks per frame.")] = 20,
    frames: Annotated[int, typer.Option("--frames", callback=COUNT, help="Frames (9.4 Hz).")] = 600,
    stream_frames: Annotated[
        int,
        typer.Option(
            "--stream-frames", callback=COUNT, help="Frames alerted one at a time, ours and the baseline."
        ),
    ] = 200,
    as_json: JsonOption = False,
) -> None:
    """Alerting frames per second (with advice), the range-only miss distance against a numpy baseline,
    and alerting frame by frame against re-alerting every row so far on each frame."""
    from skyradar.benchmarks.alert import run as run_bench

    result = run_bench(n_tracks=tracks, n_frames=frames, stream_frames=stream_frames)
    emit_measurement(result, as_json, "bench alert")
