"""Synthetic detections from truth geometry: noise, aliasing, missed detections, clutter.

Used to test and benchmark the tracker independently of the simulator and the detector: each
visible truth is detected with probability ``pd``, its range gets Gaussian noise, its radial
velocity gets Gaussian noise and is then wrapped into ``[-VLim, VLim)`` as the Doppler FFT does;
clutter is uniform over the image. The range includes the sawtooth range-Doppler coupling.
Optional 3-D positions get an angular error.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from skyradar.config import RadarConfig
from skyradar.units import wrap

__all__ = ["synthetic_detections"]


def synthetic_detections(
    times_s: np.ndarray,
    range_m: np.ndarray,
    radial_velocity_mps: np.ndarray,
    visible: np.ndarray | None = None,
    config: RadarConfig | None = None,
    sigma_range_m: float = 4.0,
    sigma_velocity_mps: float = 0.1,
    pd_detect: float = 1.0,
    clutter_per_frame: float = 0.0,
    positions_ned_m: np.ndarray | None = None,
    sigma_angle_rad: float = 0.04,
    seed: int = 0,
    coupling: bool = True,
    clutter_min_range_m: float = 0.0,
) -> pd.DataFrame:
    """Detections table (``time_s, frame, range_m, radial_velocity_mps, target``) from truth.

    Parameters
    ----------
    times_s : ndarray, shape (n_time,)
    range_m, radial_velocity_mps : ndarray, shape (n_time, n_target)
        True range and (unaliased) radial velocity.
    visible : ndarray of bool, shape (n_time, n_target), optional
        Which truths can be detected (default all with range below the processed range).
    config : RadarConfig, optional
        Sets VLim and the processed range (default: thesis prototype).
    sigma_range_m, sigma_velocity_mps : float
        Measurement noise.
    pd_detect : float or ndarray, shape (n_time, n_target)
        Probability of detection of a visible truth (an array: per truth and frame, e.g. from its SNR).
    clutter_per_frame : float
        Mean number of clutter detections per frame (Poisson), uniform over the image.
    positions_ned_m : ndarray, shape (n_time, n_target, 3), optional
        True positions; adds ``north_m, east_m, down_m`` with isotropic error ``range * sigma_angle``.
    seed : int
    coupling : bool
        Add the sawtooth range-Doppler coupling ``config.range_doppler_coupling_s * V`` (true,
        unaliased ``V``) to the range, as the radar measures it.
    clutter_min_range_m : float
        Clutter is uniform in range over ``[clutter_min_range_m, range_limit_m)``.

    Examples
    --------
    >>> t = np.arange(3) * 0.1
    >>> det = synthetic_detections(t, np.full((3, 1), 1000.0), np.full((3, 1), -60.0))
    >>> det.radial_velocity_mps.round(0).tolist()
    [18.0, 18.0, 18.0]
    """
    config, rng = config or RadarConfig.prototype_2022(), np.random.default_rng(seed)
    t = np.asarray(times_s, float)
    R, V = (np.asarray(a, float).reshape(t.size, -1) for a in (range_m, radial_velocity_mps))
    vis = (config.range_limit_m > R) if visible is None else np.asarray(visible, bool).reshape(R.shape)
    # One generator, drawn in a fixed order (detections, noise, positions, clutter): same seed, same table.
    fi, ti = np.nonzero(vis & (rng.random(R.shape) < pd_detect))
    cols = _noisy_truth(rng, t, R, V, fi, ti, config, sigma_range_m, sigma_velocity_mps, coupling)
    cols |= _noisy_positions(rng, positions_ned_m, fi, ti, R[fi, ti] * sigma_angle_rad)
    clutter = _clutter(rng, t, clutter_per_frame, config, positions_ned_m is not None, clutter_min_range_m)
    df = pd.concat([pd.DataFrame(cols), pd.DataFrame(clutter)], ignore_index=True)
    return df.sort_values(["time_s", "range_m"], kind="stable").reset_index(drop=True)


def _noisy_truth(rng, t, R, V, fi, ti, config: RadarConfig, sigma_range_m, sigma_velocity_mps, coupling):
    """Detections of the truths at (frame ``fi``, target ``ti``): noisy range, noisy wrapped velocity."""
    width = 2.0 * config.v_lim_mps
    range_m = R[fi, ti] + (config.range_doppler_coupling_s * V[fi, ti] if coupling else 0.0)
    range_m = range_m + rng.normal(0.0, sigma_range_m, fi.size)
    velocity = wrap(V[fi, ti] + rng.normal(0.0, sigma_velocity_mps, fi.size), width)
    return {"time_s": t[fi], "frame": fi, "range_m": range_m, "radial_velocity_mps": velocity, "target": ti}


def _noisy_positions(rng, positions_ned_m, fi, ti, sigma_m: np.ndarray) -> dict[str, np.ndarray]:
    """Positions of the truths at (``fi``, ``ti``) with isotropic Gaussian error ``sigma_m``; {} without."""
    if positions_ned_m is None:
        return {}
    pos = np.asarray(positions_ned_m, float)[fi, ti]
    err = rng.normal(0.0, 1.0, (pos.shape[0], 3)) * sigma_m[:, None]
    return {name: pos[:, c] + err[:, c] for c, name in enumerate(("north_m", "east_m", "down_m"))}


def _clutter(
    rng, t, clutter_per_frame: float, config: RadarConfig, with_positions: bool, min_range_m: float
) -> dict:
    """Poisson-many clutter detections per frame, uniform over the image (``target`` -1, no position)."""
    n_clutter = rng.poisson(clutter_per_frame, t.size) if clutter_per_frame > 0 else np.zeros(t.size, int)
    cf = np.repeat(np.arange(t.size), n_clutter)
    clutter = {
        "time_s": t[cf],
        "frame": cf,
        "range_m": rng.uniform(min_range_m, config.range_limit_m, cf.size),
        "radial_velocity_mps": rng.uniform(-config.v_lim_mps, config.v_lim_mps, cf.size),
        "target": np.full(cf.size, -1),
    }
    if with_positions:
        for name in ("north_m", "east_m", "down_m"):
            clutter[name] = np.full(cf.size, np.nan)
    return clutter
