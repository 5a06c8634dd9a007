"""Own-ship navigation from radar: flight state (height and velocity) over the terrain (ch5), and the
GPS integrity check of a side-looking radar against a map (ch6, :mod:`skyradar.nav.gpscheck`).

The names users call, importable from here (each is imported from its module on first use, so
``import skyradar.nav`` stays cheap):

- :func:`~.flight_state.estimate_run` (``skyradar state``) and :func:`~.flight_state.estimate_frame`;
- :class:`~.terrain_aware.TerrainAwareEstimator`, the estimator on 3-D ground points;
- :func:`~.ridge.extract_ridge`, the ground-return ridge of a frame, and
  :func:`~.kalman_state.filter_states`.

Modules: flight state (:mod:`.flight_state`, :mod:`.ridge`, :mod:`.inversion`, :mod:`.huber_fit`,
:mod:`.kalman_state`, :mod:`.terrain_aware`, :mod:`.radar_height`, :mod:`.state_summary`) and the GPS
check (:mod:`.gpscheck`, whose ``check.check_run`` runs ``skyradar gpscheck``).
"""

from __future__ import annotations

from skyradar.lazy_exports import lazy_exports

# Each public name by the module it lives in, imported on first use (PEP 562).
_EXPORTS = {
    "flight_state": ("estimate_run", "estimate_frame"),
    "terrain_aware": ("TerrainAwareEstimator",),
    "ridge": ("extract_ridge",),
    "kalman_state": ("filter_states",),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
