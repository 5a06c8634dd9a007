"""The documentation site builds offline with warnings as errors, and its generated pages hold what
they are generated from: the results page the numbers of docs/results/*.json, the CLI reference the
commands of the Typer app, the scenario reference every key of the scenario models (checked against
their JSON schema and the shipped scenarios), the output-tables page every documented column."""

from __future__ import annotations

import html
import importlib.util
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SOURCE = ROOT / "docs" / "source"
RESULTS = ROOT / "docs" / "results"

pytestmark = [
    pytest.mark.docs,
    pytest.mark.skipif(
        importlib.util.find_spec("sphinx") is None,
        reason="sphinx is not installed: install the docs extra (pip install -e '.[docs]', part of dev)",
    ),
]


def _text(page: Path) -> str:
    """A built page's text, tags dropped and whitespace collapsed."""
    return re.sub(r"\s+", " ", html.unescape(re.sub(r"<[^>]+>", " ", page.read_text())))


def _from_docs_extension(*names: str) -> tuple:
    """The named objects of the docs' Sphinx extension (``docs/source/_ext/skyradar_docs.py``)."""
    sys.path.insert(0, str(SOURCE / "_ext"))
    try:
        import skyradar_docs
    finally:
        sys.path.remove(str(SOURCE / "_ext"))
    return tuple(getattr(skyradar_docs, name) for name in names)


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("docs")
    html_dir, doctrees = out / "html", out / "doctrees"
    cmd = [sys.executable, "-m", "sphinx", "-b", "html", "-W", "--keep-going", "-q", "-d", str(doctrees)]
    # The gallery's examples write their outputs into temporary folders: under this test's own
    # (TMPDIR), which pytest removes, so a test run leaves nothing in the system's.
    scratch = out / "examples-tmp"
    scratch.mkdir()
    env = {**os.environ, "TMPDIR": str(scratch)}
    # The timeout guards against a hung build, not its speed: the gallery runs every example, and a
    # loaded 2-core machine takes several minutes.
    proc = subprocess.run(
        [*cmd, str(SOURCE), str(html_dir)], capture_output=True, text=True, timeout=480, cwd=ROOT, env=env
    )
    assert proc.returncode == 0, f"sphinx build failed:\n{proc.stdout}\n{proc.stderr}"
    return html_dir


def test_results_page_holds_the_measured_numbers(site):
    _row_as_shown, format_value = _from_docs_extension("_row_as_shown", "format_value")
    text = _text(site / "results.html")
    files = sorted(RESULTS.glob("*.json"))
    assert files, "no measured summaries in docs/results"
    for path in files:
        summary = json.loads(path.read_text())
        row = _row_as_shown(summary["rows"][0])  # the interval from the counts where not recorded
        assert path.name in text
        assert summary["date_utc"] in text
        assert summary["command"] in text
        # The row's terrain, layout and headline numbers, in the page's table order.
        columns = ("terrain", "layout", "encounters", "conflicts", "observable_conflicts", "missed_warnings")
        columns += ("false_warnings", "false_warning_rate", "false_warning_rate_ci95")
        columns += ("median_warning_lead_s",)
        if "lead_against_clear_sky" in row:  # a run that flew clear sky too: the paired change of lead
            columns += ("lead_change_against_clear_sky_s",)
        cells = [format_value(k, row[k]) for k in columns]
        assert " ".join(cells) in text, f"{path.name}: first row {cells} not on the results page"
    benchmarks = sorted((RESULTS / "benchmarks").glob("*.json"))
    assert benchmarks, "no saved benchmark results in docs/results/benchmarks"
    for path in benchmarks:
        result = json.loads(path.read_text())
        assert path.name in text and result["date_utc"] in text and result["command"] in text


def test_a_run_with_clear_sky_shows_its_paired_change_of_lead():
    # A run over a terrain and clear sky (`--terrain hills,none`) records, per terrain row, its lead
    # against clear sky on the same encounters; the results page shows the median change.
    _row_as_shown, format_value = _from_docs_extension("_row_as_shown", "format_value")
    paired = {"encounters": 51, "median_lead_s": 24.0, "median_difference_s": -2.56}
    row = _row_as_shown({"terrain": "hills", "lead_against_clear_sky": paired})
    assert format_value("lead_change_against_clear_sky_s", row["lead_change_against_clear_sky_s"]) == "-2.6"
    assert "lead_change_against_clear_sky_s" not in _row_as_shown({"terrain": "none"})


