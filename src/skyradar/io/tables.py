"""Tables (detections, tracks, states, poses, alerts) as pandas DataFrames in Parquet.

Writers go through a unique temporary name and rename (:mod:`skyradar.io.atomic`), so an
interrupted job never leaves a half-written file under the final name nor a stray temporary file.
Readers check required columns and say which are missing.
"""

from __future__ import annotations

import io
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from skyradar.errors import InputError
from skyradar.io.atomic import write_with

__all__ = [
    "finite_column",
    "check_within",
    "write_table",
    "read_table",
    "appended",
]


def appended(table: pd.DataFrame | None, rows: pd.DataFrame) -> pd.DataFrame:
    """``table`` with ``rows`` after it, numbered from 0; a missing or empty side gives the other.

    A stream that keeps its rows so far appends each frame's with one concatenation of two, so a
    frame costs the same at any point of a run (concatenating every frame's table anew grows with
    the run), and an empty frame, which may lack the table's columns, adds nothing.

    Examples
    --------
    >>> t = appended(None, pd.DataFrame({"x": [1.0]}))
    >>> appended(appended(t, pd.DataFrame()), pd.DataFrame({"x": [2.0]}))["x"].tolist()
    [1.0, 2.0]
    """
    if table is None or len(table) == 0:
        return rows.reset_index(drop=True)
    if len(rows) == 0:
        return table.reset_index(drop=True)
    return pd.concat([table, rows], ignore_index=True)


def write_table(df: pd.DataFrame, path: str | Path, metadata: dict[str, Any] | None = None) -> Path:
    """Write ``df`` to Parquet atomically; ``metadata`` goes into ``df.attrs`` (kept by pyarrow).

    Parameters
    ----------
    df : pandas.DataFrame
        The table; its index is not written. ``df`` itself is left unchanged.
    path : path
        The Parquet file.
    metadata : dict, optional
        Extra table attributes. ``skyradar_format`` (default ``"table/1"``) marks the file as ours
        (:mod:`skyradar.io.outputs` then lets a later run replace it without ``--overwrite``).

    Returns
    -------
    Path
        ``path``.

    Examples
    --------
    >>> import tempfile
    >>> df = pd.DataFrame({"time_s": [0.0, 0.1], "range_m": [120.0, 118.5]})
    >>> with tempfile.TemporaryDirectory() as d:
    ...     back = read_table(write_table(df, Path(d) / "det.parquet", {"origin_lla": [52.0, 5.0, 0.0]}))
    >>> back.equals(df), back.attrs["skyradar_format"], back.attrs["origin_lla"], df.attrs
    (True, 'table/1', [52.0, 5.0, 0.0], {})
    """
    df = df.copy(deep=False)
    df.attrs.update({"skyradar_format": "table/1", **(metadata or {})})
    return write_with(path, lambda tmp: df.to_parquet(tmp, index=False))


def read_table(
    path: str | Path, required: Iterable[str] = (), sort_by: str | None = None, finite: Iterable[str] = ()
) -> pd.DataFrame:
    """Read a Parquet (or CSV) table and check that ``required`` columns are present.

    Parameters
    ----------
    path : path
        A ``.parquet`` or ``.csv`` file; without either suffix the content decides (Parquet starts
        with ``PAR1``), so a named pipe reads as what it holds.
    required : iterable of str
        Columns that must be present.
    sort_by : str, optional
        A column that must be non-decreasing.
    finite : iterable of str
        Columns that must hold finite numbers.

    Returns
    -------
    pandas.DataFrame

    Raises
    ------
    InputError
        Naming the file when it is missing, unreadable or lacks a required column; naming the first
        bad row when a ``finite`` column holds a string, NaN or inf, or ``sort_by`` goes backwards.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     csv = Path(d) / "tracks.csv"
    ...     _ = csv.write_text("time_s,range_m\\n0.0,100.0\\n0.1,98.0\\n0.05,97.0\\n")
    ...     df = read_table(csv, required=["time_s", "range_m"], finite=["range_m"])
    ...     try:
    ...         read_table(csv, sort_by="time_s")
    ...     except InputError as err:
    ...         message = str(err).replace(d, "DIR")
    >>> df["range_m"].tolist(), message
    ([100.0, 98.0, 97.0], "DIR/tracks.csv: field 'time_s' goes backwards at row 2 (0.1 -> 0.05)")
    """
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: no such file")
    if path.is_dir():
        raise InputError(f"{path}: is a directory, not a table (Parquet or CSV file)")
    # A device or a socket is no table (pyarrow reports /dev/null as missing); a named pipe is read
    # as it streams (a shell's process substitution gives one).
    if path.is_char_device() or path.is_block_device() or path.is_socket():
        raise InputError(f"{path}: is a device, not a table (Parquet or CSV file)")
    if path.is_file() and path.stat().st_size == 0:
        raise InputError(f"{path}: is empty, not a table (Parquet or CSV file)")
    try:
        df = _read_by_format(path)
    except Exception as exc:  # noqa: BLE001 - reader failure becomes one clear line
        raise InputError(f"{path}: cannot read table ({type(exc).__name__}: {exc})") from exc
    missing = [c for c in required if c not in df.columns]
    if missing:
        raise InputError(f"{path}: missing column(s) {missing} (have {list(df.columns)})")
    for col in finite:
        finite_column(df, col, path)
    if sort_by is not None and len(df) > 1:
        values = df[sort_by].to_numpy()
        back = (values[1:] < values[:-1]).nonzero()[0]
        if back.size:
            i = int(back[0]) + 1
            raise InputError(
                f"{path}: field '{sort_by}' goes backwards at row {i} ({values[i - 1]} -> {values[i]})"
            )
    return df


