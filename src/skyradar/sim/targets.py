"""Point targets (aircraft) in the image domain: geometry, line of sight over terrain, pixels.

A target's truth (range, radial velocity, antenna-frame angles, expected SNR) and its
contribution to a frame use the same geometry, so the truth written with a run describes exactly
what was simulated.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from skyradar.config import RadarConfig
from skyradar.geo import direction_angles
from skyradar.sim.geometry import AntennaGeometry, PointTarget, TerrainView
from skyradar.sim.horizon import target_bins
from skyradar.sim.psf import PSF_WINDOW, target_psf_taps
from skyradar.units import nearest_bin

__all__ = ["line_of_sight", "target_geometry", "add_targets", "swerling1_power"]


def swerling1_power(seed: int, frame_index: int, n_targets: int) -> np.ndarray:
    """Swerling 1 power factors: exponential of mean 1, independent per frame and target.

    Drawn from the stream ``(seed, frame_index)`` so any frame is reproducible alone.

    Examples
    --------
    >>> f = swerling1_power(0, 3, 100_000)
    >>> round(float(f.mean()), 2), round(float(np.mean(f < np.log(2))), 2)  # mean 1, median ln 2
    (1.0, 0.5)
    """
    return np.random.default_rng([int(seed), int(frame_index), 0x5357]).standard_exponential(int(n_targets))


def line_of_sight(
    view: TerrainView | None, geom: AntennaGeometry, targets: Sequence[PointTarget]
) -> np.ndarray:
    """True for targets not hidden behind terrain (the same horizon test as terrain facets).

    Parameters
    ----------
    view : TerrainView or None
        The frame's terrain and horizon; None: no terrain, nothing hidden.
    geom : AntennaGeometry
        The antenna's position (the horizon's centre).
    targets : sequence of PointTarget

    Returns
    -------
    ndarray of bool, shape (n_targets,)

    Examples
    --------
    A horizon of slope -0.1 out to 1 km: 200 m below the antenna at 1 km (slope -0.2) is hidden,
    50 m below (-0.05) is not:

    >>> geom = AntennaGeometry(np.zeros(3), np.eye(3), np.zeros(3), 52.0, 4.0)
    >>> view = TerrainView(np.zeros((1, 1, 3)), np.full((4, 3), -0.1), np.pi / 2, 500.0)
    >>> targets = [PointTarget(np.array([1000.0, 0.0, d]), np.zeros(3)) for d in (200.0, 50.0)]
    >>> line_of_sight(view, geom, targets).tolist(), line_of_sight(None, geom, targets).tolist()
    ([False, True], [True, True])
    """
    rel = np.array([t.position_ned_m for t in targets], float).reshape(-1, 3) - geom.origin_ned_m
    if view is None:
        return np.ones(len(rel), bool)
    a, k, slope = target_bins(rel, view.az_bin_rad, view.h_bin_m, *view.horizon.shape)
    return slope >= view.horizon[a, k]


def target_geometry(
    cfg: RadarConfig,
    geom: AntennaGeometry,
    targets: Sequence[PointTarget],
    coupling_s: float,
    clear: np.ndarray,
    noise_w: float | None = None,
):
    """Per-target geometry, bins and expected power; ``snr_db`` against ``noise_w`` per pixel.

    Parameters
    ----------
    cfg : RadarConfig
    geom : AntennaGeometry
        The antenna's position, turn and velocity this frame.
    targets : sequence of PointTarget
    coupling_s : float
        Range-Doppler coupling of the sawtooth chirp, s: a return shows at ``R + coupling_s v_r``.
    clear : ndarray of bool, shape (n_targets,)
        Line of sight (:func:`line_of_sight`).
    noise_w : float, optional
        Noise power per pixel, W; default ``cfg.noise_power_w`` (frames without the window
        point-spread).

    Returns
    -------
    dict of ndarray
        Per target: ``range_m`` (half the mean two-way path), ``radial_velocity_mps``,
        ``azimuth_rad``, ``elevation_rad``, ``power_w`` (the radar equation), ``snr_db``,
        ``range_position_bins``, ``range_bin``, ``doppler_bin``, ``visible`` (ahead of the
        antenna, inside the range bins and clear) and ``path_m`` (two-way path per channel of a
        frame, m: per receive antenna, or per virtual channel ``t * n_rx + r`` of a time-division
        MIMO radar, ``|P - tx_t| + |P - rx_r| + 2 v_r t / PRF``: transmitter ``t`` chirps ``t / PRF``
        after transmitter 0, and the target's range moves ``v_r t / PRF`` meanwhile).

    Examples
    --------
    A 2 m^2 target 1 km ahead on boresight (gain G = 9.25 dBi), closing at 20 m/s, receives
    ``Pe G^2 lambda^2 sigma / ((4 pi)^3 R^4)`` = 7.2e-16 W (-121.4 dBm):

    >>> cfg = RadarConfig.prototype_2022()
    >>> geom = AntennaGeometry(np.zeros(3), np.eye(3), np.array([30.0, 0, 0]), 52.0, 4.0)
    >>> target = PointTarget(np.array([1000.0, 0, 0]), np.array([10.0, 0, 0]), rcs_m2=2.0)
    >>> g = target_geometry(cfg, geom, [target], 0.0, np.array([True]))
    >>> round(float(g["range_m"][0]), 3), float(g["radial_velocity_mps"][0]), int(g["range_bin"][0])
    (1000.0, -20.0, 67)
    >>> gain = 10 ** (float(cfg.antenna.gain_db(0.0, 0.0)) / 10)
    >>> expected = cfg.pe_w * gain**2 * cfg.wavelength_m**2 * 2.0 / ((4 * np.pi) ** 3 * 1000.0**4)
    >>> power = float(g["power_w"][0])
    >>> round(float(10 * np.log10(power)) + 30, 2), bool(np.isclose(power, expected))
    (-121.41, True)
    >>> round(float(g["snr_db"][0]), 2)  # over cfg.noise_power_w, -155.0 dBm
    33.62
    """
    pos = np.array([t.position_ned_m for t in targets], float).reshape(-1, 3)
    vel = np.array([t.velocity_ned_mps for t in targets], float).reshape(-1, 3)
    rcs = np.array([t.rcs_m2 for t in targets], float)
    p_ant = (pos - geom.origin_ned_m) @ geom.rot_ned_to_ant.T
    v_ant = (vel - geom.velocity_ned_mps) @ geom.rot_ned_to_ant.T
    r_tx = np.linalg.norm(p_ant[:, None, :] - cfg.transmitters_m[None], axis=2)  # (n_targets, n_tx)
    r_rx = np.linalg.norm(p_ant[:, None, :] - cfg.rx_positions_m[None], axis=2)
    rng, az, el = direction_angles(p_ant)
    u = p_ant / np.maximum(rng, 1e-9)[:, None]
    v_r = np.einsum("ij,ij->i", v_ant, u)
    half_path = (r_tx[:, :1] + r_rx).mean(axis=1) / 2.0
    slot_m = 2.0 * v_r[:, None] * np.arange(cfg.n_tx) / cfg.prf_hz  # (n_targets, n_tx); 0 for one transmitter
    path = ((r_tx + slot_m)[:, :, None] + r_rx[:, None, :]).reshape(len(p_ant), cfg.n_virtual)
    gain_db = cfg.antenna.gain_db(az, el)
    power_w = cfg.pe_w * 10 ** (gain_db / 5.0) * cfg.wavelength_m**2 * rcs / ((4 * np.pi) ** 3 * half_path**4)
    k = nearest_bin(half_path + coupling_s * v_r, cfg.range_resolution_m)  # coupling_s may differ from cfg's
    j = cfg.doppler_bin(v_r)
    in_view = (p_ant[:, 0] > 0) & (k >= 0) & (k < cfg.n_range) & clear
    return {
        "range_m": half_path,
        "radial_velocity_mps": v_r,
        "azimuth_rad": az,
        "elevation_rad": el,
        "power_w": power_w,
        "snr_db": 10 * np.log10(np.maximum(power_w, 1e-300) / (noise_w or cfg.noise_power_w)),
        "range_position_bins": (half_path + coupling_s * v_r) / cfg.range_resolution_m,
        "range_bin": k,
        "doppler_bin": j,
        "visible": in_view,
        "path_m": path,
    }


def add_targets(
    cube: np.ndarray,
    cfg: RadarConfig,
    geom,
    targets,
    coupling_s: float,
    clear: np.ndarray,
    power_factor: np.ndarray | None = None,
    psf_reach: tuple[int, int] | None = None,
) -> None:
    """Add the targets' returns to ``cube``: one pixel each, or the windows' exact point-spread.

    Parameters
    ----------
    cube : ndarray, shape ``cfg.frame_shape``, complex
        The frame, changed in place; pixel units ``|pixel|^2`` in W.
    cfg : RadarConfig
    geom : AntennaGeometry
    targets : sequence of PointTarget
    coupling_s : float
        Range-Doppler coupling, s (:func:`target_geometry`).
    clear : ndarray of bool, shape (n_targets,)
        Line of sight (:func:`line_of_sight`).
    power_factor : ndarray, shape (n_targets,), optional
        Scales each target's received power (Swerling fluctuation).
    psf_reach : (int, int), optional
        (range, Doppler) bins: spread each target over the windows' response at its fractional
        (range, Doppler) position (:mod:`skyradar.sim.psf`); default one pixel.

    Examples
    --------
    One pixel per antenna with the radar equation's power (:func:`target_geometry`):

    >>> cfg = RadarConfig.prototype_2022()
    >>> geom = AntennaGeometry(np.zeros(3), np.eye(3), np.array([30.0, 0, 0]), 52.0, 4.0)
    >>> target = PointTarget(np.array([1000.0, 0, 0]), np.array([10.0, 0, 0]), rcs_m2=2.0)
    >>> cube = np.zeros((cfg.n_range, cfg.n_doppler, cfg.n_rx), np.complex64)
    >>> add_targets(cube, cfg, geom, [target], 0.0, np.array([True]))
    >>> k, j, _ = np.unravel_index(np.abs(cube).argmax(), cube.shape)
    >>> round(float(cfg.range_axis_m[k]), 1), round(float(cfg.doppler_axis_mps[j]), 1)
    (1004.3, -20.0)
    >>> int(np.count_nonzero(cube)), f"{float(np.abs(cube[k, j, 0]) ** 2):.2e}"
    (4, '7.23e-16')
    """
    g = target_geometry(cfg, geom, targets, coupling_s, clear)
    keep = g["visible"]
    if not np.any(keep):
        return
    power = g["power_w"] if power_factor is None else g["power_w"] * np.asarray(power_factor, float)
    amp = np.sqrt(power[keep])[:, None]
    phase = 2 * np.pi * np.mod(g["path_m"][keep] / cfg.wavelength_m, 1.0)
    values = amp * np.exp(1j * phase)
    if psf_reach is not None:
        _add_spread(cube, cfg, g, keep, values, psf_reach)
        return
    for q in range(cfg.n_virtual):
        np.add.at(
            cube[..., q], (g["range_bin"][keep], g["doppler_bin"][keep]), values[:, q].astype(cube.dtype)
        )


def _add_spread(cube, cfg: RadarConfig, g, keep, values, reach: tuple[int, int]) -> None:
    # Range position as the bins' own (with the coupling shift), Doppler as doppler_bin's.
    x_range = g["range_position_bins"][keep]
    n_doppler = cfg.n_doppler_per_tx
    x_doppler = g["radial_velocity_mps"][keep] / cfg.doppler_resolution_mps + n_doppler // 2
    for t in range(values.shape[0]):
        kr, wr = target_psf_taps(PSF_WINDOW, cfg.samples_per_chirp, x_range[t], reach[0], cfg.n_range, False)
        kd, wd = target_psf_taps(PSF_WINDOW, n_doppler, x_doppler[t], reach[1], n_doppler, True)
        spread = np.multiply.outer(np.multiply.outer(wr, wd), values[t])
        cube[np.ix_(kr, kd)] += spread.astype(cube.dtype)
