"""Truth of a simulated passive recording, kept beside it and never in its SigMF metadata.

``NAME.truth.parquet`` has one row per reflector (building point, clutter point, aircraft) per sweep, at
the time the main beam's axis crosses it. Sweep ``k`` is the rotation ``[k T, (k + 1) T)`` counted from
the first sample (``T`` the rotation period), so a 40 s recording at 13.5 rpm has sweeps 0..8. Columns:

``time_s, sweep, kind, name, north_m, east_m, down_m`` (receiver's NED frame), ``azimuth_from_tx_deg``,
``r_tx_m, r_rx_m, bistatic_range_m`` (``r_tx + r_rx - L``), ``bistatic_doppler_hz``, ``rcs_m2``,
``snr_db`` (single long-pulse matched-filter SNR at the beam's peak).

``NAME.truth.json`` holds the scan and timing a processor must recover (beam azimuth at sample 0,
emission time of PRI 0, the times the beam points at the receiver) and a summary of each cluster.
Azimuths (``azimuth_from_tx_deg``, ``azimuth_at_t0_deg``) are clockwise from north of the receiver's NED
frame, measured at the transmitter in that frame; true north at the transmitter differs by the meridian
convergence (0.13 deg for the thesis geometry).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from skyradar.io.json_results import write_json_atomic
from skyradar.io.sigmf_io import sigmf_paths
from skyradar.io.tables import write_table
from skyradar.passive.budget import db, echo_power_w, matched_filter_snr
from skyradar.passive.scene import PassiveScene, bistatic_geometry

__all__ = ["truth_paths", "truth_table", "truth_summary", "write_truth"]


def truth_paths(meta_path: str | Path) -> tuple[Path, Path]:
    """(table, json) truth paths beside a recording ``NAME.sigmf-meta``.

    Parameters
    ----------
    meta_path : str or Path
        The recording: ``NAME.sigmf-meta``, ``NAME.sigmf-data`` or the bare ``NAME``.

    Returns
    -------
    (Path, Path)
        ``NAME.truth.parquet`` and ``NAME.truth.json`` in the recording's folder.

    Examples
    --------
    >>> [p.name for p in truth_paths("runs/rec.sigmf-data")]
    ['rec.truth.parquet', 'rec.truth.json']
    """
    meta, _ = sigmf_paths(meta_path)
    stem = meta.name.removesuffix(".sigmf-meta")
    return meta.with_name(stem + ".truth.parquet"), meta.with_name(stem + ".truth.json")


def _static_rows(scene: PassiveScene) -> pd.DataFrame:
    refl, ill = scene.reflectors, scene.illuminator
    period, w = ill.rotation_period_s, ill.rotation_rate_rad_s
    az = scene.azimuth_from_tx_rad(refl.position_ned_m)
    first = np.mod(az - scene.azimuth_at_t0_rad, 2 * np.pi) / w
    n_sweeps = int(np.ceil(scene.duration_s / period)) + 1
    t = first[:, None] + period * np.arange(n_sweeps)[None, :]
    i, m = np.nonzero(t < scene.duration_s)
    pos = refl.position_ned_m[i]
    return pd.DataFrame(
        {
            "time_s": t[i, m],
            "kind": refl.kind[i].astype(str),
            "name": refl.group[i].astype(str),
            "position": list(pos),
            "velocity": list(np.zeros_like(pos)),
            "rcs_m2": refl.rcs_m2[i],
        }
    )


def _aircraft_rows(scene: PassiveScene) -> pd.DataFrame:
    ill = scene.illuminator
    w, period = ill.rotation_rate_rad_s, ill.rotation_period_s
    rows = []
    for plane in scene.aircraft:
        for m in range(int(np.ceil(scene.duration_s / period)) + 1):
            t = m * period
            for _ in range(6):  # fixed point: the beam's crossing time of the moving aircraft
                present, pos, vel = plane.states(np.array([t]))
                if not present[0]:
                    break
                az = scene.azimuth_from_tx_rad(pos)[0]
                t = (np.mod(az - scene.azimuth_at_t0_rad - 2 * np.pi * m, 2 * np.pi) + 2 * np.pi * m) / w
            present, pos, vel = plane.states(np.array([t]))
            if present[0] and 0.0 <= t < scene.duration_s:
                rows.append(
                    {
                        "time_s": t,
                        "kind": "aircraft",
                        "name": plane.name,
                        "position": pos[0],
                        "velocity": vel[0],
                        "rcs_m2": plane.rcs_m2,
                    }
                )
    return pd.DataFrame(rows, columns=["time_s", "kind", "name", "position", "velocity", "rcs_m2"])


def truth_table(scene: PassiveScene) -> pd.DataFrame:
    """One row per reflector per sweep (see the module docstring), sorted by time.

    Parameters
    ----------
    scene : PassiveScene
        The simulated scene.

    Returns
    -------
    DataFrame
        The truth table: the columns of the module docstring, one row per reflector per main-beam
        crossing within the recording.

    Examples
    --------
    The illuminator 12 km due west, a mast 4 km due east: on the baseline's extension, so
    ``r_tx = 16 km``, ``r_rx = 4 km`` and the bistatic range 16 + 4 - 12 = 8 km; the beam (starting
    north, 4.44 s a turn) crosses it a quarter turn in, and once per turn after.

    >>> from skyradar.geo import ned_to_geodetic
    >>> from skyradar.passive.illuminator import Illuminator
    >>> from skyradar.passive.scene import PassiveScene, Receiver, Reflectors
    >>> rx = Receiver(52.0, 5.0, 40.0)
    >>> ill = Illuminator(*map(float, ned_to_geodetic(np.array([0.0, -12000.0, 0.0]), *rx.geodetic)))
    >>> mast = Reflectors([[0.0, 4000.0, 0.0]], [10.0], "building", "mast")
    >>> t = truth_table(PassiveScene(rx, ill, mast, duration_s=8.0))
    >>> t[["time_s", "sweep", "bistatic_range_m", "r_rx_m"]].round(3).values.tolist()
    [[1.111, 0.0, 8000.0, 4000.0], [5.556, 1.0, 8000.0, 4000.0]]
    """
    parts = [df for df in (_static_rows(scene), _aircraft_rows(scene)) if len(df)]
    df = pd.concat(parts, ignore_index=True) if parts else _aircraft_rows(scene)
    ill, rx = scene.illuminator, scene.receiver
    pos = np.stack(df["position"].to_numpy()) if len(df) else np.zeros((0, 3))
    vel = np.stack(df["velocity"].to_numpy()) if len(df) else np.zeros((0, 3))
    g = bistatic_geometry(pos, vel, scene.illuminator_ned_m, ill.wavelength_m)
    power = echo_power_w(
        ill.peak_power_w,
        ill.antenna_gain_dbi,
        1.0,
        rx.antenna_gain_dbi,
        ill.wavelength_m,
        df["rcs_m2"],
        g["r_tx_m"],
        g["r_rx_m"],
    )
    out = pd.DataFrame(
        {
            "time_s": df["time_s"].to_numpy(float),
            "sweep": np.floor(df["time_s"].to_numpy(float) / ill.rotation_period_s).astype(np.int64),
            "kind": df["kind"].astype(str),
            "name": df["name"].astype(str),
            "north_m": pos[:, 0],
            "east_m": pos[:, 1],
            "down_m": pos[:, 2],
            "azimuth_from_tx_deg": np.degrees(scene.azimuth_from_tx_rad(pos)),
            "r_tx_m": g["r_tx_m"],
            "r_rx_m": g["r_rx_m"],
            "bistatic_range_m": g["bistatic_range_m"],
            "bistatic_doppler_hz": g["bistatic_doppler_hz"],
            "rcs_m2": df["rcs_m2"].to_numpy(float),
            "snr_db": db(matched_filter_snr(power, ill.long_pulse.width_s, rx.noise_figure_db)),
        }
    )
    return out.sort_values("time_s", kind="stable").reset_index(drop=True)


def truth_summary(scene: PassiveScene, sample_rate_hz: float) -> dict:
    """The scan, timing and cluster summary written to ``NAME.truth.json``.

    Parameters
    ----------
    scene : PassiveScene
        The simulated scene.
    sample_rate_hz : float
        The recording's sample rate, Hz.

    Returns
    -------
    dict
        JSON-ready: the frame, sample rate (Hz), duration (s), illuminator position (NED, m), baseline
        (m), beam azimuth at sample 0 (deg), rotation period (s), emission time of PRI 0 (s), main-beam
        crossings of the receiver (s), the building clusters' centres, the aircraft and the seed.

    Examples
    --------
    >>> from skyradar.geo import ned_to_geodetic
    >>> from skyradar.passive.illuminator import Illuminator
    >>> from skyradar.passive.scene import PassiveScene, Receiver, Reflectors
    >>> rx = Receiver(52.0, 5.0, 40.0)
    >>> ill = Illuminator(*map(float, ned_to_geodetic(np.array([0.0, -12000.0, 0.0]), *rx.geodetic)))
    >>> mast = Reflectors([[0.0, 4000.0, 0.0]], [10.0], "building", "mast")
    >>> summary = truth_summary(PassiveScene(rx, ill, mast, duration_s=8.0), 5e6)
    >>> round(summary["baseline_m"], 3), [round(t, 3) for t in summary["receiver_crossing_times_s"]]
    (12000.0, [1.111, 5.556])
    >>> summary["clusters"][0]["name"], summary["clusters"][0]["r_rx_m"]
    ('mast', 4000.0)
    """
    refl = scene.reflectors
    clusters = []
    for name in dict.fromkeys(refl.group[refl.kind == "building"]):
        sel = refl.group == name
        centre = refl.position_ned_m[sel].mean(axis=0)
        clusters.append(
            {
                "name": str(name),
                "n_points": int(sel.sum()),
                "north_m": float(centre[0]),
                "east_m": float(centre[1]),
                "r_rx_m": float(np.linalg.norm(centre[:2])),
            }
        )
    return {
        "frame": "NED at the receiving antenna (SigMF core:geolocation), metres",
        "sample_rate_hz": sample_rate_hz,
        "duration_s": scene.duration_s,
        "illuminator_ned_m": scene.illuminator_ned_m.tolist(),
        "baseline_m": scene.baseline_m,
        "azimuth_at_t0_deg": float(np.degrees(scene.azimuth_at_t0_rad)),
        "rotation_period_s": scene.illuminator.rotation_period_s,
        "first_pulse_s": scene.first_pulse_s,
        "receiver_crossing_times_s": scene.receiver_crossing_times_s.tolist(),
        "clusters": clusters,
        "aircraft": [{"name": a.name, "rcs_m2": a.rcs_m2} for a in scene.aircraft],
        "seed": scene.seed,
    }


def write_truth(scene: PassiveScene, meta_path: str | Path, sample_rate_hz: float) -> tuple[Path, Path]:
    """Write ``NAME.truth.parquet`` and ``NAME.truth.json`` beside the recording.

    Parameters
    ----------
    scene : PassiveScene
        The simulated scene.
    meta_path : str or Path
        The recording (see :func:`truth_paths`).
    sample_rate_hz : float
        The recording's sample rate, Hz.

    Returns
    -------
    (Path, Path)
        The table and the JSON summary written.

    Examples
    --------
    >>> import json, tempfile, pathlib
    >>> from skyradar.geo import ned_to_geodetic
    >>> from skyradar.passive.illuminator import Illuminator
    >>> from skyradar.passive.scene import PassiveScene, Receiver, Reflectors
    >>> rx = Receiver(52.0, 5.0, 40.0)
    >>> ill = Illuminator(*map(float, ned_to_geodetic(np.array([0.0, -12000.0, 0.0]), *rx.geodetic)))
    >>> mast = Reflectors([[0.0, 4000.0, 0.0]], [10.0], "building", "mast")
    >>> scene = PassiveScene(rx, ill, mast, duration_s=8.0)
    >>> with tempfile.TemporaryDirectory() as d:
    ...     table, summary = write_truth(scene, pathlib.Path(d) / "rec", 5e6)
    ...     rows, info = len(pd.read_parquet(table)), json.loads(summary.read_text())
    >>> table.name, rows, info["sample_rate_hz"]
    ('rec.truth.parquet', 2, 5000000.0)
    """
    table, summary = truth_paths(meta_path)
    write_table(truth_table(scene), table, metadata={"skyradar_format": "passive-truth/1"})
    write_json_atomic(summary, truth_summary(scene, sample_rate_hz))
    return table, summary
