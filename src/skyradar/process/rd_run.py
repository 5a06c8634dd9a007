"""Deprecated alias (renamed in issue 16; removed in the next release).

Now: :mod:`skyradar.process.rd_store`.
"""

from skyradar.deprecation import alias_getattr
from skyradar.process.rd_store import *  # noqa: F403

__getattr__ = alias_getattr("skyradar.process.rd_run", ("skyradar.process.rd_store",))
