"""Antenna gain pattern from two 1-D cuts (azimuth, elevation).

Manufacturers publish a horizontal and a vertical cut, often asymmetric. The 3-D pattern is
built from the two cuts: L1 adds the two dB losses (the thesis' choice), L2 takes their
Euclidean norm (a rounder, less pessimistic beam off the principal planes).

Angles are in the antenna frame: boresight along +x, y to the right, z down. Azimuth is
positive to the right, elevation positive up.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np

from skyradar.errors import InputError

__all__ = ["GainCut", "AntennaPattern", "read_gain_cut"]


@dataclass(frozen=True)
class GainCut:
    """One principal-plane cut: gain in dB at sorted angles in degrees."""

    angle_deg: np.ndarray
    gain_db: np.ndarray

    def __post_init__(self) -> None:
        angle = np.asarray(self.angle_deg, dtype=float)
        gain = np.asarray(self.gain_db, dtype=float)
        if angle.ndim != 1 or angle.shape != gain.shape or angle.size < 2:
            raise InputError("gain cut needs two equal-length 1-D arrays of at least 2 points")
        if not (np.all(np.isfinite(angle)) and np.all(np.isfinite(gain))):
            raise InputError("gain cut contains NaN or inf")
        order = np.argsort(angle)
        if np.any(np.diff(angle[order]) == 0):
            raise InputError("gain cut has a repeated angle")
        object.__setattr__(self, "angle_deg", angle[order])
        object.__setattr__(self, "gain_db", gain[order])

    def __call__(self, angle_rad: np.ndarray) -> np.ndarray:
        """Gain in dB at ``angle_rad``; beyond the table the edge value holds."""
        return np.interp(np.degrees(angle_rad), self.angle_deg, self.gain_db)


def read_gain_cut(path: str | Path) -> GainCut:
    """Read a gain cut from a CSV with columns ``angle_deg,gain_db`` (header required).

    Examples
    --------
    >>> import tempfile, os
    >>> p = os.path.join(tempfile.mkdtemp(), "az.csv")
    >>> _ = open(p, "w").write("angle_deg,gain_db\\n-90,-20\\n0,9\\n90,-20\\n")
    >>> read_gain_cut(p)(np.radians([0.0, 45.0])).round(1).tolist()
    [9.0, -5.5]
    """
    path = Path(path)
    try:
        table = np.genfromtxt(path, delimiter=",", names=True, dtype=float)
    except OSError as exc:
        raise InputError(f"{path}: cannot read antenna cut ({exc})") from exc
    names = table.dtype.names or ()
    for column in ("angle_deg", "gain_db"):
        if column not in names:
            raise InputError(f"{path}: missing column '{column}' (have {list(names)})")
    try:
        return GainCut(np.atleast_1d(table["angle_deg"]), np.atleast_1d(table["gain_db"]))
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from exc


def _default_cut(beamwidth_deg: float, peak_db: float) -> GainCut:
    # Gaussian main lobe (-3 dB at half the beamwidth) floored at -30 dB below peak: a patch
    # array of about 70 deg beamwidth, the seed prototype's field of view.
    angle = np.linspace(-180.0, 180.0, 721)
    loss = 12.0 * (angle / beamwidth_deg) ** 2
    return GainCut(angle, peak_db - np.minimum(loss, 30.0))


@dataclass(frozen=True)
class AntennaPattern:
    """Two-cut antenna gain pattern, used for transmit and receive.

    Parameters
    ----------
    azimuth : GainCut
        Gain in dB against azimuth (elevation 0).
    elevation : GainCut
        Gain in dB against elevation (azimuth 0).
    combine : {"L1", "L2"}
        How the two dB losses combine off the principal planes.

    Examples
    --------
    >>> pattern = AntennaPattern.default()
    >>> float(pattern.gain_db(0.0, 0.0)) == pattern.peak_db
    True
    >>> round(float(pattern.peak_db - pattern.gain_db(np.radians(35.0), 0.0)), 1)
    3.0
    """

    azimuth: GainCut
    elevation: GainCut
    combine: Literal["L1", "L2"] = "L1"
    peak_db: float = field(init=False)

    def __post_init__(self) -> None:
        if self.combine not in ("L1", "L2"):
            raise InputError(f"antenna combine must be 'L1' or 'L2', got {self.combine!r}")
        peak = max(float(self.azimuth.gain_db.max()), float(self.elevation.gain_db.max()))
        object.__setattr__(self, "peak_db", peak)

    @classmethod
    def default(cls, beamwidth_deg: float = 70.0, combine: Literal["L1", "L2"] = "L1") -> AntennaPattern:
        """Built-in pattern: -3 dB at +-beamwidth/2 in both planes, peak from the beam solid angle."""
        if not 1.0 <= beamwidth_deg <= 180.0:
            raise InputError(f"antenna beamwidth_deg must be in [1, 180], got {beamwidth_deg}")
        # Directivity of a beam of theta x theta degrees: about 41253 / theta^2 (Kraus).
        peak_db = 10.0 * np.log10(41253.0 / beamwidth_deg**2)
        cut = _default_cut(beamwidth_deg, peak_db)
        return cls(cut, cut, combine)

    @classmethod
    def from_csv(
        cls, azimuth_csv: str | Path, elevation_csv: str | Path, combine: Literal["L1", "L2"] = "L1"
    ) -> AntennaPattern:
        """Pattern from two CSV cuts with columns ``angle_deg,gain_db``."""
        return cls(read_gain_cut(azimuth_csv), read_gain_cut(elevation_csv), combine)

    def gain_db(self, azimuth_rad: np.ndarray | float, elevation_rad: np.ndarray | float) -> np.ndarray:
        """One-way gain in dBi at the given antenna-frame angles (radians)."""
        loss_az = self.peak_db - self.azimuth(np.asarray(azimuth_rad))
        loss_el = self.peak_db - self.elevation(np.asarray(elevation_rad))
        if self.combine == "L1":
            return self.peak_db - (loss_az + loss_el)
        return self.peak_db - np.hypot(loss_az, loss_el)

    def gain_table(self, n: int = 721) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Regular-grid tables (angle_rad, az_loss_db, el_loss_db) for compiled kernels."""
        angle = np.linspace(-np.pi, np.pi, n)
        return (
            angle,
            self.peak_db - self.azimuth(angle),
            self.peak_db - self.elevation(angle),
        )
