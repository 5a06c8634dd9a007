"""IQ recordings of a passive receiver: SigMF (read and write) and raw cf32/ci16 files with a sidecar.

SigMF (https://sigmf.org) pairs ``NAME.sigmf-data`` (the samples) with ``NAME.sigmf-meta`` (JSON).
:class:`SigmfWriter` streams complex64 chunks to the data file (``cf32_le``), hashing as it goes, and
writes the metadata through the ``sigmf`` package, which validates it against the SigMF schema. Both
files are written under temporary names and renamed at the end, data first, so a metadata file under
the final name always describes a complete data file.

Metadata a passive-radar processor needs beyond ``core`` lives in the ``skyradar`` extension
(declared in ``core:extensions``):

- ``core:geolocation``: the receiver's position (GeoJSON point: longitude, latitude, altitude);
- ``skyradar:illuminator``: the transmitter (``latitude``, ``longitude``, ``altitude`` and its
  radar parameters, see :mod:`skyradar.passive.illuminator`);
- ``skyradar:receiver``: noise figure, antenna gain, antenna height (optional);
- ``skyradar:sample_count``: the number of samples written, so a truncated data file is caught
  without hashing it (``core:sha512`` is written too).

A raw ``NAME.cf32`` or ``NAME.ci16`` file (interleaved little-endian I/Q) is read with a sidecar
``NAME.json`` / ``NAME.yaml``: ``sample_rate_hz``, ``center_frequency_hz``, optional ``n_samples`` and
``start_time``, ``receiver`` (``latitude``, ``longitude``, ``altitude``) and ``illuminator`` (as above).

:func:`read_iq_recording` returns an :class:`IqRecording`: the samples stay memory-mapped and are read
in chunks (:meth:`IqRecording.chunks`), so memory is bounded by the chunk size, not the recording.
Sample values are as recorded (the simulator writes sqrt(W) at the receiver input); ``ci16`` codes
are divided by 32768. Bad input raises :class:`~skyradar.errors.InputError` naming file, field, value.
"""

from __future__ import annotations

import datetime as dt
import hashlib
import json
import warnings
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

from skyradar.errors import InputError
from skyradar.io.atomic import atomic_path, write_text_atomic
from skyradar.io.safe_yaml import load_yaml

__all__ = ["DATATYPES", "IqRecording", "SigmfWriter", "read_iq_recording", "sigmf_paths", "write_raw_iq"]

# SigMF datatype -> (numpy element dtype on disk, scale to float)
DATATYPES: dict[str, tuple[str, float]] = {"cf32_le": ("<c8", 1.0), "ci16_le": ("<i2", 1.0 / 32768.0)}
_RAW_SUFFIXES = {".cf32": "cf32_le", ".ci16": "ci16_le", ".cs16": "ci16_le"}
EXTENSION = {"name": "skyradar", "version": "1.0.0", "optional": True}
_POSITION = ("latitude", "longitude", "altitude")


def sigmf_paths(path: str | Path) -> tuple[Path, Path]:
    """(meta, data) paths of a SigMF pair named by either file or by the bare stem.

    Examples
    --------
    >>> [p.name for p in sigmf_paths("out/rec.sigmf-meta")]
    ['rec.sigmf-meta', 'rec.sigmf-data']
    """
    path = Path(path)
    if path.suffix in (".sigmf-meta", ".sigmf-data"):
        path = path.with_suffix("")
    return path.with_name(path.name + ".sigmf-meta"), path.with_name(path.name + ".sigmf-data")


def _position(where: str, field: str, obj: Any) -> tuple[float, float, float]:
    try:
        lat, lon, alt = (float(obj[k]) for k in _POSITION)
    except (KeyError, TypeError, ValueError):
        raise InputError(
            f"{where}: field '{field}' needs latitude, longitude and altitude, got {obj!r}"
        ) from None
    if not (abs(lat) <= 90 and abs(lon) <= 360 and np.isfinite(alt)):
        raise InputError(f"{where}: field '{field}' has an impossible position {(lat, lon, alt)}")
    return lat, lon, alt


