"""Deprecated alias (renamed in issue 16; removed in the next release).

Now: :mod:`skyradar.sim.impairment_signals`.
"""

from skyradar.deprecation import alias_getattr
from skyradar.sim.impairment_signals import *  # noqa: F403

__getattr__ = alias_getattr("skyradar.sim.impairment_effects", ("skyradar.sim.impairment_signals",))
