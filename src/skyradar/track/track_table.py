"""Run the range-Doppler tracker (and the 3-D tracker when DoA positions exist) over a detections table."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np
import pandas as pd

from skyradar.config import RadarConfig
from skyradar.io.tables import appended
from skyradar.track.doa_feed import OWNSHIP_COLUMNS, Measure3D
from skyradar.track.frame_grid import frame_grid, frame_numbers
from skyradar.track.fusion import fuse_heads, restore_detection_rows
from skyradar.track.ground_doa import altitude_measured
from skyradar.track.ground_tracks import (
    HOLD_REASONS,
    GroundTrackTest,
    default_ground_test,
    hold_ground_tracks,
)
from skyradar.track.io import validate_detections
from skyradar.track.models import MotionModel, radar_model, traditional_model
from skyradar.track.reacquired_ids import relabel_reacquired
from skyradar.track.tracker import RangeDopplerTracker, TrackerConfig

__all__ = [
    "make_model",
    "track_detections",
    "TrackTableStream",
    "track_air_detections",
    "tracker_detections",
    "own_speeds_mps",
    "empty_tracks",
    "TRACK_COLUMNS",
    "TRACK_TABLE_COLUMNS",
    "OWNSHIP_COLUMNS",
]

_NED = ("north", "east", "down")
# The tracks table (``skyradar track``), column -> "unit; meaning" (skyradar.io.table_columns).
TRACK_TABLE_COLUMNS: dict[str, str] = {
    "time_s": "s; elapsed time of the frame since the run's start_time",
    "frame": "-; frame number in the run (the --ownship run's frames, else the detections' frame column)",
    "track_id": "-; the track's number; a track reacquired after a loss keeps it",
    "range_m": "m; filtered range (radar model: the true range, the range-Doppler coupling removed)",
    "radial_velocity_mps": "m/s; filtered radial velocity, positive receding (radar model: de-aliased)",
    "range_rate_mps": "m/s; range rate fitted to the track's range history (de-aliases the radial velocity)",
    "radial_accel_mps2": "m/s^2; filtered radial acceleration",
    "var_range_m2": "m^2; variance of range_m",
    "var_radial_velocity_m2ps2": "m^2/s^2; variance of radial_velocity_mps",
    "innovation_range_m": "m; range innovation of this frame's update (NaN without a detection)",
    "innovation_radial_velocity_mps": "m/s; radial-velocity innovation of this frame's update (NaN: none)",
    "detection_row": "-; row of the detections table that updated the track on this frame; -1: none",
    "north_m": "m; 3-D position north in the scenario NED frame (NaN without DoA positions)",
    "east_m": "m; 3-D position east in the scenario NED frame (NaN without DoA positions)",
    "down_m": "m; 3-D position down in the scenario NED frame (NaN without DoA positions)",
    "vn_mps": "m/s; 3-D velocity north (NaN without DoA positions)",
    "ve_mps": "m/s; 3-D velocity east (NaN without DoA positions)",
    "vd_mps": "m/s; 3-D velocity down (NaN without DoA positions)",
    "lat_deg": "deg; WGS84 latitude of the 3-D position (NaN without an origin)",
    "lon_deg": "deg; WGS84 longitude of the 3-D position (NaN without an origin)",
    "alt_m": "m; height of the 3-D position above the WGS84 ellipsoid (NaN without an origin)",
    **{
        f"cov_{block}_{i}{j}": f"{unit}; {what} covariance, NED row {_NED[i]}, column {_NED[j]}"
        for block, unit, what in (
            ("pp", "m^2", "position"),
            ("vv", "m^2/s^2", "velocity"),
            ("pv", "m^2/s", "position-velocity"),
        )
        for i in range(3)
        for j in range(3)
    },
    "confirmed": "-; True: the track is confirmed on this row (M-of-N met, not held back by the ground test)",
    "held_by": "-; why the row is not confirmed, empty when it is (ground_tracks.HOLD_REASONS): "
    + ", ".join(reason for reason in HOLD_REASONS if reason),
    "n_updates": "-; detections the track has taken up to this frame",
    "misses": "-; frames since the track's last detection",
    "coasted": "-; True: no detection on this frame, the row is the track's prediction",
    "altitude_measured": "-; False: no elevation of the track was measured; its height is a prior",
}
TRACK_COLUMNS = list(TRACK_TABLE_COLUMNS)


_INTEGER_COLUMNS = ("frame", "track_id", "detection_row", "n_updates", "misses")


def empty_tracks() -> pd.DataFrame:
    """A tracks table with no rows: :data:`TRACK_COLUMNS` with the dtypes of a non-empty one.

    Examples
    --------
    >>> empty = empty_tracks()
    >>> len(empty), list(empty.columns) == TRACK_COLUMNS, str(empty["detection_row"].dtype)
    (0, True, 'int64')
    """

    return _EMPTY_TRACKS.copy()


def _empty_tracks_template() -> pd.DataFrame:
    # Integer row indices stay integer so that callers can index with them even when empty.
    def dtype(column: str) -> type:
        flags = ("confirmed", "coasted", "altitude_measured")
        if column == "held_by":
            return object
        return np.int64 if column in _INTEGER_COLUMNS else bool if column in flags else float

    return pd.DataFrame({c: pd.Series(dtype=dtype(c)) for c in TRACK_COLUMNS}, columns=TRACK_COLUMNS)


_EMPTY_TRACKS = _empty_tracks_template()  # built once: a stream asks for an empty table on many frames


def make_model(name: str, config: RadarConfig, **noise: float) -> MotionModel:
    """``'radar'`` or ``'traditional'`` model for the image width of ``config`` (W = 2 VLim).

    The radar model also gets the range-Doppler coupling of ``config``; its tracks then report the
    true range ``R``, where the image model reports the apparent range ``R + c V_R``.

    Examples
    --------
    >>> make_model("radar", RadarConfig.prototype_2022()).coupled
    True
    """
    width = 2.0 * config.v_lim_mps
    if name == "radar":
        noise.setdefault("coupling_s", config.range_doppler_coupling_s)
        return radar_model(width, **noise)
    if name == "traditional":
        return traditional_model(width, **noise)
    raise ValueError(f"model must be 'radar' or 'traditional', got {name!r}")


def _frame_slices(
    times: np.ndarray, frame_times_s: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Frame times and [start, stop) row ranges of each frame (empty frames included)."""
    uniq, start = np.unique(times, return_index=True)
    grid = uniq if frame_times_s is None else np.union1d(np.asarray(frame_times_s, float), uniq)
    lo = np.searchsorted(times, grid, "left")
    hi = np.searchsorted(times, grid, "right")
    return grid, lo, hi


