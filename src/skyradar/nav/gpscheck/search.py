"""Continuous search for the pose offset that best aligns a radar ground image with the map.

The thesis' named next step (Maas 2022, ch. 6): instead of scoring a pool of 300 poses, estimate the
offset ``(d_north, d_east, d_heading)`` from the GPS pose to the pose where radar and map agree best.

For each candidate heading the map is sampled once on a body grid enlarged by the search margin, and
the normalised cross-correlation (NCC) of the radar image with every shift of it is computed at once by
FFT (masked NCC: the radar footprint is the mask; the map's mean and energy under the footprint come from
two more correlations). Coarse headings first, then a finer step around the best, a parabola through the
peak for sub-pixel shifts and sub-step heading. The confidence is the peak-to-sidelobe ratio (PSR):
the peak's height above the surface's mean, in standard deviations of the surface away from the peak.

A shift of the body grid by ``(df, dr)`` (forward, right) at heading ``psi`` is the world offset
``d_north = df cos psi - dr sin psi``, ``d_east = df sin psi + dr cos psi``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import fft

from skyradar.errors import InputError
from skyradar.nav.gpscheck.compare import crop_to_mask
from skyradar.scene.ground_grid import GroundGrid, PoseGrid, sample_at_poses

__all__ = ["PoseOffset", "ncc_surface", "search_offset", "similarity_surface", "fuse_offsets"]


@dataclass(frozen=True)
class PoseOffset:
    """The estimated correction to the GPS pose and how sure the search is of it.

    Attributes
    ----------
    d_north_m, d_east_m : float
        Correction to add to the GPS position, m.
    d_heading_deg : float
        Correction to add to the GPS heading, deg.
    peak_ncc : float
        Normalised cross-correlation at the best alignment.
    gps_ncc : float
        Normalised cross-correlation at the GPS pose.
    psr : float
        Peak-to-sidelobe ratio of the search: its confidence.

    Examples
    --------
    >>> PoseOffset(3.0, -4.0, 0.5, 0.8, 0.3, 7.0).distance_m
    5.0
    """

    d_north_m: float
    d_east_m: float
    d_heading_deg: float
    peak_ncc: float
    gps_ncc: float
    psr: float

    @property
    def distance_m(self) -> float:
        """Horizontal length of the correction."""
        return float(np.hypot(self.d_north_m, self.d_east_m))


def _template(radar: np.ndarray, mask: np.ndarray) -> tuple[np.ndarray, float]:
    """Radar pixels zero-mean and unit-norm inside the mask, 0 outside; and the mask's pixel count."""
    t = np.where(mask, np.nan_to_num(radar), 0.0).astype(np.float64)
    n = float(mask.sum())
    t[mask] -= t[mask].mean()
    norm = np.sqrt((t**2).sum())
    return (t / norm if norm > 0 else t), n


def ncc_surface(
    template_fft: np.ndarray, mask_fft: np.ndarray, n_mask: float, patch: np.ndarray, shifts: tuple[int, int]
) -> np.ndarray:
    """Masked NCC of a template with every shift ``(0..shifts[0]-1, 0..shifts[1]-1)`` of a larger patch.

    ``template_fft`` and ``mask_fft`` are ``rfft2`` of the zero-padded template and mask at the FFT
    shape of ``patch``; entry ``[a, b]`` compares the template with ``patch[a:a+h, b:b+w]``.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> patch = rng.random((40, 30))
    >>> t, n = _template(patch[5:25, 7:17], np.ones((20, 10), bool))
    >>> tf = fft.rfft2(t, s=patch.shape)
    >>> mf = fft.rfft2(np.ones((20, 10)), s=patch.shape)
    >>> surface = ncc_surface(tf, mf, n, patch, (21, 21))
    >>> np.unravel_index(surface.argmax(), surface.shape), round(float(surface.max()), 6)
    ((np.int64(5), np.int64(7)), 1.0)
    """
    shape = patch.shape
    pf = fft.rfft2(patch, s=shape, workers=-1)
    p2f = fft.rfft2(patch * patch, s=shape, workers=-1)
    num = fft.irfft2(pf * np.conj(template_fft), s=shape, workers=-1)[: shifts[0], : shifts[1]]
    s1 = fft.irfft2(pf * np.conj(mask_fft), s=shape, workers=-1)[: shifts[0], : shifts[1]]
    s2 = fft.irfft2(p2f * np.conj(mask_fft), s=shape, workers=-1)[: shifts[0], : shifts[1]]
    var = np.maximum(s2 - s1 * s1 / n_mask, 0.0)
    floor = 1e-9 * max(float(var.max()), 1e-30)
    return np.where(var > floor, num / np.sqrt(np.maximum(var, floor)), 0.0)


