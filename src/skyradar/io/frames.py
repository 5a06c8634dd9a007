"""Frames as labelled xarray Datasets, and their Zarr store.

A run is one Dataset with dims ``(time, range, doppler, rx)`` holding complex64 ``iq`` (pixel
units: ``|iq|^2`` is received power in W, thermal noise power per pixel is
``RadarConfig.noise_power_w``), coordinates in SI units, the RadarConfig as a JSON attribute,
and, when simulated, own-ship truth on ``time`` and intruder truth on ``(time, target)``.

Writers never leave a half-written run under the final name: :class:`FrameStoreWriter` writes
into ``NAME.partial`` chunk by chunk along time, marks each finished chunk, and renames the
store when the last chunk is in (done marks sit in ``NAME.partial.done``). Re-running with the
same fingerprint resumes: finished chunks are skipped. A finished store carries the attribute
``skyradar_complete``; :func:`open_frames` refuses ``.partial`` and unfinished stores.
"""

from __future__ import annotations

import shutil
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.io import cint16
from skyradar.io import frames_heads as heads
from skyradar.io.checks import check_frame_times
from skyradar.io.frames_model import (
    DEFAULT_START_TIME,
    IQ_LONG_NAME,
    OWNSHIP_VARS,
    TARGET_VARS,
    axis_coordinates,
    format_start_time,
    frame_times_s,
    parse_start_time,
    radar_attrs,
    variable_attrs,
)
from skyradar.io.outputs import check_output, is_ours, notify, replace_path
from skyradar.io.store_size import check_store_space, store_bytes

__all__ = [
    "OWNSHIP_VARS",
    "TARGET_VARS",
    "frames_dataset",
    "frame_times_s",
    "radar_config_of",
    "open_frames",
    "FrameStoreWriter",
    "COMPRESSORS",
    "PRECISIONS",
    "store_bytes",
    "check_store_space",
]

# Lossless codecs for ``iq`` (Zarr v3). "none" stores raw complex64 (8 bytes per pixel).
COMPRESSORS = ("none", "zstd", "blosc")
# Pixel formats: complex64 (exact), or cint16 (int16 I/Q with a scale per frame, range bin and rx;
# see :mod:`skyradar.io.cint16` for the error bound).
PRECISIONS = cint16.PRECISIONS


def _add_truth(data_vars: dict, coords: dict, ownship, targets, target_names) -> None:
    """Own-ship truth on ``time`` and intruder truth on (``time``, ``target``), with CF attributes."""
    for name, values in (ownship or {}).items():
        units, desc = OWNSHIP_VARS[name]
        data_vars[name] = ("time", np.asarray(values), variable_attrs(name, units, desc))
    if not targets:
        return
    for name, values in targets.items():
        units, desc = TARGET_VARS[name]
        data_vars[name] = (("time", "target"), np.asarray(values), variable_attrs(name, units, desc))
    n_targets = np.asarray(next(iter(targets.values()))).shape[1]
    coords["target"] = (
        "target",
        np.array(target_names or [f"T{i}" for i in range(n_targets)], dtype=object),
        {"long_name": "intruder name"},
    )


