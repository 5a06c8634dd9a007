"""Raw ADC recordings of an FMCW radar as SigMF: ``NAME.sigmf-meta`` (JSON) + ``NAME.sigmf-data``.

SigMF (https://sigmf.org) describes a stream of samples; an FMCW radar's frames are that stream
cut into chirps. The data file holds the samples of every receive channel interleaved (SigMF's
multichannel layout), chirp after chirp and frame after frame, so on disk the order is
(frame, chirp, sample, rx), each sample a real value or an (I, Q) pair.

The metadata uses SigMF's ``core`` keys where they exist and skyradar's own (the ``skyradar``
extension, declared in ``core:extensions``) for the sweep:

- ``core:datatype``: ``ci16_le``, ``cf32_le``, ``ri16_le`` or ``rf32_le`` (or their ``_be``);
- ``core:sample_rate``: the ADC rate Fs, Hz (the complex rate for complex data);
- ``core:num_channels``: the receive channels; other than 4 needs ``rx_positions_m`` in
  ``skyradar:radar``;
- ``core:frequency`` (first capture): the radar's carrier ``fc_hz``, Hz;
- ``core:datetime`` (first capture, optional): UTC time of the first sample;
- ``core:header_bytes`` (first capture, optional): bytes before the first sample;
- ``skyradar:bandwidth_hz``: the sweep per chirp, Hz;
- ``skyradar:prf_hz``: chirps per second (sawtooth, one chirp per interval), Hz;
- ``skyradar:chirps_per_frame``: chirps in one frame, the Doppler FFT's length;
- ``skyradar:samples_per_chirp`` (optional): samples recorded per chirp, at most (and by default)
  Fs / PRF;
- ``skyradar:sample_count`` (optional): samples per channel in the data file, so that a truncated
  file is named rather than read short;
- ``skyradar:scale`` (optional): sample value x scale = sqrt(W) at the ADC;
- ``skyradar:frame_period_s`` (optional): frame start to frame start, s; default chirps / PRF;
- ``skyradar:frame_times_s`` (optional, instead): every frame's start time, s;
- ``skyradar:radar`` (optional): further :class:`~skyradar.config.RadarConfig` fields
  (``pe_dbm``, ``noise_figure_db``, ``range_limit_m``, ``rx_positions_m``, ...).

The number of frames is what the data file holds: its samples per channel divided by chirps per
frame times samples per chirp, which must divide exactly. One capture segment only: a retune or a
gap inside the recording would change the sweep the frames are processed with.

:func:`read_sigmf_recording` (what :func:`skyradar.io.recordings.read_recording` calls for a SigMF
path) checks these fields, then serves the frames as a ``skyradar-adc/1`` recording would; every
inconsistency is an :class:`~skyradar.errors.InputError` naming the file, the field and the value.
:func:`skyradar.io.recording_writer.write_sigmf_recording` writes this format.
"""

from __future__ import annotations

import json
import math
import re
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.io.recordings import AdcFrames, open_described
from skyradar.io.sigmf_io import sigmf_paths

__all__ = ["EXTENSION", "SIGMF_DTYPES", "read_sigmf_recording", "sigmf_adc_metadata"]

EXTENSION = {"name": "skyradar", "version": "1.0.0", "optional": False}
# SigMF datatype -> skyradar-adc/1 dtype (the element type, real or (I, Q) pairs) and byte order
SIGMF_DTYPES: dict[str, tuple[str, str]] = {
    f"{kind}{bits}_{order}": (name, {"le": "little", "be": "big"}[order])
    for kind, bits, name in (
        ("ci", "16", "complex_int16"),
        ("cf", "32", "complex64"),
        ("ri", "16", "int16"),
        ("rf", "32", "float32"),
    )
    for order in ("le", "be")
}
_BYTES_PER_SAMPLE = {"complex_int16": 4, "complex64": 8, "int16": 2, "float32": 4}
# Field names of the skyradar-adc/1 description -> the SigMF key they come from (for messages).
# Every field of the radar's configuration (``radar.<field>``) comes from ``skyradar:radar``.
_RENAMED = {
    "frame_times_s": "skyradar:frame_times_s",
    "frame_period_s": "skyradar:frame_period_s",
    "radar": "skyradar:radar",
}
_RADAR_FIELD = re.compile(r"(?<![\w:.])'?radar\.([A-Za-z_][\w.]*)'?")


