"""Deprecated alias of :mod:`skyradar.parallel` (the generic Dask helper moved there in issue 16).

Kept for one release so code outside the package that imported ``skyradar.sim.cluster`` keeps working.
"""

import warnings

from skyradar.parallel import *  # noqa: F403
from skyradar.parallel import __all__  # noqa: F401

warnings.warn(
    "skyradar.sim.cluster is deprecated: import skyradar.parallel instead",
    DeprecationWarning,
    stacklevel=2,
)