def test_results_page_holds_the_clutter_experiments_numbers(site):
    """Each saved ``experiment clutter`` summary (``skyradar-clutter``): its provenance, a row per
    figure of merit with one value per terrain, and the figures kept beside it."""
    CLUTTER_FIGURES, format_value = _from_docs_extension("CLUTTER_FIGURES", "format_value")
    page = (site / "results.html").read_text()
    text = _text(site / "results.html").replace("\u2019", "'")  # smart quotes back to plain
    files = sorted((RESULTS / "clutter").glob("*.json"))
    assert files, "no clutter experiment summaries in docs/results/clutter"
    for path in files:
        summary = json.loads(path.read_text())
        assert path.name in text
        for key in ("version", "command", "date_utc"):
            assert summary[key] in text, (path.name, key)
        assert format_value("load_average_1min", summary["load_average_1min"]) in text
        cases = summary["terrains"]
        assert "key meaning " + " ".join(cases) in text, f"{path.name}: no table with a column per terrain"
        for key, meaning, _ in CLUTTER_FIGURES:
            cells = [format_value(key, case[key]) for case in cases.values()]
            if key == "visible_frames":
                cells = [f"{c} of {case['frames']}" for c, case in zip(cells, cases.values(), strict=True)]
            row = " ".join([key, meaning, *cells])
            assert row in text, f"{path.name}: row {row!r} not on the page"
        kept = [Path(f).name for f in summary["figures"] if (path.parent / Path(f).name).is_file()]
        assert kept, f"{path.name}: no figure kept beside it"
        for name in kept:
            stem = re.escape(Path(name).stem)
            image = re.search(rf'<img[^>]+src="(_images/{stem}\d*\.png)"', page)
            assert image and (site / image[1]).is_file(), name


def test_cli_reference_names_the_commands(site):
    text = _text(site / "cli.html")
    for command in ("simulate", "process", "track", "alert", "experiment encounters"):
        assert f"skyradar {command}" in text
    assert "--output" in text and "--ownship" in text


def test_gallery_runs_every_example(site):
    """Every script in examples/ is run by the build: its page holds what it printed and a figure it
    drew, and the gallery holds an example of each task a newcomer starts with."""
    scripts = sorted((ROOT / "examples").glob("plot_*.py"))
    for script in scripts:
        page = site / "gallery" / f"{script.stem}.html"
        assert page.is_file(), script.name
        text = page.read_text()
        assert "sphx-glr-script-out" in text, f"{script.name}: no printed output on its page"
        image = re.search(rf'<img[^>]+src="\.\./(_images/sphx_glr_{script.stem}_\d+\.png)"', text)
        assert image and (site / image[1]).is_file(), f"{script.name}: no figure on its page"
    tasks = {
        "the demo": "plot_demo",
        "a scenario over your own DEM with real ADS-B traffic": "plot_own_terrain_real_traffic",
        "reading alerts and advice, opening the live display": "plot_alerts_and_display",
        "your own raw ADC recording": "plot_own_recording",
        "your own SigMF recording": "plot_own_recording_sigmf",
        "reproducing a thesis table": "plot_thesis_ch3",
    }
    missing = {task for task, stem in tasks.items() if not (ROOT / "examples" / f"{stem}.py").is_file()}
    assert not missing, f"no gallery example for: {sorted(missing)}"


def test_pages_of_every_stage_are_built(site):
    for page in ("getting-started", "user-guide/simulate", "how-it-works/alerting", "api/track", "changelog"):
        assert (site / f"{page}.html").is_file(), page
    for page in ("clutter-suppression", "elevation-trust"):  # drawn by the library at the build
        assert (site / "how-it-works" / f"{page}.html").is_file(), page
        assert (site / "_images" / f"{page}-1.png").is_file(), page
    assert "Unreleased" in _text(site / "changelog.html")  # CHANGELOG.md is included


# ---- the scenario reference ------------------------------------------------------------------
def _plain(fragment: str) -> str:
    """An HTML fragment's text, tags dropped and whitespace collapsed."""
    return re.sub(r"\s+", " ", html.unescape(re.sub(r"<[^>]+>", "", fragment))).strip()


