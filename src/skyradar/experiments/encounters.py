"""Encounter set: does the DAA layer warn in time for conflicts, and stay quiet for near misses?

Chain (``chain="sensor-model"``; the full image chain is too slow for hundreds of encounters in
minutes on two cores and is not wired here): truth trajectories from
:func:`skyradar.scene.flights.encounter` -> a radar measurement model -> the project's 3-D tracker
(:class:`skyradar.track.tracker3d.Tracker3D`, ideal association) -> :func:`alerts_from_tracks`.

Measurement model, per frame at ``frame_rate_hz``: an intruder inside the range limit and the field
of view (``fov_deg`` full width in azimuth and elevation around boresight, forward mount) is
detected with probability ``p_detect``; its range gets Gaussian noise of ``dR / sqrt(12)`` (the
range bin's uniform spread) and its
direction Gaussian azimuth / elevation noise of ``sigma_az_deg`` / ``sigma_el_deg`` (seed-brief.md
ch3: raw DoA SD 1.8 deg and 2.7 deg).

Own-ship flies north, level, at 50 m/s, 1000 m up, for ``duration_s``; each intruder reaches its
closest point of approach at ``t_cpa_s``. The set mixes head-on, crossing, overtaking, converging
and climbing-through geometries with horizontal misses 0-1600 m and vertical misses 0-300 m, so
it holds conflicts and near misses that stay well clear.

Scoring (non-cooperative DO-365 volume, 2200 ft / 450 ft): a *conflict* is a truth loss of well
clear; it is *observable* when the intruder is inside range and field of view over the whole
warning window ``[t_LoWC - 25 s, t_LoWC]``. A *missed warning* is an observable conflict without a
warning (issued level 3) before ``t_LoWC``; a *late warning* comes less than ``late_lead_s`` before
it; a *false warning* is any warning in a non-conflict encounter.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pandas as pd

from skyradar.config import RadarConfig
from skyradar.daa.alerting import AlertConfig
from skyradar.daa.conflict import WellClearVolume
from skyradar.daa.pipeline import alerts_from_tracks
from skyradar.io.tables import write_json_atomic, write_table
from skyradar.scene.flights import encounter, straight
from skyradar.track.tracker3d import Tracker3D

__all__ = ["make_encounters", "run_encounters", "run_encounter", "run"]

_KINDS = ("head-on", "crossing", "overtaking", "converging", "climbing")


def make_encounters(n: int, seed: int = 0) -> pd.DataFrame:
    """Encounter parameters: kind, horizontal / vertical miss (m), intruder speed (m/s), angle, climb.

    Examples
    --------
    >>> make_encounters(5).columns.tolist()[:3]
    ['kind', 'horizontal_miss_m', 'vertical_miss_m']
    """
    rng = np.random.default_rng(seed)
    kind = np.array(_KINDS)[np.arange(n) % len(_KINDS)]
    # Half the set close to the 2200 ft / 450 ft boundary, half spread wider.
    h = np.where(rng.random(n) < 0.5, rng.uniform(0, 1000, n), rng.uniform(0, 1600, n))
    v = np.where(rng.random(n) < 0.6, rng.uniform(0, 160, n), rng.uniform(0, 300, n))
    climbing = kind == "climbing"
    v[climbing] = 0.0
    speed = np.where(kind == "overtaking", rng.uniform(65, 80, n), rng.uniform(30, 70, n))
    return pd.DataFrame(
        {
            "kind": kind,
            "horizontal_miss_m": h,
            "vertical_miss_m": v * rng.choice([-1.0, 1.0], n),
            "intruder_speed_mps": speed,
            "crossing_angle_deg": np.where(
                kind == "converging", rng.uniform(20, 70, n), rng.uniform(60, 120, n)
            ),
            "climb_mps": np.where(climbing, rng.choice([-1.0, 1.0], n) * rng.uniform(2.0, 6.0, n), np.nan),
        }
    )


def _intruder(own, p: pd.Series, t_cpa_s: float):
    kind = "crossing" if p.kind == "climbing" else p.kind
    kw = {"crossing_angle_deg": float(p.crossing_angle_deg)} if kind in ("crossing", "converging") else {}
    if p.kind == "climbing":
        kw["intruder_climb_mps"] = float(p.climb_mps)
    return encounter(
        own, kind, t_cpa_s, float(p.horizontal_miss_m), float(p.vertical_miss_m), float(p.intruder_speed_mps),
        rate_hz=10.0, **kw,
    )  # fmt: skip


def _measure(rel: np.ndarray, rng, config: RadarConfig, fov_deg, p_detect, sigma_az, sigma_el, sigma_r):
    """Noisy relative NED positions (NaN when not detected), per-axis variances (m^2) and visibility."""
    r = np.linalg.norm(rel, axis=-1)
    az = np.arctan2(rel[..., 1], rel[..., 0])  # forward mount, own-ship level and heading north
    el = np.arctan2(-rel[..., 2], np.hypot(rel[..., 0], rel[..., 1]))
    half = np.radians(fov_deg / 2)
    visible = (r <= config.range_limit_m) & (np.abs(az) <= half) & (np.abs(el) <= half)
    detected = visible & (rng.random(r.shape) < p_detect)
    rm = r + rng.normal(0, sigma_r, r.shape)
    azm = az + rng.normal(0, sigma_az, r.shape)
    elm = el + rng.normal(0, sigma_el, r.shape)
    meas = np.stack([rm * np.cos(elm) * np.cos(azm), rm * np.cos(elm) * np.sin(azm), -rm * np.sin(elm)], -1)
    meas[~detected] = np.nan
    return meas, (r * max(sigma_az, sigma_el)) ** 2 + sigma_r**2, visible


_TRACK_COLS = ["time_s", "track_id", "north_m", "east_m", "down_m", "vn_mps", "ve_mps", "vd_mps"] + [
    f"cov_{m}_{i}{j}" for m in ("pp", "vv") for i in range(3) for j in range(3)
]


def _track(t: np.ndarray, meas_ned: np.ndarray, var: np.ndarray, coast_s: float = 1.0) -> pd.DataFrame:
    """3-D tracks table, one track per encounter (id = row), from noisy NED positions (n_enc, n_t, 3).

    Like the range-Doppler tracker, a track is dropped after ``coast_s`` without a detection; a later
    detection starts a new track (same id, fresh filter).
    """
    tracker, ids, rows = Tracker3D(), np.arange(meas_ned.shape[0]), []
    last_seen = np.full(ids.size, -np.inf)
    for i, ti in enumerate(t):
        seen = np.isfinite(meas_ned[:, i, 0])
        last_seen[seen] = ti
        alive = ti - last_seen <= coast_s
        x, P = tracker.step(float(ti), ids[alive], meas_ned[alive, i], var[alive, i])
        ok = np.isfinite(x[:, 0])
        k = int(ok.sum())
        rows.append(np.hstack([np.full((k, 1), ti), ids[alive][ok, None], x[ok], P[ok, :3, :3].reshape(k, 9),
                               P[ok, 3:, 3:].reshape(k, 9)]))  # fmt: skip
    return pd.DataFrame(np.vstack(rows), columns=_TRACK_COLS).astype({"track_id": int})


def _ownship_table(t: np.ndarray, own) -> pd.DataFrame:
    cols = {"time_s": t}
    for i, k in enumerate(["north_m", "east_m", "down_m"]):
        cols[f"own_{k}"] = own.position_ned_m[:, i]
    for i, k in enumerate(["vn_mps", "ve_mps", "vd_mps"]):
        cols[f"own_{k}"] = own.velocity_ned_mps[:, i]
    return pd.DataFrame(cols)


def run_encounters(
    params: pd.DataFrame,
    seed: int = 0,
    frame_rate_hz: float = 9.4,
    duration_s: float = 90.0,
    t_cpa_s: float = 60.0,
    fov_deg: float = 70.0,
    p_detect: float = 0.9,
    sigma_az_deg: float = 1.8,
    sigma_el_deg: float = 2.7,
    sigma_range_m: float | None = None,
    alert_config: AlertConfig | None = None,
) -> pd.DataFrame:
    """Encounters (rows of :func:`make_encounters`) through the chain, all at once (one tracker, one
    alerting pass; encounters are independent). One result row per encounter; times in s, NaN when none.
    """
    config = RadarConfig.seed_prototype()
    t = np.arange(0.0, duration_s, 1.0 / frame_rate_hz)
    own_t = straight([0.0, 0.0, -1000.0], 0.0, 50.0, duration_s, rate_hz=10.0)
    own = own_t.sample(t)
    rel = np.stack([_intruder(own_t, p, t_cpa_s).sample(t).position_ned_m for _, p in params.iterrows()])
    rel -= own.position_ned_m[None]
    vol = WellClearVolume.do365_noncoop()
    lowc = (np.hypot(rel[..., 0], rel[..., 1]) <= vol.dthr_m) & (np.abs(rel[..., 2]) <= vol.zthr_m)
    t_lowc = np.where(lowc.any(axis=1), t[np.argmax(lowc, axis=1)], np.nan)
    sig = np.radians([sigma_az_deg, sigma_el_deg])
    sigma_r = config.range_resolution_m / np.sqrt(12) if sigma_range_m is None else sigma_range_m
    meas, var, visible = _measure(rel, np.random.default_rng(seed), config, fov_deg, p_detect, *sig, sigma_r)
    tracks = _track(t, meas + own.position_ned_m[None], var)
    alerts = alerts_from_tracks(tracks, _ownship_table(t, own), alert_config, with_advice=False)
    warn = alerts[alerts["level"] >= 3].groupby("track_id")["time_s"].min()
    window = (t[None] >= t_lowc[:, None] - 25.0) & (t[None] <= t_lowc[:, None])
    return pd.DataFrame(
        {
            "t_lowc_s": t_lowc,
            "conflict": lowc.any(axis=1),
            "observable": lowc.any(axis=1) & np.all(visible | ~window, axis=1),
            "t_warning_s": warn.reindex(np.arange(len(params))).to_numpy(float),
            "min_horizontal_m": np.min(np.hypot(rel[..., 0], rel[..., 1]), axis=1),
            "min_vertical_m": np.min(np.abs(rel[..., 2]), axis=1),
        }
    )


def run_encounter(p: pd.Series, seed: int = 0, **kw) -> dict:
    """One encounter through :func:`run_encounters`; returns its result row as a dict."""
    return run_encounters(p.to_frame().T.reset_index(drop=True), seed, **kw).iloc[0].to_dict()


def _summary(res: pd.DataFrame, late_lead_s: float) -> dict:
    lead = res["t_lowc_s"] - res["t_warning_s"]
    warned_in_time = res["t_warning_s"] <= res["t_lowc_s"]
    obs = res["observable"]
    non = ~res["conflict"]
    good = obs & warned_in_time
    return {
        "encounters": int(len(res)),
        "conflicts": int(res["conflict"].sum()),
        "observable_conflicts": int(obs.sum()),
        "missed_warnings": int((obs & ~warned_in_time).sum()),
        "missed_warnings_unobservable": int((res["conflict"] & ~obs & ~warned_in_time).sum()),
        "late_warnings": int((obs & warned_in_time & (lead < late_lead_s)).sum()),
        "false_warnings": int((non & res["t_warning_s"].notna()).sum()),
        "non_conflicts": int(non.sum()),
        "false_warning_rate": float((non & res["t_warning_s"].notna()).sum() / max(int(non.sum()), 1)),
        "median_warning_lead_s": float(np.median(lead[good])) if good.any() else float("nan"),
    }


def _figure(res: pd.DataFrame, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(11, 4.5))
    warned = res["t_warning_s"].notna()
    hidden = res["conflict"] & ~res["observable"]
    groups = ((warned & ~hidden, "tab:red", "warning issued"), (~warned & ~hidden, "tab:green", "no warning"),
              (hidden, "0.6", "conflict outside field of view / range"))  # fmt: skip
    for mask, colour, label in groups:
        ax[0].scatter(
            res.loc[mask, "min_horizontal_m"], res.loc[mask, "min_vertical_m"], s=8, c=colour, label=label
        )
    vol = WellClearVolume.do365_noncoop()
    ax[0].add_patch(plt.Rectangle((0, 0), vol.dthr_m, vol.zthr_m, fill=False, ls="--", color="k"))
    ax[0].set(xlabel="minimum horizontal separation [m]", ylabel="minimum vertical separation [m]",
              title="encounters (dashed: 2200 ft / 450 ft well clear)")  # fmt: skip
    ax[0].legend(loc="upper right", fontsize=8)
    lead = (res["t_lowc_s"] - res["t_warning_s"])[res["observable"]]
    ax[1].hist(lead.dropna(), bins=30, color="tab:blue")
    ax[1].axvline(25.0, color="k", ls="--", label="warning alerting time 25 s")
    ax[1].set(
        xlabel="warning lead before loss of well clear [s]", ylabel="observable conflicts", title="lead"
    )
    ax[1].legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def run(
    out_dir: Path,
    n_encounters: int = 500,
    seed: int = 0,
    frame_rate_hz: float = 9.4,
    late_lead_s: float = 12.5,
    uncertainty: bool = True,
    sigma_az_deg: float = 1.8,
    sigma_el_deg: float = 2.7,
) -> dict:
    """Run the encounter set; write ``encounters.parquet``, ``encounters.csv``, ``summary.json`` and
    ``encounters.png`` into ``out_dir``; return the summary.

    ``uncertainty=False`` turns off the widening of the volumes by the track covariance (all
    z-scores 0). ``late_lead_s``: a warning with less lead than this (default half the 25 s
    warning alerting time) is late.
    """
    t0 = time.perf_counter()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    cfg = AlertConfig() if uncertainty else AlertConfig(z_h_pos=0.0, z_h_vel=0.0, z_v_pos=0.0, z_v_vel=0.0)
    enc = make_encounters(n_encounters, seed)
    out = run_encounters(enc, seed, frame_rate_hz, alert_config=cfg, sigma_az_deg=sigma_az_deg,
                         sigma_el_deg=sigma_el_deg)  # fmt: skip
    res = pd.concat([enc, out], axis=1)
    summary = _summary(res, late_lead_s)
    summary.update(chain="sensor-model", frame_rate_hz=frame_rate_hz, uncertainty=uncertainty,
                   sigma_az_deg=sigma_az_deg, sigma_el_deg=sigma_el_deg, seed=seed)  # fmt: skip
    write_table(res, out_dir / "encounters.parquet")
    res.to_csv(out_dir / "encounters.csv", index=False)
    _figure(res, out_dir / "encounters.png")
    summary["runtime_s"] = time.perf_counter() - t0
    write_json_atomic(out_dir / "summary.json", summary)
    return summary
