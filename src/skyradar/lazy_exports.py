"""Public names of a package imported on first use (PEP 562), so importing the package stays cheap.

A package's ``__init__`` names, module by module, the functions users call; the first access to one
imports its module and keeps the name as a plain attribute of the package from then on.

Examples
--------
>>> names, getattr_, dir_ = lazy_exports("skyradar", {"units": ("wrap",)})
>>> names, getattr_("wrap").__name__, "wrap" in dir_()
(['wrap'], 'wrap', True)
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from importlib import import_module
from typing import Any

__all__ = ["lazy_exports"]


def lazy_exports(
    package: str, exports: dict[str, tuple[str, ...]]
) -> tuple[list[str], Callable[[str], Any], Callable[[], list[str]]]:
    """``__all__``, ``__getattr__`` and ``__dir__`` of ``package`` re-exporting ``exports``.

    Parameters
    ----------
    package : str
        The package's dotted name (its ``__name__``).
    exports : dict
        Module name inside the package -> the public names it gives the package.

    Returns
    -------
    names, getattr, dir
        The names in order, and the two module-level functions of PEP 562.

    Examples
    --------
    The name resolves to the module's object; an unknown name is an :class:`AttributeError`, as for
    any module (here on the standard library's ``json``, which already holds the name):

    >>> import json
    >>> names, getattr_, dir_ = lazy_exports("json", {"decoder": ("JSONDecodeError",)})
    >>> getattr_("JSONDecodeError") is json.decoder.JSONDecodeError, "JSONDecodeError" in dir_()
    (True, True)
    >>> getattr_("no_such_name")
    Traceback (most recent call last):
    ...
    AttributeError: module 'json' has no attribute 'no_such_name'
    """
    names = [name for module_names in exports.values() for name in module_names]
    home = {name: module for module, module_names in exports.items() for name in module_names}

    def __getattr__(name: str) -> Any:
        if name not in home:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(import_module(f"{package}.{home[name]}"), name)
        setattr(sys.modules[package], name, value)  # imported once; a plain attribute from then on
        return value

    def __dir__() -> list[str]:
        return sorted({*vars(sys.modules[package]), *names})

    return names, __getattr__, __dir__
