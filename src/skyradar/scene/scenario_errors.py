"""One line per scenario validation error: the file, the dotted field, what is wrong, the value."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from skyradar.io.safe_yaml import short_repr
from skyradar.scene.scenario_models import TAGS

__all__ = ["validation_error_line"]

_SENSE = {"greater_than": ">", "greater_than_equal": ">=", "less_than": "<", "less_than_equal": "<="}
_SENSE_KEY = {"greater_than": "gt", "greater_than_equal": "ge", "less_than": "lt", "less_than_equal": "le"}


def _describe(value: Any) -> str:
    # Bounded: str() of a value built from YAML aliases can expand to gigabytes.
    return short_repr(value)


def validation_error_line(source: str, err: Mapping[str, Any]) -> str:
    """One line from a pydantic error: file, dotted field, what is wrong, the value.

    Parameters
    ----------
    source : str
        The scenario file (or a label), first on the line.
    err : Mapping
        One entry of pydantic's ``ValidationError.errors()``; union tags leave the dotted field.

    Returns
    -------
    str

    Examples
    --------
    >>> err = {"type": "greater_than", "loc": ("frame_rate_hz",), "ctx": {"gt": 0.0}, "input": -5}
    >>> validation_error_line("s.yaml", err)
    "s.yaml: field 'frame_rate_hz': must be > 0 (got -5)"
    >>> err = {"type": "extra_forbidden", "loc": ("ownship", "straight", "sped_mps")}  # "straight": a tag
    >>> validation_error_line("s.yaml", err)
    "s.yaml: unknown key 'ownship.sped_mps'"
    """
    loc = [
        str(p) for p in err["loc"] if not (isinstance(p, str) and (p in TAGS or p.startswith("function-")))
    ]
    dotted = ".".join(loc) or "(top level)"
    kind, ctx, value = err["type"], err.get("ctx", {}), err.get("input")
    if kind == "extra_forbidden":
        return f"{source}: unknown key '{dotted}'"
    if kind == "missing" or (kind in ("model_attributes_type", "dict_type") and value is None):
        return f"{source}: field '{dotted}': is required"
    if kind in ("model_attributes_type", "dict_type"):
        return f"{source}: field '{dotted}': must be a mapping of keys (got {_describe(value)})"
    if kind in _SENSE:
        what = f"must be {_SENSE[kind]} {ctx[_SENSE_KEY[kind]]:g}"
    elif kind == "union_tag_invalid":
        what = f"'type' must be one of {ctx['expected_tags']}"
        value = ctx.get("tag")
    elif kind == "union_tag_not_found":
        return f"{source}: field '{dotted}': needs a 'type'"
    elif kind == "literal_error":
        what = f"must be one of {ctx['expected']}"
    elif kind in (
        "float_parsing",
        "float_type",
        "int_parsing",
        "int_type",
        "int_from_float",
        "finite_number",
    ):
        what = "must be a finite number" if kind != "int_from_float" else "must be a whole number"
    else:
        what = str(err["msg"]).removeprefix("Value error, ")
        what = what[:1].lower() + what[1:]
    return f"{source}: field '{dotted}': {what} (got {_describe(value)})"
