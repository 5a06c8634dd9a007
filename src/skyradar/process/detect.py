"""Pixel detection in range-Doppler images: CFAR and Shi-Tomasi corners, one point per object.

A point object falls in about one range bin and one Doppler bin, but leakage spreads it into a
small blob. A plain threshold splits the blob into several detections; here every detector
returns one detection per connected blob, at the blob's brightest pixel, refined to sub-pixel
accuracy by a parabola through the dB values of the peak and its neighbours.

Images are the non-coherent mean over receive channels, ``mean_k |x_k / c_k|^2`` (W,
:func:`skyradar.process.power.power_image`, also importable here as ``integrate_channels``), so the
thermal noise per pixel keeps its single-channel mean ``config.noise_power_w`` and follows a
Gamma(L, 1/L) law for L channels; the CFAR factors below are exact for that law. The Doppler
axis wraps around (aliasing), so every window and every blob wraps across its edges.

Examples
--------
>>> from skyradar.config import RadarConfig
>>> cfg = RadarConfig.prototype_2022()
>>> rng = np.random.default_rng(0)
>>> shape = (cfg.n_range, cfg.n_doppler, cfg.n_rx)
>>> cube = (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)) * np.sqrt(cfg.noise_power_w / 2)
>>> cube[100, 40, :] += np.sqrt(1000 * cfg.noise_power_w)  # one 30 dB object
>>> det = detect(integrate_channels(cube), cfg)
>>> det.range_index.tolist(), det.doppler_index.tolist(), bool(abs(det.snr_db[0] - 30) < 1)
([100], [40], True)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import cv2
import numpy as np
from numba import njit

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.process.cfar import cfar_2d, cfar_2d_floor, cfar_factor
from skyradar.process.power import power_image
from skyradar.units import wrap

__all__ = [
    "Detections",
    "integrate_channels",
    "cfar_factor",
    "cfar_2d",
    "shi_tomasi",
    "blob_peaks",
    "refine_peaks",
    "detect",
]


@dataclass(frozen=True)
class Detections:
    """Detections of one frame (all arrays of length n).

    Attributes
    ----------
    range_index, doppler_index : ndarray of int
        Peak pixel.
    range_bin, doppler_bin : ndarray of float
        Sub-pixel peak position in bins (Doppler wrapped into [0, n_doppler)).
    power_w : ndarray
        Peak pixel power (mean over channels), W.
    noise_w : ndarray
        Noise power per pixel used for the SNR, W.
    snr_db : ndarray
        Per-channel, per-pixel SNR of the peak, ``(power - noise) / noise`` in dB.
    secondary : ndarray of bool
        True where the blob passed only the secondary threshold of a nulled cell (see
        :func:`detect`'s ``pfa_secondary``); all False by default.

    Examples
    --------
    One 30 dB pixel in range bin 100 (100 x 14.99 m) and Doppler bin 40 (85 bins of 0.313 m/s
    below zero Doppler, bin 125):

    >>> from skyradar.config import RadarConfig
    >>> cfg = RadarConfig.prototype_2022()
    >>> power = np.full((cfg.n_range, cfg.n_doppler), cfg.noise_power_w, np.float32)
    >>> power[100, 40] = 1001 * cfg.noise_power_w
    >>> det = detect(power, cfg)
    >>> len(det), det.snr_db.round(3).tolist(), det.range_m(cfg).round(2).tolist()
    (1, [30.0], [1498.96])
    >>> det.radial_velocity_mps(cfg).round(2).tolist(), len(det.select(det.snr_db > 40.0))
    ([-26.61], 0)
    """

    range_index: np.ndarray
    doppler_index: np.ndarray
    range_bin: np.ndarray
    doppler_bin: np.ndarray
    power_w: np.ndarray
    noise_w: np.ndarray
    snr_db: np.ndarray
    secondary: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.secondary is None:
            object.__setattr__(self, "secondary", np.zeros(self.range_index.size, bool))

    def __len__(self) -> int:
        return int(self.range_index.size)

    def range_m(self, config: RadarConfig) -> np.ndarray:
        """Range of each detection, m (bin k centred at k*dR)."""
        return config.range_at_bin_m(self.range_bin)

    def radial_velocity_mps(self, config: RadarConfig) -> np.ndarray:
        """Radial velocity (aliased into [-VLim, VLim)), m/s, positive receding."""
        v = config.radial_velocity_at_bin_mps(self.doppler_bin)
        return wrap(v, 2.0 * config.v_lim_mps)

    def select(self, keep: np.ndarray) -> Detections:
        """The subset where ``keep`` is true (boolean or index array)."""
        return Detections(*(getattr(self, f)[keep] for f in self.__dataclass_fields__))


# The channel-integrated image has one home, skyradar.process.power; the old name stays importable here.
integrate_channels = power_image


def shi_tomasi(
    power_db: np.ndarray,
    max_corners: int = 200,
    quality: float = 0.05,
    min_distance: int = 3,
    block_size: int = 3,
) -> np.ndarray:
    """Shi-Tomasi corners of a dB image (OpenCV ``goodFeaturesToTrack``), Doppler wrapping.

    Parameters
    ----------
    power_db : ndarray (n_range, n_doppler)
        Power image, dB.
    max_corners : int
        Most corners returned.
    quality : float
        Relative to the strongest corner's minimum eigenvalue, as in OpenCV.
    min_distance : int
        Least distance between two corners, bins.
    block_size : int
        Side of the window the gradient covariance is summed over, bins.

    Returns
    -------
    ndarray (n, 2) of int
        (range_index, doppler_index), strongest corner first.

    Examples
    --------
    >>> img = np.zeros((20, 30))
    >>> img[5, 10], img[12, 20] = 30.0, 20.0
    >>> shi_tomasi(img).tolist()
    [[5, 10], [12, 20]]
    """
    image = np.asarray(power_db, dtype=np.float32)
    pad = block_size + min_distance
    # Doppler wraps; beyond the range edges lies a flat noise floor, so peaks on the first/last bin
    # stay corners (reflection would mirror them into ridges).
    padded = np.pad(
        np.concatenate([image[:, -pad:], image, image[:, :pad]], axis=1),
        ((pad, pad), (0, 0)),
        constant_values=float(np.median(image)),
    )
    corners = cv2.goodFeaturesToTrack(
        np.ascontiguousarray(padded), max_corners, quality, min_distance, blockSize=block_size
    )
    if corners is None:
        return np.zeros((0, 2), np.int64)
    xy = np.rint(corners[:, 0, :]).astype(np.int64) - pad  # OpenCV gives (x = Doppler, y = range)
    inside = (xy[:, 0] >= 0) & (xy[:, 0] < image.shape[1]) & (xy[:, 1] >= 0) & (xy[:, 1] < image.shape[0])
    return np.stack([xy[inside, 1], xy[inside, 0]], axis=1)


@njit(cache=True)
def _flood_peaks(mask: np.ndarray, power: np.ndarray, seeds: np.ndarray, use_seeds: bool) -> np.ndarray:
    """(n, 2) peak pixels of 8-connected blobs; Doppler (axis 1) wraps, range does not."""
    n_r, n_d = mask.shape
    seen = np.zeros((n_r, n_d), np.bool_)
    stack = np.empty((n_r * n_d, 2), np.int64)
    peaks = np.empty((n_r * n_d // 2 + 1, 2), np.int64)
    n_peaks = 0
    for i0 in range(n_r):
        for j0 in range(n_d):
            if not mask[i0, j0] or seen[i0, j0]:
                continue
            seen[i0, j0] = True
            top = 0
            stack[0, 0], stack[0, 1] = i0, j0
            best, bi, bj, seeded = power[i0, j0], i0, j0, seeds[i0, j0]
            while top >= 0:
                i, j = stack[top, 0], stack[top, 1]
                top -= 1
                for di in range(-1, 2):
                    ii = i + di
                    if ii < 0 or ii >= n_r:
                        continue
                    for dj in range(-1, 2):
                        jj = (j + dj) % n_d
                        if mask[ii, jj] and not seen[ii, jj]:
                            seen[ii, jj] = True
                            top += 1
                            stack[top, 0], stack[top, 1] = ii, jj
                            seeded = seeded or seeds[ii, jj]
                            if power[ii, jj] > best:
                                best, bi, bj = power[ii, jj], ii, jj
            if seeded or not use_seeds:
                peaks[n_peaks, 0], peaks[n_peaks, 1] = bi, bj
                n_peaks += 1
    return peaks[:n_peaks]


def _snap_to_max(power: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Move each (range, Doppler) point to the brightest pixel of its 3x3 neighbourhood."""
    if len(points) == 0:
        return points
    n_r, n_d = power.shape
    off = np.array([(a, b) for a in (-1, 0, 1) for b in (-1, 0, 1)])
    r = np.clip(points[:, None, 0] + off[:, 0], 0, n_r - 1)
    d = (points[:, None, 1] + off[:, 1]) % n_d
    best = np.argmax(power[r, d], axis=1)
    rows = np.arange(len(points))
    return np.stack([r[rows, best], d[rows, best]], axis=1)


def blob_peaks(
    mask: np.ndarray, power: np.ndarray, seeds: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Brightest pixel of each 8-connected blob of ``mask`` (blobs join across the Doppler edge).

    Parameters
    ----------
    mask : ndarray of bool (n_range, n_doppler)
        Pixels that passed the threshold.
    power : ndarray (n_range, n_doppler)
        Power image, W: the brightest pixel of each blob is its peak.
    seeds : ndarray of bool (n_range, n_doppler), optional
        Only blobs containing a seed pixel are kept.

    Returns
    -------
    (range_index, doppler_index) : tuple of ndarray of int
        Peak pixel of each blob, strongest blob first.

    Examples
    --------
    Pixels (1, 0) and (1, 7) touch across the Doppler edge and form one blob:

    >>> mask = np.zeros((5, 8), bool)
    >>> mask[1, [0, 7]] = mask[3, 3] = True
    >>> power = np.zeros((5, 8))
    >>> power[1, 0], power[1, 7], power[3, 3] = 2.0, 5.0, 3.0
    >>> [x.tolist() for x in blob_peaks(mask, power)]
    [[1, 3], [7, 3]]
    >>> [x.tolist() for x in blob_peaks(mask, power, seeds=power == 2.0)]
    [[1], [7]]
    """
    mask = np.ascontiguousarray(mask, dtype=np.bool_)
    use_seeds = seeds is not None
    seeds = np.ascontiguousarray(seeds, dtype=np.bool_) if use_seeds else mask
    peaks = _flood_peaks(mask, np.ascontiguousarray(power, dtype=np.float32), seeds, use_seeds)
    order = np.argsort(-power[peaks[:, 0], peaks[:, 1]], kind="stable")
    return peaks[order, 0], peaks[order, 1]


_TINY32 = np.float32(np.finfo(np.float32).tiny)


def refine_peaks(power: np.ndarray, r: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sub-pixel peak position: a parabola through the dB values of the peak and its neighbours.

    Exact for a Gaussian-shaped peak; for a Hann-windowed sinc the bias stays below about 0.05 bin.
    Range edges get no offset; Doppler neighbours wrap.

    Parameters
    ----------
    power : ndarray (n_range, n_doppler)
        Power image, W.
    r, d : ndarray of int
        Peak pixels.

    Returns
    -------
    (range_bin, doppler_bin) : tuple of ndarray of float
        Sub-pixel positions, bins (offsets at most half a bin; Doppler wrapped into [0, n_doppler)).

    Examples
    --------
    A Gaussian peak centred at range bin 10.3, Doppler bin 4:

    >>> rr, dd = np.meshgrid(np.arange(20.0), np.arange(16.0), indexing="ij")
    >>> power = np.exp(-((rr - 10.3) ** 2) / 2.0 - (dd - 4.0) ** 2 / 8.0)
    >>> [x.round(6).tolist() for x in refine_peaks(power, np.array([10]), np.array([4]))]
    [[10.3], [4.0]]
    """
    n_r, n_d = power.shape
    floor = _TINY32
    db = lambda i, j: np.log(np.maximum(power[i, j], floor))  # noqa: E731 - local shorthand
    c = db(r, d)
    rm, rp = np.clip(r - 1, 0, n_r - 1), np.clip(r + 1, 0, n_r - 1)
    dm, dp = (d - 1) % n_d, (d + 1) % n_d

    def offset(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        den = lo - 2.0 * c + hi
        with np.errstate(divide="ignore", invalid="ignore"):
            off = np.where(den < 0, 0.5 * (lo - hi) / den, 0.0)
        return np.clip(off, -0.5, 0.5)

    dr = offset(db(rm, d), db(rp, d))
    dr[(r == 0) | (r == n_r - 1)] = 0.0
    dd = offset(db(r, dm), db(r, dp))
    return r + dr, (d + dd) % n_d


def _shi_tomasi_blobs(power: np.ndarray, noise_power_w: float, min_snr_db: float, exclude) -> tuple:
    """Peaks of the blobs around the Shi-Tomasi corners of the dB image that reach ``min_snr_db``."""
    floor = np.float32(noise_power_w * 1e-3)
    image = power if exclude is None else np.where(exclude, np.float32(noise_power_w), power)
    corners = shi_tomasi(10.0 * np.log10(np.maximum(image, floor)))
    corners = _snap_to_max(image, corners)
    noise_all = np.full(len(corners), noise_power_w, np.float32)
    strong = power[corners[:, 0], corners[:, 1]] >= noise_all * (1.0 + 10 ** (min_snr_db / 10.0))
    seeds = np.zeros(power.shape, bool)
    seeds[corners[strong, 0], corners[strong, 1]] = True
    # Each strong corner stands for its whole blob (pixels above half its SNR): one object, one detection.
    grow = power > noise_all.dtype.type(noise_power_w * (1.0 + 0.5 * 10 ** (min_snr_db / 10.0)))
    if exclude is not None:
        seeds &= ~exclude
        grow &= ~exclude
    return blob_peaks(grow | seeds, power, seeds)


def _suppressed_cfar(power, floor_w, channels, exclude, train_exclude, guard, train, pfa):
    """CA-CFAR of a clutter-suppressed image: spur pixels out of everything, clutter out of training."""
    skip = exclude if train_exclude is None else train_exclude
    skip = skip if exclude is None or train_exclude is None else exclude | train_exclude
    # Noise estimates only where a hit is possible: the peaks read it, nothing else does.
    hits, noise_map = cfar_2d_floor(power, channels, floor_w, skip, guard, train, pfa, noise_map=False)
    return (hits if exclude is None else hits & ~exclude), noise_map, skip


def _secondary_blobs(
    power, hits, noise_map, channels, n_rx, floor_w, exclude, skip, guard, train, pfa_secondary
):
    """Peaks of the blobs that pass ``pfa_secondary`` in nulled cells and hold no primary hit.

    A blob with a primary hit is the primary detection's; the rest are the secondary detections.
    Their noise estimates are merged into ``noise_map`` (NaN elsewhere, as the sparse CFAR leaves it).
    """
    low, low_noise = cfar_2d_floor(
        power, channels, floor_w, skip, guard, train, pfa_secondary, noise_map=False
    )
    low &= channels < n_rx
    if exclude is not None:
        low &= ~exclude
    if not low.any():
        return np.zeros(0, np.intp), np.zeros(0, np.intp)
    merged = low | hits
    r_all, d_all = blob_peaks(merged, power)
    r_pri, d_pri = blob_peaks(merged, power, hits)
    primary = np.zeros(power.shape, bool)
    primary[r_pri, d_pri] = True
    keep = ~primary[r_all, d_all]
    r, d = r_all[keep], d_all[keep]
    noise_map[r, d] = low_noise[r, d]
    return r, d


def detect(
    power: np.ndarray,
    config: RadarConfig,
    method: Literal["cfar", "os-cfar", "shi-tomasi"] = "cfar",
    pfa: float = 2e-8,
    guard: tuple[int, int] = (2, 2),
    train: tuple[int, int] = (4, 8),
    min_snr_db: float = 12.0,
    use_cfar_noise: bool = True,
    exclude: np.ndarray | None = None,
    channels: np.ndarray | None = None,
    train_exclude: np.ndarray | None = None,
    noise_floor_w: float | None = None,
    pfa_secondary: float | None = None,
) -> Detections:
    """Detect objects in a channel-integrated power image: one detection per blob.

    Parameters
    ----------
    power : ndarray, shape (n_range, n_doppler)
        Mean power over ``config.n_rx`` channels, W (:func:`integrate_channels`).
    config : RadarConfig
        Supplies the channel count and the thermal noise power per pixel.
    method : {"cfar", "os-cfar", "shi-tomasi"}
        CA-CFAR or OS-CFAR blobs; or Shi-Tomasi corners of the dB image kept when their SNR
        against ``config.noise_power_w`` reaches ``min_snr_db`` (the thesis' detector).
    pfa : float
        CFAR false-alarm probability per pixel (2e-8: about 0.002 false alarms per prototype frame).
    guard, train : (int, int)
        CFAR guard and training cells on each side (range, Doppler), bins.
    min_snr_db : float
        SNR a Shi-Tomasi corner needs, dB.
    use_cfar_noise : bool
        SNR against the CFAR noise estimate (True) or against ``config.noise_power_w``.
    exclude : ndarray of bool, optional
        Pixels never detected and left out of CFAR training (e.g. ``SpurMap.mask``).
    channels, train_exclude, noise_floor_w : optional
        A clutter-suppressed image's channels per pixel, pixels kept out of CFAR training only and
        noise floor (default ``config.noise_power_w``): :func:`skyradar.process.cfar.cfar_2d_floor`.
    pfa_secondary : float, optional
        With ``channels`` and above ``pfa``: also report, flagged ``secondary``, the blobs of
        nulled cells (fewer than ``config.n_rx`` channels left) that pass CA-CFAR at this larger
        false-alarm probability but not at ``pfa``. The nulls cost a target in a ground cell several dB of
        SNR; a tracker that already follows it needs only the few cells its gate predicts, where
        this threshold's false alarms are rare, and may update it from them (never start a track).

    Returns
    -------
    Detections
        One per blob, strongest first (``secondary`` ones after the others).

    Examples
    --------
    A single pixel 1000 times over a flat noise floor: one detection at 30 dB SNR, in its pixel
    (its neighbours are equal, so no sub-pixel offset):

    >>> from skyradar.config import RadarConfig
    >>> cfg = RadarConfig.prototype_2022()
    >>> power = np.full((cfg.n_range, cfg.n_doppler), cfg.noise_power_w, np.float32)
    >>> power[100, 40] = 1001 * cfg.noise_power_w
    >>> det = detect(power, cfg)
    >>> det.range_bin.tolist(), det.doppler_bin.tolist(), det.snr_db.round(3).tolist()
    ([100.0], [40.0], [30.0])
    >>> det = detect(power, cfg, method="shi-tomasi")
    >>> det.range_index.tolist(), det.doppler_index.tolist()
    ([100], [40])
    """
    power = np.asarray(power, dtype=np.float32)
    if power.shape != config.frame_shape[:2]:
        raise InputError(
            f"frame: power image shape {power.shape} does not match radar_config {config.frame_shape[:2]}"
        )
    if channels is not None and method == "cfar":
        floor = config.noise_power_w if noise_floor_w is None else noise_floor_w
        hits, noise_map, skip = _suppressed_cfar(
            power, floor, channels, exclude, train_exclude, guard, train, pfa
        )
        r, d = blob_peaks(hits, power)
        secondary = np.zeros(r.size, bool)
        if pfa_secondary is not None and not 0.0 < pfa_secondary < 1.0:
            raise InputError(f"detect: field 'pfa_secondary' must be in (0, 1), got {pfa_secondary}")
        if pfa_secondary is not None and pfa_secondary > pfa:
            args = (power, hits, noise_map, channels, config.n_rx, floor, exclude, skip, guard, train)
            r_low, d_low = _secondary_blobs(*args, pfa_secondary)
            r, d = np.concatenate([r, r_low]), np.concatenate([d, d_low])
            secondary = np.concatenate([secondary, np.ones(r_low.size, bool)])
        noise = noise_map[r, d] if use_cfar_noise else np.full(r.size, config.noise_power_w, np.float32)
    elif method in ("cfar", "os-cfar"):
        kind: Literal["ca", "os"] = "ca" if method == "cfar" else "os"
        hits, noise_map = cfar_2d(power, guard, train, pfa, kind, config.n_rx, exclude=exclude)
        r, d = blob_peaks(hits, power)
        noise = noise_map[r, d] if use_cfar_noise else np.full(r.size, config.noise_power_w, np.float32)
    elif method == "shi-tomasi":
        r, d = _shi_tomasi_blobs(power, config.noise_power_w, min_snr_db, exclude)
        noise = np.full(r.size, config.noise_power_w, np.float32)
    else:
        raise InputError(f"detect: field 'method' must be 'cfar', 'os-cfar' or 'shi-tomasi', got {method!r}")
    rb, db = refine_peaks(power, r, d)
    p = power[r, d]
    snr = 10.0 * np.log10(np.maximum(p / noise - 1.0, 1e-3))
    if channels is not None and method == "cfar":
        return Detections(r, d, rb, db, p, noise, snr, secondary)
    return Detections(r, d, rb, db, p, noise, snr)
