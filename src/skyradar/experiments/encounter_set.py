"""The encounter set of ``skyradar experiment encounters``: geometries, scenarios and scoring.

Own-ship flies north, level, at ``OWN_SPEED_MPS`` and ``OWN_ALTITUDE_M`` (or the terrain's height,
:mod:`skyradar.experiments.encounter_terrain`) with the forward mount or the scenario's ``radars:``;
each intruder flies straight and reaches its closest point of approach (CPA) at
:data:`T_CPA_S`. Kinds: ``head-on``, ``crossing`` (60-120 deg from either side), ``converging``
(20-60 deg), ``overtaking`` (own-ship overtakes a slower aircraft ahead: a forward radar cannot see
one that overtakes from behind) and ``climbing`` (crossing while climbing or descending through
own-ship's level). Misses are drawn so that the set holds conflicts (loss of the non-cooperative
DO-365 well-clear volume, 2200 ft / 450 ft) and near misses on both sides of its boundary.

Scoring follows DO-365's split of encounters into *must alert*, *may alert* and *must not alert*:
a loss of well clear (LoWC) must be warned before it happens; an encounter that stays well clear
but comes within ``buffer`` times the volume (horizontally and vertically at once) may be warned,
since a sensor with finite accuracy cannot tell it from a conflict; a warning for an encounter that
stays outside that buffer is false.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from skyradar.daa.conflict import WellClearVolume
from skyradar.io.atomic import savefig_atomic

__all__ = [
    "rate_interval",
    "OWN_SPEED_MPS",
    "OWN_ALTITUDE_M",
    "T_CPA_S",
    "make_encounters",
    "make_fast_closures",
    "FAST_CLOSURE_AGL_M",
    "encounter_scenario",
    "relative_truth",
    "event_times",
    "score_encounter",
    "summarise",
    "plot_encounters",
]

OWN_SPEED_MPS = 50.0
OWN_ALTITUDE_M = 1000.0
T_CPA_S = 120.0  # own-ship flies 0..T_CPA_S + 10 s; the frames cover the end of the approach only
KINDS = ("head-on", "crossing", "converging", "overtaking", "climbing")
_DT_TRUTH_S = 0.05


def _draw_misses(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Horizontal and vertical misses (m) and the vertical side (+-1) of ``n`` encounters: a third
    inside the well-clear volume (conflicts), the rest spread to three times it, half of those a near
    miss clearly outside in one of the two only."""
    inside = rng.random(n) < 1 / 3
    vol = WellClearVolume.do365_noncoop()
    h = np.where(inside, rng.uniform(0, 0.9 * vol.dthr_m, n), rng.uniform(0, 3.0 * vol.dthr_m, n))
    v = np.where(inside, rng.uniform(0, 0.9 * vol.zthr_m, n), rng.uniform(0, 3.0 * vol.zthr_m, n))
    spread = ~inside & (rng.random(n) < 0.5)
    v[spread] = rng.uniform(0, 0.9 * vol.zthr_m, spread.sum())
    return h, v, rng.choice([-1.0, 1.0], n)


def make_encounters(n: int, seed: int = 0) -> pd.DataFrame:
    """Encounter parameters, ``n`` rows cycling through the kinds; seeded and reproducible.

    Columns: ``kind``, ``horizontal_miss_m``, ``vertical_miss_m`` (CPA offset; positive above),
    ``intruder_speed_mps``, ``crossing_angle_deg`` (NaN for head-on/overtaking), ``climb_mps``
    (NaN: level), ``side``, ``rcs_m2`` (log-uniform 1-5 m^2, light aircraft at X band).

    Examples
    --------
    >>> make_encounters(5)["kind"].tolist()
    ['head-on', 'crossing', 'converging', 'overtaking', 'climbing']
    """
    rng = np.random.default_rng(seed)
    kind = np.array(KINDS)[np.arange(n) % len(KINDS)]
    h, v, sign = _draw_misses(rng, n)
    angle = np.select(
        [kind == "crossing", kind == "converging", kind == "climbing"],
        [rng.uniform(60, 120, n), rng.uniform(20, 60, n), rng.uniform(30, 150, n)],
        np.nan,
    )
    speed = np.where(kind == "overtaking", rng.uniform(20, 35, n), rng.uniform(30, 70, n))
    climbing = kind == "climbing"
    return pd.DataFrame(
        {
            "kind": kind,
            "horizontal_miss_m": np.where(climbing, np.maximum(h, 1.0), h),
            "vertical_miss_m": np.where(climbing, 0.0, v * sign),
            "intruder_speed_mps": speed,
            "crossing_angle_deg": angle * rng.choice([-1.0, 1.0], n),
            "climb_mps": np.where(climbing, sign * rng.uniform(2.0, 6.0, n), np.nan),
            "side": rng.choice(["left", "right"], n),
            "rcs_m2": np.exp(rng.uniform(np.log(1.0), np.log(5.0), n)),
        }
    )


