"""Own-ship navigation with errors: what the aircraft's GNSS and AHRS report instead of the truth.

The error model (:class:`skyradar.scene.navigation_config.NavigationConfig`, whose docstring gives
the ``ga-typical`` values and their sources) is, per axis, white noise per sample plus a
first-order Gauss-Markov bias (:func:`gauss_markov`) started from its stationary distribution, so
a short flight sees a near-constant offset of random size and sign; each sensor's data is also a
little late (the truth ``gnss_latency_s`` / ``ahrs_latency_s`` earlier, linearly interpolated).

:func:`navigation_solution` turns own-ship truth (``own_*`` arrays) into the navigation solution
(``nav_*`` arrays, same suffixes); :func:`navigation_variables` does it for a built scenario,
seeded from ``navigation.seed`` or else ``simulation.seed``. Every error group draws from its
own random stream whatever its size, so ``only-heading`` sees exactly ``ga-typical``'s heading
error: the cost of each error can be compared on one realisation.

This is also the home of the AHRS attitude model the flight-state chapter uses (:func:`ahrs_attitude`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass

import numpy as np

from skyradar.errors import InputError
from skyradar.geo import ned_to_geodetic
from skyradar.scene.navigation_config import NavigationConfig, navigation_config
from skyradar.units import wrap_angle

__all__ = [
    "AhrsModel",
    "ahrs_attitude",
    "gauss_markov",
    "navigation_at_frame",
    "navigation_solution",
    "navigation_variables",
]

_NAV_TAG = 0x6E6176  # "nav": keeps the navigation streams apart from the simulator's noise seeds
_XYZ = ("north", "east", "down")
_VXYZ = ("vn", "ve", "vd")
_ATT = ("yaw", "pitch", "roll")


@dataclass(frozen=True)
class AhrsModel:
    """1-sigma attitude errors of an AHRS, deg, and bias correlation times, s.

    Defaults: a MEMS AHRS of the VectorNav VN-100 datasheet class (pitch/roll 0.5 deg RMS static,
    1.0 deg dynamic; magnetic heading 2.0 deg RMS): pitch and roll 0.1 deg white plus a 0.3 deg
    bias, heading 0.2 deg white plus a 1.5 deg bias; bias correlation times 100 s and 300 s.

    Examples
    --------
    >>> AhrsModel().roll_pitch_bias_deg
    0.3
    """

    roll_pitch_noise_deg: float = 0.1
    roll_pitch_bias_deg: float = 0.3
    roll_pitch_tau_s: float = 100.0
    heading_noise_deg: float = 0.2
    heading_bias_deg: float = 1.5
    heading_tau_s: float = 300.0

    def as_dict(self) -> dict[str, float]:
        """The model's fields (for a result file)."""
        return asdict(self)


def gauss_markov(times_s: np.ndarray, sd: float, tau_s: float, rng: np.random.Generator) -> np.ndarray:
    """First-order Gauss-Markov sequence of stationary SD ``sd`` sampled at ``times_s``.

    Examples
    --------
    >>> x = gauss_markov(np.arange(0.0, 2e5), 2.0, 10.0, np.random.default_rng(0))
    >>> round(float(x.std()), 1)
    2.0
    """
    out = np.empty(times_s.size)
    if times_s.size == 0:
        return out
    out[0] = rng.normal(0.0, sd)  # stationary start: the bias is already there at take-off
    decay = np.exp(-np.diff(times_s) / tau_s)
    kicks = rng.normal(0.0, 1.0, times_s.size - 1) * sd * np.sqrt(1.0 - decay**2)
    for i in range(1, times_s.size):
        out[i] = decay[i - 1] * out[i - 1] + kicks[i - 1]
    return out


def _check(times: np.ndarray, attitude: np.ndarray, model: AhrsModel) -> None:
    if attitude.ndim != 2 or attitude.shape[1] != 3 or attitude.shape[0] != times.size:
        raise InputError(
            f"AHRS: field 'attitude_rad' must have shape ({times.size}, 3), got {attitude.shape}"
        )
    if times.size and (not np.all(np.isfinite(times)) or np.any(np.diff(times) < 0)):
        raise InputError("AHRS: field 'times_s' must be finite and non-decreasing")
    for name, value in model.as_dict().items():
        bad = not np.isfinite(value) or value < 0 or (name.endswith("tau_s") and value == 0)
        if bad:
            raise InputError(f"AHRS: field '{name}' must be finite and >= 0 (tau > 0), got {value!r}")


