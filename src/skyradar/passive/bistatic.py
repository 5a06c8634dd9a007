"""Bistatic geometry in the horizontal plane: delay ellipse intersected with the beam direction.

An echo delayed ``dt`` after the direct path lies on the ellipse ``R1 + R2 = L + c dt`` with foci at
the transmitter and the receiver (``L`` the baseline). The rotating illuminator's beam azimuth at the
pulse picks one point: along the unit beam vector ``u`` from the transmitter, with ``b`` the vector from
transmitter to receiver and ``S = R1 + R2``, ``|R1 u - b| = S - R1`` gives

    ``R1 = (S^2 - L^2) / (2 (S - u . b))``.

This is the transmitter-angle form of the thesis' ``R2 = ((R1+R2)^2 - L^2) / (2 (R1+R2 + L sin a))``
(Maas 2022, ch. 7; Willis, Bistatic Radar, eq. 5.2; ``a`` the receiver's look angle from the baseline
normal), which the tests check against. Near the baseline the direct pulse swamps the echoes: that
blind zone is masked.
"""

from __future__ import annotations

import numpy as np

from skyradar.units import wrap_angle

__all__ = ["C_MPS", "bistatic_range_m", "ellipse_point", "receiver_range_willis", "in_blind_zone"]

C_MPS = 299_792_458.0


def bistatic_range_m(point_en: np.ndarray, tx_en: np.ndarray, rx_en: np.ndarray) -> np.ndarray:
    """``R1 + R2 - L`` for points (..., 2) east/north, metres: the extra path an echo travels.

    Examples
    --------
    >>> float(bistatic_range_m(np.array([0.0, 4000.0]), np.array([0.0, 0.0]), np.array([3000.0, 0.0])))
    6000.0
    """
    point_en, tx_en, rx_en = (np.asarray(a, dtype=float) for a in (point_en, tx_en, rx_en))
    r1 = np.linalg.norm(point_en - tx_en, axis=-1)
    r2 = np.linalg.norm(point_en - rx_en, axis=-1)
    return r1 + r2 - np.linalg.norm(rx_en - tx_en)


def ellipse_point(
    bistatic_range: np.ndarray | float,
    azimuth_rad: np.ndarray | float,
    tx_en: np.ndarray,
    rx_en: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """East/north (..., 2) of echoes at ``bistatic_range`` (m, > 0) along beam azimuth (from north, cw).

    Returns the point and the transmitter and receiver ranges ``R1``, ``R2``.

    Examples
    --------
    >>> p, r1, r2 = ellipse_point(6000.0, 0.0, np.array([0.0, 0.0]), np.array([3000.0, 0.0]))
    >>> np.round(p, 6).tolist(), float(r1), float(r2)
    ([0.0, 4000.0], 4000.0, 5000.0)
    """
    tx_en, rx_en = np.asarray(tx_en, dtype=float), np.asarray(rx_en, dtype=float)
    b = rx_en - tx_en
    baseline = float(np.hypot(*b))
    az = np.asarray(azimuth_rad, dtype=float)
    u = np.stack([np.sin(az), np.cos(az)], axis=-1)
    s = np.asarray(bistatic_range, dtype=float) + baseline
    r1 = (s**2 - baseline**2) / (2.0 * (s - u @ b))
    return tx_en + r1[..., None] * u, r1, s - r1


def receiver_range_willis(
    bistatic_range: np.ndarray | float, baseline_m: float, theta_r_rad: np.ndarray
) -> np.ndarray:
    """The thesis' and Willis' receiver range ``R2 = (S^2 - L^2) / (2 (S + L sin theta_R))``.

    ``theta_R`` is the receiver's look angle from the baseline's normal, positive away from the
    transmitter: ``sin theta_R = -unit(target - rx) . unit(tx - rx)``.

    Examples
    --------
    >>> float(receiver_range_willis(6000.0, 3000.0, np.arcsin(-0.6)))  # the 3-4-5 example above
    5000.0
    """
    s = np.asarray(bistatic_range, dtype=float) + baseline_m
    return (s**2 - baseline_m**2) / (2.0 * (s + baseline_m * np.sin(theta_r_rad)))


def in_blind_zone(
    bistatic_range: np.ndarray | float,
    azimuth_rad: np.ndarray | float,
    bearing_rad: float,
    min_bistatic_range_m: float,
    half_width_rad: float,
) -> np.ndarray:
    """True where an echo cannot be told from the direct path.

    Either its extra path is shorter than ``min_bistatic_range_m`` (it sits in the direct pulse's
    compressed main lobe: the thin ellipse around the baseline between transmitter and receiver) or the
    beam points within ``half_width_rad`` of the receiver (the main-beam direct path swamps the sweep).

    Examples
    --------
    >>> in_blind_zone([100.0, 5000.0, 5000.0], [1.0, 1.0, 0.01], 0.0, 500.0, 0.05).tolist()
    [True, False, True]
    """
    off = np.abs(wrap_angle(np.asarray(azimuth_rad, dtype=float) - bearing_rad))
    return (np.asarray(bistatic_range, dtype=float) < min_bistatic_range_m) | (off < half_width_rad)
