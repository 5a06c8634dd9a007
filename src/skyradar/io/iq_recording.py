"""A single-channel IQ recording of a passive receiver, read in chunks, with the metadata a processor needs.

:class:`IqRecording` is what :func:`skyradar.io.sigmf_io.read_iq_recording` returns for a SigMF pair or a
raw ``.cf32``/``.ci16`` file with a sidecar (:mod:`skyradar.io.iq_raw`). The samples stay on disk and
are read in chunks (:meth:`IqRecording.chunks`), so memory is bounded by the chunk size, not the
recording. Sample values are as recorded (the simulator writes sqrt(W) at the receiver input); ``ci16``
codes are divided by 32768.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from skyradar.errors import InputError

__all__ = ["DATATYPES", "IqRecording", "positive_number"]

# SigMF datatype -> (numpy element dtype on disk, scale to float)
DATATYPES: dict[str, tuple[str, float]] = {"cf32_le": ("<c8", 1.0), "ci16_le": ("<i2", 1.0 / 32768.0)}
_POSITION = ("latitude", "longitude", "altitude")


def metadata_position(where: str, field: str, obj: Any) -> tuple[float, float, float]:
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
    """A single-channel IQ recording on disk, read in chunks, with the metadata a passive processor needs.

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

    Parameters
    ----------
    path, data_path : Path
        The metadata (or sidecar) file and the sample file.
    datatype : str
        A key of :data:`DATATYPES`.
    offset_bytes : int
        Header bytes before the first sample in ``data_path``.
    info : dict
        ``sample_rate_hz`` (Hz), ``center_frequency_hz`` (Hz), ``receiver_geodetic``,
        ``illuminator``, ``illuminator_geodetic``, and optionally ``start_time``, ``receiver`` and
        ``n_samples`` (the data file must hold at least that many).

    Raises
    ------
    InputError
        When the data file is shorter than its header or than ``n_samples``, ends inside a sample, or
        holds float32 values declared as ``ci16_le``.

    Examples
    --------
    Five cf32 samples after an 8-byte header, read in chunks of two with one sample of overlap.

    >>> import tempfile
    >>> info = {"sample_rate_hz": 1e6, "center_frequency_hz": 1e9, "receiver_geodetic": (52.0, 5.0, 10.0),
    ...         "illuminator": {}, "illuminator_geodetic": None}
    >>> with tempfile.TemporaryDirectory() as d:
    ...     data = Path(d) / "r.cf32"
    ...     _ = data.write_bytes(bytes(8) + (np.arange(5) * 1j).astype("<c8").tobytes())
    ...     rec = IqRecording(data.with_suffix(".json"), data, "cf32_le", 8, info)
    ...     rec.n_samples, [(start, block.imag.tolist()) for start, block in rec.chunks(2, overlap=1)]
    (5, [(0, [0.0, 1.0, 2.0]), (2, [2.0, 3.0, 4.0]), (4, [4.0])])
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
        if size < 0:
            raise InputError(
                f"{self.data_path}: data file of {size + offset_bytes} bytes is shorter than its "
                f"{offset_bytes}-byte header (core:header_bytes)"
            )
        if size % sample_bytes:
            raise InputError(
                f"{self.data_path}: data file of {size + offset_bytes} bytes ends inside a sample "
                f"({datatype}, {sample_bytes} bytes per sample after {offset_bytes} header bytes): truncated?"
            )
        self.n_samples = size // sample_bytes
        expected = info.get("n_samples")
        if expected is not None and (
            isinstance(expected, bool) or not isinstance(expected, int) or expected < 0
        ):
            raise InputError(f"{self.path}: field 'n_samples' must be a whole number >= 0, got {expected!r}")
        if expected is not None and expected > self.n_samples:
            raise InputError(
                f"{self.data_path}: data file holds {self.n_samples} samples, shorter than the "
                f"{int(expected)} its metadata ({self.path.name}) says"
            )
        self._dtype, self._offset, self._sample_bytes = dtype, offset_bytes, sample_bytes
        if datatype == "ci16_le":
            declared = info.get("datatype_declared_by") or f"field 'core:datatype' of {self.path.name}"
            _check_not_float32(self.data_path, offset_bytes, self.n_samples, declared)
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
        n = max(stop - start, 0)
        # A plain read per call, not a long-lived memmap: pages of a mapping stay in the process's RSS
        # once touched, which would grow with the recording; this keeps memory at one chunk.
        with open(self.data_path, "rb") as f:
            f.seek(self._offset + start * self._sample_bytes)
            block = np.fromfile(f, dtype=self._dtype, count=n * (2 if self.datatype == "ci16_le" else 1))
        if self.datatype == "ci16_le":
            out = np.empty(n, np.complex64)
            out.real, out.imag = block[0::2], block[1::2]
            return out * np.float32(self._scale)
        return block.astype(np.complex64, copy=False)

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


