"""Which code measured a result: the package version and a digest of its source.

A version number alone does not name the code: a set of hundreds of encounters, or a benchmark
against the one before it, can span days of development at one version number. Experiments resume
only on the same code, and every measured result records it.
"""

from __future__ import annotations

import hashlib
import sys
from importlib.metadata import version
from pathlib import Path

__all__ = ["code_version"]


def code_version() -> str:
    """``VERSION+DIGEST``: the installed version and the first 16 hex digits of the SHA-256 of every
    ``.py`` file of the package (relative path and content, in path order).

    Examples
    --------
    >>> release, digest = code_version().split("+")
    >>> len(digest)
    16
    """
    # The package that holds this module (always imported before it); looked up, not imported, so
    # that this module stays below every other in the layers.
    digest = hashlib.sha256()
    root = Path(str(sys.modules["skyradar"].__file__)).parent
    for path in sorted(root.rglob("*.py")):
        digest.update(str(path.relative_to(root)).encode() + b"\0" + path.read_bytes())
    return f"{version('skyradar')}+{digest.hexdigest()[:16]}"
