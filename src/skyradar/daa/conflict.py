"""Conflict geometry: closest point of approach, well-clear volumes and the FLARM-style indication.

All functions work on relative states in the local NED frame: ``s = p_intruder - p_ownship`` (m)
and ``v = v_intruder - v_ownship`` (m/s), shape ``(..., 3)``, with straight-line propagation
``s(t) = s + t v``. Horizontal quantities use the north/east components, vertical ones the down
component.

Well clear follows DAIDALUS' ``WCV_TAUMOD`` definition (RTCA DO-365): horizontally violated when
``|s_h| <= DTHR``, or when the horizontal miss distance ``d_cpa <= DTHR`` and the modified tau
``(DTHR^2 - |s_h|^2) / (s_h . v_h)`` lies in ``[0, TTHR]``; vertically violated when
``|s_z| <= ZTHR`` or the time to co-altitude lies in ``[0, TCOA]``. With ``TTHR = TCOA = 0`` this is
the plain cylinder of the non-cooperative DO-365 volume (2200 ft, 450 ft). Because every condition
is a quadratic or linear inequality in ``t``, the time interval of a predicted loss of well clear
has a closed form (:func:`loss_of_well_clear_interval`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skyradar.units import wrap_angle

__all__ = [
    "FT",
    "WellClearVolume",
    "cpa",
    "horizontal_violation",
    "vertical_violation",
    "horizontal_interval",
    "vertical_interval",
    "loss_of_well_clear_interval",
    "widened_thresholds",
    "flarm_alarm_level",
    "traffic_indication",
]

FT = 0.3048  # m per foot


@dataclass(frozen=True)
class WellClearVolume:
    """A DAIDALUS-style well-clear volume.

    Parameters
    ----------
    dthr_m : float
        Horizontal distance threshold (DMOD / DTHR), m.
    zthr_m : float
        Vertical threshold (ZTHR), m.
    tthr_s : float
        Modified-tau threshold (TTHR), s; 0 gives a plain cylinder.
    tcoa_s : float
        Time-to-co-altitude threshold (TCOA), s.

    Examples
    --------
    >>> round(WellClearVolume.do365_noncoop().dthr_m, 1)
    670.6
    """

    dthr_m: float
    zthr_m: float
    tthr_s: float = 0.0
    tcoa_s: float = 0.0

    @classmethod
    def do365_noncoop(cls) -> WellClearVolume:
        """DO-365 non-cooperative volume: 2200 ft horizontal, 450 ft vertical, no tau."""
        return cls(2200 * FT, 450 * FT, 0.0, 0.0)

    @classmethod
    def do365_cooperative(cls) -> WellClearVolume:
        """DO-365 (Phase I) volume: DMOD 0.66 NM (4000 ft), ZTHR 450 ft, modified tau 35 s."""
        return cls(4000 * FT, 450 * FT, 35.0, 0.0)

    @classmethod
    def nmac(cls) -> WellClearVolume:
        """Near mid-air collision cylinder: 500 ft horizontal, 100 ft vertical."""
        return cls(500 * FT, 100 * FT, 0.0, 0.0)


def _split(s: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, ...]:
    s = np.asarray(s, float)
    v = np.asarray(v, float)
    return s[..., :2], v[..., :2], s[..., 2], v[..., 2]


def cpa(s: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Horizontal closest point of approach of a straight-line encounter.

    Parameters
    ----------
    s, v : ndarray, shape (..., 3)
        Relative position (m) and velocity (m/s), intruder minus own-ship, NED.

    Returns
    -------
    tcpa_s : ndarray
        Time of horizontal closest approach, s (negative when diverging; 0 without relative motion).
    hmd_m : ndarray
        Horizontal miss distance at ``max(tcpa, 0)``, m.
    vmd_m : ndarray
        Vertical separation at ``max(tcpa, 0)``, m.

    Examples
    --------
    >>> t, h, z = cpa(np.array([1000.0, 100.0, -50.0]), np.array([-100.0, 0.0, 0.0]))
    >>> float(t), float(h), float(z)
    (10.0, 100.0, 50.0)
    """
    sh, vh, sz, vz = _split(s, v)
    vv = np.sum(vh * vh, axis=-1)
    sv = np.sum(sh * vh, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        tcpa = np.where(vv > 0, -sv / np.where(vv > 0, vv, 1.0), 0.0)
    t = np.maximum(tcpa, 0.0)
    hmd = np.linalg.norm(sh + t[..., None] * vh, axis=-1)
    vmd = np.abs(sz + t * vz)
    return tcpa, hmd, vmd


def horizontal_violation(s: np.ndarray, v: np.ndarray, dthr_m, tthr_s=0.0) -> np.ndarray:
    """Instantaneous DAIDALUS horizontal well-clear violation (``WCV_TAUMOD``) of the state ``(s, v)``.

    Parameters
    ----------
    s : ndarray, shape (..., 3)
        Intruder position relative to the own-ship, NED, m (only north and east are read).
    v : ndarray, shape (..., 3)
        Intruder velocity relative to the own-ship, NED, m/s.
    dthr_m : float or ndarray
        Horizontal distance threshold ``DTHR``, m.
    tthr_s : float or ndarray
        Modified-tau threshold ``TTHR``, s (0: the disc alone).

    Returns
    -------
    ndarray of bool, shape (...)
        True where the state is inside the disc, or closes on it with a modified tau of at most
        ``TTHR`` and a closest approach within ``DTHR``.

    Examples
    --------
    Closing head-on at 100 m/s with ``DTHR = 500`` m and ``TTHR = 10`` s: inside the disc at 400 m;
    at 1000 m the modified tau ``(DTHR^2 - r^2) / (s.v)`` is 7.5 s; at 2000 m it is 37.5 s.

    >>> s = np.array([[400.0, 0, 0], [1000.0, 0, 0], [2000.0, 0, 0]])
    >>> horizontal_violation(s, np.array([-100.0, 0, 0]), 500.0, 10.0).tolist()
    [True, True, False]
    """
    sh, vh, _, _ = _split(s, v)
    dthr = np.asarray(dthr_m, float)
    dist2 = np.sum(sh * sh, axis=-1)
    sv = np.sum(sh * vh, axis=-1)
    vv = np.sum(vh * vh, axis=-1)
    # Unclipped closest approach of the whole line: only used where s.v < 0 (approaching).
    dcpa2 = dist2 - np.where(vv > 0, sv * sv / np.where(vv > 0, vv, 1.0), 0.0)
    dcpa = np.sqrt(np.maximum(dcpa2, 0.0))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        taumod = np.where(sv < 0, (dthr**2 - dist2) / np.where(sv < 0, sv, -1.0), -1.0)
    return (dist2 <= dthr**2) | ((dcpa <= dthr) & (sv < 0) & (taumod >= 0) & (taumod <= tthr_s))


def vertical_violation(s: np.ndarray, v: np.ndarray, zthr_m, tcoa_s=0.0) -> np.ndarray:
    """Instantaneous vertical well-clear violation: ``|s_z| <= ZTHR`` or co-altitude within ``TCOA``.

    Parameters
    ----------
    s : ndarray, shape (..., 3)
        Intruder position relative to the own-ship, NED, m (only ``down`` is read).
    v : ndarray, shape (..., 3)
        Intruder velocity relative to the own-ship, NED, m/s.
    zthr_m : float or ndarray
        Vertical distance threshold ``ZTHR``, m.
    tcoa_s : float or ndarray
        Time-to-co-altitude threshold ``TCOA``, s.

    Returns
    -------
    ndarray of bool, shape (...)
        True where the vertical condition is violated.

    Examples
    --------
    An intruder descending towards the own-ship's altitude at 10 m/s, with ``ZTHR = 100`` m and
    ``TCOA = 20`` s: 50 m above is inside ``ZTHR``; 150 m above reaches co-altitude in 15 s, 300 m
    above only in 30 s.

    >>> s = np.array([[0, 0, -50.0], [0, 0, -150.0], [0, 0, -300.0]])
    >>> vertical_violation(s, np.array([0, 0, 10.0]), 100.0, 20.0).tolist()
    [True, True, False]
    """
    _, _, sz, vz = _split(s, v)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        tcoa = np.where(sz * vz < 0, -sz / np.where(vz != 0, vz, 1.0), -1.0)
    return (np.abs(sz) <= zthr_m) | ((tcoa >= 0) & (tcoa <= tcoa_s))


def _quadratic_interval(a, b, c) -> tuple[np.ndarray, np.ndarray]:
    """Interval where ``a t^2 + b t + c <= 0`` for ``a >= 0`` (NaN when empty; +-inf when unbounded)."""
    a, b, c = np.broadcast_arrays(*(np.asarray(x, float) for x in (a, b, c)))
    lo = np.full(a.shape, np.nan)
    hi = np.full(a.shape, np.nan)
    quad = a > 0
    disc = b * b - 4 * a * c
    ok = quad & (disc >= 0)
    root = np.sqrt(np.where(ok, disc, 0.0))
    den = np.where(ok, 2 * a, 1.0)
    lo = np.where(ok, (-b - root) / den, lo)
    hi = np.where(ok, (-b + root) / den, hi)
    # a == 0 happens only with no relative horizontal motion: then b == 0 too and c decides.
    const_ok = ~quad & (c <= 0)
    lo = np.where(const_ok, -np.inf, lo)
    hi = np.where(const_ok, np.inf, hi)
    return lo, hi


def horizontal_interval(s: np.ndarray, v: np.ndarray, dthr_m, tthr_s=0.0) -> tuple[np.ndarray, np.ndarray]:
    """Times ``t`` (any sign) at which ``s + t v`` violates the horizontal well-clear condition.

    The set is an interval: the disc ``|s_h(t)| <= DTHR`` extended earlier by the modified-tau
    condition ``|s_h(t)|^2 + TTHR s_h(t).v_h <= DTHR^2`` when ``d_cpa <= DTHR``.

    Parameters
    ----------
    s : ndarray, shape (..., 3)
        Intruder position relative to the own-ship, NED, m (only north and east are read).
    v : ndarray, shape (..., 3)
        Intruder velocity relative to the own-ship, NED, m/s.
    dthr_m : float or ndarray
        Horizontal distance threshold ``DTHR``, m.
    tthr_s : float or ndarray
        Modified-tau threshold ``TTHR``, s.

    Returns
    -------
    t_in, t_out : ndarray
        Interval bounds, s; NaN where the horizontal condition is never violated.

    Examples
    --------
    Closing head-on from 2000 m at 100 m/s on a 500 m disc: inside from 15 s to 25 s. With
    ``TTHR = 10`` s the entry comes earlier, at the range ``x = 500 (1 + sqrt(2))`` m where
    ``x^2 - 1000 x = 500^2``, i.e. at ``(2000 - x) / 100`` s.

    >>> s, v = np.array([2000.0, 0, 0]), np.array([-100.0, 0, 0])
    >>> t_in, t_out = horizontal_interval(s, v, 500.0)
    >>> float(t_in), float(t_out)
    (15.0, 25.0)
    >>> round(float(horizontal_interval(s, v, 500.0, 10.0)[0]), 2)
    7.93
    """
    sh, vh, _, _ = _split(s, v)
    dthr = np.asarray(dthr_m, float)
    tthr = np.asarray(tthr_s, float)
    a = np.sum(vh * vh, axis=-1)
    sv = np.sum(sh * vh, axis=-1)
    ss = np.sum(sh * sh, axis=-1)
    t1, t2 = _quadratic_interval(a, 2 * sv, ss - dthr**2)
    r1, _ = _quadratic_interval(a, 2 * sv + tthr * a, ss + tthr * sv - dthr**2)
    t_in = np.where(np.isfinite(r1) & (r1 < t1), r1, t1)
    return t_in, t2


def vertical_interval(sz, vz, zthr_m, tcoa_s=0.0) -> tuple[np.ndarray, np.ndarray]:
    """Times at which the vertical well-clear condition is violated (NaN when never, +-inf when always).

    Parameters
    ----------
    sz : float or ndarray
        Intruder ``down`` relative to the own-ship, m.
    vz : float or ndarray
        Intruder vertical velocity relative to the own-ship (positive down), m/s.
    zthr_m : float or ndarray
        Vertical distance threshold ``ZTHR``, m.
    tcoa_s : float or ndarray
        Time-to-co-altitude threshold ``TCOA``, s: the interval starts at most this long before
        co-altitude.

    Returns
    -------
    t_lo, t_hi : ndarray
        Interval bounds, s.

    Examples
    --------
    300 m above and descending at 10 m/s relative, ``ZTHR = 100`` m: inside from 20 s to 40 s.
    Level flight is inside always or never.

    >>> [float(t) for t in vertical_interval(-300.0, 10.0, 100.0)]
    [20.0, 40.0]
    >>> [float(t) for t in vertical_interval([-50.0, -500.0], 0.0, 100.0)[0]]
    [-inf, nan]
    """
    sz, vz, zthr, tcoa = np.broadcast_arrays(*(np.asarray(x, float) for x in (sz, vz, zthr_m, tcoa_s)))
    # Below 1e-9 m/s the co-altitude time exceeds any lookahead; treating it as level avoids overflow.
    moving = np.abs(vz) > 1e-9
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        t_co = -sz / np.where(moving, vz, 1.0)
        half = zthr / np.where(moving, np.abs(vz), 1.0)
    lo = np.where(moving, t_co - np.maximum(half, tcoa), np.nan)
    hi = np.where(moving, t_co + half, np.nan)
    level_in = ~moving & (np.abs(sz) <= zthr)
    lo = np.where(level_in, -np.inf, lo)
    hi = np.where(level_in, np.inf, hi)
    return lo, hi


def loss_of_well_clear_interval(
    s: np.ndarray, v: np.ndarray, volume: WellClearVolume, lookahead_s: float, dthr_m=None, zthr_m=None
) -> tuple[np.ndarray, np.ndarray]:
    """Predicted interval of loss of well clear within ``[0, lookahead_s]``.

    Parameters
    ----------
    s, v : ndarray, shape (..., 3)
        Relative position (m) and velocity (m/s), intruder minus own-ship, NED.
    volume : WellClearVolume
    lookahead_s : float
        Prediction horizon, s.
    dthr_m, zthr_m : array_like, optional
        Per-encounter thresholds overriding the volume's (e.g. from :func:`widened_thresholds`).

    Returns
    -------
    t_in_s, t_out_s : ndarray
        Entry and exit time, s; NaN where well clear holds over the whole lookahead.

    Examples
    --------
    >>> vol = WellClearVolume(dthr_m=500.0, zthr_m=100.0)
    >>> s, v = np.array([2000.0, 0, 0]), np.array([-100.0, 0, 0])
    >>> t_in, t_out = loss_of_well_clear_interval(s, v, vol, 60.0)
    >>> float(t_in), float(t_out)
    (15.0, 25.0)
    """
    s = np.asarray(s, float)
    v = np.asarray(v, float)
    dthr = volume.dthr_m if dthr_m is None else dthr_m
    zthr = volume.zthr_m if zthr_m is None else zthr_m
    h_in, h_out = horizontal_interval(s, v, dthr, volume.tthr_s)
    z_in, z_out = vertical_interval(s[..., 2], v[..., 2], zthr, volume.tcoa_s)
    with np.errstate(invalid="ignore"):
        t_in = np.maximum(np.maximum(h_in, z_in), 0.0)
        t_out = np.minimum(np.minimum(h_out, z_out), lookahead_s)
        empty = ~(t_in <= t_out)  # also true where any bound is NaN
    return np.where(empty, np.nan, t_in), np.where(empty, np.nan, t_out)


def widened_thresholds(
    volume: WellClearVolume,
    cov_pos_m2: np.ndarray | None,
    cov_vel_m2ps2: np.ndarray | None,
    t_ref_s,
    z_h_pos: float = 1.5,
    z_h_vel: float = 1.0,
    z_v_pos: float = 0.75,
    z_v_vel: float = 1.5,
) -> tuple[np.ndarray, np.ndarray]:
    """Horizontal and vertical thresholds widened by the sensor uncertainty.

    In the spirit of DAIDALUS' sensor uncertainty mitigation, each threshold grows by a z-score
    times the standard deviation of the relative position predicted ``t_ref_s`` ahead:
    ``DTHR' = DTHR + z_hp sigma_hp + z_hv sigma_hv t_ref`` with ``sigma_hp`` the square root of the
    largest eigenvalue of the north/east position covariance (and the same for velocity), and
    ``ZTHR' = ZTHR + z_vp sigma_down + z_vv sigma_vdown t_ref``.

    Parameters
    ----------
    volume : WellClearVolume
    cov_pos_m2, cov_vel_m2ps2 : ndarray, shape (..., 3, 3) or None
        Relative position / velocity covariance (NED), m^2 and m^2/s^2; NaN entries count as 0.
    t_ref_s : array_like
        Prediction time for the velocity term, s (e.g. the clipped time to closest approach).

    Examples
    --------
    >>> d, z = widened_thresholds(WellClearVolume(500.0, 100.0), np.eye(3) * 100.0, None, 10.0)
    >>> float(d), float(z)
    (515.0, 107.5)
    """

    def sigmas(cov):
        if cov is None:
            return 0.0, 0.0
        cov = np.nan_to_num(np.asarray(cov, float))
        h = cov[..., :2, :2]
        # Largest eigenvalue of a symmetric 2x2 in closed form (vectorised, no LAPACK per row).
        tr = h[..., 0, 0] + h[..., 1, 1]
        det = h[..., 0, 0] * h[..., 1, 1] - h[..., 0, 1] * h[..., 1, 0]
        lam = tr / 2 + np.sqrt(np.maximum(tr * tr / 4 - det, 0.0))
        return np.sqrt(np.maximum(lam, 0.0)), np.sqrt(np.maximum(cov[..., 2, 2], 0.0))

    hp, vp = sigmas(cov_pos_m2)
    hv, vv = sigmas(cov_vel_m2ps2)
    t_ref = np.maximum(np.asarray(t_ref_s, float), 0.0)
    dthr = volume.dthr_m + z_h_pos * hp + z_h_vel * hv * t_ref
    zthr = volume.zthr_m + z_v_pos * vp + z_v_vel * vv * t_ref
    return np.asarray(dthr, float), np.asarray(zthr, float)


def flarm_alarm_level(
    time_to_impact_s, thresholds_s: tuple[float, float, float] = (18.0, 13.0, 8.0)
) -> np.ndarray:
    """FLARM-style alarm level 0..3 from the time to impact (NaN = no predicted impact).

    Level 1 (low) at or below 18 s, 2 (important) at or below 13 s, 3 (urgent) at or below 8 s.

    Examples
    --------
    >>> flarm_alarm_level(np.array([np.nan, 20.0, 15.0, 10.0, 5.0])).tolist()
    [0, 0, 1, 2, 3]
    """
    t = np.asarray(time_to_impact_s, float)
    level = np.zeros(t.shape, int)
    with np.errstate(invalid="ignore"):
        for k, thr in enumerate(thresholds_s, start=1):
            level = np.where(t <= thr, k, level)
    return level


def traffic_indication(
    s: np.ndarray, heading_rad, layer_limits_deg: tuple[float, float] = (7.0, 14.0)
) -> dict[str, np.ndarray]:
    """FLARM-like direction indication: 12 sectors of 30 deg, relative altitude and 5 vertical layers.

    Parameters
    ----------
    s : ndarray, shape (..., 3)
        Relative position, intruder minus own-ship, NED, m.
    heading_rad : array_like
        Own-ship heading from north, rad.
    layer_limits_deg : tuple
        Elevation angles separating the 5 layers (FLARM: about 7 and 14 deg).

    Returns
    -------
    dict
        ``bearing_rad`` (relative to the heading, [-pi, pi), positive right), ``sector`` (0 = dead
        ahead within +-15 deg, counting clockwise to 11), ``rel_alt_m`` (positive above),
        ``elevation_rad`` and ``layer`` (-2 far below .. 0 level .. 2 far above).

    Examples
    --------
    >>> ind = traffic_indication(np.array([0.0, 1000.0, -200.0]), 0.0)
    >>> int(ind["sector"]), float(ind["rel_alt_m"]), int(ind["layer"])
    (3, 200.0, 1)
    """
    s = np.asarray(s, float)
    bearing = wrap_angle(np.arctan2(s[..., 1], s[..., 0]) - np.asarray(heading_rad, float))
    sector = np.floor(((np.degrees(bearing) + 15.0) % 360.0) / 30.0).astype(int) % 12
    rel_alt = -s[..., 2]
    elev = np.arctan2(rel_alt, np.hypot(s[..., 0], s[..., 1]))
    e_deg = np.degrees(elev)
    lo, hi = layer_limits_deg
    layer = np.select([e_deg >= hi, e_deg >= lo, e_deg > -lo, e_deg > -hi], [2, 1, 0, -1], -2)
    return {
        "bearing_rad": bearing,
        "sector": sector,
        "rel_alt_m": rel_alt,
        "elevation_rad": elev,
        "layer": layer,
    }
