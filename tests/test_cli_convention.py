"""One command-line convention over the whole command tree: every output path is ``-o/--output``,
one option name per meaning, the SI unit in the name of every option that carries one, no other
unit in a name, and every option with fixed choices lists them in ``--help``.

The walk covers every command the Typer app registers, so a new command or option is held to the
convention the day it is added."""

from __future__ import annotations

import inspect
import re

import pytest
import typer.main
from typer.testing import CliRunner

from skyradar.cli import app

# The unit a help text states for a number (``"Reflector range, m."``) and the suffix its name carries.
_UNIT_IN_HELP = re.compile(r",\s*(s|m|deg|Hz|dB)\b")
_SUFFIX = {"s": "-s", "m": "-m", "deg": "-deg", "Hz": "-hz", "dB": "-db"}
_NON_SI = re.compile(r"-(km|ft|kt|kts|nm|mi|mph|min|ms|fpm|feet|knots|seconds|minutes)$")
# Options kept outside the convention, each for a reason: ``experiment ch5`` validates its durations
# in its own module (skyradar.experiments.ch5), whose messages name ``--duration`` and
# ``--fast-duration``; renaming them means changing those messages with them.
_EXEMPT = {("experiment ch5", "--duration-s"), ("experiment ch5", "--fast-duration")}


def _commands() -> list[tuple[str, object, object]]:
    """(command path, command, context) of every leaf command of the app."""
    found = []

    def walk(command, ctx, path: list[str]) -> None:
        names = getattr(command, "list_commands", lambda _: [])(ctx)
        if not names:
            found.append((" ".join(path), command, ctx))
        for name in names:
            sub = command.get_command(ctx, name)
            walk(sub, sub.context_class(sub, info_name=name, parent=ctx), [*path, name])

    root = typer.main.get_command(app)
    walk(root, root.context_class(root, info_name="skyradar"), [])
    return found


COMMANDS = _commands()
OPTIONS = [
    (path, param)
    for path, command, ctx in COMMANDS
    for param in command.get_params(ctx)
    if param.param_type_name == "option" and param.name != "help"
]
_IDS = [f"{path} {max(param.opts, key=len)}" for path, param in OPTIONS]


def _long(param) -> list[str]:
    return [opt for opt in param.opts if opt.startswith("--")]


def test_the_walk_finds_the_commands():
    paths = {path for path, _, _ in COMMANDS}
    assert {"simulate", "process", "track", "alert", "demo", "experiment encounters", "bench sim"} <= paths
    assert len(OPTIONS) > 150


@pytest.mark.parametrize(("path", "param"), OPTIONS, ids=_IDS)
def test_an_output_path_is_dash_o_output(path, param):
    """An option named as an output, or whose help says it is what the command writes, is exactly
    ``-o/--output``."""
    named = param.name in ("out", "output") or {"-o", "--out", "--output"} & set(param.opts)
    written = not param.is_flag and re.search(
        r"\bto write\b|^Output|^Folder|^Report folder", param.help or ""
    )
    if named or written:
        assert sorted(param.opts) == ["--output", "-o"] and not param.secondary_opts, (path, param.opts)


@pytest.mark.parametrize(("path", "command", "ctx"), COMMANDS, ids=[path for path, _, _ in COMMANDS])
def test_a_command_that_checks_its_output_takes_it_as_dash_o_output(path, command, ctx):
    """Every command that writes an output checks it first (skyradar.io.outputs.check_output); that
    output is given with ``-o/--output``."""
    source = inspect.getsource(command.callback)
    if "check_output(" not in source:
        return
    opts = [sorted(p.opts) for p in command.get_params(ctx) if p.param_type_name == "option"]
    assert ["--output", "-o"] in opts, f"skyradar {path} writes an output but has no -o/--output"
    assert 'option="--out"' not in source


@pytest.mark.parametrize(("path", "param"), OPTIONS, ids=_IDS)
def test_one_name_per_option(path, param):
    """One long name per option (a ``--x/--no-x`` flag pair is one name and its negation)."""
    if (path, _long(param)[0] if _long(param) else "") in _EXEMPT:
        return
    assert len(_long(param)) == 1, f"skyradar {path}: {param.opts} name one option twice"


@pytest.mark.parametrize(("path", "param"), OPTIONS, ids=_IDS)
def test_a_number_with_a_unit_carries_it_in_its_name(path, param):
    """An option whose help gives its unit (``"..., s."``, ``"..., deg"``) ends its name with the SI
    unit; no name carries a non-SI unit."""
    for name in _long(param):
        assert not _NON_SI.search(name), f"skyradar {path} {name}: not an SI unit"
    unit = _UNIT_IN_HELP.search(param.help or "")
    if param.is_flag or unit is None or (path, _long(param)[0]) in _EXEMPT:
        return
    assert _long(param)[0].endswith(_SUFFIX[unit[1]]), f"skyradar {path} {param.opts}: unit {unit[1]}"


@pytest.mark.parametrize(("path", "command", "ctx"), COMMANDS, ids=[path for path, _, _ in COMMANDS])
def test_every_choice_option_lists_its_choices_in_help(path, command, ctx):
    choice_params = [
        p
        for p in command.get_params(ctx)
        if getattr(getattr(p, "type_descriptor", None), "choices", None)
        or getattr(getattr(p, "type", None), "choices", None)
    ]
    if not choice_params:
        return
    result = CliRunner().invoke(app, [*path.split(), "--help"], env={"COLUMNS": "250"})
    assert result.exit_code == 0, result.output
    for p in choice_params:
        held = getattr(getattr(p, "type_descriptor", None), "choices", None) or p.type.choices
        names = [str(getattr(choice, "value", choice)) for choice in held]
        assert "|".join(names) in result.output, f"skyradar {path} {p.opts}: choices {names} not in --help"
