"""At which geometry each frame's clutter prediction is computed: a pure function of the run's navigation.

The predicted clutter subspace (:func:`skyradar.process.clutter.clutter_subspace`) depends on the
own-ship's velocity in a heading-free frame, its pitch, roll and height above the ground below it.
A prediction costs 0.1-0.2 s of CPU, so one is reused while the navigated geometry stays within a
tolerance of the geometry it was computed at, its *anchor* (:data:`V_TOLERANCE_MPS` per velocity
axis, about one Doppler bin; :data:`ANGLE_TOLERANCE_DEG` of pitch and roll; :data:`HEIGHT_TOLERANCE`
of the height). Which anchor serves a frame depends on the frames before it (the most recently
used anchor within the tolerance), so :func:`prediction_anchors` walks the run from its first
frame: the anchor of frame ``i`` is the same whether the run is processed whole, in Dask chunks,
resumed, or after other runs in the same process (it was a cache shared by every run a process
had seen, and a Dask chunk started from its own first frame: a 2-frame chunked run gave one
detection more than the plain loop, ``tests/test_scale.py``).

Why the tolerance and the velocity mean: without them the GNSS noise of ``ga-typical`` navigation
(0.2 m/s vertical) crossed a quantisation step on most frames and each frame paid for a new
prediction. The velocity is the mean over the frame and the 4 before it, each in its own
heading-free frame: the white GNSS velocity noise and the heading noise (0.2 deg, 0.2 m/s across
the track at 60 m/s) still crossed the tolerance every few frames (6-10 predictions per 75 frames
over flat ground, 2-3 with the mean). In a steady 35 deg banked turn the heading-free velocity is
constant (one prediction, tested); the mean lags a changing velocity by 0.2 s. Measured on the
``experiment clutter`` scene at 1000 m, a prediction off by the whole tolerance in every quantity
at once lowers the improvement factor in the intruder's lost cells from 27.3 to 26.3-26.6 dB;
with 5 % of height and the adaptive nulls (:mod:`skyradar.process.clutter_adaptive`), 25.3 and
26.5 dB, the same intruder hits. Over relief the height below jumps with every hill; tried on
encounter windows, the median ground height within 5 km lost intruder hits over hills and a
tolerance grown with the relief's spread lost them over Jacksboro, so the height stays the one
below.
"""

from __future__ import annotations

from collections import OrderedDict
from typing import Any

import numpy as np

from skyradar.io.ownship_states import OwnShipStates
from skyradar.process.ground import height_above_ground_m

__all__ = [
    "AnchorWalk",
    "frame_geometries",
    "prediction_anchors",
    "anchor_key",
    "V_TOLERANCE_MPS",
    "ANGLE_TOLERANCE_DEG",
    "HEIGHT_TOLERANCE",
    "RECENT_ANCHORS",
]

_V_STEP, _ANGLE_STEP_DEG, _HEIGHT_STEP = 0.25, 1.0, 0.0025  # the quantisation an anchor is computed at
V_TOLERANCE_MPS, ANGLE_TOLERANCE_DEG, HEIGHT_TOLERANCE = 0.35, 0.5, 0.05  # reuse of an anchor
RECENT_ANCHORS = 8  # anchors the walk keeps (clutter_frames caches as many predictions)
_SMOOTH_FRAMES = 5  # velocity mean over this frame and the 4 before it (GNSS velocity noise is white)


