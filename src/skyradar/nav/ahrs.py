"""Deprecated alias (moved in issue 13 beside the GNSS errors; removed in the next release).

Now: :mod:`skyradar.sim.navigation` (the one home of the navigation error models).
"""

from skyradar.deprecation import alias_getattr
from skyradar.sim.navigation import *  # noqa: F403

__getattr__ = alias_getattr("skyradar.nav.ahrs", ("skyradar.sim.navigation",))
