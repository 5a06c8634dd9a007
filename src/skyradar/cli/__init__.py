"""Command-line interface: ``skyradar COMMAND --help``.

Each command module registers its commands on the shared Typer apps in :mod:`skyradar.cli.app`;
this module imports them, runs the command with its outputs locked (one writer per output) and turns
bad input into one line on stderr with exit code 2. Public: ``app`` (the Typer application, for
``typer.testing.CliRunner``) and :func:`main` (the ``skyradar`` script).

Modules: :mod:`.app` (the apps, option callbacks, result printing), :mod:`.choices` (the options'
fixed choices as string enums) and one module per group of commands: :mod:`.commands_sim`
(``simulate``, ``scenarios``, ``sweep``), :mod:`.commands_raw` (``rd``), :mod:`.commands_process`
(``process``, ``calibrate``, ``spur-map``), :mod:`.commands_track` (``track``, ``evaluate``),
:mod:`.commands_nav` (``state``), :mod:`.commands_gpscheck` (``gpscheck``), :mod:`.commands_daa`
(``alert``, ``serve``), :mod:`.commands_export` (``export``), :mod:`.commands_traffic` (``flight``,
``make-encounter``), :mod:`.commands_passive` (``passive``), :mod:`.commands_passive_sim`
(``simulate-passive``), :mod:`.commands_demo` (``demo``), :mod:`.commands_encounters` and
:mod:`.commands_clutter` (``experiment encounters``, ``experiment clutter``),
:mod:`.commands_closed_loop` (``experiment closed-loop``), :mod:`.commands_bluesky` (``experiment
bluesky``), :mod:`.commands_arrays` (``experiment arrays``); each also holds its
``experiment`` and ``bench`` commands.
"""

from __future__ import annotations

import importlib
import signal
import sys
from types import ModuleType
from typing import Any

import typer

import skyradar.cli.commands_arrays  # noqa: F401  (registers commands)
import skyradar.cli.commands_bluesky  # noqa: F401  (registers commands)
import skyradar.cli.commands_closed_loop  # noqa: F401  (registers commands)
import skyradar.cli.commands_clutter  # noqa: F401  (registers commands)
import skyradar.cli.commands_daa  # noqa: F401  (registers commands)
import skyradar.cli.commands_demo  # noqa: F401  (registers commands)
import skyradar.cli.commands_encounters  # noqa: F401  (registers commands)
import skyradar.cli.commands_export  # noqa: F401  (registers commands)
import skyradar.cli.commands_gpscheck  # noqa: F401  (registers commands)
import skyradar.cli.commands_nav  # noqa: F401  (registers commands)
import skyradar.cli.commands_passive  # noqa: F401  (registers commands)
import skyradar.cli.commands_passive_sim  # noqa: F401  (registers commands)
import skyradar.cli.commands_process  # noqa: F401  (registers commands)
import skyradar.cli.commands_raw  # noqa: F401  (registers commands)
import skyradar.cli.commands_track  # noqa: F401  (registers commands)
import skyradar.cli.commands_traffic  # noqa: F401  (registers commands)
from skyradar.cli import commands_sim  # noqa: F401  (registers commands)
from skyradar.cli.app import app
from skyradar.errors import InputError
from skyradar.io.locks import command_outputs

__all__ = ["app", "main"]


def _click_exception_modules() -> list[ModuleType]:
    """The ``exceptions`` modules of every click the installed typer may raise from.

    typer >= 0.2x vendors click as ``typer._click``; older typer raises the separate click package's
    classes. Catch both, so usage errors stay short whichever typer is installed.
    """
    modules = []
    for name in ("typer._click.exceptions", "click.exceptions"):
        try:
            modules.append(importlib.import_module(name))
        except ImportError:
            continue
    return modules


def _classes(name: str, *extra: type[BaseException]) -> tuple[type[Any], ...]:
    # type[Any]: the classes come from whichever click is installed, found by name at run time.
    found = [getattr(module, name) for module in _click_exception_modules() if hasattr(module, name)]
    return tuple(dict.fromkeys([*found, *extra]))


