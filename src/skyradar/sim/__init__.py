"""Radar simulators: image domain (fast) and chirp-level raw ADC, plus hardware impairments.

The names users call, importable from here (each is imported from its module on first use, so
``import skyradar.sim`` stays cheap; the compiled kernels load with the simulator):

- :func:`~.simulate_store.simulate_to_zarr`: a built scenario into a frames store, chunk by chunk,
  resumable (``skyradar simulate``); :func:`~.scenario_frames.simulate_frames` and
  :func:`~.scenario_frames.make_simulator` for frames in memory;
- :class:`~.image.ImageSimulator`, the image-domain simulator of one radar head;
- :func:`~.raw.simulate_adc`, the de-chirped ADC cube of one frame;
- :func:`~.impairments.apply_impairments`, the hardware impairments of real frames.

Modules: the image-domain simulator (:mod:`.image`, :mod:`.geometry`, :mod:`.targets`,
:mod:`.facets`, :mod:`.horizon`, :mod:`.psf`); runs of a scenario (:mod:`.scenario_frames`,
:mod:`.simulate_store`, :mod:`.sweep`, :mod:`.fingerprint`, :mod:`.navigation`); the raw chain
(:mod:`.raw`); impairments (:mod:`.impairments`, :mod:`.impairment_signals`); the side-looking
radar over a map (:mod:`.land_cover_scene`).
"""

from __future__ import annotations

from skyradar.lazy_exports import lazy_exports

# Each public name by the module it lives in, imported on first use (PEP 562).
_EXPORTS = {
    "simulate_store": ("simulate_to_zarr",),
    "scenario_frames": ("simulate_frames", "make_simulator"),
    "image": ("ImageSimulator",),
    "raw": ("simulate_adc",),
    "impairments": ("apply_impairments",),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