def _load(meta_path: Path, data_path: Path, named: Path) -> dict[str, Any]:
    if not meta_path.exists():
        if not data_path.exists():
            raise InputError(f"{named}: no such SigMF recording ({meta_path.name}, {data_path.name})")
        raise InputError(f"{named}: no SigMF metadata file {meta_path.name} beside {data_path.name}")
    if not data_path.exists():
        raise InputError(f"{meta_path}: its data file {data_path.name} does not exist")
    try:
        meta = json.loads(meta_path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"{meta_path}: not a SigMF metadata file ({type(exc).__name__}: {exc})") from None
    except RecursionError:  # JSON nested deeper than the parser's stack: no metadata file is
        raise InputError(f"{meta_path}: not a SigMF metadata file (JSON nested too deeply)") from None
    if not isinstance(meta, dict) or not isinstance(meta.get("global"), dict):
        raise InputError(f"{meta_path}: not a SigMF metadata file (no 'global' object)")
    return meta


def _number(where: Path, obj: dict[str, Any], key: str, meaning: str, whole: bool = False) -> float:
    """``obj[key]``, a finite number above 0 (a whole one if ``whole``); else InputError naming it."""
    if key not in obj:
        raise InputError(f"{where}: field '{key}' ({meaning}) is missing")
    value = obj[key]
    number = isinstance(value, int | float) and not isinstance(value, bool)
    if not number or not (math.isfinite(value) and value > 0) or (whole and not isinstance(value, int)):
        kind = "a whole number > 0" if whole else "a finite number > 0"
        raise InputError(f"{where}: field '{key}' ({meaning}) must be {kind}, got {value!r}")
    return value


def _capture(where: Path, meta: dict[str, Any]) -> dict[str, Any]:
    captures = meta.get("captures") or [{}]
    if not isinstance(captures, list) or not all(isinstance(c, dict) for c in captures):
        raise InputError(f"{where}: field 'captures' must be a list of objects, got {captures!r}")
    if len(captures) > 1:
        raise InputError(
            f"{where}: field 'captures' has {len(captures)} segments; a radar recording is read as one "
            "(one carrier and sweep, no gap): split it into one recording per segment"
        )
    return captures[0]


def _validate_schema(where: Path, meta: dict[str, Any]) -> None:
    """The SigMF schema's checks of everything else (``sigmf`` package)."""
    import sigmf.validate

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sigmf.validate.validate(meta)
    except Exception as exc:  # noqa: BLE001 - a schema failure becomes one line
        msg = str(getattr(exc, "message", exc)).splitlines()[0]
        raise InputError(f"{where}: not valid SigMF ({msg})") from None


