"""Honest scoring of the encounter set: every conflict, why the unwarned ones were not seen, clutter.

A conflict is *observable* by a layout of radar heads when, in every frame of the
``observe_window_s`` before its loss of well clear (LoWC), the intruder is inside at least one
head's beam (azimuth and elevation within half the field of view in that head's antenna frame),
in line of sight, and at least ``min_snr_db`` above that head's thermal noise: the simulator's
truth of the geometry and the link budget, never the chain's detections, and never clutter
(clutter is the chain's problem, not an excuse). A conflict that is not warned before its LoWC is
counted under the first cause that holds in some frame of that window:

``missed``
    observable: the chain's failure;
``behind``
    the intruder is in own-ship's rear hemisphere (more than 90 deg off the nose);
``outside_beams``
    in front, but outside every head's beam;
``terrain_masked``
    in a beam, but hidden by the terrain (or beyond the range bins);
``below_13db``
    in a beam and in view, but weaker than ``min_snr_db``.

Tracks that do not follow the intruder (:func:`skyradar.chain.label_tracks`) are
clutter; a clutter track is a *ground* track when its median height above the terrain is below
half of own-ship's (only over terrain).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

from skyradar.experiments.encounter_set import rate_interval, summarise
from skyradar.experiments.sensor_figures import sensor_summary
from skyradar.units import wrap_angle

__all__ = ["CAUSES", "frame_status", "conflict_cause", "unwarned_cause", "track_counts", "summarise_layout"]

CAUSES = ("missed", "behind", "outside_beams", "terrain_masked", "below_13db")


def frame_status(truths: list, fov_deg: float = 70.0, min_snr_db: float = 13.0) -> pd.DataFrame:
    """Per frame of a run: ``time_s``, ``observable`` and the status flags of the causes.

    ``truths``: one frames Dataset (without ``iq``) per head of the layout, on the same frames;
    the intruder is target 0. Columns ``behind``, ``in_beam`` (some head), ``in_view`` (some head
    whose beam it is in has it in line of sight) and ``observable``.
    """
    from skyradar.io.frames_model import frame_times_s

    half = np.radians(fov_deg / 2)
    first = truths[0]
    rel_n = first["tgt_north_m"].values[:, 0] - first["own_north_m"].values
    rel_e = first["tgt_east_m"].values[:, 0] - first["own_east_m"].values
    bearing = wrap_angle(np.arctan2(rel_e, rel_n) - first["own_yaw_rad"].values)
    in_beam = np.zeros(rel_n.size, bool)
    in_view, observable = in_beam.copy(), in_beam.copy()
    for truth in truths:
        az = truth["tgt_azimuth_rad"].values[:, 0]
        el = truth["tgt_elevation_rad"].values[:, 0]
        with np.errstate(invalid="ignore"):
            beam = (np.abs(az) <= half) & (np.abs(el) <= half)
            view = beam & truth["tgt_visible"].values[:, 0].astype(bool)
            strong = view & (truth["tgt_snr_db"].values[:, 0] >= min_snr_db)
        in_beam |= beam
        in_view |= view
        observable |= strong
    with np.errstate(invalid="ignore"):
        behind = np.abs(bearing) > np.pi / 2
    return pd.DataFrame(
        {
            "time_s": frame_times_s(first),
            "behind": behind,
            "in_beam": in_beam,
            "in_view": in_view,
            "observable": observable,
        }
    )


def conflict_cause(status: pd.DataFrame, t_lowc_s: float, observe_window_s: float) -> str:
    """Cause (:data:`CAUSES`) a conflict would go unwarned, from :func:`frame_status` over the
    ``observe_window_s`` before its LoWC; ``""`` for no conflict (NaN LoWC).

    Examples
    --------
    >>> s = pd.DataFrame({"time_s": [0.0, 1.0], "behind": [False, False], "in_beam": [True, False],
    ...                   "in_view": [True, False], "observable": [True, False]})
    >>> conflict_cause(s, 1.0, 5.0), conflict_cause(s, 0.0, 0.5)
    ('outside_beams', 'missed')
    """
    if not np.isfinite(t_lowc_s):
        return ""
    ft = status["time_s"].to_numpy(float)
    w = status[(ft >= t_lowc_s - observe_window_s) & (ft <= t_lowc_s)]
    if w.empty:
        return "outside_beams"  # no frame before the LoWC: never in view of the chain
    if w["observable"].all():
        return "missed"
    for cause, flag in (
        ("behind", w["behind"]),
        ("outside_beams", ~w["in_beam"]),
        ("terrain_masked", ~w["in_view"]),
    ):
        if flag.any():
            return cause
    return "below_13db"


def unwarned_cause(status: pd.DataFrame, t_lowc_s: float, t_warning_s: float, observe_window_s: float) -> str:
    """:func:`conflict_cause` of a conflict not warned before its LoWC; ``""`` for one warned in time
    (the table's ``cause`` column says why a conflict went unwarned, not what would have caused it).

    Examples
    --------
    >>> s = pd.DataFrame({"time_s": [0.0, 1.0], "behind": [False, False], "in_beam": [True, True],
    ...                   "in_view": [True, True], "observable": [True, True]})
    >>> [unwarned_cause(s, 1.0, t_warning, 5.0) for t_warning in (0.5, 1.5, np.nan)]
    ['', 'missed', 'missed']
    """
    if t_warning_s < t_lowc_s:
        return ""
    return conflict_cause(status, t_lowc_s, observe_window_s)


def track_counts(
    tracks: pd.DataFrame,
    warned_ids: set[int],
    labels: dict[int, str],
    terrain=None,
    own_agl_m: float = float("nan"),
) -> dict[str, int]:
    """Intruder, clutter and ground tracks of one run and the clutter/ground tracks that warned.

    ``labels`` from :func:`~skyradar.chain.label_tracks`; ``warned_ids`` the tracks
    with a warning; ``terrain`` (a :class:`~skyradar.scene.terrain.Terrain` or None) and own-ship's
    median height above it decide which clutter tracks are ground tracks: median height below half
    the own-ship's, or no measured altitude on any row (``altitude_measured``: its height is the
    co-altitude prior, so it says nothing, and in a terrain scene clutter is the ground's).
    """
    clutter = [tid for tid, name in labels.items() if name == "clutter"]
    ground: list[int] = []
    if terrain is not None and clutter and np.isfinite(own_agl_m):
        rows = tracks[tracks["track_id"].isin(clutter)]
        with np.errstate(invalid="ignore"):
            agl = rows["alt_m"].to_numpy(float) - terrain.height_at(
                rows["lat_deg"].to_numpy(float), rows["lon_deg"].to_numpy(float)
            )
        med = pd.Series(agl, index=rows.index).groupby(rows["track_id"]).median()
        ground = [int(tid) for tid, h in med.items() if not h >= 0.5 * own_agl_m]  # NaN: off the grid
        if "altitude_measured" in rows:
            prior_only = ~rows["altitude_measured"].astype(bool).groupby(rows["track_id"]).any()
            ground = sorted(set(ground) | {int(tid) for tid in prior_only.index[prior_only.to_numpy()]})
    return {
        "intruder_tracks": sum(name != "clutter" for name in labels.values()),
        "clutter_tracks": len(clutter),
        "clutter_warning_tracks": len(warned_ids.intersection(clutter)),
        "ground_tracks": len(ground),
        "ground_warning_tracks": len(warned_ids.intersection(ground)),
    }


def summarise_layout(res: pd.DataFrame, late_lead_s: float) -> dict[str, Any]:
    """:func:`~skyradar.experiments.encounter_set.summarise` of one terrain and layout, plus the
    score over all conflicts, unwarned conflicts by cause, clutter, ground and fragments."""
    s = summarise(res, late_lead_s)
    conflict = res["conflict"].astype(bool)
    in_time = (res["t_warning_s"] < res["t_lowc_s"]) & conflict
    minutes = float(res["flight_s"].sum()) / 60.0
    unwarned = res.loc[conflict & ~in_time, "cause"]
    frag = res.loc[res["intruder_tracks"] > 0, "intruder_tracks"]
    # A warning must hold to the closest approach where well clear is lost; for a near miss it may
    # end once the intruder's path shows it passes clear (a manoeuvring intruder turns away).
    warned = res["t_warning_s"].notna() & conflict
    held = res["warning_held"].astype(bool) if "warning_held" in res else pd.Series(True, index=res.index)
    s.update(
        warnings_not_held=int((warned & ~held).sum()),
        alert_flickers=int(res["warning_flickers"].sum()) if "warning_flickers" in res else 0,
        encounters_with_alert_flicker=int((res["warning_flickers"] > 0).sum())
        if "warning_flickers" in res
        else 0,
        warned_before_lowc=int(in_time.sum()),
        warned_before_lowc_fraction=float(in_time.sum() / max(int(conflict.sum()), 1)),
        warned_before_lowc_fraction_ci95=rate_interval(int(in_time.sum()), int(conflict.sum())),
        unwarned_by_cause={c: int((unwarned == c).sum()) for c in CAUSES},
        flight_minutes=round(minutes, 2),
        clutter_tracks=int(res["clutter_tracks"].sum()),
        clutter_tracks_per_min=float(res["clutter_tracks"].sum() / minutes) if minutes else float("nan"),
        clutter_warnings=int(res["clutter_warning_tracks"].sum()),
        encounters_with_clutter_warnings=int((res["clutter_warning_tracks"] > 0).sum()),
        ground_tracks=int(res["ground_tracks"].sum()),
        ground_tracks_per_min=float(res["ground_tracks"].sum() / minutes) if minutes else float("nan"),
        ground_track_warnings=int(res["ground_warning_tracks"].sum()),
        intruder_tracked_encounters=int(frag.size),
        sensor=sensor_summary(res),
        track_fragments_per_intruder={
            "median": float(frag.median()) if frag.size else float("nan"),
            "mean": float(frag.mean()) if frag.size else float("nan"),
            "max": int(frag.max()) if frag.size else 0,
        },
    )
    return s