class IqRecording:
    """A memory-mapped single-channel IQ recording with the metadata a passive processor needs.

    Attributes
    ----------
    path, data_path : Path
        The metadata (or sidecar) file and the sample file.
    datatype : str
        ``"cf32_le"`` or ``"ci16_le"``.
    sample_rate_hz, center_frequency_hz : float
    n_samples : int
    start_time : str or None
        ISO 8601 UTC time of sample 0.
    receiver_geodetic, illuminator_geodetic : tuple of float
        (lat_deg, lon_deg, alt_m), WGS84.
    illuminator, receiver : dict
        The ``skyradar:illuminator`` and ``skyradar:receiver`` objects.
    """

    def __init__(self, path: Path, data_path: Path, datatype: str, offset_bytes: int, info: dict) -> None:
        self.path, self.data_path, self.datatype = Path(path), Path(data_path), datatype
        self.sample_rate_hz = float(info["sample_rate_hz"])
        self.center_frequency_hz = float(info["center_frequency_hz"])
        self.start_time: str | None = info.get("start_time")
        self.receiver_geodetic: tuple[float, float, float] = info["receiver_geodetic"]
        self.illuminator: dict = info["illuminator"]
        self.illuminator_geodetic = info["illuminator_geodetic"]
        self.receiver: dict = info.get("receiver", {})
        dtype, self._scale = DATATYPES[datatype]
        sample_bytes = np.dtype(dtype).itemsize * (2 if datatype == "ci16_le" else 1)
        size = self.data_path.stat().st_size - offset_bytes
        if size < 0 or size % sample_bytes:
            raise InputError(
                f"{self.data_path}: data file of {size + offset_bytes} bytes ends inside a sample "
                f"({datatype}, {sample_bytes} bytes per sample after {offset_bytes} header bytes): truncated?"
            )
        self.n_samples = size // sample_bytes
        expected = info.get("n_samples")
        if expected is not None and int(expected) > self.n_samples:
            raise InputError(
                f"{self.data_path}: data file holds {self.n_samples} samples, shorter than the "
                f"{int(expected)} its metadata ({self.path.name}) says"
            )
        shape = (self.n_samples, 2) if datatype == "ci16_le" else (self.n_samples,)
        self._raw = (
            np.memmap(self.data_path, dtype=dtype, mode="r", offset=offset_bytes, shape=shape)
            if self.n_samples
            else np.zeros(shape, dtype)
        )
        stem = self.path.name.removesuffix(".sigmf-meta")
        stem = stem.rsplit(".", 1)[0] if stem == self.path.name else stem
        truth = self.path.with_name(stem + ".truth.parquet")
        self.truth_table_path = truth if truth.exists() else None
        truth_json = self.path.with_name(stem + ".truth.json")
        self.truth_json_path = truth_json if truth_json.exists() else None

    @property
    def duration_s(self) -> float:
        return self.n_samples / self.sample_rate_hz

    def read(self, start: int, count: int) -> np.ndarray:
        """Samples ``start .. start + count`` (clipped at the end) as a new complex64 array."""
        start = max(int(start), 0)
        stop = min(start + max(int(count), 0), self.n_samples)
        block = self._raw[start:stop]
        if self.datatype == "ci16_le":
            out = np.empty(stop - start if stop > start else 0, np.complex64)
            out.real, out.imag = block[:, 0], block[:, 1]
            return out * np.float32(self._scale)
        return np.array(block, dtype=np.complex64)

    def chunks(self, chunk_samples: int, overlap: int = 0) -> Iterator[tuple[int, np.ndarray]]:
        """Yield ``(start, samples)`` for consecutive chunks; each holds ``overlap`` extra samples after it.

        Memory is one chunk (plus overlap) at a time whatever the recording's length.
        """
        if chunk_samples < 1 or overlap < 0:
            raise InputError(f"chunk_samples must be >= 1 and overlap >= 0, got {chunk_samples}, {overlap}")
        for start in range(0, self.n_samples, chunk_samples):
            yield start, self.read(start, chunk_samples + overlap)

    def __repr__(self) -> str:
        return (
            f"IqRecording({self.path.name}, {self.datatype}, {self.n_samples} samples at "
            f"{self.sample_rate_hz / 1e6:g} MS/s, {self.duration_s:.3f} s)"
        )