def frame_geometries(own: OwnShipStates, terrain: Any = None, stop: int | None = None) -> np.ndarray:
    """Velocity in a heading-free frame (m/s, forward, right, down; the mean over each frame and the
    4 before it), pitch, roll (rad) and height above the ground below (m) of frames ``0:stop``.

    ``own`` is the run's navigated :class:`~skyradar.io.ownship_states.OwnShipStates`. The height
    is the navigated one, else the terrain's under the own-ship (``terrain.height_at(lat, lon)`` or
    a callable) when the run is geodetic; a DEM without ground there reads as no ground (1e9 m).
    Rows without a height, or not above the ground, are NaN.

    Examples
    --------
    >>> one, zero = np.ones(2), np.zeros(2)
    >>> own = OwnShipStates.from_columns({"time_s": [0.0, 0.1], "own_north_m": zero, "own_east_m": zero,
    ...     "own_down_m": zero, "own_vn_mps": zero, "own_ve_mps": 50 * one, "own_vd_mps": zero,
    ...     "own_yaw_rad": np.radians(90) * one, "own_height_agl_m": np.array([500.0, -1.0])})
    >>> frame_geometries(own).round(6).tolist()
    [[50.0, 0.0, 0.0, 0.0, 0.0, 500.0], [nan, nan, nan, nan, nan, nan]]
    """
    n = own.yaw_rad.size if stop is None else int(stop)
    yaw = own.yaw_rad[:n]
    vn, ve, vd = own.vn_mps[:n], own.ve_mps[:n], own.vd_mps[:n]
    # Flat ground is the same in every direction: each frame's velocity in its own heading-free frame
    # (constant through a coordinated turn), averaged against the GNSS velocity noise.
    free = np.column_stack([np.cos(yaw) * vn + np.sin(yaw) * ve, np.cos(yaw) * ve - np.sin(yaw) * vn, vd])
    # Windows over zeros before the first frame (a NaN velocity spoils its own 5 windows, no more).
    padded = np.vstack([np.zeros((_SMOOTH_FRAMES - 1, 3)), free])
    windows = np.lib.stride_tricks.sliding_window_view(padded, _SMOOTH_FRAMES, axis=0)
    mean = windows.sum(axis=-1) / np.minimum(np.arange(1, n + 1), _SMOOTH_FRAMES)[:, None]
    height = np.array(own.height_agl_m[:n], float)
    unknown = ~np.isfinite(height)
    if unknown.any() and own.has_geo and terrain is not None:
        height[unknown] = _height_over_terrain(own, terrain, np.flatnonzero(unknown))
    out = np.column_stack([mean, own.pitch_rad[:n], own.roll_rad[:n], height])
    out[~(height > 0)] = np.nan
    return out


def _height_over_terrain(own: OwnShipStates, terrain: Any, rows: np.ndarray) -> np.ndarray:
    """Own-ship altitude less the terrain height under it at ``rows``, m (1e9 outside the DEM)."""
    lat, lon, alt = own.lat_deg[rows], own.lon_deg[rows], own.alt_m[rows]
    agl = height_above_ground_m(lat, lon, alt, terrain)
    return np.where(np.isfinite(agl), agl, 1e9)


def anchor_key(anchor: np.ndarray) -> tuple:
    """Integer key of an anchor (quantised velocity, pitch, roll, height), for caches.

    Parameters
    ----------
    anchor : ndarray, shape (6,)
        Heading-free velocity (forward, right, down), m/s, pitch and roll, rad, and height above
        the ground, m (a row of :func:`prediction_anchors`).

    Returns
    -------
    tuple
        Velocity in steps of 0.25 m/s and pitch and roll in steps of 1 deg (ints), then the height
        in m rounded to 1 mm.

    Examples
    --------
    >>> anchor_key(np.array([60.0, 0.0, 0.5, np.radians(2.0), np.radians(-1.0), 1000.0]))
    (240, 0, 2, 2, -1, 1000.0)
    """
    v = np.round(np.asarray(anchor[:3], float) / _V_STEP).astype(int)
    angles = np.round(np.degrees(anchor[3:5]) / _ANGLE_STEP_DEG).astype(int)
    return (*v.tolist(), *angles.tolist(), round(float(anchor[5]), 3))


