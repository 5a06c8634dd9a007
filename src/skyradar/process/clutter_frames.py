"""Clutter suppression inside the frames pipeline: per-frame geometry (cached) and DoA after projection.

:func:`frame_subspace` turns one frame's navigation state (the own-ship dict of
:mod:`skyradar.process.pipeline`: velocity, attitude, height above ground) into the predicted
clutter subspace over flat ground at the own-ship's height above the ground below it (from the
navigation, else from the terrain under the own-ship). It depends on the velocity in a
heading-free frame, pitch, roll and height only, so it is cached on those, and reused while the
navigated geometry stays within a stated tolerance (see the function): a straight flight computes
it once; each new geometry costs about 0.1-0.2 s of CPU (the sum over the ground rings, then the
eigen-pairs of only the cells the frames' clutter gates, :mod:`skyradar.process.clutter`). The
terrain-following prediction (:func:`skyradar.process.clutter.clutter_subspace` with
``depth_fn``) is not used per frame: it would cost that for every few metres flown.

:func:`directions_after_projection` (home: :mod:`skyradar.process.clutter_doa`) estimates the
direction of a detection whose cell was projected: the projected matched filter's best direction;
the plain phase estimate of the unsuppressed snapshot would follow the clutter that dominates the
cell. With two nulls elevation is often unobservable (see that module, whose example shows it).
"""

from __future__ import annotations

from collections import OrderedDict
from typing import Any

import numpy as np

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.geo import rotation_matrix
from skyradar.process.clutter import ClutterSubspace, clutter_subspace
from skyradar.process.clutter_adaptive import ring_whitening
from skyradar.process.clutter_doa import directions_after_projection, projected_directions
from skyradar.process.clutter_suppress import projected_snapshots, suppress_clutter
from skyradar.process.detect import Detections, detect
from skyradar.process.doa import direction_coherence, estimate_directions, steering_vector
from skyradar.process.ground import static_radial_velocity_mps
from skyradar.units import wrap

__all__ = [
    "frame_subspace",
    "frame_clutter",
    "directions_after_projection",
    "detect_suppressed",
    "plain_wave_is_mixed",
    "SUPPRESSIONS",
]

SUPPRESSIONS = ("none", "knowledge-aided", "auto")
_CACHE: OrderedDict[tuple, tuple[np.ndarray, ClutterSubspace]] = OrderedDict()
_CACHE_SIZE = 8  # predictions kept: about 20 MB each (packed covariance, eigenvectors as cells need them)
_V_STEP, _ANGLE_STEP_DEG, _HEIGHT_STEP = 0.25, 1.0, 0.0025
V_TOLERANCE_MPS, ANGLE_TOLERANCE_DEG, HEIGHT_TOLERANCE = 0.35, 0.5, 0.05  # reuse of a cached prediction


def _depth_fn(terrain: Any, lat_deg: float, lon_deg: float, alt_m: float):
    """Ground depth below the radar at NED offsets, from a terrain's ``height_at(lat, lon)``."""
    height_at = terrain.height_at if hasattr(terrain, "height_at") else terrain
    m_lat = 111_132.954 - 559.822 * np.cos(2 * np.radians(lat_deg))  # metres per degree (WGS84 series)
    m_lon = 111_412.84 * np.cos(np.radians(lat_deg))

    def depth(dn: np.ndarray, de: np.ndarray) -> np.ndarray:
        h = np.asarray(height_at(lat_deg + dn / m_lat, lon_deg + de / m_lon), float)
        return alt_m - np.where(np.isfinite(h), h, alt_m - 1e9)  # outside the DEM: no ground

    return depth


_SMOOTH_FRAMES = 5  # velocity mean over this frame and the 4 before it (GNSS velocity noise is white)


