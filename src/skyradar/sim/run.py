"""Deprecated alias (renamed in issue 16; removed in the next release).

Now: :mod:`skyradar.sim.scenario_frames`, :mod:`skyradar.sim.simulate_store`, :mod:`skyradar.sim.fingerprint`.
"""

from skyradar.deprecation import alias_getattr
from skyradar.sim.fingerprint import *  # noqa: F403
from skyradar.sim.scenario_frames import *  # noqa: F403
from skyradar.sim.simulate_store import *  # noqa: F403

__getattr__ = alias_getattr(
    "skyradar.sim.run",
    (
        "skyradar.sim.scenario_frames",
        "skyradar.sim.simulate_store",
        "skyradar.sim.fingerprint",
    ),
)
