"""Raw ADC recordings: a documented binary format with a sidecar, and numpy ``.npy`` files.

Binary format (``skyradar-adc/1``)
----------------------------------
A recording is two files with the same stem: the samples (``NAME.bin``, or the file named by
``data_file``) and a sidecar ``NAME.json`` or ``NAME.yaml``::

    {
      "format": "skyradar-adc/1",        # optional tag
      "data_file": "NAME.bin",           # optional, relative to the sidecar; default NAME.bin
      "dtype": "complex_int16",          # int16 (real) | complex_int16 (I,Q interleaved) |
                                         # float32 (real) | complex64
      "byte_order": "little",            # optional: little (default) | big
      "offset_bytes": 0,                 # optional header length to skip
      "shape": [300, 4, 250, 2032],      # C order on disk, one entry per axis
      "axes": ["frame", "rx", "chirp", "sample"],   # any order of these four names
      "sample_rate_hz": 10.0e6,          # ADC rate Fs (complex rate for complex dtypes)
      "fc_hz": 9.425e9,                  # carrier
      "bandwidth_hz": 10.0e6,            # sweep per chirp
      "prf_hz": 4921.0,                  # chirps per second (sawtooth, one chirp per interval)
      "scale": 1.0e-6,                   # optional: sample value x scale = sqrt(W) at the ADC
      "frame_period_s": 0.1064,          # optional: default chirps / prf (back-to-back frames)
      "frame_times_s": [...],            # optional instead of frame_period_s
      "radar": {"pe_dbm": 40, "noise_figure_db": 6, "range_limit_m": 5000,
                "rx_positions_m": [[0, -0.008, -0.008], ...]}   # optional RadarConfig fields
    }

``chirp`` becomes the Doppler axis (``n_doppler`` = its length), ``sample`` must not exceed
``Fs / PRF`` samples (shorter chirps are zero-padded by the range FFT). A recording with ``rx``
other than 4 needs ``radar.rx_positions_m``. A 3-D recording without a ``frame`` axis is one frame.
A time-division MIMO recording gives ``radar.tx_positions_m``: its chirps are in transmit order,
chirp ``n`` from transmitter ``n mod n_tx`` (:mod:`skyradar.process.mimo` sorts them);
:func:`skyradar.io.recording_writer.write_recording` records the transmitters of its config.

``.npy`` files carry dtype and shape themselves; a sidecar with the same stem is optional and
supplies the radar fields and ``axes`` (default ``frame, rx, chirp, sample``); without one the
thesis prototype's parameters are assumed.

A SigMF recording (``NAME.sigmf-meta`` + ``NAME.sigmf-data``) carries the same fields in SigMF's
``core`` keys and skyradar's ``skyradar:`` keys: :mod:`skyradar.io.recording_sigmf`.

Every inconsistency raises :class:`InputError` naming the file, the field and the value, before any
output is written. :func:`skyradar.io.recording_writer.write_recording` writes this format.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.io.checks import MAX_TIME_S
from skyradar.io.safe_yaml import load_yaml

__all__ = ["AXES", "DTYPES", "AdcFrames", "is_sigmf", "open_described", "read_recording"]

AXES = ("frame", "rx", "chirp", "sample")
# Sidecar dtype name -> (numpy element dtype, values per sample)
DTYPES: dict[str, tuple[str, int]] = {
    "int16": ("i2", 1),
    "complex_int16": ("i2", 2),
    "float32": ("f4", 1),
    "complex64": ("f4", 2),
}
_REQUIRED = ("dtype", "shape", "axes", "sample_rate_hz", "fc_hz", "bandwidth_hz", "prf_hz")


class AdcFrames:
    """Lazy view of a recording's frames in (frame, rx, chirp, sample) order.

    Indexing returns one frame as complex64 (complex dtypes) or float32 (real), multiplied by
    ``scale``; ``raw`` is the underlying (memory-mapped) array in file order.

    Attributes
    ----------
    shape : tuple of int
        (n_frames, n_rx, n_chirps, n_samples).
    times_s : ndarray
        Frame times, s.
    is_complex : bool

    Parameters
    ----------
    raw : ndarray
        The data in file order; with ``complex_pairs``, a last axis of length 2 holds I and Q.
    axes : list of str
        The names of ``raw``'s first four axes, any order of :data:`AXES`.
    complex_pairs : bool
        ``raw`` holds I/Q pairs (``complex_int16``, ``complex64`` on disk).
    scale : float
        Sample value times ``scale`` is sqrt(W) at the ADC.
    times_s : ndarray
        Frame times, s.

    Examples
    --------
    int16 I/Q pairs stored (frame, chirp, sample, rx), read as (rx, chirp, sample) frames:

    >>> raw = np.arange(2 * 3 * 4 * 2 * 2, dtype=np.int16).reshape(2, 3, 4, 2, 2)
    >>> frames = AdcFrames(raw, ["frame", "chirp", "sample", "rx"], True, 0.5, np.array([0.0, 0.1]))
    >>> frames.shape, len(frames), frames[1].dtype
    ((2, 2, 3, 4), 2, dtype('complex64'))
    >>> raw[1, 2, 3, 1].tolist(), complex(frames[1][1, 2, 3])
    ([94, 95], (47+47.5j))
    """

    def __init__(
        self, raw: np.ndarray, axes: list[str], complex_pairs: bool, scale: float, times_s: np.ndarray
    ):
        self.raw = raw
        order = [axes.index(a) for a in AXES]
        self._view = raw.transpose(*order, *([raw.ndim - 1] if complex_pairs else []))
        self._pairs = complex_pairs
        self.is_complex = complex_pairs or np.iscomplexobj(raw)
        self.scale = float(scale)
        self.times_s = times_s
        self.shape = tuple(int(n) for n in self._view.shape[:4])

    def __len__(self) -> int:
        return self.shape[0]

    def __getitem__(self, index: int) -> np.ndarray:
        if not -len(self) <= index < len(self):
            raise IndexError(index)
        block = np.asarray(self._view[index])
        if self._pairs:
            out = np.empty(block.shape[:-1], np.complex64)
            out.real = block[..., 0]
            out.imag = block[..., 1]
        else:
            out = block.astype(np.complex64 if self.is_complex else np.float32)
        if self.scale != 1.0:
            out *= np.float32(self.scale)
        return out

    def __iter__(self) -> Iterator[np.ndarray]:
        for i in range(len(self)):
            yield self[i]


def _sidecar_of(path: Path) -> Path | None:
    for suffix in (".json", ".yaml", ".yml"):
        candidate = path.with_suffix(suffix)
        if candidate.exists():
            return candidate
    return None


def _load_sidecar(path: Path) -> dict[str, Any]:
    try:
        text = path.read_text()
        meta = json.loads(text) if path.suffix == ".json" else load_yaml(text, path)
    except InputError:
        raise
    except (OSError, ValueError, yaml.YAMLError) as exc:
        raise InputError(f"{path}: cannot parse sidecar ({type(exc).__name__}: {exc})") from exc
    except RecursionError:  # JSON nested deeper than the parser's stack
        raise InputError(f"{path}: cannot parse sidecar (nested too deeply)") from None
    if not isinstance(meta, dict):
        raise InputError(f"{path}: sidecar must be a mapping of fields, got {type(meta).__name__}")
    return meta


def _check_axes(sidecar: Path, axes: Any, ndim: int) -> list[str]:
    if not isinstance(axes, list) or not all(isinstance(a, str) for a in axes):
        raise InputError(f"{sidecar}: field 'axes' must be a list of names, got {axes!r}")
    unknown = [a for a in axes if a not in AXES]
    if unknown:
        raise InputError(f"{sidecar}: field 'axes' has unknown name(s) {unknown}; use {list(AXES)}")
    if len(set(axes)) != len(axes):
        raise InputError(f"{sidecar}: field 'axes' repeats a name: {axes}")
    if len(axes) != ndim:
        raise InputError(f"{sidecar}: field 'axes' has {len(axes)} names but the data has {ndim} dimensions")
    missing = [a for a in AXES[1:] if a not in axes]
    if missing:
        raise InputError(f"{sidecar}: field 'axes' lacks {missing}")
    return axes


def _positive(sidecar: Path, meta: dict[str, Any], name: str) -> float:
    value = meta[name]
    if (
        not isinstance(value, int | float)
        or isinstance(value, bool)
        or not (math.isfinite(value) and value > 0)
    ):
        raise InputError(f"{sidecar}: field '{name}' must be a positive number, got {value!r}")
    return float(value)


def _config(sidecar: Path, meta: dict[str, Any], sizes: dict[str, int]) -> RadarConfig:
    fields = {k: _positive(sidecar, meta, k) for k in ("fc_hz", "bandwidth_hz", "prf_hz")}
    fields["fs_hz"] = _positive(sidecar, meta, "sample_rate_hz")
    extra = meta.get("radar", {}) or {}
    if not isinstance(extra, dict):
        raise InputError(f"{sidecar}: field 'radar' must be a mapping, got {extra!r}")
    clash = sorted(set(extra) & set(fields) | ({"n_doppler"} & set(extra)))
    if clash:
        raise InputError(f"{sidecar}: field(s) {clash} in 'radar' are given by the top-level fields / shape")
    if sizes["rx"] != 4 and "rx_positions_m" not in extra:
        raise InputError(f"{sidecar}: recording has {sizes['rx']} rx channels; give 'radar.rx_positions_m'")
    try:
        config = RadarConfig.from_dict({**fields, "n_doppler": sizes["chirp"], **extra})
    except InputError as exc:
        raise InputError(f"{sidecar}: {exc}") from None
    except (TypeError, ValueError) as exc:
        raise InputError(f"{sidecar}: field 'radar' is invalid ({exc})") from None
    if config.n_rx != sizes["rx"]:
        raise InputError(
            f"{sidecar}: 'radar.rx_positions_m' has {config.n_rx} antennas, data has {sizes['rx']}"
        )
    if sizes["sample"] > config.samples_per_chirp:
        raise InputError(
            f"{sidecar}: field 'shape' has {sizes['sample']} samples per chirp, more than "
            f"sample_rate_hz / prf_hz = {config.samples_per_chirp}"
        )
    return config


def _frame_times(sidecar: Path, meta: dict[str, Any], n_frames: int, config: RadarConfig) -> np.ndarray:
    if "frame_times_s" in meta:
        times = np.asarray(meta["frame_times_s"], float)
        if times.shape != (n_frames,) or not np.all(np.isfinite(times)):
            raise InputError(f"{sidecar}: field 'frame_times_s' must hold {n_frames} finite times")
        far = np.flatnonzero(np.abs(times) > MAX_TIME_S)  # 1e308 is finite, and no clock's reading
        if far.size:
            raise InputError(
                f"{sidecar}: field 'frame_times_s' is {times[far[0]]:g} s at frame {far[0]}, beyond "
                f"+-{MAX_TIME_S:g} s"
            )
        back = np.flatnonzero(np.diff(times) <= 0)  # a repeated time is as wrong as a backward one
        if back.size:
            i = int(back[0]) + 1
            what = "repeats" if times[i] == times[i - 1] else "goes backwards"
            raise InputError(
                f"{sidecar}: field 'frame_times_s' {what} at frame {i} ({times[i - 1]} -> {times[i]})"
            )
        return times
    period = (
        _positive(sidecar, meta, "frame_period_s") if "frame_period_s" in meta else config.frame_duration_s
    )
    return np.arange(n_frames) * period


def _open_binary(sidecar: Path, meta: dict[str, Any]) -> tuple[np.ndarray, bool, Path]:
    missing = [f for f in _REQUIRED if f not in meta]
    if missing:
        raise InputError(f"{sidecar}: missing field(s) {missing}")
    if meta["dtype"] not in DTYPES:
        raise InputError(f"{sidecar}: field 'dtype' is {meta['dtype']!r}; choose from {sorted(DTYPES)}")
    shape = meta["shape"]
    if not isinstance(shape, list) or not all(isinstance(n, int) and not isinstance(n, bool) for n in shape):
        raise InputError(f"{sidecar}: field 'shape' must be a list of integers, got {shape!r}")
    if any(n < 0 for n in shape):
        raise InputError(f"{sidecar}: field 'shape' has a negative size: {shape}")
    order = meta.get("byte_order", "little")
    if order not in ("little", "big"):
        raise InputError(f"{sidecar}: field 'byte_order' must be 'little' or 'big', got {order!r}")
    offset = meta.get("offset_bytes", 0)
    if not isinstance(offset, int) or offset < 0:
        raise InputError(f"{sidecar}: field 'offset_bytes' must be a non-negative integer, got {offset!r}")
    data = sidecar.parent / meta.get("data_file", sidecar.with_suffix(".bin").name)
    if not data.exists():
        raise InputError(f"{sidecar}: data file {data} does not exist")
    code, per = DTYPES[meta["dtype"]]
    dtype = np.dtype(("<" if order == "little" else ">") + code)
    full = [*shape, per] if per == 2 else list(shape)
    need = offset + int(np.prod(full, dtype=np.int64)) * dtype.itemsize
    have = data.stat().st_size
    if have != need:
        what = "truncated" if have < need else "larger than described"
        raise InputError(
            f"{data}: {what}: file has {have} bytes, sidecar {sidecar.name} (shape {shape}, dtype "
            f"{meta['dtype']}, offset {offset}) needs {need} bytes"
        )
    if math.prod(shape) == 0:
        raise InputError(f"{data}: empty recording (shape {shape})")
    raw = np.memmap(data, dtype=dtype, mode="r", offset=offset, shape=tuple(full))
    return raw, per == 2, data


def _open_npy(path: Path, meta: dict[str, Any]) -> tuple[np.ndarray, bool, Path]:
    try:
        raw = np.load(path, mmap_mode="r", allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: cannot read as .npy ({exc})") from exc
    if raw.dtype.kind not in "iufc":
        raise InputError(f"{path}: dtype {raw.dtype} is not numeric ADC data")
    if raw.size == 0:
        raise InputError(f"{path}: empty recording (shape {list(raw.shape)})")
    return raw, False, path


def _assume_prototype(meta: dict[str, Any]) -> None:
    """Sweep fields a ``.npy`` recording's sidecar leaves out: the thesis prototype's."""
    proto = RadarConfig.prototype_2022()
    for key, value in (
        ("sample_rate_hz", proto.fs_hz),
        ("fc_hz", proto.fc_hz),
        ("bandwidth_hz", proto.bandwidth_hz),
        ("prf_hz", proto.prf_hz),
    ):
        meta.setdefault(key, value)


def read_recording(path: str | Path) -> tuple[AdcFrames, RadarConfig]:
    """Open a raw ADC recording (binary + sidecar, ``.npy`` or SigMF) without reading it into memory.

    Parameters
    ----------
    path : path
        The data file (``NAME.bin``, ``NAME.npy``) or its sidecar (``NAME.json``/``NAME.yaml``), or
        a SigMF recording (``NAME.sigmf-meta``, ``NAME.sigmf-data`` or ``NAME``; the fields it needs
        are in :mod:`skyradar.io.recording_sigmf`).

    Returns
    -------
    frames : AdcFrames
        Frames in (frame, rx, chirp, sample) order, scaled, with ``frames.times_s``.
    config : RadarConfig
        Radar parameters from the sidecar (chirp count as ``n_doppler``).

    Examples
    --------
    >>> import tempfile
    >>> from skyradar.io.recording_writer import write_recording
    >>> cfg = RadarConfig.prototype_2022(n_doppler=8)
    >>> adc = np.full((2, 4, 8, cfg.samples_per_chirp), 1 + 1j, np.complex64)
    >>> d = Path(tempfile.mkdtemp())
    >>> _ = write_recording(d / "rec.bin", adc, cfg, scale=0.5)
    >>> frames, config = read_recording(d / "rec.json")
    >>> frames.shape, config.n_doppler, complex(frames[1][0, 0, 0])
    ((2, 4, 8, 2032), 8, (1+1j))
    """
    path = Path(path)
    if is_sigmf(path):
        from skyradar.io.recording_sigmf import read_sigmf_recording

        return read_sigmf_recording(path)
    if not path.exists():
        raise InputError(f"{path}: no such recording")
    sidecar = path if path.suffix in (".json", ".yaml", ".yml") else _sidecar_of(path)
    if path.suffix == ".npy":
        meta = _load_sidecar(sidecar) if sidecar else {}
        raw, pairs, _ = _open_npy(path, meta)
        meta.setdefault("axes", list(AXES if raw.ndim == 4 else AXES[1:]))
        _assume_prototype(meta)
        return _frames_of(sidecar or path, meta, raw, pairs)
    if sidecar is None:
        raise InputError(
            f"{path}: no sidecar {path.with_suffix('.json').name} or {path.with_suffix('.yaml').name}"
        )
    meta = _load_sidecar(sidecar)
    if "data_file" not in meta and path != sidecar:
        meta["data_file"] = path.name
    return open_described(sidecar, meta)


def is_sigmf(path: str | Path) -> bool:
    """True if ``path`` names a SigMF recording: ``NAME.sigmf-meta``, ``NAME.sigmf-data``, or a bare
    ``NAME`` with a ``NAME.sigmf-meta`` beside it.

    Examples
    --------
    >>> is_sigmf("rec.sigmf-meta"), is_sigmf("rec.sigmf-data"), is_sigmf("rec.json")
    (True, True, False)
    """
    path = Path(path)
    if path.suffix in (".sigmf-meta", ".sigmf-data"):
        return True
    return not path.exists() and path.with_name(path.name + ".sigmf-meta").exists()


def open_described(sidecar: Path, meta: dict[str, Any]) -> tuple[AdcFrames, RadarConfig]:
    """Open the binary data file a ``skyradar-adc/1`` description names, checked field by field.

    The part of :func:`read_recording` after the sidecar is parsed, for readers of other metadata
    formats (:mod:`skyradar.io.recording_sigmf`) that translate their fields into these.

    Parameters
    ----------
    sidecar : Path
        The metadata file, named in every error and the base of a relative ``data_file``.
    meta : dict
        The fields of the ``skyradar-adc/1`` format (module docstring).

    Returns
    -------
    frames : AdcFrames
    config : RadarConfig

    Raises
    ------
    InputError
        Naming ``sidecar``, the field and the value for any inconsistency.

    Examples
    --------
    Real float32 samples, two frames of 4 rx x 2 chirps x 8 samples, 0.25 s apart:

    >>> import tempfile
    >>> meta = {"dtype": "float32", "shape": [2, 4, 2, 8], "axes": list(AXES), "sample_rate_hz": 10e6,
    ...         "fc_hz": 9.425e9, "bandwidth_hz": 10e6, "prf_hz": 4921.0, "frame_period_s": 0.25}
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = (Path(d) / "rec.bin").write_bytes(np.arange(128, dtype="<f4").tobytes())
    ...     frames, config = open_described(Path(d) / "rec.json", meta)
    ...     frames.shape, frames[1][0, 1].tolist(), frames.times_s.tolist(), config.n_doppler
    ((2, 4, 2, 8), [72.0, 73.0, 74.0, 75.0, 76.0, 77.0, 78.0, 79.0], [0.0, 0.25], 2)
    """
    raw, pairs, _ = _open_binary(sidecar, meta)
    return _frames_of(sidecar, meta, raw, pairs)


def _frames_of(
    sidecar: Path, meta: dict[str, Any], raw: np.ndarray, pairs: bool
) -> tuple[AdcFrames, RadarConfig]:
    """The frames view and radar of an opened data array, once axes, radar and times are checked."""
    ndim = raw.ndim - (1 if pairs else 0)
    axes = _check_axes(sidecar, meta["axes"], ndim)
    if "frame" not in axes:
        raw = raw[None]
        axes = ["frame", *axes]
    sizes = {a: int(raw.shape[axes.index(a)]) for a in AXES}
    config = _config(sidecar, meta, sizes)
    scale = _positive(sidecar, meta, "scale") if "scale" in meta else 1.0
    times = _frame_times(sidecar, meta, sizes["frame"], config)
    return AdcFrames(raw, axes, pairs, scale, times), config
