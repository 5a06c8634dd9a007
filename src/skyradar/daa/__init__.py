"""Detect and avoid: conflict detection, alert levels and resolution advice.

The names users call, importable from here (each is imported from its module on first use, so
``import skyradar.daa`` stays cheap):

- :func:`~.pipeline.alerts_for_run` and :func:`~.pipeline.alerts_from_tracks`: tracks and own-ship
  state in, an alerts table out (``skyradar alert``); :func:`~.pipeline.alert_summary`;
- :class:`~.alerting.AlertConfig` and its two named settings, ``RADAR_ALERT_CONFIG`` (every DAA result
  of the docs) and ``DO365B_ALERT_CONFIG`` (DAIDALUS' DO-365B non-cooperative alerter);
- :class:`~.conflict.WellClearVolume`, :func:`~.conflict.cpa` and
  :func:`~.advice.resolution_advice`.

Modules: :mod:`.conflict` (closest approach, well clear), :mod:`.alerting` (levels, persistence),
:mod:`.alert_config` (settings by name or file), :mod:`.advice` (bands, the preferred manoeuvre),
:mod:`.range_miss`, :mod:`.range_only` (alerting a track without a position),
:mod:`.lost_tracks`; tables (:mod:`.pipeline`, :mod:`.tables`,
:mod:`.run_tables`, :mod:`.provenance`).
"""

from __future__ import annotations

from skyradar.lazy_exports import lazy_exports

# Each public name by the module it lives in, imported on first use (PEP 562).
_EXPORTS = {
    "pipeline": ("alerts_for_run", "alerts_from_tracks", "alert_summary"),
    "alerting": ("AlertConfig", "RADAR_ALERT_CONFIG", "DO365B_ALERT_CONFIG"),
    "conflict": ("WellClearVolume", "cpa"),
    "advice": ("resolution_advice",),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
