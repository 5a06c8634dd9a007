"""The flyable path built from a file's fixes, drawn against those fixes.

Three panels: the map (north against east) with the fixes the path was fitted to, the fixes it
repaired away and the path; the speed along the path beside the speed the fixes imply between
each other and the ground speed the file reports; and the path's horizontal and vertical
acceleration against its aircraft class's limits.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from skyradar.io.atomic import savefig_atomic  # noqa: E402
from skyradar.scene.adsb import FlightFit  # noqa: E402
from skyradar.scene.flyable import hermite_accelerations  # noqa: E402

__all__ = ["flight_fit_figure"]


def flight_fit_figure(fit: FlightFit, path: str | Path, window_s: tuple[float, float] | None = None) -> Path:
    """Write the figure of ``fit`` (from :func:`skyradar.scene.adsb.fit_flight`) to ``path``.

    Parameters
    ----------
    fit : FlightFit
        The built flight and its fixes.
    path : str or Path
        The image to write (PNG, SVG or PDF by its suffix); written atomically.
    window_s : (float, float), optional
        Only this time span of the flight, s on its clock; default the whole flight.

    Returns
    -------
    Path
        ``path``.

    Examples
    --------
    Four fixes of a flight north at 11 m/s; the SVG, with its text kept as text, names what each
    panel shows:

    >>> import re, tempfile
    >>> from skyradar.scene.adsb import fit_flight
    >>> rows = "0,52,4,300\\n10,52.001,4,300\\n20,52.002,4,300\\n30,52.003,4,300\\n"
    >>> with tempfile.TemporaryDirectory() as d, plt.rc_context({"svg.fonttype": "none"}):
    ...     f = Path(d) / "ga.csv"
    ...     _ = f.write_text("time_s,latitude,longitude,alt_m\\n" + rows)
    ...     svg = flight_fit_figure(fit_flight(f), Path(d) / "ga.svg").read_text()
    >>> texts = re.findall(r"<text[^>]*>([^<]*)</text>", svg)
    >>> [t for t in ("ga: map", "fixes used (4)", "speed", "ga horizontal limit") if t in texts]
    ['ga: map', 'fixes used (4)', 'speed', 'ga horizontal limit']
    """
    traj = fit.trajectory
    start, end = window_s if window_s is not None else (traj.start_s, traj.end_s)
    start, end = max(start, traj.start_s), min(end, traj.end_s)
    t = np.linspace(start, end, max(int((end - start) * 4), 2))
    s = traj.sample(t)
    inside = (fit.fix_time_s >= start) & (fit.fix_time_s <= end)
    kept = fit.path.kept & inside
    repaired = ~fit.path.kept & inside
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    ax = axes[0]
    ax.plot(s.position_ned_m[:, 1], s.position_ned_m[:, 0], "-", color="tab:blue", lw=1.2, label="built path")
    ax.plot(
        fit.fix_position_ned_m[kept, 1],
        fit.fix_position_ned_m[kept, 0],
        ".",
        color="0.35",
        ms=4,
        label=f"fixes used ({int(kept.sum())})",
    )
    if repaired.any():
        off = fit.fix_position_ned_m[repaired]
        label = f"fixes repaired away ({int(repaired.sum())})"
        ax.plot(off[:, 1], off[:, 0], "x", color="tab:red", ms=6, label=label)
    ax.set(xlabel="east (m)", ylabel="north (m)", title=f"{traj.name}: map", aspect="equal")
    ax.legend(loc="best", fontsize=8)
    ax = axes[1]
    ax.plot(t, np.linalg.norm(s.velocity_ned_mps, axis=1), "-", color="tab:blue", label="built path")
    fix_t, fix_p = fit.fix_time_s[kept], fit.fix_position_ned_m[kept]
    if fix_t.size > 1:
        between = np.linalg.norm(np.diff(fix_p, axis=0), axis=1) / np.diff(fix_t)
        ax.plot(0.5 * (fix_t[1:] + fix_t[:-1]), between, ".", color="0.35", ms=4, label="between fixes")
    if fit.fix_velocity_ned_mps is not None:
        reported = np.linalg.norm(fit.fix_velocity_ned_mps[inside], axis=1)
        ax.plot(fit.fix_time_s[inside], reported, ".", color="tab:orange", ms=4, label="reported")
    ax.set(xlabel="time (s)", ylabel="speed (m/s)", title="speed")
    ax.legend(loc="best", fontsize=8)
    ax = axes[2]
    a0, _a1 = hermite_accelerations(traj.time_s, traj.position_ned_m, traj.velocity_ned_mps)
    mid = traj.time_s[:-1]
    shown = (mid >= start) & (mid <= end)
    ax.plot(
        mid[shown], np.hypot(a0[shown, 0], a0[shown, 1]), "-", color="tab:blue", lw=0.8, label="horizontal"
    )
    ax.plot(mid[shown], np.abs(a0[shown, 2]), "-", color="tab:green", lw=0.8, label="vertical")
    lim = fit.limits
    ax.axhline(
        lim.horizontal_accel_mps2, color="tab:blue", ls="--", lw=0.8, label=f"{lim.name} horizontal limit"
    )
    ax.axhline(
        lim.vertical_accel_mps2, color="tab:green", ls="--", lw=0.8, label=f"{lim.name} vertical limit"
    )
    ax.set(xlabel="time (s)", ylabel="acceleration (m/s$^2$)", title="acceleration of the built path")
    ax.legend(loc="best", fontsize=8)
    fig.tight_layout()
    try:
        return savefig_atomic(fig, path, dpi=110)
    finally:
        plt.close(fig)
