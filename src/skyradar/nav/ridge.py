"""The ground-return ridge of a range-Doppler image: per range bin, the largest closing speed.

Sign convention: radial velocity is positive receding, so ground ahead of a forward-flying
aircraft approaches with *negative* radial velocity. At a given range the ground point straight
ahead on the track approaches fastest; the thesis' "largest radial velocity" is therefore the
largest closing speed, i.e. the **most negative** radial velocity of the ground band in that
range bin. This module returns it, unaliased.

Steps per frame:

1. Power image (sum of ``|iq|^2`` over receivers, :func:`summed_power_image`) and a noise floor: the
   larger of the thermal noise of the RadarConfig and a low quantile of the image scaled by the
   chi-square statistics of ``n_rx`` summed exponentials, so real data with a raised floor gate correctly.
2. Gate: pixels ``threshold_db`` above the noise floor are "occupied"; per range bin, fades of
   up to ``max_gap_bins`` Doppler bins inside the band are closed and runs shorter than
   ``min_band_bins`` (noise, small intruders) are dropped. All of this is circular in Doppler.
3. Per range bin the Doppler axis is a circle (a radial velocity outside [-VLim, VLim) wraps):
   the ground band [V_min(r), V_max(r)] plus an empty arc. The ridge pixel is the first occupied
   bin after the widest empty arc, going towards receding velocities: the closing end of the
   band, wherever it wrapped to. (A histogram over all ranges does not work: antenna sidelobes
   put ground near the nadir and behind the antenna at every Doppler.)
4. Aliasing: the ridge velocities are unwrapped along range (the ridge is continuous in range;
   an isolated outlier bin does not shift its neighbours), then shifted by whole multiples of
   2 VLim: to the turn nearest a predicted ridge when a prior state is given, otherwise so that
   the median ridge velocity lies in [-2 VLim, 0) (ground ahead closes). Without a prior that
   covers ground speeds up to about 2.5 VLim (100 m/s for the prototype).
5. Sub-bin placement: the image simulator, like the thesis', puts each surface into its nearest
   bin, so within range bin ``k`` the fastest-closing ground lies at the *far edge* of the bin,
   ``(k + 1/2) dR`` (closing speed grows with range along the ridge), and its radial velocity is
   anywhere in the ridge Doppler bin (estimate: the bin centre, unbiased). Using the bin centre
   in range instead biases every pair by dR/2 = 7.5 m, the size of the thesis' height error.
   The sawtooth range-Doppler coupling (apparent range shifted by ``v * fc / (B PRF)``, 0.19 m
   per m/s) is removed with the unaliased velocity.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.nav._flight_state_kernels import ridge_rows
from skyradar.process.power import power_image
from skyradar.quantiles import gamma_quantile

__all__ = ["Ridge", "summed_power_image", "noise_floor_w", "band_start", "extract_ridge"]


@dataclass(frozen=True)
class Ridge:
    """Ridge pairs of one frame (only range bins where a ground band was found).

    Attributes
    ----------
    range_m : ndarray
        True range of the ridge point (edge placement and range-Doppler coupling removed), m.
    radial_velocity_mps : ndarray
        Unaliased radial velocity of the ridge point (negative: closing), m/s.
    range_bin : ndarray of int
        Range bin index.
    doppler_bin : ndarray of int
        Doppler bin index in the image (FFT-shifted order) of the ridge pixel.
    snr_db : ndarray
        Ridge pixel power over the noise floor, dB.
    noise_w : float
        Noise floor of the summed power image, W per pixel.
    n_occupied : int
        Pixels above the gate in the whole image.

    Examples
    --------
    >>> ridge = Ridge(np.array([600.0, 615.0]), np.array([-20.0, -21.5]), np.array([40, 41]),
    ...               np.array([60, 58]), np.array([18.0, 17.5]), 1e-13, 35)
    >>> len(ridge), len(Ridge.empty()), ridge.radial_velocity_mps.min()
    (2, 0, np.float64(-21.5))
    >>> cfg = RadarConfig.prototype_2022()
    >>> len(extract_ridge(np.zeros((cfg.n_range, cfg.n_doppler)), cfg))  # only sky: no ridge
    0
    """

    range_m: np.ndarray
    radial_velocity_mps: np.ndarray
    range_bin: np.ndarray
    doppler_bin: np.ndarray
    snr_db: np.ndarray
    noise_w: float
    n_occupied: int

    def __len__(self) -> int:
        return int(self.range_m.size)

    @classmethod
    def empty(cls, noise_w: float = float("nan"), n_occupied: int = 0) -> Ridge:
        e = np.zeros(0)
        return cls(e, e, e.astype(int), e.astype(int), e, noise_w, n_occupied)


def summed_power_image(iq: np.ndarray) -> np.ndarray:
    """Channel-SUMMED received power per pixel, W (float64): (range, doppler, rx) complex -> (range, doppler).

    ``n_rx`` times :func:`skyradar.process.power.power_image` (the channel mean), so thermal noise
    is a sum of ``n_rx`` exponentials, as :func:`noise_floor_w` assumes. A real 2-D array is taken
    as a summed power image already.

    Examples
    --------
    >>> summed_power_image(np.full((2, 3, 4), 1 + 1j)).tolist()[0]
    [8.0, 8.0, 8.0]
    """
    arr = np.asarray(iq)
    if arr.ndim == 3:
        return arr.shape[2] * power_image(arr, dtype=np.float64)
    if arr.ndim == 2 and not np.iscomplexobj(arr):
        return arr.astype(np.float64)
    raise InputError(
        f"frame: expected (range, doppler, rx) complex or (range, doppler) power, got shape {arr.shape}"
    )


def noise_floor_w(
    power: np.ndarray, n_rx: int, thermal_w: float | None = None, quantile: float = 0.2
) -> float:
    """Mean noise power per pixel of a summed power image, W.

    The ``quantile`` of the image divided by the same quantile of a Gamma(n_rx) variable
    (sum of ``n_rx`` exponentials), floored at ``n_rx * thermal_w`` when given.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> p = rng.exponential(2.0, (300, 250, 4)).sum(axis=2)
    >>> round(noise_floor_w(p, 4) / 8.0, 1)
    1.0
    """
    est = float(np.quantile(power, quantile)) * n_rx / _gamma_quantile(quantile, n_rx)
    if thermal_w is not None:
        est = max(est, n_rx * float(thermal_w))
    return est


@lru_cache(maxsize=64)
def _gamma_quantile(quantile: float, n_rx: int) -> float:
    # Every frame asks the same question; the cache answers it once.
    return gamma_quantile(quantile, n_rx)


def band_start(occupied: np.ndarray) -> np.ndarray | int | None:
    """First occupied Doppler bin after the widest circular run of empty bins (the ground band's start).

    ``occupied`` is one row (returns an int, or None when the row is all empty or all
    occupied) or a 2-D array of rows (returns an int array, -1 for such rows).

    Examples
    --------
    >>> band_start(np.array([1, 1, 0, 0, 0, 0, 1, 1], bool))  # band 6, 7, 0, 1 wraps
    6
    >>> band_start(np.array([0, 1, 1, 1, 0, 0, 0, 0], bool))
    1
    """
    occ = np.atleast_2d(np.asarray(occupied, bool))
    n = occ.shape[1]
    doubled = np.concatenate([occ, occ], axis=1)
    index = np.arange(2 * n)
    # Length of the empty run ending at each position of the doubled (unrolled) circle.
    last_occupied = np.maximum.accumulate(np.where(doubled, index, -1), axis=1)
    run = np.where(doubled, 0, index - last_occupied)
    start = (np.argmax(run, axis=1) + 1) % n
    start[~occ.any(axis=1) | occ.all(axis=1)] = -1
    if np.ndim(occupied) == 1:
        return None if start[0] < 0 else int(start[0])
    return start


def extract_ridge(
    frame: np.ndarray,
    config: RadarConfig,
    threshold_db: float = 8.0,
    min_range_m: float = 150.0,
    max_gap_bins: int = 2,
    min_band_bins: int = 2,
    edge_offset_bins: float = 0.5,
    prior_state: tuple[float, float, float] | None = None,
) -> Ridge:
    """Ground ridge of one frame (see the module docstring for the method).

    Parameters
    ----------
    frame : ndarray
        (range, doppler, rx) complex pixels, or a (range, doppler) power image, W.
    config : RadarConfig
        Axes, coupling and thermal noise.
    threshold_db : float
        Gate above the noise floor. 8 dB over the mean of four summed exponentials leaves about
        one false pixel in ten frames of 333 x 250.
    min_range_m : float
        Ignore nearer bins (near-range leakage in real data).
    max_gap_bins, min_band_bins : int
        Fades up to this many Doppler bins inside the band are closed; bands shorter than
        ``min_band_bins`` are not ground.
    edge_offset_bins : float
        Where in a range bin the ridge point lies: 0.5 (far edge) for nearest-bin imaging.
    prior_state : (vx_mps, vz_mps, h_m), optional
        Predicted flight state; resolves the alias multiple of 2 VLim.

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> extract_ridge(np.zeros((cfg.n_range, cfg.n_doppler)), cfg).range_m.size
    0
    """
    power = summed_power_image(frame)
    if power.shape != (config.n_range, config.n_doppler):
        raise InputError(
            f"frame: shape {power.shape} does not match radar ({config.n_range}, {config.n_doppler})"
        )
    n_rx = frame.shape[2] if np.asarray(frame).ndim == 3 else config.n_rx
    noise = noise_floor_w(power, n_rx, config.noise_power_w)
    mask = power > noise * 10 ** (threshold_db / 10.0)
    mask[: int(np.ceil(min_range_m / config.range_resolution_m))] = False
    n_occ = int(mask.sum())
    # Per range row: fades closed, short runs dropped, the band's first bin (see band_start).
    rows, dopp = ridge_rows(mask, max_gap_bins, min_band_bins)
    if rows.size == 0:
        return Ridge.empty(noise, n_occ)
    # Unwrap along range (the ridge is continuous in range), then pick the alias turn.
    width = 2.0 * config.v_lim_mps
    vel = np.unwrap(config.doppler_axis_mps[dopp], period=width)
    vel = vel + width * _alias_turns(vel, rows, config, prior_state, edge_offset_bins)
    rng = config.range_at_bin_m(rows + edge_offset_bins) - config.range_doppler_coupling_s * vel
    snr = 10.0 * np.log10(power[rows, dopp] / noise)
    return Ridge(rng, vel, rows, dopp, snr, noise, n_occ)


def _alias_turns(
    vel: np.ndarray,
    rows: np.ndarray,
    config: RadarConfig,
    prior_state: tuple[float, float, float] | None,
    edge_offset_bins: float,
) -> int:
    width = 2.0 * config.v_lim_mps
    if vel.size == 0:
        return 0
    if prior_state is not None and all(np.isfinite(prior_state)):
        from skyradar.nav.inversion import ridge_velocity

        r = config.range_at_bin_m(rows + edge_offset_bins)
        predicted = ridge_velocity(r, *prior_state)
        ok = np.isfinite(predicted)
        if ok.sum() >= 3:
            return int(np.round(np.median(predicted[ok] - vel[ok]) / width))
    return int(np.floor(-np.median(vel) / width))