def _illuminator(where: str, obj: Any, required: bool) -> tuple[dict, tuple | None]:
    if not isinstance(obj, dict) or not all(k in obj for k in _POSITION):
        if required:
            raise InputError(
                f"{where}: field 'skyradar:illuminator' has no position (latitude, longitude, altitude): "
                f"the transmitter's site is needed to place echoes (got {obj!r})"
            )
        return (obj if isinstance(obj, dict) else {}), None
    return obj, _position(where, "skyradar:illuminator", obj)


def _read_sigmf(meta_path: Path, data_path: Path, require_illuminator: bool) -> IqRecording:
    import sigmf.validate

    try:
        meta = json.loads(meta_path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"{meta_path}: not a SigMF metadata file ({type(exc).__name__}: {exc})") from None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sigmf.validate.validate(meta)
    except Exception as exc:  # noqa: BLE001 - schema failure becomes one line
        msg = str(getattr(exc, "message", exc)).splitlines()[0]
        raise InputError(f"{meta_path}: not valid SigMF ({msg})") from None
    glob = meta["global"]
    datatype = glob["core:datatype"]
    if datatype not in DATATYPES:
        raise InputError(
            f"{meta_path}: field 'core:datatype' is {datatype!r}; readable: {', '.join(DATATYPES)}"
        )
    if int(glob.get("core:num_channels", 1)) != 1:
        raise InputError(f"{meta_path}: field 'core:num_channels' is {glob['core:num_channels']}; need 1")
    if "core:geolocation" not in glob:
        raise InputError(f"{meta_path}: field 'core:geolocation' (the receiver's position) is missing")
    lon, lat, *alt = glob["core:geolocation"]["coordinates"]
    captures = meta.get("captures") or [{}]
    ends = [int(c.get("core:sample_start", 0)) + 1 for c in captures[1:]]
    for a in meta.get("annotations", []):
        ends.append(int(a["core:sample_start"]) + int(a.get("core:sample_count", 0)))
    if "skyradar:sample_count" in glob:
        ends.append(int(glob["skyradar:sample_count"]))
    illum, illum_pos = _illuminator(str(meta_path), glob.get("skyradar:illuminator"), require_illuminator)
    info = {
        "sample_rate_hz": glob["core:sample_rate"] if "core:sample_rate" in glob else _missing(meta_path),
        "center_frequency_hz": captures[0].get("core:frequency", illum.get("carrier_frequency_hz", 0.0)),
        "start_time": captures[0].get("core:datetime"),
        "receiver_geodetic": (float(lat), float(lon), float(alt[0]) if alt else 0.0),
        "illuminator": illum,
        "illuminator_geodetic": illum_pos,
        "receiver": glob.get("skyradar:receiver", {}),
        "n_samples": max(ends) if ends else None,
    }
    if not data_path.exists():
        raise InputError(f"{meta_path}: its data file {data_path.name} does not exist")
    return IqRecording(meta_path, data_path, datatype, int(captures[0].get("core:header_bytes", 0)), info)


def _missing(where: Path) -> float:
    raise InputError(f"{where}: field 'core:sample_rate' is missing")


def _read_raw(data_path: Path, require_illuminator: bool) -> IqRecording:
    sidecars = [data_path.with_suffix(s) for s in (".json", ".yaml", ".yml")]
    sidecar = next((p for p in sidecars if p.exists()), None)
    if sidecar is None:
        raise InputError(f"{data_path}: no sidecar {data_path.stem}.json or .yaml with sample_rate_hz etc.")
    try:
        info = json.loads(sidecar.read_text()) if sidecar.suffix == ".json" else load_yaml(sidecar)
    except (OSError, ValueError) as exc:
        raise InputError(f"{sidecar}: cannot read sidecar ({exc})") from None
    if not isinstance(info, dict):
        raise InputError(f"{sidecar}: sidecar must be a mapping, got {type(info).__name__}")
    for key in ("sample_rate_hz", "center_frequency_hz"):
        value = info.get(key)
        if (
            not isinstance(value, int | float)
            or not np.isfinite(value)
            or value < 0
            or (key == "sample_rate_hz" and value == 0)
        ):
            raise InputError(f"{sidecar}: field '{key}' must be a positive number, got {value!r}")
    illum, illum_pos = _illuminator(str(sidecar), info.get("illuminator"), require_illuminator)
    receiver = info.get("receiver")
    fields = {
        **info,
        "receiver_geodetic": _position(str(sidecar), "receiver", receiver),
        "illuminator": illum,
        "illuminator_geodetic": illum_pos,
        "receiver": receiver,
    }
    return IqRecording(sidecar, data_path, _RAW_SUFFIXES[data_path.suffix.lower()], 0, fields)


