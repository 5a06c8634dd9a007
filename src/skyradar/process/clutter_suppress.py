"""Clutter suppression before detection: per cell, project the snapshot off the predicted clutter.

For each range-Doppler cell the four calibrated channels ``z`` are projected orthogonal to the
``m`` strongest eigenvectors ``E`` of the predicted clutter covariance
(:func:`skyradar.process.clutter.clutter_subspace`): ``y = (I - E E^H) z``. How many directions
are nulled follows the measured clutter: where the clutter-to-noise ratio ``c`` of the cell's
neighbourhood (largest of the unsuppressed power image 2-3 Doppler bins either side, or of the
cell itself unless it is a point-like peak 6 dB above that quiet neighbourhood) exceeds ``gate``
(default 3, 4.8 dB: the largest of 12 noise pixels of a 4-channel mean stays under 4 times the
noise in about 99.8 % of windows), the fewest eigenvectors that leave at most a quarter of the
noise of predicted clutter, at most ``max_nulls``. Clean cells keep all channels (no loss in clear sky).

Calibration: ``y`` spans ``L = n_rx - m`` orthonormal dimensions, so the detection image
``|y|^2 / L`` keeps the thermal noise mean per pixel (measured per frame where no ground can be,
:func:`measured_floor`) and a Gamma(L, 1/L) law per pixel;
the CFAR threshold uses each pixel's ``L`` (:func:`skyradar.process.cfar.cfar_2d` accepts an array
``n_integrated``). A target from ``s`` keeps ``|P s|^2 / L`` of its per-channel power: close to 1
away from the nulls. Cells whose predicted clutter left outside the nulls still exceeds the noise
(``c * sum(remaining fractions) > 1``) are returned as ``unsuppressed`` for the CFAR to keep out of
its training cells.

Where the prediction is wrong (relief: the ground is not flat at the height below), the cells whose
neighbours still hold clutter after the predicted nulls take nulls trained on those neighbours
instead (:mod:`skyradar.process.clutter_adaptive`, ``adaptive=True``, the default): same ``L``,
same noise law, ``Suppressed.adaptive`` says which cells.

Examples
--------
>>> from skyradar.config import RadarConfig
>>> from skyradar.process.clutter import clutter_subspace
>>> cfg = RadarConfig.prototype_2022()
>>> sub = clutter_subspace(cfg, np.array([50.0, 0.0, 0.0]), np.eye(3), 1000.0)
>>> rng = np.random.default_rng(0)
>>> shape = (cfg.n_range, cfg.n_doppler, cfg.n_rx)
>>> cube = ((rng.standard_normal(shape) + 1j * rng.standard_normal(shape)) * np.sqrt(cfg.noise_power_w / 2))
>>> out = suppress_clutter(cube.astype(np.complex64), sub, cfg)
>>> round(float(out.power.mean() / cfg.noise_power_w), 2), bool((out.nulls > 0).mean() < 0.01)  # noise only
(1.0, True)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy.special import gammaincinv

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.process.clutter import ClutterSubspace, cell_scratch, decompose_cell
from skyradar.process.clutter_adaptive import adaptive_nulls
from skyradar.process.detect import Detections, detect
from skyradar.process.doa import channel_calibration
from skyradar.process.power import power_image
from skyradar.rx_layouts import MAX_RX

__all__ = [
    "default_max_nulls",
    "Suppressed",
    "suppress_clutter",
    "null_count",
    "measured_floor",
    "projected_power",
    "projected_snapshots",
]


@dataclass(frozen=True)
class Suppressed:
    """One frame after suppression (arrays of shape (n_range, n_doppler)).

    power : float32, W, thermal noise mean ``noise_power_w``; channels : int8, ``L`` per pixel;
    unsuppressed : bool, predicted clutter left above the noise; nulls : int8, ``n_rx - L``;
    clutter_to_noise : float32, measured neighbourhood clutter-to-noise ratio (linear);
    noise_floor_w : the frame's measured thermal noise per pixel (:func:`measured_floor`);
    adaptive : bool, cells whose nulls were trained on their neighbours
    (:mod:`skyradar.process.clutter_adaptive`), ``adaptive_vectors`` their eigenvectors
    (n_range, n_doppler, n_rx, n_rx), valid where ``adaptive``.

    Examples
    --------
    Clutter 40 dB over the noise from 30 deg below boresight, predicted right in every cell:
    one null each, the noise left, and the nulled vector is the clutter's direction:

    >>> from skyradar.config import RadarConfig
    >>> from skyradar.process.clutter import ClutterSubspace
    >>> from skyradar.process.doa import direction_from_angles, steering_vector
    >>> cfg = RadarConfig.prototype_2022()
    >>> u = steering_vector(direction_from_angles(0.0, np.radians(-30.0)), cfg)
    >>> outer, iu = np.outer(u, u.conj()), np.triu_indices(4, 1)
    >>> pairs = np.stack([outer[iu].real, outer[iu].imag], -1).ravel()  # upper triangle (re, im)
    >>> packed = np.concatenate([outer.diagonal().real, pairs])
    >>> sub = ClutterSubspace(np.tile(packed, (40, 32, 1)), 4)
    >>> rng = np.random.default_rng(0)
    >>> def gauss(*s):
    ...     return (rng.standard_normal(s) + 1j * rng.standard_normal(s)) * np.sqrt(cfg.noise_power_w / 2)
    >>> cube = (gauss(40, 32, 4) + 100.0 * gauss(40, 32)[..., None] * u).astype(np.complex64)
    >>> out = suppress_clutter(cube, sub, cfg)
    >>> np.unique(out.nulls).tolist(), round(float(out.power.mean() / out.noise_floor_w), 2)
    ([1], 1.0)
    >>> e = out.cell_vectors(sub, np.array([20]), np.array([16]))[0, :, 0]
    >>> round(float(abs(e.conj() @ u) ** 2 / 4), 6)
    1.0
    """

    power: np.ndarray
    channels: np.ndarray
    unsuppressed: np.ndarray
    nulls: np.ndarray
    clutter_to_noise: np.ndarray
    noise_floor_w: float
    adaptive: np.ndarray | None = None
    adaptive_vectors: np.ndarray | None = None

    def cell_vectors(self, subspace: ClutterSubspace, range_index, doppler_index) -> np.ndarray:
        """Eigenvectors (n, n_rx, n_rx) whose first ``nulls`` columns were nulled in the given cells:
        the adaptive ones where the cell was adaptive, else the prediction's."""
        vectors = subspace.cell_vectors(range_index, doppler_index)
        if self.adaptive is not None:
            assert self.adaptive_vectors is not None  # set together with adaptive
            own = self.adaptive[range_index, doppler_index]
            vectors[own] = self.adaptive_vectors[range_index[own], doppler_index[own]]
        return vectors

    def detections(self, config: RadarConfig, **detect_kwargs) -> Detections:
        """CFAR on the suppressed image as the chain runs it (:func:`skyradar.process.detect.detect`):
        each pixel's channel count from its nulls (``n_rx - nulls``, so a pass that rewrote
        ``nulls`` in place is read as it now is), training outside unsuppressed clutter, against the
        frame's measured floor; ``detect_kwargs`` as ``detect`` takes them (``method``,
        ``exclude``, ...)."""
        channels = (config.n_virtual - self.nulls).astype(np.int8)
        return detect(
            self.power,
            config,
            channels=channels,
            train_exclude=self.unsuppressed,
            noise_floor_w=self.noise_floor_w,
            **detect_kwargs,
        )

    def applied_vectors(self, subspace: ClutterSubspace) -> np.ndarray:
        """:meth:`cell_vectors` of every cell (n_range, n_doppler, n_rx, n_rx)."""
        if self.adaptive is None or not self.adaptive.any():
            return subspace.vectors
        assert self.adaptive_vectors is not None  # set together with adaptive
        return np.where(self.adaptive[..., None, None], self.adaptive_vectors, subspace.vectors)


