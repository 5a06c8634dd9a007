"""Live traffic display (FastAPI + WebSocket + static page), the ``web`` extra (``skyradar serve``).

The names users call, importable from here (each is imported from its module on first use, so
``import skyradar.web`` needs neither the extra nor its time):

- :func:`~.server.create_app` (the display of one run) and :func:`~.server.serve_in_thread`;
- :class:`~.source.RunSource`, a run and its traffic re-read as the run grows;
- :func:`~.sample.write_sample_run`, a small synthetic run to try the display on.

Modules: :mod:`.server`, :mod:`.source`, :mod:`.net` (loopback and same-origin safety) and
:mod:`.sample`; the page itself is ``static/``.
"""

from __future__ import annotations

from skyradar.lazy_exports import lazy_exports

# Each public name by the module it lives in, imported on first use (PEP 562).
_EXPORTS = {
    "server": ("create_app", "serve_in_thread"),
    "source": ("RunSource",),
    "sample": ("write_sample_run",),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
