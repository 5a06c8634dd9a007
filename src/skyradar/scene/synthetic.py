"""Deprecated alias (renamed in issue 16; removed in the next release).

Now: :mod:`skyradar.scene.synthetic_terrain`.
"""

from skyradar.deprecation import alias_getattr
from skyradar.scene.synthetic_terrain import *  # noqa: F403

__getattr__ = alias_getattr("skyradar.scene.synthetic", ("skyradar.scene.synthetic_terrain",))
