"""Knowledge-aided clutter prediction: which ground directions can produce each range-Doppler cell.

A static ground point seen from the radar along the NED unit vector ``u`` at slant range ``R`` shows
at radial velocity ``-v_own . u`` (aliased into ``[-VLim, VLim)``) and apparent range
``R + v * range_doppler_coupling_s`` (the sawtooth chirp's coupling). Over flat ground ``h`` below
the radar every range ``R >= h`` is a ring of depression ``asin(h / R)``; sampling the ring in
azimuth gives, for every cell, the few directions (left and right of the ground track, and one
pair per Doppler alias) its clutter comes from. Their receive steering vectors
(:func:`skyradar.process.doa.steering_vector`) weighted by the two-way antenna gain and a
constant-gamma reflectivity (``sigma0 ~ sin(grazing)``), spread over the Hann point-spread of the
range and Doppler FFTs (main lobe, +-2 bins), sum to a predicted clutter covariance per cell. Its
eigenvectors span the clutter subspace that :mod:`skyradar.process.clutter_suppress` projects out
(the knowledge-aided STAP idea: Guerci and Baranoski, "Knowledge-aided adaptive radar at DARPA",
IEEE Signal Processing Magazine 23(1), 2006; Ward, "Space-time adaptive processing for airborne
radar", MIT Lincoln Laboratory TR-1015, 1994, section 2 for the clutter ridge).

A terrain (``depth_fn(north_offset_m, east_offset_m) -> ground depth below the radar, m``) replaces
the flat ground: the depression of each ring sample is iterated to the terrain height under it.

Cost (one prediction of the prototype, 720 ring samples per range bin, ~213k samples): the
samples' geometry and steering are computed in compiled passes, each sample's outer product once
(its Hermitian upper triangle, ``n_rx**2`` reals) and added to its 3 x 5 point-spread taps; a
cell's eigen-pairs (compiled cyclic Jacobi, :func:`hermitian_eigh`, started from the previous
cell's basis) are computed only when a frame's measured clutter gates it
(:meth:`ClutterSubspace.ensure`), 30-50 % of the cells over terrain. About 0.15 CPU-s at load 5
without the eigen-pairs (0.85 s for the numpy sum and batched ``eigh`` of every cell before);
checked against the straightforward numpy sum and ``numpy.linalg.eigh`` in
``tests/test_clutter_prediction_cost.py``.

Examples
--------
>>> from skyradar.config import RadarConfig
>>> cfg = RadarConfig.prototype_2022()
>>> sub = clutter_subspace(cfg, np.array([50.0, 0.0, 0.0]), np.eye(3), 1000.0)
>>> bool(sub.predicted[:60].any()), bool(sub.predicted[200].any())  # no ground nearer than 1000 m
(False, True)
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cached_property

import numpy as np
from numba import njit

from skyradar.config import RadarConfig
from skyradar.process.small_hermitian import hermitian_eigh

__all__ = ["ClutterSubspace", "clutter_subspace", "hermitian_eigh", "decompose_cell", "cell_scratch"]


class ClutterSubspace:
    """Predicted clutter of one frame geometry, per range-Doppler cell.

    Built by :func:`clutter_subspace` from the packed predicted covariance of every cell; a cell's
    eigen-decomposition is computed when first needed (:meth:`ensure`, or inside the suppression
    kernel for the cells the measured clutter gates), so a prediction costs only the cells used.

    Parameters
    ----------
    covariance : ndarray, shape (n_range, n_doppler, n_rx * n_rx), float64
        Packed predicted covariance per cell (layout under ``covariance`` below).
    n_rx : int
        Channels of the covariance.
    velocity_ant_mps : ndarray, shape (3,), optional
        Radar velocity over the ground in the antenna frame, m/s, the prediction was made for.
    down_ant : ndarray, shape (3,), optional
        The down axis (NED) in the antenna frame, unit vector.
    height_agl_m : float, optional
        Height above the ground below the radar, m.

    Attributes
    ----------
    covariance : ndarray, shape (n_range, n_doppler, n_rx * n_rx), float64
        Predicted clutter covariance per cell, packed: the ``n_rx`` real diagonal entries, then the
        upper triangle's (re, im) pairs row by row (unnormalised).
    predicted : ndarray of bool, shape (n_range, n_doppler)
        Cells some ground direction reaches (main lobe of the point-spread included).
    vectors : ndarray, shape (n_range, n_doppler, n_rx, n_rx), complex64
        Eigenvectors of the trace-normalised covariance, columns by decreasing eigenvalue
        (identity where no clutter is predicted). Every cell is decomposed on first access.
    fractions : ndarray, shape (n_range, n_doppler, n_rx), float32
        Eigenvalues divided by their sum (0 where no clutter is predicted), decreasing.

    Examples
    --------
    Two channels; cell (0, 0) holds the covariance ``s s^H`` of the steering vector ``s = (1, 1)``
    (packed: diagonal 1, 1, then ``s_0 conj(s_1) = 1 + 0i``), cell (0, 1) no clutter:

    >>> sub = ClutterSubspace(np.array([[[1.0, 1.0, 1.0, 0.0], [0.0, 0.0, 0.0, 0.0]]]), 2)
    >>> sub.predicted.tolist(), sub.free_cells.tolist()
    ([[True, False]], [1])
    >>> vectors = sub.cell_vectors(np.array([0]), np.array([0]))  # rank one: its first vector is s / |s|
    >>> np.round(np.abs(vectors[0, :, 0]) ** 2, 6).tolist(), np.round(sub.fractions[0], 6).tolist()
    ([0.5, 0.5], [[1.0, 0.0], [0.0, 0.0]])
    """

    def __init__(
        self,
        covariance: np.ndarray,
        n_rx: int,
        velocity_ant_mps: np.ndarray | None = None,
        down_ant: np.ndarray | None = None,
        height_agl_m: float | None = None,
    ):
        n_r, n_d = covariance.shape[:2]
        self.covariance = covariance
        self.predicted = np.einsum("rdk->rd", covariance[..., :n_rx]) > 0
        self.done = np.zeros((n_r, n_d), np.bool_)  # cells decomposed so far
        self._vectors = np.empty((n_r, n_d, n_rx, n_rx), np.complex64)
        self._fractions = np.zeros((n_r, n_d, n_rx), np.float32)
        # e_i^H diag(1 / gain) of a cell's first n_rx - 1 eigenvectors, for the calibration `rows_key`:
        # the suppression kernel's inner products with an uncalibrated snapshot, filled as it needs them.
        self.rows = np.empty((n_r, n_d, n_rx - 1, n_rx), np.complex64)
        self.rows_done = np.zeros((n_r, n_d), np.bool_)
        self.rows_key = b""
        # The geometry it was predicted for: antenna-frame velocity, m/s, the down axis in the
        # antenna frame and the height above the ground below, m. None: unknown.
        self.velocity_ant_mps, self.down_ant, self.height_agl_m = velocity_ant_mps, down_ant, height_agl_m

    def ensure(self, range_index: np.ndarray | None = None, doppler_index: np.ndarray | None = None) -> None:
        """Decompose the given cells (default: all) that are not decomposed yet."""
        if range_index is None:
            rr, dd = np.nonzero(~self.done)
        else:
            rr, dd = np.broadcast_arrays(
                np.asarray(range_index, np.int64), np.asarray(doppler_index, np.int64)
            )
        _decompose(self.covariance, self.done, self._vectors, self._fractions, rr.ravel(), dd.ravel())

    def cell_vectors(self, range_index: np.ndarray, doppler_index: np.ndarray) -> np.ndarray:
        """Eigenvectors (n, n_rx, n_rx) of the given cells only (decomposing just those)."""
        self.ensure(range_index, doppler_index)
        return self._vectors[range_index, doppler_index]

    def calibrated_rows(self, inv_gain: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``rows`` and ``rows_done`` for the calibration ``inv_gain``; a different one starts them afresh."""
        key = np.asarray(inv_gain).tobytes()
        if self.rows_key != key:
            self.rows_done[:] = False
            self.rows_key = key
        return self.rows, self.rows_done

    @property
    def vectors(self) -> np.ndarray:
        self.ensure()
        return self._vectors

    @property
    def fractions(self) -> np.ndarray:
        self.ensure()
        return self._fractions

    @cached_property
    def free_cells(self) -> np.ndarray:
        """Flat indices of the cells no ground direction reaches (where the noise floor is measured)."""
        return np.flatnonzero(~self.predicted)


