"""Deprecated alias (renamed in issue 16; removed in the next release).

Now: :mod:`skyradar.track.simulated_detections`.
"""

from skyradar.deprecation import alias_getattr
from skyradar.track.simulated_detections import *  # noqa: F403

__getattr__ = alias_getattr("skyradar.track.synthetic", ("skyradar.track.simulated_detections",))
