"""Sphinx directives that build pages of the skyradar documentation from the project itself.

``skyradar-results``
    One section per measured summary in ``docs/results/*.json``: its settings and provenance
    (command, version, date, load average) and a table of the headline numbers of each row. No
    number on the results page is written by hand.
``skyradar-benchmarks``
    One section per saved benchmark result in ``docs/results/benchmarks/*.json`` (the last line of
    ``skyradar bench NAME --json``): its provenance, then every key it measured.
``skyradar-clutter``
    One section per ``skyradar experiment clutter`` summary in ``docs/results/clutter/*.json``: its
    settings and provenance, a table of the figures of merit per terrain, and the figures the run
    wrote that are kept beside the JSON.
``skyradar-cli``
    The command-line reference, read from the Typer app's click command tree
    (``typer.main.get_command``): each command's help, usage, arguments and options.
``skyradar-alert-config``
    The alerting settings, DAIDALUS' DO-365B non-cooperative alerter beside the radar's, read from
    the package.
``skyradar-api``
    A subpackage's API: its docstring, a summary table of its public modules and an ``automodule``
    section per module. Private modules (``_name``) and deprecated aliases are left out.
``skyradar-scenario``
    The scenario file's reference, read from the pydantic models: one section per model reachable
    from the top-level scenario model, with the YAML paths it appears at and a table of its keys
    (type, whether required, default, description). A field without a description is a warning,
    which ``make docs`` (``-W``) turns into an error.
``skyradar-columns``
    An output table's columns from the producing module's ``*_COLUMNS`` constant (column ->
    ``"unit; meaning"``, optional columns ending in ``"; optional: when"``).

Nothing is written into the source tree; every page is built from the files and the package as
they are at build time.
"""

from __future__ import annotations

import datetime
import importlib
import importlib.util
import inspect
import json
import math
import os
import pkgutil
import re
import types
import typing
from pathlib import Path

import annotated_types as at
import pydantic
import pydantic.fields
from docutils import nodes
from docutils.parsers.rst import directives
from docutils.statemachine import StringList
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective
from sphinx.util.nodes import nested_parse_with_titles

# Settings of one summary, in the order shown; `split` and `load_average_1min` are shown when present.
SUMMARY_FIELDS = ("family", "terrains", "layouts", "encounters", "seed", "split", "alert_config")
PROVENANCE_FIELDS = ("command", "version", "date_utc", "load_average_1min")
# Headline numbers of one row (a terrain and a layout); `false_warnings_sensor` (the false warnings
# perfect surveillance does not give), `false_warnings_altitude_prior` (those first warned on a co-altitude
# prior), `false_warnings_any_track` (must-not-alert encounters warned on any track), `warnings_not_held`
# and `alert_flickers` only when present.
ROW_FIELDS = (
    "conflicts",
    "observable_conflicts",
    "missed_warnings",
    "false_warnings",
    "false_warning_rate",
    "false_warning_rate_ci95",
    "median_warning_lead_s",
    "lead_change_against_clear_sky_s",
    "warnings_not_held",
    "alert_flickers",
    "false_warnings_sensor",
    "false_warnings_altitude_prior",
    "false_warnings_any_track",
)
# Figures of merit of one terrain case of the clutter experiment (its summary's ``terrains``), in the
# order shown: key, meaning (with its unit), decimals (None: a count).
CLUTTER_FIGURES = (
    ("own_agl_m_median", "own-ship height above the ground, median, m", 0),
    ("visible_frames", "frames the intruder is detected in without the ground, of all frames", None),
    ("detection_fraction_none", "detection fraction without suppression", 2),
    ("detection_fraction_suppressed", "detection fraction with suppression", 2),
    ("detection_fraction_suppressed_with_secondary", "the same counting secondary detections", 2),
    ("intruder_cell_if_db_median", "improvement factor in the intruder's cell, median, dB", 1),
    (
        "intruder_cell_clutter_frames",
        "of those, frames whose intruder cell holds clutter over the noise",
        None,
    ),
    ("intruder_cell_if_db_median_clutter", "improvement factor in its cell in those frames, median, dB", 1),
    ("lost_frames_with_cells", "frames lost to clutter with CFAR-window cells of CNR >= 25 dB", None),
    ("if_db_lost_cells_median", "improvement factor in those cells (the lost cells), median, dB", 1),
    ("mdv_mps_none", "minimum detectable velocity without suppression, m/s", 2),
    ("mdv_mps_suppressed", "minimum detectable velocity with suppression, m/s", 2),
    ("usable_doppler_fraction_none", "usable Doppler fraction without suppression", 2),
    ("usable_doppler_fraction_suppressed", "usable Doppler fraction with suppression", 2),
)
CLUTTER_SETTINGS = ("frames_per_case", "seed", "terrains")
# What each figure of a terrain case shows, by its file name's prefix.
CLUTTER_PLOTS = {
    "sinr_loss": "SINR loss against radial velocity, with and without suppression",
    "intruder": "the intruder's SNR, the clutter and the improvement factor at it against its range, "
    "and its detections",
}

