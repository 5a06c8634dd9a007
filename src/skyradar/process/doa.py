"""Direction of arrival from phase differences between receive antennas, and its Cramer-Rao bound.

Phase model (far field, antenna frame): the pixel of receiver k for a scatterer in unit direction
``u`` is ``A exp(i (phi - (2 pi / lambda) u . r_k))`` with a common phase ``phi`` (two-way path,
transmitter term shared). Linearly, ``psi_k = -(2 pi / lambda) u . r_k + phi`` for the measured
phases ``psi_k``, which is least squares in ``u`` with a free intercept ``phi``. The intercept is
what makes the estimator use all pairs optimally: with independent phase noise of equal variance
it is the best linear unbiased estimator, and it reaches the Cramer-Rao bound at high SNR.

Layouts:

* non-coplanar arrays (rank 3): all three components by least squares, normalised, then
  refined by Gauss-Newton in (azimuth, elevation) so that ``|u| = 1`` is part of the fit;
* coplanar arrays (rank 2): the two in-plane components by least squares and the third from
  ``|u| = 1`` (the position is ``range * u``), on the side of the array that faces the scene
  (the side the boresight +x points to);
* collinear arrays or fewer than three distinct antennas cannot give a direction: InputError.

Ambiguity: a pair of antennas further apart than half a wavelength wraps its phase difference.
A coarse direction comes first from the pairs at most lambda/2 apart (unambiguous) when they span
a coplanar array, otherwise from a beamforming grid search over the field of view (non-coplanar
and sparse arrays; grating lobes outside the field of view are ignored); every phase is then unwrapped
to the value the coarse direction predicts and the least-squares fit is redone on all antennas.
A square of side d > lambda/2 is unique only within ``asin(lambda / (2 d))`` of boresight on
either axis (56.4 deg at 0.6 lambda); beyond that a direction is reported at its grating lobe.

Time-division MIMO (``config.n_tx > 1``): the channels are the virtual channels
``t * n_rx + r`` at ``tx_t + rx_r`` (:attr:`skyradar.config.RadarConfig.virtual_positions_m`), whose
far-field phase is the receive phase above for an antenna at ``tx_t + rx_r``; every function here
then takes pixels of ``n_virtual`` channels, after the transmitter slots' Doppler phase is removed
(:mod:`skyradar.process.mimo`). Calibration is per receiver, the same for every transmitter. A
one-transmitter radar uses ``rx_positions_m``: its ``tx + rx`` differ from them by a common shift,
which changes only the common phase.

Cramer-Rao bound: for ``x_k = A exp(i theta_k) + n_k``, ``n_k ~ CN(0, sigma^2)`` and the unknowns
(A, phi, az, el), the Fisher information of (az, el) after eliminating the nuisance phase is
``J = 2 SNR sum_k (g_k - mean(g)) (g_k - mean(g))^T`` with ``g_k = -(2 pi / lambda) (du/daz . r_k,
du/del . r_k)`` and ``SNR = A^2 / sigma^2`` per channel and pixel; ``CRLB = J^-1``.

Examples
--------
>>> from skyradar.config import RadarConfig
>>> cfg = RadarConfig.prototype_2022()
>>> u = direction_from_angles(np.radians(10.0), np.radians(-5.0))
>>> pixels = steering_vector(u, cfg)[None, :]
>>> az, el = angles_from_direction(estimate_directions(pixels, cfg))
>>> np.round(np.degrees([az[0], el[0]]), 6).tolist()
[10.0, -5.0]
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.units import wrap_angle

__all__ = [
    "ArrayGeometry",
    "array_geometry",
    "direction_from_angles",
    "angles_from_direction",
    "steering_vector",
    "estimate_directions",
    "direction_coherence",
    "doa_crlb",
    "direction_covariance",
    "field_of_view_rad",
    "FIELD_OF_VIEW_LOSS_DB",
    "antenna_to_body",
    "channel_positions_m",
    "channel_calibration",
]


@dataclass(frozen=True)
class ArrayGeometry:
    """Precomputed least-squares operators of one receive array.

    Attributes
    ----------
    basis : ndarray, shape (3, dims)
        Solved direction components ``a = basis.T @ u`` (the array plane for coplanar arrays).
    normal : ndarray, shape (3,) or None
        Unit normal on the facing side (coplanar arrays only).
    design : ndarray, shape (n_rx, dims)
        ``-(2 pi / lambda) (r_k - centroid) @ basis``: phase per unit of ``a``.
    solve : ndarray, shape (dims, n_rx)
        Pseudo-inverse of ``design``; its rows sum to zero, so a common phase drops out.
    pairs : ndarray, shape (n_pairs, 2) or None
        Antenna pairs at most lambda/2 apart, when they span ``dims`` (unambiguous coarse fit).
    pair_solve : ndarray, shape (dims, n_pairs) or None
    grid : ndarray, shape (n_grid, dims) or None
        Coarse search grid in ``a`` over the field of view (within 6 dB of peak gain) when no
        unambiguous pair set exists.
    grid_match : ndarray, shape (n_rx, n_grid), complex, or None
        Conjugate steering vectors of the grid points (precomputed: the complex exponentials
        cost more than the beamforming product itself).

    Examples
    --------
    >>> from skyradar.config import RadarConfig
    >>> geo = array_geometry(RadarConfig.prototype_2022())  # the 2x2 square in the y-z plane
    >>> geo.dims, geo.normal.round(6).tolist(), geo.pairs.tolist()
    (2, [1.0, 0.0, 0.0], [[0, 1], [0, 2], [1, 3], [2, 3]])
    >>> bool(np.allclose(geo.solve.sum(axis=1), 0.0))  # a common phase drops out
    True
    """

    basis: np.ndarray
    normal: np.ndarray | None
    design: np.ndarray
    solve: np.ndarray
    pairs: np.ndarray | None
    pair_solve: np.ndarray | None
    grid: np.ndarray | None
    grid_match: np.ndarray | None = None

    @property
    def dims(self) -> int:
        return int(self.basis.shape[1])


def _search_grid(
    q: np.ndarray,
    basis: np.ndarray,
    normal: np.ndarray | None,
    wavelength_m: float,
    facing: np.ndarray,
    half: float,
) -> np.ndarray:
    """Coarse grid of ``a`` over the field of view (a cone around ``facing``).

    The step keeps the coarse phase error on the longest baseline below pi/4. Grating lobes of
    arrays sparser than lambda/2 are only resolved inside the cone: outside it they are real
    ambiguities of the layout.
    """
    step = min(0.05, wavelength_m / (16.0 * float(np.linalg.norm(q, axis=1).max())))
    if normal is not None:
        axis = np.arange(-1.0, 1.0 + step, step)
        a = np.stack(np.meshgrid(axis, axis, indexing="ij"), axis=-1).reshape(-1, 2)
        a = a[np.sum(a * a, axis=1) <= 1.0]
        u = a @ basis.T + np.sqrt(1.0 - np.sum(a * a, axis=1))[:, None] * normal
    else:
        n = int(4.0 * np.pi / step**2)
        i = np.arange(n) + 0.5
        z = 1.0 - 2.0 * i / n  # Fibonacci sphere
        phi = np.pi * (1.0 + 5**0.5) * i
        u = np.stack([np.sqrt(1 - z * z) * np.cos(phi), np.sqrt(1 - z * z) * np.sin(phi), z], axis=1)
        a = u
    return a[u @ facing >= np.cos(half)]


@lru_cache(maxsize=32)
def _geometry(
    rx_bytes: bytes, n_rx: int, wavelength_m: float, facing: tuple[float, float, float], half_angle_rad: float
) -> ArrayGeometry:
    rx = np.frombuffer(rx_bytes).reshape(n_rx, 3)
    k = 2.0 * np.pi / wavelength_m
    scale = max(float(np.ptp(rx, axis=0).max()), 1e-12)
    distinct = np.unique(np.round(rx / (1e-6 * scale)), axis=0).shape[0]
    if distinct < 3:
        raise InputError(f"radar.rx_positions_m: {distinct} distinct antennas; a direction needs at least 3")
    q = rx - rx.mean(axis=0)
    _, sv, vt = np.linalg.svd(q)
    rank = int(np.sum(sv > 1e-6 * sv[0]))
    if rank < 2:
        raise InputError(
            "radar.rx_positions_m: all antennas are on one line; azimuth and elevation are not separable"
        )
    normal = None
    if rank == 2:
        basis = vt[:2].T
        normal = np.cross(basis[:, 0], basis[:, 1])
        face = float(normal @ np.asarray(facing))
        if abs(face) < 0.1:
            raise InputError(
                "radar.rx_positions_m: the array plane contains the boresight; cannot tell the facing side"
            )
        normal = normal * np.sign(face)
    else:
        basis = np.eye(3)
    design = -k * q @ basis
    solve = np.linalg.pinv(design)
    ii, jj = np.triu_indices(n_rx, 1)
    short = np.linalg.norm(rx[jj] - rx[ii], axis=1) <= wavelength_m / 2.0 * (1.0 + 1e-9)
    pairs = pair_solve = grid = None
    pair_design = -k * (rx[jj[short]] - rx[ii[short]]) @ basis
    # Non-coplanar arrays always search the grid: a lambda/2 pair along the boresight wraps at
    # +-pi exactly where targets are, and only the field of view tells front from back.
    if rank == 2 and short.any() and np.linalg.matrix_rank(pair_design) == 2:
        pairs = np.stack([ii[short], jj[short]], axis=1)
        pair_solve = np.linalg.pinv(pair_design)
    else:
        grid = _search_grid(q, basis, normal, wavelength_m, np.asarray(facing), half_angle_rad)
    match = None if grid is None else np.ascontiguousarray(np.exp(-1j * grid @ design.T).T)
    return ArrayGeometry(basis, normal, design, solve, pairs, pair_solve, grid, match)


def channel_positions_m(config: RadarConfig) -> np.ndarray:
    """Positions (n_channels, 3), m, of the channels DoA works on: receivers, or virtual channels for MIMO.

    Examples
    --------
    >>> channel_positions_m(RadarConfig.prototype_2022()).shape
    (4, 3)
    """
    return config.rx_positions_m if config.n_tx == 1 else config.virtual_positions_m


def channel_calibration(config: RadarConfig) -> np.ndarray:
    """Complex gain per channel: ``rx_calibration``, repeated for every transmitter slot for MIMO
    (calibration is per receiver, the same through every transmitter).

    Examples
    --------
    >>> channel_calibration(RadarConfig.prototype_2022(rx_positions_m="mimo-2x4")).shape
    (8,)
    """
    return config.rx_calibration if config.n_tx == 1 else np.tile(config.rx_calibration, config.n_tx)


def array_geometry(
    config: RadarConfig, facing: tuple[float, float, float] = (1.0, 0.0, 0.0)
) -> ArrayGeometry:
    """Least-squares operators of ``config``'s receive (or MIMO virtual) array (cached); InputError for
    unusable layouts.

    Parameters
    ----------
    config : RadarConfig
        Antenna positions (m) and wavelength (m); the field of view bounds the coarse search grid.
    facing : (float, float, float)
        Side a coplanar array looks at (antenna frame, any length); the default is the boresight.

    Returns
    -------
    ArrayGeometry
        The same object for the same layout, wavelength and facing side.

    Examples
    --------
    >>> from skyradar.config import RadarConfig
    >>> cfg = RadarConfig.prototype_2022()
    >>> geo = array_geometry(cfg)
    >>> geo.design.shape, geo.grid is None  # 4 receivers, 2 in-plane unknowns, unambiguous pairs
    ((4, 2), True)
    >>> array_geometry(cfg) is geo
    True
    """
    rx = np.ascontiguousarray(channel_positions_m(config), dtype=float)
    fx, fy, fz = (float(f) for f in np.asarray(facing, float) / np.linalg.norm(facing))
    return _geometry(
        rx.tobytes(), rx.shape[0], float(config.wavelength_m), (fx, fy, fz), _fov_half_angle(config)
    )


_FOV_CACHE: dict[int, tuple[object, float]] = {}
FIELD_OF_VIEW_LOSS_DB = 6.0  # one-way loss from the pattern's peak at the field of view's edge, dB


def field_of_view_rad(config: RadarConfig) -> float:
    """Half-angle of the field of view, rad: the widest off-boresight angle at which either principal
    cut of ``config.antenna`` is within :data:`FIELD_OF_VIEW_LOSS_DB` of its peak (the cone the coarse
    DoA search covers).

    Parameters
    ----------
    config : RadarConfig
        Its ``antenna`` pattern sets the angle (searched on a 0.5 deg grid).

    Returns
    -------
    float
        Half-angle, rad, in [0, pi / 2].

    Examples
    --------
    >>> from skyradar.config import RadarConfig
    >>> round(float(np.degrees(field_of_view_rad(RadarConfig.prototype_2022()))), 3)
    49.5
    """
    return _fov_half_angle(config)


def _fov_half_angle(config: RadarConfig, max_loss_db: float = FIELD_OF_VIEW_LOSS_DB) -> float:
    """Widest off-boresight angle (rad) at which either principal cut is within ``max_loss_db`` of peak."""
    ant = config.antenna
    cached = _FOV_CACHE.get(id(ant))
    if cached is not None and cached[0] is ant:  # the pattern is immutable; keyed by identity
        return cached[1]
    half = _fov_of_pattern(ant, max_loss_db)
    if len(_FOV_CACHE) > 64:
        _FOV_CACHE.clear()
    _FOV_CACHE[id(ant)] = (ant, half)
    return half


def _fov_of_pattern(ant, max_loss_db: float) -> float:
    angle = np.radians(np.arange(0.0, 90.5, 0.5))
    half = 0.0
    for cut in (
        ant.gain_db(angle, 0.0),
        ant.gain_db(-angle, 0.0),
        ant.gain_db(0.0, angle),
        ant.gain_db(0.0, -angle),
    ):
        inside = ant.peak_db - cut <= max_loss_db
        half = max(half, float(angle[np.argmin(inside)] if not inside.all() else angle[-1]))
    return round(half, 6)


def direction_from_angles(azimuth_rad: np.ndarray | float, elevation_rad: np.ndarray | float) -> np.ndarray:
    """Unit vectors (..., 3) in the antenna frame (x boresight, y right, z down).

    Parameters
    ----------
    azimuth_rad : array_like
        Azimuth, rad, positive to the right.
    elevation_rad : array_like
        Elevation, rad, positive up; broadcast against ``azimuth_rad``.

    Returns
    -------
    ndarray, shape (..., 3)
        ``(cos el cos az, cos el sin az, -sin el)``.

    Examples
    --------
    >>> direction_from_angles(0.0, np.radians(30.0)).round(6).tolist()  # 30 deg up: z is negative
    [0.866025, 0.0, -0.5]
    """
    az, el = np.broadcast_arrays(np.asarray(azimuth_rad, float), np.asarray(elevation_rad, float))
    return np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)], axis=-1)


def angles_from_direction(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Azimuth (positive right) and elevation (positive up) of vectors (..., 3), radians.

    Parameters
    ----------
    u : ndarray, shape (..., 3)
        Vectors in the antenna frame (x boresight, y right, z down), any length (e.g. positions in m).

    Returns
    -------
    (azimuth_rad, elevation_rad) : tuple of ndarray
        Each of shape (...), rad; the inverse of :func:`direction_from_angles`.

    Examples
    --------
    >>> az, el = angles_from_direction(np.array([1.0, 1.0, -np.sqrt(2.0)]))
    >>> np.round(np.degrees([az, el]), 6).tolist()  # 45 deg right, 45 deg up
    [45.0, 45.0]
    """
    u = np.asarray(u, float)
    norm = np.maximum(np.linalg.norm(u, axis=-1), 1e-300)
    return np.arctan2(u[..., 1], u[..., 0]), np.arcsin(np.clip(-u[..., 2] / norm, -1.0, 1.0))


