"""Frames in, detections table out: spur mask, detection, DoA, world position, ground filter.

One row per detection per frame with the columns of :data:`DETECTION_COLUMNS` (SI units,
radians; :data:`DETECTION_TABLE_COLUMNS` gives each one's unit and meaning). ``range_m`` is the
apparent range of the peak (bin ``k`` at ``k * dR``): the sawtooth range-Doppler coupling
(``v * fc / (B PRF)``, 0.19 m per m/s) is left in because the measured radial velocity may be
aliased. World coordinates need the own-ship navigation state in the
Dataset (``nav_*`` variables, GNSS/AHRS with errors, via :func:`skyradar.io.navigation.navigation_state`;
``own_*`` truth only in stores without ``nav_*`` variables, with a logged note and
``table.attrs["navigation_source"] == "truth"``); the scenario's geodetic origin is read from the attributes
``origin_lat_deg``, ``origin_lon_deg``, ``origin_alt_m`` (or ``origin`` as a list) when present,
otherwise latitude/longitude/altitude are taken relative to the own-ship position (about 2 m off
at 5 km from the origin). Without an own-ship state those columns are NaN.

Examples
--------
>>> from skyradar.config import RadarConfig
>>> from skyradar.io.frames import frames_dataset
>>> cfg = RadarConfig.prototype_2022()
>>> rng = np.random.default_rng(0)
>>> shape = (1, cfg.n_range, cfg.n_doppler, cfg.n_rx)
>>> iq = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)) * np.sqrt(cfg.noise_power_w / 2)
>>> iq[0, 100, 40, :] += np.sqrt(1e4 * cfg.noise_power_w)
>>> table = process_frames(frames_dataset(iq.astype(np.complex64), np.array([0.0]), cfg))
>>> len(table), round(float(table.range_m[0]))
(1, 1499)
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any, Literal

import numpy as np
import pandas as pd
import xarray as xr

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.geo import ned_rotation_to, ned_to_geodetic, rotation_matrix
from skyradar.io.checks import check_finite_frames
from skyradar.io.frames import radar_config_of
from skyradar.io.frames_model import frame_times_s
from skyradar.io.ownship_states import OwnShipStates
from skyradar.io.run_origin import scenario_origin  # re-exported: the origin of a processed run
from skyradar.process.clutter_anchors import prediction_anchors
from skyradar.process.clutter_frames import detect_suppressed, frame_clutter
from skyradar.process.detect import detect, integrate_channels
from skyradar.process.doa import (
    angles_from_direction,
    antenna_to_body,
    channel_calibration,
)
from skyradar.process.ground import GeodeticFn, flag_ground, height_above_ground_m, surface_height_fn
from skyradar.process.mimo import plain_directions
from skyradar.process.spurs import SpurMap

__all__ = [
    "DETECTION_COLUMNS",
    "DETECTION_TABLE_COLUMNS",
    "PFA_SECONDARY",
    "clutter_anchors",
    "process_chunk",
    "process_cube",
    "process_frames",
    "scenario_origin",
]

# The detections table (``skyradar process``), column -> "unit; meaning" (skyradar.io.table_columns).
DETECTION_TABLE_COLUMNS: dict[str, str] = {
    "time_s": "s; elapsed time of the frame since the run's start_time",
    "frame": "-; frame number in the run, from 0",
    "range_m": "m; apparent range of the peak: bin k at k dR, the range-Doppler coupling left in",
    "radial_velocity_mps": "m/s; radial velocity of the peak, positive receding, aliased into [-VLim, VLim)",
    "range_bin": "-; sub-pixel range bin of the peak",
    "doppler_bin": "-; sub-pixel Doppler bin of the peak, wrapped into [0, n_doppler)",
    "snr_db": "dB; signal-to-noise ratio of the peak per channel and pixel, (power - noise) / noise",
    "power_db": "dBW; peak pixel power, the mean over the receive channels",
    "azimuth_rad": "rad; direction of arrival in the antenna frame, positive right",
    "elevation_rad": "rad; direction of arrival in the antenna frame, positive up (0 where not measured)",
    "elevation_measured": "-; False: clutter suppression left no elevation; elevation_rad is the level prior",
    "x_body_m": "m; position in the body frame, forward of the reference point",
    "y_body_m": "m; position in the body frame, right",
    "z_body_m": "m; position in the body frame, down",
    "north_m": "m; position north in the scenario NED frame, from the navigation solution (NaN without it)",
    "east_m": "m; position east in the scenario NED frame (NaN without own-ship navigation)",
    "down_m": "m; position down in the scenario NED frame (NaN without own-ship navigation)",
    "right_axis_north": "-; north component of the antenna's right axis in the scenario NED frame: "
    "sin(azimuth_rad) cos(elevation_rad) is the direction cosine along it (NaN without own-ship navigation)",
    "right_axis_east": "-; east component of the antenna's right axis (NaN without own-ship navigation)",
    "right_axis_down": "-; down component of the antenna's right axis (NaN without own-ship navigation)",
    "lat_deg": "deg; WGS84 latitude (NaN without own-ship navigation)",
    "lon_deg": "deg; WGS84 longitude (NaN without own-ship navigation)",
    "alt_m": "m; height above the WGS84 ellipsoid (NaN without own-ship navigation)",
    "is_ground": "-; True: the ground filter explains the detection as a ground return",
    "spur": "-; True: the peak lies in the spur map (--spur-mode flag; masked spurs are not detected)",
    "secondary": "-; True: the peak passed only the secondary threshold of a nulled cell: it may update "
    "a track, never start one",
    "residue": "-; time-division MIMO: the transmit-slot residue m mod n_tx the frame chose for the "
    "peak (its true radial velocity is radial_velocity_mps + m 2 VLim, modulo n_tx 2 VLim); 0 with one "
    "transmitter",
    "other_residue": "-; time-division MIMO: the runner-up residue, where the field of view chose less "
    "clearly (-1 with one transmitter)",
    "other_north_m": "m; time-division MIMO: position north from the runner-up residue's direction; a "
    "track whose range rate says that residue takes it (NaN with one transmitter or without navigation)",
    "other_east_m": "m; time-division MIMO: position east from the runner-up residue's direction",
    "other_down_m": "m; time-division MIMO: position down from the runner-up residue's direction",
    "other_azimuth_rad": "rad; time-division MIMO: the runner-up residue's azimuth in the antenna frame (NaN "
    "with one transmitter): its angle error, where a track takes its position",
    "other_elevation_rad": "rad; time-division MIMO: the runner-up residue's elevation in the antenna frame",
    "radar": "-; name of the radar head that detected it (`radar` for a run of one head)",
}
# The columns of one head's frames (process_frames); `radar` is added when the heads' tables merge
# (skyradar.process.detect_run.merge_head_tables).
DETECTION_COLUMNS = [c for c in DETECTION_TABLE_COLUMNS if c != "radar"]
# The secondary threshold of nulled cells. Two nulls in a ground cell cost a target about 5 dB;
# against the primary 2e-8 this threshold is about 2.4 dB lower (Gamma(2) noise), and a confirmed
# track's gate of a few cells sees one of its false alarms in thousands of frames.
PFA_SECONDARY = 1e-4


def process_cube(
    cube: np.ndarray,
    config: RadarConfig,
    spur_map: SpurMap | None = None,
    method: Literal["cfar", "os-cfar", "shi-tomasi"] = "cfar",
    spur_mode: Literal["mask", "flag"] = "mask",
    clutter: Any = None,
    pfa_secondary: float | None = PFA_SECONDARY,
    **detect_kwargs: Any,
) -> dict[str, np.ndarray]:
    """Detection and DoA for one (n_range, n_doppler, n_rx) frame, antenna and body frames.

    With a spur map, ``spur_mode="mask"`` removes spur pixels before detection (they are neither
    detected nor used as CFAR training cells, so an object beside a spur line stays visible);
    ``"flag"`` detects as usual and marks detections whose peak is in the map (thesis). With
    ``clutter`` (a :class:`skyradar.process.clutter.ClutterSubspace`) ground clutter is suppressed
    first, and the nulled cells also take the secondary threshold ``pfa_secondary``
    (:func:`skyradar.process.detect.detect`; None: none).

    Parameters
    ----------
    cube : ndarray (n_range, n_doppler, n_rx), complex
        One frame, uncalibrated (amplitude, sqrt(W)).
    config : RadarConfig
        Axes, calibration, antenna positions (m) and mount.
    spur_map : SpurMap, optional
        Spur pixels, used as ``spur_mode`` says.
    method : {"cfar", "os-cfar", "shi-tomasi"}
        Detector (:func:`skyradar.process.detect.detect`).
    spur_mode : {"mask", "flag"}
        As above.
    clutter : ClutterSubspace, optional
        The frame's predicted clutter; None: no suppression.
    pfa_secondary : float or None
        As above.
    **detect_kwargs
        Passed to :func:`skyradar.process.detect.detect` (``pfa``, ``guard``, ...).

    Returns
    -------
    dict of ndarray
        Equal-length arrays: the detection columns up to ``z_body_m`` (ranges and body positions in
        m, angles in rad, radial velocity in m/s, SNR in dB) plus ``spur``, ``u_ant`` (n, 3) unit
        vectors, ``coherence`` (:func:`.direction_coherence`), ``residue`` and ``other_residue``
        (a time-division MIMO radar's chosen and runner-up residue of the velocity ambiguity,
        :func:`skyradar.process.mimo.virtual_pixels`; 0 and -1 with one transmitter),
        ``other_azimuth_rad``, ``other_elevation_rad`` and ``other_u_ant`` (n, 3), the runner-up's
        direction (rad; unit vectors), and ``other_body_m`` (n, 3), the body position it gives (NaN
        with one transmitter), m.

    Examples
    --------
    Noise and one 30 dB target at range bin 100, Doppler bin 40, 10 deg right and 5 deg down:

    >>> from skyradar.process.doa import direction_from_angles, steering_vector
    >>> cfg = RadarConfig.prototype_2022()
    >>> rng = np.random.default_rng(0)
    >>> shape = (cfg.n_range, cfg.n_doppler, cfg.n_rx)
    >>> cube = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)) * np.sqrt(cfg.noise_power_w / 2)
    >>> u = direction_from_angles(np.radians(10.0), np.radians(-5.0))
    >>> cube[100, 40] += np.sqrt(1000 * cfg.noise_power_w) * steering_vector(u, cfg)
    >>> out = process_cube(cube.astype(np.complex64), cfg)
    >>> out["range_bin"].round().tolist(), out["doppler_bin"].round().tolist(), out["snr_db"].round().tolist()
    ([100.0], [40.0], [30.0])
    >>> np.degrees(out["azimuth_rad"]).round().tolist(), np.degrees(out["elevation_rad"]).round().tolist()
    ([10.0], [-5.0])
    """
    if cube.ndim != 3 or cube.shape[2] != config.n_virtual:
        raise InputError(
            f"frame: field 'rx' has {cube.shape[-1]} channels, radar_config has {config.n_virtual}"
        )
    if spur_mode not in ("mask", "flag"):
        raise InputError(f"process: field 'spur_mode' must be 'mask' or 'flag', got {spur_mode!r}")
    exclude = spur_map.mask if spur_map is not None and spur_mode == "mask" else None
    if clutter is not None:  # a ClutterSubspace: knowledge-aided suppression before detection
        found = detect_suppressed(
            cube, config, clutter, exclude, method, pfa_secondary=pfa_secondary, **detect_kwargs
        )
        det, directions = found.detections, found.directions
    else:
        calibration = channel_calibration(config)
        power = integrate_channels(cube, calibration)
        det = detect(power, config, method=method, exclude=exclude, **detect_kwargs)
        pixels = cube[det.range_index, det.doppler_index] / calibration
        directions = plain_directions(pixels, det.doppler_bin, config)
    u, u_other = directions.u_ant, directions.other_u_ant
    range_m = det.range_m(config)
    body = antenna_to_body(range_m[:, None] * u, config)
    az, el = angles_from_direction(u)
    n = len(det)
    body_other, other_az, other_el = np.full((n, 3), np.nan), np.full(n, np.nan), np.full(n, np.nan)
    if config.n_tx > 1:  # the runner-up residue's direction and position
        body_other = antenna_to_body(range_m[:, None] * u_other, config)
        other_az, other_el = angles_from_direction(u_other)
    spur = (
        spur_map.contains(det.range_bin, det.doppler_bin)
        if spur_map is not None
        else np.zeros(len(det), bool)
    )
    return {
        "range_m": range_m,
        "radial_velocity_mps": det.radial_velocity_mps(config),
        "range_bin": det.range_bin,
        "doppler_bin": det.doppler_bin,
        "snr_db": det.snr_db,
        "power_db": 10.0 * np.log10(np.maximum(det.power_w, 1e-300)),
        "azimuth_rad": az,
        "elevation_rad": el,
        "elevation_measured": directions.elevation_measured,
        "x_body_m": body[:, 0],
        "y_body_m": body[:, 1],
        "z_body_m": body[:, 2],
        "spur": spur,
        "secondary": det.secondary,
        "u_ant": u,
        "coherence": directions.coherence,
        "residue": directions.residue,
        "other_residue": directions.other_residue,
        "other_u_ant": u_other,
        "other_azimuth_rad": other_az,
        "other_elevation_rad": other_el,
        "other_body_m": body_other,
    }


def navigated_own_state(ds: xr.Dataset, source: str = "frames") -> OwnShipStates | None:
    """Own-ship state per frame as the aircraft knows it: the navigation solution, never the truth.

    :meth:`skyradar.io.ownship_states.OwnShipStates.from_frames` reads ``nav_*`` (``own_*`` only
    for a store without a navigation solution); None without position and velocity.
    """
    return OwnShipStates.from_frames(ds, source)


def _position(own: OwnShipStates, i: int) -> np.ndarray:
    """NED position of frame ``i``, m."""
    return np.array([own.north_m[i], own.east_m[i], own.down_m[i]])


def _body_to_ned(own: OwnShipStates, i: int, origin: tuple | None) -> np.ndarray:
    """Rotation of frame ``i`` from the body frame to the scenario NED frame."""
    body_to_ned = rotation_matrix(own.yaw_rad[i], own.pitch_rad[i], own.roll_rad[i])
    if origin is not None and own.has_geo:
        # Attitude is relative to the local vertical at the aircraft (as in the simulator).
        lat, lon = own.lat_deg[i], own.lon_deg[i]
        body_to_ned = ned_rotation_to(origin[0], origin[1], lat, lon).T @ body_to_ned
    return body_to_ned


def _to_world(
    out: dict[str, np.ndarray], own: OwnShipStates, i: int, config: RadarConfig, origin: tuple | None
) -> tuple[np.ndarray, tuple[np.ndarray, np.ndarray, np.ndarray], np.ndarray, np.ndarray, np.ndarray]:
    """NED position, geodetic position and NED unit direction of one frame's detections, the
    antenna's right axis in NED (3,), and the NED position of ``other_body_m`` (the runner-up
    residue's, NaN with one transmitter)."""
    pos, body_to_ned = _position(own, i), _body_to_ned(own, i, origin)
    body = np.stack([out["x_body_m"], out["y_body_m"], out["z_body_m"]], axis=1)
    ned = pos + body @ body_to_ned.T
    other_ned = pos + out["other_body_m"] @ body_to_ned.T
    ant_to_ned = body_to_ned @ config.mount.rotation
    u_ned = out["u_ant"] @ ant_to_ned.T
    geodetic = _geodetic_fn(own, i, origin)
    if geodetic is not None:
        geo = geodetic(ned)
    else:
        geo = (np.full(len(ned), np.nan), np.full(len(ned), np.nan), np.full(len(ned), np.nan))
    return ned, geo, u_ned, ant_to_ned[:, 1], other_ned