# Decimals of the fractional numbers; the rest are counts.
DECIMALS = {
    "false_warning_rate": 3,
    "median_warning_lead_s": 1,
    "lead_change_against_clear_sky_s": 1,
    "load_average_1min": 2,
} | {key: decimals for key, _, decimals in CLUTTER_FIGURES if decimals is not None}


def format_value(name: str, value: object) -> str:
    """A summary value as the results page shows it (the test reads numbers back the same way).

    >>> format_value("false_warning_rate", 0.02702702702702703), format_value("conflicts", 49)
    ('0.027', '49')
    >>> format_value("median_warning_lead_s", None), format_value("terrains", ["none", "hills"])
    ('n/a', 'none, hills')
    """
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    if name.endswith("_ci95") and isinstance(value, list | tuple) and len(value) == 2:
        return "n/a" if any(math.isnan(v) for v in value) else f"{value[0]:.3f}-{value[1]:.3f}"
    if isinstance(value, list | tuple):
        return ", ".join(str(v) for v in value)
    if isinstance(value, float) and name in DECIMALS:
        return f"{value:.{DECIMALS[name]}f}"
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    return str(value)


# Rates and the counts they come from: a summary written before it recorded the rate's interval gets
# it from those counts here (the same Wilson interval skyradar.experiments.encounter_set writes).
RATE_COUNTS = {"false_warning_rate": ("false_warnings", "must_not_alert_encounters")}


def _row_as_shown(row: dict) -> dict:
    """A summary row as the results page shows it: with each rate's ``_ci95`` interval, from its
    counts where the summary lacks it, and the median change of warning lead against clear sky on
    the same encounters where the run flew clear sky too (``lead_change_against_clear_sky_s``, s)."""
    from skyradar.experiments.encounter_set import rate_interval

    row = dict(row)
    paired = row.get("lead_against_clear_sky")
    if isinstance(paired, dict):
        row["lead_change_against_clear_sky_s"] = paired.get("median_difference_s")
    for rate, (count, trials) in RATE_COUNTS.items():
        if f"{rate}_ci95" not in row and count in row and trials in row:
            row[f"{rate}_ci95"] = rate_interval(int(row[count]), int(row[trials]))
    return row


def _inline(text: str) -> list[nodes.Node]:
    """Plain text with ``backtick`` spans as inline literals (no reST parsing of help texts)."""
    parts = text.split("`")
    if len(parts) % 2 == 0:  # an unmatched backtick: keep the text as it is
        return [nodes.Text(text)]
    return [nodes.literal(p, p) if i % 2 else nodes.Text(p) for i, p in enumerate(parts) if p]


def _paragraph(text: str) -> nodes.paragraph:
    para = nodes.paragraph()
    para.extend(_inline(text))
    return para


def _table(header: list[str], rows: list[list[str | nodes.Node]], classes: list[str] | None = None):
    table = nodes.table(classes=classes or [])
    group = nodes.tgroup(cols=len(header))
    table += group
    group.extend(nodes.colspec(colwidth=1) for _ in header)

    def row(cells):
        out = nodes.row()
        for cell in cells:
            entry = nodes.entry()
            entry += cell if isinstance(cell, nodes.Node) else nodes.paragraph(text=cell)
            out += entry
        return out

    head = nodes.thead()
    head += row(header)
    body = nodes.tbody()
    body.extend(row(cells) for cells in rows)
    group += head
    group += body
    return table


def _link(text: str, label: str) -> nodes.reference:
    """A link to a section of the same page, by the label :func:`_section` gave it."""
    return nodes.reference(text, text, internal=True, refid=nodes.make_id(label))


def _section(directive: SphinxDirective, title: str, label: str) -> nodes.section:
    """A section with an explicit label, so that pages can refer to it with ``:ref:``."""
    section = nodes.section(ids=[nodes.make_id(label)], names=[label])
    section += nodes.title(title, title)
    directive.state.document.note_explicit_target(section, section)
    return section


def _field_list(values: dict[str, object]) -> nodes.field_list:
    """A field list of ``values`` shown with :func:`format_value`, the command and version as code."""
    fields = nodes.field_list()
    for key, value in values.items():
        text = format_value(key, value)
        body = nodes.paragraph()
        body += nodes.literal(text, text) if key in ("command", "version") else nodes.Text(text)
        fields += nodes.field("", nodes.field_name(key, key), nodes.field_body("", body))
    return fields


