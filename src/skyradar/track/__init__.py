"""Multi-target tracking in range-Doppler and 3-D, with swappable parts, and track metrics.

The names users call, importable from here (each is imported from its module on first use, so
``import skyradar.track`` stays cheap):

- :func:`~.track_table.track_detections`, :func:`~.track_table.track_air_detections`: a detections
  table in, a tracks table out (``skyradar track``);
- :class:`~.tracker.RangeDopplerTracker` with its :class:`~.tracker.TrackerConfig` and the motion
  models :func:`~.models.radar_model` and :func:`~.models.traditional_model`; the roles it is
  composed of, for parts of one's own (:mod:`.components`): :class:`~.components.Predictor`,
  :class:`~.components.Associator`, :class:`~.components.Updater`, :class:`~.components.Initiator`,
  :class:`~.components.Deleter` and :class:`~.components.Reacquirer`; the live tracks it holds,
  :class:`~.types.TrackArrays`, and what a frame returns, :class:`~.types.FrameTracks`;
  :class:`~.range_walk.RangeWalks` with its :class:`~.range_walk.RangeWalkRule`, which confirms a
  fast closure by its range history;
  :class:`~.tracker3d.Tracker3D`, the 3-D filter on direction-of-arrival positions;
- :func:`~.io.read_detections` and :func:`~.simulated_detections.synthetic_detections`, detections
  from a file or from truth;
- :func:`~.evaluate.evaluate_run` (``skyradar evaluate``) and :func:`~.metrics.track_metrics`.

Modules: the tracker (:mod:`.tracker`, :mod:`.types`, :mod:`.components`, :mod:`.models`,
:mod:`.kalman`, :mod:`.association`, :mod:`.initiation`, :mod:`.range_walk`, :mod:`.deletion`,
:mod:`.dealias`, :mod:`.reacquisition`, :mod:`.reacquired_ids`); 3-D tracks (:mod:`.tracker3d`,
:mod:`.measure3d`, :mod:`.doa_feed`, :mod:`.elevation_trust`); several heads (:mod:`.fusion`); the ground
(:mod:`.ground_tracks`, :mod:`.ground_doa`, :mod:`.static_point`); tables in and out
(:mod:`.track_table`, :mod:`.io`, :mod:`.frame_grid`, :mod:`.simulated_detections`); scoring
(:mod:`.evaluate`, :mod:`.detectable`, :mod:`.metrics`).
"""

from __future__ import annotations

from skyradar.lazy_exports import lazy_exports

# Each public name by the module it lives in, imported on first use (PEP 562).
_EXPORTS = {
    "track_table": ("track_detections", "track_air_detections"),
    "tracker": ("RangeDopplerTracker", "TrackerConfig"),
    "range_walk": ("RangeWalks", "RangeWalkRule"),
    "models": ("radar_model", "traditional_model"),
    "components": ("Predictor", "Associator", "Updater", "Initiator", "Deleter", "Reacquirer"),
    "types": ("TrackArrays", "FrameTracks"),
    "tracker3d": ("Tracker3D",),
    "io": ("read_detections",),
    "simulated_detections": ("synthetic_detections",),
    "evaluate": ("evaluate_run",),
    "metrics": ("track_metrics",),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
