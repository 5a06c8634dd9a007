"""skyradar: airborne FMCW radar for General Aviation detect-and-avoid.

The pipeline, one subpackage per stage::

    scene -> sim -> process -> track -> daa
                    process -> nav (own-ship height and velocity over the terrain)
    scene (map) -> sim (side-looking) -> nav.gpscheck (GPS check against the map, seed-brief.md ch6)
    io (SigMF IQ) -> passive (passive radar with an ATC radar as illuminator, ch7)
"""

from skyradar.antenna import AntennaPattern
from skyradar.config import Mount, RadarConfig
from skyradar.errors import InputError

__all__ = ["AntennaPattern", "InputError", "Mount", "RadarConfig"]
__version__ = "0.1.0"
