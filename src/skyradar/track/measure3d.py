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
1.1 at 16-22 dB, 1.3 above 22 dB, where a floor takes over).
"""

from __future__ import annotations

import numpy as np

from skyradar.config import RadarConfig

__all__ = ["angle_sigma_rad", "position_covariance"]


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


def position_covariance(
    positions_m: np.ndarray,
    own_position_m: np.ndarray,
    angle_sigma: np.ndarray,
    range_sigma_m: np.ndarray | float,
    elevation_sigma: np.ndarray | None = None,
) -> np.ndarray:
    """Covariance of DoA positions, ``(R s)^2 (I - u u^T) + s_R^2 u u^T``, shape (k, 3, 3), m^2.

    With ``elevation_sigma`` the variance along ``e``, the direction of increasing elevation
    across the line of sight, is ``(R s_e)^2`` instead of ``(R s)^2``.

    Parameters
    ----------
    positions_m : ndarray, shape (k, 3)
        NED positions of the detections.
    own_position_m : ndarray, shape (3,)
        Own-ship NED position (the radar), m.
    angle_sigma : ndarray, shape (k,)
        Per-axis angle standard deviation, rad.
    range_sigma_m : float or ndarray, shape (k,)
        Range standard deviation, m.
    elevation_sigma : ndarray, shape (k,), optional
        Elevation standard deviation, rad (default ``angle_sigma``).

    Examples
    --------
    >>> C = position_covariance(np.array([[1000.0, 0, 0]]), np.zeros(3), np.array([0.01]), 5.0)
    >>> np.diag(C[0]).round(6).tolist()
    [25.0, 100.0, 100.0]
    >>> C = position_covariance(np.array([[1000.0, 0, 0]]), np.zeros(3), [0.01], 5.0, np.array([0.1]))
    >>> np.diag(C[0]).round(6).tolist()  # north, east, down: the vertical one loosened
    [25.0, 100.0, 10000.0]
    """
    d = np.asarray(positions_m, float) - np.asarray(own_position_m, float)
    r = np.linalg.norm(d, axis=1)
    u = d / np.maximum(r, 1e-9)[:, None]
    uu = u[:, :, None] * u[:, None, :]
    across = (r * np.asarray(angle_sigma, float)) ** 2
    along = np.broadcast_to(np.asarray(range_sigma_m, float) ** 2, r.shape)
    cov = across[:, None, None] * (np.eye(3) - uu) + along[:, None, None] * uu
    if elevation_sigma is not None:
        h = np.maximum(np.hypot(u[:, 0], u[:, 1]), 1e-9)
        e = np.column_stack([u[:, 2] * u[:, 0] / h, u[:, 2] * u[:, 1] / h, -h])  # up, across the sight line
        extra = (r * np.asarray(elevation_sigma, float)) ** 2 - across
        cov += extra[:, None, None] * (e[:, :, None] * e[:, None, :])
    return cov