FAST_CLOSURE_AGL_M = (300.0, 700.0)
FAST_CLOSURE_KINDS = ("head-on", "crossing", "climbing")


def make_fast_closures(n: int, seed: int = 0) -> pd.DataFrame:
    """The fast-closure family: encounters whose closing speed aliases into the ground's Doppler band.

    Own-ship at ``OWN_SPEED_MPS`` (50 m/s) meets intruders at 30-70 m/s head-on, crossing at
    110-160 deg, or crossing at 110-170 deg while climbing or descending 2-6 m/s through its
    level: closing speeds of about 78-117 m/s, which alias (image width 78.3 m/s at the
    prototype's 9.4 frames/s) into the band of radial velocities the ground ahead fills. Over
    relief that is the geometry where clutter hides an intruder and a radar has the least time.
    Misses are drawn as in :func:`make_encounters` (a third inside the well-clear volume). The
    column ``own_agl_m`` (uniform in :data:`FAST_CLOSURE_AGL_M`) sets the own-ship's lowest height
    above the ground under its track over hills and Jacksboro.

    Examples
    --------
    >>> enc = make_fast_closures(6, seed=1)
    >>> enc["kind"].tolist()
    ['head-on', 'crossing', 'climbing', 'head-on', 'crossing', 'climbing']
    >>> bool(enc["crossing_angle_deg"].abs().min() >= 110.0), bool(enc["own_agl_m"].between(300, 700).all())
    (True, True)
    """
    rng = np.random.default_rng(seed)
    kind = np.array(FAST_CLOSURE_KINDS)[np.arange(n) % len(FAST_CLOSURE_KINDS)]
    h, v, sign = _draw_misses(rng, n)
    angle = np.select(
        [kind == "crossing", kind == "climbing"], [rng.uniform(110, 160, n), rng.uniform(110, 170, n)], np.nan
    )
    climbing = kind == "climbing"
    return pd.DataFrame(
        {
            "kind": kind,
            "horizontal_miss_m": np.where(climbing, np.maximum(h, 1.0), h),
            "vertical_miss_m": np.where(climbing, 0.0, v * sign),
            "intruder_speed_mps": rng.uniform(30, 70, n),
            "crossing_angle_deg": angle * rng.choice([-1.0, 1.0], n),
            "climb_mps": np.where(climbing, sign * rng.uniform(2.0, 6.0, n), np.nan),
            "side": rng.choice(["left", "right"], n),
            "rcs_m2": np.exp(rng.uniform(np.log(1.0), np.log(5.0), n)),
            "own_agl_m": rng.uniform(*FAST_CLOSURE_AGL_M, n),
        }
    )


def _intruder_spec(p: pd.Series) -> dict[str, Any]:
    kind = "crossing" if p["kind"] == "climbing" else str(p["kind"])
    spec = {
        "name": "intruder",
        "type": "encounter",
        "kind": kind,
        "t_cpa_s": T_CPA_S,
        "horizontal_miss_m": float(p["horizontal_miss_m"]),
        "vertical_miss_m": float(p["vertical_miss_m"]),
        "intruder_speed_mps": float(p["intruder_speed_mps"]),
        "side": str(p["side"]),
        "rcs_m2": float(p["rcs_m2"]),
        "rate_hz": 20.0,
    }
    if np.isfinite(p["crossing_angle_deg"]):
        spec["crossing_angle_deg"] = float(p["crossing_angle_deg"])
    if np.isfinite(p["climb_mps"]):
        spec["intruder_climb_mps"] = float(p["climb_mps"])
    return spec


