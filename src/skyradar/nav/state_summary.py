"""Summary of a flight-state table (``skyradar state``): quality counts, medians, height error."""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

__all__ = ["state_summary"]


def state_summary(table: pd.DataFrame, true_height_agl_m: np.ndarray | None = None) -> dict[str, Any]:
    """Frames, low-quality frames, mean quality and the medians of ``h_m``, ``vx_mps``, ``vz_mps``.

    Medians are over frames of good quality (NaN when there is none). With the true height above
    ground per frame (a simulated run), also the mean and SD of the height error ``h_m - truth``.

    Examples
    --------
    >>> table = pd.DataFrame({"low_quality": [False, True], "quality": [0.9, 0.1], "h_m": [500.0, np.nan],
    ...                       "vx_mps": [50.0, np.nan], "vz_mps": [0.5, np.nan]})
    >>> s = state_summary(table, np.array([498.0, 497.0]))
    >>> s["low_quality_frames"], s["h_m_median"], s["h_err_mean_m"]
    (1, 500.0, 2.0)
    """
    good = ~table["low_quality"].to_numpy()

    def median(name: str) -> float:
        return float(np.nanmedian(table[name])) if good.any() else float("nan")

    result = {
        "frames": len(table),
        "low_quality_frames": int((~good).sum()),
        "mean_quality": float(table["quality"].mean()),
        "h_m_median": median("h_m"),
        "vx_mps_median": median("vx_mps"),
        "vz_mps_median": median("vz_mps"),
    }
    if true_height_agl_m is not None:
        err = table["h_m"].to_numpy() - np.asarray(true_height_agl_m, float)
        result["h_err_mean_m"] = float(np.nanmean(err)) if np.isfinite(err).any() else float("nan")
        result["h_err_sd_m"] = float(np.nanstd(err)) if np.isfinite(err).any() else float("nan")
    return result