def steering_vector(u: np.ndarray, config: RadarConfig) -> np.ndarray:
    """Far-field receive phases ``exp(-i (2 pi / lambda) u . r_k)``, shape (..., n_rx) (MIMO: n_virtual).

    Parameters
    ----------
    u : ndarray, shape (..., 3)
        Unit directions in the antenna frame.
    config : RadarConfig
        Wavelength (m) and channel positions ``r_k`` (m): the receivers, or the virtual channels for MIMO.

    Returns
    -------
    ndarray, shape (..., n_rx), complex
        Unit-modulus phasors, one per channel.

    Examples
    --------
    With half-wavelength spacing along y, receivers 0 and 1 differ by ``-pi sin(az)`` in phase:

    >>> from skyradar.config import RadarConfig
    >>> s = steering_vector(direction_from_angles(np.radians(20.0), 0.0), RadarConfig.prototype_2022())
    >>> s.shape, round(float(np.angle(s[1] * np.conj(s[0]))), 4)
    ((4,), -1.0745)
    >>> round(-np.pi * float(np.sin(np.radians(20.0))), 4)
    -1.0745
    """
    return np.exp(
        -1j * (2.0 * np.pi / config.wavelength_m) * (np.asarray(u, float) @ channel_positions_m(config).T)
    )


