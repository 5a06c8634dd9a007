"""One writer per output: an exclusive, OS-level lock held while a command writes a path.

Two commands writing the same output at once interleave their chunks and attributes: one of them can
report success for a store the other half overwrote. The lock is an advisory ``flock`` on a lock file
beside the output (``.NAME.lock``), so a second writer is refused at once with one line. The operating
system releases the lock when the holder exits, however it exits (``kill -9`` included), so a lock
file left behind by a killed command blocks nobody: the next writer takes it and removes it when done.

Two ways to hold it:

- :func:`command_outputs` around a whole command (the entry point :func:`skyradar.cli.main` opens
  it): every output that :func:`skyradar.io.outputs.check_output` passes inside it is locked there,
  before any work, and stays locked until the command has returned, that is after its output is
  renamed into place. Every writing command checks its outputs, so every one of them locks.
- :func:`exclusive_output` around one write, for library callers (``simulate_to_zarr``).

A lock this process already holds is not taken again: the checks of one command name the same
output several times (the command, then the store writer, then the final rename).
"""

from __future__ import annotations

import fcntl
import hashlib
import os
from collections.abc import Iterator
from contextlib import ExitStack, contextmanager
from pathlib import Path

from skyradar.errors import InputError

__all__ = ["command_outputs", "exclusive_output", "hold_output", "lock_path"]

_NAME_MAX = 255  # bytes in a file name on the usual file systems (ext4, XFS, btrfs, APFS)
_ATTEMPTS = 100  # a lock file removed between our open and our lock is opened again, this many times
# Lock file (absolute, folder resolved) -> open descriptor, for every lock this process holds. A forked
# child inherits the descriptors together with this table, and the locks stay shared with the parent.
_HELD: dict[str, int] = {}
# The command scope: (process id, stack that releases its locks); None outside a command.
_SCOPE: tuple[int, ExitStack] | None = None


def lock_path(path: str | Path) -> Path:
    """The lock file of output ``path``: ``.NAME.lock`` in the same folder.

    ``.``, ``..`` and the like are named by the folder they mean; a name too long for another six
    characters gets ``.skyradar-HASH.lock``.

    Examples
    --------
    >>> lock_path("out/run.zarr").as_posix()
    'out/.run.zarr.lock'
    >>> lock_path("out/..") == lock_path(Path.cwd())
    True
    """
    path = Path(path)
    if path.name in ("", ".", ".."):
        path = Path(os.path.abspath(path))
    if not path.name:  # the root folder: its lock lies inside it
        return path / ".skyradar-output.lock"
    name = f".{path.name}.lock"
    if len(os.fsencode(name)) > _NAME_MAX:  # a long output name keeps a lock name the file system takes
        name = f".skyradar-{hashlib.sha256(os.fsencode(path.name)).hexdigest()[:32]}.lock"
    return path.with_name(name)


def _key(lock: Path) -> str:
    return os.path.join(os.path.realpath(os.path.abspath(lock.parent)), lock.name)


def _missing_folders(folder: Path) -> list[Path]:
    """The folders of ``folder`` and its parents that do not exist yet, innermost first."""
    missing = []
    for candidate in (folder, *folder.parents):
        if candidate.exists():
            break
        missing.append(candidate)
    return missing


def _acquire(path: Path, lock: Path, option: str) -> int:
    """An open descriptor holding the exclusive lock of ``lock``; :class:`InputError` when taken."""
    for _ in range(_ATTEMPTS):
        lock.parent.mkdir(parents=True, exist_ok=True)
        try:
            fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
        except FileNotFoundError:  # a holder releasing its lock removed the folder it had made
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise InputError(
                f"{option} {path}: another skyradar command is writing it now; wait for it to finish "
                "or name another output"
            ) from None
        try:  # the holder before us may have removed the file we locked: lock the one that is there
            if os.fstat(fd).st_ino == os.stat(lock).st_ino:
                return fd
        except FileNotFoundError:
            pass
        os.close(fd)
    raise InputError(f"{option} {path}: its lock file {lock} keeps being removed; retry")


def _release(lock: Path, fd: int, made: list[Path]) -> None:
    """Remove the lock file, then the folders the lock made when they are still empty, and unlock."""
    try:
        lock.unlink(missing_ok=True)
        for folder in made:  # a failed command leaves no empty folder that only the lock needed
            try:
                folder.rmdir()
            except OSError:
                break
    finally:
        os.close(fd)


@contextmanager
def exclusive_output(path: str | Path, option: str = "--output") -> Iterator[Path]:
    """Hold the exclusive lock of output ``path`` for the block; :class:`InputError` when another
    process holds it. A lock this process already holds is kept as it is (and not released here).

    Examples
    --------
    >>> import fcntl, tempfile
    >>> out = Path(tempfile.mkdtemp()) / "run.zarr"
    >>> with exclusive_output(out):
    ...     with exclusive_output(out):  # this process holds it: not taken twice
    ...         pass
    >>> other = os.open(lock_path(out), os.O_RDWR | os.O_CREAT)  # as another process would hold it
    >>> fcntl.flock(other, fcntl.LOCK_EX)
    >>> with exclusive_output(out):
    ...     pass
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: --output .../run.zarr: another skyradar command is writing it now; ...
    >>> os.close(other)
    """
    path = Path(path)
    lock = lock_path(path)
    key = _key(lock)
    if key in _HELD:
        yield lock
        return
    made = _missing_folders(lock.parent)
    fd = _acquire(path, lock, option)
    _HELD[key] = fd
    try:
        yield lock
    finally:
        del _HELD[key]
        _release(lock, fd, made)


@contextmanager
def command_outputs() -> Iterator[None]:
    """Hold every output lock :func:`hold_output` takes in the block until the block ends.

    Examples
    --------
    >>> import tempfile
    >>> out = Path(tempfile.mkdtemp()) / "table.parquet"
    >>> with command_outputs():
    ...     hold_output(out), lock_path(out).exists()
    (True, True)
    >>> lock_path(out).exists(), hold_output(out)
    (False, False)
    """
    global _SCOPE
    outer = _SCOPE
    with ExitStack() as stack:
        _SCOPE = (os.getpid(), stack)
        try:
            yield
        finally:
            _SCOPE = outer


def hold_output(path: str | Path, option: str = "--output") -> bool:
    """Lock output ``path`` until the running command ends (:func:`command_outputs`).

    Parameters
    ----------
    path : path
        The output to lock (its lock file is :func:`lock_path`).
    option : str
        The command-line option that names ``path``, for the error message.

    Returns
    -------
    bool
        True when locked; False, and no lock, outside a command or in a worker process forked from one.

    Raises
    ------
    InputError
        When another process is writing ``path``.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     out = Path(d) / "tracks.parquet"
    ...     with command_outputs():
    ...         locked = hold_output(out), hold_output(out), lock_path(out).exists()
    ...     locked, lock_path(out).exists(), hold_output(out)
    ((True, True, True), False, False)
    """
    if _SCOPE is None or _SCOPE[0] != os.getpid():
        return False
    _SCOPE[1].enter_context(exclusive_output(path, option))
    return True
