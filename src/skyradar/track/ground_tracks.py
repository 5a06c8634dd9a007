"""Tracks the ground explains are held back from confirmation: a track-level ground test.

A detection's direction can be wrong (sidelobe ground, ground left and right of the track in one
cell, the residual of clutter suppression), but its range and Doppler are measured to a pixel, and
the own-ship's motion fixes the range and Doppler history of every static point: for a point ``P``
seen from ``o(t)`` moving at ``v(t)``, ``r = |P - o|`` and ``dr/dt = -(P - o) . v / r`` (the
apparent range is ``r + c dr/dt``, range-Doppler coupling ``c``). A track is *ground* while a
single static point on the surface explains its whole history of detections (range, and Doppler
modulo the image width ``2 VLim``) within the measurement errors (:func:`fits_static_ground`),
whatever its DoA said. A track is *not an object* while its ranges contradict its Doppler: for
every real scatterer ``dr/dt`` is its (de-aliased) radial velocity (:func:`range_doppler_consistent`);
residual clutter hopping between cells fails this. Nor is it one object while its Doppler does not
follow one smooth curve (:func:`doppler_smooth`): a point's radial velocity is measured to a few
hundredths of a m/s (CRLB at 13 dB: 0.027 m/s) and changes by about 1 m/s^2; the scatterers of a
ground patch that take turns in one track (over relief, at the alias edge, with scattered
directions and no single static point fitting them) jump by a Doppler bin. A track whose measured
elevations put it on the surface (:func:`doa_on_the_ground`) needs ten detections, not three,
before these tests may release it: some alias fits three hopping ranges, and the Doppler test
needs its full window.

A track whose range closes faster than any static point's can is an object, whatever its aliased
Doppler says (:func:`faster_than_ground`): a static point's range rate is bounded by
the own-ship's speed, ``|dr/dt| <= |v|``, and the range history tells which alias of the measured
Doppler is the true radial velocity. A head-on closure at 107 m/s aliases into the band the ground
ahead fills, but its range falls by a whole image width (78 m/s) faster than the ground's of the
same Doppler: over five detections at 9.4 frames/s that is 33 m, six times the slope's error. Such
a track is judged an object at its fifth detection, the most urgent geometry there is released
first; a track whose radial velocity lies inside the ground's band keeps the slower tests below.
The release has two limits, both because a ground patch fills one Doppler bin over many ranges
and the tracker can string its scatterers along a line of almost any slope, one that some alias
then fits. It is for closures: a history receding faster than the ground is no threat and waits
for the slower tests. And, on an array with three or more channels left after the clutter nulls
(:func:`~skyradar.track.ground_doa.directions_tell_patches`, ``GroundTrackTest.patch_directions``),
it does not overrule directions that are a patch's (:func:`doa_of_a_ground_patch`): measured
elevations on the surface while the azimuths scatter across the beam; there an aircraft keeps one
azimuth even when its cell's mixture pulls its elevation down. On such arrays those directions
hold a track at any age, in the slower tests too: a patch strung along a steep line is fitted by
no single static point once its history outgrows the first detections, and the scatterers taking
turns are what its directions show. With two channels left (the 2x2 square) an aircraft over
relief can read both ways at once, so the range rate and the static fit alone decide.

Why aircraft are kept: in straight flight the history of a point moving at relative velocity
``w`` has ``d(r dr/dt)/dt = |w|^2``, a static point's ``|v|^2``; so an aircraft fits a static
point only while its relative speed equals the own-ship's speed, and then that point lies at its
miss distance from the own-ship's line of flight: it can be ground only when that miss distance
reaches the terrain. A circling aircraft's ``w`` turns and fits no static point. The price is
time: an aircraft inside the ground's range-Doppler band is held until its history departs from
a static point's (about 1.5 s for a 20 m/s relative-speed difference; a converging aircraft at
46.5 m/s against the own-ship's 50 m/s, 550 m miss over ground 300 m below, is held 7 s and
warned after its loss of well clear). So a direction of arrival that says, reliably and
consistently, that the track flies above the ground overrules the static fit
(:func:`doa_in_the_air`); sidelobe ground read as air with a consistent wrong direction then
stays a track. An elevation that clutter suppression left unobservable (``process.clutter_doa``
places it co-altitude) is no evidence either way: it neither overrules the static fit (its prior
elevation 0 with a steady azimuth looks like "one direction in the air" and would release ground
patches over hills) nor holds a track by itself. Its azimuth is: the array measures the direction
cosine along the antenna's right axis whatever the elevation, and a track seen, consistently, where
none of the static points that fit its history is (:func:`azimuth_off_static_points`) is an object.

:func:`hold_ground_tracks` applies both tests causally (a row uses only the detections up to it)
to a tracks table: rows of a track while the ground explains it, or while it is not an object,
are not ``confirmed``; a track never confirmed is dropped, like a tentative track.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from skyradar.config import RadarConfig
from skyradar.quantiles import chi2_upper_quantile, normal_upper_quantile
from skyradar.track.dealias import alias_count
from skyradar.track.ground_doa import (
    AXIS_COLUMNS,
    DOA_COLUMNS,
    DOA_FIELD_RAD,
    DOA_SIGMA_RAD,
    azimuth_off_static_points,
    direction_measured,
    directions_tell_patches,
    doa_height_sd,
    doa_in_the_air,
    doa_of_a_ground_patch,
    doa_on_the_ground,
    elevation_measured_flags,
)
from skyradar.track.static_point import (
    fits_static_ground,
    flat_surface,
    static_ground_points,
    static_point_measurements,
    terrain_surface,
    trimmed_sum,
)

_CLEAR_S = 3.0  # judged an object off the ground this long on end: not judged again
_SPIKE_MIN_DETECTIONS = 6  # a Doppler history this long may leave out one detection and still test a curve

# Why a track row is not confirmed (the tracks table's ``held_by``; "" when it is confirmed).
HOLD_REASONS: dict[str, str] = {
    "": "confirmed",
    "tentative": "the tracker's M-of-N confirmation is not met yet",
    "coasting": "no detection for as many frames as confirmation takes: an extrapolation",
    "young": "too few detections for the ground test to judge it",
    "range": "its ranges contradict its Doppler (not one scatterer)",
    "rough": "its Doppler is not one smooth curve (scatterers of a patch taking turns)",
    "direction": "its measured elevations put it on the surface, or none is measured, or its directions "
    "are a ground patch's",
    "ground": "a static point on the surface explains its range-Doppler history and is where it is seen",
    "ground-release": "a static ground point fitted it; judged an object for too short a span yet",
}

__all__ = [
    "HOLD_REASONS",
    "GroundTrackTest",
    "default_ground_test",
    "static_point_measurements",
    "fits_static_ground",
    "range_doppler_consistent",
    "hold_ground_tracks",
    "TrackHoldWalk",
    "faster_than_ground",
    "flat_surface",
    "terrain_surface",
    "doa_in_the_air",
    "azimuth_off_static_points",
    "static_ground_points",
    "doppler_smooth",
    "doa_on_the_ground",
    "direction_measured",
    "median_ground_down_m",
]


@dataclass(frozen=True)
class GroundTrackTest:
    """Settings of the track-level ground test.

    Parameters
    ----------
    sigma_range_m, sigma_velocity_mps : float
        Errors of one detection's range (half a 15 m bin: straddle, window sidelobes, own-ship
        position), m, and radial velocity (half a Doppler bin and the own-ship's velocity error),
        m/s.
    tail : float
        False-rejection probability of each chi-square test.
    trim : float
        Fraction of the worst-fitting detections left out of each fit (another scatterer of the
        same clutter patch, a noise hit in the gate).
    min_detections : int
        Detections of a track in the table (its first one starts it and is not there) before it
        can be judged; fewer: held.
    release_detections : int
        Detections before a track judged an object is released. Five, not three: three hits of
        residual clutter on different scatterers can fit a range line through some Doppler alias
        and confirm a clutter track for half a second. Judging still starts at
        ``min_detections``, so a static fit seen at the third detection counts (an altitude
        return can be judged an object first at its fifth).
    release_span_detections : int
        Detections a run of "object" verdicts must span to release a track a static ground point
        fitted. A ground patch 2.7-3.1 km away read a few degrees off its azimuth over a valley
        gives a few verdicts in a row that say "in the air"; successive judgements share 9 of 10
        directions, so a release needs verdicts spanning three detections. Five would cost a fast
        head-on intruder whose aliased Doppler fits a static point 1.4 s of warning; three cost it
        0.3 s.
    max_history : int
        The most recent detections a fit uses.
    surface_down : callable, optional
        NE points (k, 2) -> ``down`` of the ground surface, m (:func:`terrain_surface`); default:
        a level ground at the own-ship's ``own_height_agl_m``.
    rejudge_gap_s : float
        A gap between two detections of a track longer than this (the tracker's coasting time)
        starts its history again: across it the track was reacquired on a prediction, and the
        detections before may come from another scatterer (residual clutter joined to residual
        clutter made one "object" receding at 110 m/s over hills), s.
    doa_sigma_rad, doa_field_rad : float
        A direction of arrival this accurate (CRLB at 13-20 dB plus attitude errors) inside this
        half-angle of boresight may overrule the static-ground fit (:func:`doa_in_the_air`), rad.
    point_sigma_velocity_mps : float or None
        Doppler error of one point target's detections about a smooth curve (the radial velocity
        as measured, without the own-ship's velocity error), m/s: a track whose Doppler scatters
        more is not one object (:func:`doppler_smooth`); None: that test is off.
    ground_min_detections : int
        Detections a track needs, instead of ``min_detections``, while its measured directions put
        it on the surface (:func:`doa_on_the_ground`) or while it has no measured direction (fewer
        than three measured elevations of its last ten: ground left and right of it in every cell):
        three cannot tell residual clutter hopping between cells (its ranges fit some alias) from
        an object; ten fill the Doppler test's window.
    sigma_range_jitter_m : float
        Error of one detection's range about its neighbours' within a second (sub-bin
        interpolation and straddle at 13 dB and more), m; the own-ship's position error, common
        to those detections, is not in it. The range-rate test (:func:`faster_than_ground`)
        uses it.
    patch_directions : bool
        Directions a ground patch's scatterers give (:func:`doa_of_a_ground_patch`) hold a track,
        at any age and against the early release of a closure faster than the ground; only for
        arrays whose directions in a ground cell can tell a patch from an aircraft
        (:func:`~skyradar.track.ground_doa.directions_tell_patches`).
    fast_min_detections : int
        Detections a history needs before its range rate may judge it faster than the ground.
        Over five detections at 9.4 frames/s the slope is known to 12 m/s, a sixth of the image
        width between two aliases; over three or four, ranges of residual clutter hopping between
        cells fit a steep line.

    Examples
    --------
    A track closing at 50 m/s, its ranges following its Doppler, with no own-ship state (only the
    range-Doppler test applies): held while young, released at ``release_detections``; an earlier
    release with a looser test.

    >>> k = np.arange(8)
    >>> det = pd.DataFrame({"time_s": 0.1 * k, "range_m": 1000.0 - 5.0 * k, "radial_velocity_mps": -50.0})
    >>> tracks = pd.DataFrame({"time_s": 0.1 * k, "track_id": 1, "detection_row": k, "confirmed": True})
    >>> hold_ground_tracks(tracks, det, None, 78.3, 0.0)["held_by"].tolist()
    ['young', 'young', 'young', 'young', '', '', '', '']
    >>> test = GroundTrackTest(min_detections=2, release_detections=3)
    >>> hold_ground_tracks(tracks, det, None, 78.3, 0.0, test=test)["held_by"].tolist()[:4]
    ['young', 'direction', '', '']
    """

    sigma_range_m: float = 8.0
    sigma_velocity_mps: float = 0.25
    tail: float = 1e-3
    trim: float = 0.1
    min_detections: int = 3
    release_detections: int = 5
    release_span_detections: int = 3
    max_history: int = 120
    surface_down: Callable[[np.ndarray], np.ndarray] | None = None
    rejudge_gap_s: float = 2.0
    doa_sigma_rad: float = DOA_SIGMA_RAD
    doa_field_rad: float = DOA_FIELD_RAD
    point_sigma_velocity_mps: float | None = 0.1
    ground_min_detections: int = 10
    sigma_range_jitter_m: float = 4.0
    fast_min_detections: int = 5
    patch_directions: bool = False


def default_ground_test(
    config: RadarConfig, surface_down: Callable[[np.ndarray], np.ndarray] | None = None
) -> GroundTrackTest:
    """The ground test for a radar: :class:`GroundTrackTest`'s settings, ``surface_down`` (default a
    level ground at the own-ship's height above it) and the patch-direction rule where the array's
    directions can tell a patch (:func:`~skyradar.track.ground_doa.directions_tell_patches`).

    Examples
    --------
    >>> default_ground_test(RadarConfig.prototype_2022()).patch_directions
    False
    >>> default_ground_test(RadarConfig.prototype_2022(rx_positions_m="ura-2x3")).patch_directions
    True
    """
    return GroundTrackTest(surface_down=surface_down, patch_directions=directions_tell_patches(config))


def _doppler_path(
    t: np.ndarray, radial_velocity_mps: np.ndarray, width_mps: float, coupling_s: float
) -> tuple[np.ndarray, np.ndarray]:
    """The radial velocities unwrapped by continuity, and the apparent range change they make from the
    first detection (their time integral plus the range-Doppler coupling's change), m."""
    v = np.unwrap(np.asarray(radial_velocity_mps, float), period=width_mps)
    moved = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))]) + coupling_s * (v - v[0])
    return v, moved


