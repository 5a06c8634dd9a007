"""The Typer application objects that every command module registers on."""

from __future__ import annotations

import json
from typing import Annotated, Any

import typer
from rich.console import Console
from rich.table import Table

from skyradar.io.tables import jsonable

__all__ = ["app", "experiment_app", "bench_app", "console", "emit_result", "JsonOption"]

app = typer.Typer(
    name="skyradar",
    help="Airborne FMCW radar for General Aviation detect-and-avoid: simulate, process, track, alert.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
experiment_app = typer.Typer(
    help="Reproduce the thesis chapters (seed-brief.md ch2..ch7).", no_args_is_help=True
)
bench_app = typer.Typer(help="Speed benchmarks; each prints JSON with --json.", no_args_is_help=True)
app.add_typer(experiment_app, name="experiment")
app.add_typer(bench_app, name="bench")

JsonOption = Annotated[bool, typer.Option("--json", help="Print the result as JSON (last stdout line).")]

# Progress bars and tables go to stderr so that stdout's last line is the JSON result.
console = Console(stderr=True)


def emit_result(result: dict[str, Any], as_json: bool, title: str) -> None:
    """Show ``result`` as a table (stderr); with ``as_json`` also print it as JSON, the last stdout line."""
    table = Table(title=title)
    table.add_column("key")
    table.add_column("value", justify="right")
    for key, value in result.items():
        if isinstance(value, dict | list):
            continue
        shown = f"{value:.4g}" if isinstance(value, float) else str(value)
        table.add_row(str(key), shown)
    console.print(table)
    if as_json:
        print(json.dumps(jsonable(result)), flush=True)
