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

:func:`read_iq_recording` returns an :class:`IqRecording`: the samples stay on disk and are read
in chunks (:meth:`IqRecording.chunks`), so memory is bounded by the chunk size, not the recording.
Sample values are as recorded (the simulator writes sqrt(W) at the receiver input); ``ci16`` codes
are divided by 32768. Bad input raises :class:`~skyradar.errors.InputError` naming file, field, value.
"""

from __future__ import annotations

import datetime as dt
import hashlib
import json
import warnings
from contextlib import AbstractContextManager
from pathlib import Path
from typing import Any, BinaryIO, Literal

import numpy as np

from skyradar.errors import InputError
from skyradar.io.atomic import atomic_path, write_text_atomic
from skyradar.io.iq_raw import RAW_SUFFIXES, read_raw_iq, write_raw_iq
from skyradar.io.iq_recording import (
    DATATYPES,
    IqRecording,
    metadata_illuminator,
    metadata_position,
    positive_number,
)

__all__ = ["DATATYPES", "IqRecording", "SigmfWriter", "read_iq_recording", "sigmf_paths", "write_raw_iq"]

EXTENSION = {"name": "skyradar", "version": "1.0.0", "optional": True}


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


def _read_sigmf(meta_path: Path, data_path: Path, require_illuminator: bool) -> IqRecording:
    import sigmf.validate

    try:
        meta = json.loads(meta_path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"{meta_path}: not a SigMF metadata file ({type(exc).__name__}: {exc})") from None
    except RecursionError:  # JSON nested deeper than the parser's stack: no metadata file is
        raise InputError(f"{meta_path}: not a SigMF metadata file (JSON nested too deeply)") from None
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
        count = glob["skyradar:sample_count"]
        if isinstance(count, bool) or not isinstance(count, int) or count < 0:
            raise InputError(
                f"{meta_path}: field 'skyradar:sample_count' must be a whole number, got {count!r}"
            )
        ends.append(count)
    illum, illum_pos = metadata_illuminator(
        str(meta_path), glob.get("skyradar:illuminator"), require_illuminator
    )
    info = {
        "sample_rate_hz": _sample_rate(meta_path, glob),
        "center_frequency_hz": _centre_frequency(meta_path, captures[0], illum),
        "start_time": captures[0].get("core:datetime"),
        "receiver_geodetic": (float(lat), float(lon), float(alt[0]) if alt else 0.0),
        "illuminator": illum,
        "illuminator_geodetic": illum_pos,
        "receiver": _mapping(meta_path, "skyradar:receiver", glob.get("skyradar:receiver", {})),
        "n_samples": max(ends) if ends else None,
    }
    if not data_path.exists():
        raise InputError(f"{meta_path}: its data file {data_path.name} does not exist")
    return IqRecording(meta_path, data_path, datatype, int(captures[0].get("core:header_bytes", 0)), info)


def _centre_frequency(where: Path, capture: dict, illuminator: dict) -> float:
    # The receiver's tuning; without it the illuminator's carrier (a passive receiver tunes to it).
    value = capture.get("core:frequency", illuminator.get("carrier_frequency_hz"))
    if isinstance(value, bool) or not isinstance(value, int | float) or not value > 0:
        raise InputError(
            f"{where}: field 'core:frequency' (first capture) is {value!r} and the illuminator names no "
            "carrier_frequency_hz: the centre frequency is needed for Doppler"
        )
    return float(value)


def _mapping(where: Path, field: str, value: object) -> dict:
    if not isinstance(value, dict):
        raise InputError(f"{where}: field '{field}' must be an object, got {value!r}")
    return value


def _sample_rate(where: Path, glob: dict) -> float:
    """``core:sample_rate``, a finite rate above 0 (NaN, infinite or negative rates are refused)."""
    if "core:sample_rate" not in glob:
        raise InputError(f"{where}: field 'core:sample_rate' is missing")
    return positive_number(str(where), "core:sample_rate", glob["core:sample_rate"], "a finite rate > 0 Hz")


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
    if path.suffix.lower() in RAW_SUFFIXES:
        if not path.exists():
            raise InputError(f"{path}: no such file")
        return read_raw_iq(path, require_illuminator)
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
        Complex sample rate and centre frequency, Hz.
    receiver : dict
        ``latitude``, ``longitude``, ``altitude`` of the receiving antenna (WGS84 deg, deg, m).
    illuminator : dict
        ``skyradar:illuminator``: at least ``latitude``, ``longitude``, ``altitude``.
    receiver_info : dict, optional
        ``skyradar:receiver`` (noise_figure_db, antenna_gain_dbi, height_above_ground_m).
    start_time : datetime or str, optional
        UTC time of the first sample (default now).
    description : str
        ``core:description``; default "passive radar receiver recording".
    overwrite : bool
        Replace existing files (otherwise an existing one raises :class:`InputError`).

    Examples
    --------
    Two chunks appended; the metadata counts and hashes all of them, and an exception inside the
    block leaves no file.

    >>> import tempfile
    >>> rx = {"latitude": 52.0, "longitude": 5.0, "altitude": 40.0}
    >>> tx = {"latitude": 52.1, "longitude": 5.0, "altitude": 20.0}
    >>> with tempfile.TemporaryDirectory() as d:
    ...     with SigmfWriter(Path(d) / "rec", 2e6, 1e9, rx, tx, start_time="2026-05-01T10:00:00Z") as w:
    ...         w.write(np.arange(3) * 1j)
    ...         w.write(np.ones(2))
    ...     meta = json.loads((Path(d) / "rec.sigmf-meta").read_text())
    ...     data = np.fromfile(Path(d) / "rec.sigmf-data", "<c8")
    ...     try:
    ...         with SigmfWriter(Path(d) / "bad", 2e6, 1e9, rx, tx) as w:
    ...             raise ValueError("receiver stopped")
    ...     except ValueError:
    ...         pass
    ...     names = sorted(p.name for p in Path(d).iterdir())
    >>> meta["global"]["skyradar:sample_count"], meta["global"]["core:geolocation"]["coordinates"]
    (5, [5.0, 52.0, 40.0])
    >>> data.tolist(), names
    ([0j, 1j, 2j, (1+0j), (1+0j)], ['rec.sigmf-data', 'rec.sigmf-meta'])
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
        lat, lon, alt = metadata_position(str(self.meta_path), "receiver", receiver)
        metadata_illuminator(str(self.meta_path), illuminator, True)
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
        self._capture: dict[str, Any] = {"core:sample_start": 0, "core:frequency": float(center_frequency_hz)}
        self._capture["core:datetime"] = _iso(start_time)
        self._hash = hashlib.sha512()
        self._ctx: AbstractContextManager[Path] | None = None  # the data file's atomic_path, while open
        self._file: BinaryIO | None = None

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
        assert self._file is not None, "SigmfWriter.write outside its with block"
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

    def __exit__(self, exc_type, exc, tb) -> Literal[False]:
        assert self._file is not None and self._ctx is not None  # set by __enter__
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