def _parabola(m1: float, m0: float, p1: float) -> float:
    """Vertex offset (-0.5..0.5) of the parabola through three equally spaced samples."""
    den = m1 - 2 * m0 + p1
    return float(np.clip(0.5 * (m1 - p1) / den, -0.5, 0.5)) if den < 0 else 0.0


def _subpixel(surface: np.ndarray, a: int, b: int) -> tuple[float, float]:
    """Sub-pixel peak offsets along rows and columns (0 at the surface's edge)."""
    rows, cols = surface.shape
    da = _parabola(surface[a - 1, b], surface[a, b], surface[a + 1, b]) if 0 < a < rows - 1 else 0.0
    db = _parabola(surface[a, b - 1], surface[a, b], surface[a, b + 1]) if 0 < b < cols - 1 else 0.0
    return da, db


def _psr(surface: np.ndarray, peak: tuple[int, int], exclude_px: int) -> float:
    """Peak-to-sidelobe ratio: (peak - mean) / SD of the surface outside ``exclude_px`` of the peak."""
    rows, cols = np.ogrid[: surface.shape[0], : surface.shape[1]]
    side = (np.abs(rows - peak[0]) > exclude_px) | (np.abs(cols - peak[1]) > exclude_px)
    lobe = surface[side]
    sd = lobe.std() if lobe.size > 1 else 0.0
    return float((surface[peak] - lobe.mean()) / sd) if sd > 0 else 0.0


class _Searcher:
    """The FFTs of one radar frame, reused for every heading tried."""

    def __init__(self, radar, mask, map_world, grid, pose_grid, gps_pose, margin_m, map_pose_grid=None):
        self.map_world, self.grid, self.gps = map_world, grid, np.asarray(gps_pose, float)
        self.pix = pose_grid.pixel_m
        self.m = int(np.ceil(margin_m / self.pix))
        where = pose_grid if map_pose_grid is None else map_pose_grid
        radar, mask, where = crop_to_mask(radar, mask, where)
        h, w = where.shape
        self.big = PoseGrid(
            where.forward0_m - self.m * self.pix,
            where.right0_m - self.m * self.pix,
            self.pix,
            (h + 2 * self.m, w + 2 * self.m),
        )
        self.fft_shape = (fft.next_fast_len(h + 2 * self.m), fft.next_fast_len(w + 2 * self.m, real=True))
        t, self.n = _template(radar, mask)
        self.tf = fft.rfft2(t, s=self.fft_shape, workers=-1)
        self.mf = fft.rfft2(mask.astype(np.float64), s=self.fft_shape, workers=-1)
        self.shifts = (2 * self.m + 1, 2 * self.m + 1)

    def surfaces(self, d_heading_rad: np.ndarray) -> list[np.ndarray]:
        poses = np.column_stack([np.full((len(d_heading_rad), 2), self.gps[:2]), self.gps[2] + d_heading_rad])
        patches = sample_at_poses(self.map_world, self.grid, self.big, poses, fill=0.0).astype(np.float64)
        out = []
        for patch in patches:
            padded = np.zeros(self.fft_shape)
            padded[: patch.shape[0], : patch.shape[1]] = patch
            out.append(ncc_surface(self.tf, self.mf, self.n, padded, self.shifts))
        return out


