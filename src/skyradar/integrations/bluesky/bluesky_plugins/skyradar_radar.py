"""skyradar: radar-equipped aircraft see the traffic through skyradar's radar tracks.

BlueSky finds this file in its plugin folders and loads it with ``PLUGIN LOAD SKYRADAR``; the
plugin itself is :mod:`skyradar.integrations.bluesky.plugin`. BlueSky reads the plugin's name and
type from the literal dictionary below before it imports the file.
"""

from importlib import import_module

_skyradar = import_module("skyradar.integrations.bluesky.plugin")


def init_plugin():
    """Install the plugin (its gates, hooks and stack commands); BlueSky's plugin configuration."""
    config = {"plugin_name": "SKYRADAR", "plugin_type": "sim"}
    config.update(_skyradar.install())
    return config
