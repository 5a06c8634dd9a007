"""What one radar-equipped aircraft's conflict detection and resolution see of the other traffic.

BlueSky's conflict detection compares every own-ship with every intruder, both taken from the same
``Traffic`` arrays (``cd.update(traf, traf)``), and its resolution reads the intruders' states from
them by aircraft index. :class:`TrafficPicture` is such an intruder object for one own-ship: the
arrays of the traffic, index for index, where every aircraft the own-ship's radar tracks holds the
track's estimate flown on to the present, and :attr:`TrafficPicture.tracked` says which are seen.
An aircraft whose track was lost holds its last estimate flown on (the resolution still looks at it
until the conflict is past); an aircraft never tracked keeps its index but takes no part:
:func:`merge_detection` keeps only the own-ship's conflicts with tracked aircraft.

Nothing here imports BlueSky: the objects are read by attribute (``id``, ``lat``, ``lon``, ``alt``,
``gs``, ``trk``, ``vs``, ``gsnorth``, ``gseast``) as BlueSky's detection and resolution read them.

Examples
--------
>>> from types import SimpleNamespace
>>> traf = SimpleNamespace(id=["A", "B"], ntraf=2, lat=np.array([52.0, 52.1]), lon=np.array([4.0, 4.0]),
...     alt=np.array([900.0, 900.0]), gs=np.array([60.0, 60.0]), trk=np.array([0.0, 180.0]),
...     vs=np.zeros(2), gsnorth=np.array([60.0, -60.0]), gseast=np.zeros(2))
>>> seen = TrackEstimate(7, 10.0, 52.09, 4.0, 950.0, -55.0, 0.0, 0.0, acid="B")
>>> picture = TrafficPicture.of(traf, "A", {"B": seen}, 10.0)
>>> picture.tracked.tolist(), float(picture.alt[1]), float(picture.trk[1]), float(picture.gs[1])
([False, True], 950.0, 180.0, 55.0)
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from skyradar.integrations.bluesky.radar import TrackEstimate

__all__ = ["DetectionResult", "TrafficPicture", "merge_detection"]


@dataclass
class TrafficPicture:
    """The intruder arrays one own-ship's conflict detection and resolution read (BlueSky's names).

    Attributes
    ----------
    id : list of str
        Aircraft identifiers, the traffic's order.
    ntraf : int
        Number of aircraft.
    lat, lon : ndarray
        Position, deg.
    alt : ndarray
        Altitude, m.
    gs : ndarray
        Ground speed, m/s.
    trk : ndarray
        Track angle, deg clockwise from north.
    vs : ndarray
        Vertical speed, m/s, positive up.
    gsnorth, gseast : ndarray
        Ground velocity north and east, m/s.
    tracked : ndarray of bool
        Aircraft the own-ship's radar has a confirmed track on now (the own-ship itself: False).

    Examples
    --------
    ``B``'s track was lost at 10 s: its last estimate (south at 55 m/s), flown on to 20 s, stands in
    for it, 550 m further south, and it does not count as tracked.

    >>> from types import SimpleNamespace
    >>> from skyradar.geo import geodetic_to_ned
    >>> traf = SimpleNamespace(id=["A", "B"], lat=[52.0, 52.1], lon=[4.0, 4.0], alt=[900.0, 900.0],
    ...     vs=[0.0, 0.0], gsnorth=[60.0, -60.0], gseast=[0.0, 0.0])
    >>> last = TrackEstimate(7, 10.0, 52.09, 4.0, 900.0, -55.0, 0.0, 0.0, acid="B")
    >>> picture = TrafficPicture.of(traf, "A", {}, 20.0, lost={"B": last})
    >>> picture.tracked.tolist(), float(picture.gs[1]), float(picture.trk[1])
    ([False, False], 55.0, 180.0)
    >>> round(float(geodetic_to_ned(picture.lat[1], picture.lon[1], 900.0, 52.09, 4.0, 900.0)[0]), 1)
    -550.0
    """

    id: list[str]
    ntraf: int
    lat: np.ndarray
    lon: np.ndarray
    alt: np.ndarray
    gs: np.ndarray
    trk: np.ndarray
    vs: np.ndarray
    gsnorth: np.ndarray
    gseast: np.ndarray
    tracked: np.ndarray

    @classmethod
    def of(
        cls,
        traffic: Any,
        own: str,
        current: Mapping[str, TrackEstimate],
        time_s: float,
        lost: Mapping[str, TrackEstimate] | None = None,
    ) -> TrafficPicture:
        """The picture of own-ship ``own``: ``current`` tracks (by aircraft) and ``lost`` ones' last
        estimates, both flown on to ``time_s`` (s); the rest of ``traffic`` as it is (unused)."""
        ids = list(traffic.id)
        arrays = {
            k: np.array(getattr(traffic, k), float) for k in ("lat", "lon", "alt", "vs", "gsnorth", "gseast")
        }
        tracked = np.zeros(len(ids), bool)
        for estimates, seen in (((lost or {}), False), (current, True)):
            for acid, estimate in estimates.items():
                if acid not in ids or acid == own:
                    continue
                j, e = ids.index(acid), estimate.at(time_s)
                arrays["lat"][j], arrays["lon"][j], arrays["alt"][j] = e.lat_deg, e.lon_deg, e.alt_m
                arrays["gsnorth"][j], arrays["gseast"][j], arrays["vs"][j] = e.vn_mps, e.ve_mps, e.vs_mps
                tracked[j] = seen
        gs = np.hypot(arrays["gsnorth"], arrays["gseast"])
        trk = np.degrees(np.arctan2(arrays["gseast"], arrays["gsnorth"])) % 360.0
        return cls(ids, len(ids), gs=gs, trk=trk, tracked=tracked, **arrays)


@dataclass
class DetectionResult:
    """What BlueSky's ``ConflictDetection.detect`` returns, by name.

    Attributes
    ----------
    confpairs, lospairs : list of tuple of str
        Conflicts and losses of separation (own-ship id, intruder id), one entry per own-ship side.
    inconf : ndarray of bool
        Per aircraft: in conflict.
    tcpamax : ndarray
        Per aircraft: the largest time to closest approach of its conflicts, s.
    qdr, dist, dcpa, tcpa, tLOS : ndarray
        Per conflict pair: bearing (deg), distance (m), distance at closest approach (m), time to
        closest approach (s) and time to loss of separation (s).

    Examples
    --------
    ``detect``'s tuple by name and back (per-pair scalars become arrays):

    >>> returned = ([("A", "B")], [], [True, False], [30.0, 0.0], 90.0, 5000.0, 100.0, 30.0, 25.0)
    >>> result = DetectionResult.of(returned)
    >>> result.confpairs, result.inconf.tolist(), result.dist.tolist(), result.tcpa.tolist()
    ([('A', 'B')], [True, False], [5000.0], [30.0])
    >>> len(result.astuple())
    9
    """

    confpairs: list[tuple[str, str]]
    lospairs: list[tuple[str, str]]
    inconf: np.ndarray
    tcpamax: np.ndarray
    qdr: np.ndarray
    dist: np.ndarray
    dcpa: np.ndarray
    tcpa: np.ndarray
    tLOS: np.ndarray

    @classmethod
    def of(cls, returned: tuple) -> DetectionResult:
        """From ``detect``'s tuple (confpairs, lospairs, inconf, tcpamax, qdr, dist, dcpa, tcpa, tLOS)."""
        pairs, los, inconf, tcpamax, *per_pair = returned
        arrays = [np.atleast_1d(np.asarray(a, float)) for a in per_pair]
        return cls(list(pairs), list(los), np.asarray(inconf, bool), np.asarray(tcpamax, float), *arrays)

    def astuple(self) -> tuple:
        """``detect``'s tuple."""
        return (
            self.confpairs,
            self.lospairs,
            self.inconf,
            self.tcpamax,
            self.qdr,
            self.dist,
            self.dcpa,
            self.tcpa,
            self.tLOS,
        )


