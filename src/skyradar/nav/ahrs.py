"""AHRS-like attitude errors: what the estimators get instead of the simulator's true attitude.

A General Aviation aircraft knows its attitude from an AHRS (attitude and heading reference
system), not from the truth. The error model per axis is the usual one for a MEMS AHRS: white
noise per sample plus a first-order Gauss-Markov bias (a slowly wandering offset with
correlation time ``tau``), started from its stationary distribution so that a short flight sees
a near-constant offset of random size and sign.

The default :class:`AhrsModel` is a typical MEMS AHRS of the class fitted to GA and UAV
aircraft: the VectorNav VN-100 datasheet class gives pitch/roll 0.5 deg RMS static (1.0 deg
dynamic) and magnetic heading 2.0 deg RMS. Defaults: pitch and roll 0.1 deg white plus a
0.3 deg bias (about 0.32 deg RMS in total), heading 0.2 deg white plus a 1.5 deg bias; bias
correlation times 100 s (pitch, roll) and 300 s (heading). The errors are seeded, so a run is
repeatable.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from skyradar.errors import InputError

__all__ = ["AhrsModel", "ahrs_attitude"]


@dataclass(frozen=True)
class AhrsModel:
    """1-sigma attitude errors of an AHRS, deg, and bias correlation times, s (see module docstring).

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


def _gauss_markov(times_s: np.ndarray, sd: float, tau_s: float, rng: np.random.Generator) -> np.ndarray:
    """First-order Gauss-Markov sequence of stationary SD ``sd`` sampled at ``times_s``."""
    out = np.empty(times_s.size)
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


def ahrs_attitude(
    true_attitude_rad: np.ndarray,
    times_s: np.ndarray,
    model: AhrsModel | None = None,
    seed: int = 0,
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
    seed : int
        Random seed: same seed, same errors.

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
    err_deg = np.column_stack(
        [
            _gauss_markov(times, bias, tau, rng) + rng.normal(0.0, noise, times.size)
            for noise, bias, tau in axes
        ]
    )
    out = truth + np.radians(err_deg)
    yaw = out[:, 0]
    # Wrap only what left [-pi, pi): the rest stays bit-exact (a zero model returns the truth).
    out[:, 0] = np.where((yaw < -np.pi) | (yaw >= np.pi), (yaw + np.pi) % (2.0 * np.pi) - np.pi, yaw)
    return out