def _description(meta_path: Path, data_path: Path, meta: dict[str, Any]) -> dict[str, Any]:
    """The ``skyradar-adc/1`` fields of a SigMF recording, each SigMF field checked on the way."""
    glob = meta["global"]
    datatype = glob.get("core:datatype")
    if datatype not in SIGMF_DTYPES:
        raise InputError(
            f"{meta_path}: field 'core:datatype' is {datatype!r}; readable: {', '.join(SIGMF_DTYPES)}"
        )
    dtype, byte_order = SIGMF_DTYPES[datatype]
    fs = _number(meta_path, glob, "core:sample_rate", "the ADC rate, Hz")
    if "skyradar:prf_hz" not in glob and "skyradar:chirps_per_frame" not in glob:
        raise InputError(
            f"{meta_path}: field 'skyradar:prf_hz' (chirps per second) is missing: not an FMCW radar's "
            "recording (a passive receiver's is read by `skyradar passive`)"
        )
    prf = _number(meta_path, glob, "skyradar:prf_hz", "chirps per second, Hz")
    bandwidth = _number(meta_path, glob, "skyradar:bandwidth_hz", "sweep per chirp, Hz")
    chirps = int(_number(meta_path, glob, "skyradar:chirps_per_frame", "chirps per frame", whole=True))
    n_rx = int(_number(meta_path, glob, "core:num_channels", "receive channels", whole=True))
    capture = _capture(meta_path, meta)
    fc = _number(meta_path, capture, "core:frequency", "the radar's carrier, Hz, in the first capture")
    radar = glob.get("skyradar:radar", {})
    if not isinstance(radar, dict):
        raise InputError(f"{meta_path}: field 'skyradar:radar' must be an object, got {radar!r}")
    if n_rx != 4 and "rx_positions_m" not in radar:
        raise InputError(
            f"{meta_path}: field 'core:num_channels' is {n_rx}: give the antennas' positions as "
            "'rx_positions_m' in 'skyradar:radar'"
        )
    samples = int(fs // prf)
    if "skyradar:samples_per_chirp" in glob:
        recorded = int(_number(meta_path, glob, "skyradar:samples_per_chirp", "samples per chirp", True))
        if recorded > samples:
            raise InputError(
                f"{meta_path}: field 'skyradar:samples_per_chirp' is {recorded}, more than a chirp "
                f"interval holds ('core:sample_rate' / 'skyradar:prf_hz' = {samples})"
            )
        samples = recorded
    header = capture.get("core:header_bytes", 0)
    if isinstance(header, bool) or not isinstance(header, int) or header < 0:
        raise InputError(f"{meta_path}: field 'core:header_bytes' must be a whole number >= 0, got {header}")
    sample_bytes = _BYTES_PER_SAMPLE[dtype] * n_rx
    size = data_path.stat().st_size - header
    if size < 0 or size % sample_bytes:
        raise InputError(
            f"{data_path}: {size + header} bytes are not {header} header bytes and whole samples of "
            f"{n_rx} channels of {datatype} ({sample_bytes} bytes each): truncated, or 'core:datatype' / "
            "'core:num_channels' is wrong"
        )
    count = size // sample_bytes
    if "skyradar:sample_count" in glob:
        declared = glob["skyradar:sample_count"]
        if isinstance(declared, bool) or not isinstance(declared, int) or declared != count:
            raise InputError(
                f"{data_path}: holds {count} samples per channel, but field 'skyradar:sample_count' of "
                f"{meta_path.name} is {declared!r}: truncated or overwritten?"
            )
    per_frame = chirps * samples
    if count == 0 or count % per_frame:
        raise InputError(
            f"{data_path}: {count} samples per channel are not whole frames of 'skyradar:chirps_per_frame' "
            f"{chirps} x 'skyradar:samples_per_chirp' {samples} = {per_frame} samples"
        )
    description: dict[str, Any] = {
        "data_file": data_path.name,
        "dtype": dtype,
        "byte_order": byte_order,
        "offset_bytes": header,
        "shape": [count // per_frame, chirps, samples, n_rx],
        "axes": ["frame", "chirp", "sample", "rx"],
        "sample_rate_hz": fs,
        "fc_hz": fc,
        "bandwidth_hz": bandwidth,
        "prf_hz": prf,
        "radar": radar,
    }
    for key in ("scale", "frame_period_s", "frame_times_s"):
        if f"skyradar:{key}" in glob:
            description[key] = glob[f"skyradar:{key}"]
    if "scale" in description:
        _number(meta_path, glob, "skyradar:scale", "sqrt(W) per sample unit")
    return description


def read_sigmf_recording(path: str | Path) -> tuple[AdcFrames, RadarConfig]:
    """Open an FMCW radar's SigMF recording without reading it into memory.

    Parameters
    ----------
    path : str or Path
        ``NAME.sigmf-meta``, ``NAME.sigmf-data`` or the bare ``NAME``.

    Returns
    -------
    frames : AdcFrames
        Frames in (frame, rx, chirp, sample) order, scaled to sqrt(W), with ``frames.times_s`` (s).
    config : RadarConfig
        The radar: sweep from the metadata, chirps per frame as ``n_doppler``.

    Examples
    --------
    >>> import tempfile
    >>> from skyradar.io.recording_writer import write_sigmf_recording
    >>> cfg = RadarConfig.prototype_2022(n_doppler=8)
    >>> adc = np.full((2, 4, 8, cfg.samples_per_chirp), 1 - 2j, np.complex64)
    >>> meta = write_sigmf_recording(Path(tempfile.mkdtemp()) / "radar", adc, cfg, "cf32_le")
    >>> frames, config = read_sigmf_recording(meta)
    >>> frames.shape, config.n_doppler, complex(frames[1][3, 7, 0])
    ((2, 4, 8, 2032), 8, (1-2j))
    """
    path = Path(path)
    meta_path, data_path = sigmf_paths(path)
    meta = _load(meta_path, data_path, path)
    description = _description(meta_path, data_path, meta)
    _validate_schema(meta_path, meta)
    try:
        return open_described(meta_path, description)
    except InputError as exc:  # name the SigMF key a translated field came from
        message = str(exc)
        message = _RADAR_FIELD.sub(lambda m: f"'skyradar:radar.{m.group(1)}'", message)
        for field, key in _RENAMED.items():
            message = message.replace(f"'{field}'", f"'{key}'")
        raise InputError(message) from None


def sigmf_adc_metadata(
    config: RadarConfig,
    n_rx: int,
    samples_per_chirp: int,
    datatype: str,
    sample_count: int,
    scale: float = 1.0,
    times_s: np.ndarray | None = None,
    start_time: str | None = None,
    sha512: str | None = None,
) -> dict[str, Any]:
    """The SigMF metadata (``global``, ``captures``, ``annotations``) of a radar recording.

    Parameters
    ----------
    config : RadarConfig
        The radar; ``n_doppler`` is written as ``skyradar:chirps_per_frame``.
    n_rx, samples_per_chirp, sample_count : int
        Receive channels, samples per chirp, samples per channel in the data file.
    datatype : str
        A key of :data:`SIGMF_DTYPES`.
    scale : float
        sqrt(W) per sample unit.
    times_s : ndarray, optional
        Frame start times, s (default: back-to-back frames).
    start_time : str, optional
        ISO 8601 UTC time of the first sample.
    sha512 : str, optional
        Hash of the data file.

    Returns
    -------
    dict
        JSON-able metadata.

    Examples
    --------
    >>> meta = sigmf_adc_metadata(RadarConfig.prototype_2022(n_doppler=8), 4, 2032, "ci16_le", 65024)
    >>> meta["global"]["core:datatype"], meta["global"]["skyradar:chirps_per_frame"]
    ('ci16_le', 8)
    """
    import sigmf

    sweep = ("fc_hz", "fs_hz", "bandwidth_hz", "prf_hz", "n_doppler")
    glob: dict[str, Any] = {
        "core:version": sigmf.__specification__,
        "core:datatype": datatype,
        "core:sample_rate": config.fs_hz,
        "core:num_channels": n_rx,
        "core:recorder": "skyradar",
        "core:description": "FMCW radar ADC samples, channels interleaved, chirp after chirp",
        "core:extensions": [dict(EXTENSION)],
        "skyradar:bandwidth_hz": config.bandwidth_hz,
        "skyradar:prf_hz": config.prf_hz,
        "skyradar:chirps_per_frame": config.n_doppler,
        "skyradar:samples_per_chirp": samples_per_chirp,
        "skyradar:sample_count": sample_count,
        "skyradar:scale": float(scale),
        "skyradar:radar": {k: v for k, v in config.to_dict().items() if k not in sweep},
    }
    if sha512 is not None:
        glob["core:sha512"] = sha512
    if times_s is not None:
        glob["skyradar:frame_times_s"] = [float(t) for t in times_s]
    capture: dict[str, Any] = {"core:sample_start": 0, "core:frequency": config.fc_hz}
    if start_time is not None:
        capture["core:datetime"] = start_time
    meta = {"global": glob, "captures": [capture], "annotations": []}
    return json.loads(json.dumps(meta, default=float))  # plain Python types
