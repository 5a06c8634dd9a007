"""Antenna gain pattern from two 1-D cuts (azimuth, elevation).

Manufacturers publish a horizontal and a vertical cut, often asymmetric. The 3-D pattern is
built from the two cuts: L1 adds the two dB losses (the thesis' choice, the default), L2 takes
their Euclidean norm (a rounder, less pessimistic beam off the principal planes).

The built-in pattern (:meth:`AntennaPattern.default`) is SYNTHETIC: a Gaussian main lobe with
-3 dB at half the beamwidth, floored 30 dB below a peak taken from the beam solid angle. It is
no measured antenna. Measured cuts are loaded from CSV, either two files (one per cut, columns
``angle_deg,gain_db``) or one file with a ``cut`` column (``azimuth`` or ``elevation``); see
:func:`read_gain_cut`, :func:`read_gain_cuts` and, in a scenario, ``radar.antenna.azimuth_csv`` +
``radar.antenna.elevation_csv`` or ``radar.antenna.cuts_csv``. Between measured angles the gain
in dB is interpolated linearly; a cut must cover [-90, 90] deg, the front hemisphere the
simulator looks up; beyond its ends (behind the antenna plane) the end value holds.

Angles are in the antenna frame: boresight along +x, y to the right, z down. Azimuth is
positive to the right, elevation positive up.
"""

from __future__ import annotations

import csv
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np

from skyradar.errors import InputError

__all__ = ["GainCut", "AntennaPattern", "read_gain_cut", "read_gain_cuts", "REQUIRED_COVERAGE_DEG"]

# The simulator tabulates the gain over the front hemisphere (both angles in [-90, 90] deg).
REQUIRED_COVERAGE_DEG = (-90.0, 90.0)
CUT_NAMES = ("azimuth", "elevation")


