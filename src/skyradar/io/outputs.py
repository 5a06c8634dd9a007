"""The output guard: every writing command checks its output path here before any work starts.

Rules (one :class:`~skyradar.errors.InputError` line naming the option, the path and the reason):

- an output never is, contains or lies inside one of the command's inputs (symlinks, ``.`` and
  ``..`` resolved), even with ``--overwrite``;
- a store or file output never is the current folder or one of its parents, ``/`` or the home folder;
- ``NAME.partial`` (a run being written) is never an output;
- an existing path is replaced only when this tool wrote it (a frames store carries the attribute
  ``skyradar_format``, a Parquet table the metadata key ``skyradar_format``, an output folder the
  marker file :data:`FOLDER_MARKER`) or with ``--overwrite``; other existing paths are refused;
- one writer per output: inside a command (:func:`skyradar.io.locks.command_outputs`) a checked
  output is locked until the command ends, so a second command writing it is refused at once.

Replacement happens at the very end (:func:`replace_path`: old aside, new in, old deleted), so an
interrupted run never loses the old output.
"""

from __future__ import annotations

import json
import os
import shutil
import sys
from collections.abc import Iterable
from pathlib import Path

from skyradar.errors import InputError
from skyradar.io.locks import hold_output

__all__ = [
    "FOLDER_MARKER",
    "OVERWRITE_HELP",
    "KINDS",
    "check_output",
    "is_ours",
    "mark_folder",
    "replace_path",
    "check_disk_space",
    "notify",
]

FOLDER_MARKER = ".skyradar-output"
OVERWRITE_HELP = (
    "Replace an existing output that skyradar did not write (never an input). Outputs skyradar "
    "wrote are replaced without it, at the very end of a successful run."
)
KINDS = ("frames store", "table", "file", "folder")
# Free space kept beyond the estimate: other writers, metadata, file-system overhead.
_MARGIN_FRACTION = 0.10
_MARGIN_BYTES = 64 * 2**20


def notify(message: str) -> None:
    """One line to stderr (progress notes that are not errors).

    Parameters
    ----------
    message : str
        The note, printed with a newline and flushed at once.

    Examples
    --------
    >>> import contextlib, io
    >>> err = io.StringIO()
    >>> with contextlib.redirect_stderr(err):
    ...     notify("run.zarr: resuming at chunk 3")
    >>> err.getvalue()
    'run.zarr: resuming at chunk 3\\n'
    """
    print(message, file=sys.stderr, flush=True)


def _resolved(path: str | Path) -> Path:
    return Path(os.path.abspath(Path(path).expanduser())).resolve()


def _is_within(inner: Path, outer: Path) -> bool:
    return inner == outer or outer in inner.parents


def _zarr_attrs(path: Path) -> dict:
    for name, key in (("zarr.json", "attributes"), (".zattrs", None)):
        meta = path / name
        if meta.is_file():
            try:
                data = json.loads(meta.read_text())
            except (OSError, ValueError):
                return {}
            return (data.get(key, {}) if key else data) or {}
    return {}


def _table_format(path: Path) -> str | None:
    try:
        import pyarrow.parquet as pq

        meta = pq.read_schema(path).metadata or {}
        return json.loads(meta.get(b"PANDAS_ATTRS", b"{}")).get("skyradar_format")
    except Exception:  # noqa: BLE001 - anything unreadable is simply not ours
        return None


def is_ours(path: str | Path, kind: str) -> bool:
    """True when ``path`` is a ``kind`` this tool wrote (safe to replace without ``--overwrite``).

    Examples
    --------
    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> is_ours(folder, "folder"), is_ours(mark_folder(folder), "folder")
    (False, True)
    """
    path = Path(path)
    if path.is_symlink():
        return False
    if kind == "frames store":
        return path.is_dir() and "skyradar_format" in _zarr_attrs(path)
    if kind == "table":
        return path.is_file() and _table_format(path) is not None
    if kind == "folder":
        return path.is_dir() and (path / FOLDER_MARKER).is_file()
    return False