def _scenario_page(site: Path) -> dict[str, dict]:
    """The built scenario reference by model (lower-case name): its YAML paths and its key rows,
    each row ``{"type", "required", "default", "description"}`` as the page shows them."""
    page = (site / "reference" / "scenario.html").read_text()
    sections = {}
    for chunk in page.split('<section id="scenario-')[1:]:
        name = chunk[: chunk.index('"')]
        where = re.search(r'<p class="skyradar-scenario-paths">(.*?)</p>', chunk, re.DOTALL)
        table = re.search(r"<tbody>(.*?)</tbody>", chunk, re.DOTALL)
        if where is None or table is None:  # the page's own title section
            continue
        paths = [_plain(code) for code in re.findall(r"<code[^>]*>(.*?)</code>", where[1], re.DOTALL)]
        rows = {}
        for row in re.findall(r"<tr[^>]*>(.*?)</tr>", table[1], re.DOTALL):
            key, *cells = [_plain(cell) for cell in re.findall(r"<td[^>]*>(.*?)</td>", row, re.DOTALL)]
            rows[key] = dict(zip(("type", "required", "default", "description"), cells, strict=True))
        sections[name] = {"paths": ["" if p == "(top level)" else p for p in paths], "rows": rows}
    return sections


def _schema_keys() -> tuple[set[tuple[str, str]], set[tuple[str, str]], dict]:
    """From the scenario model's JSON schema: every (model, key), every (YAML path, model) and each
    model's properties, so that the page is checked against pydantic's view, not the directive's."""
    from skyradar.scene.scenario_models import ScenarioModel

    schema = ScenarioModel.model_json_schema()
    defs = {name.lower(): d for name, d in schema["$defs"].items()} | {"scenariomodel": schema}
    keys = {(model, key) for model, d in defs.items() for key in d.get("properties", {})}
    paths: set[tuple[str, str]] = set()

    def walk(node: dict, path: str) -> None:
        if "$ref" in node:
            model = node["$ref"].rsplit("/", 1)[1].lower()
            if (path, model) not in paths:
                paths.add((path, model))
                for key, sub in defs[model]["properties"].items():
                    walk(sub, f"{path}.{key}" if path else key)
            return
        for sub in node.get("anyOf", []) + node.get("oneOf", []):
            walk(sub, path)
        if isinstance(node.get("items"), dict):
            walk(node["items"], path + "[]")

    paths.add(("", "scenariomodel"))
    for key, sub in schema["properties"].items():
        walk(sub, key)
    return keys, paths, defs


def test_scenario_reference_lists_every_key_of_the_schema(site):
    """Every key reachable from the top-level scenario model is on the page, in its model's section,
    with a description; every YAML path a model appears at is named; every default the page shows
    reads back (as YAML) as the schema's default. A new field without documentation fails here."""
    import yaml

    page = _scenario_page(site)
    keys, paths, defs = _schema_keys()
    on_page = {(model, key) for model, section in page.items() for key in section["rows"]}
    assert on_page == keys, f"missing: {sorted(keys - on_page)}; not in the schema: {sorted(on_page - keys)}"
    assert {(p, model) for model, s in page.items() for p in s["paths"]} == paths
    for model, section in page.items():
        for key, row in section["rows"].items():
            assert row["description"], f"{model}.{key} has no description"
            assert row["required"] in ("yes", "no"), (model, key, row)
            prop = defs[model]["properties"][key]
            assert (row["required"] == "yes") == (key in defs[model].get("required", [])) or (
                model == "navigationconfig" and row["default"].startswith("from model")
            ), (model, key, row)
            if "default" in prop and row["default"] and not row["default"].startswith("from "):
                assert yaml.safe_load(row["default"]) == prop["default"], (model, key, row["default"])


def _section_at(page: dict, path: str, data: dict) -> dict:
    """The page's section for the mapping ``data`` at ``path``; a tagged union's by ``data["type"]``."""
    candidates = [s for s in page.values() if path in s["paths"]]
    if len(candidates) > 1:
        candidates = [s for s in candidates if s["rows"].get("type", {}).get("type") == data.get("type")]
    assert len(candidates) == 1, f"{path}: {len(candidates)} sections for {data}"
    return candidates[0]


