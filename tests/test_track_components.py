"""The tracker's roles are typed interfaces: the shipped parts fill them, and parts of one's own
plug in and are used."""

from __future__ import annotations

import numpy as np

from skyradar.track.association import associate
from skyradar.track.components import Associator, Deleter, Initiator, Predictor, Reacquirer, Updater
from skyradar.track.deletion import MissDeleter
from skyradar.track.initiation import MOfN
from skyradar.track.kalman import predict, update
from skyradar.track.models import radar_model
from skyradar.track.reacquisition import LostTracks
from skyradar.track.tracker import RangeDopplerTracker

MODEL = radar_model(78.3)


def _frames(gap: tuple[int, ...] = ()) -> list[tuple[float, np.ndarray]]:
    """A target closing at 50 m/s from 1 km, 10 frames/s; no detection on the frames in ``gap``."""
    return [
        (0.1 * k, np.zeros((0, 2)) if k in gap else np.array([[1000.0 - 5.0 * k, -50.0 + 78.3]]))
        for k in range(30)
    ]


def _ids(tracker: RangeDopplerTracker, frames) -> list[list[int]]:
    return [tracker.step(t, z).track_id.tolist() for t, z in frames]


def test_the_shipped_parts_fill_the_roles_and_an_object_without_the_methods_does_not():
    assert isinstance(associate, Associator)
    assert isinstance(predict, Predictor) and isinstance(update, Updater)
    assert isinstance(MOfN(4, 5), Initiator)
    assert isinstance(MissDeleter(), Deleter)
    assert isinstance(LostTracks(MODEL, 8.0, 1.5, 16.0, 13.0), Reacquirer)
    assert not isinstance(object(), Deleter) and not isinstance(object(), Initiator)


def test_a_deleter_of_ones_own_closes_the_track_the_default_coasts():
    class OneMiss:
        """Closes a track on its first missed frame."""

        max_coast_s = 2.0

        def delete(self, misses: np.ndarray, time_since_update_s: np.ndarray) -> np.ndarray:
            return np.asarray(misses) >= 1

    frames = _frames(gap=(15,))  # one frame without the target's detection
    coasting = _ids(RangeDopplerTracker(MODEL), frames)
    assert coasting[14] == coasting[15] == coasting[16] == [0]  # the default coasts through the gap
    impatient = _ids(RangeDopplerTracker(MODEL, deleter=OneMiss()), frames)
    assert impatient[14] == [0] and 0 not in impatient[15]  # closed at the first miss


def test_an_associator_of_ones_own_is_called_with_the_frame_and_its_answer_used():
    calls = []

    def counting(*args, **kwargs):
        calls.append(len(args[2]))  # the frame's detections
        return associate(*args, **kwargs)

    frames = _frames()
    assert _ids(RangeDopplerTracker(MODEL, associator=counting), frames) == _ids(
        RangeDopplerTracker(MODEL), frames
    )
    assert calls and set(calls) == {1}


def _states(tracker: RangeDopplerTracker, frames) -> list[np.ndarray]:
    return [tracker.step(t, z).state.copy() for t, z in frames]


def test_a_predictor_and_an_updater_of_ones_own_are_called_and_their_answers_used():
    """Wrappers that hand the shipped Kalman step's answers back give the default tracker's states
    exactly; the same wrappers changing the answers change the states."""
    frames = _frames(gap=(15,))
    calls = {"predict": 0, "update": 0}

    def counting_predict(x, P, F, Q):
        calls["predict"] += 1
        return predict(x, P, F, Q)

    def counting_update(x, P, y, H, R, S=None):
        calls["update"] += 1
        return update(x, P, y, H, R, S)

    default = _states(RangeDopplerTracker(MODEL), frames)
    wrapped = _states(RangeDopplerTracker(MODEL, predictor=counting_predict, updater=counting_update), frames)
    assert calls["predict"] >= 28 and calls["update"] >= 28  # every frame after the first has a track
    assert len(wrapped) == len(default)
    for a, b in zip(wrapped, default, strict=True):
        np.testing.assert_array_equal(a, b)

    def frozen_update(x, P, y, H, R, S=None):
        """Ignores every measurement: the tracks coast on their first state."""
        return x, P

    coasted = _states(RangeDopplerTracker(MODEL, updater=frozen_update), frames)
    assert any(a.shape == b.shape and not np.array_equal(a, b) for a, b in zip(coasted, default, strict=True))
