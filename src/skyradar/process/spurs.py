"""Spur maps: pixels that light up in most frames whatever the scene does.

Self-interference puts fixed bright spots into every frame. With a static radar looking at a
static scene every bright spot is a spur (Maas 2022, ch. 3): run the detector over a series of
frames, dilate every detected point by one pixel (Doppler wraps), count how often each pixel is
hit, and call pixels hit in more than a fraction ``threshold`` of the frames spurs (the thesis
compared 2, 5, 10 and 25 %). Detections whose peak falls inside the map are flagged.

On a moving platform the scene moves through the image while spurs stay put, so
:class:`OnlineSpurMap` keeps an exponentially weighted hit frequency and flags the pixels that
stay lit. An object that holds the same range and radial velocity for longer than the time
constant (e.g. formation flight) would be learned too; keep the time constant short next to
the time the scene takes to move by a pixel.

Examples
--------
>>> from skyradar.config import RadarConfig
>>> cfg = RadarConfig.prototype_2022()
>>> hits = np.zeros((10, cfg.n_range, cfg.n_doppler), bool)
>>> hits[:, 50, 0] = True  # a spur on the Doppler edge, in every frame
>>> spur_map = SpurMap.from_hits(hits, threshold=0.05)
>>> spur_map.contains(np.array([50.0, 51.0, 60.0]), np.array([249.4, 1.0, 0.0])).tolist()
[True, True, False]
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any, Literal

import numpy as np
from scipy import ndimage

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.process.detect import detect
from skyradar.quantiles import gamma_quantile, gamma_upper_quantile

__all__ = ["THESIS_THRESHOLDS", "SpurMap", "detection_pixels", "learn_spur_map", "OnlineSpurMap"]

THESIS_THRESHOLDS = (0.02, 0.05, 0.10, 0.25)
_SQUARE = np.ones((3, 3), bool)


def _dilate(hits: np.ndarray) -> np.ndarray:
    """Grow every hit by one pixel (8-neighbourhood), wrapping in Doppler (last axis)."""
    padded = np.concatenate([hits[..., -1:], hits, hits[..., :1]], axis=-1)
    structure = _SQUARE if hits.ndim == 2 else _SQUARE[None]
    return ndimage.binary_dilation(padded, structure=structure)[..., 1:-1]


def detection_pixels(
    power: np.ndarray, config: RadarConfig, pixels: Literal["peaks", "hits"] = "peaks", **detect_kwargs: Any
) -> np.ndarray:
    """Boolean image of one channel-integrated frame's detections.

    ``"peaks"``: the detector's point per object (the thesis' corners). ``"hits"``: every pixel
    above the thermal noise floor at false-alarm probability ``pfa`` (default 1e-5), the floor
    estimated from the image median, so extended interference (zero-Doppler line, near-range
    leakage with its range gradient) is learned whole, not only where a CFAR window would fire.

    Parameters
    ----------
    power : ndarray (n_range, n_doppler)
        Channel-integrated frame, W.
    config : RadarConfig
        Image shape, channel count and noise power for the detector.
    pixels : {"peaks", "hits"}
        Detector points or every pixel above the floor.
    **detect_kwargs
        Passed to :func:`skyradar.process.detect.detect` (``pfa`` also sets the ``"hits"`` threshold).

    Returns
    -------
    ndarray of bool (n_range, n_doppler)

    Examples
    --------
    >>> from skyradar.config import RadarConfig
    >>> cfg = RadarConfig.prototype_2022()
    >>> def frame(target_range):  # flat noise, a spur at (50, 0) and a target at (target_range, 100)
    ...     p = np.full((cfg.n_range, cfg.n_doppler), cfg.noise_power_w, np.float32)
    ...     p[50, 0] = p[target_range, 100] = 1000 * cfg.noise_power_w
    ...     return p
    >>> np.argwhere(detection_pixels(frame(100), cfg)).tolist()
    [[50, 0], [100, 100]]
    >>> np.argwhere(detection_pixels(frame(100), cfg, "hits")).tolist()
    [[50, 0], [100, 100]]
    """
    if pixels == "hits":
        # Mean of n_rx unit exponential powers: gamma of shape n_rx and scale 1 / n_rx.
        floor = np.median(power) / (gamma_quantile(0.5, config.n_rx) / config.n_rx)
        threshold = gamma_upper_quantile(detect_kwargs.get("pfa", 1e-5), config.n_rx) / config.n_rx
        return power > np.float32(threshold * floor)
    if pixels != "peaks":
        raise InputError(f"spur map: field 'pixels' must be 'peaks' or 'hits', got {pixels!r}")
    det = detect(power, config, **detect_kwargs)
    hits = np.zeros(power.shape, bool)
    hits[det.range_index, det.doppler_index] = True
    return hits


@dataclass(frozen=True)
class SpurMap:
    """Per-pixel hit frequency over a series of frames and the threshold that makes a spur.

    Attributes
    ----------
    frequency : ndarray, shape (n_range, n_doppler), float32
        Fraction of frames in which the (dilated) detections covered each pixel.
    threshold : float
        Pixels with ``frequency > threshold`` are spurs.
    n_frames : int
        Frames the map was learned from.

    Examples
    --------
    Positions are rounded to the nearest pixel, Doppler wrapping (bin 2.0 of 2 is bin 0):

    >>> spur_map = SpurMap(np.array([[0.0, 0.3], [0.1, 0.02]]), threshold=0.05)
    >>> spur_map.mask.tolist()
    [[False, True], [True, False]]
    >>> spur_map.contains(np.array([0.2, 1.4, 0.0]), np.array([1.3, 2.0, 0.4])).tolist()
    [True, True, False]
    >>> int(spur_map.with_threshold(0.2).mask.sum())
    1
    """

    frequency: np.ndarray
    threshold: float = 0.05
    n_frames: int = 0

    def __post_init__(self) -> None:
        freq = np.asarray(self.frequency, np.float32)
        if freq.ndim != 2:
            raise InputError(f"spur map: field 'frequency' must be 2-D, got shape {freq.shape}")
        if not 0.0 <= self.threshold < 1.0:
            raise InputError(f"spur map: field 'threshold' must be in [0, 1), got {self.threshold}")
        object.__setattr__(self, "frequency", freq)

    @classmethod
    def from_hits(cls, hits: np.ndarray, threshold: float = 0.05) -> SpurMap:
        """Map from a (n_frames, n_range, n_doppler) boolean stack of detection pixels."""
        hits = np.asarray(hits, bool)
        if hits.ndim != 3 or hits.shape[0] == 0:
            raise InputError(f"spur map: need a (frames, range, doppler) stack, got shape {hits.shape}")
        return cls(_dilate(hits).mean(axis=0), threshold, hits.shape[0])

    @cached_property
    def mask(self) -> np.ndarray:
        """Boolean spur image (computed once; read-only)."""
        mask = self.frequency > self.threshold
        mask.setflags(write=False)
        return mask

    def with_threshold(self, threshold: float) -> SpurMap:
        return SpurMap(self.frequency, threshold, self.n_frames)

    def contains(self, range_bin: np.ndarray, doppler_bin: np.ndarray) -> np.ndarray:
        """True for (sub-pixel) positions whose nearest pixel is a spur."""
        n_r, n_d = self.frequency.shape
        r = np.clip(np.rint(np.asarray(range_bin, float)).astype(np.int64), 0, n_r - 1)
        d = np.rint(np.asarray(doppler_bin, float)).astype(np.int64) % n_d
        return self.mask[r, d]

    def save(self, path: str | Path) -> Path:
        """Write to ``.npz`` atomically."""
        from skyradar.io.atomic import write_with

        # savez appends ".npz" to a name without it: give it the open file so the name is kept.
        def save(tmp: Path) -> None:
            with open(tmp, "wb") as f:
                np.savez_compressed(
                    f, frequency=self.frequency, threshold=self.threshold, n_frames=self.n_frames
                )

        return write_with(path, save)

    @classmethod
    def load(cls, path: str | Path, config: RadarConfig | None = None) -> SpurMap:
        """Read a map written by :meth:`save`; with ``config`` check it fits the radar's image."""
        path = Path(path)
        if not path.exists():
            raise InputError(f"{path}: no such spur map")
        try:
            with np.load(path) as data:
                spur_map = cls(data["frequency"], float(data["threshold"]), int(data["n_frames"]))
        except (OSError, KeyError, ValueError) as exc:
            raise InputError(f"{path}: not a spur map ({type(exc).__name__}: {exc})") from exc
        if config is not None and spur_map.frequency.shape != config.frame_shape[:2]:
            raise InputError(
                f"{path}: field 'frequency' has shape {spur_map.frequency.shape}, radar_config needs "
                f"{config.frame_shape[:2]}"
            )
        return spur_map


