"""skyradar's radar as the surveillance of BlueSky's conflict detection and resolution (``bluesky`` extra).

For an aircraft that carries a skyradar radar, the intruder states BlueSky's conflict detection and
resolution see come from the tracks of that radar, simulated frame by frame over the scenario's
terrain from the traffic BlueSky flies; every other part of BlueSky (its traffic, stack commands and
resolution methods) is unchanged. The names users call (each imported from its module on first use):

- :class:`~.radar.AirborneRadar`, :class:`~.radar.TerrainSpec`, :class:`~.radar.TrafficState`,
  :class:`~.radar.TrackEstimate`, :func:`~.radar.check_mountable` and ``MOUNTABLE_TYPES``: one
  aircraft's radar over traffic given one state at a time (no BlueSky needed);
- :class:`~.plugin.SkyradarPlugin` (its one instance: ``skyradar.integrations.bluesky.plugin.plugin``)
  and :func:`~.plugin.install`: the BlueSky plugin (its stack commands ``SKYRADAR``,
  ``SKYRADARTERRAIN``, ``SKYRADARCFG``);
- :func:`~.runner.run_scenario`, :class:`~.runner.BlueSkyRun` and ``PLUGIN_DIR`` (the folder to put
  on BlueSky's plugin path): a scenario file run headless.

Modules: :mod:`.radar` (the radar of one aircraft), :mod:`.picture` (what an equipped aircraft's
detection sees), :mod:`.plugin` (the BlueSky plugin), :mod:`.runner` (headless runs) and
``bluesky_plugins`` (the file BlueSky's plugin loader finds).
"""

from __future__ import annotations

from skyradar.lazy_exports import lazy_exports

_EXPORTS = {
    "radar": (
        "AirborneRadar",
        "TerrainSpec",
        "TrafficState",
        "TrackEstimate",
        "check_mountable",
        "MOUNTABLE_TYPES",
    ),
    "plugin": ("SkyradarPlugin", "install"),
    "runner": ("run_scenario", "BlueSkyRun", "PLUGIN_DIR"),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
