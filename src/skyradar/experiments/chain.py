"""Deprecated alias (renamed in issue 16; removed in the next release).

Now: :mod:`skyradar.experiments.daa_chain`.
"""

from skyradar.deprecation import alias_getattr
from skyradar.experiments.daa_chain import *  # noqa: F403

__getattr__ = alias_getattr("skyradar.experiments.chain", ("skyradar.experiments.daa_chain",))
