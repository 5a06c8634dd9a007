"""The folder BlueSky searches for the skyradar plugin (:data:`skyradar.integrations.bluesky.PLUGIN_DIR`)."""