def encounter_scenario(
    p: pd.Series,
    start_s: float,
    duration_s: float,
    frame_rate_hz: float,
    seed: int,
    terrain: str | None = None,
    *,
    radars: list[dict] | None = None,
    navigation: str | dict | None = None,
    own_altitude_m: float | None = None,
    terrain_seed: int | None = None,
    simulation: dict[str, Any] | None = None,
    rx_layout: str = "square",
) -> dict[str, Any]:
    """Scenario dict (:meth:`skyradar.scene.scenario.Scenario.from_dict`) of one encounter row.

    Own-ship passes the origin at the CPA. ``terrain``: None flies the encounter in clear sky
    (every detection is the intruder or noise); a name of
    :data:`skyradar.experiments.encounter_terrain.TERRAINS` puts that ground under it (``"flat"``:
    flat ground ``OWN_ALTITUDE_M`` below, 16 km square around the origin, so the ground clutter
    fills the range-Doppler image behind and around the intruder), simulated with the scenario
    defaults (facets no coarser than half a range bin) with the range and Doppler windows'
    point-spread, terrain speckle and Swerling 1 aircraft. ``own_altitude_m`` replaces the terrain's
    nominal own-ship altitude (:func:`~skyradar.experiments.encounter_terrain.site`; over hills
    and Jacksboro it is chosen from the ground under the track). ``radars`` is the scenario's
    ``radars:`` list (None: one forward head) and ``navigation`` its ``navigation:`` key (None:
    the scenario default). ``terrain_seed`` (default ``seed``) picks the hills surface and the
    point over Jacksboro. ``simulation`` overrides keys of the scenario's ``simulation:`` section
    (tests about scoring turn the costly realism off); ``rx_layout`` names every head's receive array.
    """
    from skyradar.experiments.encounter_terrain import site

    where = site(terrain, seed if terrain_seed is None else terrain_seed)
    alt = where["own_altitude_m"] if own_altitude_m is None else float(own_altitude_m)
    scenario = {
        "name": f"encounter {p['kind']}",
        "origin": where["origin"],
        "ownship": {
            "type": "straight",
            "start_ned_m": [-OWN_SPEED_MPS * T_CPA_S, 0.0, -alt],
            "heading_deg": 0.0,
            "speed_mps": OWN_SPEED_MPS,
            "start_time_s": 0.0,
            "duration_s": T_CPA_S + 10.0,
        },
        "intruders": [_intruder_spec(p)],
        "frame_rate_hz": frame_rate_hz,
        "start_s": float(start_s),
        "duration_s": float(duration_s),
        # The simulator's realistic options (sim.image): window point-spread, terrain speckle, Swerling 1.
        "simulation": {
            "noise": True,
            "seed": int(seed),
            "psf": True,
            "speckle": True,
            "swerling": 1,
            **(simulation or {}),
        },
    }
    if radars is None:
        scenario["mount"] = "forward"
    else:
        scenario["radars"] = [dict(r) for r in radars]
    if navigation is not None:
        scenario["navigation"] = navigation
    if rx_layout != "square":  # the prototype's array is the scenario default
        scenario["radar"] = {"rx_layout": rx_layout}
    if where["terrain"] is not None:
        scenario["terrain"] = where["terrain"]
    return scenario


def relative_truth(built) -> tuple[np.ndarray, np.ndarray]:
    """Dense truth times (s) and intruder-minus-own-ship NED positions (m) over own-ship's span."""
    own = built.ownship
    t = np.arange(own.start_s, own.end_s, _DT_TRUTH_S)
    rel = built.intruders[0].trajectory.sample(t).position_ned_m - own.sample(t).position_ned_m
    return t, rel


def _first(mask: np.ndarray, t: np.ndarray) -> float:
    return float(t[np.argmax(mask)]) if mask.any() else float("nan")


def event_times(t: np.ndarray, rel: np.ndarray) -> tuple[float, float]:
    """First loss of well clear (NaN: none) and closest approach of a dense relative truth, s.

    Examples
    --------
    >>> t = np.arange(0.0, 20.0, 0.5)
    >>> rel = np.stack([1000.0 - 100.0 * t, np.zeros_like(t), np.zeros_like(t)], axis=1)
    >>> event_times(t, rel)
    (3.5, 10.0)
    """
    vol = WellClearVolume.do365_noncoop()
    lowc = (np.hypot(rel[:, 0], rel[:, 1]) <= vol.dthr_m) & (np.abs(rel[:, 2]) <= vol.zthr_m)
    return _first(lowc, t), float(t[np.argmin(np.linalg.norm(rel, axis=1))])


