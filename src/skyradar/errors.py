"""The one exception type for bad input.

Every reader and validator raises :class:`InputError` with a message that names the file,
the field and the offending value. The CLI turns it into one line on stderr and exit code 2,
never a traceback.
"""

from __future__ import annotations

__all__ = ["InputError"]


class InputError(ValueError):
    """Bad user input: the message names the file, field and value.

    A :class:`ValueError`, so code that catches those catches it too.

    Examples
    --------
    >>> try:
    ...     raise InputError("scene.yaml: field 'duration_s' must be > 0, got -1")
    ... except ValueError as exc:
    ...     print(type(exc).__name__, exc)
    InputError scene.yaml: field 'duration_s' must be > 0, got -1
    """
