"""Range-walk initiation: a fast closure seen in a fraction of its frames is confirmed by its range
history, and static clutter at the same Doppler never is (physics: a static point's range changes at
most at the own-ship's speed)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import poisson

from skyradar.track.ground_tracks import doppler_smooth
from skyradar.track.models import radar_model
from skyradar.track.range_walk import RangeWalkRule, RangeWalks
from skyradar.track.tracker import RangeDopplerTracker

WIDTH_MPS = 78.3  # the prototype's Doppler image at 9.4 frames/s
FRAME_S = 1.0 / 9.4
OWN_SPEED_MPS = 50.0


def _wrap(v: np.ndarray | float) -> np.ndarray:
    return (np.asarray(v, float) + WIDTH_MPS / 2) % WIDTH_MPS - WIDTH_MPS / 2


def _clutter(rng: np.random.Generator, n_frames: int, per_frame: int, doppler_mps: float) -> list[np.ndarray]:
    """Static ground scatterers at the target's Doppler (within a bin), their ranges moving at the
    static point's radial velocity (the cell's Doppler: it is inside the own-ship's speed); each
    frame shows a random ``per_frame`` of them, as a speckled patch does."""
    start = rng.uniform(800.0, 4000.0, 60)
    out = []
    for k in range(n_frames):
        pick = rng.choice(start.size, per_frame, replace=False)
        r = start[pick] + doppler_mps * k * FRAME_S + rng.normal(0.0, 4.0, per_frame)
        v = doppler_mps + rng.normal(0.0, 0.15, per_frame)
        out.append(np.column_stack([r, v]))
    return out


def _run(frames: list[np.ndarray], own_speed_mps: float) -> tuple[RangeDopplerTracker, list]:
    tracker = RangeDopplerTracker(radar_model(WIDTH_MPS))
    outs = [tracker.step(k * FRAME_S, z, static_speed_mps=own_speed_mps) for k, z in enumerate(frames)]
    return tracker, outs


@pytest.mark.parametrize("closing_mps", [-100.0, -113.0, -117.0])
def test_a_fast_closure_detected_in_a_third_of_its_frames_is_confirmed_by_its_range_walk(closing_mps):
    rng = np.random.default_rng(7)
    n = 60
    hit = rng.random(n) < 0.33
    frames = _clutter(rng, n, 2, float(_wrap(closing_mps)))
    for k in np.flatnonzero(hit):
        target = [
            3200.0 + closing_mps * k * FRAME_S + rng.normal(0, 4.0),
            _wrap(closing_mps) + rng.normal(0, 0.1),
        ]
        frames[k] = np.vstack([frames[k], target])
    tracker, outs = _run(frames, OWN_SPEED_MPS)
    on_target = []
    for k, out in enumerate(outs):
        expected = 3200.0 + closing_mps * k * FRAME_S
        near = out.confirmed & (np.abs(out.state[:, 0] - expected) < 60.0)
        if near.any():
            on_target.append((k, float(out.state[near, 1][0])))
    assert on_target, "the closure is never confirmed"
    first, velocity = on_target[0]
    sixth = np.flatnonzero(hit)[5]
    # Confirmed once its walk holds six frames over two seconds, within a second of that.
    assert first * FRAME_S <= max(sixth * FRAME_S, 2.0) + 1.0
    assert velocity == pytest.approx(closing_mps, abs=1.0)  # the alias resolved by the walk
    # Without the walk (no own-ship speed), 4 of 5 frames never hold at this rate.
    _, plain = _run(frames, float("nan"))
    plain_first = [k for k, out in enumerate(plain) if (out.confirmed & (out.state[:, 0] > 0)).any()]
    assert not plain_first or plain_first[0] > first


def test_static_clutter_at_the_closures_doppler_starts_no_walk():
    rng = np.random.default_rng(3)
    frames = _clutter(rng, 600, 12, float(_wrap(-113.0)))  # a minute of a dense patch, 12 per frame
    walks = RangeWalks(WIDTH_MPS)
    started = 0
    for k, z in enumerate(frames):
        rows, _ = walks.step(k * FRAME_S, z, np.ones(len(z), bool), OWN_SPEED_MPS)
        started += rows.size
    assert started == 0


def test_a_walk_no_faster_than_a_static_point_starts_nothing():
    """A closure at 55 m/s against an own-ship at 50 m/s: a static point could be that fast (margin)."""
    walks = RangeWalks(WIDTH_MPS)
    for k in range(60):
        z = np.array([[3000.0 - 55.0 * k * FRAME_S, -55.0 + WIDTH_MPS]])
        rows, _ = walks.step(k * FRAME_S, z, np.ones(1, bool), OWN_SPEED_MPS)
        assert rows.size == 0


def test_without_the_own_ships_speed_no_walk_starts():
    walks = RangeWalks(WIDTH_MPS)
    for k in range(60):
        z = np.array([[3000.0 - 113.0 * k * FRAME_S, _wrap(-113.0)]])
        rows, _ = walks.step(k * FRAME_S, z, np.ones(1, bool), float("nan"))
        assert rows.size == 0


def test_a_walk_must_span_its_minimum_time():
    """Six detections in six consecutive frames (0.53 s) are what M-of-N is for, not a walk."""
    walks = RangeWalks(WIDTH_MPS, RangeWalkRule(min_span_s=2.0))
    for k in range(6):
        z = np.array([[3000.0 - 113.0 * k * FRAME_S, _wrap(-113.0)]])
        rows, _ = walks.step(k * FRAME_S, z, np.ones(1, bool), OWN_SPEED_MPS)
        assert rows.size == 0


def test_bad_rules_are_refused():
    with pytest.raises(ValueError, match="least_frames"):
        RangeWalkRule(least_frames=2)
    with pytest.raises(ValueError, match="min_span_s"):
        RangeWalkRule(min_span_s=5.0, window_s=4.0)


def test_one_clutter_hit_in_a_tracks_doppler_history_is_not_a_patch():
    t = np.arange(10) * 0.106
    v = -34.5 + 0.02 * t + np.random.default_rng(1).normal(0, 0.03, 10)
    spiked = v.copy()
    spiked[4] += 1.3  # the gate took a clutter detection once
    assert doppler_smooth(t, spiked, WIDTH_MPS)
    twice = spiked.copy()
    twice[7] -= 1.0  # two: scatterers taking turns
    assert not doppler_smooth(t, twice, WIDTH_MPS)


def test_a_walk_on_a_lost_tracks_aircraft_takes_its_id_back():
    """Confirmed by M-of-N, lost for three seconds, then seen in a third of its frames: the walk
    confirms it again and the tracks table carries the lost track's id (rows stay sorted by id)."""
    import pandas as pd

    from skyradar.track.track_table import track_detections

    rng = np.random.default_rng(5)
    t = np.arange(0.0, 14.0, FRAME_S)
    seen = (t < 2.0) | ((t > 5.0) & (rng.random(t.size) < 0.33))
    closing = -113.0
    det = pd.DataFrame(
        {
            "time_s": t[seen],
            "range_m": 4200.0 + closing * t[seen] + rng.normal(0, 3.0, seen.sum()),
            "radial_velocity_mps": _wrap(closing) + rng.normal(0, 0.05, seen.sum()),
        }
    )
    other = pd.DataFrame(  # a second aircraft, so the lost track is not the only one
        {"time_s": t, "range_m": 2500.0 - 20.0 * t, "radial_velocity_mps": np.full(t.size, -20.0)}
    )
    det = pd.concat([det, other]).sort_values("time_s", kind="stable").reset_index(drop=True)
    own = pd.DataFrame(
        {"time_s": t, "own_north_m": OWN_SPEED_MPS * t, "own_east_m": 0.0, "own_down_m": -1000.0}
        | {"own_vn_mps": OWN_SPEED_MPS, "own_ve_mps": 0.0, "own_vd_mps": 0.0}
    )
    tracks = track_detections(det, frame_times_s=t, ownship=own, ground_test=False)
    fast = tracks[tracks.confirmed & (tracks.radial_velocity_mps < -100.0)]
    early, late = fast[fast.time_s < 2.5], fast[fast.time_s > 6.0]
    assert len(early) and len(late)
    assert set(late.track_id) == set(early.track_id)  # the same id after the gap
    assert late.time_s.min() < 10.0  # confirmed again by its walk, not by 4 hits in 5 frames