def frames_dataset(
    iq: Any,
    times_s: np.ndarray,
    config: RadarConfig,
    ownship: Mapping[str, np.ndarray] | None = None,
    targets: Mapping[str, np.ndarray] | None = None,
    target_names: list[str] | None = None,
    attrs: Mapping[str, Any] | None = None,
    start_time: Any = None,
) -> xr.Dataset:
    """Wrap a (time, range, doppler, rx) cube and truth arrays into the frames Dataset.

    The data model (absolute UTC ``time`` plus elapsed ``time_s``, CF attributes, ``radar_*``
    attributes) is described in :mod:`skyradar.io.frames_model`; read frame times with
    :func:`frame_times_s`.

    Parameters
    ----------
    iq : array_like, shape (n_time, n_range, n_doppler, n_channels)
        Complex pixels (numpy or dask), each frame ``config.frame_shape``; for a time-division MIMO
        radar the ``rx`` axis holds the virtual channels and ``doppler`` one transmitter's bins.
    times_s : ndarray, shape (n_time,)
        Frame times, s.
    config : RadarConfig
        Stored as the ``radar_config`` attribute.
    ownship, targets : mapping, optional
        Truth arrays keyed by the names in ``OWNSHIP_VARS`` / ``TARGET_VARS``.
    target_names : list of str, optional
        One name per intruder (the ``target`` coordinate).
    attrs : mapping, optional
        Extra dataset attributes (a ``start_time`` here is used when the argument is not given).
    start_time : str or datetime64, optional
        ISO 8601 UTC instant of ``times_s = 0``; default ``DEFAULT_START_TIME`` (1970-01-01T00:00:00Z).

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022()
    >>> cube = np.zeros((2, cfg.n_range, cfg.n_doppler, cfg.n_rx), np.complex64)
    >>> frames_dataset(cube, np.array([0.0, 0.1]), cfg).iq.dims
    ('time', 'range', 'doppler', 'rx')
    """
    expected = (len(times_s), *config.frame_shape)
    if tuple(iq.shape) != expected:
        raise InputError(
            f"frames: iq has shape {tuple(iq.shape)}, expected (time, range, doppler, rx) = {expected}"
        )
    data_vars: dict[str, Any] = {
        "iq": (("time", "range", "doppler", "rx"), iq, {"units": "W^0.5", "long_name": IQ_LONG_NAME}),
    }
    if start_time is None:
        start_time = (attrs or {}).get("start_time")
    start = parse_start_time(DEFAULT_START_TIME if start_time is None else start_time, "frames")
    coords = axis_coordinates(config, times_s, start)
    _add_truth(data_vars, coords, ownship, targets, target_names)
    all_attrs = {"Conventions": "CF-1.10", "radar_config": config.to_json(), "skyradar_format": "frames/2"}
    all_attrs |= radar_attrs(config) | dict(attrs or {}) | {"start_time": format_start_time(start)}
    return xr.Dataset(data_vars, coords=coords, attrs=all_attrs)


def _open_zarr(path: Path) -> xr.Dataset:
    # No consolidated metadata: it is not part of Zarr v3, and stores are written chunk by chunk.
    return xr.open_zarr(path, consolidated=False)


def radar_config_of(ds: xr.Dataset, source: str = "frames") -> RadarConfig:
    """The RadarConfig stored with a frames Dataset.

    Parameters
    ----------
    ds : xarray.Dataset
        A frames Dataset (its ``radar_config`` attribute holds the configuration as JSON).
    source : str
        Names the store in error messages.

    Returns
    -------
    RadarConfig

    Raises
    ------
    InputError
        When the attribute is missing or does not describe a valid RadarConfig.

    Examples
    --------
    >>> cfg = RadarConfig.prototype_2022(n_doppler=4, range_limit_m=100.0)
    >>> ds = frames_dataset(np.zeros((1, cfg.n_range, 4, cfg.n_rx), np.complex64), np.zeros(1), cfg)
    >>> radar_config_of(ds) == cfg, radar_config_of(ds).n_doppler
    (True, 4)
    >>> radar_config_of(xr.Dataset(), "run.zarr")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: run.zarr: no 'radar_config' attribute; not a skyradar frames store
    """
    text = ds.attrs.get("radar_config")
    if text is None:
        raise InputError(f"{source}: no 'radar_config' attribute; not a skyradar frames store")
    try:
        return RadarConfig.from_json(text)
    except InputError as exc:  # name the store: "radar.x ..." alone does not say which file
        raise InputError(f"{source}: attribute 'radar_config': {exc}") from None