def _quantised(state: np.ndarray) -> np.ndarray:
    v = np.round(state[:3] / _V_STEP) * _V_STEP
    angles = np.radians(np.round(np.degrees(state[3:5]) / _ANGLE_STEP_DEG) * _ANGLE_STEP_DEG)
    height = np.exp(np.round(np.log(state[5]) / _HEIGHT_STEP) * _HEIGHT_STEP)
    return np.array([*v, *angles, height])


def _within_tolerance(state: np.ndarray, at: np.ndarray) -> bool:
    """Whether a prediction computed at anchor ``at`` serves a frame at ``state``."""
    return bool(
        np.all(np.abs(state[:3] - at[:3]) <= V_TOLERANCE_MPS)
        and np.all(np.abs(state[3:5] - at[3:5]) <= np.radians(ANGLE_TOLERANCE_DEG))
        and abs(np.log(state[5] / at[5])) <= HEIGHT_TOLERANCE
    )


def prediction_anchors(own: OwnShipStates, terrain: Any = None, stop: int | None = None) -> np.ndarray:
    """The geometry (:func:`frame_geometries`' columns, quantised) each of frames ``0:stop`` is
    predicted at; NaN rows where there is no height above the ground.

    A frame takes the anchor of its own quantised geometry when the walk has it, else the most
    recently used one within the tolerance, else its own (the walk keeps the 8 last used). Heights are
    quantised by 0.25 %.

    Examples
    --------
    >>> n = 4
    >>> own = OwnShipStates.from_columns({"time_s": np.arange(n) * 0.1, "own_north_m": np.zeros(n),
    ...     "own_east_m": np.zeros(n), "own_down_m": np.zeros(n), "own_vn_mps": np.full(n, 50.0),
    ...     "own_ve_mps": np.zeros(n), "own_vd_mps": np.array([0.0, 0.3, 0.0, 0.0]),
    ...     "own_height_agl_m": np.array([1000.0, 1030.0, 1200.0, 1000.0])})
    >>> a = prediction_anchors(own)
    >>> a[:, 5].round(1).tolist()  # 3 % higher: the first anchor; 20 % higher: a new one; back: the first
    [999.7, 999.7, 1199.9, 999.7]
    """
    states = frame_geometries(own, terrain, stop)
    walk = AnchorWalk()
    return np.array([walk.next(state) for state in states], float).reshape(states.shape)


class AnchorWalk:
    """The walk of :func:`prediction_anchors` one frame at a time: the anchor of each next frame.

    It keeps the 8 anchors last used, so frame ``i``'s anchor is the one the whole run's walk gives
    it when the frames are fed in order from frame 0 (a stream, :mod:`skyradar.stream`).

    Examples
    --------
    >>> walk = AnchorWalk()
    >>> first = walk.next(np.array([50.0, 0.0, 0.0, 0.0, 0.0, 1000.0]))
    >>> bool(np.array_equal(walk.next(np.array([50.0, 0.0, 0.3, 0.0, 0.0, 1030.0])), first))
    True
    >>> bool(np.isnan(walk.next(np.full(6, np.nan))).all())
    True
    """

    def __init__(self) -> None:
        self._recent: OrderedDict[tuple, np.ndarray] = OrderedDict()

    def next(self, state: np.ndarray) -> np.ndarray:
        """Anchor of the frame whose geometry is ``state`` (a :func:`frame_geometries` row); NaN
        where the geometry is unknown (no height above the ground)."""
        if not np.all(np.isfinite(state)):
            return np.full(np.shape(state), np.nan)
        recent = self._recent
        at = _quantised(state)
        key = anchor_key(at)
        hit = recent.get(key)
        if hit is None:
            for other in reversed(recent):
                if _within_tolerance(state, recent[other]):
                    key, hit = other, recent[other]
                    break
        if hit is None:
            recent[key] = hit = at
            while len(recent) > RECENT_ANCHORS:
                recent.popitem(last=False)
        recent.move_to_end(key)
        return hit