def score_encounter(
    t: np.ndarray,
    rel: np.ndarray,
    warn_times_s: np.ndarray,
    observed: pd.DataFrame,
    buffer: float,
    observe_window_s: float,
) -> dict[str, float | bool]:
    """One encounter's result row from its dense relative truth and the chain's output.

    ``observed``: per frame ``time_s`` and ``observable`` (in the field of view with enough SNR).
    A conflict is *observable* when the intruder is observable in every frame of the
    ``observe_window_s`` before its LoWC.
    """
    vol = WellClearVolume.do365_noncoop()
    horiz, vert = np.hypot(rel[:, 0], rel[:, 1]), np.abs(rel[:, 2])
    t_lowc, t_cpa = event_times(t, rel)
    in_buffer = (horiz <= buffer * vol.dthr_m) & (vert <= buffer * vol.zthr_m)
    warn = np.sort(np.asarray(warn_times_s, float))
    t_warn = float(warn[0]) if warn.size else float("nan")
    conflict = bool(np.isfinite(t_lowc))
    observable = False
    if conflict:
        ft, ok = observed["time_s"].to_numpy(float), observed["observable"].to_numpy(bool)
        window = (ft >= t_lowc - observe_window_s) & (ft <= t_lowc)
        observable = bool(window.any() and ok[window].all())
    return {
        "t_lowc_s": t_lowc,
        "t_cpa_s": t_cpa,
        "conflict": conflict,
        "may_alert": bool(not conflict and in_buffer.any()),
        "observable": observable,
        "t_warning_s": t_warn,
        "min_horizontal_m": float(horiz.min()),
        "min_vertical_m": float(vert.min()),
        "min_distance_m": float(np.linalg.norm(rel, axis=1).min()),
    }


def rate_interval(count: int, trials: int) -> list[float]:
    """95 % Wilson score interval ``[low, high]`` of a rate ``count / trials`` (NaN without trials).

    A rate from a few dozen encounters is a wide range, not a number: one false warning in 34
    must-not-alert encounters is anywhere from 0.5 % to 15 %. The Wilson interval (scipy's
    ``binomtest(...).proportion_ci(method="wilson")``) keeps its coverage near 95 % down to counts of
    0 and ``trials``, where the normal approximation collapses to a point.

    Examples
    --------
    >>> [round(x, 3) for x in rate_interval(1, 34)]
    [0.005, 0.149]
    >>> [round(x, 3) for x in rate_interval(0, 34)]
    [0.0, 0.102]
    """
    if trials <= 0:
        return [float("nan"), float("nan")]
    from scipy.stats import binomtest

    ci = binomtest(int(count), int(trials)).proportion_ci(confidence_level=0.95, method="wilson")
    return [float(ci.low), float(ci.high)]


