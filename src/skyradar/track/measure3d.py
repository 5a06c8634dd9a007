"""Measurement noise of DoA positions for the 3-D tracker.

A detection's NED position is ``p_own + R u`` with the measured range ``R`` and the estimated
direction ``u``. In principle its error along the line of sight is the range error (a few metres,
plus the range-Doppler coupling ``c V_R`` when the radial velocity is not known unaliased) and
across it the angle error times the range; :func:`position_covariance` writes that model. (On the
full chain the along-sight error was measured at 17-25 m RMS, so the tracker
(:mod:`skyradar.track.track_table`) passes an along-sight sigma no smaller than the across-sight one.)
The angle error is the Cramer-Rao bound of the phase-difference DoA
(:func:`skyradar.process.doa.doa_crlb`) at the detection's SNR, which matches the measured error of
the full chain (ch4 Free, RMS across-line-of-sight error / bound: 1.1 at 8-12 dB, 1.0 at 12-16 dB,
1.1 at 16-22 dB, 1.3 above 22 dB, where a floor takes over). Across the line of sight it sits on the
array's two axes, each with its own bound and their correlation (:func:`angle_covariance_rad2`):
a two-row array measures the elevation worse than the azimuth, and a covariance with one value for
both would let a few low-SNR elevations pull the track's height and vertical speed.
"""

from __future__ import annotations

import numpy as np

from skyradar.config import RadarConfig

__all__ = ["angle_sigma_rad", "angle_covariance_rad2", "position_covariance"]


def angle_sigma_rad(
    snr_db: np.ndarray,
    config: RadarConfig,
    azimuth_rad: np.ndarray | None = None,
    elevation_rad: np.ndarray | None = None,
    floor_rad: float = 0.01,
    max_rad: float = 0.3,
) -> np.ndarray:
    """Per-axis angle standard deviation of a DoA estimate: the CRLB with a floor, radians.

    Without angles the bound is taken at boresight. The per-axis value is the RMS of the
    azimuth and elevation bounds. Above ``max_rad`` (very low SNR, or an estimate at the edge of
    the field of view, where the bound of a planar array diverges) the position carries no
    usable direction and the result is ``inf``, so that the 3-D tracker skips it.

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> s = angle_sigma_rad(np.array([10.0, 30.0, -20.0]), cfg)
    >>> bool(s[0] > s[1] >= 0.01), bool(np.isinf(s[2]))
    (True, True)
    """
    from skyradar.process.doa import doa_crlb

    snr = np.asarray(snr_db, float)
    az = np.zeros_like(snr) if azimuth_rad is None else np.nan_to_num(np.asarray(azimuth_rad, float))
    el = np.zeros_like(snr) if elevation_rad is None else np.nan_to_num(np.asarray(elevation_rad, float))
    sd_az, sd_el = doa_crlb(snr, az, el, config)
    sigma = np.sqrt(0.5 * (sd_az**2 + sd_el**2))
    sigma = np.maximum(np.nan_to_num(sigma, nan=np.inf), floor_rad)
    return np.where(sigma > max_rad, np.inf, sigma)


def angle_covariance_rad2(
    snr_db: np.ndarray,
    config: RadarConfig,
    azimuth_rad: np.ndarray,
    elevation_rad: np.ndarray,
    floor_rad: float = 0.01,
) -> np.ndarray:
    """Covariance of a DoA estimate's error across the line of sight, on the array's axes, rad^2.

    The Cramer-Rao bound of :func:`skyradar.process.doa.direction_covariance` (rightward and upward
    angular displacement in the antenna frame, with their correlation) at the detection's SNR and
    direction, each axis at least ``floor_rad``, turned onto the axes :func:`position_covariance`
    takes: the array's right axis made perpendicular to the line of sight, and ``a x u``. An array
    wider than it is tall measures the elevation worse than the azimuth; :func:`angle_sigma_rad`'s
    one per-axis value averages the two, and a track that takes it for both trusts the elevation
    more than the array can measure it (``ura-2x4`` and ``mimo-2x4``: 1.3 times). NaN where the
    bound is (one channel, a line).

    Parameters
    ----------
    snr_db, azimuth_rad, elevation_rad : ndarray, shape (k,)
        Detection SNR (dB) and direction in the antenna frame (rad); NaN angles are taken as 0.
    config : RadarConfig
        The array.
    floor_rad : float
        Least standard deviation on each axis, rad.

    Returns
    -------
    ndarray, shape (k, 2, 2)

    Examples
    --------
    >>> wide = RadarConfig.prototype_2022(rx_positions_m="ura-2x4")
    >>> C = angle_covariance_rad2(np.array([12.0]), wide, np.zeros(1), np.zeros(1))
    >>> bool(C[0, 1, 1] > 4.0 * C[0, 0, 0])
    True
    """
    from skyradar.process.doa import direction_covariance

    az, el = (np.nan_to_num(np.asarray(a, float)) for a in (azimuth_rad, elevation_rad))
    cov = direction_covariance(np.asarray(snr_db, float), az, el, config)
    for i in (0, 1):
        cov[..., i, i] = np.maximum(cov[..., i, i], floor_rad**2)
    # The array's right axis made perpendicular to the line of sight is cos(az) rightward minus
    # sin(el) sin(az) upward: off boresight in both angles it turns from the rightward axis by
    # gamma (9 deg at 42 deg azimuth and 10 deg elevation). Onto that axis and its upward
    # perpendicular, the axes position_covariance builds from the right axis.
    gamma = np.arctan2(-np.sin(el) * np.sin(az), np.cos(az))
    c, s = np.cos(gamma), np.sin(gamma)
    turn = np.stack([np.stack([c, s], axis=-1), np.stack([-s, c], axis=-1)], axis=-2)
    return turn @ cov @ np.swapaxes(turn, -1, -2)


