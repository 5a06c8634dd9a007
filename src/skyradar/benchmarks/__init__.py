"""Speed benchmarks: each measures our code and a baseline in the same run and returns a dict.

Each ``skyradar bench NAME`` runs one module's entry point and prints its dict (``--json``: as
JSON). The benchmarks, the public modules of this package (none is imported with the package):

- :mod:`.sim` (``run``: the image-domain simulator), :mod:`.flight` (``run``: a whole flight on
  Dask, 1 against 2 workers, and memory) and :mod:`.range_doppler` (``run``: ADC cube to
  range-Doppler, ``bench chain``);
- :mod:`.process` (``run``: detection and direction of arrival, with :mod:`.process_clutter`'s
  ``run_suppressed`` and :mod:`.process_adaptive`'s ``run_adaptive`` for clutter suppression) and
  :mod:`.realtime` (``run_realtime``: three heads fed at their frame rate on one core);
- :mod:`.track` (``run``: the tracker), :mod:`.alert` (``run``: alerting),
  :mod:`.flight_state` (``run``: ``bench state``), :mod:`.gpscheck` (``run``) and
  :mod:`.passive` (``run``).

``bench encounter`` is :mod:`skyradar.experiments.encounter_cost`.
"""

__all__ = [
    "sim",
    "flight",
    "range_doppler",
    "process",
    "process_clutter",
    "process_adaptive",
    "realtime",
    "track",
    "alert",
    "flight_state",
    "gpscheck",
    "passive",
]
