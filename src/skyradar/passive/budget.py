"""Power budget of a passive receiver: the direct path (Friis) and echoes (bistatic radar equation).

Direct path from a transmitter of peak power ``Pt`` and gain ``Gt g(az)`` toward the receiver (``g`` the
azimuth pattern relative to the peak) to an antenna of gain ``Gr`` at the baseline distance ``L``::

    Pd = Pt Gt g Gr lambda^2 / ((4 pi)^2 L^2)

Echo from a reflector of RCS ``sigma`` at ``r_tx`` from the transmitter and ``r_rx`` from the receiver::

    Pr = Pt Gt g Gr lambda^2 sigma / ((4 pi)^3 r_tx^2 r_rx^2)

(free space, no losses; Skolnik, Radar Handbook 3rd ed., ch. 23 "Bistatic radar", eq. 23.1). The
single-pulse matched-filter SNR of a pulse of duration ``T`` is ``Pr T / (k T0 F)``.
"""

from __future__ import annotations

import numpy as np

__all__ = ["db", "direct_path_power_w", "echo_power_w", "matched_filter_snr"]

BOLTZMANN_J_K = 1.380649e-23
T0_K = 290.0


def db(x: np.ndarray | float) -> np.ndarray:
    """10 log10 of a power ratio.

    Parameters
    ----------
    x : array_like
        Power ratio (linear, > 0).

    Returns
    -------
    ndarray
        The ratio in dB.

    Examples
    --------
    >>> db(np.array([100.0, 0.5])).round(2).tolist()
    [20.0, -3.01]
    """
    return 10.0 * np.log10(x)


def direct_path_power_w(
    peak_power_w: float,
    tx_gain_dbi: float,
    pattern_gain: np.ndarray | float,
    rx_gain_dbi: float,
    wavelength_m: float,
    baseline_m: float,
) -> np.ndarray:
    """Received direct-path power (W) by the Friis equation.

    Examples
    --------
    25 kW (74 dBm), 34 + 2 dBi, lambda^2 -19.4 dB, (4 pi)^2 22.0 dB, L^2 81.6 dB: -13.0 dBm.

    >>> p = direct_path_power_w(25e3, 34.0, 1.0, 2.0, 299792458 / 2.8e9, 12e3)
    >>> round(float(db(p / 1e-3)), 1)
    -13.0
    """
    gains = 10.0 ** ((tx_gain_dbi + rx_gain_dbi) / 10.0) * np.asarray(pattern_gain, dtype=float)
    return peak_power_w * gains * wavelength_m**2 / ((4.0 * np.pi) ** 2 * baseline_m**2)


def echo_power_w(
    peak_power_w: float,
    tx_gain_dbi: float,
    pattern_gain: np.ndarray | float,
    rx_gain_dbi: float,
    wavelength_m: float,
    rcs_m2: np.ndarray | float,
    r_tx_m: np.ndarray | float,
    r_rx_m: np.ndarray | float,
) -> np.ndarray:
    """Received echo power (W) by the bistatic radar equation.

    Parameters
    ----------
    peak_power_w : float
        Transmitter peak power, W.
    tx_gain_dbi : float
        Transmit antenna peak gain, dBi.
    pattern_gain : array_like
        Transmit azimuth pattern toward the reflector, relative to the peak (linear, <= 1).
    rx_gain_dbi : float
        Receive antenna gain, dBi.
    wavelength_m : float
        Carrier wavelength, m.
    rcs_m2 : array_like
        Bistatic radar cross-section of the reflector, m^2.
    r_tx_m, r_rx_m : array_like
        Ranges from the transmitter to the reflector and from the reflector to the receiver, m.

    Returns
    -------
    ndarray
        Echo power at the receive antenna port, W (broadcast over the array arguments).

    Examples
    --------
    Over the direct path (:func:`direct_path_power_w`) the echo is ``sigma L^2 / (4 pi r_tx^2 r_rx^2)``:
    an RCS of 4 pi m^2 with ``r_tx = r_rx = L = 1 km`` is 1e-6 of it, -60 dB.

    >>> echo = echo_power_w(25e3, 34.0, 1.0, 2.0, 0.107, 4 * np.pi, 1000.0, 1000.0)
    >>> direct = direct_path_power_w(25e3, 34.0, 1.0, 2.0, 0.107, 1000.0)
    >>> round(float(db(echo / direct)), 6)
    -60.0
    """
    gains = 10.0 ** ((tx_gain_dbi + rx_gain_dbi) / 10.0) * np.asarray(pattern_gain, dtype=float)
    r2 = (np.asarray(r_tx_m, dtype=float) * np.asarray(r_rx_m, dtype=float)) ** 2
    return (
        peak_power_w * gains * wavelength_m**2 * np.asarray(rcs_m2, dtype=float) / ((4.0 * np.pi) ** 3 * r2)
    )


def matched_filter_snr(power_w: np.ndarray | float, width_s: float, noise_figure_db: float) -> np.ndarray:
    """Single-pulse matched-filter SNR (linear): pulse energy over the noise density ``k T0 F``.

    Parameters
    ----------
    power_w : array_like
        Received pulse power, W.
    width_s : float
        Pulse duration, s.
    noise_figure_db : float
        Receiver noise figure ``F``, dB.

    Returns
    -------
    ndarray
        Peak SNR at the matched filter's output (linear).

    Examples
    --------
    -90 dBm for 100 us (-40 dB s) against ``k T0`` = -174 dBm/Hz and F = 0 dB: -90 - 40 + 174 = 44 dB.

    >>> round(float(db(matched_filter_snr(1e-12, 100e-6, 0.0))), 1)
    44.0
    """
    n0 = BOLTZMANN_J_K * T0_K * 10.0 ** (noise_figure_db / 10.0)
    return np.asarray(power_w, dtype=float) * width_s / n0
