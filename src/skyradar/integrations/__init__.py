"""Bridges from skyradar to other tools; each is an optional extra.

:mod:`.bluesky`: skyradar's radar as the surveillance of BlueSky's conflict detection
and resolution (the ``bluesky`` extra).
"""

__all__ = ["bluesky"]
