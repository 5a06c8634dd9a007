"""Which code measured a result: the package version and a digest of its source.

A version number alone does not name the code: a set of hundreds of encounters, or a benchmark
against the one before it, can span days of development at one version number. Experiments resume
only on the same code, and every measured result records it with :func:`provenance`: the code, the
command, the UTC date and the machine's load.
"""

from __future__ import annotations

import hashlib
import os
import sys
import time
from importlib.metadata import version
from pathlib import Path
from typing import Any

__all__ = ["code_version", "invoked_command", "provenance"]


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


def invoked_command() -> str:
    """This process' command line: ``skyradar ARGS`` under the ``skyradar`` entry point (or
    ``python -m skyradar``), else the program's name and its arguments.

    Examples
    --------
    >>> import sys
    >>> argv, sys.argv = sys.argv, ["/venv/bin/skyradar", "bench", "sim", "--json"]
    >>> invoked_command()
    'skyradar bench sim --json'
    >>> sys.argv = argv
    """
    program = Path(sys.argv[0]) if sys.argv and sys.argv[0] else Path("python")
    is_skyradar = program.name == "skyradar" or program.parts[-2:] == ("skyradar", "__main__.py")
    return " ".join(["skyradar" if is_skyradar else program.name, *sys.argv[1:]])


def provenance(command: str | None = None, version: str | None = None) -> dict[str, Any]:
    """The keys every measured result records of how it was measured, in this order: ``version``
    (:func:`code_version`), ``command`` (``command``, or :func:`invoked_command`), ``date_utc`` (now,
    ``YYYY-MM-DDTHH:MM:SSZ``) and ``load_average_1min`` (the machine's one-minute load average).

    ``version`` is the code version taken when the run started, where it may run long enough for
    the source to change under it; by default it is taken now.

    Examples
    --------
    >>> list(provenance("skyradar experiment clutter"))
    ['version', 'command', 'date_utc', 'load_average_1min']
    """
    return {
        "version": version if version is not None else code_version(),
        "command": command if command is not None else invoked_command(),
        "date_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "load_average_1min": round(os.getloadavg()[0], 2),
    }
