"""Every public function and class of the library shows a runnable example in its docstring.

The examples run as doctests (``--doctest-modules``), so a user reading one reads code that works.
Protocols (the tracker's roles) describe an interface, not a call; the entry points below run a whole
simulated run, a Dask cluster or BlueSky, too slow or too heavy for an example: they are shown in the
guides and exercised by the tests instead.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil

import skyradar

WHOLE_RUN_ENTRY_POINTS = {
    "skyradar.chain.run_chain",
    "skyradar.chain.track_and_alert",
    "skyradar.closed_loop.fly_radar",
    "skyradar.demo.run_chain",
    "skyradar.demo.run_demo",
    "skyradar.integrations.bluesky.plugin.install",
    "skyradar.integrations.bluesky.runner.BlueSkyRun",
    "skyradar.integrations.bluesky.runner.run_scenario",
    "skyradar.parallel.connect",
    "skyradar.parallel.map_chunks",
    "skyradar.passive.pipeline.PassiveResult",
    "skyradar.passive.pipeline.process_recording",
    "skyradar.process.clutter_frames.detect_suppressed",
    "skyradar.process.detect_run.detect_run",
    "skyradar.process.detect_run.detect_run_heads",
    "skyradar.process.pipeline.clutter_anchors",
    "skyradar.process.pipeline.process_chunk",
    "skyradar.process.pipeline.process_frames",
    "skyradar.process.rd_store.recording_to_frames",
    "skyradar.sim.simulate_store.simulate_to_zarr",
    "skyradar.track.doa_feed.Measure3D",
    "skyradar.track.evaluate.evaluate_run",
    "skyradar.track.io.truth_from_frames",
    "skyradar.viz.report.write_report",
}


def _public_library_objects():
    """(dotted name, object) of every function and class a library module lists in ``__all__``."""
    for info in pkgutil.walk_packages(skyradar.__path__, "skyradar."):
        parts = info.name.split(".")[1:]
        if any(p.startswith("_") for p in parts) or parts[0] in ("experiments", "benchmarks", "cli"):
            continue
        module = importlib.import_module(info.name)
        for name in getattr(module, "__all__", ()):
            obj = getattr(module, name, None)
            if (inspect.isfunction(obj) or inspect.isclass(obj)) and obj.__module__ == info.name:
                yield f"{info.name}.{name}", obj


def test_every_public_function_and_class_has_a_runnable_example():
    objects = dict(_public_library_objects())
    assert len(objects) > 500  # the walk found the library
    missing = [
        name
        for name, obj in objects.items()
        if ">>>" not in (inspect.getdoc(obj) or "")
        and not getattr(obj, "_is_protocol", False)
        and name not in WHOLE_RUN_ENTRY_POINTS
    ]
    assert not missing, "no Examples section: " + ", ".join(missing)
    stale = sorted(WHOLE_RUN_ENTRY_POINTS - objects.keys())
    assert not stale, f"listed but not public: {stale}"