def _check_not_input(out: Path, inputs: Iterable[str | Path | None], label: str) -> None:
    for item in inputs:
        if item is None:
            continue
        inp = _resolved(item)
        if _is_within(out, inp):
            what = "is" if out == inp else "is inside"
            raise InputError(f"{label}: {what} the input {item}; choose another output")
        if _is_within(inp, out):
            raise InputError(f"{label}: contains the input {item}; choose another output")


def _check_not_precious(out: Path, label: str, kind: str) -> None:
    if kind == "folder":
        return  # folders are written into, never replaced
    if _is_within(_resolved(Path.cwd()), out):
        raise InputError(f"{label}: is the current folder or one of its parents; name a new path")
    if out == Path(out.anchor) or out == _resolved(Path.home()):
        raise InputError(f"{label}: is the root or home folder; name a new path")


def check_output(
    path: str | Path,
    inputs: Iterable[str | Path | None] = (),
    overwrite: bool = False,
    kind: str = "file",
    option: str = "--output",
) -> Path:
    """Check that ``path`` may be written by a command reading ``inputs``; return it unchanged.

    Parameters
    ----------
    path : path
        The output the command will create (or replace at its very end).
    inputs : iterable of path
        Everything the command reads; ``None`` entries are ignored.
    overwrite : bool
        Allow replacing an existing path this tool did not write (never an input).
    kind : {"frames store", "table", "file", "folder"}
        What the command writes; a "folder" is written into (files of the same name replaced,
        others kept) and gets the :data:`FOLDER_MARKER` file.
    option : str
        The option named in the error (``--output``).

    Inside a command (:func:`skyradar.io.locks.command_outputs`) the output is locked from here until
    the command ends; the checks that do not depend on what is at ``path`` come first, those of an
    existing path after the lock (a second writer learns that another command writes it, not what
    that command's half-written output looks like).

    Examples
    --------
    >>> import tempfile
    >>> d = Path(tempfile.mkdtemp())
    >>> check_output(d / "run.zarr", inputs=[d / "s.yaml"], kind="frames store").name
    'run.zarr'
    >>> check_output(d, inputs=[d / "s.yaml"], kind="frames store")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: --output ...: contains the input .../s.yaml; choose another output
    """
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    path = Path(path)
    label = f"{option} {path}"
    if path.name.endswith((".partial", ".partial.done")):
        raise InputError(f"{label}: a '.partial' name is a run being written, not an output; name a new path")
    for parent in path.absolute().parents:  # a file where a folder must be: refused before any work
        if parent.exists():
            if not parent.is_dir():
                raise InputError(f"{label}: {parent} is a file, not a folder; name another output")
            _check_writable(parent, label)
            if kind != "folder":  # a folder is made under its own name; files go inside it
                _check_name_length(path, parent, label)
            break
    out = _resolved(path)
    _check_not_input(out, inputs, label)
    _check_not_precious(out, label, kind)
    hold_output(path, option)
    if path.exists() or path.is_symlink():
        _check_replaceable(path, label, kind, overwrite)
    return path


# What skyradar adds to an output's name while writing it: ``.NAME.<12 hex>.tmp<suffix>`` for a file
# (skyradar.io.atomic), ``NAME.partial.done`` for a store, ``.NAME.old-<pid>`` for the replaced one.
_TEMPORARY_EXTRA_BYTES = 18


def _check_name_length(path: Path, folder: Path, label: str) -> None:
    """The output's name, and the temporary names skyradar writes it under first, must fit the file
    system's name limit: else the command would fail at its very end, after all its work, naming a
    file the user never gave."""
    if path.name in ("", ".", ".."):
        return
    try:
        limit = os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError):
        limit = 255
    size = len(os.fsencode(path.name))
    extra = _TEMPORARY_EXTRA_BYTES + len(os.fsencode(path.suffix))
    if size + extra > limit:
        raise InputError(
            f"{label}: File name too long: {size} bytes, and skyradar writes it under a temporary name "
            f"{extra} bytes longer; {folder} takes names of at most {limit} bytes: keep it to {limit - extra}"
        )


