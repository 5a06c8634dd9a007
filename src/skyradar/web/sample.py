"""A small synthetic run for the display's tests and for trying the display without a simulator.

Own-ship flies north at 50 m/s, 1000 m up. Intruder ``head-on`` comes south at 50 m/s on the same
line from 6500 m (a collision course); intruder ``crossing`` crosses from the right well clear.
Each frame holds only the intruders' point responses (a 3x3 blob per intruder at its range and
aliased radial velocity, peak 20 dB above the noise power, all receivers in phase) on an empty
background, so the store compresses to a few kilobytes per frame.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from skyradar.config import RadarConfig
from skyradar.io.frames import FrameStoreWriter, frames_dataset

__all__ = ["sample_run_dataset", "write_sample_run"]


def _truth(t: np.ndarray, range_limit_m: float) -> tuple[dict, dict]:
    own_n = 50.0 * t
    zeros = np.zeros_like(t)
    own = {
        "own_north_m": own_n,
        "own_east_m": zeros,
        "own_down_m": zeros - 1000.0,
        "own_vn_mps": zeros + 50.0,
        "own_ve_mps": zeros,
        "own_vd_mps": zeros,
        "own_yaw_rad": zeros,
        "own_pitch_rad": zeros,
        "own_roll_rad": zeros,
        "own_height_agl_m": zeros + 1000.0,
    }
    pos = np.stack(
        [
            np.stack([6500.0 - 50.0 * t, zeros, zeros - 1000.0], -1),
            np.stack([1500.0 + 20.0 * t, 3000.0 - 40.0 * t, zeros - 1400.0], -1),
        ],
        axis=1,
    )  # (time, target, 3)
    vel = np.broadcast_to(np.array([[-50.0, 0.0, 0.0], [20.0, -40.0, 0.0]]), pos.shape)
    own_p = np.stack([own_n, zeros, zeros - 1000.0], -1)[:, None, :]
    own_v = np.array([50.0, 0.0, 0.0])
    rel = pos - own_p
    rng = np.linalg.norm(rel, axis=-1)
    radial = np.sum(rel * (vel - own_v), axis=-1) / rng
    tgt = {f"tgt_{k}": pos[..., i] for i, k in enumerate(["north_m", "east_m", "down_m"])}
    tgt.update({f"tgt_{k}": vel[..., i].copy() for i, k in enumerate(["vn_mps", "ve_mps", "vd_mps"])})
    tgt.update(
        tgt_range_m=rng,
        tgt_radial_velocity_mps=radial,
        tgt_azimuth_rad=np.arctan2(rel[..., 1], rel[..., 0]),
        tgt_elevation_rad=np.arctan2(-rel[..., 2], np.hypot(rel[..., 0], rel[..., 1])),
        tgt_visible=rng <= range_limit_m,
    )
    return own, tgt


def sample_run_dataset(
    n_frames: int = 60, dt_s: float = 1.0, config: RadarConfig | None = None
) -> xr.Dataset:
    """Frames Dataset of the sample encounter (see module docstring).

    Examples
    --------
    >>> ds = sample_run_dataset(n_frames=3)
    >>> ds.sizes["time"], list(ds["target"].values)
    (3, ['head-on', 'crossing'])
    """
    config = config or RadarConfig.prototype_2022()
    t = np.arange(n_frames) * dt_s
    own, tgt = _truth(t, config.range_limit_m)
    iq = np.zeros((n_frames, config.n_range, config.n_doppler, config.n_rx), np.complex64)
    amp = np.sqrt(config.noise_power_w * 100.0)
    for i in range(n_frames):
        for k in range(tgt["tgt_range_m"].shape[1]):
            if not tgt["tgt_visible"][i, k]:
                continue
            r_bin = int(config.range_bin(tgt["tgt_range_m"][i, k]))
            d_bin = int(config.doppler_bin(tgt["tgt_radial_velocity_mps"][i, k]))
            # A 3x3 blob (Hann-windowed main lobe: -6 dB on the neighbours), Doppler wrapping around.
            for dr, dd in np.ndindex(3, 3):
                rr, jj = r_bin + dr - 1, (d_bin + dd - 1) % config.n_doppler
                if 0 <= rr < config.n_range:
                    iq[i, rr, jj, :] = amp * 0.5 ** (abs(dr - 1) + abs(dd - 1))
    return frames_dataset(iq, t, config, ownship=own, targets=tgt, target_names=["head-on", "crossing"])


def write_sample_run(path: str | Path, n_frames: int = 60, dt_s: float = 1.0, chunk_frames: int = 10) -> Path:
    """Write the sample run as a Zarr frames store at ``path`` (atomically, via ``.partial``).

    Parameters
    ----------
    path : str or Path
        The store to write (``RUN.zarr``).
    n_frames : int
        Number of frames.
    dt_s : float
        Time between frames, s.
    chunk_frames : int
        Frames per stored chunk.

    Returns
    -------
    Path
        The finished store.

    Examples
    --------
    >>> import tempfile
    >>> from skyradar.io.frames import open_frames
    >>> from skyradar.io.frames_model import frame_times_s
    >>> with tempfile.TemporaryDirectory() as d:
    ...     run = write_sample_run(Path(d) / "run.zarr", n_frames=4, chunk_frames=2)
    ...     names = sorted(p.name for p in Path(d).iterdir())
    ...     times = frame_times_s(open_frames(run)).tolist()
    >>> names, times
    (['run.zarr'], [0.0, 1.0, 2.0, 3.0])
    """
    ds = sample_run_dataset(n_frames, dt_s)
    template = ds.assign(iq=ds["iq"].chunk({"time": chunk_frames}))
    writer = FrameStoreWriter(path, template, chunk_frames, fingerprint="skyradar-sample-run")
    for k in writer.pending_chunks():
        writer.write_chunk(k, ds["iq"].values[writer.chunk_slice(k)])
    return writer.close()
