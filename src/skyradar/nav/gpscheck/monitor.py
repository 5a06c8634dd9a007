"""GPS integrity verdicts per frame, and the alert when GPS disagrees with the radar for N frames.

A frame is decided only when the radar sees enough ground with enough structure:

* ``"no decision: wing up"``: the beam sees too little ground (in a turn with the radar wing up), the
  thesis' failure case; such frames are never scored as correct or wrong;
* ``"no decision: too little structure"``: the best alignment is not distinct (its peak-to-sidelobe
  ratio is below ``min_psr``): open water, fields, a featureless footprint;
* otherwise ``"consistent"`` when the correction the search found is within the tolerances
  (``max_position_m``, ``max_heading_deg``), else ``"inconsistent"``.

The alert is raised at a frame when the last ``alert_frames`` decided frames are all inconsistent;
undecided frames in between neither break nor extend the streak (a turn does not reset the evidence).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skyradar.errors import InputError
from skyradar.nav.gpscheck.search import PoseOffset

__all__ = [
    "CONSISTENT",
    "INCONSISTENT",
    "DEFAULT_SETTINGS",
    "WING_UP",
    "LOW_STRUCTURE",
    "VERDICTS",
    "MonitorSettings",
    "inconsistency",
    "frame_verdict",
    "alerts",
]

CONSISTENT = "consistent"
INCONSISTENT = "inconsistent"
WING_UP = "no decision: wing up"
LOW_STRUCTURE = "no decision: too little structure"
VERDICTS = (CONSISTENT, INCONSISTENT, WING_UP, LOW_STRUCTURE)


@dataclass(frozen=True)
class MonitorSettings:
    """Thresholds of the monitor (defaults: the acceptance bounds and ch6's calibration).

    Attributes
    ----------
    min_ground_fraction : float
        Share of the beam on the ground (0..1) below which a frame is wing up.
    min_psr : float
        Peak-to-sidelobe ratio below which the alignment is not distinct (too little structure).
    max_position_m : float
        Largest correction still consistent, m.
    max_heading_deg : float
        Largest heading correction still consistent, deg.
    alert_frames : int
        Decided frames in a row that must be inconsistent for the alert.

    Examples
    --------
    A 5 m, 0.5 deg correction found with PSR 7: consistent by default, not with tighter settings.

    >>> offset = PoseOffset(3.0, 4.0, 0.5, 0.8, 0.3, 7.0)
    >>> frame_verdict(0.9, offset), frame_verdict(0.9, offset, MonitorSettings(max_position_m=4.0))
    ('consistent', 'inconsistent')
    >>> frame_verdict(0.9, offset, MonitorSettings(min_psr=8.0))
    'no decision: too little structure'
    >>> MonitorSettings(alert_frames=0)
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: MonitorSettings: alert_frames must be at least 1, got 0
    """

    min_ground_fraction: float = 0.5
    # ch6 seeds 6-8: every unspoofed frame with PSR >= 4.5 was within 8 m; at 4.0 a turn frame was 45 m off.
    min_psr: float = 4.5
    max_position_m: float = 15.0
    max_heading_deg: float = 2.0
    alert_frames: int = 3

    def __post_init__(self) -> None:
        for name in ("min_ground_fraction", "min_psr", "max_position_m", "max_heading_deg"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise InputError(f"MonitorSettings: {name} must be a finite number >= 0, got {value!r}")
        if int(self.alert_frames) < 1:
            raise InputError(f"MonitorSettings: alert_frames must be at least 1, got {self.alert_frames!r}")


DEFAULT_SETTINGS = MonitorSettings()


def inconsistency(offset: PoseOffset, settings: MonitorSettings = DEFAULT_SETTINGS) -> float:
    """How far the correction is outside the tolerances: > 1 is inconsistent.

    Examples
    --------
    >>> inconsistency(PoseOffset(30.0, 0.0, 1.0, 0.5, 0.1, 9.0))
    2.0
    """
    return float(
        max(offset.distance_m / settings.max_position_m, abs(offset.d_heading_deg) / settings.max_heading_deg)
    )


def frame_verdict(
    ground_fraction: float, offset: PoseOffset | None, settings: MonitorSettings = DEFAULT_SETTINGS
) -> str:
    """One frame's verdict from the share of the beam on the ground and the search's correction.

    ``offset`` may be ``None`` when the search was not run (wing up).

    Examples
    --------
    >>> frame_verdict(0.1, None)
    'no decision: wing up'
    >>> frame_verdict(0.9, PoseOffset(2.0, 1.0, 0.3, 0.6, 0.5, 12.0))
    'consistent'
    >>> frame_verdict(0.9, PoseOffset(50.0, 0.0, 0.0, 0.6, 0.1, 12.0))
    'inconsistent'
    """
    if not np.isfinite(ground_fraction) or ground_fraction < settings.min_ground_fraction or offset is None:
        return WING_UP
    if not np.isfinite(offset.psr) or offset.psr < settings.min_psr:
        return LOW_STRUCTURE
    return CONSISTENT if inconsistency(offset, settings) <= 1.0 else INCONSISTENT


def alerts(verdicts: list[str], alert_frames: int = 3) -> np.ndarray:
    """True at each frame where the last ``alert_frames`` decided frames were all inconsistent.

    Examples
    --------
    >>> v = ["inconsistent", "no decision: wing up", "inconsistent", "inconsistent", "consistent"]
    >>> alerts(v, 3).tolist()
    [False, False, False, True, False]
    """
    if alert_frames < 1:
        raise InputError(f"--alert-frames: must be at least 1, got {alert_frames!r}")
    out = np.zeros(len(verdicts), dtype=bool)
    streak = 0
    for i, verdict in enumerate(verdicts):
        if verdict == INCONSISTENT:
            streak += 1
        elif verdict == CONSISTENT:
            streak = 0
        out[i] = verdict == INCONSISTENT and streak >= alert_frames
    return out
