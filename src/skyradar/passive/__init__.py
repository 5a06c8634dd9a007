"""Passive bistatic radar with a rotating ATC primary radar as illuminator (Maas 2022, ch. 7).

Illuminator model, scene and IQ recording simulator (:mod:`.illuminator`, :mod:`.scene`,
:mod:`.simulate`, :mod:`.truth`, :mod:`.budget`); the processor beside them: pulses
(:mod:`.pulses`, :mod:`.profiles`), matched filter (:mod:`.matched_filter`), MTI (:mod:`.mti`), CFAR
(:mod:`.cfar`, :mod:`.dwell`), bistatic localisation (:mod:`.bistatic`) and the whole recording
(:mod:`.pipeline`). Layer 3: imports only errors, units, geo, config, io and scene.

The names users call, importable from here (each is imported from its module on first use, so
``import skyradar.passive`` stays cheap):

- :func:`~.pipeline.process_recording` with its :class:`~.pipeline.PassiveSettings`: a recording in,
  detections out (``skyradar passive``);
- :func:`~.simulate.simulate_recording`, :func:`~.scene.thesis_scene` and
  :class:`~.scene.PassiveScene` (``skyradar simulate-passive``); :class:`~.illuminator.Illuminator`.
"""

from __future__ import annotations

from skyradar.lazy_exports import lazy_exports

# Each public name by the module it lives in, imported on first use (PEP 562).
_EXPORTS = {
    "pipeline": ("process_recording", "PassiveSettings"),
    "simulate": ("simulate_recording",),
    "scene": ("thesis_scene", "PassiveScene"),
    "illuminator": ("Illuminator",),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