# Median of Gamma(L, 1/L) (the channel mean of L unit-noise channels), L = 1..MAX_RX.
# Median of the mean of n unit-mean exponentials (Gamma(n, 1/n)); scipy.special, not scipy.stats, keeps
# `import skyradar.process` light for every command that only reads a table.
_GAMMA_MEDIAN = np.array([np.nan, *(gammaincinv(n, 0.5) / n for n in range(1, MAX_RX + 1))])


def measured_floor(
    raw: np.ndarray, predicted: np.ndarray, nominal_w: float, n_rx: int = 4, free: np.ndarray | None = None
) -> float:
    """Thermal noise per pixel of one frame, W, measured where no ground can be.

    The median of the channel-mean image over the cells no ground direction reaches (nearer than
    the height, Doppler outside the ground band), divided by the median of Gamma(L, 1/L): robust to
    a few targets. The window point-spread of a real (or ``psf``-simulated) chain raises the noise
    per pixel above ``nominal_w`` (``RadarConfig.noise_power_w``, +3.5 dB for Hann x Hann), so the
    floor is measured, not assumed; with fewer than 2000 such cells ``nominal_w`` is used.
    ``free`` (flat indices of ``~predicted``, :attr:`ClutterSubspace.free_cells`) saves the mask.

    Parameters
    ----------
    raw : ndarray (n_range, n_doppler), float32
        Channel-mean power image before suppression, W.
    predicted : ndarray of bool (n_range, n_doppler)
        Cells some ground direction reaches (:attr:`ClutterSubspace.predicted`).
    nominal_w : float
        Noise per pixel used when fewer than 2000 cells are free of ground, W.
    n_rx : int
        Channels averaged into each pixel (sets the Gamma median).
    free : ndarray of int, optional
        Flat indices of the free cells, instead of ``~predicted``.

    Returns
    -------
    float
        Noise per pixel, W.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> raw = rng.gamma(4.0, 0.25 * 3e-13, (40, 100)).astype(np.float32)  # 4-channel means, 3e-13 W
    >>> round(measured_floor(raw, np.zeros(raw.shape, bool), 1e-13) / 3e-13, 2)
    1.0
    >>> measured_floor(raw[:10], np.zeros((10, 100), bool), 1e-13)  # 1000 free cells: the nominal
    1e-13
    """
    values = raw.ravel()[free] if free is not None else raw[~predicted]  # a copy: partitioned in place
    if values.size < 2000:
        return float(nominal_w)
    k = values.size // 2
    values.partition(k)  # np.median's result without its wrapper (a tenth of a frame's suppression)
    median = values[k] if values.size % 2 else (values[:k].max() + values[k]) / np.float32(2.0)
    return float(median / _GAMMA_MEDIAN[min(max(n_rx, 1), MAX_RX)])