_NO_ARGS_IS_HELP = _classes("NoArgsIsHelpError")
_CLICK_ERRORS = _classes("ClickException")
_MISSING = _classes("MissingParameter")
_EXITS = _classes("Exit", typer.Exit)
_ABORTS = _classes("Abort", typer.Abort)
_INTERRUPTS: tuple[type[BaseException], ...] = (KeyboardInterrupt, *_ABORTS)


def _interrupt(signum: int, frame: object) -> None:
    # `kill` (SIGTERM) stops like Ctrl-C: a job's worker processes are ended (killed by the default
    # action, `experiment encounters` left its spawned workers running for minutes) and what
    # finished is kept for the rerun to resume.
    raise KeyboardInterrupt


def _os_error_line(exc: OSError) -> str:
    """``PATH: reason`` of a file-system error (both paths of a rename), on one line."""
    reason = exc.strerror or str(exc)
    paths = [str(p) for p in (exc.filename, exc.filename2) if p is not None]
    return f"{' -> '.join(paths)}: {reason}" if paths else reason


def _choice_error(exc: Exception) -> str | None:
    """``--method: must be one of cfar, os-cfar, shi-tomasi, got 'x'``: a value outside the choices of an
    option typed with an enum (:mod:`skyradar.cli.choices`), on one line; None for other usage errors."""
    param = getattr(exc, "param", None)
    if param is None or isinstance(exc, _MISSING):
        return None
    # typer >= 0.2x keeps the choices on the parameter's type descriptor; older typer on a click.Choice.
    choices = getattr(getattr(param, "type_descriptor", None), "choices", None)
    choices = choices or getattr(getattr(param, "type", None), "choices", None)
    if not choices:
        return None
    names = ", ".join(str(getattr(choice, "value", choice)) for choice in choices)
    if param.param_type_name == "argument":
        name = str(param.name).upper()
    else:
        name = next((opt for opt in param.opts if opt.startswith("--")), param.opts[0])
    errors = getattr(exc.__cause__, "errors", None)  # typer's pydantic check holds the value given
    first = errors()[0] if callable(errors) and errors() else {}
    if "input" in first:
        return f"{name}: must be one of {names}, got {first['input']!r}"
    return f"{name}: {str(getattr(exc, 'message', exc)).removeprefix('Value error, ')}"  # click.Choice's


def main() -> None:
    """Entry point of the ``skyradar`` script."""
    signal.signal(signal.SIGTERM, _interrupt)
    try:
        # Every output a command checks (skyradar.io.outputs.check_output, before any work) stays
        # locked until the command returns, after its output is renamed into place.
        with command_outputs():
            code = app(standalone_mode=False)
    except InputError as exc:
        # One line even when a wrapped library message spans several (pandas' CSV parser errors do).
        message = " ".join(part.strip() for part in str(exc).splitlines() if part.strip())
        print(f"error: {message}", file=sys.stderr)
        sys.exit(2)
    except OSError as exc:
        # The file system said no (permission, a name too long, not a folder, a full disk): the user's
        # paths, not a bug. One line with the path, as for bad input.
        print(f"error: {_os_error_line(exc)}", file=sys.stderr)
        sys.exit(2)
    except RuntimeError as exc:
        if not str(exc).startswith("Symlink loop"):  # pathlib's resolve() reports a loop this way
            raise
        print(f"error: {str(exc).removeprefix('Symlink loop from ')}: a symbolic link loop", file=sys.stderr)
        sys.exit(2)
    except _NO_ARGS_IS_HELP as exc:
        # A bare `skyradar` (or `skyradar bench`) asks for help: Typer's rich help is already printed
        # while the exception was built; the plain one is the message.
        text = exc.format_message()
        if text.strip():
            print(text)
        sys.exit(0)
    except _EXITS as exc:
        sys.exit(exc.exit_code)
    except _CLICK_ERRORS as exc:
        line = _choice_error(exc)
        if line is None:
            exc.show()
            sys.exit(exc.exit_code)
        print(f"error: {line}", file=sys.stderr)  # as a value checked by hand
        sys.exit(2)
    except _INTERRUPTS:
        code = 130
    # With standalone_mode=False click returns 130 on Ctrl-C instead of raising.
    if code == 130:
        print("interrupted: finished chunks are kept; rerun the same command to resume", file=sys.stderr)
    if isinstance(code, int) and code:
        sys.exit(code)