# A float32 whose biased exponent lies here is 2^-64 .. 2^40 in magnitude (5e-20 .. 1e12): any sample
# value a receiver writes as cf32. Read as ci16, such a word is one whose Q code (the top bits, where
# the exponent is) lies in 8064 .. 21503 or -24704 .. -11265. Real int16 data has small codes too:
# noise puts at most 40 % of its samples there (clipped at full scale), a tone at most 70 % (at 0.65
# of full scale), cf32 data all but its zeros.
_FLOAT32_EXPONENTS = (127 - 64, 127 + 40)
_LIKE_FLOAT32 = 0.95  # share of non-zero samples in that band above which ci16 data is cf32
_PROBE_SAMPLES = 1 << 16  # read at the start and in the middle of the data


def _check_not_float32(data_path: Path, offset_bytes: int, n_samples: int, declared: str) -> None:
    """Refuse ci16 data whose 4-byte samples are float32 values (cf32 data declared ci16).

    Cf32 data read as ci16 is twice as many samples of bit patterns, not a signal; the processor
    would only report that it finds no pulse. :class:`InputError` names the file and where the
    datatype is declared (``declared``).
    """
    words = []
    with open(data_path, "rb") as f:
        for start in sorted({0, max(n_samples // 2 - _PROBE_SAMPLES // 2, 0)}):
            f.seek(offset_bytes + 4 * start)
            words.append(np.fromfile(f, dtype="<u4", count=min(_PROBE_SAMPLES, n_samples - start)))
    word = np.concatenate(words)
    word = word[(word & 0x7FFFFFFF) != 0]  # zero samples (I = Q = 0, or +-0.0) say nothing
    if word.size < 256:
        return
    exponent = (word >> 23) & 0xFF
    share = float(np.mean((exponent >= _FLOAT32_EXPONENTS[0]) & (exponent <= _FLOAT32_EXPONENTS[1])))
    if share >= _LIKE_FLOAT32:
        raise InputError(
            f"{data_path}: the data does not look like the declared datatype 'ci16_le' ({declared}): "
            f"{share:.0%} of its non-zero 4-byte samples are float32 values between 5e-20 and 1e12, as "
            "in cf32_le data; declare 'cf32_le' if it is"
        )


def positive_number(where: str, field: str, value: Any, must_be: str = "a positive number") -> float:
    """``value`` of metadata ``field`` as a float when it is a finite number above 0, else
    :class:`InputError` naming ``where``, the field and the value (``must_be`` says what it must be).

    Examples
    --------
    >>> positive_number("rec.json", "sample_rate_hz", 2e6)
    2000000.0
    >>> positive_number("rec.json", "sample_rate_hz", float("nan"))
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: rec.json: field 'sample_rate_hz' must be a positive number, got nan
    """
    if isinstance(value, bool) or not isinstance(value, int | float) or not np.isfinite(value) or value <= 0:
        raise InputError(f"{where}: field '{field}' must be {must_be}, got {value!r}")
    return float(value)


def metadata_illuminator(where: str, obj: Any, required: bool) -> tuple[dict, tuple | None]:
    if not isinstance(obj, dict) or not all(k in obj for k in _POSITION):
        if required:
            raise InputError(
                f"{where}: field 'skyradar:illuminator' has no position (latitude, longitude, altitude): "
                f"the transmitter's site is needed to place echoes (got {obj!r})"
            )
        return (obj if isinstance(obj, dict) else {}), None
    return obj, metadata_position(where, "skyradar:illuminator", obj)
