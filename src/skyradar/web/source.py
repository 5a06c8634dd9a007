"""What the live display replays: a frames run (finished or still being written) and its alerts.

A run still being written is a ``NAME.partial`` Zarr store from
:class:`skyradar.io.frames.FrameStoreWriter`; only frames of chunks marked done (a leading run of
chunks) are shown, because an unwritten chunk reads as zeros. When the writer renames the store
to its final name, :meth:`RunSource.refresh` reopens it there.

Traffic comes from, in order of preference: an alerts table, a tracks table (alerted here), or
the intruder truth stored in a simulated run (alerted here; labelled ``truth``).
"""

from __future__ import annotations

import base64
import threading
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pandas as pd
import xarray as xr

from skyradar.daa.alerting import RADAR_ALERT_CONFIG
from skyradar.daa.pipeline import alerts_for_run
from skyradar.daa.run_tables import has_ownship
from skyradar.errors import InputError
from skyradar.io import cint16
from skyradar.io.frames import FrameStoreWriter, open_frames, radar_config_of
from skyradar.io.frames_model import frame_times_s
from skyradar.io.json_results import jsonable
from skyradar.io.navigation import navigation_state
from skyradar.io.tables import read_table
from skyradar.process.power import power_image

__all__ = ["RunSource", "range_doppler_png"]

_ADVICE_KEYS = (
    "heading_bands_deg",
    "vs_bands_mps",
    "terrain_vs_bands_mps",
    "preferred_heading_deg",
    "preferred_vs_mps",
)


def range_doppler_png(iq_frame: np.ndarray, noise_power_w: float, span_db: float = 40.0) -> bytes:
    """Colour PNG of one (range, doppler, rx) frame: receiver-integrated power, noise floor to +span_db.

    Range grows upwards, radial velocity to the right.

    Examples
    --------
    >>> png = range_doppler_png(np.zeros((4, 8, 2), np.complex64), 1e-12)
    >>> png[:4]
    b'\\x89PNG'
    """
    power = power_image(iq_frame, dtype=np.float64)  # channel mean: noise averages noise_power_w
    floor_db = 10 * np.log10(noise_power_w)
    db = 10 * np.log10(np.maximum(power, 1e-30))
    img = np.clip((db - floor_db + 3.0) / (span_db + 3.0), 0.0, 1.0)
    img8 = (img[::-1] * 255).astype(np.uint8)
    ok, buf = cv2.imencode(".png", cv2.applyColorMap(img8, cv2.COLORMAP_VIRIDIS))
    if not ok:  # pragma: no cover - OpenCV always encodes a uint8 image
        raise RuntimeError("PNG encoding failed")
    return buf.tobytes()


