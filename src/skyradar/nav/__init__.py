"""Own-ship navigation from radar: flight state (height and velocity) over the terrain.

The GPS check against a map (seed-brief.md ch6) is not built.
"""