def null_count(
    fractions: np.ndarray, cnr: np.ndarray, max_nulls: int = 2, gate: float = 3.0, residual: float = 0.25
) -> tuple[np.ndarray, np.ndarray]:
    """Nulls per cell and whether predicted clutter above the noise remains after them.

    A cell with clutter (``cnr > gate``) gets the fewest nulls that leave at most ``residual``
    times the noise of predicted clutter (``cnr * (1 - sum of nulled fractions)``), at most
    ``max_nulls``; it is ``unsuppressed`` when more than the noise is left.

    >>> n, left = null_count(np.array([[[0.9, 0.1, 0.0, 0.0]]]), np.array([[100.0]]))
    >>> n.tolist(), left.tolist()
    ([[2]], [[False]])
    """
    if not 0 <= max_nulls < fractions.shape[-1]:
        top = fractions.shape[-1] - 1
        raise InputError(f"suppression: field 'max_nulls' must be in [0, {top}], got {max_nulls}")
    left = cnr[..., None] * np.clip(1.0 - np.cumsum(fractions, axis=-1), 0.0, 1.0)  # after 1, 2, ... nulls
    needed = 1 + np.sum(left[..., :max_nulls] > residual, axis=-1)
    clutter = (cnr > gate) & (fractions[..., 0] > 0)
    n = np.where(clutter, np.minimum(needed, max_nulls), 0).astype(np.int8)
    kept = np.take_along_axis(left, np.maximum(n.astype(np.int64) - 1, 0)[..., None], axis=-1)[..., 0]
    return n, np.where(n > 0, kept, cnr) > 1.0


