"""YAML from users, read safely: no alias bombs, no recursive aliases, one-line errors.

``yaml.safe_load`` builds aliases as shared objects, so a 342-byte "billion laughs" file loads
in microseconds, but anything that then walks the value (validation, ``str()`` in an error
message, JSON) expands it to 10^9 items and tens of GB. :func:`load_yaml` composes the node
graph first, counts the nodes the document stands for with every alias expanded (memoised,
so counting costs one pass over the distinct nodes) and refuses documents above
:data:`MAX_EXPANDED_NODES` before constructing anything. A key given twice in one mapping is
refused too (PyYAML would keep the last one without a word).
"""

from __future__ import annotations

import reprlib
from pathlib import Path
from typing import Any

import yaml

from skyradar.errors import InputError

__all__ = ["MAX_EXPANDED_NODES", "load_yaml", "expanded_size", "short_repr"]

# A scenario or sidecar has hundreds of nodes; an inline trajectory some ten thousand.
MAX_EXPANDED_NODES = 1_000_000


def expanded_size(node: yaml.Node, limit: int = MAX_EXPANDED_NODES) -> int:
    """Number of nodes under ``node`` with every alias expanded; stops counting above ``limit``.

    Raises :class:`ValueError` for a recursive alias (a node that contains itself).

    Examples
    --------
    >>> node = yaml.compose("a: &x [1, 2, 3]\\nb: [*x, *x]", Loader=yaml.SafeLoader)
    >>> expanded_size(node)
    16
    """
    sizes: dict[int, int] = {}
    active: set[int] = set()

    def size(n: yaml.Node) -> int:
        key = id(n)
        if key in sizes:
            return sizes[key]
        if key in active:
            raise ValueError("recursive alias (a node that contains itself)")
        if isinstance(n, yaml.ScalarNode):
            return 1
        active.add(key)
        children = n.value if isinstance(n, yaml.SequenceNode) else [c for kv in n.value for c in kv]
        total = 1
        for child in children:
            total += size(child)
            if total > limit:  # no need to count a bomb to the end
                break
        active.discard(key)
        sizes[key] = total
        return total

    return size(node)


def _refuse_duplicate_keys(node: yaml.Node, source: str | Path) -> None:
    """A key twice in one mapping: PyYAML keeps the last silently (``duration_s`` given twice)."""
    seen: set[int] = set()
    stack = [node]
    while stack:
        n = stack.pop()
        if id(n) in seen or isinstance(n, yaml.ScalarNode):
            continue
        seen.add(id(n))
        if isinstance(n, yaml.SequenceNode):
            stack.extend(n.value)
            continue
        keys: set[tuple[str, str]] = set()
        for key, value in n.value:
            if isinstance(key, yaml.ScalarNode) and key.tag != "tag:yaml.org,2002:merge":
                if (key.tag, key.value) in keys:
                    where = f"line {key.start_mark.line + 1}"
                    raise InputError(f"{source}: key '{key.value}' appears twice in one mapping ({where})")
                keys.add((key.tag, key.value))
            stack.extend((key, value))


def load_yaml(text: str, source: str | Path, limit: int = MAX_EXPANDED_NODES) -> Any:
    """Parse ``text`` (from ``source``, named in errors) with the safe loader, refusing alias bombs.

    Examples
    --------
    >>> load_yaml("a: &x [1, 2]\\nb: *x", "s.yaml")
    {'a': [1, 2], 'b': [1, 2]}
    >>> load_yaml("a: &x [1, 2]\\nb: [*x, *x, *x]", "s.yaml", limit=10)
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: s.yaml: aliases expand the document to more than 10 nodes; refused
    >>> load_yaml("duration_s: 1\\nduration_s: 50000", "s.yaml")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: s.yaml: key 'duration_s' appears twice in one mapping (line 2)
    """
    loader = yaml.SafeLoader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        try:
            n = expanded_size(node, limit)
        except ValueError as exc:
            raise InputError(f"{source}: {exc}; refused") from None
        if n > limit:
            raise InputError(f"{source}: aliases expand the document to more than {limit} nodes; refused")
        _refuse_duplicate_keys(node, source)
        return loader.construct_document(node)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or type(exc).__name__
        raise InputError(f"{source}: not valid YAML{where} ({problem})") from None
    except RecursionError:  # [[[[... deeper than the parser's stack: no scenario or setting is
        raise InputError(f"{source}: not valid YAML (nested too deeply)") from None
    finally:
        loader.dispose()


_SHORT = reprlib.Repr()
_SHORT.maxlevel, _SHORT.maxdict, _SHORT.maxlist, _SHORT.maxtuple = 2, 3, 3, 3
_SHORT.maxstring, _SHORT.maxother, _SHORT.maxlong = 50, 50, 40


def short_repr(value: Any, width: int = 60) -> str:
    """A bounded description of ``value`` for an error message, without stringifying all of it.

    Strings are quoted; containers show their first items only (``str()`` of a nested value
    costs its full expanded size, which for a shared alias structure is unbounded).

    Examples
    --------
    >>> short_repr("abc"), short_repr(5)
    ("'abc'", '5')
    >>> short_repr(list(range(1000)))
    '[0, 1, 2, ...]'
    """
    text = _SHORT.repr(value)
    return text if len(text) <= width else text[: width - 3] + "..."