def _wrap(yaw: np.ndarray) -> np.ndarray:
    # Wrap only what left [-pi, pi): the rest stays bit-exact (a zero model returns the truth).
    return np.where((yaw < -np.pi) | (yaw >= np.pi), wrap_angle(yaw), yaw)


def ahrs_attitude(
    true_attitude_rad: np.ndarray,
    times_s: np.ndarray,
    model: AhrsModel | None = None,
    seed: int | list[int] = 0,
) -> np.ndarray:
    """The attitude an AHRS reports: truth plus seeded noise and slowly varying bias.

    Parameters
    ----------
    true_attitude_rad : ndarray, shape (n, 3)
        True (yaw, pitch, roll), rad.
    times_s : ndarray, shape (n,)
        Sample times, s (finite, non-decreasing).
    model : AhrsModel, optional
        Error model; default :class:`AhrsModel` (typical MEMS AHRS).
    seed : int or list of int
        Random seed (``numpy.random.default_rng``): same seed, same errors.

    Returns
    -------
    ndarray, shape (n, 3)
        Reported (yaw, pitch, roll), rad; yaw wrapped to [-pi, pi).

    Examples
    --------
    >>> t = np.arange(0.0, 40.0)
    >>> att = ahrs_attitude(np.zeros((t.size, 3)), t, seed=5)
    >>> err_deg = np.degrees(att)
    >>> bool(np.all(np.abs(err_deg[:, 1:]) < 2.0)), bool(np.all(np.abs(err_deg[:, 0]) < 8.0))
    (True, True)
    >>> bool(np.array_equal(att, ahrs_attitude(np.zeros((t.size, 3)), t, seed=5)))
    True
    """
    model = model or AhrsModel()
    times = np.asarray(times_s, float).ravel()
    truth = np.asarray(true_attitude_rad, float)
    _check(times, truth, model)
    if times.size == 0:
        return truth.copy()
    rng = np.random.default_rng(seed)
    axes = (
        (model.heading_noise_deg, model.heading_bias_deg, model.heading_tau_s),
        (model.roll_pitch_noise_deg, model.roll_pitch_bias_deg, model.roll_pitch_tau_s),
        (model.roll_pitch_noise_deg, model.roll_pitch_bias_deg, model.roll_pitch_tau_s),
    )
    err_deg = np.column_stack([_errors(times, bias, tau, noise, rng) for noise, bias, tau in axes])
    out = truth + np.radians(err_deg)
    out[:, 0] = _wrap(out[:, 0])
    return out


def _delayed(values: np.ndarray, times: np.ndarray, latency_s: float, angle: bool = False) -> np.ndarray:
    """``values`` as they were ``latency_s`` earlier (linear; held at the first sample before it)."""
    if latency_s == 0.0 or times.size < 2:
        return values
    if angle:
        return _wrap(np.interp(times - latency_s, times, np.unwrap(values)))
    return np.interp(times - latency_s, times, values)


def _errors(times: np.ndarray, bias: float, tau: float, noise: float, rng) -> np.ndarray:
    """One axis: Gauss-Markov bias plus white noise (always drawn, so streams stay aligned)."""
    return gauss_markov(times, bias, tau, rng) + rng.normal(0.0, noise, times.size)


def _f(truth: Mapping[str, np.ndarray], name: str) -> np.ndarray:
    return np.asarray(truth[name], float)


def _gnss(truth, times: np.ndarray, cfg: NavigationConfig, seed: int) -> tuple[np.ndarray, ...]:
    """GNSS position error, position and velocity, (n, 3) NED each (streams 0 and 1)."""
    streams = [np.random.default_rng([seed, _NAV_TAG, k]) for k in range(2)]
    late = cfg.gnss_latency_s
    pos = np.stack([_delayed(_f(truth, f"own_{a}_m"), times, late) for a in _XYZ], -1)
    vel = np.stack([_delayed(_f(truth, f"own_{a}_mps"), times, late) for a in _VXYZ], -1)
    h = (cfg.gnss_horizontal_bias_m, cfg.gnss_horizontal_noise_m)
    v = (cfg.gnss_vertical_bias_m, cfg.gnss_vertical_noise_m)
    tau = cfg.gnss_position_tau_s
    pos_err = np.stack([_errors(times, b, tau, s, streams[0]) for b, s in (h, h, v)], -1)
    vel_noise = (cfg.gnss_velocity_noise_mps,) * 2 + (cfg.gnss_vertical_velocity_noise_mps,)
    bias, tau = cfg.gnss_velocity_bias_mps, cfg.gnss_velocity_tau_s
    vel_err = np.stack([_errors(times, bias, tau, s, streams[1]) for s in vel_noise], -1)
    return pos_err, pos + pos_err, vel + vel_err