def _coarse(z: np.ndarray, geo: ArrayGeometry) -> np.ndarray:
    if geo.pairs is not None:
        assert geo.pair_solve is not None  # set with pairs
        d = np.angle(z[:, geo.pairs[:, 1]] * np.conj(z[:, geo.pairs[:, 0]]))
        return d @ geo.pair_solve.T
    # Beamforming: the grid point whose predicted phases best match the measured ones.
    assert geo.grid is not None and geo.grid_match is not None  # set where pairs is not
    score = np.abs(z @ geo.grid_match)  # (n, n_grid)
    return geo.grid[np.argmax(score, axis=1)]


def _refine_on_sphere(u: np.ndarray, psi: np.ndarray, design: np.ndarray, iterations: int = 3) -> np.ndarray:
    """Gauss-Newton in (az, el) on the unwrapped phases: least squares with ``|u| = 1`` built in.

    Normalising the unconstrained 3-D solution lets the poorly observed component (small depth
    aperture) leak into azimuth and elevation; fitting the angles directly reaches the bound.
    """
    psi = psi - psi.mean(axis=1, keepdims=True)
    az, el = angles_from_direction(u)
    for _ in range(iterations):
        ca, sa, ce, se = np.cos(az), np.sin(az), np.cos(el), np.sin(el)
        u = np.stack([ce * ca, ce * sa, -se], axis=1)
        d_az = np.stack([-ce * sa, ce * ca, np.zeros_like(az)], axis=1)
        d_el = np.stack([-se * ca, -se * sa, -ce], axis=1)
        jac = np.stack([d_az @ design.T, d_el @ design.T], axis=2)  # (n, n_rx, 2)
        resid = psi - u @ design.T
        step = np.linalg.solve(
            np.einsum("nki,nkj->nij", jac, jac), np.einsum("nki,nk->ni", jac, resid)[..., None]
        )
        az, el = az + step[:, 0, 0], np.clip(el + step[:, 1, 0], -np.pi / 2, np.pi / 2)
    return direction_from_angles(az, el)


