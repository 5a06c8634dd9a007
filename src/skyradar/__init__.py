"""skyradar: airborne FMCW radar for General Aviation detect-and-avoid.

The pipeline, one subpackage per stage::

    scene -> sim -> process -> track -> daa
                    process -> nav (flight state, GPS check)
    passive (ATC radar as illuminator)
"""

from skyradar.antenna import AntennaPattern
from skyradar.config import Mount, RadarConfig
from skyradar.errors import InputError

__all__ = ["AntennaPattern", "InputError", "Mount", "RadarConfig"]
__version__ = "0.1.0"
