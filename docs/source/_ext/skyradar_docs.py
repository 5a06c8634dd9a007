"""Sphinx directives that build pages of the skyradar documentation from the project itself.

``skyradar-results``
    One section per measured summary in ``docs/results/*.json``: its settings and provenance
    (command, version, date, load average) and a table of the headline numbers of each row. No
    number on the results page is written by hand.
``skyradar-cli``
    The command-line reference, read from the Typer app's click command tree
    (``typer.main.get_command``): each command's help, usage, arguments and options.
``skyradar-alert-config``
    The alerting settings, DAIDALUS' defaults beside the radar's, read from the package.
``skyradar-api``
    A subpackage's API: its docstring, a summary table of its public modules and an ``automodule``
    section per module. Private modules (``_name``) and deprecated aliases are left out.

Nothing is written into the source tree; every page is built from the files and the package as
they are at build time.
"""

from __future__ import annotations

import importlib
import importlib.util
import json
import math
import pkgutil
import re
from pathlib import Path

from docutils import nodes
from docutils.parsers.rst import directives
from docutils.statemachine import StringList
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective
from sphinx.util.nodes import nested_parse_with_titles

# Settings of one summary, in the order shown; `split` and `load_average_1min` are shown when present.
SUMMARY_FIELDS = ("family", "terrains", "layouts", "encounters", "seed", "split")
PROVENANCE_FIELDS = ("command", "version", "date_utc", "load_average_1min")
# Headline numbers of one row (a terrain and a layout); `warnings_not_held` only when present.
ROW_FIELDS = (
    "conflicts",
    "observable_conflicts",
    "missed_warnings",
    "false_warnings",
    "false_warning_rate",
    "median_warning_lead_s",
    "warnings_not_held",
)
# Decimals of the fractional numbers; the rest are counts.
DECIMALS = {"false_warning_rate": 3, "median_warning_lead_s": 1, "load_average_1min": 2}


def format_value(name: str, value: object) -> str:
    """A summary value as the results page shows it (the test reads numbers back the same way).

    >>> format_value("false_warning_rate", 0.02702702702702703), format_value("conflicts", 49)
    ('0.027', '49')
    >>> format_value("median_warning_lead_s", None), format_value("terrains", ["none", "hills"])
    ('n/a', 'none, hills')
    """
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    if isinstance(value, list | tuple):
        return ", ".join(str(v) for v in value)
    if isinstance(value, float) and name in DECIMALS:
        return f"{value:.{DECIMALS[name]}f}"
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    return str(value)


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
        fields = [f for f in SUMMARY_FIELDS if f != "split" or any("split" in s for _, s in summaries)]
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
        fields = nodes.field_list()
        for key in (*SUMMARY_FIELDS, *PROVENANCE_FIELDS):
            if key not in summary and key in ("split", "load_average_1min"):
                continue
            value = format_value(key, summary.get(key))
            body = nodes.paragraph()
            body += nodes.literal(value, value) if key in ("command", "version") else nodes.Text(value)
            fields += nodes.field("", nodes.field_name(key, key), nodes.field_body("", body))
        section += fields
        rows = summary.get("rows") or [summary]
        shown = [f for f in ROW_FIELDS if f != "warnings_not_held" or any(f in r for r in rows)]
        section += _table(
            # A zero-width space after each underscore lets the long column names wrap.
            [f.replace("_", "_\u200b") for f in ("terrain", "layout", "encounters", *shown)],
            [[format_value(f, r.get(f)) for f in ("terrain", "layout", "encounters", *shown)] for r in rows],
            classes=["skyradar-results-rows"],
        )
        return section


class AlertConfigDirective(SphinxDirective):
    """``.. skyradar-alert-config::``: every field of ``AlertConfig()`` (DAIDALUS' DO-365B settings)
    beside ``RADAR_ALERT_CONFIG`` (``skyradar alert --config radar``), read from the package."""

    def run(self) -> list[nodes.Node]:
        import dataclasses

        from skyradar.daa.alerting import RADAR_ALERT_CONFIG, AlertConfig

        default = AlertConfig()
        rows = []
        for f in dataclasses.fields(AlertConfig):
            a, b = getattr(default, f.name), getattr(RADAR_ALERT_CONFIG, f.name)
            if f.name == "levels":
                a, b = (", ".join(f"{lv.name} {lv.alerting_time_s:g} s" for lv in x) for x in (a, b))
            elif f.name == "collision_volume":
                a, b = (f"{x.dthr_m:g} m x {x.zthr_m:g} m" for x in (a, b))
            rows.append([nodes.paragraph("", "", nodes.literal(f.name, f.name)), str(a), str(b)])
        return [_table(["field", "default", "radar"], rows, classes=["skyradar-alert-config"])]


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


def setup(app: Sphinx) -> dict:
    app.add_directive("skyradar-results", ResultsDirective)
    app.add_directive("skyradar-cli", CliDirective)
    app.add_directive("skyradar-api", ApiDirective)
    app.add_directive("skyradar-alert-config", AlertConfigDirective)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