@njit(cache=True)
def _project_power(z, vectors, nulls, out):  # pragma: no cover - compiled
    n_r, n_d, n_k = z.shape
    for r in range(n_r):
        for d in range(n_d):
            # |P z|^2 = |z|^2 - sum_i |e_i^H z|^2 (orthonormal e_i): the projected, not the plain, power.
            total = 0.0
            for k in range(n_k):
                total += abs(z[r, d, k]) ** 2
            m = nulls[r, d]
            for i in range(m):
                c = 0j
                for k in range(n_k):
                    c += np.conj(vectors[r, d, k, i]) * z[r, d, k]
                total -= abs(c) ** 2
            out[r, d] = max(total, 0.0) / (n_k - m)
    return out


def default_max_nulls(n_rx: int, n_tx: int = 1) -> int:
    """Most clutter directions one cell nulls by default on an array of ``n_rx`` channels.

    Over flat ground a range-Doppler cell holds clutter from two directions, left and right of
    the ground track at one depression angle: two nulls, on any array of three channels or more
    (one on two channels, none on one). A time-division MIMO frame of ``n_tx`` transmitters folds
    ``n_tx`` aliases of each Doppler into one cell (:mod:`skyradar.process.clutter`), each alias a
    left and right pair of its own: ``2 n_tx`` directions, nulled up to ``n_rx - 2`` so that two
    dimensions stay to measure a target's direction. With two transmitters the ground that shares
    an intruder's aliased Doppler at its azimuth lies one alias away from the pair the antenna's
    sidelobes see far off the nose; two nulls leave that pair 20-30 dB over the noise in the
    cells of an intruder whose own speed along the line of sight is near ``2 v_lim``
    (``tests/test_clutter_suppression.py``).

    A larger array could take more: after ``m`` nulls a target's snapshot spans ``n_rx - m``
    dimensions, and two are enough for its direction to be estimable. Over relief more directions
    hold clutter, and ``suppress_clutter(..., max_nulls=n_rx - 2)`` nulls them: on the frames over
    hills of ``skyradar bench process`` an eight-channel array then detects as few cells as the
    square with two nulls, instead of 2.5 times as many. It is not the default because the target
    pays for it. Each null takes with it the part of the target's steering vector along it, and with
    two dimensions left its direction is estimable but poorly: on the development fast-closure sets
    over the hills (the results page, ``...-ura-2x3-ceiling`` against ``...-ura-2x3-two-nulls``,
    ``...-ura-4x2-ceiling`` against ``...-ura-4x2``), the eight-channel upright array's track of a
    climbing intruder had its horizontal miss at 1.1-2.8 km for 8 s (386 m true) and was warned 8.3
    s later (about when perfect surveillance warns), the six-channel array warned one more
    must-not-alert encounter, and the tracks on the ground stayed about as many, for twice the
    processing time a frame.

    Parameters
    ----------
    n_rx : int
        Receive (or virtual) channels of the array.
    n_tx : int
        Transmitters taking turns (time-division MIMO; 1 otherwise).

    Returns
    -------
    int
        The default ceiling on nulls per cell.

    Examples
    --------
    >>> [default_max_nulls(n) for n in (1, 2, 3, 4, 6, 8)]
    [0, 1, 2, 2, 2, 2]
    >>> default_max_nulls(8, n_tx=2)  # the 2 TX x 4 RX MIMO array's eight virtual channels
    4
    """
    keep = 2 if n_rx >= 4 else 1  # two channels stay to measure a direction; one on smaller arrays
    return max(min(2 * max(int(n_tx), 1), int(n_rx) - keep), 0)


