"""The README's example works as written: its scenario through its four commands and its Python example.

Its scenario uses only keys of the scenario model, and its results table is the one the measured JSON gives.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pandas as pd
import yaml

from skyradar.experiments.readme_results import END, README_RESULTS, START, readme_table

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()
HISTORY = re.compile(
    r"session [0-9]|issue [0-9]|encounter [0-9]+|\b[0-9a-f]{7}\b \(|seed[-]brief", flags=re.IGNORECASE
)


def _blocks(language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", README, flags=re.DOTALL)


def test_the_readme_is_short_and_tells_no_history():
    assert len(README.splitlines()) <= 200
    assert not HISTORY.findall(README)
    assert _blocks("sh")[0].split("\n")[:2] == [
        "make demo   # creates .venv, installs skyradar, runs the end-to-end demo on the embedded scenario",
        "make test   # creates .venv with the dev extras and runs the test suite (doctests included)",
    ]


def test_the_readme_scenario_runs_through_its_commands_and_its_python_example(tmp_path):
    (scenario,) = _blocks("yaml")
    (tmp_path / "head_on.yaml").write_text(scenario)
    chain = next(b for b in _blocks("sh") if "skyradar simulate" in b)
    for line in chain.strip().splitlines():
        command = line.split("#")[0].split()
        assert command[0] == "skyradar"
        done = subprocess.run(
            [sys.executable, "-m", "skyradar", *command[1:]],
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert done.returncode == 0, (line, done.stderr[-2000:])
    alerts = pd.read_parquet(tmp_path / "alerts.parquet")
    assert (alerts["level"] == 3).any()  # the head-on glider is warned
    (example,) = _blocks("python")
    done = subprocess.run(
        [sys.executable, "-c", example], cwd=tmp_path, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert "time_s" in done.stdout and "preferred_heading_deg" in done.stdout


def test_the_readme_results_table_is_generated_from_the_measured_json():
    # The table between the markers is exactly what the measured summaries give: a hand edit fails here.
    assert README.count(START) == 1 and README.count(END) == 1
    shown = README.split(START, 1)[1].split(END, 1)[0].strip()
    results = ROOT / "docs" / "results"
    assert shown == readme_table(results, README_RESULTS)
    assert len(shown.splitlines()) >= 2 + len(README_RESULTS)


def _scenario_key_paths() -> dict[str, set[str]]:
    """Each YAML path of the scenario model (``intruders[]`` for a list's items) and the keys allowed
    there, from ``ScenarioModel.model_json_schema()`` as the scenario reference page is generated;
    a tagged union's keys per variant, under ``path#type``."""
    from skyradar.scene.scenario_models import ScenarioModel

    schema = ScenarioModel.model_json_schema()
    defs = {name.lower(): d for name, d in schema["$defs"].items()} | {"scenariomodel": schema}
    allowed: dict[str, set[str]] = {}
    seen: set[tuple[str, str]] = set()

    def add(path: str, model: str) -> None:
        properties = defs[model]["properties"]
        variant = properties.get("type", {}).get("const")
        for where in (path, f"{path}#{variant}") if variant else (path,):
            allowed.setdefault(where, set()).update(properties)
        if (path, model) in seen:
            return
        seen.add((path, model))
        for key, sub in properties.items():
            walk(sub, f"{path}.{key}" if path else key)

    def walk(node: dict, path: str) -> None:
        if "$ref" in node:
            add(path, node["$ref"].rsplit("/", 1)[1].lower())
            return
        for sub in node.get("anyOf", []) + node.get("oneOf", []):
            walk(sub, path)
        if isinstance(node.get("items"), dict):
            walk(node["items"], path + "[]")

    add("", "scenariomodel")
    return allowed


def _keys_not_in_model(allowed: dict[str, set[str]], data: dict, path: str = "") -> list[str]:
    """The key paths of a scenario mapping (recursively) the model does not have at their path; a
    mapping with a ``type`` is checked against that variant's keys only."""
    where = f"{path}#{data['type']}" if isinstance(data.get("type"), str) else path
    keys = allowed.get(where) or allowed.get(path, set())
    missing = []
    for key, value in data.items():
        here = f"{path}.{key}" if path else key
        if key not in keys:
            missing.append(here)
        elif isinstance(value, dict):
            missing += _keys_not_in_model(allowed, value, here)
        elif isinstance(value, list):
            items = (item for item in value if isinstance(item, dict))
            missing += [m for item in items for m in _keys_not_in_model(allowed, item, here + "[]")]
    return missing


def test_the_readme_scenario_uses_only_keys_the_scenario_reference_lists():
    allowed = _scenario_key_paths()
    (block,) = _blocks("yaml")
    scenario = yaml.safe_load(block)
    assert {"origin", "terrain", "ownship", "intruders"} <= set(scenario)
    assert _keys_not_in_model(allowed, scenario) == []
    # The checker rejects what the model does not have: a made-up key, a key of another variant.
    assert _keys_not_in_model(allowed, scenario | {"radar": {"not_a_key": 1}}) == ["radar.not_a_key"]
    wrong_variant = scenario | {"terrain": {"type": "jacksboro", "size_m": 16000}}
    assert _keys_not_in_model(allowed, wrong_variant) == ["terrain.size_m"]
    glider = scenario["intruders"][0] | {"not_a_key": 0}
    assert _keys_not_in_model(allowed, scenario | {"intruders": [glider]}) == ["intruders[].not_a_key"]
