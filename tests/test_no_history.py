"""Comments, docstrings and documents state rules and their reasons, never the project's history.

No session numbers, issue numbers, commit hashes, evaluation-encounter ids or citations of a private
brief: a reader has none of them, and the thesis (Maas 2022) is the reference to cite. The README,
every document under docs/ except docs/results/ (JSON records of runs) and every Python file of the
package are searched.
"""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HISTORY = re.compile(
    r"session [0-9]|issue [0-9]|encounter [0-9]+|\b[0-9a-f]{7}\b \(|seed-brief", flags=re.IGNORECASE
)


def _searched() -> list[Path]:
    docs = ROOT / "docs"
    skipped = {docs / "results"}
    documents = (p for p in docs.rglob("*") if p.is_file() and "__pycache__" not in p.parts)
    files = [ROOT / "README.md"]
    files += sorted(p for p in documents if not skipped & set(p.parents))
    files += sorted((ROOT / "src" / "skyradar").rglob("*.py"))
    return files


def _hits(path: Path) -> list[str]:
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError:  # images and other binary files tell no history in words
        return []
    where = path.relative_to(ROOT)
    lines = enumerate(text.splitlines(), 1)
    return [f"{where}:{n}: {line.strip()}" for n, line in lines if HISTORY.search(line)]


def test_the_searched_files_exist():
    files = _searched()
    assert files[0].is_file()
    assert any(p.suffix == ".py" for p in files)


def test_no_comment_docstring_or_document_tells_history():
    hits = [hit for path in _searched() for hit in _hits(path)]
    assert not hits, "history in comments, docstrings or documents:\n" + "\n".join(hits)