def suppress_clutter(
    cube: np.ndarray,
    subspace: ClutterSubspace,
    config: RadarConfig,
    max_nulls: int | None = None,
    gate: float = 3.0,
    adaptive: bool = True,
) -> Suppressed:
    """Project every cell of a (n_range, n_doppler, n_channels) frame off its predicted clutter directions.

    Parameters
    ----------
    cube : ndarray, complex
        One frame, uncalibrated channels (:func:`~skyradar.process.doa.channel_calibration` is
        divided out here): the receivers, or a time-division MIMO radar's virtual channels with
        their transmit-slot phase still in, which the prediction models (:mod:`skyradar.process.clutter`).
    subspace : ClutterSubspace
        The frame geometry's predicted clutter.
    config : RadarConfig
        Channel count, calibration and nominal noise power ``noise_power_w`` (W).
    max_nulls : int, optional
        Most directions nulled in one cell; default :func:`default_max_nulls` of the array's
        channel count, at most ``n_channels - 1`` (none on a one-channel radar).
    gate : float
        A direction is nulled when the measured clutter-to-noise ratio times its eigenvalue
        fraction exceeds this.
    adaptive : bool
        Where the predicted nulls leave clutter over a cell's neighbours, null the directions
        trained on them instead (:func:`skyradar.process.clutter_adaptive.adaptive_nulls`).

    Returns
    -------
    Suppressed
        The projected power image (W), channel counts, nulls and flags of the frame.

    Examples
    --------
    Clutter 40 dB over the noise from 30 deg below boresight, predicted in every cell: one null
    per cell takes it out and leaves the noise:

    >>> from skyradar.config import RadarConfig
    >>> from skyradar.process.clutter import ClutterSubspace
    >>> from skyradar.process.doa import direction_from_angles, steering_vector
    >>> cfg = RadarConfig.prototype_2022()
    >>> u = steering_vector(direction_from_angles(0.0, np.radians(-30.0)), cfg)
    >>> outer, iu = np.outer(u, u.conj()), np.triu_indices(4, 1)
    >>> pairs = np.stack([outer[iu].real, outer[iu].imag], -1).ravel()  # upper triangle (re, im)
    >>> packed = np.concatenate([outer.diagonal().real, pairs])
    >>> sub = ClutterSubspace(np.tile(packed, (40, 32, 1)), 4)
    >>> rng = np.random.default_rng(0)
    >>> def gauss(*s):
    ...     return (rng.standard_normal(s) + 1j * rng.standard_normal(s)) * np.sqrt(cfg.noise_power_w / 2)
    >>> cube = (gauss(40, 32, 4) + 100.0 * gauss(40, 32)[..., None] * u).astype(np.complex64)
    >>> out = suppress_clutter(cube, sub, cfg)
    >>> raw = float(np.mean(np.abs(cube) ** 2) / cfg.noise_power_w)
    >>> left = float(out.power.mean() / cfg.noise_power_w)
    >>> round(10 * np.log10(raw)), np.unique(out.nulls).tolist(), round(left, 2)
    (40, [1], 1.0)
    """
    cube = np.asarray(cube)
    if cube.shape != subspace.predicted.shape + (config.n_virtual,):
        raise InputError(f"suppression: frame shape {cube.shape} does not fit the clutter prediction")
    if max_nulls is None:
        max_nulls = default_max_nulls(config.n_virtual, config.n_tx)
    if not 0 <= max_nulls < config.n_virtual:
        raise InputError(
            f"suppression: field 'max_nulls' must be in [0, {config.n_virtual - 1}], got {max_nulls}"
        )
    calibration = channel_calibration(config)
    raw = power_image(cube, calibration)
    floor = measured_floor(
        raw, subspace.predicted, config.noise_power_w, config.n_virtual, subspace.free_cells
    )
    power, nulls = np.empty(raw.shape, np.float32), np.empty(raw.shape, np.int8)
    unsuppressed, cnr = np.empty(raw.shape, np.bool_), np.empty(raw.shape, np.float32)
    inv_gain = (1.0 / calibration).astype(np.complex64)
    z = np.ascontiguousarray(cube, np.complex64)
    rule = (np.float32(1.0 / floor), np.int64(max_nulls), np.float32(gate), np.float32(_RESIDUAL))
    cells = (subspace.covariance, subspace.predicted, subspace.done, subspace._vectors, subspace._fractions)
    rows = (*subspace.calibrated_rows(inv_gain), inv_gain)
    _fused(z, raw, *cells, *rows, *rule, power, nulls, unsuppressed, cnr)
    trained: tuple[np.ndarray, np.ndarray] | tuple[None, None] = (None, None)
    if adaptive:
        trained = adaptive_nulls(z, inv_gain, cnr, floor, power, nulls, unsuppressed, max_nulls, gate)
    channels = (config.n_virtual - nulls).astype(np.int8)
    return Suppressed(power, channels, unsuppressed, nulls, cnr, floor, *trained)