def merge_detection(
    truth: DetectionResult, seen: DetectionResult, index: int, own: str, tracked: set[str]
) -> DetectionResult:
    """``truth`` with own-ship ``own``'s conflicts (aircraft ``index``) replaced by those of ``seen``
    with the ``tracked`` aircraft.

    ``truth`` is the detection on the true states, ``seen`` the detection against the own-ship's
    :class:`TrafficPicture`. Losses of separation stay the true ones: they are what happened.

    Examples
    --------
    >>> truth = DetectionResult([("A", "B"), ("B", "A")], [], np.array([True, True]), np.array([30.0, 30.0]),
    ...     *(np.array([v, v]) for v in (0.0, 5000.0, 100.0, 30.0, 25.0)))
    >>> seen = DetectionResult([("A", "B"), ("B", "A")], [], np.array([True, True]), np.array([28.0, 28.0]),
    ...     *(np.array([v, v]) for v in (1.0, 4900.0, 90.0, 28.0, 24.0)))
    >>> merged = merge_detection(truth, seen, 0, "A", set())  # A's radar sees nothing
    >>> merged.confpairs, merged.inconf.tolist(), merged.tcpamax.tolist()
    ([('B', 'A')], [False, True], [0.0, 30.0])
    >>> merge_detection(truth, seen, 0, "A", {"B"}).dist.tolist()
    [5000.0, 4900.0]
    """
    keep = [k for k, pair in enumerate(truth.confpairs) if pair[0] != own]
    add = [k for k, pair in enumerate(seen.confpairs) if pair[0] == own and pair[1] in tracked]
    inconf, tcpamax = truth.inconf.copy(), truth.tcpamax.copy()
    inconf[index] = bool(add)
    tcpamax[index] = float(np.max(seen.tcpa[add])) if add else 0.0
    per_pair = [
        np.concatenate([getattr(truth, name)[keep], getattr(seen, name)[add]])
        for name in ("qdr", "dist", "dcpa", "tcpa", "tLOS")
    ]
    pairs = [truth.confpairs[k] for k in keep] + [seen.confpairs[k] for k in add]
    return DetectionResult(pairs, list(truth.lospairs), inconf, tcpamax, *per_pair)
