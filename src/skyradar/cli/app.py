"""The Typer application objects that every command module registers on."""

from __future__ import annotations

import json
import logging
import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console
from rich.table import Table

from skyradar.errors import InputError
from skyradar.io.json_results import jsonable

__all__ = [
    "app",
    "experiment_app",
    "bench_app",
    "console",
    "emit_result",
    "emit_measurement",
    "JsonOption",
    "number_in",
    "check_number",
    "POSITIVE",
    "NON_NEGATIVE",
    "COUNT",
    "PROBABILITY",
    "WORKERS",
    "SCHEDULER",
    "CHUNK_SAMPLES",
    "HeadOption",
    "open_one_head",
    "notes_after_inputs",
]

app = typer.Typer(
    name="skyradar",
    help="Airborne FMCW radar for General Aviation detect-and-avoid: simulate, process, track, alert.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
experiment_app = typer.Typer(
    help="Reproduce thesis chapters ch2-ch7; DAA encounter sets, open and closed loop; skyradar in BlueSky.",
    no_args_is_help=True,
)
bench_app = typer.Typer(help="Speed benchmarks; each prints JSON with --json.", no_args_is_help=True)
app.add_typer(experiment_app, name="experiment")
app.add_typer(bench_app, name="bench")

JsonOption = Annotated[bool, typer.Option("--json", help="Print the result as JSON (last stdout line).")]

# Progress bars and tables go to stderr so that stdout's last line is the JSON result.
console = Console(stderr=True)


@contextmanager
def notes_after_inputs() -> Iterator[None]:
    """Hold the warnings skyradar logs in the block (the one-line repair note of each flight file) and
    show them when the block ends well: when an input read in the block is refused, its error is the
    one line on stderr, not the note of the file read before it."""
    held: list[logging.LogRecord] = []

    class _Hold(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            held.append(record)

    logger, handler = logging.getLogger("skyradar"), _Hold(logging.WARNING)
    propagate = logger.propagate
    logger.addHandler(handler)
    logger.propagate = False
    try:
        yield
    finally:
        logger.removeHandler(handler)
        logger.propagate = propagate
    for record in held:  # reached only when the block raised nothing
        logging.getLogger(record.name).handle(record)


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


def emit_measurement(result: dict[str, Any], as_json: bool, title: str) -> None:
    """:func:`emit_result` for a measurement (a benchmark): with the code that measured it
    (:func:`skyradar.code_version.code_version`), the command, the UTC date and the 1-minute load
    average, so that a saved result says what ran, when, and how busy the machine was."""
    import os
    import sys
    import time

    from skyradar.code_version import code_version

    result = {
        "version": code_version(),
        "command": "skyradar " + " ".join(sys.argv[1:]),
        "date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "load_average_1min": round(os.getloadavg()[0], 2),  # unless the benchmark sampled its own
    } | result
    emit_result(result, as_json, title)


def check_number(
    name: str,
    value: float | None,
    low: float | None = None,
    high: float | None = None,
    *,
    low_open: bool = False,
    high_open: bool = False,
) -> float | None:
    """``value`` if finite and within the bounds, else :class:`InputError` naming ``name`` and the value.

    ``None`` (an option left unset) passes. Typer's ``min``/``max`` let NaN through (every comparison
    with NaN is false), so every float option is checked here.

    Examples
    --------
    >>> check_number("--min-time-s", 2.0, 0.0, low_open=True)
    2.0
    >>> check_number("--min-time-s", float("nan"), 0.0, low_open=True)
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: --min-time-s: must be a finite number > 0, got nan
    """
    from skyradar.errors import InputError

    if value is None:
        return None
    below = low is not None and (value <= low if low_open else value < low)
    above = high is not None and (value >= high if high_open else value > high)
    if not math.isfinite(value) or below or above:
        bounds = []
        if low is not None:
            bounds.append(f"{'>' if low_open else '>='} {low:g}")
        if high is not None:
            bounds.append(f"{'<' if high_open else '<='} {high:g}")
        rule = " ".join(["an integer" if isinstance(value, int) else "a finite number", " and ".join(bounds)])
        raise InputError(f"{name}: must be {rule.strip()}, got {value!r}")
    return value


def number_in(
    low: float | None = None, high: float | None = None, *, low_open: bool = False, high_open: bool = False
) -> Callable[..., Any]:
    """A Typer option callback that applies :func:`check_number` under the option's own name.

    Examples
    --------
    >>> callback = number_in(0.0, 1.0, low_open=True, high_open=True)
    >>> callback(None, None, 0.5)
    0.5
    """

    def callback(ctx: typer.Context, param: typer.CallbackParam, value: Any) -> Any:
        # During shell completion or --help parsing the value may be absent.
        if ctx is not None and getattr(ctx, "resilient_parsing", False):
            return value
        name = param.opts[0] if param is not None and param.opts else "value"
        return check_number(name, value, low, high, low_open=low_open, high_open=high_open)

    return callback


POSITIVE = number_in(0.0, low_open=True)  # durations, distances, rates: finite and > 0
BenchSecondsOption = Annotated[
    float, typer.Option("--min-time-s", callback=POSITIVE, help="Minimum timing per implementation, s.")
]
NON_NEGATIVE = number_in(0.0)  # counts and durations where 0 means "skip"
COUNT = number_in(1)  # frames, workers, chunk sizes: at least one
# IQ samples per chunk: each chunk has a fixed cost (a write, filter state), so below a few thousand
# samples the overhead dominates (1-sample chunks made a 1-s recording take hours); 2**26 complex
# samples are 512 MiB.
CHUNK_SAMPLES = number_in(4096, 1 << 26)
PROBABILITY = number_in(0.0, 1.0, low_open=True, high_open=True)


HeadOption = Annotated[
    str | None, typer.Option("--head", help="The radar head to use, by name, in a run of several heads.")
]


def open_one_head(run: Path, head: str | None, what: str):
    """The frames of one head of ``run`` for a command that uses one (``what``): a run of several
    heads must name it (taking the first silently would estimate, map or calibrate the wrong one)."""
    from skyradar.io.frames import open_frames
    from skyradar.io.frames_heads import store_heads

    heads = store_heads(run) if Path(run).is_dir() else None
    if heads and len(heads) > 1 and head is None:
        raise InputError(
            f"{run}: has {len(heads)} radar heads ({', '.join(heads)}); {what} uses one: give --head NAME"
        )
    if heads and head is not None and head not in heads:
        raise InputError(f"--head: {head!r} is not a head of {run} ({', '.join(heads)})")
    return open_frames(run, head=head)


def WORKERS(ctx: typer.Context, param: typer.CallbackParam, value: int | None) -> int | None:  # noqa: N802
    """Callback for local worker counts: 1 to 4 per core (:func:`~skyradar.parallel.check_workers`)."""
    from skyradar.parallel import check_workers

    if ctx is not None and getattr(ctx, "resilient_parsing", False):
        return value
    name = param.opts[0] if param is not None and param.opts else "--workers"
    return check_workers(value, name)


def SCHEDULER(ctx: typer.Context, param: typer.CallbackParam, value: str | None) -> str | None:  # noqa: N802
    """Callback for ``--scheduler``: a Dask address (:func:`~skyradar.parallel.check_scheduler`), before
    any work."""
    from skyradar.parallel import check_scheduler

    if ctx is not None and getattr(ctx, "resilient_parsing", False):
        return value
    name = param.opts[0] if param is not None and param.opts else "--scheduler"
    return check_scheduler(value, name)