def _geodetic_fn(own: OwnShipStates, i: int, origin: tuple | None) -> GeodeticFn | None:
    """NED points -> (lat, lon, alt) for frame ``i``: from the scenario origin, else relative to the
    own-ship's geodetic fix (about 2 m off at 5 km); None with neither."""
    if origin is not None:
        return lambda points: ned_to_geodetic(points, *origin)
    if not own.has_geo:
        return None
    pos = _position(own, i)
    fix = (float(own.lat_deg[i]), float(own.lon_deg[i]), float(own.alt_m[i]))
    return lambda points: ned_to_geodetic(points - pos, *fix)


def _ground_flags(
    out: dict[str, np.ndarray],
    own: OwnShipStates | None,
    i: int,
    u_ned: np.ndarray | None,
    config: RadarConfig,
    terrain: Any,
    origin: tuple | None = None,
) -> np.ndarray:
    """Ground filter of one frame (:func:`skyradar.process.ground.flag_ground`).

    The surface is the terrain (DEM) under each detection, else (and beyond the DEM) a flat
    ground at the terrain height under the own-ship, from its navigated height above ground or
    the DEM; with neither, nothing is ground. A time-division MIMO radar's detection is ground too
    where its runner-up residue's direction is: the ground below the field of view (the altitude
    return, 30-80 deg down within 1.4 heights of range) is strong enough to be detected there, and
    the field of view, which chooses the residue, prefers the mirror near the horizontal: read so,
    it sits a few tens of metres above the own-ship with every Doppler of the folded image, and
    would start tracks near co-altitude that only the runner-up's direction explains.
    """
    n = len(out["range_m"])
    if own is None or n == 0:
        return np.zeros(n, bool)
    assert u_ned is not None  # found with own (_to_world)
    own_agl = float(own.height_agl_m[i])
    pos = _position(own, i)
    geodetic = _geodetic_fn(own, i, origin)
    located = geodetic is not None
    if terrain is not None and geodetic is not None and not np.isfinite(own_agl):
        own_agl = float(height_above_ground_m(*geodetic(pos[None]), terrain)[0])
    if not np.isfinite(own_agl):
        return np.zeros(n, bool)  # no terrain, no own-ship height: Doppler alone cannot decide
    height_fn = surface_height_fn(pos[2] + own_agl, terrain if located else None, geodetic)
    vel = np.array([own.vn_mps[i], own.ve_mps[i], own.vd_mps[i]])
    ant_to_ned = _body_to_ned(own, i, origin) @ config.mount.rotation
    flags = flag_ground(out, u_ned, vel, ant_to_ned, height_fn, own_agl, config)
    other = np.isfinite(out["other_u_ant"]).all(axis=1) & np.isfinite(out["other_down_m"]) & ~flags
    if other.any():
        mirror = {k: np.asarray(v)[other] for k, v in out.items() if np.ndim(v) >= 1 and len(v) == n}
        mirror |= {
            "azimuth_rad": mirror["other_azimuth_rad"],
            "elevation_rad": mirror["other_elevation_rad"],
            "north_m": mirror["other_north_m"],
            "east_m": mirror["other_east_m"],
            "down_m": mirror["other_down_m"],
            "u_ant": mirror["other_u_ant"],
        }
        u_mirror = mirror["u_ant"] @ ant_to_ned.T
        # The runner-up is a hypothesis: along it, as along its aliases, only the surface is ground.
        runner_up = (mirror, u_mirror, vel, ant_to_ned, height_fn, own_agl, config)
        flags[other] = flag_ground(*runner_up, hypothesis=True)
    return flags


