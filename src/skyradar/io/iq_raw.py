"""Raw IQ files: ``NAME.cf32`` or ``NAME.ci16`` (interleaved little-endian I/Q) with a sidecar.

The sidecar ``NAME.json`` / ``NAME.yaml`` holds ``sample_rate_hz``, ``center_frequency_hz``, optional
``n_samples`` and ``start_time``, ``receiver`` (``latitude``, ``longitude``, ``altitude``) and
``illuminator`` (the ``skyradar:illuminator`` object of :mod:`skyradar.io.sigmf_io`).
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from skyradar.errors import InputError
from skyradar.io.atomic import atomic_path, write_text_atomic
from skyradar.io.iq_recording import (
    DATATYPES,
    IqRecording,
    metadata_illuminator,
    metadata_position,
    positive_number,
)
from skyradar.io.safe_yaml import load_yaml

__all__ = ["RAW_SUFFIXES", "read_raw_iq", "write_raw_iq"]

RAW_SUFFIXES = {".cf32": "cf32_le", ".ci16": "ci16_le", ".cs16": "ci16_le"}


def read_raw_iq(data_path: str | Path, require_illuminator: bool = True) -> IqRecording:
    """Open ``NAME.cf32``/``NAME.ci16`` with its sidecar ``NAME.json``/``.yaml``/``.yml``.

    Parameters
    ----------
    data_path : path
        The sample file; its suffix (``.cf32``, ``.ci16`` or ``.cs16``) sets the datatype.
    require_illuminator : bool
        Refuse a sidecar without the illuminator's position (lat, lon in degrees, alt in m).

    Returns
    -------
    IqRecording
        The samples stay on disk until read.

    Raises
    ------
    InputError
        When the file or its sidecar is missing or unreadable, or a required field is missing or invalid.

    Examples
    --------
    A YAML sidecar; the ``ci16`` codes are divided by 32768 on reading.

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     data = Path(d) / "r.ci16"
    ...     _ = data.write_bytes(np.array([16384, -8192, 0, 32767], "<i2").tobytes())
    ...     _ = data.with_suffix(".yaml").write_text("{sample_rate_hz: 2000000, center_frequency_hz: 1.0e+9, "
    ...         "receiver: {latitude: 52.0, longitude: 5.0, altitude: 10.0}}")
    ...     rec = read_raw_iq(data, require_illuminator=False)
    ...     rec.n_samples, rec.duration_s, rec.read(0, 2).tolist()
    (2, 1e-06, [(0.5-0.25j), 0.999969482421875j])
    >>> read_raw_iq("missing.cf32")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: missing.cf32: no such file
    """
    data_path = Path(data_path)
    if not data_path.exists():
        raise InputError(f"{data_path}: no such file")
    sidecars = [data_path.with_suffix(s) for s in (".json", ".yaml", ".yml")]
    sidecar = next((p for p in sidecars if p.exists()), None)
    if sidecar is None:
        raise InputError(f"{data_path}: no sidecar {data_path.stem}.json or .yaml with sample_rate_hz etc.")
    try:
        text = sidecar.read_text()
        info = json.loads(text) if sidecar.suffix == ".json" else load_yaml(text, sidecar)
    except (OSError, ValueError) as exc:
        raise InputError(f"{sidecar}: cannot read sidecar ({exc})") from None
    except RecursionError:  # JSON nested deeper than the parser's stack
        raise InputError(f"{sidecar}: cannot read sidecar (nested too deeply)") from None
    if not isinstance(info, dict):
        raise InputError(f"{sidecar}: sidecar must be a mapping, got {type(info).__name__}")
    for key in ("sample_rate_hz", "center_frequency_hz"):
        positive_number(str(sidecar), key, info.get(key))
    illum, illum_pos = metadata_illuminator(str(sidecar), info.get("illuminator"), require_illuminator)
    receiver = info.get("receiver")
    fields = {
        **info,
        "receiver_geodetic": metadata_position(str(sidecar), "receiver", receiver),
        "illuminator": illum,
        "illuminator_geodetic": illum_pos,
        "receiver": receiver,
        "datatype_declared_by": f"the file suffix {data_path.suffix!r}",
    }
    return IqRecording(sidecar, data_path, RAW_SUFFIXES[data_path.suffix.lower()], 0, fields)


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
    >>> read_raw_iq(p).read(0, 2).tolist()
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
