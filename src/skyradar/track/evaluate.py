"""``skyradar evaluate``: a tracks table scored against the intruder truth of the run it came from.

The truth is what the radar could see (:mod:`skyradar.track.detectable`): in a beam and at an
expected SNR of at least the CA-CFAR's 50 % detection threshold (``truth='detectable'``, the
default), or every in-beam frame (``truth='beam'``, the earlier behaviour). A track is matched on
every row from its confirmation until it is closed, its coasted predictions included
(``coasting=True``; :func:`skyradar.track.metrics.track_metrics`), as Stone Soup's SIAP
completeness counts a track's predictions; ``completeness_confirmed`` repeats the figure over
confirmed rows only.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from skyradar.errors import InputError
from skyradar.track.detectable import detectable, detection_threshold_snr_db
from skyradar.track.io import truth_from_frames
from skyradar.track.metrics import track_metrics

__all__ = ["evaluate_run", "TRUTH_MODES"]

TRUTH_MODES = ("detectable", "beam")


def evaluate_run(
    run: str | Path,
    tracks: pd.DataFrame,
    threshold_px: float = 5.0,
    gospa_c_px: float = 10.0,
    truth: str = "detectable",
    min_snr_db: float | None = None,
    coasting: bool = True,
) -> dict:
    """Track metrics of ``tracks`` against the truth of ``run`` (a simulated frames store).

    Parameters
    ----------
    run : path
        Zarr frames store with ``tgt_range_m``, ``tgt_radial_velocity_mps``, ``tgt_visible`` and
        (for ``truth='detectable'``) ``tgt_snr_db``; several heads are combined
        (:func:`skyradar.track.io.truth_from_frames`).
    tracks : DataFrame
        From ``skyradar track``.
    truth : {'detectable', 'beam'}
    min_snr_db : float, optional
        Detection threshold for ``'detectable'`` (default: the CA-CFAR's Pd 50 % SNR for the run's
        radar, :func:`~skyradar.track.detectable.detection_threshold_snr_db`).
    coasting : bool
        Match a track's coasted rows too (see the module docstring).

    Returns
    -------
    dict
        :func:`~skyradar.track.metrics.track_metrics` plus ``truth`` (the mode used),
        ``truth_snr_threshold_db`` and ``held_rows``: how many unconfirmed rows each reason of the
        tracks' ``held_by`` column holds (:data:`skyradar.track.ground_tracks.HOLD_REASONS`). A run
        without ``tgt_snr_db`` is scored on the beam and says so.
    """
    if truth not in TRUTH_MODES:
        raise InputError(f"--truth: must be one of {', '.join(TRUTH_MODES)}, got {truth!r}")
    tr, config = truth_from_frames(run)
    counted, threshold, mode = tr.visible, None, truth
    if truth == "detectable":
        if tr.snr_db is None or not np.isfinite(tr.snr_db[tr.visible]).any():
            mode = "beam (the run has no tgt_snr_db)"
        else:
            threshold = detection_threshold_snr_db(config) if min_snr_db is None else float(min_snr_db)
            counted = detectable(tr.visible, tr.snr_db, threshold)
    pixel = (config.range_resolution_m, config.doppler_resolution_mps)
    result = track_metrics(
        tracks,
        tr,
        pixel,
        2.0 * config.v_lim_mps,
        threshold_px,
        gospa_c_px,
        counted=counted,
        coasting=coasting,
    )
    held = {}
    if "held_by" in tracks and len(tracks):
        why = tracks["held_by"].fillna("").astype(str)
        held = {str(k): int(v) for k, v in why[why != ""].value_counts().sort_index().items()}
    return result | {
        "truth": mode,
        "truth_snr_threshold_db": threshold,
        "targets": list(tr.names),
        "held_rows": held,
    }
