"""Settings shared by the tests and the docstring examples (``--doctest-modules`` over src/skyradar).

A docstring example that makes a temporary folder (``tempfile.mkdtemp()``) makes it under the test's
own temporary folder, which pytest removes, not in the system's: running the examples leaves nothing.
"""

import tempfile

import pytest


@pytest.fixture(autouse=True)
def _examples_write_under_the_tests_folder(request, tmp_path, monkeypatch):
    if isinstance(request.node, pytest.DoctestItem):
        monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