def clutter_anchors(ds: xr.Dataset, terrain: Any = None, source: str = "frames") -> np.ndarray | None:
    """The clutter predictions' anchors of every frame of the run ``ds`` (None without own-ship state).

    For a run processed in blocks (``process_frames(block, anchors=...)``): each block is then
    suppressed as in the whole run (:mod:`skyradar.process.clutter_anchors`).
    """
    own = navigated_own_state(ds, source)
    return None if own is None else prediction_anchors(own, terrain)


def process_chunk(
    path: str,
    start: int,
    stop: int,
    spur_map: SpurMap | None = None,
    terrain: Any = None,
    method: Literal["cfar", "os-cfar", "shi-tomasi"] = "cfar",
    spur_mode: Literal["mask", "flag"] = "mask",
    progress: Callable[[int], None] | None = None,
    batch_frames: int = 16,
    **kwargs: Any,
) -> pd.DataFrame:
    """:func:`process_frames` on frames ``start:stop`` of the run at ``path`` (frame numbers kept).

    The unit of work for Dask workers: they open the run themselves. The own-ship state and the
    clutter predictions' anchors are the whole run's, so the rows equal the plain loop's. The
    other arguments are :func:`process_frames`'.
    """
    from skyradar.io.frames import open_frames

    return process_frames(
        open_frames(path),
        spur_map,
        terrain,
        method,
        spur_mode,
        progress,
        batch_frames,
        source=path,
        frames=slice(start, stop),
        **kwargs,
    )


