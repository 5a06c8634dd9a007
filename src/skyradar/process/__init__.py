"""Frame processing: range-Doppler, spur maps, detection, direction of arrival, ground filter.

The names users call, importable from here (each is imported from its module on first use, so
``import skyradar.process`` stays cheap):

- :func:`~.pipeline.process_frames` and :func:`~.pipeline.process_cube`: frames in, detections with
  their 3-D direction and ground flag out (``skyradar process`` runs them over a store);
- :func:`~.rd_store.recording_to_frames` (``skyradar rd``), :func:`~.rangedoppler.range_doppler` and
  :class:`~.rangedoppler.RangeDopplerProcessor`: ADC cubes to range-Doppler frames;
- :class:`~.detect.Detections`, :func:`~.detect.integrate_channels`; :func:`~.doa.estimate_directions`
  and :func:`~.doa.doa_crlb`;
- :class:`~.spurs.SpurMap`, :func:`~.spurs.learn_spur_map` (``skyradar spur-map``) and
  :func:`~.calibration.calibrate_from_frames` (``skyradar calibrate``);
- :func:`~.clutter_suppress.suppress_clutter`, knowledge-aided ground clutter suppression.

Modules: range-Doppler (:mod:`.rangedoppler`, :mod:`.windows`, :mod:`.rd_store`); detection
(:mod:`.power`, :mod:`.cfar`, :mod:`.detect`, :mod:`.spurs`, :mod:`.pipeline`, :mod:`.detect_run`,
:mod:`.realtime`); direction of arrival (:mod:`.doa`, :mod:`.calibration`, :mod:`.smoothing`,
:mod:`.mimo` for time-division MIMO's virtual channels);
the ground (:mod:`.ground`, :mod:`.ground_elevation`, :mod:`.terrain_rise`); clutter suppression
(:mod:`.clutter`, :mod:`.clutter_suppress`, :mod:`.clutter_adaptive`, :mod:`.clutter_anchors`,
:mod:`.clutter_frames`, :mod:`.clutter_doa`, :mod:`.small_hermitian`, :mod:`.top_eigen`).
"""

from __future__ import annotations

from skyradar.lazy_exports import lazy_exports

# Each public name by the module it lives in, imported on first use (PEP 562).
_EXPORTS = {
    "pipeline": ("process_frames", "process_cube"),
    "rd_store": ("recording_to_frames",),
    "rangedoppler": ("range_doppler", "RangeDopplerProcessor"),
    "detect": ("Detections", "integrate_channels"),
    "doa": ("estimate_directions", "doa_crlb"),
    "spurs": ("SpurMap", "learn_spur_map"),
    "calibration": ("calibrate_from_frames",),
    "clutter_suppress": ("suppress_clutter",),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
