"""Command-line interface: ``skyradar COMMAND --help``.

Each command module registers its commands on the shared Typer apps in :mod:`skyradar.cli.app`;
this module imports them and turns bad input into one line on stderr with exit code 2.
"""

from __future__ import annotations

import sys

import click

import skyradar.cli.commands_daa  # noqa: F401  (registers commands)
import skyradar.cli.commands_demo  # noqa: F401  (registers commands)
import skyradar.cli.commands_nav  # noqa: F401  (registers commands)
import skyradar.cli.commands_process  # noqa: F401  (registers commands)
import skyradar.cli.commands_raw  # noqa: F401  (registers commands)
import skyradar.cli.commands_track  # noqa: F401  (registers commands)
from skyradar.cli import commands_sim  # noqa: F401  (registers commands)
from skyradar.cli.app import app
from skyradar.errors import InputError

__all__ = ["app", "main"]


def main() -> None:
    """Entry point of the ``skyradar`` script."""
    try:
        code = app(standalone_mode=False)
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        sys.exit(2)
    except click.exceptions.Exit as exc:
        sys.exit(exc.exit_code)
    except click.ClickException as exc:
        exc.show()
        sys.exit(exc.exit_code)
    except (KeyboardInterrupt, click.exceptions.Abort):
        code = 130
    # With standalone_mode=False click returns 130 on Ctrl-C instead of raising.
    if code == 130:
        print("interrupted: finished chunks are kept; rerun the same command to resume", file=sys.stderr)
    if isinstance(code, int) and code:
        sys.exit(code)