def track_detections(
    detections: pd.DataFrame,
    model: str | MotionModel = "radar",
    config: RadarConfig | None = None,
    tracker_config: TrackerConfig | None = None,
    frame_times_s: np.ndarray | None = None,
    origin: tuple[float, float, float] | None = None,
    position_sigma_rad: float | None = None,
    ownship: pd.DataFrame | None = None,
    ground_test: GroundTrackTest | bool = True,
) -> pd.DataFrame:
    """Track a detections table; one output row per track per frame.

    Rows of a track before its confirmation are kept (``confirmed`` False) for tracks confirmed
    later; tentative tracks that never were are dropped. ``confirmed`` is also False on rows where a
    confirmed track has coasted ``confirm_n`` frames or more (``misses``). ``coasted``: a prediction
    of a track confirmed earlier; ``altitude_measured`` is False on the co-altitude prior.

    Parameters
    ----------
    detections : DataFrame
        Needs ``time_s, range_m, radial_velocity_mps``; with ``north_m, east_m, down_m`` a 3-D
        track is kept per range-Doppler track. ``snr_db`` (and angles) sets the DoA error (Cramer-Rao
        bound). Several heads (``radar`` column) are fused first (:mod:`skyradar.track.fusion`).
    model : {'radar', 'traditional'} or MotionModel
    config : RadarConfig, optional
        Sets the Doppler width and pixel size (default: thesis prototype).
    frame_times_s : ndarray, optional
        All frame times, so that frames without detections count as misses.
    origin : (lat_deg, lon_deg, alt_m), optional
        Scenario origin for the tracks' lat/lon/alt; NaN without it.
    position_sigma_rad : float, optional
        Fixed angular accuracy of DoA positions (default: the bound; 0.04 rad without ``snr_db``).
    ownship : DataFrame, optional
        :data:`OWNSHIP_COLUMNS` (NED, at the frame times): splits the DoA position error along and
        across the line of sight; the de-aliased radial velocity updates the 3-D velocity.
    ground_test : GroundTrackTest or bool
        Hold back tracks the ground explains (:mod:`skyradar.track.ground_tracks`); False: off.

    Returns
    -------
    DataFrame with :data:`TRACK_COLUMNS` (covariances row-major 3x3 in NED: ``cov_pp`` position
    [m^2], ``cov_vv`` velocity [m^2/s^2], ``cov_pv`` position-velocity [m^2/s]).

    Examples
    --------
    >>> t = np.arange(10) * 0.1
    >>> det = pd.DataFrame({"time_s": t, "range_m": 1000 - 50 * t, "radial_velocity_mps": np.full(10, 28.3)})
    >>> out = track_detections(det)
    >>> out.track_id.nunique(), len(out), int(out.confirmed.sum())
    (1, 9, 5)
    """
    config = config or RadarConfig.prototype_2022()
    detections, head_rows = fuse_heads(validate_detections(detections), config)  # heads -> one stream
    motion, tracker = _make_tracker(model, config, tracker_config)
    grid, lo, hi = _frame_slices(detections["time_s"].to_numpy(float), frame_times_s)
    m3 = Measure3D(
        detections,
        config,
        motion,
        position_sigma_rad,
        ownship,
        grid,
        _surface(ground_test),
        _reacquisition_memory_s(tracker),
    )
    chunks = _run_tracker(tracker, m3, detections, grid, lo, hi, own_speeds_mps(ownship, grid))
    t = _table(chunks, origin, m3, detections, ownship, config, ground_test)
    return restore_detection_rows(t, head_rows)