@njit(cache=True)
def steering_into(u0, u1, u2, rx, wavenumber, out):  # pragma: no cover - compiled
    """:func:`skyradar.process.doa.steering_vector` of one direction ``(u0, u1, u2)`` into ``out``
    (n_rx,), compiled for the kernels that form steering vectors one direction at a time."""
    for k in range(rx.shape[0]):
        phase = -wavenumber * (u0 * rx[k, 0] + u1 * rx[k, 1] + u2 * rx[k, 2])
        out[k] = complex(np.cos(phase), np.sin(phase))


@njit(cache=True)
def _accumulate(r_pos, d_pos, u_ant, rx, wavenumber, weight, n_r, n_d, acc):  # pragma: no cover - compiled
    # acc[r, d]: the cell's Hermitian covariance packed as n_k real diagonal entries, then the upper
    # triangle's (re, im) pairs row by row. Each ring sample's receive steering vector (as
    # skyradar.process.doa.steering_vector: s_k = exp(-i k u . r_k), unit modulus, so the diagonal
    # is 1) and outer product s s^H are formed once and added to its 3 x 5 point-spread taps (16
    # reals per tap); compiled, the steering costs less than numpy's complex exp and temporaries.
    n_s = r_pos.size
    n_k = rx.shape[0]
    n_p = n_k * (n_k - 1) // 2
    prod = np.ones(n_k + 2 * n_p)
    steer = np.empty(n_k, np.complex128)
    wd = np.empty(5)
    for s in range(n_s):
        steering_into(u_ant[s, 0], u_ant[s, 1], u_ant[s, 2], rx, wavenumber, steer)
        p = n_k
        for i in range(n_k):
            for j in range(i + 1, n_k):
                c = steer[i] * np.conj(steer[j])
                prod[p], prod[p + 1] = c.real, c.imag
                p += 2
        r0 = int(np.floor(r_pos[s] + 0.5))
        d0 = int(np.floor(d_pos[s] + 0.5))
        for dd in range(-2, 3):
            y = d_pos[s] - (d0 + dd)
            wd[dd + 2] = 0.5 if abs(abs(y) - 1.0) < 1e-9 else np.sinc(y) / (1.0 - y * y)
        for dr in range(-1, 2):
            r = r0 + dr
            if r < 0 or r >= n_r:
                continue
            x = r_pos[s] - r
            # Hann main lobe in the long-window limit, sinc(x) / (1 - x^2) (0.5 at one bin); the exact
            # finite-window response is skyradar.sim.psf.window_response, which process may not import.
            wr = 0.5 if abs(abs(x) - 1.0) < 1e-9 else np.sinc(x) / (1.0 - x * x)
            for dd in range(-2, 3):
                w = weight[s] * (wr * wd[dd + 2]) ** 2
                if w <= 0.0:
                    continue
                d = (d0 + dd) % n_d
                for q in range(prod.size):
                    acc[r, d, q] += w * prod[q]
    return acc