class RunSource:
    """A run and its traffic, re-read as the run grows.

    Parameters
    ----------
    run_path : path
        Final name of the frames store (``RUN.zarr``); ``RUN.zarr.partial`` is used while it exists.
    tracks_path, alerts_path : path, optional
        Tracks / alerts Parquet tables.

    Examples
    --------
    The sample run (:mod:`skyradar.web.sample`), alerted from its truth. At t = 1 s only ``crossing`` is
    within the 5 km range limit: 1470 m north, 2960 m east and 400 m below the own-ship, 3329 m away.

    >>> import tempfile
    >>> from skyradar.web.sample import write_sample_run
    >>> with tempfile.TemporaryDirectory() as d:
    ...     source = RunSource(write_sample_run(Path(d) / "run.zarr", n_frames=4, chunk_frames=2))
    ...     info, frame = source.info(), source.frame(1, with_image=False)
    >>> info["n_ready"], info["growing"], info["traffic_source"]
    (4, False, 'truth')
    >>> own = frame["ownship"]
    >>> own["north_m"], own["gs_mps"], [round(t["range_m"]) for t in frame["traffic"]]
    (50.0, 50.0, [3329])
    """

    def __init__(
        self, run_path: str | Path, tracks_path: Path | None = None, alerts_path: Path | None = None
    ):
        self.path = Path(run_path)
        self.partial = self.path.with_name(self.path.name + ".partial")
        self.tracks_path, self.alerts_path = tracks_path, alerts_path
        self._lock = threading.Lock()
        self._opened: Path | None = None
        self.ds: xr.Dataset | None = None
        self.n_ready = 0
        self.alerts = pd.DataFrame()
        self.traffic_source = "none"
        self.refresh()
        if self.ds is None:
            raise InputError(f"{self.path}: no such run (and no {self.partial.name})")

    @property
    def growing(self) -> bool:
        """True while the run is still being written."""
        return self._opened == self.partial

    def _open(self) -> None:
        if self.path.exists():
            target = self.path
        elif self.partial.exists():
            target = self.partial
        else:
            return
        if target == self._opened:
            return
        if target == self.path:
            ds = open_frames(target)
        else:
            try:
                # A cint16 run holds int16 codes and scales: decode to the usual complex64 iq.
                ds = cint16.decode(xr.open_zarr(target, consolidated=False))
            except Exception:  # noqa: BLE001 - a store still being created is simply not ready yet
                return
            radar_config_of(ds, str(target))
        self.ds, self._opened = ds, target
        self.config = radar_config_of(ds, str(target))
        self.times = frame_times_s(ds)
        # The own-ship state the pilot's display shows is the navigation solution (nav_*), never the
        # simulator's truth; it is small and written at creation: keep it in memory.
        state = navigation_state(ds, str(target))
        own = [] if state is None else [k for k in state if k.startswith("own_")]
        self._own = {} if state is None else {k: state[k].to_numpy(float) for k in own}
        self._compute_alerts()

    def _ready_frames(self) -> int:
        if not self.growing:
            return len(self.times)
        assert self.ds is not None  # counted once the run is open
        chunk = int(self.ds["iq"].data.chunks[0][0])
        # Ask the writer's own bookkeeping which chunks are done (a leading run of them is shown).
        writer = FrameStoreWriter.attach(self.partial, chunk, len(self.times))
        pending = writer.pending_chunks()
        k = pending[0] if pending else writer.n_chunks
        return min(k * chunk, len(self.times))

    def refresh(self) -> int:
        """Re-check the store (new chunks, rename to the final name); return the ready frame count."""
        with self._lock:
            self._open()
            if self.ds is not None:
                self.n_ready = self._ready_frames()
            return self.n_ready

    def _compute_alerts(self) -> None:
        if self.alerts_path is not None:
            self.alerts = read_table(self.alerts_path, required=["time_s", "track_id", "level"])
            self.traffic_source = "alerts"
            return
        assert self.ds is not None  # computed once the run is open
        if self.tracks_path is None and not has_ownship(self.ds):
            self.alerts, self.traffic_source = pd.DataFrame(), "none"  # e.g. a real recording: image only
            return
        tracks = None if self.tracks_path is None else read_table(self.tracks_path, sort_by="time_s")
        self.traffic_source = "truth" if tracks is None else "tracks"
        # Tracks without the run's own-ship state cannot be alerted: alerts_for_run says so.
        # The same settings as `skyradar alert` (its default --config radar) and every DAA result.
        self.alerts = alerts_for_run(
            self.ds, tracks, RADAR_ALERT_CONFIG, run_name=str(self._opened), tracks_name=str(self.tracks_path)
        )

    def info(self) -> dict[str, Any]:
        """Run summary for the page."""
        return {
            "type": "info",
            "run": self.path.name,
            "growing": self.growing,
            "n_ready": self.n_ready,
            "n_total": len(self.times),
            "times_s": self.times.tolist(),
            "traffic_source": self.traffic_source,
            "range_max_m": float(self.config.range_axis_m[-1]),
            "v_lim_mps": float(self.config.v_lim_mps),
        }

    def _ownship(self, i: int) -> dict[str, float | None] | None:
        if "own_north_m" not in self._own:
            return None
        row = {k: float(v[i]) for k, v in self._own.items()}
        yaw = row["own_yaw_rad"] if "own_yaw_rad" in row else np.arctan2(row["own_ve_mps"], row["own_vn_mps"])
        # NaN (no terrain under a clear-sky run: no height above ground) goes out as null: JSON has no
        # NaN, and a page's JSON.parse refuses the bare NaN a lenient encoder would write.
        return jsonable(
            {
                "north_m": row["own_north_m"],
                "east_m": row["own_east_m"],
                "alt_m": -row["own_down_m"],
                "heading_deg": float(np.degrees(yaw) % 360.0),
                "gs_mps": float(np.hypot(row["own_vn_mps"], row["own_ve_mps"])),
                "vs_mps": -row["own_vd_mps"],
                "height_agl_m": row.get("own_height_agl_m"),
            }
        )

    def _traffic(self, t: float) -> tuple[list[dict[str, Any]], dict[str, Any] | None]:
        if self.alerts.empty:
            return [], None
        dt = np.min(np.diff(self.times)) / 2 if len(self.times) > 1 else 0.5
        rows = self.alerts[np.abs(self.alerts["time_s"].to_numpy() - t) <= dt]
        keys = [
            "track_id",
            "level",
            "flarm_level",
            "sector",
            "layer",
            "range_m",
            "bearing_deg",
            "tcpa_s",
            "rel_north_m",
            "rel_east_m",
            "rel_alt_m",
            "climb_rate_mps",
        ]
        traffic = [{k: jsonable(r[k]) for k in keys if k in r} for r in rows.to_dict("records")]
        advice = None
        if len(rows) and "heading_bands_deg" in rows and rows["level"].max() > 0:
            r0 = rows.iloc[0]
            advice = {k: jsonable(r0[k]) for k in _ADVICE_KEYS if k in rows}
        return traffic, advice

    def frame(self, i: int, with_image: bool = True) -> dict[str, Any]:
        """Everything the page draws for frame ``i`` (must be ready)."""
        with self._lock:
            self._open()  # the writer may have renamed the store since the last refresh
            if not 0 <= i < self.n_ready:
                raise IndexError(f"frame {i} not ready (0..{self.n_ready - 1})")
            t = float(self.times[i])
            traffic, advice = self._traffic(t)
            payload = {
                "type": "frame",
                "index": i,
                "time_s": t,
                "n_ready": self.n_ready,
                "ownship": self._ownship(i),
                "traffic": traffic,
                "advice": advice,
                "max_level": max([int(x["level"]) for x in traffic], default=0),
            }
            if with_image:
                assert self.ds is not None  # frames are ready only once the run is open
                png = range_doppler_png(np.asarray(self.ds["iq"][i].values), self.config.noise_power_w)
                payload["rd_png"] = "data:image/png;base64," + base64.b64encode(png).decode()
        return payload
