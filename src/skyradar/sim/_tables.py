"""Look-up tables of the image-domain simulator: two-way antenna gain and incidence reflectivity."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from skyradar.config import RadarConfig
from skyradar.errors import InputError

__all__ = ["REFLECTIVITY_MODELS", "two_way_gain_table", "reflectivity_table"]

REFLECTIVITY_MODELS: dict[str, Callable[[np.ndarray], np.ndarray]] = {
    "cosine": np.cos,  # the thesis: 1 straight below, 0 at grazing
    "lambert": lambda theta: np.cos(theta) ** 2,
    "constant": lambda theta: np.ones_like(theta),
}


def two_way_gain_table(config: RadarConfig, n: int = 513) -> tuple[np.ndarray, float]:
    """Two-way linear gain G^2 on a grid of antenna-frame direction cosines (u_y, u_z) in [-1, 1]^2.

    Looking up by direction cosine spares the compiled kernel an atan2, an asin and a power per
    facet; 513 points give 0.22 deg steps at boresight, interpolated bilinearly, and the float32
    table (1 MB) stays in cache.
    """
    c = np.linspace(-1.0, 1.0, n)
    uy, uz = np.meshgrid(c, c, indexing="ij")
    ux = np.sqrt(np.clip(1.0 - uy**2 - uz**2, 0.0, None))
    gain_db = config.antenna.gain_db(np.arctan2(uy, ux), np.arcsin(-uz))
    return (10.0 ** (gain_db / 5.0)).astype(np.float32), float(c[1] - c[0])


def reflectivity_table(reflectivity: str | Callable[[np.ndarray], np.ndarray], n: int = 4097) -> np.ndarray:
    if isinstance(reflectivity, str):
        if reflectivity not in REFLECTIVITY_MODELS:
            raise InputError(
                f"simulation.reflectivity {reflectivity!r} unknown; choose {sorted(REFLECTIVITY_MODELS)}"
            )
        reflectivity = REFLECTIVITY_MODELS[reflectivity]
    # Tabulated on a uniform grid of cos(incidence) for the compiled kernel.
    table = np.asarray(reflectivity(np.arccos(np.linspace(0.0, 1.0, n))), dtype=float)
    if table.shape != (n,) or not np.all(np.isfinite(table)) or np.any(table < 0):
        raise InputError("simulation.reflectivity: the function must return finite non-negative factors")
    return table