def open_frames(path: str | Path, head: int | str | None = None) -> xr.Dataset:
    """Open a frames store (a Zarr directory) and check it is usable.

    A store of several radar heads (:mod:`skyradar.io.frames_heads`) opens as the single-head
    Dataset of ``head`` (name or index; default the first head). Stores written before absolute
    time (float ``time``, no ``start_time``) still open; :func:`frame_times_s` reads their elapsed
    seconds.

    Parameters
    ----------
    path : path
        The store (a Zarr directory); a ``.partial`` name is refused.
    head : int or str, optional
        Radar head to open in a store of several heads.

    Returns
    -------
    xarray.Dataset
        Lazy frames Dataset with complex64 ``iq`` (cint16 stores are decoded).

    Raises
    ------
    InputError
        Naming the file when it is missing, not a directory, unfinished, empty or inconsistent with
        its own RadarConfig.

    Examples
    --------
    >>> import tempfile, dask.array as da
    >>> cfg = RadarConfig.prototype_2022(n_doppler=4, range_limit_m=100.0)
    >>> iq = np.full((2, cfg.n_range, 4, cfg.n_rx), 1 - 2j, np.complex64)
    >>> template = frames_dataset(da.zeros(iq.shape, dtype=np.complex64), np.array([0.0, 0.1]), cfg)
    >>> with tempfile.TemporaryDirectory() as d:
    ...     writer = FrameStoreWriter(Path(d) / "run.zarr", template, 2, "demo")
    ...     writer.write_chunk(0, iq)
    ...     ds = open_frames(writer.close())
    ...     ds.iq.shape, bool((ds.iq.values == iq).all()), frame_times_s(ds).tolist()
    ((2, 6, 4, 4), True, [0.0, 0.1])
    >>> open_frames("missing.zarr")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: missing.zarr: no such run
    """
    path = Path(path)
    if path.name.endswith(".partial"):
        raise InputError(
            f"{path}: an unfinished run (still being written, or interrupted); rerun the command that "
            f"writes {path.name.removesuffix('.partial')} to resume it"
        )
    if not path.exists() and path.is_symlink():
        raise InputError(f"{path}: a symbolic link that leads nowhere (a loop, or its target is missing)")
    if not path.exists():
        partial = path.with_name(path.name + ".partial")
        hint = f" (an unfinished run is at {partial}; rerun to resume)" if partial.exists() else ""
        raise InputError(f"{path}: no such run{hint}")
    if not path.is_dir():  # NetCDF cannot hold complex64 iq with the engines we ship: Zarr only
        raise InputError(f"{path}: not a frames store (a frames run is a Zarr directory)")
    try:
        ds = _open_zarr(path)
    except Exception as exc:  # noqa: BLE001 - any reader failure becomes one clear line
        raise InputError(f"{path}: cannot open as a frames store ({type(exc).__name__}: {exc})") from exc
    ds = cint16.decode(heads.open_head(path, ds, head))  # cint16 reads as complex64 iq like any other
    if "skyradar_fingerprint" in ds.attrs and not ds.attrs.get("skyradar_complete"):
        raise InputError(
            f"{path}: unfinished run (no 'skyradar_complete' attribute: interrupted, or written by an "
            "older skyradar); rerun the command that wrote it"
        )
    if "iq" not in ds:
        raise InputError(f"{path}: missing variable 'iq'")
    config = radar_config_of(ds, str(path))
    if ds.sizes.get("time", 0) == 0:
        raise InputError(f"{path}: empty run (0 frames)")
    check_frame_times(frame_times_s(ds), path)
    if ds.sizes.get("rx") != config.n_virtual:
        raise InputError(
            f"{path}: field 'rx' has {ds.sizes.get('rx')} channels, radar_config has {config.n_virtual}"
        )
    for dim, n in (("range", config.n_range), ("doppler", config.n_doppler_per_tx)):
        if ds.sizes.get(dim) != n:
            raise InputError(f"{path}: dimension '{dim}' is {ds.sizes.get(dim)}, radar_config needs {n}")
    return ds


