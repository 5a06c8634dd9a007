"""Figures of experiment ch4: tracks in the range-Doppler image and in the horizontal body frame,
and the innovation histograms of both trackers."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from skyradar.config import RadarConfig
from skyradar.io.atomic import savefig_atomic
from skyradar.units import wrap

__all__ = ["draw_figures"]


def _track_colours(ids: np.ndarray) -> np.ndarray:
    import matplotlib.pyplot as plt

    uniq, inv = np.unique(ids, return_inverse=True)
    return plt.get_cmap("tab20")(inv % 20)


def _range_doppler(results: list[dict], out_dir: Path, config: RadarConfig) -> str:
    import matplotlib.pyplot as plt

    width = 2 * config.v_lim_mps
    fig, axes = plt.subplots(len(results), 2, figsize=(11, 4.2 * len(results)), squeeze=False)
    for row, res in enumerate(results):
        det = res["detections_table"]
        for col, model in enumerate(("radar", "traditional")):
            ax = axes[row, col]
            ax.scatter(det.radial_velocity_mps, det.range_m, s=1, c="0.8", rasterized=True)
            trk = res["tracks"][model]
            if len(trk):
                ax.scatter(
                    wrap(trk.radial_velocity_mps.to_numpy(), width),
                    trk.range_m,
                    s=2,
                    c=_track_colours(trk.track_id.to_numpy()),
                    rasterized=True,
                )
            ax.set_xlim(-config.v_lim_mps, config.v_lim_mps)
            ax.set_ylim(0, config.range_limit_m)
            n = res[f"tracks_{model}"]
            ax.set_title(f"{res['scenario']}: {model} tracker, {n} tracks (truth {res['truth_tracks']})")
            ax.set_xlabel("radial velocity in the image [m/s]")
            ax.set_ylabel("range [m]")
    fig.tight_layout()
    path = out_dir / "ch4_tracks_range_doppler.png"
    savefig_atomic(fig, path, dpi=90)
    plt.close(fig)
    return path.name


def _body_frame(results: list[dict], out_dir: Path) -> str:
    import matplotlib.pyplot as plt

    from skyradar.geo import rotation_matrix

    fig, axes = plt.subplots(1, len(results), figsize=(5.5 * len(results), 5.5), squeeze=False)
    for ax, res in zip(axes[0], results, strict=True):
        truth, own = res["truth"], res["truth"]["own"]
        R = rotation_matrix(own.attitude_rad[:, 0], own.attitude_rad[:, 1], own.attitude_rad[:, 2])
        rel = truth["pos"] - own.position_ned_m[:, None, :]
        body = np.einsum("nji,nmj->nmi", R, rel)  # R^T (p - own)
        vis = res["visible"]
        ax.scatter(
            body[..., 1][vis], body[..., 0][vis], s=3, c="0.75", label="truth (visible)", rasterized=True
        )
        trk = res["tracks"]["radar"]
        trk = trk[np.isfinite(trk.north_m)]
        if len(trk):
            k = trk.frame.to_numpy().astype(int)
            p = trk[["north_m", "east_m", "down_m"]].to_numpy() - own.position_ned_m[k]
            b = np.einsum("nji,nj->ni", R[k], p)
            ax.scatter(
                b[:, 1], b[:, 0], s=2, c=_track_colours(trk.track_id.to_numpy()), label="radar-aware tracks"
            )
        ax.set_xlim(-4000, 4000)
        ax.set_ylim(-500, 5000)
        ax.set_aspect("equal")
        ax.set_xlabel("right [m]")
        ax.set_ylabel("forward [m]")
        ax.set_title(f"{res['scenario']}: horizontal body frame")
        ax.legend(loc="lower right", fontsize=8, markerscale=3)
    fig.tight_layout()
    path = out_dir / "ch4_tracks_body.png"
    savefig_atomic(fig, path, dpi=90)
    plt.close(fig)
    return path.name


def _innovation_hist(results: list[dict], out_dir: Path, config: RadarConfig) -> str:
    import matplotlib.pyplot as plt

    pix = (config.range_resolution_m, config.doppler_resolution_mps)
    fig, axes = plt.subplots(1, len(results), figsize=(5 * len(results), 3.8), squeeze=False)
    bins = np.linspace(0, 15, 61)
    for ax, res in zip(axes[0], results, strict=True):
        for model, colour in (("traditional", "tab:orange"), ("radar", "tab:blue")):
            trk = res["tracks"][model]
            y = trk[["innovation_range_m", "innovation_radial_velocity_mps"]].to_numpy()
            y = y[np.all(np.isfinite(y), axis=1)]
            px = np.hypot(y[:, 0] / pix[0], y[:, 1] / pix[1])
            ax.hist(
                np.minimum(px, bins[-1]),
                bins,
                histtype="step",
                color=colour,
                label=f"{model}: mean {px.mean():.2f}, p95 {np.percentile(px, 95):.2f} px",
            )
        ax.set_yscale("log")
        ax.set_xlabel("innovation l2 [pixels]")
        ax.set_title(res["scenario"])
        ax.legend(fontsize=8)
    fig.tight_layout()
    path = out_dir / "ch4_innovation_hist.png"
    savefig_atomic(fig, path, dpi=90)
    plt.close(fig)
    return path.name


def draw_figures(results: list[dict], out_dir: Path) -> list[str]:
    """Write the three ch4 figures into ``out_dir``; returns their file names."""
    import matplotlib

    matplotlib.use("Agg")
    config = RadarConfig.prototype_2022()
    return [
        _range_doppler(results, out_dir, config),
        _body_frame(results, out_dir),
        _innovation_hist(results, out_dir, config),
    ]