class ResultsDirective(SphinxDirective):
    """``.. skyradar-results:: [folder]``: the measured summaries (default ``docs/results``)."""

    optional_arguments = 1

    def run(self) -> list[nodes.Node]:
        folder = Path(self.env.srcdir, self.arguments[0] if self.arguments else "../results").resolve()
        files = sorted(folder.glob("*.json"))
        if not files:
            return [self.state.document.reporter.warning(f"no summary JSON in {folder}", line=self.lineno)]
        summaries = []
        for path in files:
            self.env.note_dependency(str(path))
            summaries.append((path.name, json.loads(path.read_text())))
        optional = ("split", "alert_config")  # shown when some summary has them
        fields = [f for f in SUMMARY_FIELDS if f not in optional or any(f in s for _, s in summaries)]
        rows = [
            [
                nodes.paragraph("", "", _link(name, "results-" + Path(name).stem)),
                *[format_value(f, s.get(f)) for f in fields],
            ]
            for name, s in summaries
        ]
        overview = _table(["file", *fields], rows, classes=["skyradar-results-overview"])
        out: list[nodes.Node] = [overview]
        for name, summary in summaries:
            out.append(self._summary_section(name, summary))
        return out

    def _summary_section(self, name: str, summary: dict) -> nodes.section:
        section = _section(self, name, "results-" + Path(name).stem)
        optional = ("split", "alert_config", "load_average_1min")
        keys = [k for k in (*SUMMARY_FIELDS, *PROVENANCE_FIELDS) if k in summary or k not in optional]
        section += _field_list({k: summary.get(k) for k in keys})
        rows = [_row_as_shown(r) for r in summary.get("rows") or [summary]]
        optional = (  # where present
            "lead_change_against_clear_sky_s",
            "warnings_not_held",
            "alert_flickers",
            "false_warnings_sensor",
            "false_warnings_altitude_prior",
            "false_warnings_any_track",
        )
        shown = [f for f in ROW_FIELDS if f not in optional or any(f in r for r in rows)]
        section += _table(
            # A zero-width space after each underscore lets the long column names wrap.
            [f.replace("_", "_\u200b") for f in ("terrain", "layout", "encounters", *shown)],
            [[format_value(f, r.get(f)) for f in ("terrain", "layout", "encounters", *shown)] for r in rows],
            classes=["skyradar-results-rows"],
        )
        return section


class BenchmarksDirective(SphinxDirective):
    """``.. skyradar-benchmarks:: [folder]``: the saved ``skyradar bench ... --json`` results
    (default ``docs/results/benchmarks``), each with its provenance and every measured key."""

    optional_arguments = 1

    def run(self) -> list[nodes.Node]:
        where = self.arguments[0] if self.arguments else "../results/benchmarks"
        folder = Path(self.env.srcdir, where).resolve()
        files = sorted(folder.glob("*.json"))
        if not files:
            return [self.state.document.reporter.warning(f"no benchmark JSON in {folder}", line=self.lineno)]
        out: list[nodes.Node] = []
        for path in files:
            self.env.note_dependency(str(path))
            result = json.loads(path.read_text())
            section = _section(self, path.name, "bench-" + path.stem)
            section += _field_list({k: result.get(k) for k in PROVENANCE_FIELDS})
            rows = [
                [key.replace("_", "_\u200b"), _bench_value(value)]
                for key, value in result.items()
                if key not in PROVENANCE_FIELDS
            ]
            section += _table(["key", "value"], rows, classes=["skyradar-bench"])
            out.append(section)
        return out


class _SummariesDirective(SphinxDirective):
    """A section per summary JSON of a results folder (``default_folder`` unless given), each made by
    ``_summary_section``; a warning when the folder holds none."""

    optional_arguments = 1
    default_folder, what = "", ""

    def run(self) -> list[nodes.Node]:
        where = self.arguments[0] if self.arguments else self.default_folder
        folder = Path(self.env.srcdir, where).resolve()
        files = sorted(folder.glob("*.json"))
        if not files:
            warning = f"no {self.what} summary JSON in {folder}"
            return [self.state.document.reporter.warning(warning, line=self.lineno)]
        out: list[nodes.Node] = []
        for path in files:
            self.env.note_dependency(str(path))
            out.append(self._summary_section(path, json.loads(path.read_text())))
        return out

    def _summary_section(self, path: Path, summary: dict) -> nodes.section:
        raise NotImplementedError


