"""ch7 figures: the thesis' test pulse through the matched filter, and a plan view per rotation."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from skyradar.io.atomic import savefig_atomic  # noqa: E402
from skyradar.passive.matched_filter import lfm_pulse, matched_filter, thesis_test_pulse  # noqa: E402

__all__ = ["thesis_pulse_figure", "plan_view_figure", "thesis_pulse_numbers"]

_FS = 20e6


def thesis_pulse_numbers() -> dict:
    """Peak time and the 0.01 echo's visibility (strongest peak in 0.16-0.18 ms at 0.17 ms) per window."""
    from scipy import signal

    t, s = thesis_test_pulse(_FS)
    d = int(round(2e-5 * _FS))
    echo = s.copy()
    echo[d:] += 0.01 * s[:-d]
    pulse = lfm_pulse(_FS, 1e-4, 5.0e6, -7.0e9)
    out = {}
    for name, window in (("plain", None), ("hann", "hann")):
        y = np.abs(matched_filter(echo, pulse, window))
        lo, hi = int(1.6e-4 * _FS), int(1.8e-4 * _FS)
        peaks, _ = signal.find_peaks(y[lo:hi])
        strongest = lo + peaks[np.argmax(y[lo + peaks])]
        out[f"{name}_peak_ms"] = round(float(t[np.argmax(y)]) * 1e3, 4)
        out[f"{name}_echo_visible"] = bool(abs(t[strongest] - 1.7e-4) <= 1e-6)
    return out


def thesis_pulse_figure(path: Path) -> Path:
    """Filter output (dB) of the test pulse plus a 0.01 copy 0.02 ms later, without and with Hann."""
    t, s = thesis_test_pulse(_FS)
    d = int(round(2e-5 * _FS))
    echo = s.copy()
    echo[d:] += 0.01 * s[:-d]
    pulse = lfm_pulse(_FS, 1e-4, 5.0e6, -7.0e9)
    fig, axes = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
    axes[0].plot(t * 1e3, echo.real, lw=0.5)
    axes[0].set_ylabel("signal (real part)")
    axes[0].set_title(
        "thesis test pulse: 0.1 ms LFM, f(t) = 5.0 MHz - 7.0 GHz/s t, + 0.01 copy 0.02 ms later"
    )
    for ax, (name, window) in zip(axes[1:], (("no window", None), ("Hann window", "hann")), strict=True):
        for sig, label, style in ((s, "pulse alone", "0.6"), (echo, "pulse + 0.01 echo", "C0")):
            y = np.abs(matched_filter(sig, pulse, window))
            ax.plot(t * 1e3, 20 * np.log10(y / y.max() + 1e-12), color=style, lw=0.8, label=label)
        ax.axvline(0.15, color="k", ls=":", lw=0.8)
        ax.axvline(0.17, color="C3", ls="--", lw=0.8, label="echo at 0.17 ms")
        ax.set_ylim(-80, 3)
        ax.set_ylabel("filter output [dB]")
        ax.set_title(f"matched filter, {name}")
        ax.legend(fontsize=8, loc="upper right")
    axes[-1].set_xlabel("time [ms]")
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=90)
    plt.close(fig)
    return path


def plan_view_figure(
    path: Path, det: pd.DataFrame, truth: pd.DataFrame, tx_en: np.ndarray, period_s: float, n_rot: int
) -> Path:
    """One panel per rotation: detections (static grey, moving red) over the truth (towns, aircraft)."""
    cols = 3
    rows = int(np.ceil(n_rot / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 4.2 * rows), squeeze=False)
    towns = truth[truth["kind"] == "building"]
    plane = truth[truth["kind"] == "aircraft"]
    for k, ax in enumerate(axes.ravel()):
        if k >= n_rot:
            ax.axis("off")
            continue
        in_rot = (det["time_s"] >= k * period_s) & (det["time_s"] < (k + 1) * period_s)
        d = det[in_rot]
        ax.scatter(
            towns["east_m"] / 1e3, towns["north_m"] / 1e3, s=4, c="tab:blue", alpha=0.3, label="town points"
        )
        st, mv = d[d["channel"] == "static"], d[d["channel"] == "moving"]
        ax.scatter(st["east_m"] / 1e3, st["north_m"] / 1e3, s=5, c="0.35", label="static det.")
        p = plane[(plane["time_s"] >= k * period_s) & (plane["time_s"] < (k + 1) * period_s)]
        ax.scatter(
            p["east_m"] / 1e3, p["north_m"] / 1e3, s=80, marker="*", c="tab:green", label="aircraft truth"
        )
        ax.scatter(
            mv["east_m"] / 1e3, mv["north_m"] / 1e3, s=30, marker="x", c="tab:red", label="moving det."
        )
        ax.plot([tx_en[0] / 1e3, 0], [tx_en[1] / 1e3, 0], "k:", lw=0.8)
        ax.plot(tx_en[0] / 1e3, tx_en[1] / 1e3, "k^", ms=7, label="ATC radar")
        ax.plot(0, 0, "ko", ms=5, label="receiver")
        ax.set_xlim(-25, 25)
        ax.set_ylim(-25, 25)
        ax.set_aspect("equal")
        ax.set_title(f"rotation {k + 1}: {len(st)} static, {len(mv)} moving", fontsize=9)
        ax.grid(alpha=0.3)
        if k == 0:
            ax.legend(fontsize=6, loc="lower right")
    for ax in axes[-1]:
        ax.set_xlabel("east [km]")
    for ax in axes[:, 0]:
        ax.set_ylabel("north [km]")
    fig.suptitle("ch7 passive detections per rotation (receiver at the origin)")
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=80)
    plt.close(fig)
    return path


def aircraft_figure(path: Path, det: pd.DataFrame, truth: pd.DataFrame) -> Path:
    """Zoom on the receiver: the aircraft's true positions and the moving detections, per rotation."""
    fig, ax = plt.subplots(figsize=(6, 6))
    plane = truth[truth["kind"] == "aircraft"]
    ax.plot(plane["east_m"], plane["north_m"], "g*-", ms=10, label="aircraft truth (beam passes)")
    mv = det[det["channel"] == "moving"]
    near = mv[np.hypot(mv["east_m"], mv["north_m"]) < 5000]
    ax.scatter(near["east_m"], near["north_m"], marker="x", c="tab:red", label="moving detections")
    ax.plot(0, 0, "ko", label="receiver")
    ax.set_xlim(-4000, 4000)
    ax.set_ylim(-4000, 4000)
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    ax.set_xlabel("east [m]")
    ax.set_ylabel("north [m]")
    ax.legend(fontsize=8)
    ax.set_title("small aircraft (RCS 1 m^2) 1.6-2.8 km from the receiver")
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=90)
    plt.close(fig)
    return path
