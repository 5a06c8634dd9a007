"""Options with a fixed set of choices are string enums (skyradar.cli.choices): ``--help`` lists the
choices, any other value is refused in one line naming the option and the value, and each enum holds
the names the library takes."""

from __future__ import annotations

import typing
from enum import Enum

import pytest
import typer.main
from typer.testing import CliRunner

from cli_helpers import skyradar, skyradar_in_process
from skyradar.cli import app, choices


def _names(enum: type[Enum]) -> tuple[str, ...]:
    return tuple(member.value for member in enum)


def _choice_params() -> list[tuple[list[str], str, type[Enum]]]:
    """(command path, option or argument name, enum) of every enum-typed parameter of the app."""
    found = []
    by_names = {_names(getattr(choices, name)): getattr(choices, name) for name in choices.__all__}

    def walk(command, ctx, path: list[str]) -> None:
        for param in command.get_params(ctx):
            # typer >= 0.2x: the choices on the type descriptor; older typer: a click.Choice.
            held = getattr(getattr(param, "type_descriptor", None), "choices", None)
            held = held or getattr(getattr(param, "type", None), "choices", None) or ()
            names = tuple(str(getattr(choice, "value", choice)) for choice in held)
            if names:
                enum = by_names[names]
                long = next((opt for opt in param.opts if opt.startswith("--")), None)
                name = param.name.upper() if param.param_type_name == "argument" else long
                found.append((path, name, enum))
        for name in getattr(command, "list_commands", lambda _: [])(ctx):
            sub = command.get_command(ctx, name)
            walk(sub, sub.context_class(sub, info_name=name, parent=ctx), [*path, name])

    root = typer.main.get_command(app)
    walk(root, root.context_class(root, info_name="skyradar"), [])
    return found


CHOICE_PARAMS = _choice_params()
_IDS = [" ".join([*path, name]) for path, name, _ in CHOICE_PARAMS]


def test_every_choice_enum_is_an_option_of_some_command():
    used = {enum for _, _, enum in CHOICE_PARAMS}
    assert {getattr(choices, name) for name in choices.__all__} == used
    assert len(CHOICE_PARAMS) >= 25  # process --method ... bench encounter --terrain


@pytest.mark.parametrize(("path", "name", "enum"), CHOICE_PARAMS, ids=_IDS)
def test_a_value_outside_the_choices_is_one_line_naming_the_option(monkeypatch, capsys, path, name, enum):
    args = [*path, "not-a-choice"] if name.isupper() else [*path, name, "not-a-choice"]
    code, out, err = skyradar_in_process(monkeypatch, capsys, *args)
    names = ", ".join(member.value for member in enum)
    assert code == 2, out + err
    assert err.strip() == f"error: {name}: must be one of {names}, got 'not-a-choice'"


@pytest.mark.parametrize(("path", "name", "enum"), CHOICE_PARAMS, ids=_IDS)
def test_help_lists_the_choices(path, name, enum):
    result = CliRunner().invoke(app, [*path, "--help"], env={"COLUMNS": "250"})
    assert result.exit_code == 0, result.output
    assert "|".join(_names(enum)) in result.output


def test_the_entry_point_refuses_a_repeated_option_in_one_line(tmp_path):
    bad = skyradar("bench", "encounter", "--terrain", "hills", "--terrain", "marsh", cwd=tmp_path, timeout=60)
    assert bad.returncode == 2 and "Traceback" not in bad.stderr
    assert bad.stderr.strip().splitlines() == [
        "error: --terrain: must be one of none, flat-300, flat-1000, hills, jacksboro, got 'marsh'"
    ]


def test_a_missing_value_is_still_a_usage_error(monkeypatch, capsys):
    code, _, err = skyradar_in_process(
        monkeypatch, capsys, "process", "run.zarr", "-o", "d.parquet", "--method"
    )
    assert code == 2 and "requires an argument" in err


def test_each_enum_holds_the_names_the_library_takes():
    from skyradar.experiments.encounter_terrain import TERRAINS
    from skyradar.experiments.encounters import FAMILIES
    from skyradar.io.frames import COMPRESSORS, PRECISIONS
    from skyradar.nav.flight_state import METHODS as STATE_METHODS
    from skyradar.nav.gpscheck.preprocess import METHODS as GPSCHECK_METHODS
    from skyradar.process.detect import detect
    from skyradar.rx_layouts import MIMO_LAYOUTS, RX_LAYOUTS
    from skyradar.scene.encounter_from_tracks import encounter_from_tracks
    from skyradar.scene.flyable import AIRCRAFT_CLASSES
    from skyradar.scene.navigation_config import NAVIGATION_MODELS
    from skyradar.track.evaluate import TRUTH_MODES

    assert _names(choices.Family) == FAMILIES
    assert _names(choices.EncounterTerrain) == TERRAINS
    assert _names(choices.Compressor) == COMPRESSORS
    assert _names(choices.Precision) == PRECISIONS
    assert _names(choices.GpsCheckMethod) == GPSCHECK_METHODS
    assert _names(choices.TruthMode) == TRUTH_MODES
    assert _names(choices.RxLayout) == RX_LAYOUTS + MIMO_LAYOUTS
    assert _names(choices.Navigation) == NAVIGATION_MODELS
    assert _names(choices.AircraftClass) == tuple(AIRCRAFT_CLASSES)
    assert set(_names(choices.StateMethod)) == {*STATE_METHODS, "terrain"}  # terrain: estimate_run's own
    assert _names(choices.Detector) == typing.get_args(typing.get_type_hints(detect)["method"])
    assert _names(choices.Side) == typing.get_args(typing.get_type_hints(encounter_from_tracks)["side"])