def read_iq_recording(path: str | Path, require_illuminator: bool = True) -> IqRecording:
    """Open a SigMF pair (either file or the bare stem) or a raw ``.cf32``/``.ci16`` file with sidecar.

    Parameters
    ----------
    path : str or Path
        ``NAME.sigmf-meta``, ``NAME.sigmf-data``, ``NAME`` (SigMF), or ``NAME.cf32`` / ``NAME.ci16``.
    require_illuminator : bool
        Raise when the illuminator's position is missing (a passive processor cannot place echoes).

    Examples
    --------
    >>> import tempfile
    >>> rx = {"latitude": 52.0, "longitude": 5.0, "altitude": 40.0}
    >>> tx = {"latitude": 52.1, "longitude": 5.0, "altitude": 20.0}
    >>> p = Path(tempfile.mkdtemp()) / "rec.sigmf-meta"
    >>> with SigmfWriter(p, 5e6, 2.8e9, rx, tx) as w:
    ...     w.write(np.ones(1000, np.complex64))
    >>> rec = read_iq_recording(p)
    >>> rec.n_samples, rec.illuminator_geodetic, float(rec.read(998, 10).real.sum())
    (1000, (52.1, 5.0, 20.0), 2.0)
    """
    path = Path(path)
    if path.suffix.lower() in _RAW_SUFFIXES:
        if not path.exists():
            raise InputError(f"{path}: no such file")
        return _read_raw(path, require_illuminator)
    if path.name.endswith((".sigmf", ".sigmf.gz", ".sigmf.xz", ".sigmf.zip")):
        raise InputError(f"{path}: SigMF archives are not read directly; extract the .sigmf-meta/-data pair")
    meta_path, data_path = sigmf_paths(path)
    if not meta_path.exists():
        raise InputError(
            f"{path}: no SigMF metadata {meta_path.name}; readable: NAME.sigmf-meta, NAME.cf32 or NAME.ci16"
        )
    return _read_sigmf(meta_path, data_path, require_illuminator)


def _iso(start_time: dt.datetime | str | None) -> str:
    if start_time is None:
        start_time = dt.datetime.now(dt.UTC)
    if isinstance(start_time, str):
        return start_time
    if start_time.tzinfo is None:
        start_time = start_time.replace(tzinfo=dt.UTC)
    return start_time.astimezone(dt.UTC).strftime("%Y-%m-%dT%H:%M:%S.%fZ")