class ClutterDirective(_SummariesDirective):
    """``.. skyradar-clutter:: [folder]``: the saved ``skyradar experiment clutter`` summaries (default
    ``docs/results/clutter``), each with its settings and provenance, a table of
    :data:`CLUTTER_FIGURES` with one column per terrain, and the figures of its ``figures`` list
    that are kept beside the JSON (a figure left out of the folder is left out of the page)."""

    default_folder, what = "../results/clutter", "clutter"

    def _summary_section(self, path: Path, summary: dict) -> nodes.section:
        section = _section(self, path.name, "clutter-" + path.stem)
        # ``terrains`` maps each terrain case to its figures: the settings name the cases.
        values = {k: list(summary[k]) if k == "terrains" else summary.get(k) for k in CLUTTER_SETTINGS}
        section += _field_list(values | {k: summary.get(k) for k in PROVENANCE_FIELDS})
        cases = summary.get("terrains") or {}
        rows = []
        for key, meaning, _ in CLUTTER_FIGURES:
            cells = [format_value(key, case.get(key)) for case in cases.values()]
            if key == "visible_frames":  # of how many
                cells = [
                    f"{c} of {format_value('frames', case.get('frames'))}"
                    for c, case in zip(cells, cases.values(), strict=True)
                ]
            rows.append([nodes.paragraph("", "", nodes.literal(key, key)), meaning, *cells])
        section += _table(["key", "meaning", *cases], rows, classes=["skyradar-clutter"])
        section.extend(self._figures(path.parent, summary))
        return section

    def _figures(self, folder: Path, summary: dict) -> list[nodes.figure]:
        """A figure node per PNG of the summary's ``figures`` that is kept in ``folder``."""
        here = Path(self.env.doc2path(self.env.docname)).parent
        out = []
        for name in (Path(f).name for f in summary.get("figures") or []):
            png = folder / name
            if not png.is_file():
                continue
            self.env.note_dependency(str(png))
            kind, _, terrain = png.stem.rpartition("_")
            text = f"{name}: {CLUTTER_PLOTS.get(kind, kind)}, {terrain}."
            figure = nodes.figure(classes=["skyradar-clutter-figure"])
            figure += nodes.image(uri=Path(os.path.relpath(png, here)).as_posix(), alt=name)
            figure += nodes.caption(text, text)
            out.append(figure)
        return out


# The closed-loop summary's columns of one case (terrain and equipped case): counts, risk ratios with
# their intervals, separation and the pilot's time off the plan.
CLOSED_LOOP_FIELDS = (
    ("lowc_unequipped", "losses of well clear unequipped"),
    ("lowc_equipped", "losses of well clear equipped"),
    ("lowc_risk_ratio", "risk ratio, loss of well clear"),
    ("lowc_risk_ratio_interval", "its 95 % paired bootstrap interval"),
    ("lowc_induced", "losses equipped where unequipped stayed well clear"),
    ("lowc_resolved", "losses unequipped that equipped avoided"),
    ("nmac_unequipped", "NMACs unequipped (500 ft / 100 ft)"),
    ("nmac_equipped", "NMACs equipped"),
    ("nmac_risk_ratio", "risk ratio, NMAC"),
    ("nmac_risk_ratio_interval", "its 95 % paired bootstrap interval"),
    (
        "median_min_horizontal_unequipped_conflicts_m",
        "median smallest horizontal separation of the conflicts, unequipped, m",
    ),
    ("median_min_horizontal_equipped_conflicts_m", "the same equipped, m"),
    ("manoeuvred_encounters", "encounters the pilot manoeuvred in"),
    ("manoeuvre_s_mean", "mean time off the plan per encounter, s"),
    ("runtime_s_mean", "mean wall time of one encounter flown this way, s"),
)


def _closed_loop_value(name: str, value: object) -> str:
    if isinstance(value, list | tuple) and len(value) == 2:
        if any(v is None or (isinstance(v, float) and math.isnan(v)) for v in value):
            return "n/a"
        return f"{value[0]:.2f}-{value[1]:.2f}"
    if isinstance(value, float) and not math.isnan(value) and not value.is_integer():
        return f"{value:.2f}"
    return format_value(name, value)


