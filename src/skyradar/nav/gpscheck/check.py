"""The GPS check of a run: per frame, radar ground image against the map at the GPS pose.

Glue between the frames store, the map and the per-frame steps: :func:`radar_side` refuses a radar that
does not look sideways, :func:`prepare_map` renders and pre-processes the reference map once (the
pre-processing is rotation invariant, so the world map is processed once and sampled at any pose),
:func:`check_frame` projects one frame, scores the GPS pose with SSIM, searches for the correction
and gives the verdict, and :func:`check_run` does it for the frames of a run, with the alert.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from skimage.transform import downscale_local_mean

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.io.frames_model import frame_times_s
from skyradar.nav.gpscheck.compare import ssim_scores
from skyradar.nav.gpscheck.monitor import (
    DEFAULT_SETTINGS,
    VERDICTS,
    WING_UP,
    MonitorSettings,
    alerts,
    frame_verdict,
    inconsistency,
)
from skyradar.nav.gpscheck.preprocess import PreprocessOptions, preprocess
from skyradar.nav.gpscheck.projection import frame_power, ground_image, ground_in_view_fraction
from skyradar.nav.gpscheck.search import PoseOffset, search_offset
from skyradar.scene.ground_grid import GroundGrid, PoseGrid, sample_at_pose

__all__ = [
    "PIXEL_M",
    "DEFAULT_METHOD",
    "MAP_OPTIONS",
    "RADAR_OPTIONS",
    "radar_side",
    "pose_grid_for",
    "render_map",
    "prepare_map",
    "building_height_m",
    "correct_layover",
    "check_coverage",
    "FrameCheck",
    "check_frame",
    "check_run",
    "GPSCHECK_COLUMNS",
]

PIXEL_M = 4.0  # about the ch6 radar's 3 m range resolution; 4 m keeps one frame's search under 0.5 s
DEFAULT_METHOD = "clahe_ridge"
# The map draws roads light and buildings dark; the radar sees them the other way round: invert the map.
# Speckle is the radar's alone: a 3 x 3 median on the radar image.
MAP_OPTIONS: PreprocessOptions = {"invert": True}
RADAR_OPTIONS: PreprocessOptions = {"log_power": True, "despeckle_px": 3}


def radar_side(config: RadarConfig, source: str = "run") -> str:
    """``"right"`` or ``"left"``: the side a wingtip radar looks at; one-line error for any other mount.

    Examples
    --------
    >>> from skyradar.config import Mount
    >>> radar_side(RadarConfig(mount=Mount.preset("side-left")))
    'left'
    """
    yaw = (config.mount.yaw_deg + 180.0) % 360.0 - 180.0
    if not 45.0 <= abs(yaw) <= 135.0:
        raise InputError(
            f"{source}: radar mount yaw {config.mount.yaw_deg:g} deg looks forward or backward;"
            " the GPS check needs a side-looking wingtip mount (side-right or side-left, yaw +-90 deg)"
        )
    return "right" if yaw > 0 else "left"


def pose_grid_for(config: RadarConfig, pixel_m: float = PIXEL_M, source: str = "run") -> PoseGrid:
    """The body-aligned ground grid of the radar's side, out to its processed range.

    Parameters
    ----------
    config : RadarConfig
        A side-looking radar (:func:`radar_side`); its ``range_limit_m`` (m) sets the extent.
    pixel_m : float
        Pixel size, m.
    source : str
        Names the run in errors.

    Returns
    -------
    PoseGrid
        Forward ``-range..range``, sideways ``0..range`` on the radar's side.

    Examples
    --------
    >>> from skyradar.config import Mount
    >>> cfg = RadarConfig.prototype_2022(mount=Mount.preset("side-left"), range_limit_m=500.0)
    >>> body = pose_grid_for(cfg)
    >>> body.shape, float(body.forward_m[0]), float(body.right_m[0]), float(body.right_m[-1])
    ((250, 125), -498.0, -498.0, -2.0)
    """
    return PoseGrid.side_looking(config.range_limit_m, pixel_m, radar_side(config, source))


def building_height_m(layers) -> float:
    """The map's representative building height: the footprint-area-weighted mean (0 without buildings).

    Large buildings dominate what a radar sees, hence the area weights.

    Parameters
    ----------
    layers : MapLayers
        Its ``buildings`` GeoDataFrame has ``height_m`` (m) and polygon footprints (m^2 by ``.area``).

    Returns
    -------
    float
        Height, m.

    Examples
    --------
    A 300 m^2 building 10 m high and a 100 m^2 one 30 m high: (300 * 10 + 100 * 30) / 400 = 15 m.

    >>> import geopandas as gpd
    >>> from shapely.geometry import box
    >>> from skyradar.scene.map_render import MapLayers
    >>> empty = gpd.GeoDataFrame(geometry=[])
    >>> footprints = [box(0, 0, 30, 10), box(0, 20, 10, 30)]
    >>> houses = gpd.GeoDataFrame({"height_m": [10.0, 30.0]}, geometry=footprints)
    >>> layers = MapLayers(houses, empty, empty, empty, empty, empty, empty, 60.0, 25.0)
    >>> round(building_height_m(layers), 6)
    15.0
    """
    buildings = layers.buildings
    if not len(buildings):
        return 0.0
    return float(np.average(buildings["height_m"].to_numpy(float), weights=buildings.area.to_numpy() + 1e-9))


def correct_layover(
    image: np.ndarray, pose_grid: PoseGrid, height_agl_m: float, building_m: float
) -> np.ndarray:
    """The radar ground image with roofs ``building_m`` high moved back to where they stand.

    A roof ``h`` high at ground range ``x`` is at slant range ``sqrt(x^2 + (H - h)^2)``, which the flat
    ground projection puts at ``x' = sqrt(x^2 - 2 H h + h^2)``: buildings appear closer to the track
    (layover), by about ``H h / x``, most at near range and in a turn with the radar wing down. Each
    column (ground range ``x``) takes the image at ``x'`` (linear interpolation); NaN where ``x'`` does
    not exist. Ground features (roads) move out by the same amount: the map's typical building height
    is the compromise, as buildings dominate what the radar shows.

    Examples
    --------
    >>> body = PoseGrid(0.0, 2.0, 4.0, (2, 100))  # right 2..398 m
    >>> image = np.zeros((2, 100)); image[:, 49] = 1.0  # a roof shown at 198 m
    >>> moved = correct_layover(image, body, 200.0, 10.0)
    >>> float(body.right_m[np.nanargmax(moved[0])])  # stands at sqrt(198^2 + 2*200*10 - 100) = 207.7 m
    206.0
    """
    if building_m <= 0:
        return image
    right = pose_grid.right_m
    inside = right**2 - 2 * height_agl_m * building_m + building_m**2
    source = np.sqrt(np.maximum(inside, 0.0)) * np.sign(right)
    col = (source - pose_grid.right0_m) / pose_grid.pixel_m
    c0 = np.clip(np.floor(col).astype(int), 0, image.shape[1] - 2)
    frac = col - c0
    out = image[:, c0] * (1.0 - frac) + image[:, c0 + 1] * frac
    out[:, (inside < 0) | (col < 0) | (col > image.shape[1] - 1)] = np.nan
    return out.astype(np.float32)


def render_map(layers, grid: GroundGrid) -> np.ndarray:
    """The reference map on ``grid``, drawn at half the pixel size and averaged (no lost thin roads).

    Parameters
    ----------
    layers : MapLayers
        The map (needs the ``geo`` extra).
    grid : GroundGrid
        Where to draw it; pixel size in m.

    Returns
    -------
    ndarray of float32, shape ``grid.shape``
        Grey levels 0..1: roads light, buildings dark.

    Examples
    --------
    A primary road along east at north 0 on a 2 m grid:

    >>> import geopandas as gpd
    >>> from shapely.geometry import LineString
    >>> from skyradar.scene.map_render import MapLayers
    >>> empty = gpd.GeoDataFrame(geometry=[])
    >>> road = gpd.GeoDataFrame({"road_class": ["primary"], "width_m": [12.0]},
    ...                         geometry=[LineString([(-50, 0), (50, 0)])])
    >>> layers = MapLayers(gpd.GeoDataFrame({"height_m": []}, geometry=[]), road, empty, empty, empty,
    ...                    empty, empty, 60.0, 25.0)
    >>> grid = GroundGrid.from_extent(-20.0, 20.0, -20.0, 20.0, pixel_m=2.0)
    >>> image = render_map(layers, grid)
    >>> image.shape, image.dtype, [round(float(v), 2) for v in image[[10, 0], 10]]  # road, background
    ((20, 20), dtype('float32'), [1.0, 0.93])
    """
    from skyradar.scene.map_render import render_reference_map  # geo extra: imported when used

    half = GroundGrid(
        grid.north0_m - grid.pixel_m / 4,
        grid.east0_m - grid.pixel_m / 4,
        grid.pixel_m / 2,
        (2 * grid.shape[0], 2 * grid.shape[1]),
    )
    return downscale_local_mean(render_reference_map(layers, half), (2, 2)).astype(np.float32)


def prepare_map(map_image: np.ndarray, methods: Sequence[str]) -> dict[str, np.ndarray]:
    """The map pre-processed by each method (NaN, no data, is masked).

    Parameters
    ----------
    map_image : 2-D array
        The rendered or raster map (:func:`render_map`); NaN where it has no data.
    methods : sequence of str
        Methods of :data:`skyradar.nav.gpscheck.preprocess.METHODS`.

    Returns
    -------
    dict of str to ndarray
        Per method a float32 image in 0..1 (the map inverted, :data:`MAP_OPTIONS`), 0 where the map
        has no data.

    Examples
    --------
    >>> world = np.random.default_rng(0).random((50, 60))
    >>> world[:5] = np.nan
    >>> out = prepare_map(world, ["gamma"])
    >>> gamma = out["gamma"]
    >>> list(out), gamma.shape, gamma.dtype, float(gamma[:5].max()), float(gamma.max())
    (['gamma'], (50, 60), dtype('float32'), 0.0, 1.0)
    """
    valid = np.isfinite(map_image)
    return {method: preprocess(map_image, method, valid, **MAP_OPTIONS) for method in methods}


@dataclass(frozen=True)
class FrameCheck:
    """One frame's GPS check.

    Attributes
    ----------
    ground_fraction : float
        Share of the beam's two-way energy on the ground within range, 0..1.
    gps_ssim : float
        SSIM of the radar ground image and the map at the GPS pose (NaN when not searched).
    offset : PoseOffset or None
        The correction the search found; None on a wing-up frame (not searched).
    verdict : str
        One of :data:`skyradar.nav.gpscheck.monitor.VERDICTS`.

    Examples
    --------
    >>> body = PoseGrid.side_looking(range_m=40.0, pixel_m=4.0)
    >>> check_frame(np.ones(body.shape), 0.2, np.zeros(3), None, None, body)
    FrameCheck(ground_fraction=0.2, gps_ssim=nan, offset=None, verdict='no decision: wing up')
    """

    ground_fraction: float
    gps_ssim: float
    offset: PoseOffset | None
    verdict: str


def check_frame(
    radar_image: np.ndarray,
    ground_fraction: float,
    gps_pose: np.ndarray,
    map_processed: np.ndarray,
    grid: GroundGrid,
    pose_grid: PoseGrid,
    method: str = DEFAULT_METHOD,
    settings: MonitorSettings = DEFAULT_SETTINGS,
    height_agl_m: float = 0.0,
    building_m: float = 0.0,
    **search_options,
) -> FrameCheck:
    """Score the GPS pose (SSIM), search for the correction and give the verdict for one frame.

    Parameters
    ----------
    radar_image : 2-D array
        The frame's ground image on ``pose_grid``: linear power, W, NaN where unseen.
    ground_fraction : float
        Share of the beam on the ground, 0..1; below ``settings.min_ground_fraction`` the frame is
        wing up and not searched.
    gps_pose : (3,) array
        ``(north_m, east_m, heading_rad)`` the GPS reports.
    map_processed : 2-D array
        The map on ``grid``, pre-processed with ``method`` (:func:`prepare_map`).
    grid : GroundGrid
    pose_grid : PoseGrid
    method : str
        Pre-processing method for the radar image, the one the map is processed with.
    settings : MonitorSettings
    height_agl_m, building_m : float
        Height above ground and the map's building height, m: the layover correction
        (:func:`correct_layover`).
    **search_options
        Passed to :func:`skyradar.nav.gpscheck.search.search_offset` (``margin_m``, ...).

    Returns
    -------
    FrameCheck

    Examples
    --------
    A map of dark blocks (buildings) on light ground; the radar sees the buildings bright (30 dB
    above the ground). A GPS pose 20 m north and 12 m west of the true one is corrected and found
    inconsistent; the true pose is consistent.

    >>> blocks = np.random.default_rng(0).random((40, 40)) < 0.3
    >>> world = np.where(np.kron(blocks, np.ones((6, 6))), 0.2, 0.9)
    >>> grid, body = GroundGrid(0.0, 0.0, 4.0, world.shape), PoseGrid.side_looking(160.0, 4.0)
    >>> truth = np.array([480.0, 400.0, 0.3])
    >>> radar = 10.0 ** (3.0 * (1.0 - sample_at_pose(world, grid, body, *truth)))
    >>> mapped = prepare_map(world, ["gamma"])["gamma"]
    >>> options = {"method": "gamma", "margin_m": 40.0, "max_heading_deg": 3.0}
    >>> wrong = check_frame(radar, 0.9, truth + [20.0, -12.0, 0.0], mapped, grid, body, **options)
    >>> wrong.verdict, round(wrong.offset.d_north_m), round(wrong.offset.d_east_m)
    ('inconsistent', -20, 12)
    >>> right = check_frame(radar, 0.9, truth, mapped, grid, body, **options)
    >>> right.verdict, round(right.offset.distance_m), right.gps_ssim > 0.9
    ('consistent', 0, True)
    """
    radar_image = correct_layover(radar_image, pose_grid, height_agl_m, building_m)
    mask = np.isfinite(radar_image)
    if ground_fraction < settings.min_ground_fraction or mask.sum() < 64:
        return FrameCheck(float(ground_fraction), float("nan"), None, WING_UP)
    radar = preprocess(radar_image, method, mask, **RADAR_OPTIONS)
    north_m, east_m, heading_rad = gps_pose
    at_gps = sample_at_pose(map_processed, grid, pose_grid, north_m, east_m, heading_rad, fill=0.0)
    score = ssim_scores(radar, at_gps, mask)
    offset = search_offset(radar, mask, map_processed, grid, pose_grid, gps_pose, **search_options)
    return FrameCheck(
        float(ground_fraction), float(score), offset, frame_verdict(ground_fraction, offset, settings)
    )


def _state(ds, i: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """GPS pose (north, east, heading), attitude, velocity and height above ground of frame ``i``."""
    get = lambda name: float(ds[name].isel(time=i).values)  # noqa: E731
    attitude = np.array([get("own_yaw_rad"), get("own_pitch_rad"), get("own_roll_rad")])
    velocity = np.array([get("own_vn_mps"), get("own_ve_mps"), get("own_vd_mps")])
    height = get("own_height_agl_m") if "own_height_agl_m" in ds else -get("own_down_m")
    return np.array([get("own_north_m"), get("own_east_m"), attitude[0]]), attitude, velocity, height


_NO_SEARCH = "NaN on a wing-up frame (no search)"
# The GPS check table (``skyradar gpscheck``), column -> "unit; meaning" (skyradar.io.table_columns).
GPSCHECK_COLUMNS: dict[str, str] = {
    "frame": "-; frame number in the run, from 0",
    "time_s": "s; elapsed time of the frame since the run's start_time",
    "gps_north_m": "m; the GPS position checked, north in the scenario NED frame (with --gps-offset-north-m)",
    "gps_east_m": "m; the GPS position checked, east in the scenario NED frame (with --gps-offset-east-m)",
    "gps_heading_deg": "deg; the GPS heading checked, clockwise from north (with --gps-offset-heading-deg)",
    "ground_fraction": "-; share of the beam's two-way energy on the ground within range (0..1)",
    "gps_ssim": "-; structural similarity of the radar ground image and the map at the GPS pose (NaN: "
    "wing up)",
    "gps_ncc": f"-; normalised cross-correlation of radar and map at the GPS pose; {_NO_SEARCH}",
    "peak_ncc": f"-; normalised cross-correlation at the best alignment; {_NO_SEARCH}",
    "psr": f"-; peak-to-sidelobe ratio of the alignment search, its confidence; {_NO_SEARCH}",
    "d_north_m": f"m; correction north that best aligns radar and map; {_NO_SEARCH}",
    "d_east_m": f"m; correction east that best aligns radar and map; {_NO_SEARCH}",
    "d_heading_deg": f"deg; heading correction that best aligns radar and map; {_NO_SEARCH}",
    "correction_m": f"m; horizontal length of the correction; {_NO_SEARCH}",
    "inconsistency": f"-; how far the correction is outside the tolerances (> 1: inconsistent); {_NO_SEARCH}",
    "verdict": "-; the frame's verdict: " + ", ".join(VERDICTS),
    "alert": "-; True: the last --alert-frames decided frames were all inconsistent",
}


def _row(frame: int, time_s: float, gps: np.ndarray, result: FrameCheck, settings) -> dict:
    off, nan = result.offset, float("nan")
    row: dict[str, Any] = {
        "frame": frame,
        "time_s": time_s,
        "gps_north_m": float(gps[0]),
        "gps_east_m": float(gps[1]),
        "gps_heading_deg": float(np.degrees(gps[2])),
        "ground_fraction": result.ground_fraction,
        "gps_ssim": result.gps_ssim,
    }
    for name in ("gps_ncc", "peak_ncc", "psr", "d_north_m", "d_east_m", "d_heading_deg"):
        row[name] = getattr(off, name) if off else nan
    row["correction_m"] = off.distance_m if off else nan
    row["inconsistency"] = inconsistency(off, settings) if off else nan
    row["verdict"] = result.verdict
    return row


def _check_state(ds, source: str) -> None:
    needed = ("own_north_m", "own_east_m", "own_yaw_rad", "own_pitch_rad", "own_roll_rad", "own_vn_mps")
    missing = [name for name in needed if name not in ds]
    if missing:
        raise InputError(f"{source}: the run has no own-ship state ({', '.join(missing)}) for the GPS pose")


def check_coverage(
    ds,
    config: RadarConfig,
    map_extent,
    *,
    frames: Sequence[int] | None = None,
    gps_offset: Sequence[float] = (0.0, 0.0, 0.0),
    pixel_m: float = PIXEL_M,
    source: str = "run",
    map_source: str | None = None,
    min_ground_fraction: float = DEFAULT_SETTINGS.min_ground_fraction,
    map_image: np.ndarray | None = None,
    min_data_fraction: float = 0.9,
) -> None:
    """One-line error naming the map when a frame's ground footprint at the GPS pose is off the map.

    The footprint is geometric (where the beam meets the ground within range), so no frame is read.
    A map with data elsewhere but none under the flight would otherwise give every frame "no
    decision: too little structure", which reads like a verdict on the radar image, not on the map.

    Parameters
    ----------
    ds : xarray.Dataset
        A frames Dataset with the own-ship state (``own_north_m``, ..., m, m/s, rad).
    config : RadarConfig
        A side-looking radar.
    map_extent : MapLayers or GroundGrid
    frames : sequence of int, optional
        Frames to check (default all); wing-up frames are skipped.
    gps_offset : (3,) float
        ``(north_m, east_m, heading_deg)`` added to the run's pose, as in :func:`check_run`.
    pixel_m : float
        Pixel size of the footprint grid, m.
    source, map_source : str
        Names of the run and the map, for errors.
    min_ground_fraction : float
        Frames with less of the beam on the ground are wing up.
    map_image : 2-D array, optional
        A raster map on ``map_extent`` (a GroundGrid), NaN where the file has no data: at least
        ``min_data_fraction`` of every frame's footprint must then lie on data.
    min_data_fraction : float

    Raises
    ------
    InputError
        Naming the map when a footprint is off it or off its data.

    Examples
    --------
    >>> import xarray as xr
    >>> from skyradar.config import Mount
    >>> cfg = RadarConfig.prototype_2022(mount=Mount.preset("side-right"), range_limit_m=500.0)
    >>> state = {"own_north_m": 0.0, "own_east_m": 0.0, "own_yaw_rad": 0.0, "own_pitch_rad": 0.0,
    ...          "own_roll_rad": 0.0, "own_vn_mps": 50.0, "own_ve_mps": 0.0, "own_vd_mps": 0.0,
    ...          "own_height_agl_m": 100.0}
    >>> ds = xr.Dataset({name: ("time", [value]) for name, value in state.items()})
    >>> grid = GroundGrid.from_extent(-1000.0, 1000.0, -1000.0, 1000.0, pixel_m=4.0)
    >>> check_coverage(ds, cfg, grid)
    >>> check_coverage(ds, cfg, grid, gps_offset=(0.0, 1500.0, 0.0), map_source="city.osm.pbf")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: city.osm.pbf: the map (north -1000..1000 m, east -1000..1000 m) does not ...
    """
    from skyradar.scene.map_render import check_map_covers  # geo extra: imported when used

    pose_grid = pose_grid_for(config, pixel_m, source)
    _check_state(ds, source)
    ones = np.ones((config.n_range, config.n_doppler))
    offset = np.array([gps_offset[0], gps_offset[1], np.radians(gps_offset[2])])
    picked = list(range(ds.sizes["time"]) if frames is None else frames)
    short: list[tuple[int, float]] = []  # (frame, share of its footprint on map data) below the minimum
    for i in picked:
        gps, attitude, velocity, height = _state(ds, i)
        if ground_in_view_fraction(config, attitude, height) < min_ground_fraction:
            continue  # a wing-up frame is "no decision" wherever its sliver of ground falls
        seen = np.isfinite(ground_image(ones, config, pose_grid, attitude, velocity, height))
        if seen.any():
            north, east = pose_grid.world_points(*(gps + offset))
            check_map_covers(map_extent, north[seen], east[seen], source=map_source)
            if map_image is not None:
                share = _share_on_data(map_image, map_extent, north[seen], east[seen])
                if share < min_data_fraction:
                    short.append((int(i), share))
    if short:
        raise InputError(
            _no_map_data(
                map_image,
                map_extent,
                short,
                len(picked),
                map_source or "map",
                min_data_fraction,
                frame_times_s(ds),
            )
        )


def _share_on_data(image: np.ndarray, grid: GroundGrid, north: np.ndarray, east: np.ndarray) -> float:
    """Share of the world points that fall on a pixel of ``image`` holding data (finite)."""
    row, col = (np.rint(v).astype(np.intp) for v in grid.world_to_pixel(north, east))
    inside = (row >= 0) & (row < image.shape[0]) & (col >= 0) & (col < image.shape[1])
    on_data = np.zeros(row.shape, bool)
    on_data[inside] = np.isfinite(image[row[inside], col[inside]])
    return float(on_data.mean()) if on_data.size else 0.0


def _no_map_data(image, grid, short, n_frames: int, name: str, need: float, times_s) -> str:
    """The one line for footprints off the map's data: in every frame (the map does not cover the
    flight) or in some (named, to leave out with --frames)."""
    rows, cols = np.nonzero(np.isfinite(image))
    north, east = grid.pixel_to_world(rows, cols)
    where = "it holds no data"
    if rows.size:
        where = f"its data lie at north {north.min():.0f}..{north.max():.0f} m, "
        where += f"east {east.min():.0f}..{east.max():.0f} m"
    frame, share = short[0]
    rule = f"less than {100 * need:.0f}% of the radar footprint lies on map data"
    example = f"frame {frame} at t = {float(times_s[frame]):.6g} s: {100 * share:.0f}%"
    if len(short) == n_frames:
        return (
            f"{name}: the map does not cover the flight: in all {n_frames} frames checked {rule} "
            f"({example}); {where}; give a map of the flown area"
        )
    listed = ", ".join(str(f) for f, _ in short[:10]) + (", ..." if len(short) > 10 else "")
    return (
        f"{name}: the map does not cover part of the flight: in {len(short)} of {n_frames} frames ({listed}) "
        f"{rule} ({example}); {where}; give a map of the flown area, or leave those frames out with --frames"
    )


def check_run(
    ds,
    config: RadarConfig,
    map_processed: np.ndarray,
    grid: GroundGrid,
    *,
    frames: Sequence[int] | None = None,
    method: str = DEFAULT_METHOD,
    gps_offset: Sequence[float] = (0.0, 0.0, 0.0),
    settings: MonitorSettings = DEFAULT_SETTINGS,
    pixel_m: float = PIXEL_M,
    source: str = "run",
    building_m: float = 0.0,
    progress=None,
) -> pd.DataFrame:
    """The GPS check of the chosen frames of a frames dataset; one row per frame.

    Parameters
    ----------
    ds : xarray.Dataset
        A frames Dataset with ``iq`` and the own-ship state (``own_north_m``, ..., m, m/s, rad).
    config : RadarConfig
        A side-looking radar.
    map_processed : 2-D array
        The map on ``grid`` pre-processed with ``method`` (:func:`prepare_map`).
    grid : GroundGrid
    frames : sequence of int, optional
        Frames to check (default all).
    method : str
        Pre-processing method.
    gps_offset : (3,) float
        ``(north_m, east_m, heading_deg)`` added to the run's own-ship pose: a biased or spoofed GPS
        (run :func:`check_coverage` first: the footprints must lie on the map).
    settings : MonitorSettings
    pixel_m : float
        Pixel size of the ground image, m.
    source : str
        Names the run in errors.
    building_m : float
        The map's building height for the layover correction (:func:`building_height_m`), m.
    progress : callable, optional
        Called with no argument after each frame.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`GPSCHECK_COLUMNS`.

    Examples
    --------
    Frames without any return: the level one sees a featureless footprint (no decision), the one
    rolled 0.6 rad away from the radar's side sees too little ground (wing up).

    >>> from skyradar.config import Mount
    >>> from skyradar.io.frames import frames_dataset
    >>> cfg = RadarConfig.prototype_2022(mount=Mount.preset("side-right"), range_limit_m=500.0, n_doppler=16)
    >>> own = {"own_north_m": [0.0, 5.0], "own_east_m": [0.0, 0.0], "own_down_m": [-100.0, -100.0],
    ...        "own_yaw_rad": [0.0, 0.0], "own_pitch_rad": [0.0, 0.0], "own_roll_rad": [0.0, -0.6],
    ...        "own_vn_mps": [50.0, 50.0], "own_ve_mps": [0.0, 0.0], "own_vd_mps": [0.0, 0.0],
    ...        "own_height_agl_m": [100.0, 100.0]}
    >>> cube = np.zeros((2, cfg.n_range, cfg.n_doppler, cfg.n_rx), np.complex64)
    >>> ds = frames_dataset(cube, np.array([0.0, 0.1]), cfg, ownship={k: np.array(v) for k, v in own.items()})
    >>> grid = GroundGrid.from_extent(-1000.0, 1000.0, -1000.0, 1000.0, pixel_m=8.0)
    >>> mapped = prepare_map(np.random.default_rng(0).random(grid.shape), ["gamma"])["gamma"]
    >>> table = check_run(ds, cfg, mapped, grid, method="gamma", pixel_m=8.0)
    >>> list(table.columns) == list(GPSCHECK_COLUMNS), table["verdict"].tolist(), table["alert"].any()
    (True, ['no decision: too little structure', 'no decision: wing up'], np.False_)
    """
    pose_grid = pose_grid_for(config, pixel_m, source)
    _check_state(ds, source)
    frames = range(ds.sizes["time"]) if frames is None else frames
    offset = np.array([gps_offset[0], gps_offset[1], np.radians(gps_offset[2])])
    rows, times_s = [], frame_times_s(ds)
    for i in frames:
        gps, attitude, velocity, height = _state(ds, i)
        gps = gps + offset
        power = frame_power(ds["iq"].isel(time=int(i)).values)  # one frame, not the whole store per frame
        image = ground_image(power, config, pose_grid, attitude, velocity, height)
        fraction = ground_in_view_fraction(config, attitude, height)
        result = check_frame(
            image, fraction, gps, map_processed, grid, pose_grid, method, settings, height, building_m
        )
        rows.append(_row(int(i), float(times_s[i]), gps, result, settings))
        if progress is not None:
            progress()
    table = pd.DataFrame(rows)
    table["alert"] = alerts(list(table["verdict"]), settings.alert_frames) if len(table) else []
    return table