class FrameStoreWriter:
    """Write a frames Dataset to Zarr chunk by chunk along time, resumably and atomically.

    Parameters
    ----------
    path : path
        Final store name; work happens in ``path + ".partial"`` until :meth:`close`.
    template : xr.Dataset or dict of str to xr.Dataset
        The full Dataset with ``iq`` as a lazy (dask) array; every other variable is written
        at creation. Several radar heads: {head name: Dataset}, one Zarr group each.
    chunk_frames : int
        Frames per chunk along time.
    fingerprint : str
        Identifies the job (inputs, options, chunking, package version); a partial store with
        another fingerprint is our own stale run: it is discarded (said on stderr), not resumed.
    overwrite : bool
        Allow replacing an existing ``path`` that skyradar did not write (see :mod:`skyradar.io.outputs`).
    inputs : iterable of path
        The job's inputs: the output may not be, contain or lie inside any of them.
    compressor : {"none", "zstd", "blosc"}
        Lossless codec for ``iq`` (see :data:`COMPRESSORS`).
    precision : {"complex64", "cint16"}
        Pixel format (see :data:`PRECISIONS`); readers see complex64 ``iq`` either way.

    Examples
    --------
    Three frames in chunks of two: the store appears under its final name only at :meth:`close`.

    >>> import tempfile, dask.array as da
    >>> cfg = RadarConfig.prototype_2022(n_doppler=4, range_limit_m=100.0)
    >>> iq = (1 - 2j) * np.arange(3 * cfg.n_range * 4 * cfg.n_rx).reshape(3, cfg.n_range, 4, cfg.n_rx)
    >>> template = frames_dataset(da.zeros(iq.shape, dtype=np.complex64), np.array([0.0, 0.1, 0.2]), cfg)
    >>> with tempfile.TemporaryDirectory() as d:
    ...     writer = FrameStoreWriter(Path(d) / "run.zarr", template, 2, "demo")
    ...     for index in writer.pending_chunks():
    ...         writer.write_chunk(index, iq[writer.chunk_slice(index)])
    ...     names_before = sorted(p.name for p in Path(d).iterdir())
    ...     ds = open_frames(writer.close())
    ...     names_before, [p.name for p in Path(d).iterdir()], bool((ds.iq.values == iq).all())
    (['run.zarr.partial', 'run.zarr.partial.done'], ['run.zarr'], True)
    """

    def __init__(
        self,
        path: str | Path,
        template: xr.Dataset | dict[str, xr.Dataset],
        chunk_frames: int,
        fingerprint: str,
        overwrite: bool = False,
        inputs: tuple = (),
        compressor: str = "none",
        precision: str = "complex64",
    ) -> None:
        if precision not in PRECISIONS:
            raise InputError(f"--precision: must be one of {', '.join(PRECISIONS)}, got {precision!r}")
        self.path = Path(path)
        self.precision = precision
        check_output(self.path, inputs, overwrite, kind="frames store")
        self.overwrite = overwrite
        self.partial = self.path.with_name(self.path.name + ".partial")
        self.chunk_frames = int(chunk_frames)
        self.groups, templates = heads.head_templates(template)  # groups [None]: one head, the root
        self.n_frames = templates[0].sizes["time"]
        self.n_chunks = -(-self.n_frames // self.chunk_frames)
        # Done marks live beside the store: zarr must not find foreign files inside it.
        self._marks = self.partial.with_name(self.partial.name + ".done")
        # The chunk layout, codec and package version are part of every job: resuming across them
        # would mix layouts or leave chunks unwritten (zeros).
        fingerprint = f"{fingerprint}-c{self.chunk_frames}-{compressor}-{precision}-v{_version()}"
        if self.partial.exists() or self.partial.is_symlink():
            self._check_partial_is_ours()
            on_disk = self._fingerprint_on_disk()
            if on_disk != fingerprint:
                notify(
                    f"{self.partial}: discarding an unfinished run of other inputs or options "
                    f"(fingerprint {on_disk} != {fingerprint}); starting afresh"
                )
                shutil.rmtree(self.partial)
                self._remove_marks()
        if not self.partial.exists():
            self._remove_marks()
            attrs = {"skyradar_fingerprint": fingerprint, "skyradar_precision": precision}
            heads.write_heads_root(self.partial, attrs, self.groups)  # several heads: names at the root
            for group, one in zip(self.groups, templates, strict=True):
                self._create(one.assign_attrs(attrs), group, compressor)
            self._marks.mkdir()
        self._marks.mkdir(exist_ok=True)

    def _create(self, template: xr.Dataset, group: str | None, compressor: str) -> None:
        if self.precision == "cint16":
            template, encoding = cint16.encode_template(template, self.chunk_frames)
            encoding["iq_int16"].update(_codec(compressor, typesize=2))
            encoding["iq_scale"].update(_codec(compressor))
        else:
            chunks = (self.chunk_frames, *template.iq.shape[1:])
            encoding = {"iq": {"chunks": chunks, **_codec(compressor)}}
        template.to_zarr(
            self.partial, group=group, compute=False, encoding=encoding, mode="w", consolidated=False
        )

    def _check_partial_is_ours(self) -> None:
        marked = is_ours(self.partial, "frames store") or self._marks.is_dir()
        ours = marked and not self.partial.is_symlink()
        if not ours:
            raise InputError(
                f"{self.partial}: exists and is not an unfinished skyradar run; move it away or choose "
                "another output"
            )

    def _remove_marks(self) -> None:
        if not (self._marks.exists() or self._marks.is_symlink()):
            return
        if (
            self._marks.is_symlink()
            or not self._marks.is_dir()
            or any(not p.name.isdigit() for p in self._marks.iterdir())
        ):
            raise InputError(f"{self._marks}: exists and is not skyradar's chunk marks; move it away")
        shutil.rmtree(self._marks)

    @classmethod
    def attach(
        cls, partial: str | Path, chunk_frames: int, n_frames: int, precision: str | None = None
    ) -> FrameStoreWriter:
        """A writer for an existing ``.partial`` store (used by workers that write their own chunks).

        ``precision`` defaults to the one recorded in the store.
        """
        self = cls.__new__(cls)
        self.partial = Path(partial)
        if precision is None:
            import zarr

            precision = str(
                zarr.open_group(self.partial, mode="r").attrs.get("skyradar_precision", "complex64")
            )
        self.precision = precision
        self.groups = heads.store_heads(self.partial) or [None]
        self.path = self.partial.with_name(self.partial.name.removesuffix(".partial"))
        self.chunk_frames, self.n_frames = int(chunk_frames), int(n_frames)
        self.n_chunks = -(-self.n_frames // self.chunk_frames)
        self._marks = self.partial.with_name(self.partial.name + ".done")
        return self

    def _fingerprint_on_disk(self) -> str | None:
        try:
            return xr.open_zarr(self.partial, consolidated=False).attrs.get("skyradar_fingerprint")
        except Exception:  # noqa: BLE001 - an unreadable partial store is simply redone
            return None

    def chunk_slice(self, index: int) -> slice:
        return slice(index * self.chunk_frames, min((index + 1) * self.chunk_frames, self.n_frames))

    def pending_chunks(self) -> list[int]:
        """Chunk indices not yet written (all of them on a fresh store)."""
        return [i for i in range(self.n_chunks) if not (self._marks / str(i)).exists()]

    def write_chunk(self, index: int, iq: np.ndarray | Mapping[str, np.ndarray]) -> None:
        """Write frames of chunk ``index`` ((n, range, doppler, rx); heads: {name: frames}); mark it done."""
        for group, cube in (iq if isinstance(iq, Mapping) else {None: iq}).items():
            self._write_piece(self.chunk_slice(index), cube, group)
        (self._marks / str(index)).touch()

    def _write_piece(self, sl: slice, iq: np.ndarray, group: str | None) -> None:
        dims = ("time", "range", "doppler", "rx")
        region = {"time": sl, "range": slice(None), "doppler": slice(None), "rx": slice(None)}
        if self.precision == "cint16":
            codes, scale = cint16.encode(np.asarray(iq))
            variables = {
                "iq_int16": ((*dims, "iq_part"), codes),
                "iq_scale": (("time", "range", "rx"), scale),
            }
            region["iq_part"] = slice(None)
        else:
            variables = {"iq": (dims, iq.astype(np.complex64, copy=False))}
        xr.Dataset(variables).to_zarr(self.partial, group=group, region=region, consolidated=False)

    def close(self) -> Path:
        """Mark the store complete and move it to its final name.

        An older run of that name is renamed aside first and deleted only once the new one is in
        place; a path skyradar did not write is replaced only with ``overwrite``.
        """
        import zarr

        missing = self.pending_chunks()
        if missing:
            raise RuntimeError(f"{self.partial}: chunks {missing[:5]} not written; cannot finalise")
        # Checked again: something may have appeared at the final name while we were working.
        check_output(self.path, (), self.overwrite, kind="frames store")
        zarr.open_group(self.partial, mode="r+").attrs["skyradar_complete"] = True
        heads.mark_heads_complete(self.partial, self.groups)
        replace_path(self.partial, self.path)
        shutil.rmtree(self._marks)
        return self.path


def _version() -> str:
    from skyradar import __version__

    return __version__


def _codec(compressor: str, typesize: int = 4) -> dict[str, Any]:
    """Zarr v3 encoding for pixels: raw, zstd, or blosc-zstd with byte shuffle (element size ``typesize``)."""
    from zarr.codecs import BloscCodec, ZstdCodec

    if compressor == "none":
        return {"compressors": None}
    if compressor == "zstd":
        return {"compressors": [ZstdCodec(level=3)]}
    if compressor == "blosc":
        return {"compressors": [BloscCodec(cname="zstd", clevel=3, shuffle="shuffle", typesize=typesize)]}
    raise InputError(f"--compress: must be one of {', '.join(COMPRESSORS)}, got {compressor!r}")