def estimate_directions(
    pixels: np.ndarray,
    config: RadarConfig,
    calibrated: bool = False,
    facing: tuple[float, float, float] = (1.0, 0.0, 0.0),
) -> np.ndarray:
    """Unit direction vectors (antenna frame) from complex pixels of all receive channels.

    Parameters
    ----------
    pixels : ndarray, shape (n, n_rx), complex
        Peak pixel of each detection, one column per receive antenna (per virtual channel,
        ``n_virtual`` columns, for a MIMO radar).
    config : RadarConfig
        Antenna positions, wavelength and ``rx_calibration`` (divided out unless ``calibrated``).
    calibrated : bool
        True when ``pixels`` already had the calibration divided out.
    facing : (float, float, float)
        Side a coplanar array looks at (antenna frame); the default is the boresight.

    Returns
    -------
    ndarray, shape (n, 3)
        Unit vectors; multiply by the measured range for positions. A one-channel radar has no
        direction: every row is NaN (its detections carry NaN angles and positions, and the
        tracker follows them in range and range rate only).

    Examples
    --------
    Raw pixels carry each channel's complex gain; ``rx_calibration`` divides it out:

    >>> cal = np.exp(1j * np.radians([0.0, 40.0, -70.0, 120.0]))
    >>> cfg = RadarConfig.prototype_2022(rx_calibration=cal)
    >>> u = direction_from_angles(np.radians([-25.0, 5.0]), np.radians([10.0, -20.0]))
    >>> raw = steering_vector(u, cfg) * cal
    >>> np.degrees(angles_from_direction(estimate_directions(raw, cfg))).round(6).tolist()
    [[-25.0, 5.0], [10.0, -20.0]]
    """
    z = np.atleast_2d(np.asarray(pixels))
    if z.ndim != 2 or z.shape[1] != config.n_virtual:
        raise InputError(f"doa: field 'rx' has {z.shape[-1]} channels, radar_config has {config.n_virtual}")
    if config.n_virtual == 1:
        return np.full((z.shape[0], 3), np.nan)
    if not calibrated:
        z = z / channel_calibration(config)
    geo = array_geometry(config, facing)
    if z.shape[0] == 0:
        return np.zeros((0, 3))
    a0 = _coarse(z, geo)
    pred = a0 @ geo.design.T
    resid = np.angle(z * np.conj(z[:, :1])) - pred
    common = np.angle(np.sum(np.exp(1j * resid), axis=1, keepdims=True))
    unwrapped = pred + common + wrap_angle(resid - common)
    a = unwrapped @ geo.solve.T
    if geo.normal is None:
        u = a / np.maximum(np.linalg.norm(a, axis=1, keepdims=True), 1e-300)
        return _refine_on_sphere(u, unwrapped, geo.design)
    norm = np.linalg.norm(a, axis=1, keepdims=True)
    a = a / np.maximum(norm, 1.0)  # noise can push the in-plane part beyond the unit circle
    third = np.sqrt(np.maximum(1.0 - np.sum(a * a, axis=1, keepdims=True), 0.0))
    return a @ geo.basis.T + third * geo.normal


