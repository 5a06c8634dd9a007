"""``summary.md``: the page an experiment's folder opens with, written from the run's own numbers.

Every experiment writes one next to its JSON and figures: a title, a few sentences on what was
measured and how it compares with the thesis, a table of the headline values and the list of the
figure and data files in the folder. Each experiment picks its headline keys and words its sentences
(its ``summary_markdown``); this module lays the page out the same way for all of them. Numbers come
from the summary dict the run returns, never typed in, so the page says what the JSON says.
"""

from __future__ import annotations

import math
import re
import textwrap
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from skyradar.io.atomic import write_text_atomic

__all__ = ["SUMMARY_NAME", "number", "counted", "beside", "markdown_table", "page", "write_summary"]

SUMMARY_NAME = "summary.md"
WIDTH = 100  # prose lines are wrapped here; table rows stay one line each (markdown needs that)


def number(value: Any, decimals: int = 1) -> str:
    """A measured value as text: fixed decimals, ``n/a`` for a missing or non-finite one.

    Parameters
    ----------
    value : float, int, bool, str or None
        The value; a bool reads ``yes``/``no``, an int and a str are shown as they are.
    decimals : int
        Decimals of a float.

    Returns
    -------
    str
        The value as text.

    Examples
    --------
    >>> number(12.345), number(3), number(None), number(float("nan")), number(True), number(0.5, 2)
    ('12.3', '3', 'n/a', 'n/a', 'yes', '0.50')
    """
    if value is None:
        return "n/a"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int | str):
        return str(value)
    value = float(value)
    return f"{value:.{decimals}f}" if math.isfinite(value) else "n/a"


def counted(n: int, noun: str, nouns: str | None = None) -> str:
    """``n`` and the noun in the number ``n`` asks for.

    Parameters
    ----------
    n : int
        The count.
    noun, nouns : str
        Singular and plural (default: the singular with an ``s``).

    Returns
    -------
    str
        For example ``1 terrain`` or ``3 terrains``.

    Examples
    --------
    >>> counted(1, "terrain"), counted(3, "terrain"), counted(2, "own-ship flight")
    ('1 terrain', '3 terrains', '2 own-ship flights')
    """
    return f"{n} {noun if n == 1 else (nouns or noun + 's')}"


def beside(value: Any, reference: Any, decimals: int = 1) -> str:
    """A measured value with the published one in brackets; without brackets when none is published.

    Parameters
    ----------
    value, reference : float, int or None
        Ours and the reference (the thesis'); a None reference is not published.
    decimals : int
        Decimals of a float (:func:`number`).

    Returns
    -------
    str
        ``value (reference)`` or ``value``.

    Examples
    --------
    >>> beside(3.14, 4.9), beside(12, 14), beside(0.5, None)
    ('3.1 (4.9)', '12 (14)', '0.5')
    """
    shown = number(value, decimals)
    return shown if reference is None else f"{shown} ({number(reference, decimals)})"


def markdown_table(header: Sequence[str], rows: Iterable[Sequence[Any]]) -> str:
    """A markdown table; cells are written with :func:`number` (floats with one decimal) unless text.

    Parameters
    ----------
    header : sequence of str
        Column titles.
    rows : iterable of sequences
        One sequence of cells per row, as many as ``header``.

    Returns
    -------
    str
        The table, one line per row, without a trailing newline.

    Examples
    --------
    >>> print(markdown_table(["quantity", "measured", "thesis"], [["az SD [deg]", 0.71, 1.8]]))
    | quantity | measured | thesis |
    |---|---|---|
    | az SD [deg] | 0.7 | 1.8 |
    """
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for row in rows:
        cells = [str(c) if isinstance(c, str) else number(c) for c in row]
        if len(cells) != len(header):
            raise ValueError(f"a table row has {len(cells)} cells for {len(header)} columns: {row!r}")
        lines.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
    return "\n".join(lines)


def _present(out_dir: Path, label: str) -> bool:
    """Whether ``label`` (a file name, or a pattern with ``<placeholders>``) names a file in ``out_dir``."""
    if "<" not in label:
        return (out_dir / label).is_file()
    return any(p.is_file() for p in out_dir.glob(re.sub(r"<[^>]*>", "*", label)))


def page(
    title: str,
    paragraphs: Sequence[str],
    header: Sequence[str],
    rows: Iterable[Sequence[Any]],
    files: Mapping[str, str],
    out_dir: Path | None = None,
) -> str:
    """The summary page: title, paragraphs, the headline table and the files with what each holds.

    Parameters
    ----------
    title : str
        The page title (without ``#``).
    paragraphs : sequence of str
        The sentences, one paragraph each, wrapped at 100 characters.
    header, rows
        The headline table (:func:`markdown_table`).
    files : mapping of str to str
        File name (or pattern such as ``state_<case>.parquet`` for a group) to what it holds, in the
        order listed.
    out_dir : Path, optional
        The run's folder: only the files (or patterns) present in it are listed. None lists all.

    Returns
    -------
    str
        Markdown, ending in a newline.

    Examples
    --------
    >>> text = page("ch0: a test", ["Measured 2 things."], ["quantity", "measured"], [["x [m]", 1.25]],
    ...             {"ch0.png": "the figure", "ch0.json": "every number"})
    >>> print(text)
    # ch0: a test
    <BLANKLINE>
    Measured 2 things.
    <BLANKLINE>
    | quantity | measured |
    |---|---|
    | x [m] | 1.2 |
    <BLANKLINE>
    Files in this folder:
    <BLANKLINE>
    - `ch0.png`: the figure
    - `ch0.json`: every number
    <BLANKLINE>
    """
    listed = {k: v for k, v in files.items() if out_dir is None or _present(Path(out_dir), k)}
    lines = [f"# {title}", ""]
    for text in paragraphs:
        lines += [textwrap.fill(text, WIDTH, break_on_hyphens=False), ""]
    lines += [markdown_table(header, rows), ""]
    if listed:
        lines += ["Files in this folder:", ""]
        lines += [f"- `{name}`: {what}" for name, what in listed.items()]
        lines.append("")
    return "\n".join(lines)


def write_summary(out_dir: Path, text: str) -> Path:
    """Write ``text`` to ``out_dir / summary.md`` atomically; return the path.

    Parameters
    ----------
    out_dir : Path
        The run's folder (created if missing).
    text : str
        The page (:func:`page`).

    Returns
    -------
    Path
        The written file.
    """
    return write_text_atomic(Path(out_dir) / SUMMARY_NAME, text)