def _frame_geometry(own: dict[str, np.ndarray], i: int, terrain: Any) -> np.ndarray | None:
    """Velocity in a heading-free frame (3, the mean of the last ``_SMOOTH_FRAMES`` frames), pitch,
    roll and height above ground of frame ``i``."""
    pitch, roll = (float(own[k][i]) for k in ("own_pitch_rad", "own_roll_rad"))
    height = float(own["own_height_agl_m"][i])
    if not np.isfinite(height) and not (bool(own["has_geo"]) and terrain is not None):
        return None
    if not np.isfinite(height):  # only a DEM: the terrain height under the own-ship
        lat, lon, alt = (float(own[k][i]) for k in ("own_lat_deg", "own_lon_deg", "own_alt_m"))
        height = float(_depth_fn(terrain, lat, lon, alt)(np.zeros(1), np.zeros(1))[0])
    if not height > 0:
        return None
    # Flat ground is the same in every direction: each frame's velocity in its own heading-free frame
    # (constant through a coordinated turn), averaged against the GNSS velocity noise.
    v_free = np.mean(
        [
            rotation_matrix(float(own["own_yaw_rad"][j]), 0.0, 0.0).T
            @ np.array([own[k][j] for k in ("own_vn_mps", "own_ve_mps", "own_vd_mps")], float)
            for j in range(max(i - _SMOOTH_FRAMES + 1, 0), i + 1)
        ],
        axis=0,
    )
    return np.array([*v_free, pitch, roll, height])


def _within_tolerance(state: np.ndarray, at: np.ndarray) -> bool:
    """Whether a prediction computed at ``at`` serves a frame at ``state`` (see :func:`frame_subspace`)."""
    return bool(
        np.all(np.abs(state[:3] - at[:3]) <= V_TOLERANCE_MPS)
        and np.all(np.abs(state[3:5] - at[3:5]) <= np.radians(ANGLE_TOLERANCE_DEG))
        and abs(np.log(state[5] / at[5])) <= HEIGHT_TOLERANCE
    )


def frame_subspace(
    own: dict[str, np.ndarray], i: int, config: RadarConfig, terrain: Any = None
) -> ClutterSubspace | None:
    """Predicted clutter subspace of frame ``i`` (None when the height above ground is unknown).

    The prediction is computed at the geometry quantised (0.25 m/s, 1 deg, 0.25 % of the height)
    and reused for every frame whose navigated geometry lies within ``V_TOLERANCE_MPS`` per
    velocity axis (about one Doppler bin), ``ANGLE_TOLERANCE_DEG`` of pitch and roll and
    ``HEIGHT_TOLERANCE`` of the height of a cached one (the most recently used first): without the
    tolerance the GNSS noise of ``ga-typical`` navigation (0.2 m/s vertical) crossed a quantisation
    step on most frames and each frame paid for a new prediction. The velocity is the mean over
    this frame and the 4 before it (those in ``own``), each in its own heading-free frame: the
    white GNSS velocity noise (0.1 m/s horizontal, 0.2 m/s vertical) and the heading noise
    (0.2 deg, 0.2 m/s across the track at 60 m/s) still crossed the tolerance every few frames
    (6-10 predictions per 75 frames over flat ground, 2-3 with the mean). In a steady 35 deg
    banked turn the heading-free velocity is constant (one prediction, tested); the mean lags a
    changing velocity by 0.2 s (0.2 m/s at a 1 m/s^2 change, within the tolerance), and pitch, roll
    and height are not averaged. Measured on the ``experiment clutter`` scene at 1000 m, a
    prediction off by the whole tolerance in every quantity at once (0.35 m/s down, 0.5 deg
    pitch, 1 % height, either sign) lowers the improvement factor in the intruder's lost cells
    from 27.3 to 26.3-26.6 dB (2 deg and 2 % cost 2.4 dB); with 5 % of height and the adaptive
    nulls, to 25.3 and 26.5 dB (least cell 23.0 and 20.5 dB), the same 12 intruder hits of 20. Over relief
    the height below jumps with every hill (15-22 predictions per 75 frames over ``hills``). Tried
    and measured on encounter windows: the median ground height within 5 km (6-13 predictions)
    lost intruder hits over hills (34 of 75 frames against 41), a height tolerance grown with
    the relief's spread (3-11) lost them over Jacksboro (61-64 against 67-68), so the height stays
    the one below. Its tolerance was 1 % until the adaptive nulls
    (:mod:`skyradar.process.clutter_adaptive`) took over the cells where the flat-ground prediction
    fails: with them, 5 % keeps every intruder hit of a hills and a Jacksboro encounter (56 of 132
    and 23 of 79 sampled frames, the same as at 1 %) with 3 and 2 times fewer predictions (21
    against 71, 18 against 37), a prediction being the largest per-frame cost over relief. Over
    flat ground the height below only changes with the own-ship's altitude. Which cached
    prediction serves a frame can depend on the frames before
    it, so chunked and whole-run processing may use predictions that differ by at most the
    tolerance.
    """
    state = _frame_geometry(own, i, terrain)
    if state is None:
        return None
    v_q = np.round(state[:3] / _V_STEP) * _V_STEP
    step = _ANGLE_STEP_DEG
    pitch_q, roll_q = (np.radians(round(np.degrees(a) / step) * step) for a in state[3:5])
    height_q = float(np.exp(np.round(np.log(state[5]) / _HEIGHT_STEP) * _HEIGHT_STEP))
    key = (*np.round(v_q / _V_STEP).astype(int), round(np.degrees(pitch_q)), round(np.degrees(roll_q)),
           round(height_q, 3), id(config))  # fmt: skip
    hit = _CACHE.get(key)
    if hit is None:
        for other in reversed(_CACHE):
            if other[-1] == id(config) and _within_tolerance(state, _CACHE[other][0]):
                key, hit = other, _CACHE[other]
                break
    if hit is not None:
        _CACHE.move_to_end(key)
        return hit[1]
    ant_to_ned = rotation_matrix(0.0, pitch_q, roll_q) @ config.mount.rotation
    sub = clutter_subspace(config, v_q, ant_to_ned, height_q, None, n_azimuth=720)
    _CACHE[key] = (np.array([*v_q, pitch_q, roll_q, height_q]), sub)
    while len(_CACHE) > _CACHE_SIZE:
        _CACHE.popitem(last=False)
    return sub


