"""Clutter suppression inside the frames pipeline: per-frame geometry (cached) and DoA after projection.

:func:`frame_subspace` turns one frame's navigation state (the run's
:class:`~skyradar.io.ownship_states.OwnShipStates`: velocity, attitude, height above ground)
into the predicted clutter subspace over flat ground at the own-ship's height above the ground
below it (from the navigation, else from the terrain under the own-ship). It depends on the velocity in a
heading-free frame, pitch, roll and height only, so it is computed at the frame's anchor
(:mod:`skyradar.process.clutter_anchors`: reused while the navigated geometry stays within a
stated tolerance, the same anchor however the run is chunked) and cached: a straight flight computes
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
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.geo import rotation_matrix
from skyradar.io.ownship_states import OwnShipStates
from skyradar.process.clutter import ClutterSubspace, clutter_subspace
from skyradar.process.clutter_adaptive import ring_whitening
from skyradar.process.clutter_anchors import RECENT_ANCHORS, anchor_key, prediction_anchors
from skyradar.process.clutter_doa import directions_after_projection, projected_directions
from skyradar.process.clutter_suppress import projected_snapshots, suppress_clutter
from skyradar.process.detect import Detections
from skyradar.process.doa import (
    channel_calibration,
    steering_vector,
)
from skyradar.process.ground import static_radial_velocity_mps
from skyradar.process.mimo import DetectionDirections, compensate_projector, plain_directions, virtual_pixels
from skyradar.units import wrap

__all__ = [
    "frame_subspace",
    "frame_clutter",
    "directions_after_projection",
    "detect_suppressed",
    "SuppressedDetections",
    "plain_wave_is_mixed",
    "SUPPRESSIONS",
]

SUPPRESSIONS = ("none", "knowledge-aided", "auto")
_CACHE: OrderedDict[tuple, tuple[RadarConfig, ClutterSubspace]] = OrderedDict()
# Predictions kept, one per anchor the walk keeps: about 20 MB each (packed covariance, eigenvectors).
_CACHE_SIZE = RECENT_ANCHORS


def frame_subspace(
    own: OwnShipStates,
    i: int,
    config: RadarConfig,
    terrain: Any = None,
    anchors: np.ndarray | None = None,
) -> ClutterSubspace | None:
    """Predicted clutter subspace of frame ``i`` (None when the height above ground is unknown).

    Computed over flat ground at the frame's anchor (``anchors[i]``; without ``anchors``, walked
    over the run's frames up to ``i`` by
    :func:`~skyradar.process.clutter_anchors.prediction_anchors`) and kept for the next frames
    that share it (the last 8 predictions, about 20 MB each).

    Parameters
    ----------
    own : OwnShipStates
        The run's navigated own-ship state (velocity m/s, attitude rad, height above ground m).
    i : int
        Frame.
    config : RadarConfig
        The radar (its mount turns the antenna frame into the body frame).
    terrain : Terrain or callable(lat, lon), optional
        Ground height, m, for frames without a navigated height above ground.
    anchors : ndarray (n_frames, 6), optional
        The run's :func:`~skyradar.process.clutter_anchors.prediction_anchors`.

    Returns
    -------
    ClutterSubspace or None

    Examples
    --------
    Flying level north at 50 m/s, 500 m above flat ground: the ground starts at range bin 33
    (500 m); the second frame, at the same geometry, shares the prediction:

    >>> cfg = RadarConfig.prototype_2022()
    >>> one, zero = np.ones(2), np.zeros(2)
    >>> own = OwnShipStates.from_columns({"time_s": [0.0, 0.1], "own_north_m": zero, "own_east_m": zero,
    ...     "own_down_m": zero, "own_vn_mps": 50 * one, "own_ve_mps": zero, "own_vd_mps": zero,
    ...     "own_yaw_rad": zero, "own_height_agl_m": np.array([500.0, 500.0])})
    >>> sub = frame_subspace(own, 0, cfg)
    >>> int(np.nonzero(sub.predicted)[0].min()), int(cfg.range_bin(500.0)), frame_subspace(own, 1, cfg) is sub
    (33, 33, True)
    """
    if anchors is None:
        anchors = prediction_anchors(own, terrain, stop=i + 1)
    anchor = anchors[i]
    if not np.all(np.isfinite(anchor)):
        return None
    # Keyed on the config's content (RadarConfig hashes and compares its JSON): a run processed in
    # blocks reads an equal but new config per block, and a prediction depends on the content only.
    key = (*anchor_key(anchor), _config_key(config))
    hit = _CACHE.get(key)
    if hit is not None:
        _CACHE.move_to_end(key)
        return hit[1]
    ant_to_ned = rotation_matrix(0.0, float(anchor[3]), float(anchor[4])) @ config.mount.rotation
    sub = clutter_subspace(config, anchor[:3], ant_to_ned, float(anchor[5]), None, n_azimuth=720)
    _CACHE[key] = (config, sub)
    while len(_CACHE) > _CACHE_SIZE:
        _CACHE.popitem(last=False)
    return sub


def _config_key(config: RadarConfig) -> str:
    """The JSON text of ``config`` (its full content), remembered for the object last asked about."""
    global _LAST_CONFIG
    last = _LAST_CONFIG  # one tuple, replaced whole: threads never see a config with another's text
    if last[0] is config:
        return last[1]
    text = config.to_json()
    _LAST_CONFIG = (config, text)
    return text


_LAST_CONFIG: tuple[RadarConfig | None, str] = (None, "")  # the config object last keyed, its JSON


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
    the subspace's height, at its range), it is a mixture pointing at neither. Over flat ground
    300 m below, a head-on intruder aliased into the ground band has half its detections with the
    plain direction 48-90 deg off its bearing, 10-25 m/s off the static Doppler there, at the
    ground's depression; flagged ground, they would be lost to the tracker and its warning would
    come late. Those are searched through the nulls instead. A mixture pulled less far keeps its
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


def _mixed(det: Detections, z, u, nulls, sup, clutter: ClutterSubspace, config: RadarConfig):
    """:func:`plain_wave_is_mixed` of some detections in nulled cells, from their calibrated snapshots."""
    if len(z) == 0:
        return np.zeros(0, bool)
    _, y = projected_snapshots(z, sup.cell_vectors(clutter, det.range_index, det.doppler_index), nulls)
    kept = np.sum(np.abs(y) ** 2, axis=1) / np.maximum(np.sum(np.abs(z) ** 2, axis=1), 1e-300)
    return plain_wave_is_mixed(u, det.radial_velocity_mps(config), det.range_m(config), kept, clutter, config)


@dataclass(frozen=True)
class SuppressedDetections:
    """One frame's detections after clutter suppression, with their directions.

    Attributes
    ----------
    detections : Detections
        CFAR on the suppressed image.
    directions : DetectionDirections
        Their directions (:class:`skyradar.process.mimo.DetectionDirections`), searched through the
        cell's nulls where the plain one does not stand.

    Examples
    --------
    Returned by :func:`detect_suppressed`; a frame of noise alone leaves few detections:

    >>> from skyradar.process.clutter import clutter_subspace
    >>> cfg = RadarConfig.prototype_2022()
    >>> sub = clutter_subspace(cfg, np.array([50.0, 0.0, 0.0]), cfg.mount.rotation, 300.0)
    >>> rng = np.random.default_rng(0)
    >>> noise = rng.standard_normal(cfg.frame_shape) + 1j * rng.standard_normal(cfg.frame_shape)
    >>> cube = noise * np.sqrt(cfg.noise_power_w / 2)
    >>> found = detect_suppressed(cube.astype(np.complex64), cfg, sub)
    >>> found.directions.u_ant.shape == (len(found.detections), 3)
    True
    >>> bool(np.all(found.directions.other_residue == -1))
    True
    """

    detections: Detections
    directions: DetectionDirections


def detect_suppressed(
    cube: np.ndarray,
    config: RadarConfig,
    clutter: ClutterSubspace,
    exclude: np.ndarray | None = None,
    method: Literal["cfar", "os-cfar", "shi-tomasi"] = "cfar",
    **detect_kwargs: Any,
) -> SuppressedDetections:
    """Detections of one frame after clutter suppression and their directions.

    Detection runs on the projected, renormalised image (CA-CFAR with each pixel's channel count,
    training outside unsuppressed clutter, :func:`skyradar.process.cfar.cfar_2d_floor`); cells
    that were not projected, or where one plane wave explains the unsuppressed snapshot (coherence
    >= 0.9: the target dominates the clutter), keep the plain DoA of
    :func:`skyradar.process.doa.estimate_directions`. Cells whose nulls are adaptive
    (:mod:`skyradar.process.clutter_adaptive`) are always projected (over relief one unpredicted
    clutter direction 40 dB over the noise is a plane wave too: its direction, 20-40 deg below the
    intruder's, is taken for the intruder's in a quarter of a Jacksboro intruder track's
    detections) and searched through their training ring's whitening ``R^-1`` instead of the
    projector (:func:`~skyradar.process.clutter_adaptive.ring_whitening`): over Jacksboro it halves
    the median azimuth error at the intruder (4.2 to 1.9 deg over 25 frames).

    A time-division MIMO radar's frame is suppressed on its virtual channels with each
    transmitter's slot phase still in (the prediction models it, :mod:`skyradar.process.clutter`);
    a detection's slot phase comes out before its direction is read, and the residue of its
    velocity ambiguity is chosen (:func:`skyradar.process.mimo.virtual_pixels`): by the plain
    beamformer where the plain direction stands, else through the cell's projector, turned by the
    same phases (:func:`skyradar.process.mimo.compensate_projector`): the clutter the nulls take
    out does not choose the residue. The runner-up residue's direction is read the same way.

    Examples
    --------
    A target 20 dB over the noise per channel, 20 deg right, in a frame whose every cell holds
    clutter 30 dB over the noise from 60 deg below:

    >>> from skyradar.process.clutter import ClutterSubspace
    >>> from skyradar.process.doa import angles_from_direction, direction_from_angles, steering_vector
    >>> cfg = RadarConfig.prototype_2022()
    >>> g = steering_vector(direction_from_angles(0.0, np.radians(-60.0)), cfg)
    >>> outer, iu = np.outer(g, g.conj()), np.triu_indices(4, 1)
    >>> pairs = np.stack([outer[iu].real, outer[iu].imag], -1).ravel()  # upper triangle (re, im)
    >>> packed = np.concatenate([outer.diagonal().real, pairs])
    >>> sub = ClutterSubspace(np.tile(packed, (cfg.n_range, cfg.n_doppler, 1)), 4)
    >>> rng = np.random.default_rng(1)
    >>> shape = (cfg.n_range, cfg.n_doppler, cfg.n_rx)
    >>> noise = rng.standard_normal(shape) + 1j * rng.standard_normal(shape)
    >>> cube = noise * np.sqrt(cfg.noise_power_w / 2)
    >>> cube += 30.0 * (rng.standard_normal(shape[:2]) * np.sqrt(cfg.noise_power_w))[..., None] * g
    >>> u = direction_from_angles(np.radians(20.0), 0.0)
    >>> cube[100, 40] += 10.0 * np.sqrt(cfg.noise_power_w) * steering_vector(u, cfg)
    >>> found = detect_suppressed(cube.astype(np.complex64), cfg, sub)
    >>> hit = (found.detections.range_index == 100) & (found.detections.doppler_index == 40)
    >>> np.degrees(angles_from_direction(found.directions.u_ant[hit])).ravel().round().tolist()
    [20.0, 0.0]
    """
    sup = suppress_clutter(cube, clutter, config)
    det = sup.detections(config, method=method, exclude=exclude, **detect_kwargs)
    z = cube[det.range_index, det.doppler_index] / channel_calibration(config)
    directions = plain_directions(z, det.doppler_bin, config)
    u, coherence, elevation_measured = directions.u_ant, directions.coherence, directions.elevation_measured
    nulls = sup.nulls[det.range_index, det.doppler_index]
    projected = (nulls > 0) & (coherence < _PLANE_WAVE)  # one plane wave explains it: the target dominates
    maybe = (nulls > 0) & ~projected  # ... or the clutter does, and a target hides under it
    projected[maybe] = _mixed(det.select(maybe), z[maybe], u[maybe], nulls[maybe], sup, clutter, config)
    if sup.adaptive is not None:  # not where the clutter the prediction missed may be that plane wave
        projected |= sup.adaptive[det.range_index, det.doppler_index]
    if projected.any():
        r, d = det.range_index[projected], det.doppler_index[projected]
        zp = z[projected]
        proj, y = projected_snapshots(zp, sup.cell_vectors(clutter, r, d), nulls[projected])
        own = np.zeros(len(zp), bool) if sup.adaptive is None else sup.adaptive[r, d]
        if own.any():  # adaptive cells: through their ring's whitening (the adaptive matched filter)
            inv_gain = 1.0 / channel_calibration(config)
            proj[own] = ring_whitening(cube, inv_gain, r[own], d[own], sup.noise_floor_w)
        if config.n_tx > 1:  # the pixels and their projector turned by the residue chosen through it
            turned = virtual_pixels(zp, det.doppler_bin[projected], config, proj=proj)
            directions.residue[projected] = turned.residue
            directions.other_residue[projected] = turned.other_residue
            other_proj = compensate_projector(proj, turned.other_phasors)
            directions.other_u_ant[projected] = projected_directions(
                turned.other_pixels, other_proj, config, sup.noise_floor_w
            )[0]
            zp, y, proj = turned.pixels, turned.phasors * y, compensate_projector(proj, turned.phasors)
        u[projected], elevation_measured[projected] = projected_directions(
            zp, proj, config, sup.noise_floor_w
        )
        coherence[projected] = _fit(proj, zp, y, steering_vector(u[projected], config), own)
    return SuppressedDetections(det, directions)


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
    own: OwnShipStates | None,
    i: int,
    config: RadarConfig,
    terrain: Any = None,
    anchors: np.ndarray | None = None,
) -> ClutterSubspace | None:
    """The clutter subspace frame ``i`` is suppressed with under ``suppression``, or None.

    ``"none"``: never. ``"knowledge-aided"``: always; InputError when the run has no own-ship
    state (velocity, attitude and height above ground, or a terrain under a geodetic position).
    ``"auto"``: knowledge-aided where that state exists, none elsewhere. ``anchors``: the run's
    :func:`~skyradar.process.clutter_anchors.prediction_anchors` (computed here when not given).

    Parameters
    ----------
    suppression : {"none", "knowledge-aided", "auto"}
        The rule above.
    own : OwnShipStates or None
        The run's navigated own-ship state (velocity m/s, attitude rad, height above ground m).
    i : int
        Frame.
    config : RadarConfig
        The radar.
    terrain : Terrain or callable(lat, lon), optional
        Ground height, m, for frames without a navigated height above ground.
    anchors : ndarray (n_frames, 6), optional
        As above.

    Returns
    -------
    ClutterSubspace or None
        :func:`frame_subspace`'s prediction, or None where the frame is not suppressed.

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> one, zero = np.ones(2), np.zeros(2)
    >>> own = OwnShipStates.from_columns({"time_s": [0.0, 0.1], "own_north_m": zero, "own_east_m": zero,
    ...     "own_down_m": zero, "own_vn_mps": 50 * one, "own_ve_mps": zero, "own_vd_mps": zero,
    ...     "own_yaw_rad": zero, "own_height_agl_m": np.array([500.0, 500.0])})
    >>> frame_clutter("none", own, 0, cfg) is None, frame_clutter("auto", None, 0, cfg) is None
    (True, True)
    >>> frame_clutter("knowledge-aided", own, 0, cfg) is frame_subspace(own, 0, cfg)
    True
    >>> frame_clutter("knowledge-aided", None, 0, cfg)
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: suppression 'knowledge-aided' needs the own-ship state ...
    """
    if suppression not in SUPPRESSIONS:
        raise InputError(f"field 'suppression' must be one of {', '.join(SUPPRESSIONS)}, got {suppression!r}")
    if suppression == "none":
        return None
    sub = None if own is None else frame_subspace(own, i, config, terrain, anchors)
    if sub is None and suppression == "knowledge-aided":
        what = (
            "own-ship state (own_*/nav_* variables)"
            if own is None
            else "height above ground (own_height_agl_m or a terrain)"
        )
        raise InputError(f"suppression 'knowledge-aided' needs the {what}; frame {i} has none")
    return sub