def _keys_on_page(page: dict, data: dict, path: str = "") -> list[str]:
    """The keys of a scenario mapping (recursively) the page does not list at their path."""
    rows = _section_at(page, path, data)["rows"]
    missing = []
    for key, value in data.items():
        here = f"{path}.{key}" if path else key
        if key not in rows:
            missing.append(here)
        elif isinstance(value, dict):
            missing += _keys_on_page(page, value, here)
        elif isinstance(value, list):
            missing += [
                m for item in value if isinstance(item, dict) for m in _keys_on_page(page, item, here + "[]")
            ]
    return missing


def test_shipped_scenarios_use_only_keys_on_the_page(site):
    import yaml

    page = _scenario_page(site)
    shipped = sorted((ROOT / "src" / "skyradar" / "data" / "scenarios").glob("*.yaml"))
    assert any(p.name == "ch2_flat_forward.yaml" for p in shipped)
    for path in shipped:
        assert not _keys_on_page(page, yaml.safe_load(path.read_text())), path.name


def test_the_readme_scenario_uses_only_keys_on_the_page(site):
    # The README's example (run through its commands by tests/test_readme.py) is written from the
    # generated reference: every key of it is listed there, at its path and for its variant.
    import yaml

    page = _scenario_page(site)
    readme = (ROOT / "README.md").read_text()
    (block,) = re.findall(r"```yaml\n(.*?)```", readme, flags=re.DOTALL)
    scenario = yaml.safe_load(block)
    assert {"origin", "ownship", "intruders"} <= set(scenario)
    assert _keys_on_page(page, scenario) == []
    # A key the page does not list is found, at the top and inside a list's items.
    assert _keys_on_page(page, scenario | {"not_a_key": 1}) == ["not_a_key"]
    glider = scenario["intruders"][0] | {"not_a_key": 0}
    assert _keys_on_page(page, scenario | {"intruders": [glider]}) == ["intruders[].not_a_key"]


def test_a_scenario_written_from_the_page_loads(site, tmp_path):
    """A scenario whose keys all come from the page, optional ones at the defaults the page shows,
    validates to the same scenario as one that leaves them out, and builds."""
    import yaml

    from skyradar.scene.scenario import load_scenario

    page = _scenario_page(site)

    def defaults(section: dict) -> dict:
        rows = section["rows"].items()
        return {k: yaml.safe_load(r["default"]) for k, r in rows if r["default"] and r["required"] == "no"}

    minimal = {
        "origin": {"lat_deg": 52.0, "lon_deg": 4.36},
        "duration_s": 1.0,
        "ownship": {"type": "straight", "start_ned_m": [0.0, 0.0, -1000.0], "speed_mps": 50.0},
    }
    full = defaults(_section_at(page, "", {})) | minimal
    full["ownship"] = defaults(_section_at(page, "ownship", minimal["ownship"])) | minimal["ownship"]
    for section in ("origin", "simulation"):
        full[section] = defaults(_section_at(page, section, {})) | full.get(section, {})
    assert not _keys_on_page(page, full)
    for name, data in (("minimal", minimal), ("full", full)):
        (tmp_path / f"{name}.yaml").write_text(yaml.safe_dump(data, sort_keys=False))
    written = load_scenario(tmp_path / "full.yaml")
    assert written.model == load_scenario(tmp_path / "minimal.yaml").model
    assert len(written.build().times_s) == 9  # 1 s at the page's default 9.4 frames per second


# ---- the output tables -----------------------------------------------------------------------
def test_output_tables_page_shows_every_documented_column(site):
    """Each ``skyradar-columns`` table of the page holds, in order, the columns of the mapping it names."""
    import importlib

    source = (SOURCE / "reference" / "tables.rst").read_text()
    named = re.findall(r"^\.\. skyradar-columns:: (\S+)$", source, flags=re.MULTILINE)
    assert len(named) == 8  # detections, tracks, alerts, state, passive, gpscheck, two export tables
    page = (site / "reference" / "tables.html").read_text()
    tables = re.findall(r'<table class="[^"]*skyradar-table-columns[^"]*">(.*?)</table>', page, re.DOTALL)
    assert len(tables) == len(named)
    for dotted, table in zip(named, tables, strict=True):
        module, _, name = dotted.rpartition(".")
        columns = getattr(importlib.import_module(module), name)
        rows = re.findall(r"<tr[^>]*>\s*<td[^>]*>(.*?)</td>", table, re.DOTALL)
        assert [_plain(cell) for cell in rows] == list(columns), dotted
