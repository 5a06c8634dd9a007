"""The thesis' pre-processing of radar and map images before they are compared (Maas 2022, ch. 6).

Each method is a scaling step followed by a transform, as in the thesis:

========================  ================================  ==========================================
method                    scaling                           transform
========================  ================================  ==========================================
``"gamma"``               gamma correction (0.5)            none (the thesis' 53 % false-positive baseline)
``"threshold_entropy"``   threshold at the mean (method 5)  local entropy (``skimage.filters.rank``)
``"clahe_ridge"``         CLAHE (method 8)                  Sato ridge operator (Hessian eigenvalues)
``"clahe_entropy"``       CLAHE (method 9)                  local entropy
========================  ================================  ==========================================

Near-range returns are much brighter than far ones and "could not be flattened analytically" (thesis):
the local contrast steps (CLAHE, entropy) are what make a radar image comparable with a map. Every
method returns a float32 image in ``[0, 1]`` with 0 outside the valid mask, so SSIM can use
``data_range=1``. All transforms are (nearly) rotation invariant, so a world map can be processed once
and then sampled at any pose (:mod:`skyradar.nav.gpscheck.compare`).
"""

from __future__ import annotations

from typing import TypedDict

import numpy as np
from scipy.ndimage import median_filter
from skimage import exposure, filters
from skimage.morphology import disk
from skimage.util import img_as_ubyte

from skyradar.errors import InputError

__all__ = ["METHODS", "THESIS_METHOD_NUMBER", "PreprocessOptions", "scale_to_unit", "preprocess"]

METHODS = ("gamma", "threshold_entropy", "clahe_ridge", "clahe_entropy")
THESIS_METHOD_NUMBER = {"threshold_entropy": 5, "clahe_ridge": 8, "clahe_entropy": 9}


class PreprocessOptions(TypedDict, total=False):
    """Keyword options of :func:`preprocess`, kept as a set (the map's, the radar's).

    Any subset of the keys may be given; each has the meaning and default of the keyword of the
    same name of :func:`preprocess` (sizes in pixels).

    Examples
    --------
    Power 1, 10 and 100 W is 0, 10 and 20 dB, scaled to 0, 0.5 and 1; the gamma of 0.5 gives 0.707
    in the middle. NaN is outside the mask: 0.

    >>> options = PreprocessOptions(log_power=True)
    >>> preprocess(np.array([[1.0, 10.0, 100.0, np.nan]]), "gamma", **options).round(4).tolist()
    [[0.0, 0.7071, 1.0, 0.0]]
    """

    log_power: bool
    invert: bool
    despeckle_px: int
    clahe_kernel_px: int
    ridge_sigmas_px: tuple[float, ...]
    entropy_radius_px: int


def scale_to_unit(
    image: np.ndarray, mask: np.ndarray | None = None, *, log_power: bool = False, percentiles=(1.0, 99.0)
) -> np.ndarray:
    """Map the ``percentiles`` of the valid pixels to 0..1 (clipped); 0 outside ``mask``.

    Parameters
    ----------
    image : 2-D array
        Radar power (linear, set ``log_power``) or a map image; NaN counts as outside the mask.
    mask : 2-D bool array, optional
        Valid pixels (default: the finite ones).
    log_power : bool
        Convert linear power to dB first (radar images span many decades).

    Examples
    --------
    >>> scale_to_unit(np.array([[1.0, 10.0], [100.0, np.nan]]), log_power=True, percentiles=(0, 100)).tolist()
    [[0.0, 0.5], [1.0, 0.0]]
    """
    image = np.asarray(image, dtype=np.float64)
    valid = np.isfinite(image) if mask is None else (np.asarray(mask, bool) & np.isfinite(image))
    if log_power:
        with np.errstate(divide="ignore", invalid="ignore"):
            image = 10.0 * np.log10(np.where(valid, np.maximum(image, 1e-30), 1.0))
    out = np.zeros(image.shape, dtype=np.float32)
    if not valid.any():
        return out
    low, high = np.percentile(image[valid], percentiles)
    span = high - low if high > low else 1.0
    out[valid] = np.clip((image[valid] - low) / span, 0.0, 1.0)
    return out


def _entropy(unit: np.ndarray, radius_px: int) -> np.ndarray:
    """Local Shannon entropy (bits) of an 8-bit copy, scaled by its 8-bit maximum to 0..1."""
    return filters.rank.entropy(img_as_ubyte(unit), disk(radius_px)).astype(np.float32) / 8.0


def _transform(unit, valid, method, clahe_kernel_px, ridge_sigmas_px, entropy_radius_px) -> np.ndarray:
    """The method's scaling and transform of a 0..1 image."""
    if method == "gamma":
        return unit**0.5
    if method == "threshold_entropy":
        level = unit[valid].mean() if valid.any() else 0.5
        return _entropy((unit > level).astype(np.float32), entropy_radius_px)
    kernel = max(8, min(clahe_kernel_px, *unit.shape))
    equalised = exposure.equalize_adapthist(unit, kernel_size=kernel).astype(np.float32)
    if method == "clahe_entropy":
        return _entropy(equalised, entropy_radius_px)
    ridge = filters.sato(equalised, sigmas=ridge_sigmas_px, black_ridges=False, mode="reflect")
    top = np.percentile(ridge[valid], 99.0) if valid.any() else 0.0
    return np.clip(ridge / top, 0.0, 1.0) if top > 0 else np.zeros_like(ridge)


def preprocess(
    image: np.ndarray,
    method: str,
    mask: np.ndarray | None = None,
    *,
    log_power: bool = False,
    invert: bool = False,
    despeckle_px: int = 0,
    clahe_kernel_px: int = 32,
    ridge_sigmas_px: tuple[float, ...] = (1.0, 2.0),
    entropy_radius_px: int = 3,
) -> np.ndarray:
    """One of :data:`METHODS` applied to a radar or map image: float32 in 0..1, 0 outside the mask.

    Parameters
    ----------
    image : 2-D array
        Radar ground image (linear power, with ``log_power=True``) or a rendered map.
    method : str
        One of :data:`METHODS`.
    mask : 2-D bool array, optional
        Valid pixels (default: the finite ones); the result is 0 elsewhere.
    invert : bool
        Turn the grey levels over first: a map draws roads light and buildings dark, a radar sees
        buildings bright and roads dark, so the map is inverted to give both the radar's polarity.
    despeckle_px : int
        Median filter of this size (pixels) after scaling: speckle is the radar's, not the map's.
    clahe_kernel_px, ridge_sigmas_px, entropy_radius_px : scales in pixels
        CLAHE tile size, Sato scales and entropy disc radius; keep them equal for radar and map.

    Examples
    --------
    >>> img = np.zeros((40, 40)); img[:, 20] = 1.0  # a bright line
    >>> out = preprocess(img, "clahe_ridge")
    >>> out.dtype.name, bool(out[:, 20].mean() > 5 * out[:, :10].mean())
    ('float32', True)
    """
    if method not in METHODS:
        raise InputError(f"--method: must be one of {', '.join(METHODS)}, got {method!r}")
    unit = scale_to_unit(image, mask, log_power=log_power)
    valid = np.isfinite(np.asarray(image, float)) if mask is None else np.asarray(mask, bool)
    if invert:
        unit = np.where(valid, 1.0 - unit, 0.0).astype(np.float32)
    if despeckle_px > 1:
        unit = median_filter(unit, size=despeckle_px)
    out = _transform(unit, valid, method, clahe_kernel_px, ridge_sigmas_px, entropy_radius_px)
    out = np.asarray(out, dtype=np.float32)
    out[~valid] = 0.0
    return out
