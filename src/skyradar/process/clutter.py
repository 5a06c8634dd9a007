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
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numba import njit

from skyradar.config import RadarConfig
from skyradar.process.doa import steering_vector

__all__ = ["ClutterSubspace", "clutter_subspace"]


@dataclass(frozen=True)
class ClutterSubspace:
    """Predicted clutter of one frame geometry, per range-Doppler cell.

    Attributes
    ----------
    vectors : ndarray, shape (n_range, n_doppler, n_rx, n_rx), complex64
        Eigenvectors of the predicted clutter covariance, columns by decreasing eigenvalue.
    fractions : ndarray, shape (n_range, n_doppler, n_rx), float32
        Eigenvalues divided by their sum (0 where no clutter is predicted), decreasing.
    predicted : ndarray of bool, shape (n_range, n_doppler)
        Cells some ground direction reaches (main lobe of the point-spread included).
    """

    vectors: np.ndarray
    fractions: np.ndarray
    predicted: np.ndarray

    def null_rows(self, inv_gain: np.ndarray) -> np.ndarray:
        """``E^H diag(inv_gain)``, first ``n_rx - 1`` eigenvectors: (n_range, n_doppler, n_rx - 1, n_rx).

        The rows a projection of an uncalibrated snapshot takes inner products with (the channel
        calibration folded in), contiguous per cell, complex64: the suppression kernel reads 32
        bytes per null instead of a strided column of ``vectors``. Computed once per prediction
        and calibration, reused by every frame that shares them.
        """
        key = np.asarray(inv_gain, np.complex64).tobytes()
        cache = self.__dict__.setdefault("_null_rows", {})
        if key not in cache:
            rows = np.conj(np.swapaxes(self.vectors[..., :-1], -1, -2)) * np.asarray(inv_gain, np.complex64)
            cache.clear()  # one calibration per radar head: keep the latest only
            cache[key] = np.ascontiguousarray(rows, np.complex64)
        return cache[key]

    @cached_property
    def free_cells(self) -> np.ndarray:
        """Flat indices of the cells no ground direction reaches (where the noise floor is measured)."""
        return np.flatnonzero(~self.predicted)


@njit(cache=True)
def _accumulate(r_pos, d_pos, steer, weight, n_r, n_d, cov):  # pragma: no cover - compiled
    n_s, n_k = steer.shape
    for s in range(n_s):
        r0 = int(np.floor(r_pos[s] + 0.5))
        d0 = int(np.floor(d_pos[s] + 0.5))
        for dr in range(-1, 2):
            r = r0 + dr
            if r < 0 or r >= n_r:
                continue
            x = r_pos[s] - r
            # Hann main lobe in the long-window limit, sinc(x) / (1 - x^2) (0.5 at one bin); the exact
            # finite-window response is skyradar.sim.psf.window_response, which process may not import.
            wr = 0.5 if abs(abs(x) - 1.0) < 1e-9 else np.sinc(x) / (1.0 - x * x)
            for dd in range(-2, 3):
                y = d_pos[s] - (d0 + dd)
                wd = 0.5 if abs(abs(y) - 1.0) < 1e-9 else np.sinc(y) / (1.0 - y * y)
                w = weight[s] * (wr * wd) ** 2
                if w <= 0.0:
                    continue
                d = (d0 + dd) % n_d
                for i in range(n_k):
                    for j in range(n_k):
                        cov[r, d, i, j] += w * steer[s, i] * np.conj(steer[s, j])
    return cov


def _ring_directions(
    config: RadarConfig, height_agl_m: float, n_azimuth: int, depth_fn: Callable | None
) -> tuple[np.ndarray, np.ndarray]:
    """NED unit vectors (n, 3) and slant ranges (n,) of ground points on each range bin's ring."""
    rng = config.range_axis_m[config.range_axis_m > 0]
    phi = np.linspace(-np.pi, np.pi, n_azimuth, endpoint=False)
    r_grid, p_grid = np.meshgrid(rng, phi, indexing="ij")
    depth = np.full(r_grid.shape, float(height_agl_m))
    for _ in range(3 if depth_fn is not None else 0):
        # The ground under a ring sample sets its depression, which moves the sample: iterate.
        horizontal = np.sqrt(np.maximum(r_grid**2 - depth**2, 0.0))
        depth = np.asarray(depth_fn(horizontal * np.cos(p_grid), horizontal * np.sin(p_grid)), float)
    seen = (depth > 0) & (depth < r_grid)
    ud = np.where(seen, depth / r_grid, 0.0)
    uh = np.sqrt(1.0 - ud**2)
    u = np.stack([uh * np.cos(p_grid), uh * np.sin(p_grid), ud], axis=-1)
    return u[seen], r_grid[seen]


def clutter_subspace(
    config: RadarConfig,
    velocity_ned_mps: np.ndarray,
    ant_to_ned: np.ndarray,
    height_agl_m: float,
    depth_fn: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None,
    n_azimuth: int = 1440,
) -> ClutterSubspace:
    """Predicted clutter covariance eigen-decomposition of every range-Doppler cell.

    Parameters
    ----------
    config : RadarConfig
        Array geometry, wavelength, bins, antenna pattern.
    velocity_ned_mps : ndarray (3,)
        Radar velocity over the ground, NED.
    ant_to_ned : ndarray (3, 3)
        Rotation of antenna-frame vectors into NED (body-to-NED times the mount rotation).
    height_agl_m : float
        Radar height above the ground below it (flat earth when ``depth_fn`` is None).
    depth_fn : callable, optional
        Ground depth below the radar at horizontal NED offsets (north, east), m.
    n_azimuth : int
        Ring samples per range bin (1440: 0.25 deg, under a Doppler bin at 70 m/s).
    """
    u_ned, slant = _ring_directions(config, height_agl_m, int(n_azimuth), depth_fn)
    v = np.asarray(velocity_ned_mps, float)
    radial = -(u_ned @ v)
    r_pos = (slant + radial * config.range_doppler_coupling_s) / config.range_resolution_m
    d_pos = radial / config.doppler_resolution_mps + config.n_doppler // 2
    u_ant = u_ned @ np.asarray(ant_to_ned, float)  # rows: R^T u for each NED vector u
    az = np.arctan2(u_ant[:, 1], u_ant[:, 0])
    el = np.arcsin(np.clip(-u_ant[:, 2], -1.0, 1.0))
    gain2 = 10.0 ** (2.0 * config.antenna.gain_db(az, el) / 10.0)
    grazing = u_ned[:, 2]  # sin(grazing) over flat ground: constant-gamma reflectivity
    weight = gain2 * grazing
    steer = steering_vector(u_ant, config)
    n_r, n_d, n_k = config.n_range, config.n_doppler, config.n_rx
    cov = _accumulate(r_pos, d_pos, steer, weight, n_r, n_d, np.zeros((n_r, n_d, n_k, n_k), np.complex128))
    total = np.einsum("rdii->rd", cov).real
    predicted = total > 0
    vectors = np.zeros((n_r, n_d, n_k, n_k), np.complex64)
    vectors[...] = np.eye(n_k)
    fractions = np.zeros((n_r, n_d, n_k), np.float32)
    if predicted.any():
        lam, vec = np.linalg.eigh((cov[predicted] / total[predicted, None, None]).astype(np.complex64))
        vectors[predicted] = vec[..., ::-1]
        fractions[predicted] = np.clip(lam[..., ::-1], 0.0, None)
    return ClutterSubspace(vectors, fractions, predicted)
