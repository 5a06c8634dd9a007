"""Motion models for tracking in the range-Doppler image.

Both models share one state layout, ``x = (R, V_R, dR/dt, dV_R/dt)``: range [m], radial velocity
[m/s], range rate [m/s] and radial acceleration [m/s^2], and observe ``z = (R, V_R)`` through
``H = [[1, 0, 0, 0], [0, 1, 0, 0]]``. They differ in how the state moves and how the Doppler
innovation is measured (Maas 2022, ch. 4):

* :func:`traditional_model` is the camera-image tracker: two independent constant-velocity axes.
  Range follows its own rate ``dR/dt`` (column 2 of F), the Doppler axis follows ``dV_R/dt``
  (column 3), and the Doppler innovation is a plain difference, so a target whose radial velocity
  wraps across the image edge looks like a jump of ``W`` (the image width in m/s).
* :func:`radar_model` couples the axes with the thesis' matrix
  ``F = [[1, dt, 0, 0], [0, 1, 0, dt], [0, 0, 1, 0], [0, 0, 0, 1]]``: row 0 reads
  ``R <- R + dt * V_R`` (column 1 is ``V_R``), so range follows the measured radial velocity and
  ``V_R`` follows ``dV_R/dt``. ``dR/dt`` (state 2) is not driven by F; it holds the range rate fitted
  to the track's range history and is only used to de-alias ``V_R`` (:mod:`skyradar.track.dealias`).
  The Doppler innovation is wrapped to the shortest way round the image.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["MotionModel", "traditional_model", "radar_model", "MEASUREMENT_MATRIX"]

MEASUREMENT_MATRIX = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]])


@dataclass(frozen=True)
class MotionModel:
    """A linear motion model in range-Doppler with its noise and innovation rules.

    Parameters
    ----------
    name : str
        ``'radar'`` or ``'traditional'``.
    coupled : bool
        True when range follows the radial velocity (F[0, 1] = dt) instead of its own rate.
    wrap_doppler : bool
        Wrap the Doppler innovation modulo ``doppler_width_mps``.
    dealias : bool
        De-alias ``V_R`` from the fitted range rate, and wrap the range innovation of tracks with a
        single observation modulo ``W * dt``.
    doppler_width_mps : float
        Width ``W = 2 * VLim`` of the Doppler axis, m/s.
    sigma_range_m, sigma_velocity_mps : float
        Measurement noise standard deviations, m and m/s.
    q_range_mps2 : float
        Spectral density (as a standard deviation of acceleration per sqrt(s)) of the range axis'
        white-acceleration noise in the traditional model, m/s^2.
    q_velocity_mps3 : float
        White-jerk noise driving the radial acceleration, m/s^3 (both models).
    init_sigma_rate_mps, init_sigma_accel_mps2 : float
        Prior standard deviations of ``dR/dt`` (m/s) and ``dV_R/dt`` (m/s^2) for a new track.
    coupling_s : float
        Range-Doppler coupling of a sawtooth chirp, s (m of apparent range per m/s): the observed
        range is ``R + coupling_s * V_R``. The radar model knows it (so ``R`` is the true range once
        ``V_R`` is de-aliased); the image model does not (0).

    Examples
    --------
    The state is (range [m], radial velocity [m/s], range rate [m/s], radial acceleration [m/s^2]);
    in the coupled model range follows the radial velocity:

    >>> m = MotionModel("radar", coupled=True, wrap_doppler=True, dealias=True, doppler_width_mps=78.3)
    >>> (m.transition(0.1) @ [1000.0, -50.0, -50.0, 2.0]).round(3).tolist()
    [995.0, -49.8, -50.0, 2.0]
    >>> m.measurement_noise.diagonal().round(3).tolist()
    [20.25, 0.04]
    """

    name: str
    coupled: bool
    wrap_doppler: bool
    dealias: bool
    doppler_width_mps: float
    sigma_range_m: float = 4.5
    sigma_velocity_mps: float = 0.2
    q_range_mps2: float = 6.0
    q_velocity_mps3: float = 6.0
    init_sigma_rate_mps: float = 100.0
    init_sigma_accel_mps2: float = 3.0
    coupling_s: float = 0.0

    def transition(self, dt_s: float | np.ndarray) -> np.ndarray:
        """State transition matrices, shape ``dt_s.shape + (4, 4)``.

        Examples
        --------
        >>> m = radar_model(78.3)
        >>> m.transition(np.array(0.5))[0].tolist()
        [1.0, 0.5, 0.0, 0.0]
        """
        dt = np.asarray(dt_s, float)
        F = np.broadcast_to(np.eye(4), dt.shape + (4, 4)).copy()
        F[..., 0, 1 if self.coupled else 2] = dt
        F[..., 1, 3] = dt
        return F

    def process_noise(self, dt_s: float | np.ndarray) -> np.ndarray:
        """Process noise covariance matrices, shape ``dt_s.shape + (4, 4)``.

        The radar model treats ``(R, V_R, dV_R/dt)`` as one constant-acceleration chain driven by
        white jerk; the traditional model has two white-acceleration axes, ``(R, dR/dt)`` and
        ``(V_R, dV_R/dt)``.
        """
        dt = np.asarray(dt_s, float)[..., None, None]
        Q = np.zeros(dt.shape[:-2] + (4, 4))
        qj = self.q_velocity_mps3**2
        if self.coupled:
            idx = [0, 1, 3]
            block = qj * np.block(
                [
                    [dt**5 / 20, dt**4 / 8, dt**3 / 6],
                    [dt**4 / 8, dt**3 / 3, dt**2 / 2],
                    [dt**3 / 6, dt**2 / 2, dt],
                ]
            )
            Q[..., np.ix_(idx, idx)[0], np.ix_(idx, idx)[1]] = block
            # The fitted range rate drifts slowly; keep its variance from collapsing.
            Q[..., 2, 2] = qj * dt[..., 0, 0]
        else:
            qa = self.q_range_mps2**2
            cv = np.block([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]])
            Q[..., 0::2, 0::2] = qa * cv
            Q[..., 1::2, 1::2] = qj * cv
        return Q

    def transition_unresolved(self, dt_s: float) -> np.ndarray:
        """Transition of a radar-model track whose alias is not resolved yet, 4x4.

        Until the alias is known, range follows the range-rate state ``dR/dt``, which moves with
        the radial acceleration like ``V_R`` does (``dR/dt = V_R + k W`` with an unknown whole
        ``k``): ``R += dt dR/dt``, ``V_R += dt a``, ``dR/dt += dt a``.

        Examples
        --------
        >>> radar_model(78.3).transition_unresolved(1.0)[[0, 2]].tolist()
        [[1.0, 0.0, 1.0, 0.0], [0.0, 0.0, 1.0, 1.0]]
        """
        F = np.eye(4)
        F[0, 2] = F[1, 3] = F[2, 3] = dt_s
        return F

    def process_noise_unresolved(self, dt_s: float | np.ndarray) -> np.ndarray:
        """White jerk into ``a``, integrated into ``V_R`` and ``dR/dt`` alike, plus a small
        independent white acceleration on ``(R, dR/dt)``, shape ``dt_s.shape + (4, 4)``."""
        dt = np.asarray(dt_s, float)
        Q = self.q_velocity_mps3**2 * _jerk_chain_noise(dt)
        qa = (0.25 * self.q_range_mps2) ** 2
        for (i, j), value in (((0, 0), dt**3 / 3), ((0, 2), dt**2 / 2), ((2, 0), dt**2 / 2), ((2, 2), dt)):
            Q[..., i, j] += qa * value
        return Q

    @property
    def measurement_matrix(self) -> np.ndarray:
        """``H``, 2x4: observed (range, radial velocity) = ``(R + c V_R, V_R)``.

        Examples
        --------
        >>> radar_model(78.3, coupling_s=0.19).measurement_matrix[0].tolist()
        [1.0, 0.19, 0.0, 0.0]
        """
        H = MEASUREMENT_MATRIX.copy()
        H[0, 1] = self.coupling_s
        return H

    @property
    def measurement_noise(self) -> np.ndarray:
        """Measurement covariance of ``(R, V_R)``, 2x2."""
        return np.diag([self.sigma_range_m**2, self.sigma_velocity_mps**2])

    def initial_covariance(self) -> np.ndarray:
        """Covariance of a track started from one observation, 4x4."""
        return np.diag(
            [
                self.sigma_range_m**2,
                self.sigma_velocity_mps**2,
                self.init_sigma_rate_mps**2,
                self.init_sigma_accel_mps2**2,
            ]
        )


def traditional_model(doppler_width_mps: float, **noise: float) -> MotionModel:
    """The image tracker's model: independent constant-velocity axes, plain innovation.

    Examples
    --------
    >>> traditional_model(78.3).transition(np.array(1.0))[0].tolist()
    [1.0, 0.0, 1.0, 0.0]
    """
    return MotionModel("traditional", False, False, False, float(doppler_width_mps), **noise)


def radar_model(doppler_width_mps: float, **noise: float) -> MotionModel:
    """The radar-aware model: R' = V_R, wrapped Doppler innovation, de-aliasing.

    Examples
    --------
    >>> radar_model(78.3).transition(np.array(1.0))[0].tolist()
    [1.0, 1.0, 0.0, 0.0]
    """
    return MotionModel("radar", True, True, True, float(doppler_width_mps), **noise)


def _jerk_chain_noise(dt: np.ndarray) -> np.ndarray:
    """Covariance added over ``dt`` by unit white jerk to (R, V_R, dR/dt, a), ``dt.shape + (4, 4)``.

    An impulse of jerk ``s`` before the end leaves ``a`` +1, both velocities +s and range +s^2/2;
    the entries are the integrals of the products of those responses over ``[0, dt]``.
    """
    p, v, a = 0, 1, 2
    powers = {
        (p, p): dt**5 / 20,
        (p, v): dt**4 / 8,
        (p, a): dt**3 / 6,
        (v, v): dt**3 / 3,
        (v, a): dt**2 / 2,
        (a, a): dt,
    }
    kind = [p, v, v, a]
    Q = np.empty(np.shape(dt) + (4, 4))
    for i in range(4):
        for j in range(4):
            Q[..., i, j] = powers[(min(kind[i], kind[j]), max(kind[i], kind[j]))]
    return Q