class SigmfWriter:
    """Stream complex samples into a SigMF ``cf32_le`` recording; metadata validated by ``sigmf``.

    Use as a context manager and call :meth:`write` with consecutive chunks. On success the data file
    and then the metadata file appear under their final names; on an exception neither does.

    Parameters
    ----------
    path : str or Path
        ``NAME.sigmf-meta`` (or ``NAME``); the data goes to ``NAME.sigmf-data``.
    sample_rate_hz, center_frequency_hz : float
    receiver : dict
        ``latitude``, ``longitude``, ``altitude`` of the receiving antenna (WGS84 deg, deg, m).
    illuminator : dict
        ``skyradar:illuminator``: at least ``latitude``, ``longitude``, ``altitude``.
    receiver_info : dict, optional
        ``skyradar:receiver`` (noise_figure_db, antenna_gain_dbi, height_above_ground_m).
    start_time : datetime or str, optional
        UTC time of the first sample (default now).
    description : str
    overwrite : bool
        Replace existing files (otherwise an existing one raises :class:`InputError`).
    """

    def __init__(
        self,
        path: str | Path,
        sample_rate_hz: float,
        center_frequency_hz: float,
        receiver: dict,
        illuminator: dict,
        receiver_info: dict | None = None,
        start_time: dt.datetime | str | None = None,
        description: str = "",
        overwrite: bool = False,
    ) -> None:
        self.meta_path, self.data_path = sigmf_paths(path)
        for p in (self.meta_path, self.data_path):
            if p.exists() and not overwrite:
                raise InputError(f"{p}: already exists (use --overwrite to replace it)")
        lat, lon, alt = _position(str(self.meta_path), "receiver", receiver)
        _illuminator(str(self.meta_path), illuminator, True)
        self.n_samples = 0
        self._global = {
            "core:datatype": "cf32_le",
            "core:sample_rate": float(sample_rate_hz),
            "core:num_channels": 1,
            "core:recorder": "skyradar",
            "core:description": description or "passive radar receiver recording",
            "core:geolocation": {"type": "Point", "coordinates": [lon, lat, alt]},
            "core:extensions": [dict(EXTENSION)],
            "skyradar:illuminator": json.loads(json.dumps(illuminator)),
            "skyradar:receiver": dict(receiver_info or {}),
        }
        self._capture = {"core:sample_start": 0, "core:frequency": float(center_frequency_hz)}
        self._capture["core:datetime"] = _iso(start_time)
        self._hash = hashlib.sha512()
        self._ctx = None
        self._file = None

    def __enter__(self) -> SigmfWriter:
        self._ctx = atomic_path(self.data_path)
        tmp = self._ctx.__enter__()
        self._file = open(tmp, "wb")  # noqa: SIM115 - closed in __exit__
        return self

    def write(self, samples: np.ndarray) -> None:
        """Append samples (any complex array, written as little-endian complex64)."""
        block = np.ascontiguousarray(samples, dtype="<c8").ravel()
        buf = block.tobytes()
        self._hash.update(buf)
        self._file.write(buf)
        self.n_samples += block.size

    def metadata(self) -> dict:
        """The SigMF metadata for what has been written so far."""
        from sigmf import SigMFFile

        glob = {**self._global, "core:sha512": self._hash.hexdigest()}
        glob["skyradar:sample_count"] = self.n_samples
        handle = SigMFFile(metadata={"global": glob, "captures": [], "annotations": []})
        handle.add_capture(0, metadata={k: v for k, v in self._capture.items() if k != "core:sample_start"})
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            handle.validate()
        return handle._metadata

    def __exit__(self, exc_type, exc, tb) -> bool:
        self._file.close()
        if exc_type is not None:
            self._ctx.__exit__(exc_type, exc, tb)
            return False
        try:
            text = json.dumps(self.metadata(), indent=2) + "\n"
        except BaseException as err:
            self._ctx.__exit__(type(err), err, err.__traceback__)
            raise
        self._ctx.__exit__(None, None, None)  # data renamed into place first
        write_text_atomic(self.meta_path, text)
        return False


def write_raw_iq(
    path: str | Path, samples: Iterable[np.ndarray] | np.ndarray, sidecar: dict, datatype: str = "cf32_le"
) -> Path:
    """Write a raw ``.cf32``/``.ci16`` file and its ``.json`` sidecar (both atomically); return the data path.

    ``ci16`` samples are the complex values times 32768, rounded and clipped to int16.

    Examples
    --------
    >>> import tempfile
    >>> side = {"sample_rate_hz": 5e6, "center_frequency_hz": 2.8e9,
    ...         "receiver": {"latitude": 52.0, "longitude": 5.0, "altitude": 40.0},
    ...         "illuminator": {"latitude": 52.1, "longitude": 5.0, "altitude": 20.0}}
    >>> p = write_raw_iq(Path(tempfile.mkdtemp()) / "r.ci16", np.full(4, 0.5 + 0.25j), side, "ci16_le")
    >>> read_iq_recording(p).read(0, 2).tolist()
    [(0.5+0.25j), (0.5+0.25j)]
    """
    path = Path(path)
    if datatype not in DATATYPES:
        raise InputError(f"{path}: datatype {datatype!r} not writable; use one of {', '.join(DATATYPES)}")
    blocks = [samples] if isinstance(samples, np.ndarray) else samples
    n = 0
    with atomic_path(path) as tmp, open(tmp, "wb") as f:
        for block in blocks:
            block = np.asarray(block, dtype=np.complex64).ravel()
            n += block.size
            if datatype == "ci16_le":
                codes = np.clip(np.rint(block.view(np.float32) * 32768.0), -32768, 32767).astype("<i2")
                f.write(codes.tobytes())
            else:
                f.write(block.astype("<c8").tobytes())
    write_text_atomic(path.with_suffix(".json"), json.dumps({**sidecar, "n_samples": n}, indent=2))
    return path