def range_doppler_consistent(
    time_s: np.ndarray,
    range_m: np.ndarray,
    radial_velocity_mps: np.ndarray,
    width_mps: float,
    coupling_s: float,
    test: GroundTrackTest | None = None,
    max_alias: int | None = None,
) -> bool:
    """Whether a detection history's ranges follow its Doppler: ``dr/dt`` is the de-aliased radial velocity.

    The radial velocities are unwrapped by continuity, integrated over time, and shifted by a
    whole number of image widths (the alias, ``|k| <= max_alias``, by default the image's
    :func:`~skyradar.track.dealias.alias_count`); the apparent ranges must follow within the range
    error (trimmed chi-square).

    Examples
    --------
    >>> t = np.arange(10) * 0.1
    >>> range_doppler_consistent(t, 3000.0 - 90.0 * t, np.full(10, -90.0 + 78.3), 78.3, 0.19)
    True
    >>> hops = np.array([0.0, 24.0, 80.0, 420.0, 300.0, 310.0, 390.0, 200.0, 260.0, 150.0])
    >>> range_doppler_consistent(t, 3000.0 + hops, np.full(10, 33.0), 78.3, 0.19)  # residual clutter
    False
    """
    test = test or GroundTrackTest()
    t = np.asarray(time_s, float)
    rng = np.asarray(range_m, float)
    _, moved = _doppler_path(t, radial_velocity_mps, width_mps, coupling_s)
    limit = chi2_upper_quantile(test.tail, max(rng.size - int(np.floor(test.trim * rng.size)) - 1, 1))
    max_alias = alias_count(width_mps) if max_alias is None else max_alias
    for k in range(-max_alias, max_alias + 1):
        res = rng - moved - k * width_mps * (t - t[0])
        z2 = ((res - np.median(res)) / test.sigma_range_m) ** 2
        if trimmed_sum(z2, test.trim)[0] <= limit:
            return True
    return False


