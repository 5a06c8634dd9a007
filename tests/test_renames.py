"""Issue 16 renames: the old public names still work for one release, with a DeprecationWarning."""

import importlib
import sys

import pytest

from skyradar.config import RadarConfig

# old module -> (new module, a name both must give as the same object)
RENAMED = {
    "skyradar.sim.run": ("skyradar.sim.simulate_store", "simulate_to_zarr"),
    "skyradar.track.run": ("skyradar.track.track_table", "track_detections"),
    "skyradar.process.rd_run": ("skyradar.process.rd_store", "recording_to_frames"),
    "skyradar.scene.synthetic": ("skyradar.scene.synthetic_terrain", "fractal_terrain"),
    "skyradar.track.synthetic": ("skyradar.track.simulated_detections", "synthetic_detections"),
    "skyradar.sim.impairment_effects": ("skyradar.sim.impairment_signals", "spur_cube"),
    "skyradar.experiments.chain": ("skyradar.experiments.daa_chain", "run_chain"),
}


@pytest.mark.parametrize("old", sorted(RENAMED))
def test_old_module_path_warns_and_gives_the_new_objects(old):
    new, name = RENAMED[old]
    sys.modules.pop(old, None)  # the warning is raised at import
    with pytest.warns(DeprecationWarning, match=old.replace(".", r"\.")):
        module = importlib.import_module(old)
    assert getattr(module, name) is getattr(importlib.import_module(new), name)


def test_old_sim_run_private_names_still_resolve():
    with pytest.warns(DeprecationWarning):
        sys.modules.pop("skyradar.sim.run", None)
        run = importlib.import_module("skyradar.sim.run")
    from skyradar.sim import fingerprint, scenario_frames, simulate_store

    assert run._template is simulate_store._template
    assert run.fingerprint is fingerprint.fingerprint
    assert run.make_simulator is scenario_frames.make_simulator
    with pytest.raises(AttributeError):
        run.no_such_name  # noqa: B018


def test_seed_prototype_is_a_deprecated_alias_of_prototype_2022():
    with pytest.warns(DeprecationWarning, match="prototype_2022"):
        old = RadarConfig.seed_prototype(n_doppler=64)
    assert old == RadarConfig.prototype_2022(n_doppler=64)


def test_write_recording_old_home_is_a_deprecated_alias():
    from skyradar.io import recordings
    from skyradar.io.recording_writer import write_recording

    with pytest.warns(DeprecationWarning, match="recording_writer"):
        assert recordings.write_recording is write_recording
    with pytest.raises(AttributeError):
        recordings.no_such_name  # noqa: B018