_RESIDUAL = 0.25  # predicted clutter left after the nulls, in units of the noise (null_count's default)


@njit(cache=True)
def _ring_max(raw, top):  # pragma: no cover - compiled
    # Largest pixel over 3 range rows (range edges: the rows there are) at Doppler offsets -3, -2,
    # +2, +3 (wrapping), separably: column maxima into a Doppler-wrapped scratch row first. The
    # maximum, not the mean: simulated and real ground fills the image as a comb of bright pixels
    # (facets, speckle). The cell itself and its first Doppler neighbours are left out: a point
    # target's Hann main lobe ends two bins away, ground spreads along Doppler, so a target in
    # clear sky does not make its own cell look cluttered.
    n_r, n_d = raw.shape
    col = np.empty(n_d + 6, np.float32)
    for r in range(n_r):
        lo, hi = max(r - 1, 0), min(r + 1, n_r - 1)
        for d in range(n_d):
            m = raw[lo, d]
            for rr in range(lo + 1, hi + 1):
                v = raw[rr, d]
                m = v if v > m else m
            col[d + 3] = m
        for d in range(3):
            col[d] = col[n_d + d]
            col[n_d + 3 + d] = col[3 + d]
        for d in range(n_d):
            a = col[d] if col[d] > col[d + 1] else col[d + 1]
            b = col[d + 5] if col[d + 5] > col[d + 6] else col[d + 6]
            top[r, d] = a if a > b else b
    return top


@njit(cache=True)
def _fused(
    # inputs; lazily filled
    cube,
    raw,
    acc,
    predicted,
    done,
    vectors,
    fractions,
    rows,
    rows_done,
    inv_gain,
    # the rule
    inv_floor,
    max_nulls,
    gate,
    residual,
    # outputs
    power,
    nulls,
    unsuppressed,
    cnr,
):  # pragma: no cover - compiled
    # The clutter level (ring and peak rule) and null_count in one pass over the cells, then
    # projected_power where nulls were placed (same rules as those functions; tests compare them).
    # Two branch-light loops run faster than one that mixes them. A gated cell's eigen-pairs are
    # computed here the first time any frame needs them (most predicted cells never are).
    n_r, n_d, n_k = cube.shape
    one, zero, four = np.float32(1.0), np.float32(0.0), np.float32(4.0)
    scratch = cell_scratch(n_k)
    top = _ring_max(raw, np.empty((n_r, n_d), np.float32))
    for r in range(n_r):
        for d in range(n_d):
            ring = max(top[r, d] * inv_floor - one, zero)
            own = raw[r, d] * inv_floor - one
            # A cell brighter than gate counts as clutter too, unless it stands 6 dB above everything
            # 2-3 Doppler bins away while they are quiet: that is a point target, not ground.
            c = ring if (ring <= gate and own + one > four * (ring + one)) else max(ring, own)
            cnr[r, d] = c
            m = 0
            left = c
            if c > gate and predicted[r, d]:
                if not done[r, d]:
                    decompose_cell(acc, done, vectors, fractions, r, d, scratch)
                cum = zero
                for i in range(max_nulls):
                    cum += fractions[r, d, i]
                    left = c * max(one - cum, zero)
                    m = i + 1
                    if left <= residual:
                        break
            nulls[r, d] = m
            unsuppressed[r, d] = left > one
    _project_rows(cube, raw, vectors, rows, rows_done, inv_gain, nulls, power)