class ClosedLoopDirective(_SummariesDirective):
    """``.. skyradar-closed-loop:: [folder]``: the saved ``skyradar experiment closed-loop`` summaries
    (default ``docs/results/closed-loop``): settings and provenance, one column per terrain and
    equipped case, and the run's figure when it is kept beside the JSON as ``<name>.png``."""

    default_folder, what = "../results/closed-loop", "closed-loop"

    def _summary_section(self, path: Path, summary: dict) -> nodes.section:
        section = _section(self, path.name, "closed-loop-" + path.stem)
        settings = summary.get("settings") or {}
        shown = {k: settings.get(k) for k in ("family", "terrains", "layouts", "n", "seed", "split")}
        pilot = settings.get("pilot") or {}
        shown["pilot"] = ", ".join(f"{k}={v}" for k, v in pilot.items())
        shown |= {k: summary.get(k) for k in ("runtime_s", *PROVENANCE_FIELDS)}
        section += _field_list(shown)
        rows = summary.get("rows") or []
        cases = [
            f"{r['terrain']}: "
            + ("perfect surveillance" if r["condition"] == "perfect" else f"radar, {r['layout']}")
            for r in rows
        ]
        table = [
            [
                nodes.paragraph("", "", nodes.literal(key, key)),
                meaning,
                *[_closed_loop_value(key, r.get(key)) for r in rows],
            ]
            for key, meaning in (("encounters", "encounters flown"), *CLOSED_LOOP_FIELDS)
        ]
        section += _table(["key", "meaning", *cases], table, classes=["skyradar-closed-loop"])
        png = path.with_suffix(".png")
        if png.is_file():
            self.env.note_dependency(str(png))
            here = Path(self.env.doc2path(self.env.docname)).parent
            figure = nodes.figure(classes=["skyradar-closed-loop-figure"])
            figure += nodes.image(uri=Path(os.path.relpath(png, here)).as_posix(), alt=png.name)
            text = f"{png.name}: smallest horizontal separation with and without DAA, and the rates."
            figure += nodes.caption(text, text)
            section += figure
        return section


def _bench_value(value: object) -> str:
    """A measured value as shown: floats to four significant digits, lists and the rest as JSON."""
    if isinstance(value, bool) or value is None:
        return str(value)
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, int | str):
        return str(value)
    return json.dumps(value)


class AlertConfigDirective(SphinxDirective):
    """``.. skyradar-alert-config::``: every field of ``DO365B_ALERT_CONFIG`` (DAIDALUS' DO-365B
    non-cooperative alerter, ``--config do365b``) beside ``RADAR_ALERT_CONFIG`` (``--config radar``),
    read from the package."""

    def run(self) -> list[nodes.Node]:
        import dataclasses

        from skyradar.daa.alerting import DO365B_ALERT_CONFIG, RADAR_ALERT_CONFIG, AlertConfig

        def level(lv) -> str:
            early = lv.early_alerting_time_s
            hold = f" (held to {early:g} s)" if early is not None else ""
            volume = f"{lv.volume.dthr_m:.0f} m x {lv.volume.zthr_m:.0f} m"
            return f"{lv.name} {volume}, {lv.alerting_time_s:g} s{hold}"

        rows = []
        for f in dataclasses.fields(AlertConfig):
            a, b = getattr(DO365B_ALERT_CONFIG, f.name), getattr(RADAR_ALERT_CONFIG, f.name)
            if f.name == "levels":
                a, b = ("; ".join(level(lv) for lv in x) for x in (a, b))
            elif f.name == "collision_volume":
                a, b = (f"{x.dthr_m:g} m x {x.zthr_m:g} m" for x in (a, b))
            rows.append([nodes.paragraph("", "", nodes.literal(f.name, f.name)), str(a), str(b)])
        return [_table(["field", "do365b", "radar"], rows, classes=["skyradar-alert-config"])]


def _help_paragraphs(text: str | None) -> list[str]:
    """A click help text as paragraphs: cut at ``\\f``, ``\\b`` markers dropped, lines joined."""
    text = (text or "").split("\f")[0]
    paragraphs = re.split(r"\n\s*\n", text.strip())
    lines = [[line.strip() for line in p.splitlines() if line.strip() != "\b"] for p in paragraphs]
    return [" ".join(p) for p in lines if p]


class CliDirective(SphinxDirective):
    """``.. skyradar-cli::``: every command of ``skyradar``, from the click command tree."""

    def run(self) -> list[nodes.Node]:
        import typer.main

        from skyradar.cli.app import app

        root = typer.main.get_command(app)
        ctx = root.context_class(root, info_name="skyradar")
        out: list[nodes.Node] = [_paragraph(p) for p in _help_paragraphs(root.help)]
        out += self._commands(root, ctx, ["skyradar"])
        return out

    def _commands(self, group, ctx, path: list[str]) -> list[nodes.section]:
        sections = []
        for name in sorted(group.list_commands(ctx)):
            command = group.get_command(ctx, name)
            if command is None or command.hidden:
                continue
            sub = command.context_class(command, info_name=name, parent=ctx)
            sections.append(self._command(command, sub, [*path, name]))
        return sections

    def _command(self, command, ctx, path: list[str]) -> nodes.section:
        section = _section(self, " ".join(path), "cli-" + "-".join(path[1:]))
        section.extend(_paragraph(p) for p in _help_paragraphs(command.help))
        usage = " ".join([*path, *command.collect_usage_pieces(ctx)])
        section += nodes.literal_block(usage, usage, classes=["skyradar-usage"])
        params = [p for p in command.get_params(ctx) if not getattr(p, "hidden", False)]
        records = [(p, p.get_help_record(ctx)) for p in params]
        for kind, title in (("argument", "Arguments"), ("option", "Options")):
            rows = [
                [nodes.paragraph("", "", nodes.literal(rec[0], rec[0])), _paragraph(rec[1] or "")]
                for p, rec in records
                if rec and p.param_type_name == kind
            ]
            if rows:
                section += nodes.rubric(title, title)
                section += _table([kind, "description"], rows, classes=["skyradar-cli-params"])
        if hasattr(command, "list_commands"):
            section.extend(self._commands(command, ctx, path))
        return section


