"""Atomic file output: write under a unique temporary name next to the target, rename at the end.

Every file skyradar writes (tables, JSON, CSV, figures, HTML, recordings) goes through
:func:`atomic_path`: the data is written to a hidden temporary file in the target's own directory
(same file system, so the final :func:`os.replace` is atomic), whose name is unique, so two
writers of the same target never share a temporary file. On any exception the temporary file is
removed and the target is left as it was: an interrupted job leaves neither a half-written file
under the final name nor a stray temporary file.
"""

from __future__ import annotations

import contextlib
import os
import uuid
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

__all__ = ["atomic_path", "write_with", "write_text_atomic", "write_csv_atomic", "savefig_atomic"]


def _create_unique(directory: Path, name: str, suffix: str) -> Path:
    # O_EXCL makes the name ours even if another process picks the same one; mode 0o666 lets the
    # umask decide the permissions, as for any ordinary new file (mkstemp would force 0o600).
    for _ in range(100):
        tmp = directory / f".{name}.{uuid.uuid4().hex[:12]}.tmp{suffix}"
        try:
            os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
        except FileExistsError:
            continue
        return tmp
    raise FileExistsError(f"{directory}: cannot create a unique temporary file for {name}")


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a unique temporary path next to ``path``; rename it to ``path`` when the block succeeds.

    The temporary file exists (empty) when the block starts and keeps the target's suffix, so
    writers that infer the format from the name still work. Parent directories are created.
    If the block raises, the temporary file is removed and ``path`` is untouched.

    Parameters
    ----------
    path : path
        The final file name.

    Yields
    ------
    Path
        The temporary file to write.

    Examples
    --------
    >>> import tempfile
    >>> target = Path(tempfile.mkdtemp()) / "out.txt"
    >>> with atomic_path(target) as tmp:
    ...     _ = tmp.write_text("hello")
    >>> target.read_text(), sorted(p.name for p in target.parent.iterdir())
    ('hello', ['out.txt'])
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = _create_unique(path.parent, path.name, path.suffix)
    try:
        yield tmp
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def write_with(path: str | Path, writer: Callable[[Path], Any]) -> Path:
    """Call ``writer(tmp)`` inside :func:`atomic_path` and return ``path``.

    Parameters
    ----------
    path : path
        The final file name.
    writer : callable
        Called once with the temporary path; it writes the whole file there. If it raises, the
        temporary file is removed and ``path`` is untouched.

    Returns
    -------
    Path
        ``path``, holding what ``writer`` wrote.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = write_with(Path(d) / "n.bin", lambda tmp: tmp.write_bytes(bytes(range(4))))
    ...     p.read_bytes(), [q.name for q in Path(d).iterdir()]
    (b'\\x00\\x01\\x02\\x03', ['n.bin'])
    """
    with atomic_path(path) as tmp:
        writer(tmp)
    return Path(path)


def write_text_atomic(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically.

    Examples
    --------
    >>> import tempfile
    >>> p = write_text_atomic(Path(tempfile.mkdtemp()) / "a" / "page.html", "<p>hi</p>")
    >>> p.read_text()
    '<p>hi</p>'
    """
    return write_with(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))


def write_csv_atomic(df: Any, path: str | Path, **to_csv_kwargs: Any) -> Path:
    """``df.to_csv(path, **to_csv_kwargs)`` atomically (a pandas DataFrame or Series).

    Examples
    --------
    >>> import tempfile, pandas as pd
    >>> p = write_csv_atomic(pd.DataFrame({"a": [1, 2]}), Path(tempfile.mkdtemp()) / "t.csv", index=False)
    >>> p.read_text().split()
    ['a', '1', '2']
    """
    return write_with(path, lambda tmp: df.to_csv(tmp, **to_csv_kwargs))


def savefig_atomic(fig: Any, path: str | Path, **savefig_kwargs: Any) -> Path:
    """``fig.savefig(path, **savefig_kwargs)`` atomically; the format comes from ``path``'s suffix.

    The format is passed explicitly because matplotlib would otherwise take it from the
    temporary name.

    Examples
    --------
    >>> import tempfile, matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> fig, ax = plt.subplots()
    >>> p = savefig_atomic(fig, Path(tempfile.mkdtemp()) / "f.png", dpi=20)
    >>> p.read_bytes()[:4]
    b'\\x89PNG'
    """
    path = Path(path)
    savefig_kwargs.setdefault("format", path.suffix.lstrip(".").lower() or "png")
    return write_with(path, lambda tmp: fig.savefig(tmp, **savefig_kwargs))