@njit(cache=True)
def _unpack(acc_cell, n_k, a):  # pragma: no cover - compiled
    # The packed cell (see _accumulate) as a full Hermitian matrix divided by its trace; the trace.
    total = 0.0
    for i in range(n_k):
        total += acc_cell[i]
    if not total > 0.0:
        return 0.0
    p = n_k
    for i in range(n_k):
        a[i, i] = acc_cell[i] / total
        for j in range(i + 1, n_k):
            a[i, j] = complex(acc_cell[p], acc_cell[p + 1]) / total
            a[j, i] = np.conj(a[i, j])
            p += 2
    return total


@njit(cache=True)
def decompose_cell(acc, done, vectors, fractions, r, d, scratch):  # pragma: no cover - compiled
    """Eigen-pairs of cell (r, d)'s trace-normalised packed covariance into ``vectors``/``fractions``
    (decreasing; identity and 0 where no clutter is predicted); ``scratch`` (:func:`cell_scratch`)
    is work space. Every cell starts from the identity, so its eigen-pairs depend on its covariance
    alone: warm-started from the cell decomposed before it (2 Jacobi sweeps instead of 4, 0.5 us a
    cell), they depended by up to 1e-6 on which cells earlier frames had needed, and a detection at
    its threshold came and went with how a run was chunked (``tests/test_chunked_process.py``)."""
    a, v, lam, order = scratch
    n_k = vectors.shape[2]
    done[r, d] = True
    if not _unpack(acc[r, d], n_k, a) > 0.0:
        for i in range(n_k):
            for j in range(n_k):
                vectors[r, d, i, j] = 1.0 if i == j else 0.0
            fractions[r, d, i] = 0.0
        return
    hermitian_eigh(a, v, lam, order, 1e-7, 12)
    for c in range(n_k):
        fractions[r, d, c] = max(lam[order[c]], 0.0)
        for i in range(n_k):
            vectors[r, d, i, c] = v[i, order[c]]