def public_modules(package: str) -> list[str]:
    """The package's public modules, subpackages' included, in name order.

    Left out: private modules (a name part starting with ``_``) and deprecated aliases, which
    re-export another module's names (their source calls ``alias_getattr`` or warns with a
    ``DeprecationWarning`` at import).
    """
    pkg = importlib.import_module(package)
    names = []
    for info in pkgutil.walk_packages(pkg.__path__, prefix=package + "."):
        if any(part.startswith("_") for part in info.name.split(".")):
            continue
        spec = importlib.util.find_spec(info.name)
        source = Path(spec.origin).read_text() if spec and spec.origin else ""
        if "alias_getattr(" in source or re.search(r"^warnings\.warn\(", source, re.M):
            continue
        names.append(info.name)
    return sorted(names)


class ApiDirective(SphinxDirective):
    """``.. skyradar-api:: skyradar.track``: the package docstring, a module table, one section each.

    ``:exclude:`` takes module names (comma-separated, full dotted names) to leave out.
    """

    required_arguments = 1
    option_spec = {"exclude": directives.unchanged}

    def run(self) -> list[nodes.Node]:
        package = self.arguments[0]
        exclude = {m.strip() for m in self.options.get("exclude", "").split(",") if m.strip()}
        modules = [m for m in public_modules(package) if m not in exclude]
        lines = [f".. automodule:: {package}", "", ".. autosummary::", ""]
        lines += [f"   {m[len(package) + 1 :]}" for m in modules]  # relative to the package's module
        lines.append("")
        for module in modules:
            lines += [module, "-" * len(module), "", f".. automodule:: {module}", "   :members:", ""]
        node = nodes.container()
        nested_parse_with_titles(self.state, StringList(lines, source=f"<skyradar-api {package}>"), node)
        return node.children


# ---- the scenario reference ------------------------------------------------------------------
SCENARIO_MODEL = "skyradar.scene.scenario_models.ScenarioModel"
# Plain names of the Python types a YAML value takes.
TYPE_NAMES = {float: "float", int: "int", str: "str", bool: "bool", datetime.datetime: "datetime"}


def _unwrap(annotation) -> tuple[object, list]:
    """The type inside ``Annotated[...]`` layers and their metadata, outermost first."""
    metadata: list = []
    while typing.get_origin(annotation) is typing.Annotated:
        annotation, *extra = typing.get_args(annotation)
        metadata += extra
    return annotation, metadata


def _is_model(annotation) -> bool:
    return isinstance(annotation, type) and issubclass(annotation, pydantic.BaseModel)


def _union_args(annotation) -> tuple | None:
    unions = (typing.Union, types.UnionType)
    return typing.get_args(annotation) if typing.get_origin(annotation) in unions else None


def _models_in(annotation, suffix: str = "") -> list[tuple[type, str]]:
    """The models a field's value may be, each with the path suffix to it (``[]`` for a list's items)."""
    annotation, _ = _unwrap(annotation)
    if _is_model(annotation):
        return [(annotation, suffix)]
    if typing.get_origin(annotation) is list:
        return _models_in(typing.get_args(annotation)[0], suffix + "[]")
    return [found for arg in _union_args(annotation) or () for found in _models_in(arg, suffix)]


def _join(path: str, key: str) -> str:
    return f"{path}.{key}" if path else key


def scenario_models(top: type) -> list[tuple[type, list[str]]]:
    """Every model reachable from ``top`` (breadth first) with the YAML paths it appears at.

    ``top`` itself is at the path ``""``; a list's items add ``[]`` (``intruders[]``), and every
    member of a union is at the union's path.
    """
    paths: dict[type, list[str]] = {}
    queue = [(top, "")]
    while queue:
        model, path = queue.pop(0)
        if path in paths.setdefault(model, []):
            continue
        paths[model].append(path)
        for key, field in model.model_fields.items():
            queue += [(child, _join(path, key) + suffix) for child, suffix in _models_in(field.annotation)]
    return list(paths.items())


