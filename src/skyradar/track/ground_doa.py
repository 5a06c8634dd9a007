"""Direction-of-arrival evidence of tracks: for the ground test and the altitude flag.

The ground test is :mod:`skyradar.track.ground_tracks`.

A detection's direction says where a track is only when its elevation was measured: after two
clutter nulls the 2x2 array often cannot measure it and ``process.clutter_doa`` places the
detection co-altitude (elevation 0) with ``elevation_measured`` False. Such a prior is no evidence
of height either way, so each rule here counts measured elevations only.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from skyradar.config import RadarConfig
from skyradar.process.clutter_suppress import default_max_nulls

DOA_COLUMNS = ("azimuth_rad", "elevation_rad", "north_m", "east_m", "down_m", "elevation_measured")
# The antenna's right axis in NED: the azimuth is measured about it (``process.pipeline``).
AXIS_COLUMNS = ("right_axis_north", "right_axis_east", "right_axis_down")
DOA_SIGMA_RAD = float(np.radians(2.0))  # CRLB at 13-20 dB plus attitude errors
DOA_FIELD_RAD = float(np.radians(45.0))  # half-angle of boresight inside which that holds
# A direction (and the track's height) counts as measured when this many of its last detections had
# a measured elevation: one rule for the ground test and the tracks' altitude flag.
MEASURED_LEAST, MEASURED_WINDOW = 3, 10

__all__ = [
    "DOA_COLUMNS",
    "AXIS_COLUMNS",
    "doa_height_sd",
    "azimuth_off_static_points",
    "doa_in_the_air",
    "direction_measured",
    "doa_on_the_ground",
    "doa_of_a_ground_patch",
    "directions_tell_patches",
    "altitude_measured",
    "elevation_measured_flags",
]


def doa_height_sd(det: np.ndarray, surface_down, sigma_rad: float = DOA_SIGMA_RAD) -> list[np.ndarray]:
    """Azimuth and elevation (antenna frame) of each detection, its DoA position's height above
    the surface in standard deviations (range x ``sigma_rad``, 10 m for the surface), whether its
    elevation was measured (:func:`elevation_measured_flags` says how the column is read) and the
    antenna's right axis in NED (k, 3; NaN where ``det`` does not have it).

    ``det`` columns: time, range, radial velocity, then :data:`DOA_COLUMNS`, optionally
    :data:`AXIS_COLUMNS`; ``surface_down`` maps NE points (k, 2) to the ground's ``down``, m.

    Examples
    --------
    >>> det = np.array([[0.0, 1000.0, 5.0, 0.1, -0.5, 800.0, 0.0, 480.0, 1.0]])
    >>> az, el, z, measured, right = doa_height_sd(det, lambda ne: np.full(len(ne), 500.0))
    >>> round(float(z[0]), 2), bool(measured[0])  # 20 m above ground, sd hypot(35, 10) m
    (0.55, True)
    """
    az, el, measured = det[:, 3], det[:, 4], det[:, 8] == 1.0
    right = det[:, 9:12] if det.shape[1] >= 12 else np.full((len(det), 3), np.nan)
    if surface_down is None or not np.isfinite(det[:, 5:8]).any():
        return [az, el, np.full(az.size, np.nan), measured, right]
    with np.errstate(invalid="ignore"):
        height = surface_down(np.nan_to_num(det[:, 5:7])) - det[:, 7]
        return [az, el, height / np.hypot(det[:, 1] * sigma_rad, 10.0), measured, right]


def azimuth_off_static_points(
    azimuth_rad,
    elevation_rad,
    right_axis,
    own_position_m,
    points_ned,
    sigma_rad: float = DOA_SIGMA_RAD,
    field_rad: float = DOA_FIELD_RAD,
    n: int = 10,
    min_sd: float = 4.0,
) -> bool:
    """Whether a track's recent azimuths say, reliably, that it is none of the static ground points
    that explain its range and Doppler.

    The array measures the direction cosine along the antenna's right axis,
    ``sin(azimuth) cos(elevation)``, even where clutter suppression left the elevation unobservable
    (``process.clutter_doa`` searches the cone of that cosine). A static point ``P`` seen from
    ``o`` has the cosine ``(P - o) / |P - o| . right``. Of the last ``n`` detections at least half
    and five must lie inside the field (``field_rad`` of boresight) with a known right axis; their
    cosines must agree (robust spread within 3 sd, the sd being ``sigma_rad cos(azimuth)``: one
    direction, not residual clutter scattered over the beam), and their median must lie ``min_sd``
    sd or more beyond every point's on one side. Between two points is not enough: a cell holding
    ground left and right of the own-ship's track reads, after its nulls, a direction in between.
    Beyond them no static point the history allows, nor a mix of them, sits where the track is
    seen: it is an object. An aircraft whose speed relative to the own-ship equals the
    own-ship's has a static point's range-Doppler history, and the nulls of its ground cell may
    leave its elevation unmeasured; its azimuth still tells it from that point's.

    Parameters
    ----------
    azimuth_rad, elevation_rad : array_like, shape (k,)
        Directions of arrival in the antenna frame, rad (elevation 0 where it was not measured).
    right_axis : array_like, shape (k, 3)
        The antenna's right axis in NED at each detection.
    own_position_m : array_like, shape (k, 3)
        Own-ship NED position at each detection, m.
    points_ned : array_like, shape (m, 3)
        Static points that explain the history (:func:`skyradar.track.static_point.static_ground_points`).
    sigma_rad, field_rad : float
        Azimuth error and the half-angle of boresight inside which it holds, rad.
    n : int
        Detections read, the newest.
    min_sd : float
        Least distance from every point's cosine, in sd.

    Returns
    -------
    bool

    Examples
    --------
    Ground 300 m below, 2 km ahead at +-25 deg fits the history; the track is seen at 36 deg, then
    at 24.6 deg (where the point on the right is), then at 0 deg (between the two):

    >>> rng = np.random.default_rng(0)
    >>> own, right = np.zeros((10, 3)), np.tile([0.0, 1.0, 0.0], (10, 1))
    >>> points = np.array([[1780.0, 830.0, 300.0], [1780.0, -830.0, 300.0]])
    >>> seen = np.radians(36.0) + rng.normal(0, 0.02, 10)
    >>> azimuth_off_static_points(seen, np.zeros(10), right, own, points)
    True
    >>> on_the_point = seen - np.radians(36.0 - 24.6)
    >>> azimuth_off_static_points(on_the_point, np.zeros(10), right, own, points)
    False
    >>> azimuth_off_static_points(seen - np.radians(36.0), np.zeros(10), right, own, points)
    False
    """
    az, el = (np.asarray(a, float)[-n:] for a in (azimuth_rad, elevation_rad))
    right = np.asarray(right_axis, float).reshape(-1, 3)[-n:]
    own = np.asarray(own_position_m, float).reshape(-1, 3)[-n:]
    points = np.asarray(points_ned, float).reshape(-1, 3)
    with np.errstate(invalid="ignore"):
        inside = (np.abs(az) <= field_rad) & (np.abs(el) <= field_rad) & np.isfinite(right).all(axis=1)
    if points.size == 0 or inside.sum() < max(5, az.size // 2):
        return False
    cosine = (np.sin(az) * np.cos(el))[inside]
    sd = sigma_rad * float(np.median(np.cos(az[inside])))
    if 1.4826 * np.median(np.abs(cosine - np.median(cosine))) > 3.0 * sd:
        return False
    sight = points[:, None, :] - own[inside][None]  # (m, k, 3)
    point_cosine = np.sum(sight * right[inside][None], axis=2) / np.linalg.norm(sight, axis=2)
    off = np.median(cosine[None] - point_cosine, axis=1)  # each point's, signed
    return bool(np.all(off >= min_sd * sd) or np.all(off <= -min_sd * sd))


def doa_in_the_air(
    azimuth_rad,
    elevation_rad,
    height_sd,
    elevation_measured=None,
    sigma_rad: float = DOA_SIGMA_RAD,
    field_rad: float = DOA_FIELD_RAD,
    n: int = 10,
) -> bool:
    """Whether a track's recent directions of arrival say, reliably, that it flies above the ground.

    Of its last ``n`` detections, at least half and five must have a measured elevation
    (``elevation_measured``, default all; ``process.clutter_doa``'s prior of elevation 0 says
    nothing of the height) and lie inside the field
    (``field_rad`` of boresight), their azimuth and elevation must agree (robust spread within
    3 ``sigma_rad``: one direction, not residual clutter or ground beside the track scattered
    over the beam) and their median height above the surface must be 3 sd or more
    (``height_sd``: height / sd). Such a track keeps its confirmation even when a static ground
    point also fits its range and Doppler: an aircraft whose speed relative to the own-ship equals
    the own-ship's (a converging one at 60 deg, say) fits a static point as long as it flies straight.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> az, el = 0.3 + rng.normal(0, 0.02, 10), rng.normal(0, 0.02, 10)
    >>> scattered = rng.uniform(-0.6, 0.6, 10)  # residual clutter over the beam
    >>> doa_in_the_air(az, el, np.full(10, 6.0)), doa_in_the_air(scattered, el, np.full(10, 6.0))
    (True, False)
    >>> prior = np.zeros(10, bool)  # elevation 0 placed by the chain, not measured
    >>> doa_in_the_air(az, np.zeros(10), np.full(10, 6.0), prior)
    False
    """
    az, el, z = (np.asarray(a, float)[-n:] for a in (azimuth_rad, elevation_rad, height_sd))
    measured = (
        np.ones(az.size, bool) if elevation_measured is None else np.asarray(elevation_measured, bool)[-n:]
    )
    with np.errstate(invalid="ignore"):
        inside = (np.abs(az) <= field_rad) & (np.abs(el) <= field_rad) & np.isfinite(z)
        inside &= measured
    if inside.sum() < max(5, az.size // 2):
        return False
    spread = max(1.4826 * np.median(np.abs(a[inside] - np.median(a[inside]))) for a in (az, el))
    return bool(spread <= 3.0 * sigma_rad and np.median(z[inside]) >= 3.0)


def direction_measured(elevation_measured, n: int = MEASURED_WINDOW, least: int = MEASURED_LEAST) -> bool:
    """Whether at least ``least`` of a track's last ``n`` detections have a measured elevation.

    Examples
    --------
    >>> direction_measured(np.array([True, False, True, True])), direction_measured(np.zeros(9, bool))
    (True, False)
    """
    return bool(np.count_nonzero(np.asarray(elevation_measured, bool)[-n:]) >= least)


def doa_on_the_ground(elevation_measured, height_sd, n: int = 10, max_sd: float = 1.0) -> bool:
    """Whether a track's recent measured directions of arrival put it on the surface.

    Of its last ``n`` detections, those with a measured elevation (``elevation_measured``; not
    ``process.clutter_doa``'s prior of elevation 0) and a height above the surface (``height_sd``,
    in sd) count: at least
    three, and their median height is below ``max_sd``. Azimuths may scatter (ground beside the
    track in one cell). Not proof of ground: an aircraft in a ground cell can read the ground's
    direction too (a co-altitude intruder over flat ground 300 m below reads the ground's
    depression); so it only asks for more detections.

    Examples
    --------
    >>> measured = np.array([True, False, True, True])  # the second: elevation 0 as a prior
    >>> doa_on_the_ground(measured, np.array([0.4, 11.0, -0.3, 0.9]))
    True
    >>> doa_on_the_ground(measured, np.array([7.0, 11.0, 12.0, 26.0]))
    False
    """
    z = np.asarray(height_sd, float)[-n:]
    measured = np.asarray(elevation_measured, bool)[-n:] & np.isfinite(z)
    return bool(measured.sum() >= 3 and np.median(z[measured]) < max_sd)


def doa_of_a_ground_patch(
    azimuth_rad,
    elevation_rad,
    elevation_measured,
    height_sd,
    sigma_rad: float = DOA_SIGMA_RAD,
    n: int = 10,
) -> bool:
    """Whether a track's recent directions of arrival are those of a ground patch's scatterers.

    Of its last ``n`` detections, the measured elevations put it on the surface
    (:func:`doa_on_the_ground`) and the direction cosines along the antenna's right axis,
    ``sin(azimuth) cos(elevation)``, scatter beyond one direction: their rms about the median, the
    worst fifth left out (an aircraft's odd reading through a sidelobe), exceeds 3 sd, the sd being
    ``sigma_rad cos(azimuth)`` at the median azimuth. A patch's scatterers cluster (two or three
    readings from near one azimuth, then others far off), so a median absolute deviation, which
    ignores half the readings, can miss it.

    Each half alone is no proof: an aircraft in a ground cell can read the ground's elevation (the
    cell's mixture pulls it down) but it keeps one azimuth, which the array measures whatever the
    elevation; an aircraft read through the nulls over relief scatters in azimuth but reads above
    the surface. Residual clutter of a patch, its scatterers taking turns left and right of the
    own-ship's track, reads the surface and scatters across the beam: both at once.

    Parameters
    ----------
    azimuth_rad, elevation_rad : array_like, shape (k,)
        Directions of arrival in the antenna frame, rad.
    elevation_measured : array_like of bool, shape (k,)
        Whether each elevation was measured (not ``process.clutter_doa``'s prior).
    height_sd : array_like, shape (k,)
        Each DoA position's height above the surface in sd (:func:`doa_height_sd`).
    sigma_rad : float
        Direction error of one point target's detections, rad.
    n : int
        Detections read, the newest.

    Returns
    -------
    bool

    Examples
    --------
    Ground 300 m below, 2 km away (8.6 deg down): readings at that elevation, first from one
    azimuth, then from scatterers 30 deg left and 60 deg right taking turns:

    >>> el, on = np.full(6, np.radians(-8.6)), np.full(6, True)
    >>> steady = np.radians([20.0, 20.5, 19.6, 20.2, 19.9, 20.1])
    >>> doa_of_a_ground_patch(steady, el, on, np.zeros(6))
    False
    >>> doa_of_a_ground_patch(np.radians([-30.0, -29.0, -48.0, -33.0, 64.0, 64.5]), el, on, np.zeros(6))
    True
    """
    az, el = (np.asarray(a, float)[-n:] for a in (azimuth_rad, elevation_rad))
    if not doa_on_the_ground(np.asarray(elevation_measured, bool)[-n:], np.asarray(height_sd, float)[-n:]):
        return False
    cosine = np.sin(az) * np.cos(el)
    sd = sigma_rad * float(np.median(np.cos(az)))
    z2 = np.sort(((cosine - np.median(cosine)) / sd) ** 2)
    return bool(np.mean(z2[: z2.size - z2.size // 5]) > 9.0)


def directions_tell_patches(config: RadarConfig) -> bool:
    """Whether an array's directions in a ground cell can tell a patch's scatterers from an aircraft.

    True when three or more channels are left after the cell's clutter nulls
    (:func:`skyradar.process.clutter_suppress.default_max_nulls`): two to measure a direction, one
    more to see that one plane wave explains the pixel. With two left (the 2x2 square, the kite)
    the residual ground of a cell over relief pulls an aircraft's measured elevation onto the
    surface and scatters its azimuth at once: a co-altitude closure over hills, five detections in,
    read -3 to -19 deg and direction cosines from +0.38 to -0.48. There
    :func:`doa_of_a_ground_patch` is no evidence.

    Parameters
    ----------
    config : RadarConfig
        The radar (its receive, or MIMO virtual, channels).

    Returns
    -------
    bool

    Examples
    --------
    >>> [directions_tell_patches(RadarConfig.prototype_2022(rx_positions_m=a)) for a in ("square", "ura-2x3")]
    [False, True]
    """
    n = config.n_virtual
    return n - default_max_nulls(n, config.n_tx) >= 3


def altitude_measured(
    track_id: np.ndarray,
    detection_row: np.ndarray,
    detections: pd.DataFrame,
    n: int = MEASURED_WINDOW,
    least: int = MEASURED_LEAST,
) -> np.ndarray:
    """Per row of a tracks table: whether its altitude rests on measured elevations.

    True where at least ``least`` of the track's last ``n`` detections up to that row (rows in
    time order) had a measured elevation (:func:`direction_measured`'s rule). Where the nulls left
    every elevation unmeasured, the track flies at ``process.clutter_doa``'s co-altitude prior: its
    height is an assumption, and an alert on it says so. Each detection's flag is read by
    :func:`elevation_measured_flags`; a table without 3-D positions (``north_m``) measures no altitude.

    Examples
    --------
    >>> det = pd.DataFrame({"north_m": 0.0, "elevation_measured": [True, True, False, True]})
    >>> altitude_measured(np.array([1, 1, 1, 1, 1]), np.array([0, 1, -1, 2, 3]), det, least=2).tolist()
    [False, True, True, True, True]
    """
    ids, rows = np.asarray(track_id), np.asarray(detection_row)
    per_detection = elevation_measured_flags(detections) & ("north_m" in detections.columns)
    has = rows >= 0
    measured = np.zeros(rows.size, bool)
    measured[has] = per_detection[rows[has]]
    out = np.zeros(rows.size, bool)
    for idx in pd.Series(ids).groupby(ids, sort=False).indices.values():
        seen = np.cumsum(has[idx])  # detections of the track up to each row
        counted = np.concatenate([[0], np.cumsum(measured[idx][has[idx]])])
        out[idx] = counted[seen] - counted[np.maximum(seen - n, 0)] >= least
    return out


def elevation_measured_flags(detections: pd.DataFrame) -> np.ndarray:
    """Whether each detection's elevation was measured: the one reading of the column for every rule.

    The ``elevation_measured`` column where the table has it, a missing value counting as not
    measured; tables without the column were processed without clutter suppression (or written by
    other tools): every elevation they hold was measured.

    Examples
    --------
    >>> elevation_measured_flags(pd.DataFrame({"elevation_measured": [True, None, False]})).tolist()
    [True, False, False]
    >>> elevation_measured_flags(pd.DataFrame({"elevation_rad": [0.1, -0.2]})).tolist()
    [True, True]
    """
    if "elevation_measured" in detections.columns:
        flags = detections["elevation_measured"]
        return flags.where(flags.notna(), False).to_numpy(bool)
    return np.ones(len(detections), bool)