@njit(cache=True)
def _project_rows(cube, raw, vectors, rows, rows_done, inv_gain, nulls, power):  # pragma: no cover - compiled
    # |P z|^2 / L = (|z|^2 - sum_i |e_i^H z|^2) / L, z = cube / gain: rows hold e_i^H diag(1 / gain),
    # contiguous per null, made the first time a cell is projected under this calibration.
    n_r, n_d, n_k = cube.shape
    for r in range(n_r):
        for d in range(n_d):
            m = nulls[r, d]
            if m == 0:
                power[r, d] = raw[r, d]
                continue
            if not rows_done[r, d]:
                for i in range(n_k - 1):
                    for k in range(n_k):
                        rows[r, d, i, k] = np.conj(vectors[r, d, k, i]) * inv_gain[k]
                rows_done[r, d] = True
            total = raw[r, d] * n_k  # |z|^2 of the calibrated snapshot (raw is its channel mean)
            for i in range(m):
                acc = np.complex64(0)
                for k in range(n_k):
                    acc += rows[r, d, i, k] * cube[r, d, k]
                total -= acc.real * acc.real + acc.imag * acc.imag
            power[r, d] = max(total, np.float32(0.0)) / (n_k - m)


def projected_power(calibrated: np.ndarray, vectors: np.ndarray, nulls: np.ndarray) -> np.ndarray:
    """``|(I - E E^H) z|^2 / L`` per cell of a calibrated cube, ``E`` the first ``nulls`` eigenvectors.

    Parameters
    ----------
    calibrated : ndarray (n_range, n_doppler, n_rx), complex
        Calibrated cube (amplitude, sqrt(W)).
    vectors : ndarray (n_range, n_doppler, n_rx, n_rx), complex64
        Orthonormal eigenvectors per cell, columns by decreasing eigenvalue.
    nulls : ndarray of int (n_range, n_doppler)
        Columns nulled per cell; ``L = n_rx - nulls``.

    Returns
    -------
    ndarray (n_range, n_doppler), float32
        Projected power per remaining channel, W.

    Examples
    --------
    Nulling the first unit vector of ``z = (1, 2, 3, 4)`` leaves ``(4 + 9 + 16) / 3``; no null
    leaves the mean ``30 / 4``:

    >>> z = np.array([[[1.0, 2.0, 3.0, 4.0]]], complex)
    >>> e = np.eye(4, dtype=np.complex64)[None, None]
    >>> projected_power(z, e, np.array([[1]])).round(4).tolist()
    [[9.6667]]
    >>> projected_power(z, e, np.array([[0]])).tolist()
    [[7.5]]
    """
    z = np.ascontiguousarray(calibrated, dtype=np.complex64)
    return _project_power(z, vectors, np.asarray(nulls, np.int8), np.empty(z.shape[:2], np.float32))


def projected_snapshots(
    pixels: np.ndarray, vectors: np.ndarray, nulls: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Projectors ``P = I - E E^H`` (n, n_rx, n_rx) of some cells and their projected snapshots (n, n_rx).

    Parameters
    ----------
    pixels : ndarray (n, n_rx), complex
        Calibrated snapshots (amplitude, sqrt(W)).
    vectors : ndarray (n, n_rx, n_rx), complex
        Orthonormal eigenvectors of each cell, columns by decreasing eigenvalue.
    nulls : ndarray of int (n,)
        Columns nulled per cell.

    Returns
    -------
    proj : ndarray (n, n_rx, n_rx), complex
        ``I - E E^H`` with ``E`` the first ``nulls`` columns.
    projected : ndarray (n, n_rx), complex
        ``proj @ pixels``.

    Examples
    --------
    >>> z = np.array([[1.0, 2.0, 3.0, 4.0]], complex)
    >>> proj, y = projected_snapshots(z, np.eye(4)[None], np.array([1]))
    >>> proj[0].diagonal().real.tolist(), y.real.tolist()
    ([0.0, 1.0, 1.0, 1.0], [[0.0, 2.0, 3.0, 4.0]])
    """
    n, n_k = pixels.shape
    keep = np.arange(n_k)[None, :] < np.asarray(nulls)[:, None]
    e = vectors * keep[:, None, :]
    proj = np.eye(n_k)[None] - np.einsum("nki,nli->nkl", e, np.conj(e))
    return proj, np.einsum("nkl,nl->nk", proj, pixels)