def learn_spur_map(
    powers: Iterable[np.ndarray],
    config: RadarConfig,
    threshold: float = 0.05,
    pixels: Literal["peaks", "hits"] = "peaks",
    **detect_kwargs: Any,
) -> SpurMap:
    """Learn a spur map from channel-integrated frames of a static scene.

    Parameters
    ----------
    powers : iterable of ndarray (n_range, n_doppler)
        Frames from :func:`skyradar.process.detect.integrate_channels`.
    config : RadarConfig
        Image shape, channel count and noise power for the detector.
    threshold : float
        Hit frequency above which a pixel is a spur.
    pixels : {"peaks", "hits"}
        Learn detector points (thesis) or every CFAR hit pixel (:func:`detection_pixels`).
    **detect_kwargs
        Passed to :func:`skyradar.process.detect.detect`; default Shi-Tomasi corners as in the thesis.

    Returns
    -------
    SpurMap
        Hit frequency of every pixel over the frames (detections dilated by one pixel).

    Examples
    --------
    Over four frames the spur stays put and the target moves 10 range bins a frame: only the
    spur and its 8 neighbours are hit in more than half of them:

    >>> from skyradar.config import RadarConfig
    >>> cfg = RadarConfig.prototype_2022()
    >>> def frame(target_range):  # flat noise, a spur at (50, 0) and a target at (target_range, 100)
    ...     p = np.full((cfg.n_range, cfg.n_doppler), cfg.noise_power_w, np.float32)
    ...     p[50, 0] = p[target_range, 100] = 1000 * cfg.noise_power_w
    ...     return p
    >>> spur_map = learn_spur_map((frame(100 + 10 * i) for i in range(4)), cfg, threshold=0.5)
    >>> spur_map.n_frames, int(spur_map.mask.sum())
    (4, 9)
    >>> spur_map.contains(np.array([50.0, 100.0]), np.array([249.0, 100.0])).tolist()  # spur, target
    [True, False]
    """
    detect_kwargs.setdefault("method", "shi-tomasi")
    counts = None
    n = 0
    for power in powers:
        hits = _dilate(detection_pixels(power, config, pixels, **detect_kwargs))
        counts = hits.astype(np.int32) if counts is None else counts + hits
        n += 1
    if n == 0:
        raise InputError("spur map: no frames to learn from")
    assert counts is not None  # set by the first of the n frames
    return SpurMap(counts / np.float32(n), threshold, n)