def _number(value) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


_LIMITS = ((at.Gt, ">", "gt"), (at.Ge, ">=", "ge"), (at.Lt, "<", "lt"), (at.Le, "<=", "le"))


def _constraints(metadata) -> list[str]:
    """``> 0``, ``<= 180``, ``at least 1 item`` of pydantic's constraint metadata."""
    out = []
    for item in metadata:
        if isinstance(item, pydantic.fields.FieldInfo):
            out += _constraints(item.metadata)
        for kind, sign, name in _LIMITS:
            if isinstance(item, kind):
                out.append(f"{sign} {_number(getattr(item, name))}")
        if isinstance(item, at.MinLen):
            out.append(f"at least {item.min_length} item" + ("s" if item.min_length != 1 else ""))
        if isinstance(item, at.MaxLen):
            out.append(f"at most {item.max_length} items")
    return out


def _variant_tag(model: type) -> str | None:
    """The ``type`` value that picks ``model`` out of a tagged union, if it has one."""
    field = model.model_fields.get("type")
    values = typing.get_args(field.annotation) if field is not None else ()
    return values[0] if len(values) == 1 else None


def yaml_value(value) -> str:
    """A default as it is written in a scenario file (``yaml.safe_load`` reads the same value back).

    >>> yaml_value((0.0, 0.0, -1.0)), yaml_value(None), yaml_value(True), yaml_value("ga")
    ('[0.0, 0.0, -1.0]', 'null', 'true', 'ga')
    """
    import yaml

    if isinstance(value, pydantic.BaseModel):
        preset = SCENARIO_PRESETS.get(type(value).__name__)
        if preset is not None:  # a named model stands for its values
            return yaml_value(getattr(value, preset[0]))
        return "{}" if value == type(value)() else yaml_value(value.model_dump())
    if isinstance(value, list | tuple):
        return "[" + ", ".join(yaml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {yaml_value(v)}" for k, v in value.items()) + "}"
    if isinstance(value, str) and yaml.safe_load(value) != value:
        return json.dumps(value)
    return yaml.safe_dump(value, default_flow_style=True).removesuffix("\n").removesuffix("\n...")


# Models whose keys a named model fills in before validation (``navigation: ga-typical``): the model's
# name key, and the function that gives the values of a name.
SCENARIO_PRESETS = {"NavigationConfig": ("model", "skyradar.scene.navigation_config.with_preset")}


def _import(dotted: str):
    module, _, name = dotted.rpartition(".")
    return getattr(importlib.import_module(module), name)