_PLANE_WAVE = 0.9  # unsuppressed coherence above which the plain DoA is kept in a projected cell
_CLUTTER_DOMINATES = 0.1  # power fraction the nulls leave below which the clutter dominates a cell
_STATIC_FIT_MPS = 5.0  # radial velocity within which a plain direction is the clutter's own
_NEAR_GROUND = 1.5  # ranges under this many heights above ground: end-fire mirrors, keep the plain DoA
_GROUND_SLACK = 0.5  # a plain direction reaching this fraction of the way down to flat ground points at it


def plain_wave_is_mixed(
    u_ant: np.ndarray,
    radial_velocity_mps: np.ndarray,
    range_m: np.ndarray,
    kept_fraction: np.ndarray,
    clutter: ClutterSubspace,
    config: RadarConfig,
) -> np.ndarray:
    """Whether the plain direction of each coherent detection in a nulled cell is a mixture (bool).

    One plane wave fits the 2x2 array's four channels easily (coherence >= 0.9). Where the target
    dominates the cell, the nulls leave much of its power (``kept_fraction`` = ``|P z|^2 / |z|^2``
    at least :data:`_CLUTTER_DOMINATES`) and the wave is the target's. Where the clutter dominates,
    the wave is the clutter's when a static point in its direction has the detection's radial
    velocity (within :data:`_STATIC_FIT_MPS`, modulo ``2 VLim``): a ground return, for the ground
    filter. Otherwise, when it points at the ground (at least half way down to a flat ground at
    the subspace's height, at its range), it is a mixture pointing at neither. Flat ground 300 m
    below, 200-set encounter 15, a head-on intruder aliased into the ground band: half its
    detections had the plain direction 48-90 deg off its bearing, 10-25 m/s off the static Doppler
    there, at the ground's depression; flagged ground, they were lost to the tracker and its warning
    came late. Those are searched through the nulls instead. A mixture pulled less far keeps its
    plain direction (biased towards the ground, with an elevation the tracker can weigh: searched
    through the nulls it would lose it). Below :data:`_NEAR_GROUND` heights of range (the altitude
    return's end-fire mirrors) and without the subspace's geometry: never mixed.

    Examples
    --------
    >>> from skyradar.process.clutter import ClutterSubspace
    >>> cfg = RadarConfig.prototype_2022()
    >>> sub = ClutterSubspace(np.zeros((1, 1, 16)), 4, np.array([50.0, 0, 0]), np.array([0, 0, 1.0]), 300.0)
    >>> u = np.array([[0.46, 0.87, 0.18], [0.46, 0.87, 0.18], [0.96, -0.25, 0.0]])
    >>> plain_wave_is_mixed(u, np.array([-36.9, -23.0, -36.9]), np.full(3, 1460.0),
    ...                     np.array([0.01, 0.01, 0.4]), sub, cfg).tolist()  # mixed, clutter, target
    [True, False, False]
    """
    if clutter.velocity_ant_mps is None or clutter.down_ant is None or clutter.height_agl_m is None:
        return np.zeros(len(u_ant), bool)
    u, rng, height = np.asarray(u_ant, float), np.asarray(range_m, float), clutter.height_agl_m
    static = static_radial_velocity_mps(u, clutter.velocity_ant_mps)  # any frame: both antenna here
    off = np.abs(wrap(np.asarray(radial_velocity_mps, float) - static, 2.0 * config.v_lim_mps))
    grounded = rng * (u @ clutter.down_ant) >= (1.0 - _GROUND_SLACK) * height  # it would be read as ground
    far = rng >= _NEAR_GROUND * height
    return far & grounded & (np.asarray(kept_fraction, float) < _CLUTTER_DOMINATES) & (off > _STATIC_FIT_MPS)