class OnlineSpurMap:
    """Running spur map for a moving platform: pixels that stay lit while the scene moves.

    Parameters
    ----------
    shape : (int, int)
        Image shape (n_range, n_doppler).
    time_constant_frames : float
        Memory of the exponentially weighted hit frequency, frames.
    threshold : float
        Frequency above which a pixel is a spur.
    min_frames : int
        Frames to see before anything is called a spur.

    Examples
    --------
    A spur on the Doppler edge in every frame, an object moving two Doppler bins a frame: after
    ``min_frames`` only the spur's dilated 3 x 3 block (wrapping to the last column) stays lit:

    >>> online = OnlineSpurMap((6, 8), time_constant_frames=5, min_frames=3)
    >>> for i in range(4):
    ...     hits = np.zeros((6, 8), bool)
    ...     hits[1, 0] = hits[4, 2 * i] = True
    ...     mask = online.update(hits)
    >>> np.argwhere(mask).tolist()
    [[0, 0], [0, 1], [0, 7], [1, 0], [1, 1], [1, 7], [2, 0], [2, 1], [2, 7]]
    >>> online.snapshot().n_frames
    4
    """

    def __init__(
        self,
        shape: tuple[int, int],
        time_constant_frames: float = 50.0,
        threshold: float = 0.5,
        min_frames: int = 10,
    ) -> None:
        if time_constant_frames < 1:
            raise InputError(
                f"spur map: field 'time_constant_frames' must be >= 1, got {time_constant_frames}"
            )
        self.frequency = np.zeros(shape, np.float32)
        self.alpha = np.float32(1.0 / time_constant_frames)
        self.threshold = float(threshold)
        self.min_frames = int(min_frames)
        self.n_frames = 0

    def update(self, hits: np.ndarray) -> np.ndarray:
        """Add one frame's detection pixels (boolean image); returns the current spur mask."""
        hits = _dilate(np.asarray(hits, bool))
        # Bias-corrected average: equal weights until the time constant is reached.
        alpha = max(self.alpha, np.float32(1.0 / (self.n_frames + 1)))
        self.frequency += alpha * (hits - self.frequency)
        self.n_frames += 1
        return self.mask

    @property
    def mask(self) -> np.ndarray:
        if self.n_frames < self.min_frames:
            return np.zeros(self.frequency.shape, bool)
        return self.frequency > self.threshold

    def snapshot(self) -> SpurMap:
        """The current state as a :class:`SpurMap`."""
        return SpurMap(self.frequency.copy(), self.threshold, self.n_frames)
