"""The world the radar looks at: terrain, own-ship and intruder trajectories, scenario files.

The names users call, importable from here (each is imported from its module on first use, so
``import skyradar.scene`` stays cheap):

- :func:`~.scenario.load_scenario` and :class:`~.scenario.Scenario` (its ``build()`` makes the
  trajectories, terrain and radar); :func:`~.scenario.list_example_scenarios` and
  :func:`~.scenario.example_scenario`, the scenarios shipped with the package;
- :class:`~.terrain.Terrain`, :func:`~.dem_readers.read_dem`, :func:`~.synthetic_terrain.flat_terrain`
  and :func:`~.synthetic_terrain.fractal_terrain`;
- :class:`~.trajectories.Trajectory`; :func:`~.adsb.read_trajectory` and :func:`~.adsb.fit_flight`,
  recorded flights (ADS-B, GPS logs) made flyable; :func:`~.sample_flights.sample_flight`;
- :class:`~.navigation_config.NavigationConfig`, how wrong the own-ship's navigation is.

Modules: scenarios (:mod:`.scenario`, :mod:`.scenario_models`, :mod:`.scenario_sources`,
:mod:`.scenario_errors`, :mod:`.examples`, :mod:`.radar_heads`, :mod:`.navigation_config`,
:mod:`.impairment_config`); terrain (:mod:`.terrain`, :mod:`.dem_readers`, :mod:`.dem_coverage`,
:mod:`.synthetic_terrain`, :mod:`.terrain_names`); flights (:mod:`.trajectories`, :mod:`.flights`,
:mod:`.flyable`, :mod:`.adsb`, :mod:`.adsb_clean`, :mod:`.sample_flights`,
:mod:`.encounter_from_tracks`); maps for the GPS check (:mod:`.ground_grid`, :mod:`.ground_map`,
:mod:`.land_cover`, :mod:`.osm_map`, :mod:`.map_raster`, :mod:`.map_render`, :mod:`.coastline`).
"""

from __future__ import annotations

from skyradar.lazy_exports import lazy_exports

# Each public name by the module it lives in, imported on first use (PEP 562).
_EXPORTS = {
    "scenario": ("Scenario", "load_scenario", "list_example_scenarios", "example_scenario"),
    "terrain": ("Terrain",),
    "dem_readers": ("read_dem",),
    "synthetic_terrain": ("flat_terrain", "fractal_terrain"),
    "trajectories": ("Trajectory",),
    "adsb": ("read_trajectory", "fit_flight"),
    "sample_flights": ("sample_flight",),
    "navigation_config": ("NavigationConfig",),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
