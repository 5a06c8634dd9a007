"""Can ONE ground direction explain a detection's range, Doppler and measured direction together?

:func:`skyradar.process.ground.classify_ground` tests the height above the surface and the static
Doppler as two independent errors, each with its share of the DoA error. They are not independent:
one elevation error moves the point towards the surface AND changes its static Doppler. At low SNR
(DoA error of several degrees) an aircraft a couple of hundred metres above the ground then passes
both halves of the test with directions that contradict each other: the height asks for the
direction bent down to the surface, the Doppler for one that no point of the surface at that range
can have. With the range-Doppler point-spread and speckle on, this flagged 5-10 % of the aircraft
detections of the ground scenes (:mod:`skyradar.experiments.ground_scenes`).

:func:`surface_fit_chi2` fits the hypothesis "a static point of the surface" properly. The
Doppler (within half a bin, any alias) fixes the azimuth at each elevation in closed form
(``-v . u = V``); along that curve, for elevations over +-3.5 sd around the measured one and
ranges within the range leakage of the measured one, the surface crossings are found (sign
changes of ``height_fn``, so rough terrain with several crossings is handled), and each scores
``d_az^2 + d_el^2`` in the DoA's standard deviations. A pixel fed by ground left and right at
+-a (the two azimuths of one range and Doppler) reads an azimuth between them, so azimuths
inside ``|a|`` cost nothing. The smallest score has 2 degrees of freedom (four numbers: azimuth,
elevation, height 0, Doppler; two fitted angles).

Examples
--------
>>> from skyradar.config import RadarConfig
>>> cfg = RadarConfig.prototype_2022()
>>> flat = lambda p: 1000.0 - p[..., 2]  # ground 1000 m below the radar
>>> u = np.array([[np.cos(np.arcsin(0.5)), 0.0, 0.5]])  # 30 deg down, ahead: ground at 2000 m
>>> v = np.array([50.0, 0.0, 0.0])
>>> static = float(-v @ u[0])
>>> chi2 = surface_fit_chi2(u, np.array([2000.0]), np.array([static]), 0.01, 0.01, np.zeros(3), np.eye(3),
...                         flat, v, cfg)
>>> bool(chi2[0] < 1.0)
True
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from skyradar.config import RadarConfig

__all__ = ["surface_fit_chi2", "N_RANGE", "N_ELEVATION"]

N_RANGE = 3  # surface ranges over +-leakage_bins
N_ELEVATION = 29  # elevation samples over +-3.5 sd (surface crossings between them)


def _directions(az: np.ndarray, el: np.ndarray) -> np.ndarray:
    """Antenna-frame unit vectors (boresight +x, right +y, down +z) of azimuth/elevation arrays."""
    return np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)], axis=-1)


def _doppler_azimuths(el, v_ant, radial_mps, width, resolution) -> np.ndarray:
    """Azimuths (rad, new last axis: 2 branches x 3 aliases x 3 offsets) at elevations ``el`` whose
    static radial velocity ``-v_ant . u`` is ``radial_mps + k width + d`` (k = -1, 0, 1; d = 0 and
    +-half a Doppler bin, the quantisation); NaN where none."""
    a, b = v_ant[0] * np.cos(el), v_ant[1] * np.cos(el)
    shifts = (width * np.array([-1.0, 0.0, 1.0])[:, None] + resolution * np.array([-0.5, 0.0, 0.5])).ravel()
    target = -(radial_mps[..., None] + shifts) - v_ant[2] * np.sin(el)[..., None]
    with np.errstate(invalid="ignore", divide="ignore"):
        spread = np.arccos(target / np.hypot(a, b)[..., None])  # NaN: out of reach at this elevation
    centre = np.arctan2(b, a)[..., None]
    return np.concatenate([centre + spread, centre - spread], axis=-1)


def surface_fit_chi2(
    u_ant: np.ndarray,
    range_m: np.ndarray,
    radial_velocity_mps: np.ndarray,
    sd_az_rad: np.ndarray | float,
    sd_el_rad: np.ndarray | float,
    antenna_ned_m: np.ndarray,
    ant_to_ned: np.ndarray,
    height_fn: Callable[[np.ndarray], np.ndarray],
    own_velocity_ned_mps: np.ndarray,
    config: RadarConfig,
    surface_sd_m: float = 10.0,
    leakage_bins: float = 2.0,
) -> np.ndarray:
    """Smallest chi-square (2 dof) of "a static surface point" for each detection; inf: none near.

    ``u_ant`` (n, 3) measured antenna-frame directions, ``range_m`` and ``radial_velocity_mps``
    (n,) (aliased), ``sd_az_rad``/``sd_el_rad`` the DoA standard deviations, ``antenna_ned_m`` the
    antenna position, ``ant_to_ned`` (3, 3) the rotation, ``height_fn`` heights of NED points above
    the surface. The surface point may lie up to ``leakage_bins`` range bins from the detection's
    range (range sidelobes and straddle; no penalty within), and ``surface_sd_m`` (the surface's
    own error) widens the elevation standard deviation by ``surface_sd_m / R``.
    """
    u = np.asarray(u_ant, float)
    rng = np.asarray(range_m, float)
    n = rng.size
    if n == 0:
        return np.zeros(0)
    rot = np.asarray(ant_to_ned, float)
    v_ant = rot.T @ np.asarray(own_velocity_ned_mps, float)
    sd_az = np.broadcast_to(np.asarray(sd_az_rad, float), (n,))[:, None, None, None]
    az0 = np.arctan2(u[:, 1], u[:, 0])[:, None, None, None]
    el0 = np.arcsin(np.clip(-u[:, 2], -1.0, 1.0))[:, None, None]
    offsets = np.linspace(-leakage_bins, leakage_bins, N_RANGE) * config.range_resolution_m
    r = np.maximum(rng[:, None, None] + offsets[None, :, None], 1.0)  # (n, range, 1)
    sd_el = np.hypot(np.broadcast_to(np.asarray(sd_el_rad, float), (n,))[:, None, None], surface_sd_m / r)
    el = np.clip(
        el0 + np.linspace(-3.5, 3.5, N_ELEVATION)[None, None, :] * sd_el, -1.55, 1.55
    )  # (n, range, el)
    v_r = np.broadcast_to(np.asarray(radial_velocity_mps, float)[:, None, None], el.shape)
    az = _doppler_azimuths(el, v_ant, v_r, 2.0 * config.v_lim_mps, config.doppler_resolution_mps)
    el4 = np.broadcast_to(el[..., None], az.shape)
    points = np.asarray(antenna_ned_m, float) + r[..., None, None] * (_directions(az, el4) @ rot.T)
    h = height_fn(points)
    h0, h1 = h[:, :, :-1], h[:, :, 1:]  # along elevation: the surface lies between a sign change
    with np.errstate(all="ignore"):
        frac = h0 / (h0 - h1)
        cross = (np.sign(h0) != np.sign(h1)) & np.isfinite(frac) & (np.abs(frac) <= 1.0)
        el_c = el4[:, :, :-1] + frac * (el4[:, :, 1:] - el4[:, :, :-1])
        az_c = az[:, :, :-1] + frac * (az[:, :, 1:] - az[:, :, :-1])
        az_c = np.angle(np.exp(1j * az_c))
        cross &= np.abs(az_c) <= np.pi / 2  # the front hemisphere: back-lobe ground is left to flag_ground
        # A pixel fed by ground left and right at +-a reads an azimuth between them: no penalty inside.
        chi2 = (np.maximum(np.abs(az0) - np.abs(az_c), 0.0) / sd_az) ** 2 + (
            (el_c - el0[..., None]) / sd_el[..., None]
        ) ** 2
    return np.min(np.where(cross, chi2, np.inf), axis=(1, 2, 3))