def faster_than_ground(
    time_s: np.ndarray,
    range_m: np.ndarray,
    radial_velocity_mps: np.ndarray,
    own_speed_mps: np.ndarray,
    width_mps: float,
    coupling_s: float,
    test: GroundTrackTest | None = None,
    max_alias: int | None = None,
    closing: bool = False,
) -> bool:
    """Whether a detection history is one scatterer whose range moves faster than any static point's.

    The apparent ranges minus the integrated (unwrapped) Doppler leave ``k * width * t`` for the
    alias ``k`` of the true radial velocity; its least-squares slope, with the error
    ``sigma_range_jitter_m / sqrt(sum (t - mean t)^2)``, decides which aliases the range history
    allows (``|slope - k width| <= z sigma``, ``z`` the normal quantile of ``test.tail``). A static
    point's radial velocity never exceeds the own-ship's speed (plus ``z`` Doppler errors) at any
    detection; the history is faster than the ground when no such alias is allowed, one alias is,
    and the ranges follow that alias within ``sigma_range_jitter_m`` (trimmed chi-square: one
    scatterer, not a patch's ranges hopping between cells).

    Parameters
    ----------
    time_s, range_m, radial_velocity_mps : ndarray, shape (k,)
        Detection times (s), apparent ranges (m) and aliased radial velocities (m/s, positive
        receding).
    own_speed_mps : ndarray, shape (k,)
        Own-ship's speed (3-D norm of its velocity) at the detections, m/s.
    width_mps : float
        Doppler image width, ``2 VLim``, m/s.
    coupling_s : float
        Range-Doppler coupling, s (apparent range = range + coupling * radial velocity).
    test : GroundTrackTest, optional
    max_alias : int, optional
        Largest alias ``|k|`` considered; by default the image's
        :func:`~skyradar.track.dealias.alias_count` (radial speeds up to 195 m/s).
    closing : bool
        Only a history that closes (its de-aliased radial velocity negative at every detection).

    Returns
    -------
    bool

    Examples
    --------
    A head-on closure at 107 m/s, its Doppler aliased to -28.4 m/s, against own-ship at 50 m/s,
    five detections at 9.4 frames/s; then a ground point with the same Doppler; then a history
    receding at 107 m/s, faster than the ground but not closing:

    >>> t = np.arange(5) / 9.4
    >>> closure = 1500.0 - 106.7 * t
    >>> faster_than_ground(t, closure, np.full(5, -28.4), np.full(5, 50.0), 78.3, 0.19)
    True
    >>> faster_than_ground(t, 1500.0 - 28.4 * t, np.full(5, -28.4), np.full(5, 50.0), 78.3, 0.19)
    False
    >>> receding = 1500.0 + 106.7 * t
    >>> faster_than_ground(t, receding, np.full(5, 28.4), np.full(5, 50.0), 78.3, 0.19, closing=True)
    False
    """
    test = test or GroundTrackTest()
    t = np.asarray(time_s, float)
    rng = np.asarray(range_m, float)
    if t.size < 3:
        return False
    v, moved = _doppler_path(t, radial_velocity_mps, width_mps, coupling_s)
    excess = rng - moved  # constant + k * width * (t - t0) + noise
    tc = t - t.mean()
    sxx = float(np.sum(tc**2))
    if not sxx > 0.0:
        return False
    slope = float(np.sum(tc * (excess - excess.mean())) / sxx)
    z = normal_upper_quantile(test.tail)
    max_alias = alias_count(width_mps) if max_alias is None else max_alias
    aliases = np.arange(-max_alias, max_alias + 1)
    allowed = np.abs(slope - aliases * width_mps) <= z * test.sigma_range_jitter_m / np.sqrt(sxx)
    if np.count_nonzero(allowed) != 1:
        return False
    bound = np.asarray(own_speed_mps, float) + z * test.sigma_velocity_mps
    k = int(aliases[allowed][0])
    if np.all(np.abs(v + k * width_mps) <= bound):
        return False  # the allowed alias is a radial velocity some static point has
    if closing and not np.all(v + k * width_mps < 0.0):
        return False
    res = excess - k * width_mps * (t - t[0])
    z2 = ((res - res.mean()) / test.sigma_range_jitter_m) ** 2
    keep = t.size - int(np.floor(test.trim * t.size))
    return bool(trimmed_sum(z2, test.trim)[0] <= chi2_upper_quantile(test.tail, max(keep - 2, 1)))


