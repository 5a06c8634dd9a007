"""Write raw ADC frames as a ``skyradar-adc/1`` recording (see :mod:`skyradar.io.recordings`).

The frames are converted and written a few at a time, so memory stays bounded whatever the
recording's length; both files go through unique temporary names, renamed when complete.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import yaml

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.io.atomic import atomic_path
from skyradar.io.recordings import AXES, DTYPES

__all__ = ["write_recording"]

_CHUNK_BYTES = 64 * 2**20  # input bytes converted at a time by write_recording


def _frames_per_chunk(frames: np.ndarray) -> int:
    """Frames per write chunk: about ``_CHUNK_BYTES`` of input, at least one frame."""
    frame_bytes = max(1, int(np.prod(frames.shape[1:], dtype=np.int64)) * frames.itemsize)
    return max(1, _CHUNK_BYTES // frame_bytes)


def _peak(frames: np.ndarray, step: int) -> float:
    """Largest magnitude in ``frames``, ``step`` frames at a time (0 for no samples)."""
    if frames.size == 0:
        return 0.0
    return max(float(np.abs(frames[i : i + step]).max()) for i in range(0, len(frames), step))


def _encode(block: np.ndarray, scale: float, code: str, per: int) -> np.ndarray:
    """Frames as stored on disk: divided by ``scale``, (I, Q) pairs, rounded and clipped for int16."""
    values = np.asarray(block / scale)  # the only full-size temporary: the rest is in place
    if per == 2:
        # A complex array is (real, imag) pairs in memory already: view it as such, no copy.
        values = values.astype(np.result_type(values, np.complex64), copy=False)
        values = values.view(values.real.dtype).reshape(*values.shape, 2)
    if code == "i2":
        np.round(values, out=values)
        np.clip(values, -32768, 32767, out=values)
    return values.astype("<" + code)


def write_recording(
    path: str | Path,
    frames: np.ndarray,
    config: RadarConfig,
    dtype: str = "complex_int16",
    scale: float | None = None,
    times_s: np.ndarray | None = None,
    sidecar_format: str = "json",
) -> Path:
    """Write frames (frame, rx, chirp, sample) as ``NAME.bin`` plus a sidecar, atomically.

    The frames are converted and written a few at a time (about 64 MB of input per step), so
    memory stays bounded whatever the recording's length: ``frames`` may be a memory-mapped
    array larger than RAM.

    Parameters
    ----------
    path : path
        Data file name; the sidecar gets the same stem with ``.json`` or ``.yaml``.
    frames : ndarray, shape (n_frames, n_rx, n_chirps, n_samples)
    config : RadarConfig
        Radar parameters recorded in the sidecar.
    dtype : str
        One of :data:`DTYPES`; integer types are quantised as ``round(x / scale)``.
    scale : float, optional
        Value of one count; default so that the largest magnitude uses 30000 counts (int16)
        or 1.0 (float types).
    times_s : ndarray, optional
        Frame times, s (default back-to-back frames).
    sidecar_format : {'json', 'yaml'}

    Returns
    -------
    Path of the sidecar.
    """
    path = Path(path)
    frames = np.asarray(frames)
    code, per = _check_write(path, frames, dtype)
    step = _frames_per_chunk(frames)
    if scale is None:
        peak = _peak(frames, step)
        scale = peak / 30000.0 if code == "i2" and peak > 0 else 1.0
    meta = _sidecar_meta(path, frames.shape, config, dtype, scale, times_s)
    sidecar = path.with_suffix(".json" if sidecar_format == "json" else ".yaml")
    text = json.dumps(meta, indent=1) if sidecar_format == "json" else yaml.safe_dump(meta)
    # The data file is renamed first (inner block), then the sidecar that describes it.
    with atomic_path(sidecar) as tmp_side, atomic_path(path) as tmp_data:
        with open(tmp_data, "wb") as f:
            for i in range(0, len(frames), step):
                _encode(frames[i : i + step], scale, code, per).tofile(f)
        tmp_side.write_text(text)
    return sidecar


def _check_write(path: Path, frames: np.ndarray, dtype: str) -> tuple[str, int]:
    """The on-disk element code and values per sample of ``dtype``, after checking the request."""
    if dtype not in DTYPES:
        raise InputError(f"write_recording: dtype {dtype!r}; choose from {sorted(DTYPES)}")
    if frames.ndim != 4:
        raise InputError(
            f"write_recording: frames must be (frame, rx, chirp, sample), got shape {frames.shape}"
        )
    code, per = DTYPES[dtype]
    if per == 1 and np.iscomplexobj(frames):
        raise InputError(f"write_recording: dtype {dtype!r} is real but the frames are complex")
    if path.suffix.lower() in (".json", ".yaml", ".yml"):
        raise InputError(f"write_recording: data file {path} would be its own sidecar; name it NAME.bin")
    return code, per


def _sidecar_meta(path: Path, shape, config: RadarConfig, dtype: str, scale: float, times_s) -> dict:
    """The sidecar's fields (format ``skyradar-adc/1``) as plain Python types."""
    meta = {
        "format": "skyradar-adc/1",
        "data_file": path.name,
        "dtype": dtype,
        "byte_order": "little",
        "shape": list(shape),
        "axes": list(AXES),
        "sample_rate_hz": config.fs_hz,
        "fc_hz": config.fc_hz,
        "bandwidth_hz": config.bandwidth_hz,
        "prf_hz": config.prf_hz,
        "scale": float(scale),
        "radar": {
            k: v
            for k, v in config.to_dict().items()
            if k not in ("fc_hz", "fs_hz", "bandwidth_hz", "prf_hz", "n_doppler")
        },
    }
    if times_s is not None:
        meta["frame_times_s"] = [float(t) for t in times_s]
    return json.loads(json.dumps(meta, default=float))  # plain Python types for YAML too
