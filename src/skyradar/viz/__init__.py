"""Matplotlib figures (headless Agg backend).

The names users call, importable from here (each is imported from its module on first use, so
``import skyradar.viz`` does not load matplotlib):

- :func:`~.rangedoppler.save_frame_figure`, :func:`~.rangedoppler.plot_strength` and
  :func:`~.rangedoppler.plot_phase_difference`: range-Doppler frames (:mod:`.rangedoppler`);
- :func:`~.flight.flight_fit_figure`: a recorded flight's flyable path against its fixes
  (:mod:`.flight`, ``skyradar flight --figure``);
- :func:`~.report.write_report`: the figures and page of the demo (:mod:`.report`).
"""

from __future__ import annotations

from skyradar.lazy_exports import lazy_exports

# Each public name by the module it lives in, imported on first use (PEP 562).
_EXPORTS = {
    "rangedoppler": ("save_frame_figure", "plot_strength", "plot_phase_difference"),
    "flight": ("flight_fit_figure",),
    "report": ("write_report",),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