def _own_state(ownship: pd.DataFrame, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Own-ship NED position and velocity (k, 3) interpolated at ``times``."""
    t = ownship["time_s"].to_numpy(float)
    cols = [
        [np.interp(times, t, ownship[f"own_{a}"].to_numpy(float)) for a in names]
        for names in (("north_m", "east_m", "down_m"), ("vn_mps", "ve_mps", "vd_mps"))
    ]
    return np.column_stack(cols[0]), np.column_stack(cols[1])


def doppler_smooth(
    time_s: np.ndarray,
    radial_velocity_mps: np.ndarray,
    width_mps: float,
    test: GroundTrackTest | None = None,
    n: int = 10,
) -> bool:
    """Whether a track's last ``n`` radial velocities follow one smooth curve (one point, not a patch).

    A point's radial velocity changes slowly: in straight flight ``d(dr/dt)/dt = (|w|^2 -
    (dr/dt)^2) / r``, about 1 m/s^2 at 1 km, so a quadratic in time fits ~1 s of it to the
    Doppler error ``point_sigma_velocity_mps``. The scatterers of a clutter patch that take turns in one
    track jump by a Doppler bin between frames. Unwrapped by the image width; trimmed chi-square.

    Examples
    --------
    >>> t = np.arange(10) * 0.106
    >>> doppler_smooth(t, 37.7 + 0.5 * t, 77.0)
    True
    >>> doppler_smooth(t, 36.5 + np.array([-0.3, 0.6, -0.8, 0.4, 0.0, -0.7, 0.5, 0.9, -0.5, 0.3]), 77.0)
    False
    """
    test = test or GroundTrackTest()
    t, v = np.asarray(time_s, float)[-n:], np.asarray(radial_velocity_mps, float)[-n:]
    if t.size < 3:
        return True
    v = np.unwrap(v, period=width_mps)
    if _smooth_curve(t, v, test):
        return True
    # One detection off the curve is a clutter hit the track's gate took (it spans a few cells where
    # the ground is dense); a patch's scatterers taking turns put several off it.
    if t.size < _SPIKE_MIN_DETECTIONS:
        return False
    return any(_smooth_curve(np.delete(t, j), np.delete(v, j), test) for j in range(t.size))


def _smooth_curve(t: np.ndarray, v: np.ndarray, test: GroundTrackTest) -> bool:
    """The trimmed chi-square test of :func:`doppler_smooth` on unwrapped radial velocities ``v``."""
    assert test.point_sigma_velocity_mps is not None
    degree = 2 if t.size >= 5 else 1  # a line over the first 0.2-0.3 s
    res = v - np.polyval(np.polyfit(t - t[0], v, degree), t - t[0])
    z2 = (res / test.point_sigma_velocity_mps) ** 2
    keep = t.size - int(np.floor(test.trim * t.size))
    return bool(trimmed_sum(z2, test.trim)[0] <= chi2_upper_quantile(test.tail, max(keep - degree - 1, 1)))


def _judge(sl, t, rng, vel, own_p, own_v, surface_down, width, coupling, test, doa) -> str:
    """One judgement of a detection history ``sl``: why it is held (``""``: an object off the ground)."""
    if not range_doppler_consistent(t[sl], rng[sl], vel[sl], width, coupling, test):
        return "range"
    if test.point_sigma_velocity_mps is not None and not doppler_smooth(t[sl], vel[sl], width, test):
        return "rough"
    if sl.stop - sl.start < test.ground_min_detections:
        measured = doa[3][sl]
        if not direction_measured(measured) or doa_on_the_ground(measured, doa[2][sl]):
            return "direction"
    azimuth, elevation, height_sd, measured, right = (a[sl] for a in doa)
    if test.patch_directions and doa_of_a_ground_patch(
        azimuth, elevation, measured, height_sd, test.doa_sigma_rad
    ):  # a patch's directions at any age: no static point need fit scatterers taking turns
        return "direction"
    if surface_down is None or doa_in_the_air(
        azimuth, elevation, height_sd, measured, test.doa_sigma_rad, test.doa_field_rad
    ):
        return ""
    fit = (test.sigma_range_m, test.sigma_velocity_mps, test.tail, test.trim)
    points = static_ground_points(rng[sl], vel[sl], own_p[sl], own_v[sl], surface_down, width, coupling, *fit)
    if len(points) == 0:
        return ""
    if not doa_on_the_ground(measured, height_sd) and azimuth_off_static_points(
        azimuth, elevation, right, own_p[sl], points, test.doa_sigma_rad, test.doa_field_rad
    ):
        return ""  # seen where none of the static points that fit it is
    return "ground"


def _history_held(t, rng, vel, own_p, own_v, surface_down, width, coupling, test, doa) -> np.ndarray:
    """Per detection of one track: why it is held on the detections up to it (``""``: not held).

    A history faster than any static point (:func:`faster_than_ground`, on its newest ten
    detections, from ``fast_min_detections``) whose Doppler is one smooth curve is an object from
    its ``release_detections``-th detection, whatever was judged before. Otherwise judged at
    every detection for the first 30, then at every fifth. A track judged an object off the ground
    for :data:`_CLEAR_S` on end is not judged again (it was confirmed all that
    time already, so a later verdict could not undo its count; the fits cost time). A Doppler
    that is not one smooth curve starts the history again after its largest step: the detections
    before it came from another scatterer, more than the static fit's trim leaves out, and the
    new history needs ``ground_min_detections``. Once a static ground point has fitted it, a
    track is released only when the judgements running over ``release_span_detections``
    detections say otherwise, and not before ``ground_min_detections``: the surface model and a
    patch's scatterers make a fit fail now and then, and each was a confirmed ground row.
    The reasons are those of :data:`HOLD_REASONS`.
    """
    n = rng.size
    why = np.full(n, "young", dtype=object)
    walk = _HistoryWalk(test)
    speed = np.linalg.norm(own_v, axis=1) if own_v is not None else None
    history = _History(t, rng, vel, own_p, own_v, speed, doa)
    for k in range(test.min_detections - 1, n):
        why[k] = walk.judge(k, k == n - 1, history, surface_down, width, coupling)
    return why


@dataclass
class _History:
    """One detection history's columns, in time order: time (s), range (m), radial velocity (m/s),
    the own-ship's position (m) and velocity (m/s, and speed) at each, and :func:`doa_height_sd`'s
    four columns (``doa``). The own-ship's are None without an own-ship state."""

    t: np.ndarray
    rng: np.ndarray
    vel: np.ndarray
    own_p: np.ndarray | None
    own_v: np.ndarray | None
    own_speed: np.ndarray | None
    doa: list

    def upto(self, a: int, b: int) -> _History:
        """Detections ``a:b``."""

        def part(x: np.ndarray | None) -> np.ndarray | None:
            return None if x is None else x[a:b]

        return _History(
            self.t[a:b],
            self.rng[a:b],
            self.vel[a:b],
            part(self.own_p),
            part(self.own_v),
            part(self.own_speed),
            [x[a:b] for x in self.doa],
        )

    def extended(self, more: _History) -> _History:
        """These detections, then ``more``."""

        def cat(x: np.ndarray | None, y: np.ndarray | None) -> np.ndarray | None:
            return None if x is None or y is None else np.concatenate([x, y])

        doa = [np.concatenate([x, y]) for x, y in zip(self.doa, more.doa, strict=True)]
        t, rng, vel = (
            np.concatenate([x, y]) for x, y in ((self.t, more.t), (self.rng, more.rng), (self.vel, more.vel))
        )
        own_p, own_v = cat(self.own_p, more.own_p), cat(self.own_v, more.own_v)
        return _History(t, rng, vel, own_p, own_v, cat(self.own_speed, more.own_speed), doa)