class ScenarioDirective(SphinxDirective):
    """``.. skyradar-scenario:: [dotted.path.to.TopModel]``: every model of a scenario file, one
    section each (label ``scenario-<modelname>``), with a table of its keys."""

    optional_arguments = 1

    def run(self) -> list[nodes.Node]:
        models = scenario_models(_import(self.arguments[0] if self.arguments else SCENARIO_MODEL))
        for module in {model.__module__ for model, _ in models}:  # rebuilt when a model's module changes
            self.env.note_dependency(importlib.import_module(module).__file__)
        return [self._section(model, paths) for model, paths in models]

    def _section(self, model: type, paths: list[str]) -> nodes.section:
        section = _section(self, model.__name__, "scenario-" + model.__name__)
        where = nodes.paragraph(classes=["skyradar-scenario-paths"])
        where += nodes.Text("YAML: ")
        for i, path in enumerate(paths):
            where += nodes.Text(", " if i else "")
            where += nodes.literal(path or "(top level)", path or "(top level)")
        section += where
        doc = re.split(r"\n\S[^\n]*\n-{3,}\n", "\n" + inspect.cleandoc(model.__doc__ or "") + "\n")[0]
        lines = [*doc.strip().splitlines(), "", f"Model: :class:`{model.__module__}.{model.__name__}`."]
        nested_parse_with_titles(
            self.state, StringList(lines, source=f"<{model.__name__} docstring>"), section
        )
        preset = self._preset_values(model)
        keys = sorted(model.model_fields, key=lambda k: k != "type")  # a variant's tag first
        rows = [self._row(model, key, model.model_fields[key], preset) for key in keys]
        section += _table(
            ["key", "type", "required", "default", "description"], rows, classes=["skyradar-scenario-keys"]
        )
        return section

    def _preset_values(self, model: type) -> tuple[str, dict] | None:
        """The name key and the default named model's values of a model that ``SCENARIO_PRESETS`` names."""
        spec = SCENARIO_PRESETS.get(model.__name__)
        if spec is None:
            return None
        values = _import(spec[1])(None)
        return spec[0], values

    def _row(self, model: type, key: str, field, preset) -> list:
        filled = preset is not None and field.is_required() and key in preset[1]
        if field.is_required() and not filled:
            required, default = "yes", nodes.paragraph()
        else:
            required = "no"
            if filled:
                name, value = preset[1][preset[0]], yaml_value(preset[1][key])
                default = nodes.paragraph("", "", nodes.Text(f"from {preset[0]}; {name}: "))
                default += nodes.literal(value, value)
            else:
                value = yaml_value(field.default_factory() if field.default_factory else field.default)
                default = nodes.paragraph("", "", nodes.literal(value, value))
        if not field.description:
            self.state.document.reporter.warning(
                f"scenario key {model.__name__}.{key} has no description: add Field(description=...)",
                line=self.lineno,
            )
        text, messages = self.state.inline_text(field.description or "", self.lineno)
        description = nodes.paragraph("", "", *text, *messages)
        return [
            nodes.paragraph("", "", nodes.literal(key, key)),
            self._type(field),
            required,
            default,
            description,
        ]

    def _type(self, field) -> nodes.paragraph:
        out = nodes.paragraph()
        out.extend(self._type_nodes(field.annotation))
        extra = _constraints(field.metadata)
        if extra:
            out += nodes.Text(f" ({', '.join(extra)})")
        return out

    def _type_nodes(self, annotation) -> list[nodes.Node]:
        annotation, metadata = _unwrap(annotation)
        limits = _constraints(metadata)
        members = _union_args(annotation)
        origin = typing.get_origin(annotation)
        if members is not None:
            out: list[nodes.Node] = []
            for i, member in enumerate(members):
                out += ([nodes.Text(" | ")] if i else []) + self._type_nodes(member)
        elif origin is typing.Literal:
            out = []
            for i, value in enumerate(typing.get_args(annotation)):
                out += ([nodes.Text(" | ")] if i else []) + [nodes.literal(str(value), str(value))]
        elif _is_model(annotation):
            name = annotation.__name__
            out = [nodes.reference(name, name, internal=True, refid=nodes.make_id("scenario-" + name))]
            if (tag := _variant_tag(annotation)) is not None:
                out += [nodes.Text(" ("), nodes.literal(f"type: {tag}", f"type: {tag}"), nodes.Text(")")]
        elif origin is list:
            out = [nodes.Text("list of "), *self._type_nodes(typing.get_args(annotation)[0])]
        elif origin is tuple:
            args = typing.get_args(annotation)
            each = {tuple(_constraints(_unwrap(a)[1])) for a in args}
            out = [nodes.Text("[" + ", ".join(TYPE_NAMES.get(_unwrap(a)[0], str(a)) for a in args) + "]")]
            if len(each) == 1 and (common := next(iter(each))):
                out.append(nodes.Text(f" (each {', '.join(common)})"))
        elif annotation is type(None):
            out = [nodes.literal("null", "null")]
        else:
            out = [nodes.Text(TYPE_NAMES.get(annotation, getattr(annotation, "__name__", str(annotation))))]
        if limits and origin is not tuple:
            out.append(nodes.Text(f" ({', '.join(limits)})"))
        return out


class ColumnsDirective(SphinxDirective):
    """``.. skyradar-columns:: skyradar.process.pipeline.DETECTION_TABLE_COLUMNS``: a table's columns
    (name, unit, when written, meaning) from the producing module's mapping."""

    required_arguments = 1

    def run(self) -> list[nodes.Node]:
        from skyradar.io.table_columns import column_doc

        columns = _import(self.arguments[0])
        self.env.note_dependency(importlib.import_module(self.arguments[0].rpartition(".")[0]).__file__)
        rows = []
        for name, text in columns.items():
            doc = column_doc(text)
            rows.append(
                [
                    nodes.paragraph("", "", nodes.literal(name, name)),
                    doc.unit,
                    "always" if doc.optional is None else doc.optional,
                    _paragraph(doc.meaning),
                ]
            )
        return [_table(["column", "unit", "written", "meaning"], rows, classes=["skyradar-table-columns"])]


def setup(app: Sphinx) -> dict:
    app.add_directive("skyradar-results", ResultsDirective)
    app.add_directive("skyradar-benchmarks", BenchmarksDirective)
    app.add_directive("skyradar-clutter", ClutterDirective)
    app.add_directive("skyradar-closed-loop", ClosedLoopDirective)
    app.add_directive("skyradar-cli", CliDirective)
    app.add_directive("skyradar-api", ApiDirective)
    app.add_directive("skyradar-alert-config", AlertConfigDirective)
    app.add_directive("skyradar-scenario", ScenarioDirective)
    app.add_directive("skyradar-columns", ColumnsDirective)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