def _surface(ground_test) -> Callable | None:
    """The terrain the ground test knows (NE -> down), for the 3-D feed's clearance of readings."""
    return ground_test.surface_down if isinstance(ground_test, GroundTrackTest) else None


def _table(
    chunks,
    origin,
    m3,
    detections,
    ownship,
    config: RadarConfig,
    ground_test,
    at_time_s: float | None = None,
    walks: dict | None = None,
    assembled: pd.DataFrame | None = None,
    verdicts: dict | None = None,
) -> pd.DataFrame:
    """The tracks table: ids through reacquisition, ``altitude_measured`` (on the elevations the
    3-D tracker trusted, :mod:`.elevation_trust`), then the ground hold.

    With ``at_time_s`` only the tracks with a row at that time are judged after the ids (each
    track's rows are judged on its own, so theirs are those of the whole table); ``walks`` keeps
    the ground hold's judgements between calls (:func:`~skyradar.track.ground_tracks.hold_ground_tracks`);
    ``assembled`` is :func:`_assemble` of ``chunks`` when the caller keeps it; ``verdicts`` keeps
    the ground test's verdict on each reacquisition between calls
    (:func:`~skyradar.track.reacquired_ids.relabel_reacquired`)."""
    if assembled is None:
        assembled = _assemble(chunks, origin, m3.active)
    t = _reacquired_ids(assembled, chunks, detections, ownship, config, ground_test, verdicts)
    if at_time_s is not None:
        ids = t["track_id"].to_numpy()
        t = t[np.isin(ids, ids[t["time_s"].to_numpy(float) == at_time_s])].reset_index(drop=True)
    read = (
        detections.assign(elevation_measured=m3.trusted) if m3.active and m3.own is not None else detections
    )
    t = t.assign(altitude_measured=altitude_measured(t.track_id, t.detection_row, read))
    return _held(t, detections, ownship, config, ground_test, walks)


