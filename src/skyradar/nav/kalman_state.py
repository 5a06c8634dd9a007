"""Kalman filter on the flight state (V_X, V_Z, H) with H' = -V_Z.

The state is ground speed ``V_X``, vertical speed ``V_Z`` (positive down) and height above the
terrain ``H``; descending (V_Z > 0) lowers H, hence H' = -V_Z. Process noise: white
acceleration on both speeds and a random walk on H for the terrain passing underneath.

Outlier rejection needs no GPS: a frame whose normalised innovation squared exceeds the
chi-square gate is not used; after ``max_rejections`` consecutive rejections the filter
restarts from the measurement (the state, not the measurements, was wrong). The thesis' GPS
gate (drop measurements more than 150 m from the GPS height) is kept only for comparison.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skyradar.kalman import innovation_covariance, update
from skyradar.quantiles import chi2_quantile

__all__ = ["KalmanSettings", "FilterOutput", "filter_states"]

_OBSERVE_ALL = np.eye(3)  # every frame measures the whole state (V_X, V_Z, H)


@dataclass(frozen=True)
class KalmanSettings:
    """Filter tuning.

    Attributes
    ----------
    accel_psd : float
        Power spectral density of the speed random walk, (m/s^2)^2 / Hz.
    terrain_psd : float
        Height random walk for terrain relief passing underneath, m^2/s.
    gate_probability : float
        Innovations beyond this chi-square (3 dof) quantile are rejected.
    max_rejections : int
        Consecutive rejections before the filter restarts from the measurement.
    meas_sd_floor : tuple of float
        Lower bounds of the measurement SDs (V_X m/s, V_Z m/s, H m).
    gps_gate_m : float or None
        Thesis mode: reject measurements farther than this from the reference height, m.

    Examples
    --------
    A height jump of 400 m: the default gate rejects it; with ``max_rejections=1`` the filter
    restarts from it at once.

    >>> t = np.arange(6.0)
    >>> z = np.column_stack([np.full(6, 50.0), np.zeros(6), [300.0, 300.0, 300.0, 300.0, 700.0, 700.0]])
    >>> sd = np.tile([1.0, 1.0, 5.0], (6, 1))
    >>> filter_states(t, z, sd).accepted.tolist()
    [True, True, True, True, False, False]
    >>> out = filter_states(t, z, sd, KalmanSettings(max_rejections=1))
    >>> out.accepted.tolist(), out.state[4, 2]
    ([True, True, True, True, True, True], np.float64(700.0))
    """

    accel_psd: float = 0.5
    terrain_psd: float = 20.0
    gate_probability: float = 0.999
    max_rejections: int = 5
    meas_sd_floor: tuple[float, float, float] = (0.2, 0.2, 2.0)
    gps_gate_m: float | None = None


@dataclass(frozen=True)
class FilterOutput:
    """Filtered states (n, 3) in the order (V_X, V_Z, H), their SDs, and which frames were used.

    Attributes
    ----------
    state : ndarray, shape (n, 3)
        V_X (m/s), V_Z (m/s, positive down), H (m); NaN rows before the first usable measurement.
    sd : ndarray, shape (n, 3)
        One-sigma uncertainties, same units.
    accepted : ndarray of bool, shape (n,)
        Frames whose measurement the filter took.

    Examples
    --------
    Descending at 2 m/s: between measurements the height follows H' = -V_Z.

    >>> z = np.array([[50.0, 2.0, 600.0], [np.nan] * 3, [50.0, 2.0, 596.0]])
    >>> out = filter_states(np.array([0.0, 1.0, 2.0]), z, np.tile([1.0, 1.0, 5.0], (3, 1)))
    >>> np.round(out.state[:, 2], 6).tolist(), out.accepted.tolist(), out.sd[0].tolist()
    ([600.0, 598.0, 596.0], [True, False, True], [1.0, 1.0, 5.0])
    """

    state: np.ndarray
    sd: np.ndarray
    accepted: np.ndarray


def _transition(dt: float, s: KalmanSettings) -> tuple[np.ndarray, np.ndarray]:
    f = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -dt, 1.0]])
    q = s.accel_psd
    qm = np.array(
        [
            [q * dt, 0.0, 0.0],
            [0.0, q * dt, -q * dt**2 / 2.0],
            [0.0, -q * dt**2 / 2.0, q * dt**3 / 3.0 + s.terrain_psd * dt],
        ]
    )
    return f, qm


def _gated_update(x, p, z, r_diag, gate: float, s: KalmanSettings, rejections: int):
    """Kalman update with ``z`` unless it fails the chi-square gate; after ``max_rejections``
    rejections in a row the filter restarts from ``z``. Returns x, P, accepted, rejections."""
    innov, r_mat = z - x, np.diag(r_diag)
    s_mat = innovation_covariance(p, _OBSERVE_ALL, r_mat)
    d2 = float(innov @ np.linalg.solve(s_mat, innov))
    if d2 <= gate or s.gps_gate_m is not None:  # the thesis' GPS gate replaces the chi-square gate
        x, p = update(x, p, innov, _OBSERVE_ALL, r_mat, s_mat)
        return x, p, True, 0
    if rejections + 1 >= s.max_rejections:
        return z.copy(), np.diag(r_diag), True, 0
    return x, p, False, rejections + 1


def filter_states(
    times_s: np.ndarray,
    measured: np.ndarray,
    measured_sd: np.ndarray,
    settings: KalmanSettings | None = None,
    reference_h_m: np.ndarray | None = None,
) -> FilterOutput:
    """Filter per-frame (V_X, V_Z, H) measurements.

    Parameters
    ----------
    times_s : ndarray, shape (n,)
        Frame times, s (non-decreasing).
    measured, measured_sd : ndarray, shape (n, 3)
        Per-frame estimates and SDs; rows with NaN are skipped (prediction only).
    settings : KalmanSettings, optional
    reference_h_m : ndarray, shape (n,), optional
        GPS height for the thesis' gate (used only with ``settings.gps_gate_m``).

    Returns
    -------
    FilterOutput
        NaN rows until the first usable measurement.

    Examples
    --------
    >>> t = np.arange(20.0)
    >>> z = np.column_stack([np.full(20, 50.0), np.full(20, 2.0), 600.0 - 2.0 * t])
    >>> out = filter_states(t, z, np.tile([1.0, 1.0, 10.0], (20, 1)))
    >>> np.round(out.state[-1], 1).tolist()
    [50.0, 2.0, 562.0]
    """
    s = settings or KalmanSettings()
    t = np.asarray(times_s, float)
    z_all = np.asarray(measured, float)
    sd_all = np.maximum(np.asarray(measured_sd, float), np.asarray(s.meas_sd_floor))
    n = t.size
    out_x, out_sd = np.full((n, 3), np.nan), np.full((n, 3), np.nan)
    accepted = np.zeros(n, bool)
    gate = chi2_quantile(s.gate_probability, 3)
    x = p = None
    t_prev, rejections = None, 0
    for i in range(n):
        z, r_diag = z_all[i], sd_all[i] ** 2
        usable = bool(np.all(np.isfinite(z)) and np.all(np.isfinite(r_diag)))
        if usable and s.gps_gate_m is not None and reference_h_m is not None:
            usable = bool(abs(z[2] - reference_h_m[i]) <= s.gps_gate_m)
        if x is not None:
            f, q = _transition(t[i] - t_prev, s)
            x, p = f @ x, f @ p @ f.T + q
            t_prev = t[i]
        if usable and x is None:
            x, p, t_prev, accepted[i] = z.copy(), np.diag(r_diag), t[i], True
        elif usable:
            x, p, accepted[i], rejections = _gated_update(x, p, z, r_diag, gate, s, rejections)
        if x is not None:
            assert p is not None  # set with x
            out_x[i], out_sd[i] = x, np.sqrt(np.clip(np.diag(p), 0.0, None))
    return FilterOutput(out_x, out_sd, accepted)