def position_covariance(
    positions_m: np.ndarray,
    own_position_m: np.ndarray,
    angle_sigma: np.ndarray,
    range_sigma_m: np.ndarray | float,
    elevation_sigma: np.ndarray | None = None,
    right_axis: np.ndarray | None = None,
) -> np.ndarray:
    """Covariance of DoA positions, ``R^2 C_across + s_R^2 u u^T``, shape (k, 3, 3), m^2.

    Across the line of sight ``u`` the angle error's covariance ``C`` sits on the array's axes:
    ``a``, the array's right axis made perpendicular to ``u``, and ``b = a x u`` (upward); a banked
    aircraft turns them with it. With one standard deviation ``s`` per detection, ``C = s^2 I``
    and the across-sight part is ``(R s)^2 (I - u u^T)``. With ``elevation_sigma`` the variance
    along ``e``, the direction of increasing elevation across the line of sight in NED, is at least
    ``(R s_e)^2`` (a loosened elevation: one the ground may have pulled).

    Parameters
    ----------
    positions_m : ndarray, shape (k, 3)
        NED positions of the detections.
    own_position_m : ndarray, shape (3,)
        Own-ship NED position (the radar), m.
    angle_sigma : ndarray, shape (k,) or (k, 2, 2)
        Per-axis angle standard deviation (rad), or the covariance of the (rightward, upward)
        angle error on the array's axes (rad^2, :func:`angle_covariance_rad2`).
    range_sigma_m : float or ndarray, shape (k,)
        Range standard deviation, m.
    elevation_sigma : ndarray, shape (k,), optional
        Least elevation standard deviation, rad; NaN: none.
    right_axis : ndarray, shape (k, 3), optional
        The array's right axis in NED (the detections' ``right_axis_north/east/down``); absent or
        NaN: level, the horizontal to the right of the line of sight.

    Examples
    --------
    >>> C = position_covariance(np.array([[1000.0, 0, 0]]), np.zeros(3), np.array([0.01]), 5.0)
    >>> np.diag(C[0]).round(6).tolist()
    [25.0, 100.0, 100.0]
    >>> C = position_covariance(np.array([[1000.0, 0, 0]]), np.zeros(3), [0.01], 5.0, np.array([0.1]))
    >>> np.diag(C[0]).round(6).tolist()  # north, east, down: the vertical one loosened
    [25.0, 100.0, 10000.0]

    An array twice as good across as up, banked 90 deg (its right axis pointing down): the
    better axis is now the vertical one.

    >>> C2 = np.array([[[1e-4, 0.0], [0.0, 4e-4]]])
    >>> C = position_covariance(np.array([[1000.0, 0, 0]]), np.zeros(3), C2, 5.0)
    >>> np.diag(C[0]).round(6).tolist()
    [25.0, 100.0, 400.0]
    >>> down = np.array([[0, 0, 1.0]])
    >>> C = position_covariance(np.array([[1000.0, 0, 0]]), np.zeros(3), C2, 5.0, right_axis=down)
    >>> np.diag(C[0]).round(6).tolist()
    [25.0, 400.0, 100.0]
    """
    d = np.asarray(positions_m, float) - np.asarray(own_position_m, float)
    r = np.linalg.norm(d, axis=1)
    u = d / np.maximum(r, 1e-9)[:, None]
    uu = u[:, :, None] * u[:, None, :]
    h = np.maximum(np.hypot(u[:, 0], u[:, 1]), 1e-9)
    a = np.column_stack([-u[:, 1] / h, u[:, 0] / h, np.zeros(len(u))])  # level: right, horizontal
    if right_axis is not None:
        right = np.asarray(right_axis, float)
        right = right - np.sum(right * u, axis=1, keepdims=True) * u
        norm = np.linalg.norm(right, axis=1)
        ok = np.isfinite(norm) & (norm > 1e-6)
        a[ok] = right[ok] / norm[ok, None]
    b = np.cross(a, u)  # upward across the line of sight
    C = np.asarray(angle_sigma, float)
    if C.ndim == 1:
        C = C[:, None, None] ** 2 * np.eye(2)
    axes = np.stack([a, b], axis=2)  # (k, 3, 2)
    across = np.einsum("kij,kjl,kml->kim", axes, C, axes)
    along = np.broadcast_to(np.asarray(range_sigma_m, float) ** 2, r.shape)
    cov = r[:, None, None] ** 2 * across + along[:, None, None] * uu
    if elevation_sigma is not None:
        e = np.column_stack([u[:, 2] * u[:, 0] / h, u[:, 2] * u[:, 1] / h, -h])  # up, across the sight line
        extra = (r * np.asarray(elevation_sigma, float)) ** 2 - np.einsum("ki,kij,kj->k", e, cov, e)
        extra = np.where(extra > 0.0, extra, 0.0)  # NaN (no loosening) and tighter values add nothing
        cov += extra[:, None, None] * (e[:, :, None] * e[:, None, :])
    return cov