def _mixed(det: Detections, pixels, u, nulls, sup, clutter: ClutterSubspace, config: RadarConfig):
    """:func:`plain_wave_is_mixed` of some detections in nulled cells, from their snapshots."""
    if len(pixels) == 0:
        return np.zeros(0, bool)
    z = pixels / config.rx_calibration
    _, y = projected_snapshots(z, sup.cell_vectors(clutter, det.range_index, det.doppler_index), nulls)
    kept = np.sum(np.abs(y) ** 2, axis=1) / np.maximum(np.sum(np.abs(z) ** 2, axis=1), 1e-300)
    return plain_wave_is_mixed(u, det.radial_velocity_mps(config), det.range_m(config), kept, clutter, config)


def detect_suppressed(
    cube: np.ndarray,
    config: RadarConfig,
    clutter: ClutterSubspace,
    exclude: np.ndarray | None = None,
    method: str = "cfar",
    **detect_kwargs: Any,
) -> tuple[Detections, np.ndarray, np.ndarray, np.ndarray]:
    """Detections, antenna-frame directions, coherence and whether the elevation was measured
    (bool; False where the nulls left it unobservable and the direction holds elevation 0, a prior)
    of one frame after clutter suppression.

    Detection runs on the projected, renormalised image (CA-CFAR with each pixel's channel count,
    training outside unsuppressed clutter, :func:`skyradar.process.cfar.cfar_2d_floor`); cells
    that were not projected, or where one plane wave explains the unsuppressed snapshot (coherence
    >= 0.9: the target dominates the clutter), keep the plain DoA of
    :func:`skyradar.process.doa.estimate_directions`. Cells whose nulls are adaptive
    (:mod:`skyradar.process.clutter_adaptive`) are always projected (over relief one unpredicted
    clutter direction 40 dB over the noise is a plane wave too: its direction, 20-40 deg below the
    intruder's, was taken for the intruder's in a quarter of a Jacksboro intruder track's
    detections) and searched through their training ring's whitening ``R^-1`` instead of the
    projector (:func:`~skyradar.process.clutter_adaptive.ring_whitening`): over Jacksboro it halved
    the median azimuth error at the intruder (4.2 to 1.9 deg, 25 frames).
    """
    sup = suppress_clutter(cube, clutter, config)
    det = detect(
        sup.power, config, method=method, exclude=exclude, channels=sup.channels,
        train_exclude=sup.unsuppressed, noise_floor_w=sup.noise_floor_w, **detect_kwargs,
    )  # fmt: skip
    pixels = cube[det.range_index, det.doppler_index]
    u = estimate_directions(pixels, config)
    coherence = direction_coherence(pixels, u, config)
    elevation_measured = np.ones(len(pixels), bool)
    nulls = sup.nulls[det.range_index, det.doppler_index]
    projected = (nulls > 0) & (coherence < _PLANE_WAVE)  # one plane wave explains it: the target dominates
    maybe = (nulls > 0) & ~projected  # ... or the clutter does, and a target hides under it
    projected[maybe] = _mixed(det.select(maybe), pixels[maybe], u[maybe], nulls[maybe], sup, clutter, config)
    if sup.adaptive is not None:  # not where the clutter the prediction missed may be that plane wave
        projected |= sup.adaptive[det.range_index, det.doppler_index]
    if projected.any():
        r, d = det.range_index[projected], det.doppler_index[projected]
        z = pixels[projected] / config.rx_calibration
        proj, y = projected_snapshots(z, sup.cell_vectors(clutter, r, d), nulls[projected])
        own = np.zeros(len(z), bool) if sup.adaptive is None else sup.adaptive[r, d]
        if own.any():  # adaptive cells: through their ring's whitening (the adaptive matched filter)
            inv_gain = 1.0 / np.asarray(config.rx_calibration)
            proj[own] = ring_whitening(cube, inv_gain, r[own], d[own], sup.noise_floor_w)
        u[projected], elevation_measured[projected] = projected_directions(z, proj, config, sup.noise_floor_w)
        coherence[projected] = _fit(proj, z, y, steering_vector(u[projected], config), own)
    return det, u, coherence, elevation_measured


