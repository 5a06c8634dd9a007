"""Own-ship flight state over the terrain from the ground returns of each frame (Maas 2022, ch. 5).

Per frame: the ground ridge (:mod:`skyradar.nav.ridge`), a flat-plane inversion
(:mod:`skyradar.nav.inversion`) and a quality figure; over the run: the Kalman filter of
:mod:`skyradar.nav.kalman_state`. Two flat-plane methods (a third, ``terrain``, from
:mod:`skyradar.nav.terrain_aware`, is available through :func:`estimate_run`):

``thesis``
    Ridge pairs at the range-bin centre without the range-Doppler coupling correction, the
    algebraic least squares for (a, b, c); filtered with the thesis' GPS gate when a reference
    height is given (comparison only).
``robust``
    Ridge pairs at the bin edge with the coupling removed, RANSAC + Huber nonlinear least
    squares started from the previous frame's estimate with a weak prior on V_Z, GPS-free
    innovation gating in the filter.

Heights refer to the own-ship reference point: the antenna's height (what the radar sees) plus
the mount offset rotated by pitch and roll when the run carries attitude, else level flight.
The quality figure is ``inlier_fraction * min(1, n_inliers / 50)``; a frame with fewer than
``min_points`` inliers or quality below ``min_quality`` (e.g. the radar sees only sky) gets NaN
estimates and ``low_quality = True`` and is skipped by the filter.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd
import xarray as xr

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.geo import rotation_matrix
from skyradar.io.checks import check_finite_frames, check_frame_times
from skyradar.io.frames_model import frame_times_s
from skyradar.io.navigation import navigation_state
from skyradar.nav.inversion import StateFit, fit_robust, fit_thesis
from skyradar.nav.kalman_state import KalmanSettings, filter_states
from skyradar.nav.ridge import Ridge, extract_ridge
from skyradar.sim.navigation import AhrsModel, ahrs_attitude

__all__ = [
    "METHODS",
    "STATE_TABLE_COLUMNS",
    "FrameEstimate",
    "estimate_frame",
    "mount_height_offset_m",
    "filter_table",
    "estimate_run",
]

METHODS = ("thesis", "robust")
STATE_COLUMNS = ("vx", "vz", "h")
# The flight-state table (``skyradar state``), column -> "unit; meaning" (skyradar.io.table_columns).
STATE_TABLE_COLUMNS: dict[str, str] = {
    "time_s": "s; elapsed time of the frame since the run's start_time",
    "frame": "-; frame number in the run, from 0",
    "vx_raw_mps": "m/s; this frame's horizontal ground speed from the ground ridge (NaN: low quality)",
    "vz_raw_mps": "m/s; this frame's vertical speed, positive down (NaN: low quality)",
    "h_raw_m": "m; this frame's height of the own-ship reference point above the ground (NaN: low quality)",
    "vx_raw_sd_mps": "m/s; one-sigma uncertainty of vx_raw_mps",
    "vz_raw_sd_mps": "m/s; one-sigma uncertainty of vz_raw_mps",
    "h_raw_sd_m": "m; one-sigma uncertainty of h_raw_m",
    "quality": "-; 0..1, the ridge fit's inlier fraction times min(1, inliers / 50)",
    "low_quality": "-; True: too few inliers or too low a quality (only sky in view); the filter skips it",
    "n_ridge": "-; ground-ridge points of the frame",
    "n_inliers": "-; ridge points the fit kept",
    "vx_mps": "m/s; Kalman-filtered horizontal ground speed",
    "vx_sd_mps": "m/s; one-sigma uncertainty of vx_mps",
    "vz_mps": "m/s; Kalman-filtered vertical speed, positive down",
    "vz_sd_mps": "m/s; one-sigma uncertainty of vz_mps",
    "h_m": "m; Kalman-filtered height above the ground",
    "h_sd_m": "m; one-sigma uncertainty of h_m",
    "used_by_filter": "-; True: the filter took this frame's raw estimate (it passed the innovation gate)",
}


@dataclass(frozen=True)
class FrameEstimate:
    """One frame: the fit (antenna height), its ridge, quality and the low-quality flag.

    Attributes
    ----------
    fit : StateFit
        V_X (m/s), V_Z (m/s, positive down) and H (m, of the antenna); NaN on a low-quality frame.
    ridge : Ridge
        The ground-ridge pairs the fit used.
    quality : float
        ``inlier_fraction * min(1, n_inliers / 50)``, 0..1.
    low_quality : bool
        Too few inliers or too low a quality; the filter skips the frame.

    Examples
    --------
    Ridge pairs of flat ground 500 m below, flying at 60 m/s and climbing at 3 m/s:

    >>> from skyradar.nav.inversion import ridge_velocity
    >>> r = np.linspace(520.0, 4000.0, 80)
    >>> z = np.zeros(80, int)
    >>> ridge = Ridge(r, ridge_velocity(r, 60.0, -3.0, 500.0), z, z, np.full(80, 20.0), 1e-12, 80)
    >>> est = estimate_frame(None, RadarConfig.prototype_2022(), ridge=ridge)
    >>> est.quality, est.low_quality, est.n_inliers
    (1.0, False, 80)
    >>> round(est.fit.vx_mps, 2), round(est.fit.vz_mps, 2), round(est.fit.h_m, 1)
    (60.0, -3.0, 500.0)
    """

    fit: StateFit
    ridge: Ridge
    quality: float
    low_quality: bool

    @property
    def n_inliers(self) -> int:
        return int(self.fit.inliers.sum())


def estimate_frame(
    frame: np.ndarray,
    config: RadarConfig,
    method: str = "robust",
    prior_state: tuple[float, float, float] | None = None,
    min_points: int = 12,
    min_quality: float = 0.3,
    threshold_db: float = 8.0,
    ridge: Ridge | None = None,
    vz_prior_sd_mps: float = 0.5,
) -> FrameEstimate:
    """Flight state of the antenna over the ground plane from one frame.

    Parameters
    ----------
    frame : ndarray
        (range, doppler, rx) complex cube or (range, doppler) power image.
    config : RadarConfig
    method : {"thesis", "robust"}
    prior_state : (vx_mps, vz_mps, h_m), optional
        Previous estimate (antenna height): resolves ground-return aliasing; for ``robust`` it
        also starts the fit and holds V_Z with SD ``vz_prior_sd_mps`` (frame to frame V_Z
        changes slowly, while over rough terrain one frame's ridge trades H against V_Z).
    min_points, min_quality : int, float
        Below either the frame is flagged low quality and its estimates are NaN.
    threshold_db : float
        Noise gate of the ridge extraction.
    ridge : Ridge, optional
        Ridge of this frame already extracted (default edge placement); saves the extraction.

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> est = estimate_frame(np.zeros((cfg.n_range, cfg.n_doppler)), cfg)
    >>> est.low_quality, est.fit.h_m
    (True, nan)
    """
    if method not in METHODS:
        raise InputError(f"flight state: field 'method' must be one of {METHODS}, got {method!r}")
    if ridge is None:
        ridge = extract_ridge(frame, config, threshold_db=threshold_db, prior_state=prior_state)
    if method == "thesis":
        # The thesis paired the ridge velocity with the range-bin centre (apparent range).
        fit = fit_thesis(config.range_at_bin_m(ridge.range_bin), ridge.radial_velocity_mps)
    else:
        prior = None
        if prior_state is not None and np.all(np.isfinite(prior_state)):
            prior = (np.asarray(prior_state, float), np.array([np.inf, vz_prior_sd_mps, np.inf]))
        fit = fit_robust(ridge.range_m, ridge.radial_velocity_mps, prior=prior)
    n_in = int(fit.inliers.sum())
    quality = float(n_in / max(len(ridge), 1) * min(1.0, n_in / 50.0)) if fit.ok else 0.0
    low = (not fit.ok) or n_in < min_points or quality < min_quality
    if low:
        fit = StateFit.failed(len(ridge))
    return FrameEstimate(fit, ridge, quality, low)


def mount_height_offset_m(config: RadarConfig, pitch_rad: float = 0.0, roll_rad: float = 0.0) -> float:
    """How far the antenna sits below the own-ship reference point, m (add to the antenna height).

    Examples
    --------
    >>> from skyradar.config import Mount
    >>> round(mount_height_offset_m(RadarConfig(mount=Mount.preset("forward-down"))), 3)
    0.3
    """
    body_to_level = rotation_matrix(0.0, pitch_rad, roll_rad)
    return float((body_to_level @ np.asarray(config.mount.position_m))[2])


def filter_table(
    table: pd.DataFrame,
    settings: KalmanSettings | None = None,
    reference_h_m: np.ndarray | None = None,
) -> pd.DataFrame:
    """Add filtered columns (``vx_mps, vz_mps, h_m`` and their ``*_sd``) and ``used_by_filter``.

    Parameters
    ----------
    table : pandas.DataFrame
        Per-frame ``time_s`` (s) and raw ``vx_raw_mps, vz_raw_mps`` (m/s), ``h_raw_m`` (m) with their
        SDs ``vx_raw_sd_mps, vz_raw_sd_mps, h_raw_sd_m``; NaN rows are not measurements.
    settings : KalmanSettings, optional
        Filter tuning (default :class:`KalmanSettings`).
    reference_h_m : ndarray, optional
        Reference height per frame, m, for the thesis' GPS gate (``settings.gps_gate_m``).

    Returns
    -------
    pandas.DataFrame
        A copy of ``table`` with the filtered columns (NaN until the first measurement).

    Examples
    --------
    A constant state with one frame 400 m off in height: the innovation gate drops that frame.

    >>> table = pd.DataFrame({"time_s": np.arange(6.0), "vx_raw_mps": 50.0, "vz_raw_mps": 0.0,
    ...                       "h_raw_m": [np.nan, 300.0, 300.0, 300.0, 700.0, 300.0],
    ...                       "vx_raw_sd_mps": 1.0, "vz_raw_sd_mps": 1.0, "h_raw_sd_m": 5.0})
    >>> out = filter_table(table)
    >>> out["h_m"].round(1).tolist(), out["used_by_filter"].tolist()
    ([nan, 300.0, 300.0, 300.0, 300.0, 300.0], [False, True, True, True, False, True])
    """
    raw = table[["vx_raw_mps", "vz_raw_mps", "h_raw_m"]].to_numpy().astype(float)
    raw_sd = table[["vx_raw_sd_mps", "vz_raw_sd_mps", "h_raw_sd_m"]].to_numpy().astype(float)
    out = filter_states(table["time_s"].to_numpy().astype(float), raw, raw_sd, settings, reference_h_m)
    table = table.copy()
    for i, (name, unit) in enumerate(zip(STATE_COLUMNS, ("mps", "mps", "m"), strict=True)):
        table[f"{name}_{unit}"] = out.state[:, i]
        table[f"{name}_sd_{unit}"] = out.sd[:, i]
    table["used_by_filter"] = out.accepted
    return table


def _attitudes(ds: xr.Dataset, times: np.ndarray, ahrs: AhrsModel | None, seed: int) -> np.ndarray:
    """(n, 3) yaw, pitch, roll (level north when absent).

    Without ``ahrs``: the run's navigation attitude (nav_*_rad, the AHRS the run simulated; own_*
    only in runs written without navigation). With ``ahrs`` (the thesis comparison): the truth
    own_*_rad through that model's seeded errors.
    """
    names = ("own_yaw_rad", "own_pitch_rad", "own_roll_rad")
    state = ds if ahrs is not None else navigation_state(ds)
    columns = [np.asarray(state[n], float) if state is not None and n in state else None for n in names]
    attitude = np.column_stack([np.zeros(times.size) if c is None else c for c in columns])
    return attitude if ahrs is None else ahrs_attitude(attitude, times, ahrs, seed=seed)


def _frame_rows(
    ds: xr.Dataset, config: RadarConfig, method: str, progress, source: str, attitudes: np.ndarray
) -> list[dict]:
    from skyradar.nav.terrain_aware import TerrainAwareEstimator, TerrainEstimate

    times = frame_times_s(ds)
    aware = TerrainAwareEstimator(config) if method == "terrain" else None
    rows, prior = [], None
    for i in range(times.size):
        attitude = attitudes[i]
        frame = np.asarray(ds.iq[i].values)
        check_finite_frames(frame[None], i, source)  # a NaN would come out as a wrong state, not an error
        fit: TerrainEstimate | StateFit
        if aware is not None:
            est = aware.update(times[i], frame, attitude)
            fit, quality, low, n_ridge, n_in = est, est.quality, est.low_quality, est.n_points, est.n_points
        else:
            fe = estimate_frame(frame, config, method=method, prior_state=prior)
            fit, quality, low, n_ridge, n_in = fe.fit, fe.quality, fe.low_quality, len(fe.ridge), fe.n_inliers
            if fe.fit.ok:
                prior = (fit.vx_mps, fit.vz_mps, fit.h_m)
        rows.append(
            {
                "time_s": times[i],
                "frame": i,
                "vx_raw_mps": fit.vx_mps,
                "vz_raw_mps": fit.vz_mps,
                "h_raw_m": fit.h_m + mount_height_offset_m(config, *attitude[1:]),
                "vx_raw_sd_mps": fit.vx_sd_mps,
                "vz_raw_sd_mps": fit.vz_sd_mps,
                "h_raw_sd_m": fit.h_sd_m,
                "quality": quality,
                "low_quality": bool(low),
                "n_ridge": n_ridge,
                "n_inliers": n_in,
            }
        )
        if progress is not None:
            progress(i + 1, times.size)
    return rows


def estimate_run(
    ds: xr.Dataset,
    method: str = "robust",
    settings: KalmanSettings | None = None,
    gps_gate: bool = False,
    progress: Callable[[int, int], None] | None = None,
    source: str = "frames",
    ahrs: AhrsModel | None = None,
    ahrs_seed: int = 0,
) -> pd.DataFrame:
    """Per-frame raw and filtered flight state of a frames Dataset (``source`` names it in errors).

    Parameters
    ----------
    ds : xarray.Dataset
        A frames Dataset (its ``iq``, ``radar_config`` and own-ship navigation are read).
    method : {"thesis", "robust", "terrain"}
        ``terrain`` is :mod:`skyradar.nav.terrain_aware`, which takes the attitude (rad) from the
        run's navigation ``own_yaw_rad/own_pitch_rad/own_roll_rad``, i.e. an AHRS; level flight
        heading north when absent.
    settings : KalmanSettings, optional
        Filter tuning; default :class:`KalmanSettings` (``terrain_psd=400`` m^2/s for ``terrain``).
    gps_gate : bool
        The thesis' 150 m gate against the navigation's ``own_height_agl_m`` (comparison only).
    progress : callable, optional
        Called as ``progress(done, total)`` after each frame.
    source : str
        Names the run in errors.
    ahrs : AhrsModel, optional
        With a :class:`skyradar.sim.navigation.AhrsModel` the run's attitude, the simulator's truth,
        reaches the estimators only through that model's errors, seeded by ``ahrs_seed``.
    ahrs_seed : int

    Returns
    -------
    pandas.DataFrame
        The columns of :data:`STATE_TABLE_COLUMNS`: ``time_s`` (s), ``frame``, raw
        ``vx_raw_mps, vz_raw_mps`` (m/s), ``h_raw_m`` (m) with ``_sd``, filtered ``vx_mps, vz_mps,
        h_m`` with ``_sd``, ``quality, low_quality, n_ridge, n_inliers, used_by_filter``.

    Examples
    --------
    Frames that see only sky (no ground returns) are flagged and give no state:

    >>> from skyradar.io.frames import frames_dataset
    >>> cfg = RadarConfig.prototype_2022(range_limit_m=1000.0)
    >>> cube = np.zeros((3, cfg.n_range, cfg.n_doppler, cfg.n_rx), np.complex64)
    >>> table = estimate_run(frames_dataset(cube, np.array([0.0, 0.1, 0.2]), cfg))
    >>> list(table.columns) == list(STATE_TABLE_COLUMNS)
    True
    >>> table["low_quality"].tolist(), table["h_m"].isna().all(), table["used_by_filter"].any()
    ([True, True, True], np.True_, np.False_)
    """
    from skyradar.io.frames import radar_config_of

    if method not in (*METHODS, "terrain"):
        raise InputError(f"flight state: field 'method' must be thesis, robust or terrain, got {method!r}")
    config = radar_config_of(ds, source)
    check_frame_times(frame_times_s(ds), source)
    attitudes = _attitudes(ds, frame_times_s(ds), ahrs, ahrs_seed)
    table = pd.DataFrame(_frame_rows(ds, config, method, progress, source, attitudes))
    if settings is None:
        settings = KalmanSettings(terrain_psd=400.0) if method == "terrain" else KalmanSettings()
    reference = None
    if gps_gate:
        # The GPS gate compares with the GNSS height above the terrain: the navigation's, not the truth.
        nav = navigation_state(ds, source)
        if nav is None or "own_height_agl_m" not in nav:
            raise InputError(f"{source}: field 'own_height_agl_m' is needed for the GPS gate but missing")
        reference = nav["own_height_agl_m"].to_numpy(float)
        settings = KalmanSettings(**{**settings.__dict__, "gps_gate_m": 150.0})
    return filter_table(table, settings, reference)
