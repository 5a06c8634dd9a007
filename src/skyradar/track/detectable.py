"""What the radar could see: the truth a tracker is scored against, from the scenario alone.

An intruder counts as truth in a frame when the simulator's geometry puts it in a beam (in front,
inside the range limit, in line of sight: the run's ``tgt_visible``) and its expected SNR (radar
equation with the two-way antenna gain, no noise: ``tgt_snr_db``) reaches the detection threshold,
the SNR at which the CA-CFAR of :func:`skyradar.process.detect.detect` detects with 50 %
probability. Detections play no part: a frame in the beam but far below the threshold is not one
a tracker could have followed, and scoring it as missed would make every beam-edge frame a loss of
completeness.
"""

from __future__ import annotations

import inspect

import numpy as np

from skyradar.config import RadarConfig

__all__ = ["detection_threshold_snr_db", "detectable"]


def detection_threshold_snr_db(config: RadarConfig, probability: float = 0.5) -> float:
    """Expected per-channel SNR (dB) at which ``process_cube``'s CA-CFAR detects with ``probability``.

    The detector compares the mean of ``n_rx`` channels' power with ``alpha`` times the mean of
    ``N`` training cells (the ``pfa``, ``guard`` and ``train`` defaults of
    :func:`skyradar.process.detect.detect`). For a steady target of SNR ``s`` per channel the ratio
    is noncentral F with (2 n_rx, 2 N n_rx) degrees of freedom and noncentrality 2 n_rx s, which
    gives the detection probability exactly (a target filling one pixel, as the simulator puts it).

    Examples
    --------
    >>> round(detection_threshold_snr_db(RadarConfig.prototype_2022()), 1)
    7.5
    """
    from scipy import optimize, stats  # noncentral F; imported here, scipy.stats alone takes ~0.5 s

    from skyradar.process.cfar import cfar_factor, training_cells
    from skyradar.process.detect import detect

    defaults = {k: v.default for k, v in inspect.signature(detect).parameters.items()}
    n_train = training_cells(defaults["guard"], defaults["train"])
    n = config.n_rx
    alpha = cfar_factor(defaults["pfa"], n_train, n)

    def miss(snr_db: float) -> float:
        return float(stats.ncf.sf(alpha, 2 * n, 2 * n_train * n, 2 * n * 10 ** (snr_db / 10))) - probability

    return float(optimize.brentq(miss, -20.0, 40.0, xtol=1e-6))


def detectable(visible: np.ndarray, snr_db: np.ndarray, threshold_db: float) -> np.ndarray:
    """(time, target) frames in a beam with an expected SNR of at least ``threshold_db``.

    Examples
    --------
    >>> detectable(np.array([[True, True, False]]), np.array([[9.0, 5.0, 20.0]]), 7.5).tolist()
    [[True, False, False]]
    """
    snr = np.nan_to_num(np.asarray(snr_db, float), nan=-np.inf)
    return np.asarray(visible, bool) & (snr >= threshold_db)
