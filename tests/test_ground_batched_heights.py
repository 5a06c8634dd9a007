"""The ground filter asks a frame's surface heights in one call: the same flags as one call per step.

Over a DEM every call of the surface height function converts its points to geodetic coordinates
and looks them up, a fixed cost per call; :func:`skyradar.process.ground.flag_ground` gathers the
point sets of its steps (along each direction, along the mirrored end-fire directions, the terrain
rise rings, the elevation test) into one call. A point's height depends on that point alone, so
the heights, and the flags, are the same bit for bit.
"""

from __future__ import annotations

import numpy as np

from skyradar.config import RadarConfig
from skyradar.geo import ned_to_geodetic
from skyradar.process import ground
from skyradar.process.ground import flag_ground, surface_height_fn
from skyradar.scene.synthetic_terrain import fractal_terrain

CFG = RadarConfig.prototype_2022()
LAT0, LON0 = 52.0, 5.0


def _hills_height_fn(calls: list | None = None):
    terrain = fractal_terrain(LAT0, LON0, local_sd_m=60.0, size_m=12_000.0, spacing_m=30.0, seed=3)

    def geodetic(points):
        return ned_to_geodetic(points, LAT0, LON0)

    height = surface_height_fn(-50.0, terrain, geodetic)  # flat ground beyond the DEM at 50 m
    if calls is None:
        return height

    def counted(points):
        calls.append(np.shape(points))
        return height(points)

    return counted


def _frame(n: int, seed: int) -> tuple[dict, np.ndarray]:
    """Detections around a radar 600 m up: ground-like and air-like, reliable and not, some end-fire."""
    rng = np.random.default_rng(seed)
    az = rng.uniform(-np.pi, np.pi, n)
    el = rng.uniform(-1.5, 0.6, n)
    el[:3] = [np.radians(88.0), np.radians(-87.0), np.radians(-50.0)]  # end-fire: the mirror rule
    u = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)], axis=1)
    r = rng.uniform(200.0, 4500.0, n)
    antenna = np.array([100.0, -200.0, -600.0])
    p = antenna + r[:, None] * u
    v = np.array([50.0, 0.0, 0.0])
    frame = {
        "range_m": r,
        "snr_db": rng.uniform(12.0, 40.0, n),
        "azimuth_rad": az,
        "elevation_rad": el,
        "north_m": p[:, 0],
        "east_m": p[:, 1],
        "down_m": p[:, 2],
        "radial_velocity_mps": -(u @ v) + rng.normal(0.0, 3.0, n) * (rng.random(n) < 0.5),
        "u_ant": u,
        "coherence": rng.uniform(0.2, 1.0, n),  # below 0.5: unreliable, the rise and elevation tests
        "elevation_measured": rng.random(n) < 0.9,
    }
    return frame, v


class _Separate:
    """The surface height function called once per step, as without the gathering."""

    def __init__(self, height_fn, queries):
        self._fn = height_fn

    def __call__(self, points):
        return self._fn(points)


def test_one_height_call_per_frame_gives_the_flags_of_one_call_per_step(monkeypatch):
    for seed in range(4):
        frame, v = _frame(60, seed)
        calls: list = []
        args = (frame["u_ant"], v, np.eye(3), _hills_height_fn(calls), 600.0, CFG)
        gathered = flag_ground(frame, *args)
        assert len(calls) == 1  # every step's points in one call
        with monkeypatch.context() as m:
            m.setattr(ground, "_Prefetched", _Separate)
            separate = flag_ground(frame, *args)
        assert len(calls) == 1 + 5  # along, mirrored, rise (below, rings), elevation: one call each
        np.testing.assert_array_equal(gathered, separate)
        assert 0 < gathered.sum() < gathered.size  # both outcomes occur: the comparison can fail


def test_gathered_heights_equal_separate_calls_bit_for_bit():
    height = _hills_height_fn()
    rng = np.random.default_rng(0)
    sets = [rng.uniform(-5000.0, 5000.0, shape) for shape in [(1, 3), (17, 3), (16, 24, 3), (5, 29, 3)]]
    for s in sets:
        s[..., 2] = rng.uniform(-1500.0, 0.0, s.shape[:-1])
    gathered = ground._Prefetched(height, sets)
    for s in sets:
        got, want = gathered(s), height(s)
        assert got.shape == want.shape and got.tobytes() == want.tobytes()
    other = sets[1] + 1.0  # not one of the gathered sets: asked of the function itself
    assert gathered(other).tobytes() == height(other).tobytes()