def summarise(res: pd.DataFrame, late_lead_s: float) -> dict[str, Any]:
    """Counts and rates of the encounter table (see ``skyradar experiment encounters --help``);
    each rate with its 95 % interval (:func:`rate_interval`, key ``RATE_ci95``).

    The false warnings (warnings in must-not-alert encounters) are split by whether the same
    alerter warns on perfect surveillance too (column ``t_truth_warning_s``): an intruder that
    heads at the own-ship and turns away is warned by any alerter that projects straight lines
    (``false_warnings_alerter``); the rest are the sensor's (``false_warnings_sensor``). Without
    the column these counts are NaN. ``false_warnings_altitude_prior`` counts the false warnings
    whose first warning rests on a co-altitude prior (column ``warned_on_altitude_prior``): the
    track's elevation was never measured, so an intruder that passes above or below looks level and
    must be warned (NaN without the column). A pilot hears a warning whatever track raised it:
    ``false_warnings_any_track`` counts the must-not-alert encounters warned on the intruder's track
    or on any other (clutter, ground; column ``t_other_warning_s``), with its rate and interval
    (NaN without the column).

    Examples
    --------
    Two must-not-alert encounters, one warned on a clutter track only, and a conflict warned in time:

    >>> res = pd.DataFrame({"observable": [False, False, True], "conflict": [False, False, True],
    ...                     "may_alert": False, "t_lowc_s": [np.nan, np.nan, 30.0],
    ...                     "t_warning_s": [np.nan, np.nan, 5.0], "t_other_warning_s": [np.nan, 9.0, np.nan]})
    >>> s = summarise(res, 12.5)
    >>> s["false_warnings"], s["false_warnings_any_track"], s["median_warning_lead_s"]
    (0, 1, 25.0)
    """
    lead = res["t_lowc_s"] - res["t_warning_s"]
    in_time = res["t_warning_s"] < res["t_lowc_s"]
    obs, conflict = res["observable"], res["conflict"]
    must_not = ~conflict & ~res["may_alert"]
    warned = res["t_warning_s"].notna()
    good = obs & in_time
    keys = ("false_warnings_alerter", "false_warnings_sensor", "must_not_alert_truth_warned")
    split: dict[str, Any] = dict.fromkeys(keys, float("nan"))
    if "t_truth_warning_s" in res:
        truth_warned = res["t_truth_warning_s"].notna()
        split = {
            "false_warnings_alerter": int((must_not & warned & truth_warned).sum()),
            "false_warnings_sensor": int((must_not & warned & ~truth_warned).sum()),
            "must_not_alert_truth_warned": int((must_not & truth_warned).sum()),
        }
    any_track: dict[str, Any] = {
        "false_warnings_any_track": np.nan,
        "false_warning_rate_any_track": np.nan,
        "false_warning_rate_any_track_ci95": [np.nan, np.nan],
    }
    if "t_other_warning_s" in res:
        heard = int((must_not & (warned | res["t_other_warning_s"].notna())).sum())
        any_track = {
            "false_warnings_any_track": heard,
            "false_warning_rate_any_track": float(heard / max(int(must_not.sum()), 1)),
            "false_warning_rate_any_track_ci95": rate_interval(heard, int(must_not.sum())),
        }
    prior = float("nan")
    if "warned_on_altitude_prior" in res:
        prior = int((must_not & warned & res["warned_on_altitude_prior"].fillna(False).astype(bool)).sum())
    return {
        "encounters": int(len(res)),
        "conflicts": int(conflict.sum()),
        "observable_conflicts": int(obs.sum()),
        "missed_warnings": int((obs & ~in_time).sum()),
        "missed_warnings_unobservable": int((conflict & ~obs & ~in_time).sum()),
        "late_warnings": int((good & (lead < late_lead_s)).sum()),
        "non_conflicts": int((~conflict).sum()),
        "may_alert_encounters": int(res["may_alert"].sum()),
        "may_alert_warned": int((res["may_alert"] & warned).sum()),
        "must_not_alert_encounters": int(must_not.sum()),
        "false_warnings": int((must_not & warned).sum()),
        "false_warning_rate": float((must_not & warned).sum() / max(int(must_not.sum()), 1)),
        "false_warning_rate_ci95": rate_interval(int((must_not & warned).sum()), int(must_not.sum())),
        **split,
        "false_warnings_altitude_prior": prior,
        **any_track,
        "missed_warning_rate": float((obs & ~in_time).sum() / max(int(obs.sum()), 1)),
        "missed_warning_rate_ci95": rate_interval(int((obs & ~in_time).sum()), int(obs.sum())),
        "median_warning_lead_s": float(np.median(lead[good])) if good.any() else float("nan"),
    }


def plot_encounters(res: pd.DataFrame, path: Path, buffer: float, warning_time_s: float) -> None:
    """Miss-distance scatter coloured by outcome, and the warning lead histogram (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(11, 4.5))
    warned = res["t_warning_s"].notna()
    hidden = res["conflict"] & ~res["observable"]
    groups = (
        (warned & ~hidden, "tab:red", "warning issued"),
        (~warned & ~hidden, "tab:green", "no warning"),
        (hidden, "0.6", "conflict not observable (FOV / SNR)"),
    )
    for mask, colour, label in groups:
        ax[0].scatter(
            res.loc[mask, "min_horizontal_m"], res.loc[mask, "min_vertical_m"], s=8, c=colour, label=label
        )
    vol = WellClearVolume.do365_noncoop()
    ax[0].add_patch(plt.Rectangle((0, 0), vol.dthr_m, vol.zthr_m, fill=False, ls="--", color="k"))
    ax[0].add_patch(
        plt.Rectangle((0, 0), buffer * vol.dthr_m, buffer * vol.zthr_m, fill=False, ls=":", color="k")
    )
    ax[0].set(
        xlabel="minimum horizontal separation [m]",
        ylabel="minimum vertical separation [m]",
        title=f"encounters (dashed: well clear; dotted: x{buffer:g} may-alert buffer)",
    )
    ax[0].legend(loc="upper right", fontsize=8)
    lead = (res["t_lowc_s"] - res["t_warning_s"])[res["observable"]]
    ax[1].hist(lead.dropna(), bins=30, color="tab:blue")
    ax[1].axvline(warning_time_s, color="k", ls="--", label=f"warning alerting time {warning_time_s:g} s")
    ax[1].set(
        xlabel="warning lead before loss of well clear [s]",
        ylabel="observable conflicts",
        title="warning lead",
    )
    ax[1].legend()
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=110)
    plt.close(fig)
