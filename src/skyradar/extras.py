"""Optional extras: heavy dependencies only some commands need, and one clear error when one is missing.

``pip install skyradar`` installs what every command needs; ``skyradar[geo]`` (GeoTIFF DEMs, OSM maps),
``skyradar[web]`` (``skyradar serve``), ``skyradar[dask]`` (``--workers`` / ``--scheduler``),
``skyradar[flights]`` (the recorded flights the ``traffic`` package ships) and ``skyradar[bluesky]``
(the BlueSky traffic simulator, :mod:`skyradar.integrations.bluesky`) add the rest, ``skyradar[all]``
everything. Every import of an extra's module goes through :func:`import_extra`
(or :func:`require_extra` before a command starts), so a missing one is a single line naming the extra,
exit code 2, never a traceback.
"""

from __future__ import annotations

import importlib
from types import ModuleType

from skyradar.errors import InputError

__all__ = ["EXTRAS", "MissingExtraError", "import_extra", "require_extra"]

# The top-level modules each extra provides (pyproject.toml [project.optional-dependencies]).
EXTRAS: dict[str, tuple[str, ...]] = {
    "geo": ("rasterio", "pyrosm", "geopandas", "shapely"),
    "web": ("fastapi", "uvicorn", "websockets"),
    "dask": ("distributed",),
    "flights": ("traffic",),
    "bluesky": ("bluesky",),
}


class MissingExtraError(InputError):
    """A command needs an optional extra that is not installed.

    An :class:`~skyradar.errors.InputError`, so the CLI reports it in one line with exit code 2.

    Examples
    --------
    >>> try:
    ...     import_extra("no_such_module_xyz", "geo", "reading dem.tif")
    ... except InputError as exc:
    ...     print(type(exc).__name__, exc)
    MissingExtraError reading dem.tif needs the optional 'geo' extra: pip install 'skyradar[geo]'
    """


def _message(what: str, extra: str) -> str:
    return f"{what} needs the optional '{extra}' extra: pip install 'skyradar[{extra}]'"


def import_extra(module: str, extra: str, what: str) -> ModuleType:
    """``importlib.import_module(module)``, or :class:`MissingExtraError` naming ``extra`` and ``what``.

    Parameters
    ----------
    module : str
        The module to import (e.g. ``"rasterio.warp"``).
    extra : str
        The extra that provides it: a key of :data:`EXTRAS`.
    what : str
        What needs it, as the user sees it (``"skyradar serve"``, ``"reading dem.tif"``).

    Examples
    --------
    >>> import_extra("json", "web", "skyradar serve").__name__
    'json'
    >>> import_extra("no_such_module_xyz", "web", "skyradar serve")
    Traceback (most recent call last):
    ...
    skyradar.extras.MissingExtraError: ... needs the optional 'web' extra: pip install 'skyradar[web]'
    """
    if extra not in EXTRAS:
        raise ValueError(f"unknown extra {extra!r}; known: {', '.join(EXTRAS)}")
    try:
        return importlib.import_module(module)
    except ImportError:
        raise MissingExtraError(_message(what, extra)) from None


def require_extra(extra: str, what: str) -> None:
    """Import every module of ``extra`` now, so a command fails before any work if one is missing.

    Examples
    --------
    >>> require_extra("dask", "skyradar simulate --workers 2")
    """
    for module in EXTRAS[extra]:
        import_extra(module, extra, what)