def _check_writable(folder: Path, label: str) -> None:
    """The nearest existing folder of an output must take a new file: tried, not guessed from mode
    bits (root, ACLs and read-only mounts make those lie)."""
    import tempfile

    try:
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        raise InputError(f"{label}: cannot write in {folder} ({exc.strerror or exc})") from None


def _check_replaceable(path: Path, label: str, kind: str, overwrite: bool) -> None:
    """An existing output may be replaced (or written into) only when skyradar wrote it or --overwrite."""
    if kind in ("table", "file") and path.is_dir() and not path.is_symlink():
        raise InputError(f"{label}: is an existing folder; the output is a file, name a new path")
    if kind == "folder":
        if not path.is_dir():
            raise InputError(f"{label}: exists and is not a folder; name a new path")
        if is_ours(path, kind) or overwrite or not any(path.iterdir()):
            return
        raise InputError(
            f"{label}: folder exists, is not empty and was not written by skyradar "
            f"(no {FOLDER_MARKER}); pass --overwrite to write into it"
        )
    if is_ours(path, kind) or overwrite:
        return
    raise InputError(
        f"{label}: exists and is not a {kind} written by skyradar; pass --overwrite to replace it"
    )


def mark_folder(path: str | Path) -> Path:
    """Create folder ``path`` (if needed) with the marker that says skyradar wrote it; return it.

    Parameters
    ----------
    path : path
        The output folder; missing parents are created, an existing marker is kept as it is.

    Returns
    -------
    Path
        ``path``.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     out = mark_folder(Path(d) / "report" / "figures")
    ...     [p.name for p in out.iterdir()], is_ours(out, "folder"), is_ours(out.parent, "folder")
    (['.skyradar-output'], True, False)
    """
    path = Path(path)
    path.mkdir(parents=True, exist_ok=True)
    marker = path / FOLDER_MARKER
    if not marker.exists():
        marker.write_text("written by skyradar; `--output` may write into this folder again\n")
    return path


def _remove(path: Path) -> None:
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    else:
        path.unlink(missing_ok=True)


def replace_path(new: str | Path, final: str | Path) -> Path:
    """Move ``new`` to ``final``; an existing ``final`` is renamed aside first and deleted last.

    Examples
    --------
    >>> import tempfile
    >>> d = Path(tempfile.mkdtemp())
    >>> _ = (d / "old").write_text("old"), (d / "new").write_text("new")
    >>> replace_path(d / "new", d / "old").read_text(), sorted(p.name for p in d.iterdir())
    ('new', ['old'])
    """
    new, final = Path(new), Path(final)
    aside = None
    if final.exists() or final.is_symlink():
        aside = final.with_name(f".{final.name}.old-{os.getpid()}")
        _remove(aside)  # a leftover of an earlier crash of this very replacement
        final.rename(aside)
    try:
        new.rename(final)
    except OSError:
        if aside is not None:
            aside.rename(final)  # put the old one back: nothing lost
        raise
    if aside is not None:
        _remove(aside)
    return final


def _existing_parent(path: Path) -> Path:
    for candidate in (path, *path.parents):
        if candidate.exists():
            return candidate
    return Path.cwd()


def check_disk_space(path: str | Path, n_bytes: float, what: str) -> None:
    """Refuse to start when ``n_bytes`` (plus a margin) do not fit on the disk of ``path``.

    Examples
    --------
    >>> import tempfile
    >>> check_disk_space(tempfile.gettempdir(), 1e3, "test")
    >>> check_disk_space(tempfile.gettempdir(), 1e30, "test")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: ...: test needs about ... GB free; free space or write elsewhere
    """
    target = _existing_parent(Path(path).expanduser().absolute().parent)
    free = shutil.disk_usage(target).free
    need = n_bytes * (1.0 + _MARGIN_FRACTION) + _MARGIN_BYTES
    if need > free:
        raise InputError(
            f"{path}: {what} needs about {n_bytes / 1e9:.3g} GB (plus a {_MARGIN_FRACTION:.0%} margin), "
            f"{target} has {free / 1e9:.3g} GB free; free space or write elsewhere"
        )