@njit(cache=True)
def cell_scratch(n_k):  # pragma: no cover - compiled
    c = np.empty((n_k, n_k), np.complex128)
    return c, c.copy(), np.empty(n_k), np.empty(n_k, np.int64)


@njit(cache=True)
def _decompose(acc, done, vectors, fractions, rr, dd):  # pragma: no cover - compiled
    scratch = cell_scratch(vectors.shape[2])
    for c in range(rr.size):
        if not done[rr[c], dd[c]]:
            decompose_cell(acc, done, vectors, fractions, rr[c], dd[c], scratch)


def _ring_depths(
    config: RadarConfig, height_agl_m: float, n_azimuth: int, depth_fn: Callable | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Range of each range bin's ring (n_r,), ring azimuths (n_az,), ground depth per sample (n_r, n_az)."""
    rng = config.range_axis_m[config.range_axis_m > 0]
    phi = np.linspace(-np.pi, np.pi, n_azimuth, endpoint=False)
    depth = np.full((rng.size, phi.size), float(height_agl_m))
    if depth_fn is not None:
        for _ in range(3):
            # The ground under a ring sample sets its depression, which moves the sample: iterate.
            horizontal = np.sqrt(np.maximum(rng[:, None] ** 2 - depth**2, 0.0))
            depth = np.asarray(depth_fn(horizontal * np.cos(phi), horizontal * np.sin(phi)), float)
    return rng, phi, depth


@njit(cache=True)
def _ring_samples(rng, phi, depth, v, rot, coupling_s, d_range, d_velocity, zero_bin):  # pragma: no cover
    # Every ring sample with ground in view (0 < depth < range): NED direction u (depression
    # asin(depth / R)), its radial velocity -v . u, fractional range and Doppler bins (with the
    # chirp's range-Doppler coupling), antenna-frame direction rot^T u and its angles, sin(grazing).
    n = 0
    for i in range(rng.size):
        for j in range(phi.size):
            n += 1 if 0.0 < depth[i, j] < rng[i] else 0
    u_ant, az, el = np.empty((n, 3)), np.empty(n), np.empty(n)
    r_pos, d_pos, grazing = np.empty(n), np.empty(n), np.empty(n)
    s = 0
    for i in range(rng.size):
        for j in range(phi.size):
            if not 0.0 < depth[i, j] < rng[i]:
                continue
            ud = depth[i, j] / rng[i]
            uh = np.sqrt(1.0 - ud * ud)
            u0, u1 = uh * np.cos(phi[j]), uh * np.sin(phi[j])
            radial = -(u0 * v[0] + u1 * v[1] + ud * v[2])
            r_pos[s] = (rng[i] + radial * coupling_s) / d_range
            d_pos[s] = radial / d_velocity + zero_bin
            for k in range(3):
                u_ant[s, k] = u0 * rot[0, k] + u1 * rot[1, k] + ud * rot[2, k]
            az[s] = np.arctan2(u_ant[s, 1], u_ant[s, 0])
            el[s] = np.arcsin(min(max(-u_ant[s, 2], -1.0), 1.0))
            grazing[s] = ud  # sin(grazing) over flat ground: constant-gamma reflectivity
            s += 1
    return u_ant, az, el, r_pos, d_pos, grazing


def clutter_subspace(
    config: RadarConfig,
    velocity_ned_mps: np.ndarray,
    ant_to_ned: np.ndarray,
    height_agl_m: float,
    depth_fn: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None,
    n_azimuth: int = 1440,
) -> ClutterSubspace:
    """Predicted clutter covariance eigen-decomposition of every range-Doppler cell.

    The covariance is that of the frame's channels (:attr:`~skyradar.config.RadarConfig.frame_shape`):
    for a time-division MIMO radar the virtual channels, which every static point of the frame sees
    from the same moved receivers (:meth:`~skyradar.config.RadarConfig.terrain_channel_positions_m`),
    its Doppler folded into the ``nV / n_tx``-bin image, so a cell adds the covariances of every
    alias of its Doppler.

    Parameters
    ----------
    config : RadarConfig
        Array geometry (m), wavelength (m), bins, antenna pattern.
    velocity_ned_mps : ndarray (3,)
        Radar velocity over the ground, NED, m/s.
    ant_to_ned : ndarray (3, 3)
        Rotation of antenna-frame vectors into NED (body-to-NED times the mount rotation).
    height_agl_m : float
        Radar height above the ground below it, m (flat earth when ``depth_fn`` is None).
    depth_fn : callable, optional
        Ground depth below the radar at horizontal NED offsets (north, east), m.
    n_azimuth : int
        Ring samples per range bin (1440: 0.25 deg, under a Doppler bin at 70 m/s).

    Returns
    -------
    ClutterSubspace
        Packed covariance of every cell; eigen-pairs computed on demand.

    Examples
    --------
    A radar hovering 1000 m above flat ground sees its clutter at zero Doppler (bin 125, spread
    over the +-2 bins of the point-spread) from the ground's slant range 1000 m (bin 67, less
    the one-bin range spread) to the end of the processed range:

    >>> from skyradar.config import RadarConfig
    >>> cfg = RadarConfig.prototype_2022()
    >>> sub = clutter_subspace(cfg, np.zeros(3), np.eye(3), 1000.0, n_azimuth=360)
    >>> rows, cols = np.nonzero(sub.predicted)
    >>> np.unique(cols).tolist(), int(rows.min()), int(rows.max())
    ([123, 124, 125, 126, 127], 66, 332)
    """
    rng, phi, depth = _ring_depths(config, height_agl_m, int(n_azimuth), depth_fn)
    rot = np.ascontiguousarray(ant_to_ned, float)  # u_ant = rot^T u for each NED vector u
    v = np.ascontiguousarray(velocity_ned_mps, float)
    geometry = (config.range_doppler_coupling_s, config.range_resolution_m, config.doppler_resolution_mps)
    n_r, n_d, n_k = config.frame_shape
    u_ant, az, el, r_pos, d_pos, grazing = _ring_samples(rng, phi, depth, v, rot, *geometry, float(n_d // 2))
    weight = 10.0 ** (2.0 * config.antenna.gain_db(az, el) / 10.0) * grazing
    # Every static point sees the channels from the same places (the receivers; for a MIMO radar
    # also moved by each transmitter's offset and its slot's Doppler path), and its Doppler folds
    # into the frame's image: the aliases of one cell add their covariances.
    rx = np.ascontiguousarray(config.terrain_channel_positions_m(-(rot.T @ v)), float)
    wavenumber = 2.0 * np.pi / config.wavelength_m
    acc = _accumulate(r_pos, d_pos, u_ant, rx, wavenumber, weight, n_r, n_d, np.zeros((n_r, n_d, n_k * n_k)))
    return ClutterSubspace(acc, n_k, rot.T @ v, rot[2].copy(), float(height_agl_m))