def _checked_cut(
    angle: np.ndarray, gain: np.ndarray, row: Callable[[int], str], where: str
) -> tuple[np.ndarray, np.ndarray]:
    """Validated (angle ascending, gain) arrays; errors name ``where`` and the row ``row(i)``."""
    if angle.ndim != 1 or angle.shape != gain.shape or angle.size < 2:
        raise InputError(f"{where}: a cut needs at least 2 rows of angle_deg and gain_db (got {angle.size})")
    for name, values in (("angle_deg", angle), ("gain_db", gain)):
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            i = int(bad[0])
            raise InputError(f"{where}: {row(i)}: field '{name}': {values[i]} is not finite (NaN or inf)")
    step = np.diff(angle)
    sign = 1.0 if step[0] > 0 else -1.0
    bad = np.flatnonzero(step * sign <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        raise InputError(
            f"{where}: {row(i)}: field 'angle_deg': {angle[i]:g} after {angle[i - 1]:g}; "
            "angles must be strictly increasing (or strictly decreasing)"
        )
    if sign < 0:
        angle, gain = angle[::-1], gain[::-1]
    lo, hi = REQUIRED_COVERAGE_DEG
    if angle[0] > lo or angle[-1] < hi:
        raise InputError(
            f"{where}: field 'angle_deg': covers [{angle[0]:g}, {angle[-1]:g}] deg; a cut must cover "
            f"[{lo:g}, {hi:g}] (extend it with the measured floor level)"
        )
    return angle, gain


@dataclass(frozen=True)
class GainCut:
    """One principal-plane cut: gain in dB at strictly monotonic angles in degrees.

    The angles must cover [-90, 90] deg; they are stored ascending.

    Examples
    --------
    >>> cut = GainCut(np.array([-90.0, 0.0, 90.0]), np.array([-20.0, 10.0, -20.0]))
    >>> cut(np.radians([0.0, 45.0, 120.0])).tolist()
    [10.0, -5.0, -20.0]
    """

    angle_deg: np.ndarray
    gain_db: np.ndarray

    def __post_init__(self) -> None:
        angle, gain = _checked_cut(
            np.asarray(self.angle_deg, dtype=float),
            np.asarray(self.gain_db, dtype=float),
            lambda i: f"row {i}",
            "gain cut",
        )
        object.__setattr__(self, "angle_deg", angle)
        object.__setattr__(self, "gain_db", gain)

    def __call__(self, angle_rad: np.ndarray) -> np.ndarray:
        """Gain in dB at ``angle_rad`` (radians), linear in dB between rows; beyond the ends the end value."""
        return np.interp(np.degrees(angle_rad), self.angle_deg, self.gain_db)


def _read_rows(path: Path, columns: tuple[str, ...]) -> list[tuple[int, dict[str, str]]]:
    """(line number, row) pairs of a CSV with a header naming at least ``columns``."""
    try:
        with open(path, newline="", encoding="utf-8-sig") as handle:
            reader = csv.DictReader(handle, skipinitialspace=True)
            names = [name.strip() for name in reader.fieldnames or []]
            reader.fieldnames = names
            for column in columns:
                if column not in names:
                    raise InputError(f"{path}: missing column '{column}' (have {names})")
            rows = [(reader.line_num, row) for row in reader]
    except OSError as exc:
        raise InputError(f"{path}: cannot read antenna cut ({exc.strerror or exc})") from None
    except (UnicodeDecodeError, csv.Error) as exc:
        raise InputError(f"{path}: not a CSV text file ({exc})") from None
    if not rows:
        raise InputError(f"{path}: no data rows below the header")
    return rows


def _number(path: Path, line: int, column: str, text: str | None) -> float:
    cell = (text or "").strip()
    try:
        return float(cell)
    except ValueError:
        shown = repr(cell) if cell else "an empty cell"
        raise InputError(f"{path}: line {line}: field '{column}': {shown} is not a number") from None


def _cut_from_rows(path: Path, rows: list[tuple[int, dict[str, str]]], where: str) -> GainCut:
    lines = [line for line, _ in rows]
    angle = np.array([_number(path, line, "angle_deg", row["angle_deg"]) for line, row in rows])
    gain = np.array([_number(path, line, "gain_db", row["gain_db"]) for line, row in rows])
    angle, gain = _checked_cut(angle, gain, lambda i: f"line {lines[i]}", where)
    return GainCut(angle, gain)


def read_gain_cut(path: str | Path) -> GainCut:
    """Read one measured cut from a CSV with columns ``angle_deg,gain_db`` (header required).

    Extra columns are ignored. Angles in degrees, strictly increasing or decreasing and covering
    [-90, 90]; gains in dBi, finite. A bad cell raises :class:`InputError` naming the file, the
    line and the column.

    Examples
    --------
    >>> import tempfile, os
    >>> p = os.path.join(tempfile.mkdtemp(), "az.csv")
    >>> _ = open(p, "w").write("angle_deg,gain_db\\n-90,-20\\n0,9\\n90,-20\\n")
    >>> read_gain_cut(p)(np.radians([0.0, 45.0])).round(1).tolist()
    [9.0, -5.5]
    """
    path = Path(path)
    return _cut_from_rows(path, _read_rows(path, ("angle_deg", "gain_db")), str(path))


def read_gain_cuts(path: str | Path) -> tuple[GainCut, GainCut]:
    """Read the (azimuth, elevation) cuts from one CSV with columns ``cut,angle_deg,gain_db``.

    ``cut`` is ``azimuth`` or ``elevation`` on every row; each cut is validated as in
    :func:`read_gain_cut`.

    Examples
    --------
    >>> import tempfile, os
    >>> p = os.path.join(tempfile.mkdtemp(), "cuts.csv")
    >>> rows = ["cut,angle_deg,gain_db", "azimuth,-90,-20", "azimuth,0,9", "azimuth,90,-20",
    ...         "elevation,-90,-30", "elevation,0,9", "elevation,90,-30"]
    >>> _ = open(p, "w").write("\\n".join(rows) + "\\n")
    >>> az, el = read_gain_cuts(p)
    >>> round(float(az(np.radians(45.0))), 6), round(float(el(np.radians(45.0))), 6)
    (-5.5, -10.5)
    """
    path = Path(path)
    rows = _read_rows(path, ("cut", "angle_deg", "gain_db"))
    groups: dict[str, list[tuple[int, dict[str, str]]]] = {name: [] for name in CUT_NAMES}
    for line, row in rows:
        name = (row["cut"] or "").strip().lower()
        if name not in groups:
            raise InputError(
                f"{path}: line {line}: field 'cut': {row['cut']!r} is not 'azimuth' or 'elevation'"
            )
        groups[name].append((line, row))
    cuts = {name: _cut_from_rows(path, rows, f"{path} ({name} cut)") for name, rows in groups.items() if rows}
    for name in CUT_NAMES:
        if name not in cuts:
            raise InputError(f"{path}: field 'cut': no '{name}' rows")
    return cuts["azimuth"], cuts["elevation"]


def _default_cut(beamwidth_deg: float, peak_db: float) -> GainCut:
    # Synthetic: Gaussian main lobe (-3 dB at half the beamwidth) floored 30 dB below peak, a
    # stand-in for a patch array of about 70 deg beamwidth (the thesis prototype's field of view).
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
    >>> pattern = AntennaPattern.default()  # synthetic, not measured
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
        """Synthetic pattern: -3 dB at +-beamwidth/2 in both planes, peak from the beam solid angle."""
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
        """Pattern from two measured CSV cuts, columns ``angle_deg,gain_db`` (:func:`read_gain_cut`)."""
        return cls(read_gain_cut(azimuth_csv), read_gain_cut(elevation_csv), combine)

    @classmethod
    def from_cuts_csv(cls, cuts_csv: str | Path, combine: Literal["L1", "L2"] = "L1") -> AntennaPattern:
        """Pattern from one measured CSV, columns ``cut,angle_deg,gain_db`` (:func:`read_gain_cuts`)."""
        return cls(*read_gain_cuts(cuts_csv), combine)

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