def _fine(s: _Searcher, centre_rad: float, coarse_step_deg: float, fine_step_deg: float):
    """Headings around the best coarse one: (headings, best surface, peak per heading, best index)."""
    fine = centre_rad + np.radians(np.arange(-coarse_step_deg, coarse_step_deg + 1e-9, fine_step_deg))
    f_surf = s.surfaces(fine)
    peaks = np.array([sf.max() for sf in f_surf])
    k = int(np.argmax(peaks))
    return fine, f_surf[k], peaks, k


def search_offset(
    radar: np.ndarray,
    radar_mask: np.ndarray,
    map_world: np.ndarray,
    grid: GroundGrid,
    pose_grid: PoseGrid,
    gps_pose: np.ndarray,
    *,
    margin_m: float = 250.0,
    max_heading_deg: float = 15.0,
    coarse_step_deg: float = 1.5,
    fine_step_deg: float = 0.25,
    map_pose_grid: PoseGrid | None = None,
) -> PoseOffset:
    """Coarse-to-fine search for the offset from ``gps_pose`` that best aligns radar and map.

    Parameters
    ----------
    radar, radar_mask, map_world : pre-processed radar and its footprint on ``pose_grid``; map on ``grid``.
    gps_pose : (3,) array
        ``(north_m, east_m, heading_rad)`` reported by GPS.
    margin_m, max_heading_deg : float
        Search extent: shifts up to ``margin_m`` each way, headings within ``+-max_heading_deg``.
    map_pose_grid : PoseGrid, optional; where the map is sampled (default ``pose_grid``).

    Examples
    --------
    >>> grid = GroundGrid(0.0, 0.0, 4.0, (300, 300))
    >>> world = np.random.default_rng(0).random(grid.shape)
    >>> body = PoseGrid.side_looking(range_m=200.0, pixel_m=4.0)
    >>> truth = np.array([600.0, 600.0, 0.5])
    >>> radar = sample_at_poses(world, grid, body, truth)
    >>> gps = truth + np.array([30.0, -20.0, np.radians(4.0)])
    >>> off = search_offset(radar, np.ones(body.shape, bool), world, grid, body, gps, margin_m=60.0)
    >>> round(off.d_north_m), round(off.d_east_m), round(off.d_heading_deg)
    (-30, 20, -4)
    """
    if (np.asarray(radar_mask, bool) & np.isfinite(radar)).sum() < 16:
        raise InputError("search_offset: the radar footprint has fewer than 16 valid pixels")
    s = _Searcher(
        radar, radar_mask & np.isfinite(radar), map_world, grid, pose_grid, gps_pose, margin_m, map_pose_grid
    )
    coarse = np.radians(np.arange(-max_heading_deg, max_heading_deg + 1e-9, coarse_step_deg))
    c_surf = s.surfaces(coarse)
    fine, surface, peaks, k = _fine(
        s, coarse[int(np.argmax([sf.max() for sf in c_surf]))], coarse_step_deg, fine_step_deg
    )
    a, b = (int(v) for v in np.unravel_index(int(np.argmax(surface)), surface.shape))
    da, db = _subpixel(surface, a, b)
    dk = _parabola(peaks[k - 1], peaks[k], peaks[k + 1]) if 0 < k < len(peaks) - 1 else 0.0
    d_heading = fine[k] + dk * np.radians(fine_step_deg)
    psi = s.gps[2] + d_heading
    df, dr = (a + da - s.m) * s.pix, (b + db - s.m) * s.pix
    zero = c_surf[int(np.argmin(np.abs(coarse)))][s.m, s.m]
    return PoseOffset(
        d_north_m=float(df * np.cos(psi) - dr * np.sin(psi)),
        d_east_m=float(df * np.sin(psi) + dr * np.cos(psi)),
        d_heading_deg=float(np.degrees(d_heading)),
        peak_ncc=float(surface[a, b]),
        gps_ncc=float(zero),
        psr=_psr(surface, (a, b), max(2, int(round(10.0 / s.pix)))),
    )


