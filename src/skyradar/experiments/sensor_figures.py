"""Surveillance figures of the radar in an encounter set, as a DAA radar is specified (DO-366 style).

An avionics engineer buys a DAA radar by what its tracks are worth, not by its warnings alone:

- **declaration range**: the slant range (truth) at which the intruder's track is first confirmed,
  against the closing speed then: the farther, the more time the alerting has;
- **time to confirm**: from the intruder track's first row (its first associated detection) to its
  first confirmed row, s;
- **track accuracy against range**: horizontal and vertical position error and horizontal velocity
  error of the intruder's confirmed track rows against the simulator's truth at the same frame,
  RMS and 95th percentile per range band;
- **false tracks per flight hour**: confirmed tracks that follow no intruder (clutter and ground).

The truth is the simulator's (target 0 of the first head's truth), never the tracker's.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from skyradar.io.atomic import savefig_atomic

__all__ = [
    "intruder_track_figures",
    "sensor_summary",
    "plot_sensor_figures",
    "RANGE_BANDS_M",
    "CLOSING_BANDS_MPS",
]

RANGE_BANDS_M = (0.0, 1000.0, 2000.0, 3000.0, 5000.0)
CLOSING_BANDS_MPS = (0.0, 100.0, 150.0, 200.0, np.inf)
_MAX_ERROR_ROWS = 200  # per encounter: enough for percentiles over a set, small in the table


def intruder_track_figures(tracks: pd.DataFrame, labels: dict[int, str], truth: Any) -> dict[str, Any]:
    """Declaration range, closing speed then, time to confirm and the error samples of one
    encounter's intruder tracks (those ``labels`` names after target 0 of ``truth``).

    Returns ``declaration_range_m``, ``declaration_closing_mps``, ``time_to_confirm_s`` (NaN
    when no intruder track was confirmed) and ``track_errors``: up to 200 rows, evenly spread over
    the confirmed rows, of ``[range_m, horizontal_m, vertical_m, velocity_mps]``.

    Examples
    --------
    >>> import xarray as xr
    >>> t = np.arange(5.0)
    >>> truth = xr.Dataset(
    ...     {**{f"tgt_{a}_m": (("time", "target"), v[:, None]) for a, v in
    ...         (("north", 3000.0 - 100.0 * t), ("east", 0.0 * t), ("down", -1000.0 + 0.0 * t))},
    ...      **{f"tgt_{a}_mps": (("time", "target"), v[:, None]) for a, v in
    ...         (("vn", -100.0 + 0.0 * t), ("ve", 0.0 * t), ("vd", 0.0 * t))},
    ...      **{f"own_{a}_m": ("time", v) for a, v in (("north", 0.0 * t), ("east", 0.0 * t),
    ...                                                 ("down", -1000.0 + 0.0 * t))}},
    ...     coords={"time": t, "target": ["intruder"]})
    >>> tracks = pd.DataFrame({"time_s": t, "track_id": 1, "north_m": 3000.0 - 100.0 * t + 10.0,
    ...     "east_m": 0.0, "down_m": -1000.0, "vn_mps": -100.0, "ve_mps": 0.0, "vd_mps": 0.0,
    ...     "confirmed": [False, False, True, True, True]})
    >>> f = intruder_track_figures(tracks, {1: "intruder"}, truth)
    >>> f["declaration_range_m"], f["declaration_closing_mps"], f["time_to_confirm_s"]
    (2800.0, 100.0, 2.0)
    >>> f["track_errors"][0]
    [2800.0, 10.0, 0.0, 0.0]
    """
    from skyradar.io.frames_model import frame_times_s

    name = str(truth["target"].values[0])
    nan = float("nan")
    out: dict[str, Any] = {
        "declaration_range_m": nan,
        "declaration_closing_mps": nan,
        "time_to_confirm_s": nan,
        "track_errors": [],
    }
    mine = [int(tid) for tid, label in labels.items() if label == name]
    rows = tracks[tracks["track_id"].isin(mine)] if len(tracks) else tracks
    if not len(rows) or "confirmed" not in rows or not rows["confirmed"].astype(bool).any():
        return out
    times = frame_times_s(truth)
    tgt = np.stack([truth[f"tgt_{a}_m"].values[:, 0] for a in ("north", "east", "down")], -1)
    tgt_v = np.stack([truth[f"tgt_{a}_mps"].values[:, 0] for a in ("vn", "ve", "vd")], -1)
    own = np.stack([truth[f"own_{a}_m"].values for a in ("north", "east", "down")], -1)
    rel = tgt - own
    rng = np.linalg.norm(rel, axis=1)
    closing = -np.gradient(rng, times) if times.size > 1 else np.zeros_like(rng)

    def frame(t_s: np.ndarray) -> np.ndarray:
        return np.clip(np.searchsorted(times, np.asarray(t_s, float) - 1e-6), 0, times.size - 1)

    confirmed = rows[rows["confirmed"].astype(bool)].sort_values("time_s", kind="stable")
    first_confirmed = float(confirmed["time_s"].iloc[0])
    k = frame(np.array([first_confirmed]))[0]
    out["declaration_range_m"] = float(rng[k])
    out["declaration_closing_mps"] = float(closing[k])
    out["time_to_confirm_s"] = first_confirmed - float(rows["time_s"].min())
    idx = frame(confirmed["time_s"].to_numpy(float))
    pos = confirmed[["north_m", "east_m", "down_m"]].to_numpy(float)
    vel = confirmed[["vn_mps", "ve_mps"]].to_numpy(float)
    err = pos - tgt[idx]
    errors = np.column_stack(
        [
            rng[idx],
            np.hypot(err[:, 0], err[:, 1]),
            np.abs(err[:, 2]),
            np.hypot(*(vel - tgt_v[idx, :2]).T),
        ]
    )
    keep = np.unique(np.linspace(0, len(errors) - 1, min(len(errors), _MAX_ERROR_ROWS)).round().astype(int))
    out["track_errors"] = errors[keep].round(2).tolist()
    return out


def _error_samples(res: pd.DataFrame) -> np.ndarray:
    """All rows' ``track_errors`` stacked (n, 4); rows without samples (none confirmed, or a row
    of a table written before the column existed) add none. A Parquet round trip gives arrays of
    arrays, a fresh table lists of lists: both stack."""
    parts = []
    for entry in res.get("track_errors", []):
        if isinstance(entry, list | tuple | np.ndarray) and len(entry):
            parts.append(np.vstack([np.asarray(x, float) for x in entry]))
    return np.vstack(parts) if parts else np.zeros((0, 4))


def sensor_summary(res: pd.DataFrame) -> dict[str, Any]:
    """The surveillance figures of one terrain and layout's rows of the encounter table.

    ``declaration_range_m`` (median, 10th and 90th percentile over the encounters whose intruder
    was confirmed), the same by closing-speed band, ``time_to_confirm_s`` (median, 90th
    percentile), ``track_error_by_range`` (per band of :data:`RANGE_BANDS_M`: samples, RMS and 95th
    percentile of the horizontal and vertical position error, m, and the horizontal velocity
    error, m/s) and ``false_tracks_per_hour`` (clutter and ground tracks over the flight time).
    """
    decl = res["declaration_range_m"].to_numpy(float) if "declaration_range_m" in res else np.array([])
    found = np.isfinite(decl)

    def spread(x: np.ndarray, q: tuple[float, ...]) -> dict[str, float]:
        return {f"p{int(p * 100)}": float(np.quantile(x, p)) for p in q} if x.size else {}

    closing = res["declaration_closing_mps"].to_numpy(float) if "declaration_closing_mps" in res else decl
    by_closing = {}
    for lo, hi in zip(CLOSING_BANDS_MPS[:-1], CLOSING_BANDS_MPS[1:], strict=True):
        band = found & (closing >= lo) & (closing < hi)
        label = f"{lo:g}-{hi:g}" if np.isfinite(hi) else f">={lo:g}"
        by_closing[label] = {"encounters": int(band.sum()), **spread(decl[band], (0.5,))}
    confirm = res["time_to_confirm_s"].to_numpy(float) if "time_to_confirm_s" in res else decl
    errors = _error_samples(res)
    by_range = {}
    for lo, hi in zip(RANGE_BANDS_M[:-1], RANGE_BANDS_M[1:], strict=True):
        band = errors[(errors[:, 0] >= lo) & (errors[:, 0] < hi)]
        entry: dict[str, float | int] = {"samples": int(len(band))}
        for col, key in ((1, "horizontal_m"), (2, "vertical_m"), (3, "velocity_mps")):
            if len(band):
                entry[f"{key}_rms"] = float(np.sqrt(np.mean(band[:, col] ** 2)))
                entry[f"{key}_p95"] = float(np.quantile(band[:, col], 0.95))
        by_range[f"{lo / 1000:g}-{hi / 1000:g} km"] = entry
    hours = float(res["flight_s"].sum()) / 3600.0 if "flight_s" in res else 0.0
    false_tracks = float(
        res.get("clutter_tracks", pd.Series(0)).sum() + res.get("ground_tracks", pd.Series(0)).sum()
    )
    return {
        "intruder_confirmed_encounters": int(found.sum()),
        "declaration_range_m": spread(decl[found], (0.1, 0.5, 0.9)),
        "declaration_range_by_closing_mps": by_closing,
        "time_to_confirm_s": spread(confirm[np.isfinite(confirm)], (0.5, 0.9)),
        "track_error_by_range": by_range,
        "false_tracks_per_hour": false_tracks / hours if hours > 0 else float("nan"),
    }


def plot_sensor_figures(res: pd.DataFrame, path: Path, title: str) -> None:
    """Declaration range against closing speed, and the track errors against range (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 2, figsize=(11, 4.5))
    if "declaration_range_m" in res:
        ax[0].scatter(res["declaration_closing_mps"], res["declaration_range_m"] / 1000.0, s=10)
    ax[0].set(
        xlabel="closing speed at declaration [m/s]",
        ylabel="declaration range [km]",
        title=f"{title}: intruder track first confirmed",
    )
    errors = _error_samples(res)
    if len(errors):
        ax[1].scatter(errors[:, 0] / 1000.0, errors[:, 1], s=3, alpha=0.3, label="horizontal")
        ax[1].scatter(errors[:, 0] / 1000.0, errors[:, 2], s=3, alpha=0.3, label="vertical")
        ax[1].legend()
    ax[1].set(
        xlabel="range [km]",
        ylabel="position error [m]",
        yscale="log",
        title="confirmed intruder track rows against truth",
    )
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=110)
    plt.close(fig)
