"""The frames store of several radar heads: one Zarr group per head.

A run simulated with several radar heads (a scenario's ``radars:`` list) is one Zarr store whose
root holds only attributes (``skyradar_heads``: the JSON list of head names in the scenario's
order, plus the job's fingerprint, precision and completion mark) and one group per head, named
after it. Each group is an ordinary single-head frames Dataset (``iq`` on (time, range, doppler,
rx), the head's ``radar_config`` with its mount and lever arm, own-ship truth, and the intruder
truth as that head sees it), so every reader of single-head runs reads a head unchanged:
``open_frames(path, head="left")``. Groups rather than a ``radar`` dimension because heads may
differ in hardware (a per-head ``radar:`` override changes the image size) and the per-head
truth (angles, SNR, visibility) keeps its (time, target) shape. A store of one head is written
exactly as before (no groups).

Writing is chunk by chunk along time as for one head: a chunk is marked done only when every
head's frames of it are in, so an interrupted run resumes where it stopped.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path

import xarray as xr

from skyradar.errors import InputError

__all__ = ["HEADS_ATTR", "store_heads", "open_head", "head_templates", "write_heads_root"]

HEADS_ATTR = "skyradar_heads"


def head_templates(template: xr.Dataset | Mapping[str, xr.Dataset]) -> tuple[list, list[xr.Dataset]]:
    """(group names, templates) of a writer's template: ([None], [ds]) for one head at the root.

    Examples
    --------
    >>> head_templates(xr.Dataset())[0]
    [None]
    """
    if isinstance(template, xr.Dataset):
        return [None], [template]
    if not template:
        raise ValueError("a frames store needs at least one radar head")
    return list(template), list(template.values())


def write_heads_root(partial: Path, attrs: dict, groups: list) -> None:
    """Create the store's root: the head names and the job's attributes (several heads only).

    Parameters
    ----------
    partial : Path
        The store being written.
    attrs : dict
        The job's root attributes (fingerprint, precision).
    groups : list
        Head names from :func:`head_templates`; ``[None]`` (one head at the root) writes nothing.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     write_heads_root(Path(d) / "one.zarr", {}, [None])
    ...     write_heads_root(Path(d) / "two.zarr", {"skyradar_fingerprint": "f"}, ["left", "right"])
    ...     [p.name for p in Path(d).iterdir()], store_heads(Path(d) / "two.zarr")
    (['two.zarr'], ['left', 'right'])
    """
    if groups != [None]:
        root = xr.Dataset(attrs=dict(attrs) | {HEADS_ATTR: json.dumps(groups)})
        root.to_zarr(partial, mode="w", consolidated=False)


def store_heads(path: str | Path) -> list[str] | None:
    """Head names of a multi-head store (None for a single-head store).

    Parameters
    ----------
    path : path
        A frames store; anything that is not a readable Zarr group counts as single-head.

    Returns
    -------
    list of str or None
        The head names in the scenario's order.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = xr.Dataset({"a": ("x", [1])}).to_zarr(Path(d) / "one.zarr", consolidated=False)
    ...     write_heads_root(Path(d) / "two.zarr", {}, ["left", "right"])
    ...     store_heads(Path(d) / "one.zarr"), store_heads(Path(d) / "two.zarr"), store_heads(d + "/none")
    (None, ['left', 'right'], None)
    """
    import zarr

    try:
        text = zarr.open_group(Path(path), mode="r").attrs.get(HEADS_ATTR)
    except Exception:  # noqa: BLE001 - not a readable Zarr group: not a multi-head store
        return None
    return None if text is None else [str(h) for h in json.loads(str(text))]


def mark_heads_complete(partial: Path, groups: list) -> None:
    """Set ``skyradar_complete`` on every head's group (the root is marked by the writer)."""
    import zarr

    for group in groups:
        if group is not None:
            zarr.open_group(partial, path=group, mode="r+").attrs["skyradar_complete"] = True


def open_head(path: Path, root: xr.Dataset, head: int | str | None) -> xr.Dataset:
    """The single-head Dataset of ``head`` (name or index; None: the first) of the store at ``path``.

    Parameters
    ----------
    path : Path
        The store.
    root : xarray.Dataset
        The store opened at its root; a single-head store is returned as it is (``head`` may then
        be None, 0 or the name of the one head it holds, ``radar``).
    head : int or str or None
        Head name or index (negative counts from the end).

    Returns
    -------
    xarray.Dataset
        The head's Dataset with the job's marks from the root and the attributes ``radar_head``
        (its name) and ``radar_heads`` (JSON list of all names).

    Raises
    ------
    InputError
        For an unknown head name or an index out of range.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     path = Path(d) / "run.zarr"
    ...     write_heads_root(path, {"skyradar_complete": True}, ["left", "right"])
    ...     for i, name in enumerate(["left", "right"]):
    ...         _ = xr.Dataset({"a": ("x", [i])}).to_zarr(path, group=name, mode="w", consolidated=False)
    ...     root = xr.open_zarr(path, consolidated=False)
    ...     ds = open_head(path, root, -1)
    ...     ds.attrs["radar_head"], int(ds["a"][0]), ds.attrs["skyradar_complete"]
    ('right', 1, True)
    >>> open_head(Path("run.zarr"), xr.Dataset(), "left")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: run.zarr: field 'head': 'left' unknown; this run has one radar head ('radar')
    """
    text = root.attrs.get(HEADS_ATTR)
    if text is None:
        if head not in (None, 0, "radar"):
            raise InputError(f"{path}: field 'head': {head!r} unknown; this run has one radar head ('radar')")
        return root
    names = [str(h) for h in json.loads(text)]
    if head is None:
        head = 0
    if isinstance(head, str) and head not in names:
        raise InputError(f"{path}: field 'head': {head!r} unknown; the run's radar heads are {names}")
    if not isinstance(head, str) and not -len(names) <= int(head) < len(names):
        raise InputError(f"{path}: field 'head': index {head} out of range; the run's heads are {names}")
    name = head if isinstance(head, str) else names[int(head)]
    ds = xr.open_zarr(path, group=name, consolidated=False)
    for key in ("skyradar_complete", "skyradar_fingerprint"):  # the job's marks live at the root
        if key in root.attrs:
            ds.attrs[key] = root.attrs[key]
    return ds.assign_attrs(radar_head=name, radar_heads=json.dumps(names))