def similarity_surface(
    radar: np.ndarray,
    radar_mask: np.ndarray,
    map_world: np.ndarray,
    grid: GroundGrid,
    pose_grid: PoseGrid,
    pose: np.ndarray,
    margin_m: float = 150.0,
    map_pose_grid: PoseGrid | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """NCC over body shifts at the pose's heading, and the shift axis in metres (forward = rows).

    Parameters
    ----------
    radar, radar_mask : 2-D arrays on ``pose_grid``
        The pre-processed radar image and its footprint.
    map_world : 2-D array on ``grid``
        The pre-processed map.
    grid : GroundGrid
    pose_grid : PoseGrid
    pose : (3,) array
        ``(north_m, east_m, heading_rad)``.
    margin_m : float
        Shifts up to this far each way, m.
    map_pose_grid : PoseGrid, optional
        Where the map is sampled (default ``pose_grid``).

    Returns
    -------
    surface : ndarray, shape (n, n)
        Entry ``[a, b]`` scores the pose moved by ``axis[a]`` forward and ``axis[b]`` right.
    axis : ndarray, shape (n,)
        Shifts, m, in steps of the pixel size.

    Examples
    --------
    Heading north, the pose 6 m north of the truth: the best shift is 6 m back, none sideways.

    >>> grid = GroundGrid(0.0, 0.0, 2.0, (200, 200))
    >>> world = np.random.default_rng(0).random(grid.shape)
    >>> body = PoseGrid.side_looking(range_m=60.0, pixel_m=2.0)
    >>> truth = np.array([200.0, 200.0, 0.0])
    >>> radar = sample_at_poses(world, grid, body, truth)
    >>> surface, axis = similarity_surface(radar, np.ones(body.shape, bool), world, grid, body,
    ...                                    truth + [6.0, 0.0, 0.0], margin_m=20.0)
    >>> a, b = np.unravel_index(surface.argmax(), surface.shape)
    >>> surface.shape, float(axis[a]), float(axis[b]), round(float(surface.max()), 6)
    ((21, 21), -6.0, 0.0, 1.0)
    """
    radar_mask = np.asarray(radar_mask, bool) & np.isfinite(radar)
    s = _Searcher(radar, radar_mask, map_world, grid, pose_grid, pose, margin_m, map_pose_grid)
    return s.surfaces(np.zeros(1))[0], (np.arange(s.shifts[0]) - s.m) * s.pix


def fuse_offsets(offsets: list[PoseOffset], min_psr: float = 0.0) -> PoseOffset | None:
    """Evidence over consecutive frames: the PSR-weighted median correction of the confident ones.

    A spoofed GPS is off by the same world offset frame after frame while a wrong match lands anywhere,
    so a weighted median keeps the first and rejects the second. ``None`` when no frame qualifies.

    Examples
    --------
    >>> offs = [PoseOffset(50.0, 0.0, 0.0, 0.5, 0.1, 8.0)] * 3 + [PoseOffset(-90.0, 40.0, 9.0, 0.2, 0.1, 3.0)]
    >>> fused = fuse_offsets(offs)
    >>> fused.d_north_m, fused.d_east_m, fused.psr
    (50.0, 0.0, 27.0)
    """
    kept = [o for o in offsets if np.isfinite(o.psr) and o.psr >= min_psr]
    if not kept:
        return None
    weight = np.array([o.psr for o in kept])

    def wmedian(values: list[float]) -> float:
        order = np.argsort(values)
        cum = np.cumsum(weight[order])
        return float(np.asarray(values)[order][np.searchsorted(cum, cum[-1] / 2)])

    return PoseOffset(
        d_north_m=wmedian([o.d_north_m for o in kept]),
        d_east_m=wmedian([o.d_east_m for o in kept]),
        d_heading_deg=wmedian([o.d_heading_deg for o in kept]),
        peak_ncc=float(np.average([o.peak_ncc for o in kept], weights=weight)),
        gps_ncc=float(np.average([o.gps_ncc for o in kept], weights=weight)),
        psr=float(weight.sum()),
    )
