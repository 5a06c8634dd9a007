"""Deprecated alias (renamed in issue 16; removed in the next release).

Now: :mod:`skyradar.track.track_table`.
"""

from skyradar.deprecation import alias_getattr
from skyradar.track.track_table import *  # noqa: F403

__getattr__ = alias_getattr("skyradar.track.run", ("skyradar.track.track_table",))
