"""The README's results table, generated from the measured encounter summaries in ``docs/results/``.

Each file there is the JSON summary ``skyradar experiment encounters --json`` printed. The README shows
one short table of the newest evaluation-split run per encounter family and terrain (the files
:data:`README_RESULTS` names), between two HTML comment markers; every number in it is read from those
files, none is typed by hand. ``python -m skyradar.experiments.readme_results`` rewrites the table in
``README.md`` in place, run from the repository's root.
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from skyradar.experiments.encounters import EVALUATION_SEEDS_FROM
from skyradar.io.atomic import write_text_atomic

__all__ = [
    "README_RESULTS",
    "START",
    "END",
    "HEADER",
    "is_evaluation",
    "summary_rows",
    "readme_table",
    "replace_readme_table",
    "main",
]

# The newest evaluation-split run of each family and terrain the README reports, in table order.
README_RESULTS: tuple[str, ...] = (
    "encounters-synthetic-none-seed7212-n200.json",
    "encounters-synthetic-flat300-seed7214-n200.json",
    "encounters-synthetic-flat1000-seed7217-n200.json",
    "encounters-synthetic-jacksboro-seed7215-n200.json",
    "encounters-synthetic-hills-seed7216-n200.json",
    "encounters-fast-closures-hills-none-seed7219-n200.json",
    "encounters-fast-closures-jacksboro-none-seed7220-n200.json",
    "encounters-real-flights-none-seed7218-n100.json",
)

START = "<!-- results-table:start -->"
END = "<!-- results-table:end -->"

HEADER: tuple[str, ...] = (
    "family",
    "terrain",
    "layout",
    "seed",
    "missed / observable conflicts",
    "false warnings / must-not-alert (95 % interval)",
    "median warning lead [s]",
    "code",
    "measured",
)


def is_evaluation(summary: Mapping[str, Any]) -> bool:
    """Whether an encounter summary is a run on the evaluation split.

    Parameters
    ----------
    summary : mapping
        The summary's top-level keys; ``split`` if it records one, otherwise ``seed``.

    Returns
    -------
    bool
        ``split == "evaluation"``; without a ``split``, whether the seed is an evaluation seed
        (7000 or more).

    Examples
    --------
    >>> is_evaluation({"split": "evaluation", "seed": 7212}), is_evaluation({"split": "development"})
    (True, False)
    >>> is_evaluation({"seed": 7001}), is_evaluation({"seed": 0})
    (True, False)
    """
    if "split" in summary and summary["split"] is not None:
        return bool(summary["split"] == "evaluation")
    return int(summary["seed"]) >= EVALUATION_SEEDS_FROM  # a summary without a split key


def _short_version(version: str) -> str:
    """The package version with the source digest cut to seven characters."""
    base, _, digest = version.replace(" at commit ", "+").partition("+")
    return f"{base}+{digest[:7]}" if digest else base


def _lead(value: Any) -> str:
    """A median lead in s with one decimal; ``n/a`` where no warning was in time."""
    if value is None or not math.isfinite(float(value)):
        return "n/a"
    return f"{float(value):.1f}"


def summary_rows(summary: Mapping[str, Any]) -> list[tuple[str, ...]]:
    """The table's cells for one encounter summary, one tuple per terrain and layout row.

    Parameters
    ----------
    summary : mapping
        An encounter summary: ``family``, ``seed``, ``version``, ``date_utc`` and ``rows``, each row
        with ``terrain``, ``layout``, ``missed_warnings``, ``observable_conflicts``,
        ``false_warnings``, ``must_not_alert_encounters``, ``false_warning_rate_ci95`` (fractions)
        and ``median_warning_lead_s``.

    Returns
    -------
    list of tuple of str
        The cells, in the order of :data:`HEADER`.

    Examples
    --------
    >>> summary = {"family": "synthetic", "seed": 7300, "version": "0.1.0+0123456789abcdef",
    ...            "date_utc": "2026-01-02T03:04:05Z",
    ...            "rows": [{"terrain": "none", "layout": "single", "missed_warnings": 1,
    ...                      "observable_conflicts": 40, "false_warnings": 2,
    ...                      "must_not_alert_encounters": 50,
    ...                      "false_warning_rate_ci95": [0.011, 0.135],
    ...                      "median_warning_lead_s": 27.44}]}
    >>> summary_rows(summary)  # doctest: +NORMALIZE_WHITESPACE
    [('synthetic', 'none', 'single', '7300', '1 / 40', '2 / 50 (1.1-13.5 %)', '27.4',
      '0.1.0+0123456', '2026-01-02')]
    """
    cells: list[tuple[str, ...]] = []
    for row in summary["rows"]:
        low, high = row["false_warning_rate_ci95"]
        cells.append(
            (
                str(summary["family"]),
                str(row["terrain"]),
                str(row["layout"]),
                str(summary["seed"]),
                f"{row['missed_warnings']} / {row['observable_conflicts']}",
                f"{row['false_warnings']} / {row['must_not_alert_encounters']}"
                f" ({100 * low:.1f}-{100 * high:.1f} %)",
                _lead(row["median_warning_lead_s"]),
                _short_version(str(summary["version"])),
                str(summary["date_utc"])[:10],
            )
        )
    return cells


def readme_table(results_dir: Path, files: Sequence[str]) -> str:
    """The README's results table: one row per file and terrain/layout row of its summary.

    Parameters
    ----------
    results_dir : Path
        The folder of the measured summaries (``docs/results``).
    files : sequence of str
        The summaries' file names, in table order; each must be an evaluation-split run.

    Returns
    -------
    str
        A Markdown table, one line per row, without a trailing newline.

    Raises
    ------
    FileNotFoundError
        A named file is not in ``results_dir``.
    ValueError
        A named file is not an evaluation-split run.

    Examples
    --------
    >>> import json, tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> row = {"terrain": "hills", "layout": "single", "missed_warnings": 0,
    ...        "observable_conflicts": 52, "false_warnings": 3, "must_not_alert_encounters": 72,
    ...        "false_warning_rate_ci95": [0.0143, 0.1155], "median_warning_lead_s": 26.38}
    >>> summary = {"family": "fast-closures", "seed": 7400, "split": "evaluation",
    ...            "version": "0.1.0+fedcba9876543210", "date_utc": "2026-02-03T04:05:06Z",
    ...            "rows": [row]}
    >>> _ = (folder / "run.json").write_text(json.dumps(summary))
    >>> print(readme_table(folder, ["run.json"]))  # doctest: +NORMALIZE_WHITESPACE
    | family | terrain | layout | seed | missed / observable conflicts
      | false warnings / must-not-alert (95 % interval) | median warning lead [s] | code | measured |
    |---|---|---|---|---|---|---|---|---|
    | fast-closures | hills | single | 7400 | 0 / 52 | 3 / 72 (1.4-11.6 %) | 26.4 | 0.1.0+fedcba9
      | 2026-02-03 |
    """
    lines = ["| " + " | ".join(HEADER) + " |", "|" + "---|" * len(HEADER)]
    for name in files:
        path = Path(results_dir) / name
        if not path.is_file():
            raise FileNotFoundError(f"{path}: no such measured summary")
        summary = json.loads(path.read_text(encoding="utf-8"))
        if not is_evaluation(summary):
            raise ValueError(f"{path}: not an evaluation-split run (split {summary.get('split')!r})")
        lines += ["| " + " | ".join(cells) + " |" for cells in summary_rows(summary)]
    return "\n".join(lines)


def replace_readme_table(readme_text: str, table: str) -> str:
    """``readme_text`` with the text between the results-table markers replaced by ``table``.

    Parameters
    ----------
    readme_text : str
        The README, holding :data:`START` once and :data:`END` once after it.
    table : str
        The table to put between the markers.

    Returns
    -------
    str
        The README with the markers kept, each on its own line, and ``table`` between them.

    Raises
    ------
    ValueError
        The markers are missing, repeated or out of order.

    Examples
    --------
    >>> text = f"# Results\\n\\n{START}\\nold\\n{END}\\n\\nMore.\\n"
    >>> print(replace_readme_table(text, "| a |\\n|---|\\n| 1 |"))
    # Results
    <BLANKLINE>
    <!-- results-table:start -->
    | a |
    |---|
    | 1 |
    <!-- results-table:end -->
    <BLANKLINE>
    More.
    <BLANKLINE>
    """
    if readme_text.count(START) != 1 or readme_text.count(END) != 1:
        raise ValueError(f"the README needs {START} and {END} once each")
    before, _, rest = readme_text.partition(START)
    if END in before:
        raise ValueError(f"{END} comes before {START}")
    after = rest.partition(END)[2]
    return f"{before}{START}\n{table.strip()}\n{END}{after}"


def main(argv: Sequence[str] | None = None) -> None:
    """Rewrite the results table of ``README.md`` in place (atomically) from ``docs/results``.

    Parameters
    ----------
    argv : sequence of str, optional
        Command-line arguments; ``--root`` names the repository's root (default: the working
        directory).
    """
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--root", type=Path, default=Path.cwd(), help="the repository's root")
    root: Path = parser.parse_args(argv).root
    readme = root / "README.md"
    table = readme_table(root / "docs" / "results", README_RESULTS)
    write_text_atomic(readme, replace_readme_table(readme.read_text(encoding="utf-8"), table))


if __name__ == "__main__":
    main()
