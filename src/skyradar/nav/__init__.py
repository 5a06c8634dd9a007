"""Own-ship navigation from radar: flight state (height and velocity) over the terrain (ch5), and the
GPS integrity check of a side-looking radar against a map (ch6, :mod:`skyradar.nav.gpscheck`).
"""
