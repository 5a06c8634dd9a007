"""Own-ship navigation from radar: flight state over the terrain, GPS check against the map."""
