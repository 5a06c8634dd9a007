"""skyradar: airborne FMCW radar for General Aviation detect-and-avoid.

The pipeline, one subpackage per stage::

    scene -> sim -> process -> track -> daa
                    process -> nav (own-ship height and velocity over the terrain)
    scene (map) -> sim (side-looking) -> nav.gpscheck (GPS check against the map, Maas 2022, ch. 6)
    io (SigMF IQ) -> passive (passive radar with an ATC radar as illuminator, ch7)
"""

import os

# numba's OpenMP threads (libgomp) spin 300,000 times at every barrier before they sleep. A frame
# crosses about six parallel regions; on a machine shared with other jobs (load 4 on 2 cores) a
# spinning thread keeps the core from the thread it waits for: two threads then took 70 CPU-ms and
# 104 ms a frame of the bench's fine_psf scene against 37 CPU-ms and 57 ms with a short spin. Read
# once, when the first parallel kernel loads libgomp; a value the user set is kept.
os.environ.setdefault("GOMP_SPINCOUNT", "10000")

from skyradar.antenna import AntennaPattern
from skyradar.config import Mount, RadarConfig
from skyradar.errors import InputError

__all__ = ["AntennaPattern", "InputError", "Mount", "RadarConfig"]
__version__ = "0.1.0"
