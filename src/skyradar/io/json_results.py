"""JSON results: numpy values made plain and written atomically.

Results printed with ``--json``, written beside an experiment's tables and sent by the live display
share one sanitiser, :func:`jsonable`. JSON has no NaN nor infinity, so both become ``null``. The
module needs numpy only, so the command line can load it without pandas.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from skyradar.io.atomic import write_text_atomic

__all__ = ["jsonable", "write_json_atomic"]


def jsonable(value: Any) -> Any:
    """``value`` with numpy scalars and arrays made plain and NaN/inf made None (JSON has no NaN).

    Parameters
    ----------
    value : object
        A dict, list, tuple, numpy array or scalar, or a plain value; containers are walked.

    Returns
    -------
    object
        The same structure with dict keys as strings, tuples and arrays as lists, numpy scalars as
        Python numbers and non-finite floats as ``None``.

    Examples
    --------
    >>> jsonable({"a": np.float32(1.5), "b": np.array([1.0, np.nan]), 3: (np.int64(2), float("inf"))})
    {'a': 1.5, 'b': [1.0, None], '3': [2, None]}
    """
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [jsonable(v) for v in value]
    if isinstance(value, np.ndarray) and value.ndim > 0:
        return [jsonable(v) for v in value.tolist()]
    if hasattr(value, "item") and callable(value.item) and getattr(value, "ndim", 0) == 0:
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def write_json_atomic(path: str | Path, payload: Any) -> Path:
    """Write JSON to ``path`` through a temporary name and rename (NaN and inf become null).

    Parameters
    ----------
    path : path
        The JSON file; missing parent folders are created.
    payload : object
        Anything :func:`jsonable` makes plain (dicts, lists, numpy scalars and arrays).

    Returns
    -------
    Path
        ``path``.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = write_json_atomic(Path(d) / "out" / "s.json", {"rmse_m": np.float64(1.5), "ok": [np.nan]})
    ...     json.loads(p.read_text())
    {'rmse_m': 1.5, 'ok': [None]}
    """
    return write_text_atomic(path, json.dumps(jsonable(payload), indent=2, default=float, allow_nan=False))
