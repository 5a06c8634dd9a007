"""One writer per output: an exclusive, OS-level lock held while a command writes a path.

Two commands writing the same output at once interleave their chunks and attributes: one of them can
report success for a store the other half overwrote. :func:`exclusive_output` takes an advisory
``flock`` on a lock file beside the output (``.NAME.lock``) for the whole write, so a second writer is
refused at once with one line. The operating system releases the lock when the holder exits, however
it exits (``kill -9`` included), so a lock file left behind by a killed command blocks nobody: the
next writer takes it and removes it when done.
"""

from __future__ import annotations

import fcntl
import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from skyradar.errors import InputError

__all__ = ["exclusive_output", "lock_path"]


def lock_path(path: str | Path) -> Path:
    """The lock file of output ``path``: ``.NAME.lock`` in the same folder.

    Examples
    --------
    >>> lock_path("out/run.zarr").as_posix()
    'out/.run.zarr.lock'
    """
    path = Path(path)
    return path.with_name(f".{path.name}.lock")


@contextmanager
def exclusive_output(path: str | Path, option: str = "--output") -> Iterator[Path]:
    """Hold the exclusive lock of output ``path`` for the block; :class:`InputError` when another
    process holds it.

    Examples
    --------
    >>> import tempfile
    >>> out = Path(tempfile.mkdtemp()) / "run.zarr"
    >>> with exclusive_output(out):
    ...     with exclusive_output(out):
    ...         pass
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: --output .../run.zarr: another skyradar command is writing it now; ...
    """
    path = Path(path)
    lock = lock_path(path)
    lock.parent.mkdir(parents=True, exist_ok=True)
    while True:
        fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
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
                break
        except FileNotFoundError:
            pass
        os.close(fd)
    try:
        yield lock
    finally:
        try:
            lock.unlink(missing_ok=True)
        finally:
            os.close(fd)