def _make_tracker(model, config: RadarConfig, tracker_config) -> tuple[MotionModel, RangeDopplerTracker]:
    motion = make_model(model, config) if isinstance(model, str) else model
    pixel = (config.range_resolution_m, config.doppler_resolution_mps)
    return motion, RangeDopplerTracker(motion, tracker_config, pixel, report_tentative=True)


def _reacquisition_memory_s(tracker: RangeDopplerTracker) -> float:
    """The longest a lost track's id can be given back, s (its closing tracks' memory; 0 with
    reacquisition off)."""
    c = tracker.config
    return max(c.reacquire_s, c.reacquire_closing_s) if c.reacquire_s > 0 else 0.0


def _held(tracks, detections, ownship, config: RadarConfig, ground_test, walks=None) -> pd.DataFrame:
    """:func:`~skyradar.track.ground_tracks.hold_ground_tracks` with ``ground_test``'s settings, and
    ``held_by`` saying why each row is not confirmed (the tracker's reasons first)."""
    coasting = tracks["coasted"].to_numpy(bool) if "coasted" in tracks else np.zeros(len(tracks), bool)
    tracker_why = np.where(coasting, "coasting", "tentative")
    tracks = tracks.assign(held_by=np.where(tracks["confirmed"].to_numpy(bool), "", tracker_why))
    if ground_test is False:
        return tracks
    test = ground_test if isinstance(ground_test, GroundTrackTest) else default_ground_test(config)
    width, coupling = 2.0 * config.v_lim_mps, config.range_doppler_coupling_s
    return hold_ground_tracks(tracks, detections, ownship, width, coupling, test.surface_down, test, walks)


def _run_tracker(
    tracker: RangeDopplerTracker, m3, detections: pd.DataFrame, grid, lo, hi, speeds_mps: np.ndarray
) -> list[dict]:
    """Step the tracker (and the 3-D tracks) frame by frame; one dict of column arrays per frame."""
    z_all, secondary = _measurements(detections)
    frames = frame_numbers(grid, detections)
    return [
        _step_frame(tracker, m3, k, time_s, frames[k], z_all[a:b], secondary[a:b], a, speeds_mps[k])
        for k, (time_s, a, b) in enumerate(zip(grid, lo, hi, strict=True))
    ]


def own_speeds_mps(ownship: pd.DataFrame | None, times_s: np.ndarray) -> np.ndarray:
    """The own-ship's speed (m/s, NED velocity's norm) at each of ``times_s`` (s), interpolated in
    the ``ownship`` rows (:data:`OWNSHIP_COLUMNS`); NaN without them (or outside their times).

    A static point's range changes at most at this speed: the tracker's range-walk initiation
    (:mod:`skyradar.track.range_walk`) starts only tracks that close faster.

    Examples
    --------
    >>> own = pd.DataFrame({"time_s": [0.0, 1.0], "own_vn_mps": [30.0, 40.0], "own_ve_mps": [40.0, 30.0],
    ...                     "own_vd_mps": [0.0, 0.0]})
    >>> own_speeds_mps(own, np.array([0.5, 2.0])).tolist()
    [50.0, nan]
    >>> own_speeds_mps(None, np.array([0.5])).tolist()
    [nan]
    """
    times = np.asarray(times_s, float)
    columns = ("own_vn_mps", "own_ve_mps", "own_vd_mps")
    if ownship is None or len(ownship) == 0 or not all(c in ownship for c in columns):
        return np.full(times.shape, np.nan)
    t = ownship["time_s"].to_numpy(float)
    speed = np.linalg.norm(ownship[list(columns)].to_numpy(float), axis=1)
    order = np.argsort(t, kind="stable")
    return np.interp(times, t[order], speed[order], left=np.nan, right=np.nan)