# The plain search the compiled one must reproduce: each candidate's Doppler neighbours found by
# scanning every kept detection, each ambiguity's line judged in its own pass.
_MIN_EXTENT_M = 300.0


class _ReferenceWalks(RangeWalks):
    """:class:`RangeWalks` with the search written plainly, one candidate and one ambiguity at a time."""

    def _search(self, time_s: float, z: np.ndarray, limit_mps: float) -> tuple[np.ndarray, np.ndarray]:
        taken = np.zeros(self._t.size, bool)
        found = np.full(len(z), np.nan)
        for i in range(len(z)):
            walk = self._walk(time_s, z[i], limit_mps, taken)
            if walk is None:
                continue
            found[i], support = walk
            taken[support] = True
        return found, taken

    def _walk(
        self, time_s: float, zi: np.ndarray, limit_mps: float, taken: np.ndarray
    ) -> tuple[float, np.ndarray] | None:
        """The closing walk through detection ``zi`` with the most support, if it passes the rule."""
        rule, width = self.rule, self.width
        dv = (self._v - zi[1] + width / 2.0) % width - width / 2.0
        near = np.flatnonzero((np.abs(dv) <= rule.doppler_gate_mps) & ~taken)
        if near.size < rule.least_frames - 1:
            return None
        dt = self._t[near] - time_s  # <= 0
        mean_v = zi[1] + 0.5 * dv[near]  # the two detections' mean Doppler, in zi's alias

        def support(k: int) -> np.ndarray:
            residual = self._r[near] - (zi[0] + (mean_v + k * width) * dt)
            return near[np.abs(residual) <= rule.range_gate_m]

        def frames(rows: np.ndarray) -> int:
            return int(np.unique(self._f[rows]).size) + 1  # the new detection's frame too

        k_max = int(np.ceil((rule.max_closing_mps + abs(zi[1])) / width)) + 1
        ks = np.arange(-k_max, k_max + 1)
        speeds = zi[1] + ks * width
        static = max((frames(support(int(k))) for k in ks[np.abs(speeds) <= limit_mps]), default=1)
        # Chance support: the Doppler's other detections in the window, spread over the ranges they cover.
        extent_m = max(float(np.ptp(self._r[near])), _MIN_EXTENT_M) + 2.0 * rule.range_gate_m
        per_detection = 2.0 * rule.range_gate_m / extent_m
        best: tuple[float, np.ndarray] | None = None
        best_n = 0
        for k in ks[(speeds < -limit_mps) & (speeds >= -rule.max_closing_mps)]:
            rows = support(int(k))
            n = frames(rows)
            if n < rule.least_frames or n < rule.static_ratio * static or n <= best_n:
                continue
            if time_s - self._t[rows].min() < rule.min_span_s:
                continue
            chance = (near.size - rows.size) * per_detection
            if poisson.sf(n - 2, chance) > rule.false_walk_probability:  # P(at least n - 1 supports)
                continue
            best, best_n = (float(zi[1] + k * width), rows), n
        return best


