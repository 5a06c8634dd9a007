"""Flyable paths from recorded fixes, and the kinematic limits an aircraft class can fly.

Recorded fixes (ADS-B, GPS logs) are not a path an aircraft flies: ADS-B positions are stale or
misaligned in time by up to seconds (the position and velocity messages are decoded at different
moments, and a receiver stamps the message it heard, not the moment the aircraft was there), so the
speed between two fixes swings far from the ground speed the aircraft reports. A spline through every
fix turns that into accelerations of tens of g, and a simulated radar into Doppler no aircraft makes.

:func:`flyable_path` builds the truth path instead with a fixed-interval Kalman smoother
(Rauch-Tung-Striebel) under a white-noise-acceleration (nearly constant velocity) model, one per axis,
fed with the positions and with the ground speed, track and vertical rate the file reports. Its
interpolation between fixes is the cubic that minimises the integrated squared acceleration, so a gap
between fixes is bridged with the gentlest motion that joins them. Its rules:

* a fix whose position repeats the previous one while the aircraft moves is stale (the receiver
  repeated the last position it had) and is dropped;
* a fix out of reach of the flight around it at the class's top speed is dropped (a bad decode, or
  a jump the aircraft cannot have flown);
* a common lag of the positions behind the reported velocities (the time misalignment of the
  position messages) is estimated by least squares, ``r_i = -v_i * lag`` with ``r_i`` a fix's offset
  from the smoothed path, refined over a few passes, and the fixes are re-timed when it is
  significant; on a straight leg no lag shows (the lagged fixes lie on the same line);
* the noise is measured, not assumed: the process noise and the position and velocity errors are
  those that make the kept fixes most likely (the filter's innovation likelihood, a grid search;
  the horizontal axes share theirs);
* fixes more than 5 spreads (and 30 m) off the path cannot be reconciled with it and are dropped;
* a file whose track column is far off its positions' course keeps its ground speed, carried along
  the path's own direction, refined with each pass;
* the process noise is lowered until the path's acceleration, everywhere between its samples, stays
  within the class's limits (:class:`KinematicLimits`), and a fix that only a path faster than the
  class can fly reaches (across a gap) is dropped;
* a file that loses more than :data:`MAX_DROPPED_SHARE` of its fixes is refused.

Every repair is returned as a note naming the fixes (rows of the file), which the readers print as
one line per file. :func:`kinematic_violation` checks any trajectory against the limits; the scenario
builder uses it so that no own-ship or intruder beyond its class's limits is simulated.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from skyradar.errors import InputError
from skyradar.scene.adsb_clean import glitch_rows

__all__ = [
    "AIRCRAFT_CLASSES",
    "MAX_DROPPED_SHARE",
    "FlyablePath",
    "KinematicLimits",
    "flyable_path",
    "hermite_accelerations",
    "kinematic_violation",
]

GRAVITY_MPS2 = 9.80665


@dataclass(frozen=True)
class KinematicLimits:
    """What an aircraft class can fly: accelerations and speed, SI units.

    Parameters
    ----------
    name : str
        The class name used in messages.
    horizontal_accel_mps2 : float
        Largest horizontal acceleration, m/s^2. A coordinated turn at bank ``phi`` accelerates the
        aircraft by ``g tan(phi)`` toward the turn's centre: 9.8 m/s^2 at 45 deg.
    vertical_accel_mps2 : float
        Largest vertical acceleration, m/s^2 (a pull-up or push-over's load factor change times g).
    speed_mps : float
        Largest speed through the air mass plus a strong wind, m/s.
    window_s : float
        Accelerations of a checked trajectory are velocity changes over this window, s: a parametric
        path puts a transition (level-off, roll-in) into a kink that an aircraft flies in a second or
        two, and over the window the kink counts at its true average acceleration.

    Examples
    --------
    >>> ga = AIRCRAFT_CLASSES["ga"]
    >>> round(ga.horizontal_accel_mps2 / GRAVITY_MPS2, 2), round(ga.vertical_accel_mps2 / GRAVITY_MPS2, 2)
    (1.02, 0.5)
    """

    name: str
    horizontal_accel_mps2: float
    vertical_accel_mps2: float
    speed_mps: float
    window_s: float = 2.0

    def __post_init__(self) -> None:
        for key in ("horizontal_accel_mps2", "vertical_accel_mps2", "speed_mps", "window_s"):
            value = float(getattr(self, key))
            if not np.isfinite(value) or value <= 0:
                raise InputError(f"kinematic limits '{self.name}': field '{key}' must be > 0, got {value!r}")


# GA and gliders turn at up to about 45 deg of bank (g tan 45 = 9.8 m/s^2; 10 allows the along-track
# acceleration on top) and pull at most about 0.5 g beyond 1 g in normal flight; 160 m/s (310 kt) is a
# fast turboprop's cruise, and a glider's never-exceed speed is about 75 m/s. Transport
# aircraft bank at most about 30 deg (5.7 m/s^2) and keep vertical load changes near 0.3 g.
AIRCRAFT_CLASSES: dict[str, KinematicLimits] = {
    "ga": KinematicLimits("ga", 10.0, 0.5 * GRAVITY_MPS2, 160.0),
    "glider": KinematicLimits("glider", 10.0, 0.5 * GRAVITY_MPS2, 80.0),
    "transport": KinematicLimits("transport", 6.0, 0.3 * GRAVITY_MPS2, 330.0),
    # Traffic of unknown type (an ATC radar's picture): GA turns at jet speeds.
    "any": KinematicLimits("any", 10.0, 0.5 * GRAVITY_MPS2, 343.0),
}

MAX_DROPPED_SHARE = 0.25  # a file that loses more of its fixes than this is not one aircraft's flight
_STALE_M = 0.5  # a position repeated within this while the aircraft moves is a repeat, not a fix, m
_MOVING_MPS = 5.0
_OUTLIER_SPREADS = 5.0
_OUTLIER_FLOOR_M = 30.0
_SIGNIFICANT_LAG_S = 0.2
_LAG_PASSES = 12
_Q_STEPS = 9  # the likelihood search tries the starting process noise and 8 quarterings of it
_POSITION_SIGMA_GRID_M = (2.0, 4.0, 8.0, 16.0, 32.0, 64.0)
_VELOCITY_SIGMA_GRID_MPS = (0.3, 1.0, 3.0)
_SPEED_MARGIN = 0.98  # speeds between the grid's samples may exceed theirs by a little
_MAX_NOISE_HALVINGS = 24


@dataclass(frozen=True)
class FlyablePath:
    """A path built from fixes: uniform-grid states and what was repaired.

    Attributes
    ----------
    time_s : ndarray, shape (m,)
        Grid times, s (the fixes' span).
    position_ned_m, velocity_ned_mps, acceleration_ned_mps2 : ndarray, shape (m, 3)
        Smoothed states in the fixes' NED frame.
    kept : ndarray of bool, shape (n,)
        Which input fixes the path was fitted to.
    lag_s : float
        Lag of the positions behind the reported velocities, s (0 when not significant or no
        velocities were given); the kept fixes' positions belong to ``time - lag_s``.
    notes : list of str
        One phrase per repair, naming the rows.

    Examples
    --------
    Fixes every 2 s of a level 50 m/s flight north, with velocities: nothing to repair, the path
    flies them at 50 m/s on a 0.5 s grid.

    >>> t = np.arange(0.0, 40.0, 2.0)
    >>> fixes = np.column_stack([50.0 * t, 0 * t, 0 * t - 1000.0])
    >>> vel = np.tile([50.0, 0.0, 0.0], (t.size, 1))
    >>> path = flyable_path(t, fixes, vel, AIRCRAFT_CLASSES["ga"])
    >>> bool(path.kept.all()), path.lag_s, path.notes, float(np.diff(path.time_s)[0])
    (True, 0.0, [], 0.5)
    >>> bool(np.allclose(path.velocity_ned_mps, [50.0, 0.0, 0.0], atol=0.01))
    True
    >>> bool(np.allclose(path.position_ned_m[:, 0], 50.0 * path.time_s, atol=0.1))
    True
    """

    time_s: np.ndarray
    position_ned_m: np.ndarray
    velocity_ned_mps: np.ndarray
    acceleration_ned_mps2: np.ndarray
    kept: np.ndarray
    lag_s: float
    notes: list[str]


def hermite_accelerations(
    time_s: np.ndarray, position_m: np.ndarray, velocity_mps: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Accelerations at both ends of each interval of the cubic Hermite spline through the samples.

    A cubic's acceleration is linear over an interval, so these two ends bound it everywhere.

    Parameters
    ----------
    time_s : ndarray, shape (n,)
        Strictly increasing times, s.
    position_m, velocity_mps : ndarray, shape (n, 3)
        Positions (m) and velocities (m/s) at those times.

    Returns
    -------
    start, end : ndarray, shape (n - 1, 3)
        Acceleration at the start and at the end of each interval, m/s^2.

    Examples
    --------
    >>> t = np.array([0.0, 2.0])
    >>> p = np.array([[0.0, 0, 0], [4.0, 0, 0]])
    >>> v = np.array([[0.0, 0, 0], [4.0, 0, 0]])
    >>> start, end = hermite_accelerations(t, p, v)   # x = t^2: 2 m/s^2 throughout
    >>> float(start[0, 0]), float(end[0, 0])
    (2.0, 2.0)
    """
    h = np.diff(time_s)[:, None]
    dp = np.diff(position_m, axis=0)
    v0, v1 = velocity_mps[:-1], velocity_mps[1:]
    start = (6.0 * dp - h * (4.0 * v0 + 2.0 * v1)) / h**2
    end = (-6.0 * dp + h * (2.0 * v0 + 4.0 * v1)) / h**2
    return start, end


def kinematic_violation(
    time_s: np.ndarray, velocity_ned_mps: np.ndarray, limits: KinematicLimits
) -> tuple[float, str] | None:
    """The first time a trajectory's motion is beyond ``limits``, or None.

    Speeds are checked at every sample; accelerations as velocity changes over ``limits.window_s``.

    Parameters
    ----------
    time_s : ndarray, shape (n,)
        Strictly increasing sample times, s.
    velocity_ned_mps : ndarray, shape (n, 3)
        Velocities (north, east, down), m/s.
    limits : KinematicLimits

    Returns
    -------
    (time_s, what) or None
        When, and a phrase saying which limit and by how much.

    Examples
    --------
    >>> t = np.arange(0.0, 10.0, 0.1)
    >>> v = np.zeros((t.size, 3)); v[:, 0] = 50.0; v[t >= 5, 0] = 80.0  # +30 m/s in one step
    >>> kinematic_violation(t, v, AIRCRAFT_CLASSES["ga"])  # the first 2-s window holding the step
    (3.0, 'horizontal acceleration 15 m/s^2 over 2 s (ga limit 10 m/s^2)')
    >>> v[:, 0] = np.linspace(50.0, 60.0, t.size)  # 1 m/s^2
    >>> kinematic_violation(t, v, AIRCRAFT_CLASSES["ga"]) is None
    True
    """
    t = np.asarray(time_s, float)
    v = np.asarray(velocity_ned_mps, float)
    speed = np.linalg.norm(v, axis=1)
    if np.any(speed > limits.speed_mps):
        i = int(np.argmax(speed > limits.speed_mps))
        return float(t[i]), f"speed {speed[i]:.0f} m/s ({limits.name} limit {limits.speed_mps:.0f} m/s)"
    if t[-1] - t[0] < limits.window_s:
        window = t[-1] - t[0]
        later = np.full(t.size, t.size - 1)
    else:
        window = limits.window_s
        later = np.searchsorted(t, t + window - 1e-9)
    valid = (later < t.size) & (t[np.minimum(later, t.size - 1)] > t)
    i0 = np.flatnonzero(valid)
    if i0.size == 0 or window <= 0:
        return None
    i1 = later[i0]
    dt = (t[i1] - t[i0])[:, None]
    accel = (v[i1] - v[i0]) / dt
    horizontal = np.hypot(accel[:, 0], accel[:, 1])
    vertical = np.abs(accel[:, 2])
    bad_h = horizontal > limits.horizontal_accel_mps2 * (1 + 1e-6)
    bad_v = vertical > limits.vertical_accel_mps2 * (1 + 1e-6)
    if not (bad_h.any() or bad_v.any()):
        return None
    k = int(np.argmax(bad_h | bad_v))
    if bad_h[k]:
        what, value, limit = "horizontal", horizontal[k], limits.horizontal_accel_mps2
    else:
        what, value, limit = "vertical", vertical[k], limits.vertical_accel_mps2
    return float(t[i0[k]]), (
        f"{what} acceleration {value:.3g} m/s^2 over {window:.3g} s ({limits.name} limit {limit:.3g} m/s^2)"
    )


@njit(cache=True)
def _forward(t, z_pos, r_pos, z_vel, r_vel, q):  # pragma: no cover - compiled
    """One axis' Kalman filter (position, velocity; white-noise acceleration of density ``q``) with
    scalar updates: filtered and predicted states and covariances, and the measurements'
    log-likelihood (the first position only starts the filter). NaN measurements are skipped.

    The 2 x 2 algebra is written out in scalars (the covariance as p00, p01, p11): numba compiles
    that in a fraction of the time its matrix products and ``np.linalg.inv`` take."""
    n = t.size
    xf = np.zeros((n, 2))
    pf = np.zeros((n, 2, 2))
    xp = np.zeros((n, 2))
    pp = np.zeros((n, 2, 2))
    first = 0
    while first < n and not np.isfinite(z_pos[first]):
        first += 1
    x0 = z_pos[first] if first < n else 0.0
    x1 = 0.0
    p00, p01, p11 = 1e8, 0.0, 1e6
    total = 0.0
    for k in range(n):
        if k > 0:
            dt = t[k] - t[k - 1]
            x0 += dt * x1
            p00 += 2.0 * dt * p01 + dt * dt * p11 + q * dt**3 / 3.0
            p01 += dt * p11 + q * dt**2 / 2.0
            p11 += q * dt
        xp[k, 0], xp[k, 1] = x0, x1
        pp[k, 0, 0], pp[k, 0, 1], pp[k, 1, 0], pp[k, 1, 1] = p00, p01, p01, p11
        for j in range(2):
            z = z_pos[k] if j == 0 else z_vel[k]
            r = r_pos[k] if j == 0 else r_vel[k]
            if np.isfinite(z):
                pj0, pj1 = (p00, p01) if j == 0 else (p01, p11)  # row j of P (= column j)
                s = (p00 if j == 0 else p11) + r
                innovation = z - (x0 if j == 0 else x1)
                if k > first:
                    total -= 0.5 * (np.log(2.0 * np.pi * s) + innovation * innovation / s)
                g0, g1 = pj0 / s, pj1 / s
                x0 += g0 * innovation
                x1 += g1 * innovation
                p00, p01, p11 = p00 - g0 * pj0, p01 - g0 * pj1, p11 - g1 * pj1
        xf[k, 0], xf[k, 1] = x0, x1
        pf[k, 0, 0], pf[k, 0, 1], pf[k, 1, 0], pf[k, 1, 1] = p00, p01, p01, p11
    return xf, pf, xp, pp, total


@njit(cache=True)
def _rts_axis(t, z_pos, r_pos, z_vel, r_vel, q):  # pragma: no cover - compiled
    """Smoothed (position, velocity) of one axis: :func:`_forward`, then the RTS pass back.

    The gain C = Pf F^T Pp^-1 is written out for F = [[1, dt], [0, 1]] and a symmetric Pp."""
    xf, pf, xp, pp, _total = _forward(t, z_pos, r_pos, z_vel, r_vel, q)
    xs = xf.copy()
    for k in range(t.size - 2, -1, -1):
        dt = t[k + 1] - t[k]
        a00 = pf[k, 0, 0] + dt * pf[k, 0, 1]  # Pf F^T
        a10 = pf[k, 1, 0] + dt * pf[k, 1, 1]
        a01, a11 = pf[k, 0, 1], pf[k, 1, 1]
        b00, b01, b11 = pp[k + 1, 0, 0], pp[k + 1, 0, 1], pp[k + 1, 1, 1]
        det = b00 * b11 - b01 * b01
        i00, i01, i11 = b11 / det, -b01 / det, b00 / det  # Pp^-1
        c00, c01 = a00 * i00 + a01 * i01, a00 * i01 + a01 * i11
        c10, c11 = a10 * i00 + a11 * i01, a10 * i01 + a11 * i11
        d0, d1 = xs[k + 1, 0] - xp[k + 1, 0], xs[k + 1, 1] - xp[k + 1, 1]
        xs[k, 0] = xf[k, 0] + c00 * d0 + c01 * d1
        xs[k, 1] = xf[k, 1] + c10 * d0 + c11 * d1
    return xs


def _noise_by_likelihood(
    pos_t: np.ndarray, pos: np.ndarray, vel_t: np.ndarray, vel: np.ndarray | None, q0: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(q, sigma_p, sigma_v) per axis that make the fixes most likely (a grid search).

    The horizontal axes share their values (an aircraft's noise and manoeuvres have no preferred
    horizontal direction); the vertical axis has its own.
    """
    times, (at_pos, at_vel) = _grid((pos_t, vel_t), np.inf)
    q_grid = [q0 * 4.0**-k for k in range(_Q_STEPS)]
    sp_grid = _POSITION_SIGMA_GRID_M
    sv_grid = _VELOCITY_SIGMA_GRID_MPS if vel is not None else (1.0,)
    best_q, best_sp, best_sv = q0.copy(), np.array([30.0, 30.0, 15.0]), np.array([2.0, 2.0, 1.0])
    for axes in ((0, 1), (2,)):
        z = []
        for a in axes:
            z_pos = np.full(times.size, np.nan)
            z_vel = np.full(times.size, np.nan)
            z_pos[at_pos] = pos[:, a]
            if vel is not None:
                z_vel[at_vel] = vel[:, a]
            z.append((z_pos, z_vel))
        best = -np.inf
        for q in q_grid:
            for sp in sp_grid:
                for sv in sv_grid:
                    r_p, r_v = np.full(times.size, sp**2), np.full(times.size, sv**2)
                    ll = sum(_forward(times, zp, r_p, zv, r_v, q[axes[0]])[4] for zp, zv in z)
                    if ll > best:
                        best = ll
                        best_q[list(axes)] = q[axes[0]]
                        best_sp[list(axes)] = sp
                        best_sv[list(axes)] = sv
    return best_q, best_sp, best_sv


def _grid(times_s: tuple[np.ndarray, ...], step_s: float) -> tuple[np.ndarray, list[np.ndarray]]:
    """A uniform grid over the span of ``times_s`` with every given time in it; (grid, their indices)."""
    every = np.unique(np.concatenate(times_s))
    uniform = np.arange(every[0], every[-1], step_s) if np.isfinite(step_s) else every[:1]
    idx = np.clip(np.searchsorted(every, uniform), 1, every.size - 1)
    near = np.minimum(np.abs(uniform - every[idx - 1]), np.abs(uniform - every[idx]))
    grid = np.union1d(uniform[near > 0.05 * step_s], every)
    return grid, [np.searchsorted(grid, times) for times in times_s]


def _smooth(grid, at_pos, pos, at_vel, vel, sigma_p, sigma_v, q) -> np.ndarray:
    """Smoothed states (m, 3 axes, 2: position, velocity) on the grid.

    Positions are measured at the grid indices ``at_pos``, velocities at ``at_vel``.
    """
    out = np.empty((grid.size, 3, 2))
    for axis in range(3):
        z_pos = np.full(grid.size, np.nan)
        z_vel = np.full(grid.size, np.nan)
        z_pos[at_pos] = pos[:, axis]
        if vel is not None:
            z_vel[at_vel] = vel[:, axis]
        r_pos = np.full(grid.size, sigma_p[axis] ** 2)
        r_vel = np.full(grid.size, sigma_v[axis] ** 2)
        out[:, axis, :] = _rts_axis(grid, z_pos, r_pos, z_vel, r_vel, q[axis])
    return out


def _robust_sd(values: np.ndarray) -> float:
    values = values[np.isfinite(values)]
    if values.size == 0:
        return 0.0
    return float(1.4826 * np.median(np.abs(values - np.median(values))))


def _rows_phrase(rows: np.ndarray) -> str:
    shown = ", ".join(str(int(r)) for r in rows[:6])
    return f"row{'s' if rows.size > 1 else ''} {shown}{', ...' if rows.size > 6 else ''}"


def _within(states: np.ndarray, grid: np.ndarray, limits: KinematicLimits) -> tuple[bool, bool]:
    """(horizontal within, vertical within): the Hermite spline's acceleration everywhere."""
    start, end = hermite_accelerations(grid, states[:, :, 0], states[:, :, 1])
    both = np.concatenate([start, end])
    horizontal = float(np.hypot(both[:, 0], both[:, 1]).max(initial=0.0))
    vertical = float(np.abs(both[:, 2]).max(initial=0.0))
    return horizontal <= limits.horizontal_accel_mps2, vertical <= limits.vertical_accel_mps2


def flyable_path(
    time_s: np.ndarray,
    position_ned_m: np.ndarray,
    velocity_ned_mps: np.ndarray | None,
    limits: KinematicLimits,
    *,
    rows: np.ndarray | None = None,
    step_s: float = 0.5,
    label: str = "fixes",
    ground_speed_mps: np.ndarray | None = None,
) -> FlyablePath:
    """A path within ``limits`` through recorded fixes (module docstring: the rules).

    Parameters
    ----------
    time_s : ndarray, shape (n,)
        Strictly increasing fix times, s.
    position_ned_m : ndarray, shape (n, 3)
        Fix positions in a local NED frame, m.
    velocity_ned_mps : ndarray, shape (n, 3), optional
        Reported velocities (ground speed, track, vertical rate) in the same frame, m/s; NaN rows
        where a fix has none.
    limits : KinematicLimits
        The aircraft class's limits.
    rows : ndarray of int, optional
        The fixes' row numbers in the file, for the notes; default 0..n-1.
    step_s : float
        Grid step of the built path, s; the fixes' own times are added to the grid.
    label : str
        Names the input in errors (a file path).
    ground_speed_mps : ndarray, shape (n,), optional
        Reported ground speeds, m/s, for a file whose track cannot be used (``velocity_ned_mps``
        None): the path's own direction at each fix, refined with each pass, carries them.

    Returns
    -------
    FlyablePath

    Raises
    ------
    InputError
        When more than :data:`MAX_DROPPED_SHARE` of the fixes cannot be reconciled with a path, or
        no path within the limits fits them.

    Examples
    --------
    A 60 m/s aircraft circling at 6 m/s^2 whose position fixes lag its velocity by 1.5 s and carry
    10 m of noise:

    >>> rng = np.random.default_rng(1)
    >>> t = np.arange(0.0, 120.0, 1.0)
    >>> w = 0.1  # rad/s
    >>> def circle(t): return np.column_stack([600 * np.sin(w * t), 600 * (1 - np.cos(w * t)), -1000 + 0 * t])
    >>> fixes = circle(t - 1.5) + rng.normal(0, 10, (t.size, 3))
    >>> vel = np.column_stack([60 * np.cos(w * t), 60 * np.sin(w * t), 0 * t])
    >>> path = flyable_path(t, fixes, vel, AIRCRAFT_CLASSES["ga"])
    >>> speed_error = np.abs(np.linalg.norm(path.velocity_ned_mps, axis=1) - 60.0)
    >>> round(path.lag_s, 1), bool(np.median(speed_error) < 0.5), bool(speed_error.max() < 2.0)
    (1.5, True, True)
    """
    t = np.asarray(time_s, float)
    pos = np.asarray(position_ned_m, float)
    vel = None if velocity_ned_mps is None else np.asarray(velocity_ned_mps, float)
    rows = np.arange(t.size) if rows is None else np.asarray(rows)
    notes: list[str] = []
    keep = np.ones(t.size, bool)
    # Stale repeats: the same position again while the aircraft moves.
    step = np.linalg.norm(np.diff(pos, axis=0), axis=1)
    moving = np.ones(t.size - 1, bool)
    if vel is not None:
        speed = np.linalg.norm(vel[1:, :2], axis=1)
        moving = ~(speed < _MOVING_MPS)  # NaN speed: assume moving
    stale = np.concatenate([[False], (step < _STALE_M) & moving])
    if stale.any():
        keep &= ~stale
        notes.append(
            f"dropped {int(stale.sum())} stale fix(es) repeating the last position "
            f"({_rows_phrase(rows[stale])})"
        )
    # Jumps: a fix out of reach, at the class's top speed, of the flight around it.
    kept_idx = np.flatnonzero(keep)
    out_of_reach = np.zeros(t.size, bool)
    out_of_reach[kept_idx] = glitch_rows(pos[kept_idx], t[kept_idx], limits.speed_mps)
    if out_of_reach.any():
        keep &= ~out_of_reach
        notes.append(
            f"dropped {int(out_of_reach.sum())} fix(es) out of reach at the {limits.name} class's "
            f"{limits.speed_mps:g} m/s ({_rows_phrase(rows[out_of_reach])})"
        )
    heading_from_path = vel is None and ground_speed_mps is not None
    if heading_from_path:
        vel = np.full((t.size, 3), np.nan)  # horizontal filled from the path's direction below
    has_vel = vel is not None and np.isfinite(vel[:, :2]).all(axis=1).sum() >= 3 or heading_from_path
    fit_vel = vel if has_vel else None  # the velocities the smoother follows (None: positions only)
    limit = np.array([limits.horizontal_accel_mps2, limits.horizontal_accel_mps2, limits.vertical_accel_mps2])
    # Acceleration spectral density: a velocity change of the class's full acceleration held over a
    # typical interval between fixes is one standard deviation, so the first fit follows a hard turn
    # between sparse fixes; it is lowered below until the path keeps within the limits.
    typical_dt = float(np.median(np.diff(t))) if t.size > 1 else 1.0
    q = limit**2 * max(typical_dt, 1.0)
    sigma_p = np.array([30.0, 30.0, 15.0])
    sigma_v = np.array([2.0, 2.0, 1.0])
    lag = 0.0

    def fit(q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(grid, states, grid index of each kept fix's position) for the kept fixes at ``lag``."""
        pos_t = t[keep] - lag
        if pos_t.size < 2:
            raise InputError(f"{label}: fewer than 2 usable fixes after repairs")
        vel_rows = keep & vel_ok
        grid, (at_pos, at_vel) = _grid((pos_t, t[vel_rows]), step_s)
        v = None if fit_vel is None else fit_vel[vel_rows]
        return grid, _smooth(grid, at_pos, pos[keep], at_vel, v, sigma_p, sigma_v, q), at_pos

    lag_passes = _LAG_PASSES if has_vel and not heading_from_path else 0
    q0 = q.copy()

    def carry_ground_speed(grid: np.ndarray, states: np.ndarray) -> None:
        """The reported ground speeds along the path's direction at each fix."""
        at = np.clip(np.searchsorted(grid, t - lag), 0, grid.size - 1)
        horizontal = states[at, :2, 1]
        norm = np.linalg.norm(horizontal, axis=1, keepdims=True)
        assert fit_vel is not None and ground_speed_mps is not None  # heading_from_path
        fit_vel[:, :2] = np.where(
            norm > _MOVING_MPS, ground_speed_mps[:, None] * horizontal / np.maximum(norm, 1e-9), np.nan
        )

    vel_ok = np.zeros(t.size, bool)
    grid, states, _at = fit(q)  # positions only, or the reported velocities at the default noise
    for _pass in range(lag_passes + 4):
        if heading_from_path:
            carry_ground_speed(grid, states)
        if fit_vel is not None:
            vel_ok = np.isfinite(fit_vel[:, :2]).all(axis=1)
        if _pass >= lag_passes:  # the noise that makes the kept fixes most likely
            rows_v = keep & vel_ok
            q, sigma_p, sigma_v = _noise_by_likelihood(
                t[keep] - lag, pos[keep], t[rows_v], None if fit_vel is None else fit_vel[rows_v], q0
            )
        grid, states, at = fit(q)
        offset = pos[keep] - states[at, :, 0]
        if _pass < lag_passes:
            # A lag shows only where the velocity changes (on a straight line it shifts nothing); the
            # smoother absorbs part of it in each pass, so the estimate is refined a few times.
            v_at = states[at, :, 1]
            lag_step = -float(np.sum(offset * v_at) / np.sum(v_at * v_at))
            lag += lag_step
            if abs(lag_step) > 0.01 and _pass < lag_passes - 1:
                continue
            lag_passes = _pass + 1
            if abs(lag) < _SIGNIFICANT_LAG_S:
                lag = 0.0
            continue
        spread = np.maximum([_robust_sd(offset[:, a]) for a in range(3)], sigma_p)
        far = np.any(np.abs(offset) > np.maximum(_OUTLIER_SPREADS * spread, _OUTLIER_FLOOR_M), axis=1)
        if not far.any():
            break
        keep[np.flatnonzero(keep)[far]] = False
        if (~keep).sum() > MAX_DROPPED_SHARE * t.size or keep.sum() < 2:
            raise InputError(
                f"{label}: {int((~keep).sum())} of {t.size} fixes cannot be reconciled with one flyable "
                f"path (at most {MAX_DROPPED_SHARE:.0%} may be repaired)"
            )
    if lag:
        notes.append(f"positions re-timed by {-lag:+.2f} s to the reported velocity (they lagged it)")
    off_path = ~keep & ~stale & ~out_of_reach
    if off_path.any():
        notes.append(
            f"dropped {int(off_path.sum())} fix(es) off any flyable path ({_rows_phrase(rows[off_path])})"
        )
    too_fast = np.zeros(t.size, bool)
    while True:
        for _halving in range(_MAX_NOISE_HALVINGS):
            grid, states, _ = fit(q)
            ok_h, ok_v = _within(states, grid, limits)
            if ok_h and ok_v:
                break
            q[:2] *= 1.0 if ok_h else 0.25
            q[2] *= 1.0 if ok_v else 0.25
        else:
            raise InputError(
                f"{label}: no path within the {limits.name} limits ({limits.horizontal_accel_mps2:g} m/s^2 "
                f"horizontal, {limits.vertical_accel_mps2:g} m/s^2 vertical) fits the fixes"
            )
        # A path bridging a gap may need more speed than the class has (the fixes on either side of
        # it disagree): the fix that ends the fastest stretch is out of reach.
        speed = np.linalg.norm(states[:, :, 1], axis=1)
        if speed.max() <= _SPEED_MARGIN * limits.speed_mps:
            break
        kept_idx = np.flatnonzero(keep)
        fast = speed > _SPEED_MARGIN * limits.speed_mps
        edges = np.flatnonzero(np.diff(np.concatenate([[0], fast.astype(np.int8), [0]])))
        peaks = [a + int(np.argmax(speed[a:b])) for a, b in zip(edges[::2], edges[1::2], strict=True)]
        after = np.minimum(np.searchsorted(t[kept_idx] - lag, grid[peaks]), kept_idx.size - 1)
        keep[kept_idx[after]] = False
        too_fast[kept_idx[after]] = True
        if (~keep).sum() > MAX_DROPPED_SHARE * t.size or keep.sum() < 2:
            raise InputError(
                f"{label}: {int((~keep).sum())} of {t.size} fixes cannot be flown within the {limits.name} "
                f"class's {limits.speed_mps:g} m/s (at most {MAX_DROPPED_SHARE:.0%} may be repaired)"
            )
    if (~keep).sum() > MAX_DROPPED_SHARE * t.size:
        raise InputError(
            f"{label}: {int((~keep).sum())} of {t.size} fixes cannot be reconciled with one flyable path "
            f"(at most {MAX_DROPPED_SHARE:.0%} may be repaired)"
        )
    if too_fast.any():
        notes.append(
            f"dropped {int(too_fast.sum())} fix(es) that only a path faster than {limits.speed_mps:g} m/s "
            f"reaches ({_rows_phrase(rows[too_fast])})"
        )
    start, _end = hermite_accelerations(grid, states[:, :, 0], states[:, :, 1])
    accel = np.vstack([start, _end[-1:]])
    return FlyablePath(grid, states[:, :, 0], states[:, :, 1], accel, keep, lag, notes)
