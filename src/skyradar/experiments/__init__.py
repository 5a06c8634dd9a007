"""Experiments that reproduce the thesis' chapters 2 to 7 (Maas 2022), and the DAA evaluation.

``encounters`` scores the whole chain on an encounter set and ``demo`` (in :mod:`skyradar.demo`)
flies one scenario end to end. ch6 is the GPS check against a map, ch7 the passive radar.

Each experiment module's ``run(out_dir, ...) -> dict`` writes its figures (PNG), its table and
``summary.md`` (the run in sentences and a table of its headline values, laid out by
:mod:`.summary_md`), and returns the measured values that ``skyradar experiment NAME --json``
prints. The experiments, the public modules of this package (``from skyradar.experiments import
ch2``; none is imported with the package):

- :mod:`.ch2` (simulator against closed form), with no helper module;
- :mod:`.ch3` (detection and direction of arrival from the ground), with :mod:`.ch3_scene` and
  :mod:`.ch3_figures`;
- :mod:`.ch4` (radar-aware against traditional tracking), with :mod:`.ch4_flights` and
  :mod:`.ch4_figures`;
- :mod:`.ch5` (flight state over terrain), with :mod:`.ch5_flight` and :mod:`.ch5_report`;
- :mod:`.ch6` (the GPS check), with :mod:`.ch6_flight` and :mod:`.ch6_report`;
- :mod:`.ch7` (passive radar), with :mod:`.ch7_score` and :mod:`.ch7_figures`;
- :mod:`.clutter` (knowledge-aided clutter suppression), with :mod:`.clutter_scene` and
  :mod:`.clutter_report`;
- :mod:`.encounters` (the DAA encounter set), with :mod:`.encounter_set`, :mod:`.encounter_terrain`,
  :mod:`.encounter_real`, :mod:`.encounter_chain`, :mod:`.encounter_score`,
  :mod:`.encounter_report`, :mod:`.sensor_figures` and :mod:`.encounter_cost` (``bench encounter``);
- :mod:`.closed_loop` (the encounter set flown closed-loop: the pilot follows the advice);
- :mod:`.arrays` (receive arrays x terrains on the same encounters, through :mod:`.encounters`, with
  each array's minimum detectable velocity, DoA error against its bound and frames per second),
  with :mod:`.arrays_report`;
- :mod:`.bluesky_compare` (BlueSky's perfect-state conflict detection against the radar's, through
  the plugin of :mod:`skyradar.integrations.bluesky`).

:mod:`.ground_scenes` scores the ground filter on named scenes over flat ground, hills and Jacksboro;
:mod:`.readme_results` writes the README's results table from the measured JSON in docs/results/.
"""

__all__ = [
    "ch2",
    "ch3",
    "ch4",
    "ch5",
    "ch6",
    "ch7",
    "clutter",
    "encounters",
    "closed_loop",
    "arrays",
    "bluesky_compare",
]