def _geodetic(nav_pos, down_err, truth, times, latency_s, origin, terrain_height) -> dict[str, np.ndarray]:
    """Latitude, longitude, altitude and height above the terrain (database) of the GNSS position."""
    lat, lon, alt = (np.asarray(x, float) for x in ned_to_geodetic(nav_pos, *origin))
    out = {"nav_lat_deg": lat, "nav_lon_deg": lon, "nav_alt_m": alt}
    if terrain_height is not None:
        out["nav_height_agl_m"] = alt - np.asarray(terrain_height(lat, lon), float)
    elif "own_height_agl_m" in truth:
        out["nav_height_agl_m"] = _delayed(_f(truth, "own_height_agl_m"), times, latency_s) - down_err
    return out


def navigation_solution(
    truth: Mapping[str, np.ndarray],
    times_s: np.ndarray,
    config: NavigationConfig | str | dict | None,
    seed: int,
    origin: tuple[float, float, float],
    terrain_height: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None,
) -> dict[str, np.ndarray]:
    """The ``nav_*`` navigation solution of own-ship truth ``own_*`` (see the module docstring).

    Parameters
    ----------
    truth : mapping
        ``own_north_m .. own_vd_mps``, ``own_yaw_rad .. own_roll_rad`` and optionally
        ``own_height_agl_m``, arrays of shape (n,), NED at ``origin``.
    times_s : ndarray, shape (n,)
        Sample times, s (finite, non-decreasing).
    config : NavigationConfig, model name or dict
        The error model (:func:`skyradar.scene.navigation_config.navigation_config`).
    seed : int
        Random seed: same seed, same errors.
    origin : (lat_deg, lon_deg, alt_m)
        Geodetic origin of the NED frame; gives ``nav_lat_deg, nav_lon_deg, nav_alt_m``.
    terrain_height : callable(lat_deg, lon_deg) -> height_m, optional
        Terrain database: ``nav_height_agl_m`` is the navigation altitude above it at the
        navigation position. Without it, the truth height plus the vertical error.

    Returns
    -------
    dict of ndarray
        ``nav_<suffix>`` for every ``own_<suffix>`` the solution covers.

    Examples
    --------
    >>> t = np.arange(0.0, 10.0, 0.1)
    >>> own = {f"own_{k}": np.zeros(t.size) for k in ("north_m", "east_m", "down_m", "vn_mps",
    ...        "ve_mps", "vd_mps", "yaw_rad", "pitch_rad", "roll_rad")}
    >>> nav = navigation_solution(own, t, "perfect", 0, (52.0, 4.0, 0.0))
    >>> bool(np.array_equal(nav["nav_yaw_rad"], own["own_yaw_rad"])), round(float(nav["nav_lat_deg"][0]), 6)
    (True, 52.0)
    >>> nav = navigation_solution(own, t, "only-heading", 0, (52.0, 4.0, 0.0))
    >>> bool(np.any(nav["nav_yaw_rad"] != 0)), bool(np.all(nav["nav_north_m"] == 0))
    (True, True)
    """
    cfg = navigation_config(config)
    times = np.asarray(times_s, float).ravel()
    pos_err, nav_pos, nav_vel = _gnss(truth, times, cfg, seed)
    late = cfg.ahrs_latency_s
    att = np.stack([_delayed(_f(truth, f"own_{a}_rad"), times, late, a == "yaw") for a in _ATT], -1)
    ahrs = AhrsModel(**{k: getattr(cfg, k) for k in AhrsModel.__dataclass_fields__})
    nav_att = ahrs_attitude(att, times, ahrs, seed=[seed, _NAV_TAG, 2])
    out = {f"nav_{a}_m": nav_pos[:, c] for c, a in enumerate(_XYZ)}
    out |= {f"nav_{a}_mps": nav_vel[:, c] for c, a in enumerate(_VXYZ)}
    out |= {f"nav_{a}_rad": nav_att[:, c] for c, a in enumerate(_ATT)}
    out |= _geodetic(nav_pos, pos_err[:, 2], truth, times, cfg.gnss_latency_s, origin, terrain_height)
    if cfg.is_perfect:  # exactly the truth, not the truth through a geodetic round trip
        out |= {f"nav_{k[4:]}": np.asarray(v, float) for k, v in truth.items() if f"nav_{k[4:]}" in out}
    return out