@dataclass
class _HistoryWalk:
    """The walk of :func:`_history_held` over one history, one detection at a time.

    Its state after detection ``k`` depends on the detections up to ``k`` alone, and on whether
    ``k`` was the history's last (which is judged out of turn), so a stream keeps the walk over the
    detections before its newest and judges the newest on a copy.
    """

    test: GroundTrackTest
    last: str = "young"
    clear_since: float = np.inf
    start: int = 0
    ground_seen: bool = False
    object_since: float = np.inf  # the detection from which the judgements found an object
    least: int = 0
    cleared: bool = False  # an object off the ground for _CLEAR_S on end: not judged again

    def __post_init__(self) -> None:
        self.least = self.least or self.test.min_detections

    def judge(self, k: int, is_last: bool, h: _History, surface_down, width, coupling) -> str:
        """Why detection ``k`` (from ``test.min_detections - 1``, in order) holds the track."""
        test, t = self.test, h.t
        if self.cleared or t[k] - self.clear_since >= _CLEAR_S:
            self.cleared = True
            return ""
        start = self.start
        recent = slice(max(start, k + 1 - 10), k + 1)
        if (
            h.own_speed is not None
            and k + 1 - start >= max(test.min_detections, test.fast_min_detections)
            and faster_than_ground(
                t[recent],
                h.rng[recent],
                h.vel[recent],
                h.own_speed[recent],
                width,
                coupling,
                test,
                closing=True,
            )
            and (
                test.point_sigma_velocity_mps is None or doppler_smooth(t[recent], h.vel[recent], width, test)
            )
            and not (
                test.patch_directions
                and doa_of_a_ground_patch(
                    h.doa[0][recent], h.doa[1][recent], h.doa[3][recent], h.doa[2][recent], test.doa_sigma_rad
                )
            )
        ):  # one point closing faster than any static point can: an object, however its Doppler aliases
            self.ground_seen, self.least = False, test.min_detections
            self.object_since = min(self.object_since, k)
            self.last = "young" if k + 1 - start < test.release_detections else ""
            self.clear_since = np.inf if self.last else min(self.clear_since, t[k])
            return self.last
        if k + 1 - start >= self.least and (k < 30 or k % 5 == 0 or is_last):
            sl = slice(max(start, k + 1 - test.max_history), k + 1)
            args = (h.own_p, h.own_v, surface_down, width, coupling, test, h.doa)
            reason = _judge(sl, t, h.rng, h.vel, *args)
            if reason == "rough":  # a fresh history, as long as the Doppler test's window
                self.start = max(start, _largest_step(h.vel, width, sl))
                self.least = test.ground_min_detections
            if reason == "ground":  # ground once: as long a history as the Doppler test's to clear it
                self.ground_seen, self.least = True, test.ground_min_detections
            self.object_since = min(self.object_since, k) if reason == "" else np.inf
            released = k - self.object_since >= test.release_span_detections
            early = k + 1 - self.start < max(self.least, test.release_detections)
            if reason:
                self.last = reason
            elif self.ground_seen and not released:
                self.last = "ground-release"
            else:
                self.last = "young" if early else ""
            self.clear_since = np.inf if self.last else min(self.clear_since, t[k])
        return self.last


