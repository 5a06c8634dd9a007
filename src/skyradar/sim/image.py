"""Image-domain FMCW radar simulator: scene in, range x Doppler x rx cube out, one frame at a time.

The thesis' method (Maas 2022, ch. 2) made exact where it simplified:

- geodetic to local coordinates exactly (pymap3d); attitude relative to the local vertical;
- terrain cropped to RLim around the radar before any per-facet work, then subdivided into
  bilinear sub-facets no larger than ``facet_size_m`` (default dR/2, so 15 m range bins fill
  without gaps), each with its exact surface area and normal;
- incidence-angle reflectivity (cosine by default, any callable of the incidence angle);
- occlusion of terrain hidden behind terrain (line of sight along range per azimuth);
- two-way antenna gain, radar equation, exact two-way path phase per receive antenna;
- Doppler with aliasing wrap and the sawtooth range-Doppler coupling;
- one-pass scatter-add and calibrated thermal noise (k T B_n F per pixel, so SNR is physical);
- optionally: the range and Doppler windows' point-spread (:mod:`skyradar.sim.psf`),
  speckle on terrain and Swerling 1 fluctuation of the targets.

Pixel units: ``|pixel|^2`` is received power in W for a scatterer centred in that pixel.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numba import get_num_threads

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.geo import ned_rotation_to, ned_to_geodetic, rotation_matrix
from skyradar.sim._noise_kernel import finalize_frame, frame_key
from skyradar.sim._tables import REFLECTIVITY_MODELS, reflectivity_table, two_way_gain_table
from skyradar.sim._terrain_bands import banded_returns
from skyradar.sim._terrain_kernel import add_sparse, relative_points, rotate_points, terrain_returns
from skyradar.sim.facets import facet_rule
from skyradar.sim.geometry import AntennaGeometry, PlatformState, PointTarget, TerrainView
from skyradar.sim.horizon import horizon_grid, needs_horizon, target_clear, terrain_horizon
from skyradar.sim.psf import apply_psf, enbw, frame_options, psf_kernels, speckle_key
from skyradar.sim.targets import add_targets, line_of_sight, swerling1_power, target_geometry

__all__ = [
    "PlatformState",
    "PointTarget",
    "AntennaGeometry",
    "TerrainView",
    "ImageSimulator",
    "REFLECTIVITY_MODELS",
    "two_way_gain_table",
]
_NO_SPECKLE = np.uint64(0)


class ImageSimulator:
    """Simulate range-Doppler frames of the configured radar over terrain with point targets.

    Parameters
    ----------
    config : RadarConfig
        Radar hardware, antenna pattern and mount.
    terrain : skyradar.scene.terrain.Terrain, optional
        Ground; ``None`` simulates free space.
    origin : tuple of float
        Geodetic origin (lat_deg, lon_deg, alt_m) of the scenario NED frame.
    facet_size_m : float, optional
        Largest facet edge after subdivision, m. Default dR/2. Pass ``float('inf')`` to keep
        the DEM's own spacing.
    reflectivity : str or callable
        ``"cosine"`` (default), ``"lambert"``, ``"constant"``, or ``f(incidence_rad) -> factor``.
    occlusion : bool
        Hide terrain behind terrain (line of sight along range per azimuth).
    noise : bool
        Add thermal noise of power ``config.noise_power_w`` per pixel.
    seed : int
        Noise seed; frame ``i`` uses the stream ``(seed, i)`` so any frame is reproducible alone.
    flat_earth : bool
        Use the thesis' flat-earth mapping of the DEM instead of exact geodesy.
    range_doppler_coupling : bool
        Shift apparent range by ``v * fc / (B * PRF)`` as a sawtooth chirp does.
    ground_reflectivity_db : float
        Extra gain applied to terrain returns (e.g. -10 for the weaker ground seen in flight).
    psf : bool
        Frames as the Hann x Hann windowed FFTs give them (:mod:`skyradar.sim.psf`): terrain and
        noise convolved with the bin-averaged window kernel, targets spread by the exact window
        response at their fractional position. Noise per pixel becomes ``noise_power_w * ENBW``.
    speckle : bool
        Each terrain sub-facet times a unit-power complex Gaussian, new every frame.
    swerling : {0, 1}
        Target RCS constant (0) or exponential, independent per frame and target (1).
    adaptive_facets : bool, optional
        Cut each DEM cell by its own range and Doppler extent (:mod:`skyradar.sim.facets`)
        instead of by ground size. Default: on with ``psf``, off without it.

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> sim = ImageSimulator(cfg, noise=False)
    >>> own = PlatformState(np.zeros(3), np.array([30.0, 0, 0]), np.zeros(3))
    >>> cube = sim.frame(own, [PointTarget(np.array([1500.0, 0, 0]), np.zeros(3))])
    >>> k, j, _ = np.unravel_index(np.abs(cube).argmax(), cube.shape)
    >>> round(float(cfg.range_axis_m[k])), round(float(cfg.doppler_axis_mps[j]))
    (1499, -30)
    """

    def __init__(
        self,
        config: RadarConfig,
        terrain=None,
        origin: Sequence[float] = (0.0, 0.0, 0.0),
        facet_size_m: float | None = None,
        reflectivity: str | Callable[[np.ndarray], np.ndarray] = "cosine",
        occlusion: bool = True,
        noise: bool = True,
        seed: int = 0,
        flat_earth: bool = False,
        range_doppler_coupling: bool = True,
        ground_reflectivity_db: float = 0.0,
        psf: bool = False,
        speckle: bool = False,
        swerling: int = 0,
        adaptive_facets: bool | None = None,
    ) -> None:
        self.config = config
        self.terrain = terrain
        lat0, lon0, alt0 = origin
        self.origin = (float(lat0), float(lon0), float(alt0))
        self.facet_size_m = config.range_resolution_m / 2.0 if facet_size_m is None else float(facet_size_m)
        if not self.facet_size_m > 0:
            raise InputError(f"simulation.facet_size_m must be > 0, got {facet_size_m!r}")
        self.occlusion = bool(occlusion)
        self.noise = bool(noise)
        self.seed = int(seed)
        self.flat_earth = bool(flat_earth)
        self.coupling_s = config.range_doppler_coupling_s if range_doppler_coupling else 0.0
        self.ground_gain = 10.0 ** (ground_reflectivity_db / 10.0)
        self._refl_table = reflectivity_table(reflectivity)
        self.psf, self.speckle, self.swerling = frame_options(psf, speckle, swerling)
        self._psf = psf_kernels(config) if self.psf else None
        self._gain2, self._gain2_step = two_way_gain_table(config)
        self._grid_ned = None
        self._blocks: np.ndarray | None = None
        # 1: the kernel's vectorised batches; 0: its scalar reference loop (tests compare them).
        self._kernel_mode = 1
        # Per-frame work arrays kept between frames (fresh ones cost page faults every frame).
        self._scratch: dict[str, np.ndarray] = {}
        self._mount_rotation = config.mount.rotation
        self._mount_position_m = np.asarray(config.mount.position_m, float)
        if terrain is not None:
            self._grid_ned = terrain.points_ned(*self.origin, flat_earth=self.flat_earth)
            self._spacing_m = terrain.spacing_m
            dy, dx = self._spacing_m
            self._nsub = (
                max(1, int(np.ceil(dy / self.facet_size_m))),
                max(1, int(np.ceil(dx / self.facet_size_m))),
            )
            self._facet_m = max(dy / self._nsub[0], dx / self._nsub[1])
            self._level = bool(np.ptp(terrain.elevation_m) == 0.0)  # see horizon.needs_horizon
            self._horizon_grid = horizon_grid(config, self._spacing_m, self._nsub, self._facet_m)
            adaptive = self.psf if adaptive_facets is None else bool(adaptive_facets)
            self._facets = facet_rule(config, self._spacing_m, self.facet_size_m, adaptive)

    # ---- geometry ---------------------------------------------------------------------------
    def geometry(self, platform: PlatformState) -> AntennaGeometry:
        """Antenna position and orientation in the scenario NED frame for one platform state."""
        pos = np.asarray(platform.position_ned_m, float)
        yaw, pitch, roll = np.asarray(platform.attitude_rad, float)
        body_to_local = rotation_matrix(yaw, pitch, roll)
        lat, lon, _ = ned_to_geodetic(pos, *self.origin, flat_earth=self.flat_earth)
        if self.flat_earth:
            body_to_ned = body_to_local
        else:
            # Attitude is relative to the local vertical at the aircraft, not at the origin.
            body_to_ned = (
                ned_rotation_to(self.origin[0], self.origin[1], float(lat), float(lon)).T @ body_to_local
            )
        ant_to_ned = body_to_ned @ self._mount_rotation
        origin = pos + body_to_ned @ self._mount_position_m
        return AntennaGeometry(
            origin, ant_to_ned.T, np.asarray(platform.velocity_ned_mps, float), float(lat), float(lon)
        )

    # ---- one frame --------------------------------------------------------------------------
    def frame(
        self,
        platform: PlatformState,
        targets: Sequence[PointTarget] = (),
        frame_index: int = 0,
        out: np.ndarray | None = None,
    ) -> np.ndarray:
        """Simulate one frame; returns ``config.frame_shape`` complex64: (n_range, n_doppler, n_rx), or
        (n_range, n_doppler / n_tx, n_tx * n_rx) virtual channels for a time-division MIMO radar.

        ``out``, if given, is a C-contiguous complex64 array of that shape that receives the
        frame (and is returned): a caller filling a preallocated stack of frames skips a fresh
        2.7 MB allocation and its page faults per frame.
        """
        cfg = self.config
        geom = self.geometry(platform)
        view = self._terrain_view(geom, self._scratch)
        frame = self._output(out)
        sigma = np.sqrt(self.noise_per_pixel_w / 2.0) if self.noise else 0.0
        key = frame_key(self.seed, int(frame_index))
        speckle = speckle_key(key) if self.speckle else _NO_SPECKLE
        # With the point-spread, terrain lands on a grid of sub-bins spread into the frame after.
        psf = self._psf is not None and view is not None
        grid = _array(self._scratch, "grid", self._grid_shape, np.complex64) if psf else frame
        if view is None:
            finalize_frame(self._no_blocks(), sigma, key, frame)
        elif self._sparse_suits(view):
            sparse = self._sparse_buffers(view, self._scratch)
            self._accumulate_terrain(geom, view, self._no_blocks(), sparse, self._scratch, speckle)
            finalize_frame(self._no_blocks(), 0.0 if psf else sigma, key, grid)
            add_sparse(grid.reshape(-1, cfg.n_virtual), *sparse)
        else:
            blocks = self._accumulation_blocks()
            self._accumulate_terrain(geom, view, blocks, _NO_SPARSE, self._scratch, speckle)
            if psf:  # the spreading sums (and clears) the per-thread blocks itself
                grid = blocks
            else:
                finalize_frame(blocks, sigma, key, grid)
        if psf:
            self._spread(grid, frame, sigma, key)
        if targets:
            clear, reach = line_of_sight(view, geom, targets), None if self._psf is None else self._psf.reach
            factor = swerling1_power(self.seed, frame_index, len(targets)) if self.swerling else None
            add_targets(frame, cfg, geom, targets, self.coupling_s, clear, factor, reach)
        return frame

    def _spread(self, grid: np.ndarray, frame: np.ndarray, sigma: float, key: np.uint64) -> None:
        # The windows' point-spread, then the noise, white at its windowed power. ``grid``: the
        # oversampled grid, or the per-thread blocks (summed, and cleared for the next frame).
        block = _array(self._scratch, "spread", (1, *frame.shape), np.complex64)
        work = _array(self._scratch, "spread_work", (self._grid_shape[0] * frame[0].size,), np.complex64)
        assert self._psf is not None  # spread only with the point-spread
        apply_psf(grid, self._psf, block[0], work, clear=True)
        finalize_frame(block, sigma, key, frame)

    @property
    def _grid_shape(self) -> tuple[int, int, int]:
        # Accumulation grid: the frame's bins, or sub-bins with the point-spread.
        n = 1 if self._psf is None else self._psf.oversample
        n_range, n_doppler, n_channels = self.config.frame_shape
        return n * n_range, n * n_doppler, n_channels

    @property
    def noise_per_pixel_w(self) -> float:
        """Thermal noise power per pixel of the frames, W (times the windows' ENBW with ``psf``); a MIMO
        radar's pixel integrates one transmitter's chirps (``config.noise_power_w``)."""
        return self.config.noise_power_w * enbw(self._psf)

    def _output(self, out: np.ndarray | None) -> np.ndarray:
        shape = self.config.frame_shape
        if out is None:
            return np.empty(shape, np.complex64)
        if out.shape != shape or out.dtype != np.complex64 or not out.flags.c_contiguous:
            raise InputError(
                f"simulation: out must be a C-contiguous complex64 array of shape {shape}, "
                f"got {out.dtype} {out.shape}" + ("" if out.flags.c_contiguous else " (not contiguous)")
            )
        return out

    def terrain_view(self, geom: AntennaGeometry) -> TerrainView | None:
        """Terrain cropped around the antenna, with its horizon, for one frame (None: none in range)."""
        return self._terrain_view(geom, None)

    def _terrain_view(self, geom: AntennaGeometry, scratch: dict | None) -> TerrainView | None:
        # With ``scratch`` the points land in an array reused by the next frame: only for a
        # view that does not outlive the frame.
        p_ned = self._terrain_points(geom, scratch)
        if p_ned is None:
            return None
        if not needs_horizon(self._horizon_grid, p_ned, self._level, self.occlusion):
            return TerrainView(p_ned, np.full((1, 1), -np.inf, np.float32), 1.0, 1.0)
        grid = self._horizon_grid
        horizon = terrain_horizon(grid, p_ned, geom.rot_ned_to_ant, get_num_threads())
        return TerrainView(p_ned, horizon, grid.az_bin_rad, grid.h_bin_m)

    def _terrain_points(self, geom: AntennaGeometry, scratch: dict | None) -> np.ndarray | None:
        # The DEM cropped around the antenna, relative to it (NED, m); None: no terrain in range.
        if self.terrain is None:
            return None
        crop = self._crop(geom)
        if crop is None:
            return None
        rows, cols = crop
        p_ned = _array(scratch, "p_ned", (rows.stop - rows.start, cols.stop - cols.start, 3), np.float64)
        origin = np.asarray(geom.origin_ned_m, float)
        return relative_points(self._grid_ned, rows.start, rows.stop, cols.start, cols.stop, origin, p_ned)

    def terrain_cube(self, geom: AntennaGeometry, view: TerrainView | None = None) -> np.ndarray:
        """Terrain returns only, ``config.frame_shape`` complex64, without noise."""
        blocks = self._accumulation_blocks()
        view = view if view is not None else self.terrain_view(geom)
        if view is not None:
            self._accumulate_terrain(geom, view, blocks, _NO_SPARSE)
        out = np.empty(blocks.shape[1:], np.complex64)
        finalize_frame(blocks, 0.0, np.uint64(0), out)
        if self._psf is None:
            return out
        frame = np.empty(self.config.frame_shape, np.complex64)
        self._spread(out, frame, 0.0, np.uint64(0))
        return frame

    def _accumulation_blocks(self) -> np.ndarray:
        # One complex64 cube, kept between frames: the final pass reads and clears it. Shared by
        # the threads' range bands (_terrain_bands); one per thread for the scalar reference.
        shape = (get_num_threads() if self._kernel_mode != 1 else 1, *self._grid_shape)
        if self._blocks is None or self._blocks.shape != shape:
            self._blocks = np.zeros(shape, np.complex64)
        return self._blocks

    def _no_blocks(self) -> np.ndarray:
        return np.empty((0, *self._grid_shape), np.complex64)

    def _sparse_suits(self, view: TerrainView) -> bool:
        # Few facets (DEM spacing): a list of contributions beats clearing per-thread cubes.
        ny, nx = view.p_ned.shape[:2]
        n_range, n_doppler, _ = self.config.frame_shape
        return (ny - 1) * (nx - 1) * self._facets.per_cell_max <= n_range * n_doppler

    def _sparse_buffers(
        self, view: TerrainView, scratch: dict | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        n_blocks = get_num_threads()
        ny, nx = view.p_ned.shape[:2]
        cap = -(-(ny - 1) // n_blocks) * (nx - 1) * self._facets.per_cell_max
        return (
            _array(scratch, "sparse_idx", (n_blocks, cap), np.int64),
            _array(scratch, "sparse_val", (n_blocks, cap, self.config.n_virtual), np.complex64),
            np.zeros(n_blocks, np.int64),
        )

    def _accumulate_terrain(
        self,
        geom: AntennaGeometry,
        view: TerrainView,
        blocks: np.ndarray,
        sparse,
        scratch: dict | None = None,
        speckle: np.uint64 = _NO_SPECKLE,
    ) -> None:
        cfg = self.config
        n = 1 if self._psf is None else self._psf.oversample  # sub-bins per bin
        rot = geom.rot_ned_to_ant
        p_ant = rotate_points(view.p_ned, rot, _array(scratch, "p_ant", view.p_ned.shape, np.float64))
        power_const = cfg.pe_w * cfg.wavelength_m**2 / (4 * np.pi) ** 3 * self.ground_gain
        v_ground = rot @ (-geom.velocity_ned_mps)
        channels = cfg.terrain_channel_positions_m(v_ground)
        if self._kernel_mode == 1 and sparse[0].shape[1] == 0:  # dense: threads own range bands
            banded_returns(
                view.p_ned,
                p_ant,
                -rot[:, 2],
                cfg.transmitters_m[0],
                channels,
                v_ground,
                self._facets,
                cfg.wavelength_m,
                cfg.range_resolution_m / n,
                cfg.doppler_resolution_mps / n,
                self.coupling_s,
                power_const,
                self._gain2,
                self._gain2_step,
                self._refl_table,
                view,
                self.occlusion,
                blocks,
                speckle,
            )
            return
        terrain_returns(
            view.p_ned,
            p_ant,
            -rot[:, 2],
            cfg.transmitters_m[0],
            channels,
            v_ground,
            self._facets.counts,
            self._facets.adapt,
            cfg.wavelength_m,
            cfg.range_resolution_m / n,
            cfg.doppler_resolution_mps / n,
            self.coupling_s,
            power_const,
            self._gain2,
            self._gain2_step,
            self._refl_table,
            view.horizon,
            view.az_bin_rad,
            view.h_bin_m,
            self.occlusion,
            blocks.shape[0] or sparse[0].shape[0],
            blocks,
            sparse,
            self._kernel_mode,
            speckle,
        )

    def _crop(self, geom: AntennaGeometry) -> tuple[slice, slice] | None:
        # Crop around the platform; the mount offset (metres) is added to the reach.
        reach = self.config.range_limit_m + 2 * self._facet_m + float(np.linalg.norm(self._mount_position_m))
        rows, cols = self.terrain.crop_window(geom.lat_deg, geom.lon_deg, reach)
        if rows.stop - rows.start < 2 or cols.stop - cols.start < 2:
            return None
        return rows, cols

    # ---- truth ------------------------------------------------------------------------------
    def target_truth(self, platform: PlatformState, targets: Sequence[PointTarget]) -> dict[str, np.ndarray]:
        """Range, radial velocity, antenna-frame angles, expected SNR and visibility per target."""
        geom = self.geometry(platform)
        return target_geometry(
            self.config, geom, targets, self.coupling_s, self._clear(geom, targets), self.noise_per_pixel_w
        )

    def _clear(self, geom: AntennaGeometry, targets: Sequence[PointTarget]) -> np.ndarray:
        # The frame's line-of-sight test (line_of_sight on the terrain view) from the horizon's
        # entries at the targets only: a frame's truth without its whole horizon map.
        p_ned = self._terrain_points(geom, self._scratch)
        if p_ned is None or not needs_horizon(self._horizon_grid, p_ned, self._level, self.occlusion):
            return np.ones(len(targets), bool)
        rel = np.array([t.position_ned_m for t in targets], float).reshape(-1, 3) - geom.origin_ned_m
        return target_clear(self._horizon_grid, p_ned, geom.rot_ned_to_ant, rel)


def _array(scratch: dict | None, name: str, shape: tuple[int, ...], dtype) -> np.ndarray:
    """An uninitialised array, kept in ``scratch`` and reused while the shape stays (None: fresh)."""
    if scratch is None:
        return np.empty(shape, dtype)
    array = scratch.get(name)
    if array is None or array.shape != tuple(shape) or array.dtype != dtype:
        array = scratch[name] = np.empty(shape, dtype)
    return array


_NO_SPARSE = (np.empty((1, 0), np.int64), np.empty((1, 0, 1), np.complex64), np.zeros(1, np.int64))