def navigation_variables(built, ownship_truth: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The ``nav_*`` variables of a built scenario's own-ship truth (``scenario_truth``'s own_* dict).

    Parameters
    ----------
    built : BuiltScenario
        Read: ``navigation`` (the error model; None: perfect), ``sim_options["seed"]`` (the seed
        when the model sets none), ``terrain`` (the terrain database, optional), ``times_s`` (s)
        and ``origin``.
    ownship_truth : mapping
        The ``own_*`` arrays, as in :func:`navigation_solution`.

    Returns
    -------
    dict of ndarray
        The ``nav_*`` arrays of :func:`navigation_solution`.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> t = np.arange(5) * 0.1
    >>> names = [f"{a}_m" for a in _XYZ] + [f"{a}_mps" for a in _VXYZ] + [f"{a}_rad" for a in _ATT]
    >>> truth = {f"own_{k}": np.zeros(t.size) for k in names}
    >>> built = SimpleNamespace(navigation="ga-typical", sim_options={"seed": 3}, terrain=None,
    ...                         times_s=t, origin=(52.0, 4.0, 0.0))
    >>> nav = navigation_variables(built, truth)
    >>> same = navigation_solution(truth, t, "ga-typical", 3, (52.0, 4.0, 0.0))  # the scenario's seed
    >>> bool(np.array_equal(nav["nav_north_m"], same["nav_north_m"]))
    True
    >>> built.navigation = None  # perfect: the truth
    >>> bool(np.all(navigation_variables(built, truth)["nav_north_m"] == 0.0))
    True
    """
    cfg = navigation_config(getattr(built, "navigation", None) or "perfect")
    seed = cfg.seed if cfg.seed is not None else int(built.sim_options.get("seed") or 0)
    terrain = getattr(built, "terrain", None)
    height = terrain.height_at if terrain is not None and hasattr(terrain, "height_at") else None
    return navigation_solution(ownship_truth, built.times_s, cfg, seed, built.origin, height)


def navigation_at_frame(built, ownship_truth: Mapping[str, np.ndarray]) -> dict[str, float]:
    """The ``nav_*`` values of the newest frame of a run in progress: ``ownship_truth`` holds the
    own-ship truth of frames ``0..i`` (arrays of length ``i + 1``); returns frame ``i``'s solution.

    The solution is causal: the errors are drawn on the scenario's frame times (a function of the
    seed and the times alone) and the latency looks back, so frame ``i`` of
    :func:`navigation_variables` over the whole run depends on the truth up to frame ``i`` only.
    The truth after frame ``i`` is not known yet; it stands at frame ``i``'s (any value gives the
    same result). Costs one whole-run solution per call.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> built = SimpleNamespace(navigation="ga-typical", sim_options={"seed": 3}, terrain=None,
    ...                         times_s=np.arange(5) * 0.1, origin=(52.0, 4.0, 0.0))
    >>> names = [f"{a}_m" for a in _XYZ] + [f"{a}_mps" for a in _VXYZ] + [f"{a}_rad" for a in _ATT]
    >>> truth = {f"own_{k}": np.linspace(0.0, 1.0, 5) for k in names}
    >>> whole = navigation_variables(built, truth)
    >>> first3 = navigation_at_frame(built, {k: v[:3] for k, v in truth.items()})
    >>> bool(first3["nav_north_m"] == whole["nav_north_m"][2])
    True
    """
    n = built.times_s.size
    known = {k: np.asarray(v, float) for k, v in ownship_truth.items()}
    i = next(iter(known.values())).size - 1
    if not 0 <= i < n:
        raise InputError(f"navigation: {i + 1} frames of truth for a run of {n}")
    padded = {k: np.concatenate([v, np.full(n - v.size, v[-1])]) for k, v in known.items()}
    return {k: float(v[i]) for k, v in navigation_variables(built, padded).items()}