def _largest_step(vel: np.ndarray, width: float, sl: slice) -> int:
    """Index of the detection after the largest Doppler step in ``sl`` (the newest ten)."""
    first = max(sl.start, sl.stop - 10)
    v = np.unwrap(vel[first : sl.stop], period=width)
    return first + 1 + int(np.argmax(np.abs(np.diff(v)))) if v.size > 1 else sl.start


def _track_held(det: np.ndarray, ownship, surface_down, width: float, coupling: float, test) -> np.ndarray:
    """Why each detection of one track (``det``: time, range, radial velocity) holds it (``""``: not
    held), its history started again after every gap longer than ``test.rejudge_gap_s``."""
    return TrackHoldWalk(test).why(det, ownship, surface_down, width, coupling)


class TrackHoldWalk:
    """:func:`_track_held` kept between calls on one track's growing detection history (a stream's).

    Each call passes every detection of the track so far, those of earlier calls first and
    unchanged. Each detection but the newest is judged once, as the whole history's walk judges
    it (the last of a history before a gap as its last); the newest is judged on a copy of the walk,
    as the last of the history so far. The columns of a detection (own-ship state, DoA height) are
    computed when it arrives, with the ``ownship`` and ``surface_down`` of that call.

    Parameters
    ----------
    test : GroundTrackTest
        Settings of the ground test.

    Examples
    --------
    A stream's track closing at 50 m/s (no direction of arrival, no own-ship state), judged as its
    detections arrive (rows: time (s), range (m), radial velocity (m/s), the direction columns,
    the measured-elevation flag, the antenna axis):

    >>> k = np.arange(8.0)
    >>> rd = np.column_stack([0.1 * k, 1000.0 - 5.0 * k, np.full(8, -50.0)])
    >>> det = np.column_stack([rd, np.full((8, 5), np.nan), np.ones(8), np.full((8, 3), np.nan)])
    >>> walk = TrackHoldWalk(GroundTrackTest())
    >>> walk.why(det[:4], None, None, 78.3, 0.0).tolist()
    ['young', 'young', 'young', 'young']
    >>> walk.why(det, None, None, 78.3, 0.0).tolist()
    ['young', 'young', 'young', 'young', '', '', '', '']
    """

    def __init__(self, test: GroundTrackTest) -> None:
        self.test = test
        self.history = _History(np.empty(0), np.empty(0), np.empty(0), None, None, None, [])
        self.done: list[str] = []  # why of each detection judged for good
        self.segment = 0  # first detection of the current history (after the last gap)
        self.walk = _HistoryWalk(test)
        self.newest: np.ndarray | None = None  # the last call's answer, while no detection comes

    def why(self, det: np.ndarray, ownship, surface_down, width: float, coupling: float) -> np.ndarray:
        """Why each detection of ``det`` (rows: time, range, radial velocity, then
        :data:`DOA_COLUMNS`, optionally :data:`AXIS_COLUMNS`; every detection of the track so far)
        holds the track.

        A call with no new detection gives the last call's answer: every judgement depends on the
        detections and on the walk over those before the newest, and neither has changed."""
        if self.newest is not None and len(det) == self.history.t.size:
            return self.newest
        self._extend(det, ownship, surface_down)
        n = self.history.t.size
        ground = surface_down if ownship is not None else None
        for j in range(len(self.done), n - 1):  # every detection but the newest: for good
            self._start_history_at(j)
            gap_after = self.history.t[j + 1] - self.history.t[j] > self.test.rejudge_gap_s
            self.done.append(self._judge(j, gap_after, self.walk, ground, width, coupling))
        if n == 0:
            return np.array([], dtype=object)
        self._start_history_at(n - 1)
        newest = self._judge(n - 1, True, copy.copy(self.walk), ground, width, coupling)
        self.newest = np.array([*self.done, newest], dtype=object)
        return self.newest

    def _start_history_at(self, j: int) -> None:
        """A new history (and walk) from detection ``j`` when a gap precedes it."""
        t = self.history.t
        if j > self.segment and t[j] - t[j - 1] > self.test.rejudge_gap_s:
            self.segment, self.walk = j, _HistoryWalk(self.test)

    def _judge(self, j: int, is_last: bool, walk: _HistoryWalk, ground, width: float, coupling: float) -> str:
        k = j - self.segment
        if k < self.test.min_detections - 1:
            return "young"
        history = self.history.upto(self.segment, j + 1)
        return walk.judge(k, is_last, history, ground, width, coupling)

    def _extend(self, det: np.ndarray, ownship, surface_down) -> None:
        """Add the columns of the detections of ``det`` not seen before."""
        held = self.history.t.size
        new = det[held:]
        if held and new.size == 0:
            return
        t, rng, vel = new[:, :3].T
        own_p, own_v = _own_state(ownship, t) if ownship is not None else (None, None)
        speed = np.linalg.norm(own_v, axis=1) if own_v is not None else None
        ground = surface_down if ownship is not None else None
        more = _History(t, rng, vel, own_p, own_v, speed, doa_height_sd(new, ground, self.test.doa_sigma_rad))
        self.history = more if held == 0 else self.history.extended(more)