def _fit(proj: np.ndarray, z: np.ndarray, y: np.ndarray, s: np.ndarray, whitened: np.ndarray) -> np.ndarray:
    """The projected matched filter's fit in [0, 1] of snapshots ``z`` (projected: ``y``) at ``s``:
    ``|(P s)^H P z|^2 / (|P s|^2 |P z|^2)``; for ``whitened`` rows (``proj`` holds ``W = R^-1``)
    the same with ``W`` (``|s^H W z|^2 / (s^H W s z^H W z)``, the adaptive coherence estimator)."""
    ps = np.einsum("nkl,nl->nk", proj, s)
    num = np.abs(np.sum(np.conj(ps) * y, axis=1)) ** 2
    den = np.maximum(np.sum(np.abs(ps) ** 2, axis=1) * np.sum(np.abs(y) ** 2, axis=1), 1e-300)
    fit = num / den
    if whitened.any():
        w, zw, sw = proj[whitened], z[whitened], s[whitened]
        wz = np.einsum("nkl,nl->nk", w, zw)
        num = np.abs(np.sum(np.conj(sw) * wz, axis=1)) ** 2
        s_w_s = np.sum(np.conj(sw) * np.einsum("nkl,nl->nk", w, sw), axis=1).real
        fit[whitened] = num / np.maximum(s_w_s * np.sum(np.conj(zw) * wz, axis=1).real, 1e-300)
    return fit


def frame_clutter(
    suppression: str,
    own: dict | None,
    i: int,
    config: RadarConfig,
    terrain: Any = None,
    source: str = "frames",
) -> ClutterSubspace | None:
    """The clutter subspace frame ``i`` is suppressed with under ``suppression``, or None.

    ``"none"``: never. ``"knowledge-aided"``: always; InputError when the run has no own-ship
    state (velocity, attitude and height above ground, or a terrain under a geodetic position).
    ``"auto"``: knowledge-aided where that state exists, none elsewhere.
    """
    if suppression not in SUPPRESSIONS:
        raise InputError(
            f"{source}: field 'suppression' must be one of {', '.join(SUPPRESSIONS)}, got {suppression!r}"
        )
    if suppression == "none":
        return None
    sub = None if own is None else frame_subspace(own, i, config, terrain)
    if sub is None and suppression == "knowledge-aided":
        what = (
            "own-ship state (own_*/nav_* variables)"
            if own is None
            else "height above ground (own_height_agl_m or a terrain)"
        )
        raise InputError(f"{source}: suppression 'knowledge-aided' needs the {what}; frame {i} has none")
    return sub