def _dense_scene(rng: np.random.Generator, n_frames: int) -> list[np.ndarray]:
    """About 150 detections a frame spread over the image, static clutter at a few Dopplers, and
    closures at -100 to -117 m/s seen in a third to a half of their frames."""
    frames = []
    closures = [(3200.0, -100.0, 3), (2800.0, -113.0, 2), (3600.0, -117.0, 3)]
    patch = rng.uniform(800.0, 4000.0, 80)
    for k in range(n_frames):
        t = k * FRAME_S
        uniform = np.column_stack(
            [rng.uniform(200.0, 4500.0, 100), rng.uniform(-WIDTH_MPS / 2, WIDTH_MPS / 2, 100)]
        )
        pick = rng.choice(patch.size, 40, replace=False)
        ground = np.column_stack(
            [patch[pick] - 30.0 * t + rng.normal(0, 4, 40), -30.0 + rng.normal(0, 0.15, 40)]
        )
        rows = [uniform, ground]
        for r0, v, every in closures:
            if k % every == 0:
                rows.append(
                    np.array([[r0 + v * t + rng.normal(0, 3.0), float(_wrap(v + rng.normal(0, 0.05)))]])
                )
        z = np.concatenate(rows)
        frames.append(z[rng.permutation(len(z))])
    return frames


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_compiled_search_finds_the_walks_the_plain_one_finds(seed):
    rng = np.random.default_rng(seed)
    frames = _dense_scene(rng, 60)
    fast, plain = RangeWalks(WIDTH_MPS), _ReferenceWalks(WIDTH_MPS)
    started = 0
    for k, z in enumerate(frames):
        free = rng.random(len(z)) < 0.9  # some detections are taken by confirmed tracks
        rows, velocity = fast.step(k * FRAME_S, z, free, OWN_SPEED_MPS)
        rows_ref, velocity_ref = plain.step(k * FRAME_S, z, free, OWN_SPEED_MPS)
        np.testing.assert_array_equal(rows, rows_ref)
        np.testing.assert_allclose(velocity, velocity_ref, rtol=0, atol=1e-9)
        started += rows.size
    assert started >= 3, started  # the closures start walks: the comparison covers found walks, not only none