def median_ground_down_m(ownship: pd.DataFrame) -> float:
    """Median ``down`` of the ground under the own-ship (``own_down_m + own_height_agl_m``), m.

    NaN when the table has no height above ground.

    Examples
    --------
    >>> own = pd.DataFrame({"own_down_m": [-500.0, -510.0], "own_height_agl_m": [800.0, 810.0]})
    >>> median_ground_down_m(own)
    300.0
    """
    if "own_height_agl_m" not in ownship:
        return float("nan")
    ground = (ownship["own_down_m"] + ownship["own_height_agl_m"]).to_numpy(float)
    return float(np.nanmedian(ground)) if np.isfinite(ground).any() else float("nan")


def hold_ground_tracks(
    tracks: pd.DataFrame,
    detections: pd.DataFrame,
    ownship: pd.DataFrame | None,
    width_mps: float,
    coupling_s: float,
    surface_down: Callable[[np.ndarray], np.ndarray] | None = None,
    test: GroundTrackTest | None = None,
    walks: dict[int, tuple[np.ndarray, TrackHoldWalk]] | None = None,
) -> pd.DataFrame:
    """A tracks table with the rows the ground explains (or that are no object) not ``confirmed``.

    ``detection_row`` of ``tracks`` indexes ``detections`` (``time_s, range_m,
    radial_velocity_mps``). ``ownship`` (``own_*`` NED columns, optionally ``own_height_agl_m``)
    gives the static points' history; without ``surface_down`` the surface is a level ground at
    the own-ship's height above ground, and without either only the range-Doppler test applies.
    A row takes the decision of the track's newest detection at or before it, and says in
    ``held_by`` why it is not confirmed (:data:`HOLD_REASONS`); tracks left without a confirmed row
    are dropped.

    ``walks`` ({track id: (its detection rows, :class:`TrackHoldWalk`)}, updated in place) keeps
    each track's judgements between calls on a growing table (a stream's): a track whose detection
    rows extend those of the last call is judged on its new detections only. Only the tracks of
    this call are kept.

    Parameters
    ----------
    tracks : DataFrame
        Tracks table: ``time_s`` (s), ``track_id``, ``detection_row`` (-1: coasting), ``confirmed``
        and optionally ``held_by``.
    detections : DataFrame
        Detections: ``time_s`` (s), ``range_m`` (m), ``radial_velocity_mps`` (m/s), optionally the
        direction columns.
    ownship : DataFrame or None
        Own-ship table (``time_s`` in s, ``own_*`` NED position in m and velocity in m/s).
    width_mps : float
        Width of the Doppler image, m/s.
    coupling_s : float
        Range-Doppler coupling, s (m of apparent range per m/s).
    surface_down : callable, optional
        NE points (k, 2) in m -> ``down`` of the ground, m.
    test : GroundTrackTest, optional
        Settings of the test (default :class:`GroundTrackTest`).
    walks : dict, optional
        Judgements kept between calls, updated in place.

    Returns
    -------
    DataFrame
        ``tracks`` with ``confirmed`` False on held rows and the reason in ``held_by`` (``""`` on
        confirmed rows), without the tracks that have no confirmed row left.

    Examples
    --------
    Without own-ship state: a track closing at 50 m/s whose ranges follow its Doppler is released
    at its fifth detection; one whose range jumps 30 m back and forth every frame at a constant
    Doppler (no single object) is held by the range-Doppler test on most rows:

    >>> k = np.arange(8)
    >>> ranges = np.r_[1000.0 - 5.0 * k, 2000.0 + 30.0 * (k % 2)]
    >>> det = pd.DataFrame({"time_s": 0.1 * np.r_[k, k], "range_m": ranges, "radial_velocity_mps": -50.0})
    >>> tracks = pd.DataFrame({"time_s": 0.1 * np.r_[k, k], "track_id": np.repeat([1, 2], 8),
    ...                        "detection_row": np.r_[k, k + 8], "confirmed": True})
    >>> out = hold_ground_tracks(tracks, det, None, 78.3, 0.0)
    >>> out.groupby("track_id")["held_by"].agg(list).to_dict()
    {1: ['young', 'young', 'young', 'young', '', '', '', ''],
     2: ['young', 'young', 'young', 'young', 'range', '', 'range', 'range']}
    """
    test = test or GroundTrackTest()
    if len(tracks) == 0:
        return tracks
    if surface_down is None and ownship is not None and np.isfinite(median_ground_down_m(ownship)):
        surface_down = flat_surface(median_ground_down_m(ownship))
    rows = tracks["detection_row"].to_numpy()
    # Only the detections the tracks hold are read (a stream's table holds every frame's).
    used = np.unique(rows[rows >= 0])
    held_detections = detections.iloc[used]
    nan = np.full(used.size, np.nan)

    def floats(names) -> list[np.ndarray]:
        return [held_detections[c].to_numpy(float) if c in held_detections else nan for c in names]

    det = np.column_stack(
        floats(["time_s", "range_m", "radial_velocity_mps", *DOA_COLUMNS[:-1]])
        + [elevation_measured_flags(held_detections).astype(float)]
        + floats(AXIS_COLUMNS)
    )
    why = np.full(len(tracks), "young", dtype=object)
    kept: dict[int, tuple[np.ndarray, TrackHoldWalk]] = {}
    for track_id, idx in tracks.groupby("track_id", sort=False).indices.items():
        has = idx[rows[idx] >= 0]
        if has.size == 0:
            continue
        if walks is None:
            h = _track_held(
                det[np.searchsorted(used, rows[has])], ownship, surface_down, width_mps, coupling_s, test
            )
        else:
            entry = walks.get(int(track_id))
            seen = rows[has][: 0 if entry is None else entry[0].size]
            walk = TrackHoldWalk(test) if entry is None or not np.array_equal(seen, entry[0]) else entry[1]
            h = walk.why(det[np.searchsorted(used, rows[has])], ownship, surface_down, width_mps, coupling_s)
            kept[int(track_id)] = (rows[has], walk)
        # Each row (coasting ones too) takes the decision of the newest detection at or before it.
        pos = np.searchsorted(has, idx, side="right") - 1
        why[idx] = np.where(pos >= 0, h[np.maximum(pos, 0)], "young")
    if walks is not None:
        walks.clear()
        walks.update(kept)
    was = tracks["confirmed"].to_numpy(bool)
    held_by = tracks["held_by"].to_numpy(object) if "held_by" in tracks else np.where(was, "", "tentative")
    out = tracks.assign(confirmed=was & (why == ""), held_by=np.where(was, why, held_by).astype(str))
    real = np.unique(out["track_id"].to_numpy()[out["confirmed"].to_numpy()])
    return out[np.isin(out["track_id"].to_numpy(), real)].reset_index(drop=True)