def direction_coherence(
    pixels: np.ndarray, u: np.ndarray, config: RadarConfig, calibrated: bool = False
) -> np.ndarray:
    """How well one plane wave from ``u`` explains the pixels: ``|z . conj(s(u))|^2 / (n ||z||^2)`` in [0, 1].

    About ``SNR / (SNR + 1)`` for a single scatterer; clearly lower when a pixel sums returns
    from several directions (e.g. ground to the left and right at the same range and Doppler),
    where the estimated direction means nothing.

    Parameters
    ----------
    pixels : ndarray, shape (n, n_rx), complex
        Pixels of all channels (``n_virtual`` for MIMO), one row per detection.
    u : ndarray, shape (n, 3) or (3,)
        Unit directions in the antenna frame to test.
    config : RadarConfig
        Channel positions (m), wavelength (m) and ``rx_calibration`` (divided out unless ``calibrated``).
    calibrated : bool
        True when ``pixels`` already had the calibration divided out.

    Returns
    -------
    ndarray, shape (n,)
        Coherence in [0, 1]; 1 for a noise-free plane wave from ``u``.

    Examples
    --------
    >>> from skyradar.config import RadarConfig
    >>> cfg = RadarConfig.prototype_2022()
    >>> right, left = direction_from_angles(np.radians([20.0, -20.0]), 0.0)
    >>> pixels = steering_vector(right, cfg)[None, :]
    >>> np.round(direction_coherence(pixels, right, cfg), 6).tolist()
    [1.0]
    >>> np.round(direction_coherence(pixels, left, cfg), 3).tolist()  # the mirrored direction fits badly
    [0.227]
    """
    z = np.atleast_2d(np.asarray(pixels))
    if not calibrated:
        z = z / channel_calibration(config)
    steer = steering_vector(u, config)
    num = np.abs(np.sum(z * np.conj(steer), axis=1)) ** 2
    den = config.n_virtual * np.maximum(np.sum(np.abs(z) ** 2, axis=1), 1e-300)
    return num / den


