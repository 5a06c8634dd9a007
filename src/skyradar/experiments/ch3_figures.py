"""Figures of the ch3 experiment: range-Doppler with detections, 3-D track vs truth, errors over time,
DoA error SD against the Cramer-Rao bound for several array spacings."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from skyradar.config import RadarConfig  # noqa: E402
from skyradar.io.atomic import savefig_atomic  # noqa: E402
from skyradar.process.detect import integrate_channels  # noqa: E402

__all__ = ["plot_all", "plot_spacing"]


def _rd_panel(ax, cube: np.ndarray, config: RadarConfig, title: str) -> None:
    power_dbm = 10 * np.log10(np.maximum(integrate_channels(cube, config.rx_calibration), 1e-25)) + 30
    v, r = config.doppler_axis_mps, config.range_axis_m
    extent = (v[0], v[-1] + config.doppler_resolution_mps, r[-1] + config.range_resolution_m, r[0])
    im = ax.imshow(power_dbm, aspect="auto", extent=extent, cmap="viridis", vmin=-160, vmax=-100)
    ax.set_xlabel("radial velocity [m/s]")
    ax.set_ylabel("range [m]")
    ax.set_title(title)
    plt.colorbar(im, ax=ax, label="pixel power [dBm]")


def plot_range_doppler(out_dir: Path, static_frame, cal, spur_map, shown) -> Path:
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.5))
    _rd_panel(axes[0], static_frame, cal, "static scene and learned spur map (red)")
    r, d = np.nonzero(spur_map.mask)
    axes[0].scatter(cal.doppler_axis_mps[d], cal.range_axis_m[r], s=1, c="red", marker="s", lw=0, alpha=0.3)
    if shown is not None:
        cube, out, truth = shown
        _rd_panel(axes[1], cube, cal, "flyover frame: detections (o), aircraft truth (x)")
        axes[1].scatter(out["radial_velocity_mps"], out["range_m"], s=80, facecolors="none", edgecolors="red")
        v_true = cal.radial_velocity_at_bin_mps(truth["doppler_bin"][0])
        axes[1].scatter([v_true], [cal.range_at_bin_m(truth["range_bin"][0])], marker="x", c="white", s=60)
    fig.tight_layout()
    path = out_dir / "ch3_range_doppler.png"
    savefig_atomic(fig, path, dpi=110)
    plt.close(fig)
    return path


def plot_track(out_dir: Path, track: pd.DataFrame, err: pd.DataFrame, geom: Any) -> Path:
    from skyradar.process.smoothing import hann_smooth

    fig = plt.figure(figsize=(8, 6.5))
    ax = fig.add_subplot(projection="3d")
    true = track[["true_north_m", "true_east_m", "true_down_m"]].to_numpy()
    est = track[["north_m", "east_m", "down_m"]].to_numpy()
    smooth = np.where(np.isfinite(est), hann_smooth(est, 9), np.nan)
    ax.plot(true[:, 1], true[:, 0], -true[:, 2], "k-", label="truth")
    ax.scatter(est[:, 1], est[:, 0], -est[:, 2], s=6, c="tab:orange", label="raw DoA")
    ax.plot(smooth[:, 1], smooth[:, 0], -smooth[:, 2], "-", c="tab:blue", label="Hann filtered")
    radar = geom.origin_ned_m
    ax.scatter([radar[1]], [radar[0]], [-radar[2]], marker="^", c="red", s=60, label="radar")
    ax.set_xlabel("east [m]")
    ax.set_ylabel("north [m]")
    ax.set_zlabel("up [m]")
    ax.legend()
    ax.set_title("ch3: aircraft track from single-frame 3-D DoA")
    path = out_dir / "ch3_track_3d.png"
    savefig_atomic(fig, path, dpi=110)
    plt.close(fig)
    return path


def plot_errors(out_dir: Path, err: pd.DataFrame) -> Path:
    fig, axes = plt.subplots(4, 1, figsize=(9, 10), sharex=True)
    for ax, name, unit in zip(axes[:3], ("dist", "az", "el"), ("m", "deg", "deg"), strict=True):
        ax.plot(err.time_s, err[f"{name}_raw_{unit}"], ".", ms=3, c="tab:orange", label="raw")
        ax.plot(err.time_s, err[f"{name}_hann_{unit}"], "-", c="tab:blue", label="Hann")
        ax.set_ylabel(f"{name} error [{unit}]")
        ax.grid(alpha=0.3)
    axes[0].legend()
    axes[3].plot(err.time_s, err.true_snr_db, "k-")
    axes[3].axhline(13.0, ls="--", c="grey")
    axes[3].set_ylabel("true SNR [dB]")
    axes[3].set_xlabel("time [s]")
    fig.tight_layout()
    path = out_dir / "ch3_errors.png"
    savefig_atomic(fig, path, dpi=110)
    plt.close(fig)
    return path


def plot_all(out_dir: Path, static_frame, cal, spur_map, shown, track, err, geom) -> list[Path]:
    """All ch3 figures (PNG) into ``out_dir``."""
    return [
        plot_range_doppler(out_dir, static_frame, cal, spur_map, shown),
        plot_track(out_dir, track, err, geom),
        plot_errors(out_dir, err),
    ]


def plot_spacing(out_dir: Path, sweep: list[dict], thesis: dict) -> Path:
    """Raw azimuth/elevation error SD (markers) and Cramer-Rao bound (lines) against the array spacing,
    with the thesis' raw SD as horizontal lines; the unambiguous half-angle is written at each point."""
    spacing = np.array([row["rx_spacing_wavelengths"] for row in sweep])
    fig, ax = plt.subplots(figsize=(7.5, 5))
    for name, colour in (("az", "tab:blue"), ("el", "tab:orange")):
        label = "azimuth" if name == "az" else "elevation"
        ax.plot(spacing, [row[f"{name}_sd_deg"] for row in sweep], "o", c=colour, ms=8, label=f"{label} SD")
        ax.plot(spacing, [row[f"{name}_crlb_deg"] for row in sweep], "-", c=colour, label=f"{label} CRLB")
        ax.axhline(thesis[f"{name}_deg"][1], ls="--", c=colour, lw=1, label=f"thesis {label} SD")
    for row in sweep:
        ax.annotate(
            f"+-{row['unambiguous_half_angle_deg']:.0f} deg",
            (row["rx_spacing_wavelengths"], 0.3),
            ha="center",
            fontsize=8,
            color="grey",
        )
    ax.set_xticks(spacing)
    top = max(thesis["az_deg"][1], thesis["el_deg"][1], *(row["az_sd_deg"] for row in sweep))
    ax.set_ylim(0.0, 1.3 * top)  # room for the legend above the thesis lines
    ax.set_xlabel("2x2 array spacing [wavelengths] (grey: unambiguous half-angle)")
    ax.set_ylabel("raw DoA error SD [deg]")
    ax.set_title("ch3: DoA error vs array spacing (same flyover, same noise)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, ncol=3, loc="upper right")
    fig.tight_layout()
    path = out_dir / "ch3_spacing.png"
    savefig_atomic(fig, path, dpi=110)
    plt.close(fig)
    return path