def _measurements(detections: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    """Range and radial velocity (n, 2) of each detection, and whether it is a secondary one."""
    z = detections[["range_m", "radial_velocity_mps"]].to_numpy(float)
    secondary = np.zeros(len(detections), bool)
    if "secondary" in detections.columns:
        secondary = detections["secondary"].fillna(False).to_numpy(bool)
    return z, secondary


def _step_frame(
    tracker: RangeDopplerTracker, m3, k: int, time_s, frame, z, secondary, a: int, speed_mps: float
) -> dict:
    """One frame of :func:`_run_tracker`: frame ``k`` of the grid, its detections ``z`` the rows from
    ``a`` of the table, the own-ship's speed ``speed_mps`` (m/s, NaN unknown); the frame's dict of
    column arrays."""
    out = tracker.step(float(time_s), z, secondary, static_speed_mps=float(speed_mps))
    row = _frame_rows(tracker, out, time_s, frame, a)
    row["reacquired"] = out.reacquired
    row["reacquired_t"] = np.full(len(out.reacquired), float(time_s))
    if m3.active:
        m3.reacquire(out.reacquired[:, 0], out.reacquired[:, 1], k)
        x, P = m3.step(tracker, out, k, a, a + len(z))
        rows = np.searchsorted(out.alive_ids, out.track_id)
        row["x3"], row["P3"] = x[rows], P[rows]
    return row


def _frame_rows(tracker: RangeDopplerTracker, out, time_s: float, frame: int, first_row: int) -> dict:
    """One frame's track rows (``out`` from :meth:`RangeDopplerTracker.step`) as column arrays."""
    n = out.track_id.size
    rows = np.searchsorted(out.alive_ids, out.track_id)
    misses = tracker.tracks.misses[rows]
    return {
        "time_s": np.full(n, time_s),
        "frame": np.full(n, frame, np.int64),
        "track_id": out.track_id,
        "state": out.state,
        "var": out.covariance[:, [0, 1], [0, 1]],
        "innov": out.innovation,
        "det": np.where(out.detection_index >= 0, out.detection_index + first_row, -1),
        "n_updates": out.n_updates,
        # A confirmed track coasting confirm_n frames is an extrapolation, no longer confirmed.
        "confirmed": out.confirmed & (misses < tracker.initiator.n),
        "misses": misses,
        # A prediction only: the track was confirmed before and no detection was assigned to it now.
        "coasted": (out.detection_index < 0) & tracker.tracks.was_confirmed[rows],
    }


def track_air_detections(
    detections: pd.DataFrame,
    model: str = "radar",
    config: RadarConfig | None = None,
    origin: tuple[float, float, float] | None = None,
    ownship: pd.DataFrame | None = None,
    run_times_s: np.ndarray | None = None,
    ground_test: GroundTrackTest | bool = True,
) -> tuple[pd.DataFrame, int]:
    """Tracks of a ``skyradar process`` table without its ground and spur detections
    (:func:`tracker_detections`).

    The tracker steps on every frame (:func:`skyradar.track.frame_grid.frame_grid`: the run's
    times ``run_times_s`` when given, else the frames of the ``frame`` column, including frames
    without any detection), so a frame without an air detection is a miss and coasting tracks keep
    their rows. ``detection_row`` refers to the rows of ``detections``. ``ground_test``: as in
    :func:`track_detections`. Returns the tracks and the number of detections tracked.

    Examples
    --------
    >>> t = np.arange(10) * 0.1
    >>> det = pd.DataFrame({"time_s": t, "range_m": 1000 - 50 * t, "radial_velocity_mps": np.full(10, 28.3),
    ...                     "is_ground": t > 0.75})
    >>> tracks, n_used = track_air_detections(det)
    >>> n_used, int(tracks.detection_row.max())
    (8, 7)
    """
    frame_times = frame_grid(detections, run_times_s)
    air, keep = tracker_detections(detections)
    tracks = track_detections(
        air, model, config, frame_times_s=frame_times, origin=origin, ownship=ownship, ground_test=ground_test
    )
    return restore_detection_rows(tracks, keep), int(keep.size)


def tracker_detections(detections: pd.DataFrame) -> tuple[pd.DataFrame, np.ndarray]:
    """The rows of a ``skyradar process`` table the tracker takes, and their rows in it: neither
    ground-flagged (``is_ground``) nor spur rows.

    Ground-flagged rows stay out even inside a confirmed track's gate: over relief the ground's
    band holds many of them, and a clutter track fed by them lives on until the ground test
    releases it as an object.

    Examples
    --------
    >>> det = pd.DataFrame({"time_s": [0.0, 0.0, 0.0], "range_m": [900.0, 1000.0, 1100.0],
    ...     "radial_velocity_mps": [-20.0, -20.0, -20.0],
    ...     "is_ground": [False, True, False], "spur": [False, False, True]})
    >>> air, rows = tracker_detections(det)
    >>> rows.tolist(), air["range_m"].tolist()
    ([0], [900.0])
    """
    keep = np.ones(len(detections), bool)
    for flag in ("is_ground", "spur"):
        if flag in detections.columns:
            keep &= ~detections[flag].fillna(False).to_numpy(bool)
    rows = np.flatnonzero(keep)
    return detections.iloc[rows].reset_index(drop=True), rows


def _assemble(
    chunks: list[dict[str, np.ndarray]], origin: tuple[float, float, float] | None, has3d: bool
) -> pd.DataFrame:
    if not chunks or sum(c["track_id"].size for c in chunks) == 0:
        return empty_tracks()

    def cat(key: str) -> np.ndarray:
        return np.concatenate([c[key] for c in chunks])

    state, var, innov = cat("state"), cat("var"), cat("innov")
    n = state.shape[0]
    cols: dict[str, np.ndarray] = {
        "time_s": cat("time_s"),
        "frame": cat("frame"),
        "track_id": cat("track_id"),
        # A range is never negative: the estimate is projected onto range >= 0, as a Kalman filter
        # with an inequality constraint does (Simon, "Kalman filtering with state constraints",
        # IET Control Theory & Applications 4(8), 2010); a collision course passes through zero.
        "range_m": np.maximum(state[:, 0], 0.0),
        "radial_velocity_mps": state[:, 1],
        "range_rate_mps": state[:, 2],
        "radial_accel_mps2": state[:, 3],
        "var_range_m2": var[:, 0],
        "var_radial_velocity_m2ps2": var[:, 1],
        "innovation_range_m": innov[:, 0],
        "innovation_radial_velocity_mps": innov[:, 1],
        "detection_row": cat("det"),
    }
    x3 = cat("x3") if has3d else np.full((n, 6), np.nan)
    P3 = cat("P3") if has3d else np.full((n, 6, 6), np.nan)
    for i, name in enumerate(("north_m", "east_m", "down_m", "vn_mps", "ve_mps", "vd_mps")):
        cols[name] = x3[:, i]
    lat = lon = alt = np.full(n, np.nan)
    if origin is not None and has3d:
        from skyradar.geo import ned_to_geodetic

        lat, lon, alt = (np.asarray(v, float) for v in ned_to_geodetic(x3[:, :3], *origin))
    cols.update({"lat_deg": lat, "lon_deg": lon, "alt_m": alt})
    for i in range(3):
        for j in range(3):
            cols[f"cov_pp_{i}{j}"] = P3[:, i, j]
            cols[f"cov_vv_{i}{j}"] = P3[:, 3 + i, 3 + j]
            cols[f"cov_pv_{i}{j}"] = P3[:, i, 3 + j]
    cols["confirmed"] = cat("confirmed")
    cols["n_updates"] = cat("n_updates")
    cols["misses"] = cat("misses")
    cols["coasted"] = cat("coasted")
    return pd.DataFrame(cols, columns=TRACK_COLUMNS)


def _reacquired_ids(
    df: pd.DataFrame, chunks, detections, ownship, config: RadarConfig, ground_test, verdicts=None
) -> pd.DataFrame:
    """Reacquisitions of lost tracks the ground test finds objects (:mod:`.reacquired_ids`), then
    only tracks confirmed at some point: the tentative rows of the rest were clutter. ``verdicts``
    keeps the ground test's verdict on each reacquisition between calls on a growing table."""
    if len(df) == 0:
        return df
    pairs = np.concatenate([c["reacquired"] for c in chunks]).reshape(-1, 2)
    times = np.concatenate([c["reacquired_t"] for c in chunks])

    def is_object(rows: pd.DataFrame) -> bool:
        return len(_held(rows, detections, ownship, config, ground_test)) > 0

    df = relabel_reacquired(df, pairs, times, is_object, verdicts)
    real = np.unique(df["track_id"].to_numpy()[df["confirmed"].to_numpy()])
    return df[np.isin(df["track_id"].to_numpy(), real)].reset_index(drop=True)


class TrackTableStream:
    """:func:`track_detections` one frame at a time: each call gives the tracks table's rows of that frame.

    The range-Doppler tracker and the 3-D feed keep their state between frames and step once per
    frame (:func:`_step_frame`, the batch loop's body). The table's finishing (ids through
    reacquisition, ``altitude_measured``, the ground hold) runs the batch's code on the rows so far
    and keeps the tracks alive on the frame; the ground hold keeps each track's judgements
    (:class:`~skyradar.track.ground_tracks.TrackHoldWalk`) and judges only its new detections.

    What a stream cannot know makes its rows differ from the batch table's in three ways:

    - A track's rows are emitted only from its confirmation on: the batch keeps the tentative rows
      of a track confirmed later, which a stream cannot take back. Every row emitted is the batch's.
    - The ground hold judges a track's newest detection on every frame; the batch, which knows which
      detection of a long track is its last, judges every fifth after the thirtieth, and the last.
      A verdict that changes between two judgements then shows some frames earlier in the stream.
    - With several heads, every frame is fused as a multi-head one (``several_heads``); the batch
      fuses only when its table holds more than one head, and refers a single head's ranges to the
      aircraft's reference point only then.

    Parameters
    ----------
    model, config, tracker_config, origin, position_sigma_rad, ground_test
        As in :func:`track_detections`.
    several_heads : bool
        Whether the detections come from more than one radar head
        (:func:`~skyradar.track.fusion.fuse_heads`).

    Examples
    --------
    >>> frames = [pd.DataFrame({"time_s": [0.1 * k], "range_m": [1000 - 5.0 * k],
    ...                         "radial_velocity_mps": [28.3]}) for k in range(10)]
    >>> stream = TrackTableStream()
    >>> rows = pd.concat([stream.step(0.1 * k, k, f) for k, f in enumerate(frames)], ignore_index=True)
    >>> batch = track_detections(pd.concat(frames, ignore_index=True))
    >>> len(batch), len(rows), rows.equals(batch[batch.confirmed].reset_index(drop=True))
    (9, 5, True)
    """

    def __init__(
        self,
        model: str | MotionModel = "radar",
        config: RadarConfig | None = None,
        tracker_config: TrackerConfig | None = None,
        origin: tuple[float, float, float] | None = None,
        position_sigma_rad: float | None = None,
        ground_test: GroundTrackTest | bool = True,
        several_heads: bool = False,
    ) -> None:
        self.config = config or RadarConfig.prototype_2022()
        self.motion, self.tracker = _make_tracker(model, self.config, tracker_config)
        self.origin, self.position_sigma_rad = origin, position_sigma_rad
        self.ground_test, self.several_heads = ground_test, several_heads
        self._m3: Measure3D | None = None
        self._chunks: list[dict] = []
        self._fused: pd.DataFrame | None = None  # every frame's fused detections so far
        self._input_rows: list[np.ndarray] = []  # per frame: the input row of each fused detection
        self._n_input = self._n_fused = 0
        self._own: pd.DataFrame | None = None  # the own-ship rows so far
        self._walks: dict = {}  # the ground hold's judgements of each track, kept between frames
        self._assembled: pd.DataFrame | None = None  # the tracker's rows of every frame so far
        self._verdicts: dict = {}  # the ground test's verdict on each reacquisition, judged once

    def set_surface(self, surface_down: Callable | None) -> None:
        """The terrain (NE -> down, m) of the ground test and the 3-D feed from this frame on."""
        test = (
            self.ground_test
            if isinstance(self.ground_test, GroundTrackTest)
            else default_ground_test(self.config)
        )
        if self.ground_test is not False:
            self.ground_test = replace(test, surface_down=surface_down)
        if self._m3 is not None and self._m3.active:
            self._m3.surface_down = surface_down

    def step(
        self, time_s: float, frame: int, detections: pd.DataFrame, ownship: pd.DataFrame | None = None
    ) -> pd.DataFrame:
        """Track one frame: its ``detections`` (rows of that frame only, any ``time_s`` equal to
        ``time_s``, s) and the own-ship row ``ownship`` (:data:`OWNSHIP_COLUMNS` at ``time_s``).

        Returns the frame's rows with :data:`TRACK_COLUMNS`; ``detection_row`` counts the
        detections of every frame given so far, in order (the batch table's row numbers).
        """
        det = validate_detections(detections)
        fused, rows = fuse_heads(det, self.config, several_heads=self.several_heads)
        rows = np.arange(len(fused)) if rows is None else rows
        if self._m3 is None:
            surface = _surface(self.ground_test)
            memory_s = _reacquisition_memory_s(self.tracker)
            self._m3 = Measure3D(
                fused, self.config, self.motion, self.position_sigma_rad, None, [], surface, memory_s
            )
        elif self._m3.active:
            self._m3.add_detections(fused)
        if ownship is not None:
            self._own = appended(self._own, ownship)
        own = self._own
        if self._m3.active and ownship is not None:
            self._m3.add_frames(np.array([time_s], float), ownship)
        z, secondary = _measurements(fused)
        k, a = len(self._chunks), self._n_fused
        speed = float("nan")
        if ownship is not None and len(ownship):
            speed = float(own_speeds_mps(ownship, ownship["time_s"].to_numpy(float))[-1])
        self._chunks.append(_step_frame(self.tracker, self._m3, k, time_s, frame, z, secondary, a, speed))
        self._fused = appended(self._fused, fused)
        self._input_rows.append(self._n_input + rows)
        self._n_input, self._n_fused = self._n_input + len(det), self._n_fused + len(fused)
        args = (self.origin, self._m3, self._fused, own, self.config, self.ground_test)
        # Each frame's rows are assembled once (rows depend on their own frame only) and appended.
        new = _assemble(self._chunks[-1:], self.origin, self._m3.active)
        self._assembled = assembled = appended(self._assembled, new)
        t = _table(
            self._chunks,
            *args,
            at_time_s=float(time_s),
            walks=self._walks,
            assembled=assembled,
            verdicts=self._verdicts,
        )
        t = t[t["time_s"].to_numpy(float) == float(time_s)].reset_index(drop=True)
        return restore_detection_rows(t, np.concatenate(self._input_rows))
