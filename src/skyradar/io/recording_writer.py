"""Write raw ADC frames as a ``skyradar-adc/1`` recording (see :mod:`skyradar.io.recordings`) or as
SigMF (see :mod:`skyradar.io.recording_sigmf`).

The frames are converted and written a few at a time, so memory stays bounded whatever the
recording's length; both files go through unique temporary names, renamed when complete.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import yaml

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.io.atomic import atomic_path
from skyradar.io.recording_sigmf import SIGMF_DTYPES, sigmf_adc_metadata
from skyradar.io.recordings import AXES, DTYPES
from skyradar.io.sigmf_io import sigmf_paths

__all__ = ["write_recording", "write_sigmf_recording"]

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
    Path
        The sidecar.

    Examples
    --------
    The default scale maps the largest magnitude, ``|3 - 6j| = sqrt(45)``, to 30000 counts; reading
    back is exact to half a count.

    >>> import tempfile
    >>> from skyradar.io.recordings import read_recording
    >>> cfg = RadarConfig.prototype_2022(n_doppler=4)
    >>> adc = np.zeros((2, 4, 4, 16), np.complex64)
    >>> adc[1, 2, 3, 5] = 3 - 6j
    >>> with tempfile.TemporaryDirectory() as d:
    ...     side = write_recording(Path(d) / "rec.bin", adc, cfg)
    ...     meta = json.loads(side.read_text())
    ...     frames, config = read_recording(side)
    ...     back = frames[1]
    ...     side.name, sorted(p.name for p in Path(d).iterdir()), meta["dtype"], meta["shape"]
    ('rec.json', ['rec.bin', 'rec.json'], 'complex_int16', [2, 4, 4, 16])
    >>> round(meta["scale"] * 30000 / 45**0.5, 6), bool(abs(back - adc[1]).max() <= meta["scale"])
    (1.0, True)
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


def write_sigmf_recording(
    path: str | Path,
    frames: np.ndarray,
    config: RadarConfig,
    datatype: str = "ci16_le",
    scale: float | None = None,
    times_s: np.ndarray | None = None,
    start_time: str | None = None,
) -> Path:
    """Write frames (frame, rx, chirp, sample) as a SigMF recording, atomically; return the meta path.

    The samples go to ``NAME.sigmf-data`` channel-interleaved, chirp after chirp (the layout of
    :mod:`skyradar.io.recording_sigmf`), a few frames at a time, so memory stays bounded whatever
    the recording's length; then ``NAME.sigmf-meta`` describes them, with the data's SHA-512. Both
    go through temporary names, the data file renamed first, so a metadata file under its final
    name always describes a complete data file.

    Parameters
    ----------
    path : str or Path
        ``NAME``, ``NAME.sigmf-meta`` or ``NAME.sigmf-data``.
    frames : ndarray, shape (n_frames, n_rx, n_chirps, n_samples)
        sqrt(W) at the ADC; complex for the ``c`` datatypes, real for the ``r`` ones.
    config : RadarConfig
        The radar; its ``n_doppler`` must be the frames' chirp count.
    datatype : {'ci16_le', 'cf32_le', 'ri16_le', 'rf32_le'}
        Integer types are quantised as ``round(x / scale)``.
    scale : float, optional
        sqrt(W) per sample unit; default so that the largest magnitude uses 30000 counts (int16)
        or 1.0 (float types).
    times_s : ndarray, optional
        Frame start times, s (default back-to-back frames).
    start_time : str, optional
        ISO 8601 UTC time of the first sample (``core:datetime``).

    Returns
    -------
    Path
        ``NAME.sigmf-meta``.

    Examples
    --------
    >>> import tempfile
    >>> from skyradar.io.recordings import read_recording
    >>> cfg = RadarConfig.prototype_2022(n_doppler=4)
    >>> adc = np.ones((3, 4, 4, cfg.samples_per_chirp), np.complex64)
    >>> meta = write_sigmf_recording(Path(tempfile.mkdtemp()) / "radar", adc, cfg, scale=1 / 1000)
    >>> meta.name, read_recording(meta)[0].shape
    ('radar.sigmf-meta', (3, 4, 4, 2032))
    """
    meta_path, data_path = sigmf_paths(path)
    frames = np.asarray(frames)
    if datatype not in SIGMF_DTYPES or not datatype.endswith("_le"):
        writable = [d for d in SIGMF_DTYPES if d.endswith("_le")]
        raise InputError(f"write_sigmf_recording: datatype {datatype!r}; choose from {writable}")
    code, per = _check_write(data_path, frames, SIGMF_DTYPES[datatype][0])
    if frames.shape[2] != config.n_doppler:
        raise InputError(
            f"write_sigmf_recording: frames have {frames.shape[2]} chirps, config.n_doppler is "
            f"{config.n_doppler}"
        )
    step = _frames_per_chunk(frames)
    if scale is None:
        peak = _peak(frames, step)
        scale = peak / 30000.0 if code == "i2" and peak > 0 else 1.0
    digest = hashlib.sha512()
    with atomic_path(meta_path) as tmp_meta, atomic_path(data_path) as tmp_data:
        with open(tmp_data, "wb") as f:
            for i in range(0, len(frames), step):
                # SigMF's order: (frame, chirp, sample, rx), the channels of each sample side by side
                block = np.ascontiguousarray(np.moveaxis(frames[i : i + step], 1, -1))
                buf = _encode(block, scale, code, per).tobytes()
                digest.update(buf)
                f.write(buf)
        n_frames, n_rx, _, n_samples = frames.shape
        meta = sigmf_adc_metadata(
            config,
            n_rx,
            n_samples,
            datatype,
            n_frames * config.n_doppler * n_samples,
            scale,
            times_s,
            start_time,
            digest.hexdigest(),
        )
        tmp_meta.write_text(json.dumps(meta, indent=1) + "\n", encoding="utf-8")
    return meta_path