def _checked_config(ds: xr.Dataset, config: RadarConfig | None, spur_map, source: str) -> RadarConfig:
    """The radar config to process ``ds`` with (the stored one unless given), checked against the frames."""
    stored = radar_config_of(ds, source)
    config = stored if config is None else config
    for name in ("n_range", "n_doppler", "n_rx"):
        if getattr(config, name) != getattr(stored, name):
            raise InputError(
                f"{source}: radar config field '{name}' is {getattr(config, name)}, "
                f"the frames have {getattr(stored, name)}"
            )
    if ds.sizes.get("time", 0) == 0:
        raise InputError(f"{source}: empty run (0 frames)")
    if ds.sizes.get("rx") != config.n_virtual:
        raise InputError(
            f"{source}: field 'rx' has {ds.sizes.get('rx')} channels, radar_config has {config.n_virtual}"
        )
    if spur_map is not None and spur_map.frequency.shape != config.frame_shape[:2]:
        raise InputError(f"{source}: spur map shape {spur_map.frequency.shape} does not fit the frames")
    return config


def _located(
    out: dict, time_s: float, i: int, own: OwnShipStates | None, origin, config: RadarConfig, terrain
) -> dict:
    """One frame's detections with time, frame, world position (NaN without own-ship) and ground flag."""
    n = len(out["range_m"])
    out["time_s"] = np.full(n, time_s)
    out["frame"] = np.full(n, i, np.int64)
    nan = np.full(n, np.nan)
    ned, geo, u_ned, right = (np.full((n, 3), np.nan), (nan, nan, nan), None, np.full(3, np.nan))
    other_ned = np.full((n, 3), np.nan)
    if own is not None:
        ned, geo, u_ned, right, other_ned = _to_world(out, own, i, config, origin)
    del out["other_body_m"]
    out.update(north_m=ned[:, 0], east_m=ned[:, 1], down_m=ned[:, 2])
    out.update(other_north_m=other_ned[:, 0], other_east_m=other_ned[:, 1], other_down_m=other_ned[:, 2])
    for axis, component in zip(("north", "east", "down"), right, strict=True):
        out[f"right_axis_{axis}"] = np.full(n, component)
    out.update(lat_deg=np.asarray(geo[0]), lon_deg=np.asarray(geo[1]), alt_m=np.asarray(geo[2]))
    out["is_ground"] = _ground_flags(out, own, i, u_ned, config, terrain, origin)
    return out


