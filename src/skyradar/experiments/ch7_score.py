"""ch7 scoring: passive detections against the simulator's truth tables (never against themselves).

Truth (``NAME.truth.parquet`` from :mod:`skyradar.passive.truth`) has one row per reflector per beam
pass: building points, ground-clutter points and the aircraft, each at the time the beam centre
crosses it. A rotation is ``floor(time / period)``; 40 s at 13.5 rpm is 9 rotations.

- A detection *matches* a static reflector when the reflector lies in its resolution cell: bistatic
  range within ``range_tol_m`` (the pulse's range resolution c/B) and azimuth from the transmitter
  within ``az_tol_deg`` (the beamwidth). That is the radar's own definition of a false alarm (nothing
  in the cell); ``strict_false_total`` also reports the count with a 300 m position match instead.
- A cluster is *seen* in a rotation when a static-channel detection matches one of its points within
  ``time_tol_s`` of that point's beam pass.
- The aircraft is *seen* in a rotation when a detection (either channel) lies within ``aircraft_m`` of
  its true position within ``time_tol_s`` of its beam pass; the position error is that distance.
- A detection is *false* when it matches no truth reflector (building, clutter point, or the aircraft
  within ``aircraft_m`` and ``time_tol_s``): the known reflectors the acceptance counts are every
  reflector the scene holds. The blind zone is already dropped by the processor.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

__all__ = ["score"]


def _in_cell(det: pd.DataFrame, pts: pd.DataFrame, range_tol_m: float, az_tol_deg: float) -> np.ndarray:
    """(detections, points) boolean: the point lies in the detection's range-azimuth resolution cell."""
    dr = det["bistatic_range_m"].to_numpy()[:, None] - pts["bistatic_range_m"].to_numpy()[None, :]
    da = det["azimuth_deg"].to_numpy()[:, None] - pts["azimuth_from_tx_deg"].to_numpy()[None, :]
    return (np.abs(dr) <= range_tol_m) & (np.abs((da + 180.0) % 360.0 - 180.0) <= az_tol_deg)


def _near(det: pd.DataFrame, pts: pd.DataFrame, radius_m: float, time_tol_s: float | None) -> np.ndarray:
    """(detections, points) boolean: within ``radius_m`` (and ``time_tol_s`` if given)."""
    d_en = det[["east_m", "north_m"]].to_numpy()
    p_en = pts[["east_m", "north_m"]].to_numpy()
    close = np.hypot(d_en[:, None, 0] - p_en[None, :, 0], d_en[:, None, 1] - p_en[None, :, 1]) <= radius_m
    if time_tol_s is not None:
        close &= np.abs(det["time_s"].to_numpy()[:, None] - pts["time_s"].to_numpy()[None, :]) <= time_tol_s
    return close


def _aircraft(det: pd.DataFrame, plane: pd.DataFrame, aircraft_m: float, time_tol_s: float, rot):
    """Position errors of the aircraft's beam passes that were seen, and the rotations they fall in."""
    errors, seen_rot = [], set()
    for _, row in plane.iterrows():
        cand = det[np.abs(det["time_s"] - row["time_s"]) <= time_tol_s]
        if cand.empty:
            continue
        dist = np.hypot(cand["east_m"] - row["east_m"], cand["north_m"] - row["north_m"])
        if dist.min() <= aircraft_m:
            errors.append(float(round(dist.min(), 1)))
            seen_rot.add(int(rot(row["time_s"])))
    return errors, seen_rot


def _explained(det, truth, plane, range_tol_m, az_tol_deg, aircraft_m, time_tol_s, match_m):
    """Detections explained by a reflector: by resolution cell, and by a ``match_m`` position match."""
    static_truth = truth[truth["kind"] != "aircraft"]
    explained = (
        _in_cell(det, static_truth, range_tol_m, az_tol_deg).any(axis=1) if len(det) else np.zeros(0, bool)
    )
    strict = _near(det, static_truth, match_m, None).any(axis=1) if len(det) else np.zeros(0, bool)
    if len(det) and len(plane):
        by_plane = _near(det, plane, aircraft_m, time_tol_s).any(axis=1)
        explained, strict = explained | by_plane, strict | by_plane
    return explained, strict


def score(
    det: pd.DataFrame,
    truth: pd.DataFrame,
    period_s: float,
    duration_s: float,
    range_tol_m: float = 200.0,
    az_tol_deg: float = 1.4,
    aircraft_m: float = 500.0,
    time_tol_s: float = 0.3,
    match_m: float = 300.0,
) -> dict[str, Any]:
    """Per-rotation detection of clusters and aircraft, aircraft position error and false detections.

    Examples
    --------
    >>> truth = pd.DataFrame({"time_s": [1.0, 1.0, 5.5], "kind": ["building", "aircraft", "aircraft"],
    ...     "name": ["town", "plane", "plane"], "east_m": [9000.0, 1000, 1100], "north_m": [0.0, 500, 500],
    ...     "bistatic_range_m": [6000.0, 800, 900], "azimuth_from_tx_deg": [80.0, 30, 31]})
    >>> det = pd.DataFrame({"time_s": [1.01, 1.0, 3.0], "channel": ["static", "moving", "static"],
    ...     "east_m": [9100.0, 1040, -5000], "north_m": [0.0, 500, 0],
    ...     "bistatic_range_m": [6050.0, 810, 7000], "azimuth_deg": [80.5, 30, 200]})
    >>> s = score(det, truth, 4.5, 9.0)
    >>> s["rotations"], s["clusters"]["town"], s["aircraft_seen"], s["aircraft_error_m"], s["false_total"]
    (2, [1, 0], 1, [40.0], 1)
    """
    n_rot = int(round(duration_s / period_s))
    rot = lambda t: np.clip(np.floor(np.asarray(t) / period_s).astype(int), 0, n_rot - 1)  # noqa: E731
    static = det[det["channel"] == "static"].reset_index(drop=True)
    clusters: dict[str, list[int]] = {}
    for name, pts in truth[truth["kind"] == "building"].groupby("name"):
        seen = np.zeros(n_rot, int)
        if len(static):
            hit = _in_cell(static, pts, range_tol_m, az_tol_deg)
            hit &= (
                np.abs(static["time_s"].to_numpy()[:, None] - pts["time_s"].to_numpy()[None, :]) <= time_tol_s
            )
            for j in np.flatnonzero(hit.any(axis=0)):
                seen[rot(pts["time_s"].iloc[j])] = 1
        clusters[str(name)] = seen.tolist()
    plane = truth[truth["kind"] == "aircraft"].reset_index(drop=True)
    errors, seen_rot = _aircraft(det, plane, aircraft_m, time_tol_s, rot)
    explained, strict = _explained(
        det, truth, plane, range_tol_m, az_tol_deg, aircraft_m, time_tol_s, match_m
    )
    false_rot = np.bincount(rot(det["time_s"][~explained]), minlength=n_rot) if len(det) else np.zeros(n_rot)
    return {
        "rotations": n_rot,
        "clusters": clusters,
        "aircraft_passes": int(plane["time_s"].lt(n_rot * period_s).sum()),
        "aircraft_seen": len(seen_rot),
        "aircraft_error_m": errors,
        "false_total": int((~explained).sum()),
        "strict_false_total": int((~strict).sum()),
        "false_per_rotation": [int(v) for v in false_rot],
        "false_by_channel": {
            str(c): int(((det["channel"] == c).to_numpy() & ~explained).sum()) for c in ("static", "moving")
        },
    }
