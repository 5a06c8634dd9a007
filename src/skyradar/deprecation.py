"""Deprecated module aliases: an old import path that keeps working, with a warning, for one release.

Examples
--------
>>> import warnings
>>> with warnings.catch_warnings(record=True) as caught:
...     warnings.simplefilter("always")
...     getattr_ = alias_getattr("skyradar.old_units", ("skyradar.units",))
>>> caught[0].category.__name__, getattr_("nearest_bin").__name__
('DeprecationWarning', 'nearest_bin')
"""

from __future__ import annotations

import importlib
import warnings
from collections.abc import Callable

__all__ = ["alias_getattr"]


def alias_getattr(old: str, new: tuple[str, ...]) -> Callable[[str], object]:
    """Warn that module ``old`` is deprecated and return its module ``__getattr__``.

    The returned function resolves any name, private ones included (the old module had them and
    scripts may use them), from the first of the ``new`` modules that defines it.
    """
    warnings.warn(f"{old} is deprecated; import from {' or '.join(new)}", DeprecationWarning, stacklevel=3)

    def __getattr__(name: str) -> object:
        for module in new:
            value = getattr(importlib.import_module(module), name, __getattr__)
            if value is not __getattr__:
                return value
        raise AttributeError(f"module {old!r} has no attribute {name!r}")

    return __getattr__
