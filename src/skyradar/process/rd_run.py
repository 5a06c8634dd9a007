"""Deprecated alias (renamed in issue 16; removed in the next release).

Now: :mod:`skyradar.process.rd_store`.
"""

import importlib
import warnings

from skyradar.process.rd_store import *  # noqa: F403

_NEW = ("skyradar.process.rd_store",)
warnings.warn(
    "skyradar.process.rd_run is deprecated; import from skyradar.process.rd_store",
    DeprecationWarning,
    stacklevel=2,
)


def __getattr__(name: str):
    # Private names too, as the old module had them (tests and scripts may use them).
    for module in _NEW:
        value = getattr(importlib.import_module(module), name, _NEW)
        if value is not _NEW:
            return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