def process_frames(
    ds: xr.Dataset,
    spur_map: SpurMap | None = None,
    terrain: Any = None,
    method: Literal["cfar", "os-cfar", "shi-tomasi"] = "cfar",
    spur_mode: Literal["mask", "flag"] = "mask",
    progress: Callable[[int], None] | None = None,
    batch_frames: int = 16,
    source: str = "frames",
    config: RadarConfig | None = None,
    suppression: str = "none",
    frames: slice | None = None,
    anchors: np.ndarray | None = None,
    frame_costs: list[tuple[int, float, float]] | None = None,
    pfa_secondary: float | None = PFA_SECONDARY,
    **detect_kwargs: Any,
) -> pd.DataFrame:
    """Detections table of a frames Dataset (see the module docstring for the columns).

    Parameters
    ----------
    ds : xr.Dataset
        Frames Dataset (:func:`skyradar.io.frames.frames_dataset` / ``open_frames``).
    spur_map : SpurMap, optional
        Spur pixels are masked before detection (``spur_mode="mask"``) or detections inside the
        map are kept and flagged in the ``spur`` column (``"flag"``).
    terrain : Terrain or callable(lat, lon), optional
        Ground heights for the ground filter.
    progress : callable, optional
        Called with the number of frames finished after each batch.
    config : RadarConfig, optional
        Overrides the run's stored RadarConfig (e.g. one calibrated later); must fit the frames.
    suppression : {"none", "knowledge-aided", "auto"}
        Ground clutter suppression before detection (:mod:`skyradar.process.clutter_frames`):
        "auto" suppresses where the own-ship state allows, "knowledge-aided" requires it.
    frames, anchors : slice and ndarray (n_frames, 6), optional
        Only ``frames`` of ``ds`` (a Dask chunk: frame numbers, own-ship state and clutter
        predictions stay the whole run's); ``anchors`` of a block of a longer run (:func:`clutter_anchors`).
    frame_costs : list, optional
        Receives ``(frame, time_s, processing_s)`` per frame: the wall time from the frame's clutter
        prediction to its located detections (reading the frames from the store is not included).
    pfa_secondary : float or None
        With suppression, the false-alarm probability of the secondary threshold in nulled cells
        (:func:`skyradar.process.detect.detect`; rows flagged ``secondary``, which the tracker
        uses only inside a confirmed track's gate); None, or not above ``pfa``: none.
    """
    config = _checked_config(ds, config, spur_map, source)
    first, stop, _ = (frames or slice(None)).indices(ds.sizes["time"])
    own, origin = navigated_own_state(ds, source), scenario_origin(ds)
    times = frame_times_s(ds)
    if anchors is None and own is not None and suppression in ("knowledge-aided", "auto"):
        anchors = prediction_anchors(own, terrain, stop)  # walked from frame 0: chunking changes nothing
    rows: list[dict[str, np.ndarray]] = []
    for start in range(first, stop, batch_frames):
        block = np.asarray(ds["iq"].isel(time=slice(start, min(start + batch_frames, stop))).values)
        check_finite_frames(block, start, source)
        for offset, cube in enumerate(block):
            i = start + offset
            began = time.perf_counter()
            try:
                clutter = frame_clutter(suppression, own, i, config, terrain, anchors)
                out = process_cube(
                    cube,
                    config,
                    spur_map,
                    method,
                    spur_mode,
                    clutter,
                    pfa_secondary=pfa_secondary,
                    **detect_kwargs,
                )
            except InputError as exc:  # e.g. CFAR windows that do not fit: say which run
                raise InputError(f"{source}: {exc}") from None
            rows.append(_located(out, times[i], i, own, origin, config, terrain))
            if frame_costs is not None:
                frame_costs.append((i, float(times[i]), time.perf_counter() - began))
        if progress is not None:
            progress(min(start + batch_frames, stop) - first)
    table = pd.DataFrame({c: np.concatenate([r[c] for r in rows]) for c in DETECTION_COLUMNS})
    table.attrs["navigation_source"] = None if own is None else own.navigation_source
    return table
