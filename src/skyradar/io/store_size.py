"""How many bytes a frames store takes, and whether it fits on the disk before a job starts.

The ratios are measured, not assumed: thermal noise does not compress, so a lossless codec on
complex64 pixels saves only 6-8 %; int16 codes (:mod:`skyradar.io.cint16`) of noise-only pixels
are small numbers and compress to about 0.4 of their raw size.
"""

from __future__ import annotations

from pathlib import Path

from skyradar.config import RadarConfig
from skyradar.io.outputs import check_disk_space

__all__ = ["COMPRESSION_RATIO", "CINT16_COMPRESSION_RATIO", "store_bytes", "check_store_space"]


# Measured stored/raw size of ``iq`` per codec: 16 prototype frames (333 x 250 x 4) of
# circuit_three_intruders.yaml, fractal terrain, thermal noise on (`skyradar simulate --compress C`,
# size of chunk 0). Noise makes complex64 nearly incompressible: lossless codecs save 6-9 %.
COMPRESSION_RATIO = {"none": 1.0, "zstd": 0.94, "blosc": 0.92}
# The same for cint16 codes + scales (raw 4 bytes per pixel + 4 per frame, range and rx), same 16
# frames but at t = 36 s (intruders in view): measured 0.388 (zstd) and 0.451 (blosc), i.e. 0.52
# and 0.60 MB per frame against 2.66 MB raw complex64; rounded up for the disk-space check.
CINT16_COMPRESSION_RATIO = {"none": 1.0, "zstd": 0.40, "blosc": 0.46}


def store_bytes(
    config: RadarConfig, n_frames: int, compressor: str = "none", precision: str = "complex64"
) -> float:
    """Estimated size of a frames store's pixels, bytes, times the codec's measured ratio.

    complex64: 8 bytes per pixel. cint16: 4 bytes per pixel plus a 4-byte scale per frame,
    range bin and rx (:mod:`skyradar.io.cint16`).

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> store_bytes(cfg, 1) == 333 * 250 * 4 * 8
    True
    >>> store_bytes(cfg, 1, precision="cint16") == 333 * 250 * 4 * 4 + 333 * 4 * 4
    True
    """
    pixels = float(n_frames) * config.n_range * config.n_doppler * config.n_rx
    if precision == "cint16":
        raw = pixels * 4.0 + float(n_frames) * config.n_range * config.n_rx * 4.0
        return raw * CINT16_COMPRESSION_RATIO.get(compressor, 1.0)
    return pixels * 8.0 * COMPRESSION_RATIO.get(compressor, 1.0)


def check_store_space(
    path: str | Path,
    config: RadarConfig,
    n_frames: int,
    chunk_frames: int,
    compressor: str = "none",
    precision: str = "complex64",
) -> None:
    """Refuse to start when the store's unwritten chunks do not fit on the disk of ``path``.

    Chunks already marked done in ``NAME.partial.done`` (a run being resumed) are not counted; each
    unwritten chunk counts whole, ``chunk_frames`` frames.

    Parameters
    ----------
    path : path
        The store's final name.
    config : RadarConfig
        Sets the pixels per frame.
    n_frames : int
        Frames in the run.
    chunk_frames : int
        Frames per chunk along time.
    compressor : {"none", "zstd", "blosc"}
    precision : {"complex64", "cint16"}
        See :func:`store_bytes`.

    Raises
    ------
    InputError
        When the estimate (plus a margin) exceeds the free space.

    Examples
    --------
    Ten prototype frames (27 MB) fit; 10^12 frames (2.66e9 GB) do not.

    >>> import tempfile
    >>> cfg = RadarConfig.prototype_2022()
    >>> with tempfile.TemporaryDirectory() as d:
    ...     check_store_space(Path(d) / "run.zarr", cfg, 10, 4)
    ...     check_store_space(Path(d) / "run.zarr", cfg, 10**12, 16)
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: .../run.zarr: a 1000000000000-frame complex64 store needs about 2.66e+09 GB...
    """
    path = Path(path)
    chunk_frames = max(1, min(int(chunk_frames), int(n_frames)))  # a chunk is at most the whole run
    n_chunks = max(1, -(-int(n_frames) // chunk_frames))
    marks = path.with_name(path.name + ".partial.done")
    done = sum(1 for p in marks.iterdir() if p.name.isdigit()) if marks.is_dir() else 0
    # Unwritten chunks, each stored whole (the last one is padded to chunk_frames).
    padded = max(0, n_chunks - done) * chunk_frames
    need = store_bytes(config, padded, compressor, precision)
    check_disk_space(path, need, f"a {n_frames}-frame {precision} store")
