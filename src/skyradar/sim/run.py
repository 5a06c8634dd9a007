"""Deprecated alias (renamed in issue 16; removed in the next release).

Now: :mod:`skyradar.sim.scenario_frames`, :mod:`skyradar.sim.simulate_store`, :mod:`skyradar.sim.fingerprint`.
"""

import importlib
import warnings

from skyradar.sim.fingerprint import *  # noqa: F403
from skyradar.sim.scenario_frames import *  # noqa: F403
from skyradar.sim.simulate_store import *  # noqa: F403

_NEW = (
    "skyradar.sim.scenario_frames",
    "skyradar.sim.simulate_store",
    "skyradar.sim.fingerprint",
)
warnings.warn(
    "skyradar.sim.run is deprecated; use skyradar.sim.scenario_frames, .simulate_store or .fingerprint",
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