def direction_covariance(
    snr_db: np.ndarray | float,
    azimuth_rad: np.ndarray | float,
    elevation_rad: np.ndarray | float,
    config: RadarConfig,
) -> np.ndarray:
    """Cramer-Rao bound on the error of a direction across the line of sight, rad^2, shape (..., 2, 2).

    The inverse Fisher information (module docstring) of the direction's angular displacement along
    its two tangent axes in the antenna frame: rightward (increasing azimuth, ``cos(el) d az``) and
    upward (increasing elevation). A position at range ``R`` is off across the line of sight by
    ``R`` times that displacement, so ``R^2`` times this matrix is its covariance there, with the
    correlation of the two axes that an array's geometry gives off boresight. An array wider than
    it is tall measures the first axis better than the second (``ura-2x4``: 2.2 times at boresight).

    Parameters
    ----------
    snr_db : array_like
        Per-channel, per-pixel SNR ``A^2 / sigma^2`` of the pixel the direction is taken from, dB.
    azimuth_rad, elevation_rad : array_like
        True direction in the antenna frame.
    config : RadarConfig
        Antenna positions (the virtual array for MIMO) and wavelength.

    Returns
    -------
    ndarray, shape (..., 2, 2)
        Covariance of the (rightward, upward) angular displacement, rad^2; NaN where the array
        does not measure both (one channel, or a line of channels).

    Examples
    --------
    The square's two axes are alike at boresight; a row of four over two is not.

    >>> cfg = RadarConfig.prototype_2022()
    >>> C = direction_covariance(20.0, 0.0, 0.0, cfg)
    >>> bool(np.isclose(C[0, 0], C[1, 1])), float(C[0, 1])
    (True, 0.0)
    >>> C = direction_covariance(20.0, 0.0, 0.0, RadarConfig.prototype_2022(rx_positions_m="ura-2x4"))
    >>> round(float(np.sqrt(C[1, 1] / C[0, 0])), 2)
    2.24
    """
    snr = 10.0 ** (np.asarray(snr_db, float) / 10.0)
    az, el = np.broadcast_arrays(np.asarray(azimuth_rad, float), np.asarray(elevation_rad, float))
    k = 2.0 * np.pi / config.wavelength_m
    positions = channel_positions_m(config)
    q = positions - positions.mean(axis=0)
    right = np.stack([-np.sin(az), np.cos(az), np.zeros_like(az)], axis=-1)  # du/daz / cos(el)
    up = np.stack([-np.sin(el) * np.cos(az), -np.sin(el) * np.sin(az), -np.cos(el)], axis=-1)  # du/del
    g = -k * np.stack([right @ q.T, up @ q.T], axis=-1)  # (..., n, 2), centred by q
    info = np.einsum("...ki,...kj->...ij", g, g) * (2.0 * snr)[..., None, None]
    det = info[..., 0, 0] * info[..., 1, 1] - info[..., 0, 1] ** 2
    cov = np.stack([info[..., 1, 1], -info[..., 0, 1], -info[..., 1, 0], info[..., 0, 0]], axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        cov = cov / det[..., None]
    cov[~(det > 0.0)] = np.nan
    return cov.reshape(*det.shape, 2, 2)


def doa_crlb(
    snr_db: np.ndarray | float,
    azimuth_rad: np.ndarray | float,
    elevation_rad: np.ndarray | float,
    config: RadarConfig,
) -> tuple[np.ndarray, np.ndarray]:
    """Cramer-Rao bound on the standard deviation of azimuth and elevation, radians.

    Parameters
    ----------
    snr_db : array_like
        Per-channel, per-pixel SNR ``A^2 / sigma^2`` of the pixel the direction is taken from, dB.
    azimuth_rad, elevation_rad : array_like
        True direction in the antenna frame.
    config : RadarConfig
        Antenna positions (the virtual array for MIMO) and wavelength.

    Returns
    -------
    (sd_az_rad, sd_el_rad) : tuple of ndarray
        Square roots of the diagonal of the inverse Fisher information (module docstring); the
        azimuth's is that of :func:`direction_covariance`'s rightward axis over ``cos(el)``.

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> sd_az, sd_el = doa_crlb(30.0, 0.0, 0.0, cfg)
    >>> round(float(np.degrees(sd_az)), 3) == round(float(np.degrees(sd_el)), 3)  # square array
    True
    """
    cov = direction_covariance(snr_db, azimuth_rad, elevation_rad, config)
    el = np.broadcast_to(np.asarray(elevation_rad, float), cov.shape[:-2])
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.sqrt(cov[..., 0, 0]) / np.cos(el), np.sqrt(cov[..., 1, 1])


def antenna_to_body(points_m: np.ndarray, config: RadarConfig) -> np.ndarray:
    """Antenna-frame points (..., 3) to the body frame (forward, right, down) via ``config.mount``.

    Parameters
    ----------
    points_m : ndarray, shape (..., 3)
        Points in the antenna frame (x boresight, y right, z down), m.
    config : RadarConfig
        Its ``mount`` gives the rotation and the lever arm (m).

    Returns
    -------
    ndarray, shape (..., 3)
        Points in the body frame, m: rotated, then shifted by ``mount.position_m``.

    Examples
    --------
    A radar pitched 30 deg down, 2 m forward and 0.3 m below the reference point, sees a point
    100 m along its boresight 86.6 m ahead and 50 m below:

    >>> from skyradar.config import Mount, RadarConfig
    >>> cfg = RadarConfig.prototype_2022(mount=Mount.preset("forward-down"))
    >>> antenna_to_body(np.array([100.0, 0.0, 0.0]), cfg).round(3).tolist()
    [88.603, 0.0, 50.3]
    """
    mount = config.mount
    rotation = _mount_rotation(mount.yaw_deg, mount.pitch_deg, mount.roll_deg)
    return np.asarray(points_m, float) @ rotation.T + np.asarray(mount.position_m)


@lru_cache(maxsize=16)
def _mount_rotation(yaw_deg: float, pitch_deg: float, roll_deg: float) -> np.ndarray:
    from skyradar.config import Mount

    rotation = Mount(yaw_deg=yaw_deg, pitch_deg=pitch_deg, roll_deg=roll_deg).rotation
    rotation.setflags(write=False)
    return rotation