def _read_by_format(path: Path) -> pd.DataFrame:
    """The table at ``path``: CSV by its ``.csv`` suffix, Parquet by ``.parquet``; without either the
    content decides (Parquet opens with the magic bytes ``PAR1``, anything else is read as CSV), so a
    shell's process substitution (``<(cat det.csv)``, a pipe named ``/dev/fd/63``) reads as what it
    holds. A pipe cannot be read twice: its bytes are read once and parsed from memory."""
    suffix = path.suffix.lower()
    if suffix == ".csv":
        return pd.read_csv(path)
    if suffix == ".parquet":
        return pd.read_parquet(path)
    source: Path | io.BytesIO = path
    if path.is_fifo():
        data = path.read_bytes()
        source, magic = io.BytesIO(data), data[:4]
    else:
        with path.open("rb") as f:
            magic = f.read(4)
    return pd.read_parquet(source) if magic == b"PAR1" else pd.read_csv(source)


def finite_column(df: pd.DataFrame, col: str, source: str | Path, allow_nan: bool = False) -> np.ndarray:
    """Column ``col`` as float, refusing a non-number or infinity (and NaN unless ``allow_nan``).

    The :class:`InputError` names ``source``, the field, the first bad row and its raw value.

    Examples
    --------
    >>> finite_column(pd.DataFrame({"x": [1, 2.5]}), "x", "t.csv")
    array([1. , 2.5])
    >>> finite_column(pd.DataFrame({"x": [1.0, "a"]}), "x", "t.csv")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: t.csv: field 'x' is not a finite number at row 1 ('a')
    """
    column = df[col]
    if pd.api.types.is_float_dtype(column.dtype) or pd.api.types.is_integer_dtype(column.dtype):
        values = column.to_numpy(float)  # numbers already: nothing to coerce
        was_nan = np.isnan(values)
    else:
        values = pd.to_numeric(column, errors="coerce").to_numpy(float)
        # A NaN that was NaN in the file may be allowed; one made by coercing a string never is.
        was_nan = pd.isna(column).to_numpy()
    bad = np.flatnonzero(np.isinf(values) | (np.isnan(values) & (~was_nan | (not allow_nan))))
    if bad.size:
        raw = df[col].iloc[bad[0]]
        raw = raw.item() if hasattr(raw, "item") else raw
        raise InputError(f"{source}: field '{col}' is not a finite number at row {bad[0]} ({raw!r})")
    return values


def check_within(
    values: np.ndarray, limit: float, unit: str, source: str | Path, col: str, what: str
) -> None:
    """Refuse the first of ``values`` (column ``col``) beyond +-``limit``, naming the row; NaN passes.

    ``unit`` follows each number as written ("" for a dimensionless column).

    1e308 is a finite number, but no measurement or state ``what`` describes holds it.

    Examples
    --------
    >>> check_within(np.array([1.0, 1e308]), 1e7, "m", "t.csv", "x", "not a position")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: t.csv: field 'x' is 1e+308 m at row 1, beyond +-1e+07 m: not a position
    """
    with np.errstate(invalid="ignore"):
        beyond = np.flatnonzero(np.abs(values) > limit)
    if beyond.size:
        i = int(beyond[0])
        spaced = f" {unit}" if unit else ""
        raise InputError(
            f"{source}: field '{col}' is {values[i]:.6g}{spaced} at row {i}, "
            f"beyond +-{limit:g}{spaced}: {what}"
        )
