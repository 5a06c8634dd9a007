"""The documented columns of an output table: a mapping ``column -> "unit; meaning"``.

Each command that writes a table keeps one such mapping beside the code that builds the table
(:data:`skyradar.process.pipeline.DETECTION_TABLE_COLUMNS`, :data:`skyradar.track.track_table.
TRACK_TABLE_COLUMNS`, ...), in the table's column order. The documentation's output-tables page is
built from them, and a test runs the commands and compares the columns they write with them, so a
column is never written without a meaning and a unit.

The text is ``"UNIT; MEANING"``; the unit is ``-`` for flags, counts, identifiers and text. A column
written only in some runs ends in ``"; optional: WHEN"``, the condition under which it is written.

Examples
--------
>>> column_doc("m; range of the peak")
ColumnDoc(unit='m', meaning='range of the peak', optional=None)
>>> column_doc("-; the head's name; optional: a run of several radar heads").optional
'a run of several radar heads'
>>> always_written({"a": "s; time", "b": "m; x; optional: sometimes"})
['a']
"""

from __future__ import annotations

import re
from typing import NamedTuple

__all__ = ["ColumnDoc", "column_doc", "always_written"]

_TEXT = re.compile(r"(?P<unit>[^;]+); (?P<meaning>.+?)(?:; optional: (?P<optional>.+))?", re.DOTALL)


class ColumnDoc(NamedTuple):
    """One column's unit, meaning and, for a column not always written, when it is written.

    Parameters
    ----------
    unit : str
        The column's unit ("m", "m/s", "s", "rad", ...), ``-`` for flags, counts, identifiers and text.
    meaning : str
        What the column holds.
    optional : str or None
        When the column is written; None for a column every run writes.

    Examples
    --------
    >>> doc = ColumnDoc("m/s", "radial velocity", None)
    >>> doc.unit, doc == column_doc("m/s; radial velocity")
    ('m/s', True)
    """

    unit: str
    meaning: str
    optional: str | None


def column_doc(text: str) -> ColumnDoc:
    """The parts of a column's ``"unit; meaning[; optional: when]"`` text.

    Parameters
    ----------
    text : str
        ``"UNIT; MEANING"``, optionally followed by ``"; optional: WHEN"``.

    Returns
    -------
    ColumnDoc
        Unit and meaning stripped of surrounding spaces.

    Raises
    ------
    ValueError
        For text of any other form.

    Examples
    --------
    >>> column_doc("rad; azimuth; optional: a run with --angles")
    ColumnDoc(unit='rad', meaning='azimuth', optional='a run with --angles')
    >>> column_doc("azimuth")
    Traceback (most recent call last):
    ...
    ValueError: a column's text is 'unit; meaning[; optional: when]', got 'azimuth'
    """
    match = _TEXT.fullmatch(text)
    if match is None:
        raise ValueError(f"a column's text is 'unit; meaning[; optional: when]', got {text!r}")
    return ColumnDoc(match["unit"].strip(), match["meaning"].strip(), match["optional"])


def always_written(columns: dict[str, str]) -> list[str]:
    """The columns of a table's mapping that every run writes (not marked optional).

    Parameters
    ----------
    columns : dict of str to str
        Column name to ``"unit; meaning[; optional: when]"`` text, in the table's column order.

    Returns
    -------
    list of str
        The names, in the mapping's order.

    Examples
    --------
    >>> always_written({"time_s": "s; frame time", "head": "-; radar head; optional: several heads",
    ...                 "range_m": "m; range"})
    ['time_s', 'range_m']
    """
    return [name for name, text in columns.items() if column_doc(text).optional is None]
