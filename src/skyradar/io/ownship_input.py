"""What ``--ownship`` accepts, for every command that takes it (``track``, ``alert``).

Either a frames run (a Zarr store from ``simulate`` or a recording) or a table (Parquet or CSV:
``time_s`` and own-ship columns, like ``skyradar export``'s ``ownship.parquet`` or a hand-made
``own_north_m..own_vd_mps`` table). Both come back as one Dataset on ``time``, so that the one
navigation reader (:func:`skyradar.io.navigation.navigation_state`) picks the navigation solution
(``nav_*``) when present, never the truth beside it, and the run's origin is read the one way
(:func:`skyradar.io.run_origin.scenario_origin`): from the store's attributes, or from a table's
``origin_lla`` metadata (written by ``skyradar export``).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr

from skyradar.errors import InputError

__all__ = ["open_ownship", "table_as_run"]


def table_as_run(table: pd.DataFrame, source: str) -> xr.Dataset:
    """An own-ship table as a Dataset on ``time`` (numeric columns; ``time_s`` required, increasing).

    Examples
    --------
    >>> ds = table_as_run(pd.DataFrame({"time_s": [0.0, 1.0], "nav_north_m": [0.0, 50.0]}), "own.csv")
    >>> ds["nav_north_m"].values.tolist(), ds.attrs
    ([0.0, 50.0], {})
    >>> table_as_run(pd.DataFrame({"time_s": [0.0, 0.0]}), "own.csv")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: own.csv: field 'time_s' is not increasing at row 1 (0.0 -> 0.0)
    """
    if "time_s" not in table.columns:
        raise InputError(f"{source}: missing required field 'time_s'; columns are {list(table.columns)}")
    if len(table) == 0:  # an empty CSV's columns come back untyped: say so, not "missing column"
        raise InputError(f"{source}: no rows")
    t = pd.to_numeric(table["time_s"], errors="coerce").to_numpy(float)
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise InputError(f"{source}: field 'time_s' is not a number at row {int(bad[0])}")
    back = np.flatnonzero(np.diff(t) <= 0)
    if back.size:
        i = int(back[0]) + 1
        raise InputError(f"{source}: field 'time_s' is not increasing at row {i} ({t[i - 1]} -> {t[i]})")
    _own_columns_numeric(table, source)
    data = {
        str(c): ("time", table[c].to_numpy(float))
        for c in table.columns
        if c != "time_s"
        and pd.api.types.is_numeric_dtype(table[c])
        and not pd.api.types.is_bool_dtype(table[c])
    }
    ds = xr.Dataset(data, coords={"time_s": ("time", t)})
    origin = table.attrs.get("origin_lla")
    if origin is not None:  # `skyradar export` keeps the run's origin in the table's metadata
        ds.attrs["origin"] = json.dumps(list(origin) if not isinstance(origin, str) else json.loads(origin))
    return ds


def _own_columns_numeric(table: pd.DataFrame, source: str) -> None:
    """Refuse an own-ship or navigation column (``own_*``, ``nav_*``) holding text: dropped with the
    other non-numeric columns, it would go unseen (a text ``own_height_agl_m`` turned the ground's
    range-Doppler band off, and every elevation was trusted as in clear sky)."""
    for c in table.columns:
        if not str(c).startswith(("own_", "nav_")) or pd.api.types.is_bool_dtype(table[c]):
            continue
        bad = np.flatnonzero(pd.to_numeric(table[c], errors="coerce").isna() & table[c].notna())
        if bad.size:
            row = int(bad[0])
            raise InputError(f"{source}: field {c!r} is not a number at row {row} ({table[c].iloc[row]!r})")


def open_ownship(path: str | Path, option: str = "--ownship") -> xr.Dataset:
    """The own-ship source ``path``: a frames run (Zarr directory) or a table (Parquet/CSV).

    Read its navigation with :func:`skyradar.io.navigation.navigation_state` and its origin with
    :func:`skyradar.io.run_origin.scenario_origin`.

    Parameters
    ----------
    path : path
        A frames store, or a ``.parquet``/``.pq``/``.csv`` table with ``time_s`` (s) and own-ship
        columns (``own_*``/``nav_*``, units in their names: m, m/s, rad, degree).
    option : str
        The command-line option that names ``path``, for error messages.

    Returns
    -------
    xarray.Dataset
        On ``time``; a table's numeric columns become variables and ``time_s`` a coordinate.

    Raises
    ------
    InputError
        When ``path`` is missing, of another kind, or not a valid run or table.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     csv = Path(d) / "own.csv"
    ...     _ = csv.write_text("time_s,nav_north_m,nav_vn_mps\\n0.0,0.0,40.0\\n0.5,20.0,40.0\\n")
    ...     ds = open_ownship(csv)
    ...     sorted(ds.data_vars), ds["nav_north_m"].values.tolist(), ds["time_s"].values.tolist()
    (['nav_north_m', 'nav_vn_mps'], [0.0, 20.0], [0.0, 0.5])
    >>> open_ownship("missing.csv")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: --ownship missing.csv: no such run or table
    """
    from skyradar.io.frames import open_frames
    from skyradar.io.tables import read_table

    path = Path(path)
    if not path.exists() and path.is_symlink():
        raise InputError(f"{option} {path}: a symbolic link that leads nowhere (a loop, or no target)")
    if not path.exists():
        raise InputError(f"{option} {path}: no such run or table")
    if path.is_dir():
        return open_frames(path)
    if path.suffix.lower() not in (".parquet", ".pq", ".csv"):
        raise InputError(
            f"{option} {path}: expected a frames run (Zarr directory) or an own-ship table (.parquet or .csv)"
        )
    return table_as_run(read_table(path), f"{option} {path}")
