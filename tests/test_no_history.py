"""Comments, docstrings and documents state rules and their reasons, never the project's history.

No session numbers, issue numbers ("issue 12", "#41"), commit hashes, evaluation-encounter ids or
citations of a private brief: a reader has none of them, and the thesis (Maas 2022) is the reference
to cite. The README, every document under docs/ except docs/results/ (JSON records of runs), every
Python file of the package and every Python file of the tests but this one (module docstrings,
comments, docstrings and test names alike) are searched.
"""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HISTORY = re.compile(
    r"session[ _][0-9]|issue[ _][0-9]|encounter[ _][0-9]+|\b[0-9a-f]{7}\b \(|commit [0-9a-f]{7}"
    r"|seed[- ]brief|(?<![\w&/])#[0-9]+\b",
    flags=re.IGNORECASE,
)


def _searched() -> list[Path]:
    docs = ROOT / "docs"
    skipped = {docs / "results"}
    documents = (p for p in docs.rglob("*") if p.is_file() and "__pycache__" not in p.parts)
    files = [ROOT / "README.md"]
    files += sorted(p for p in documents if not skipped & set(p.parents))
    files += sorted((ROOT / "src" / "skyradar").rglob("*.py"))
    tests = (p for p in (ROOT / "tests").rglob("*.py") if "__pycache__" not in p.parts)
    files += sorted(p for p in tests if p != Path(__file__).resolve())  # this file names what it forbids
    return files


def _hits(path: Path) -> list[tuple[str, int, str]]:
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError:  # images and other binary files tell no history in words
        return []
    where = path.relative_to(ROOT).as_posix()
    lines = enumerate(text.splitlines(), 1)
    return [(where, n, line.strip()) for n, line in lines if HISTORY.search(line)]


def test_the_searched_files_exist():
    files = _searched()
    assert files[0].is_file()
    assert any(p.suffix == ".py" and "src" in p.parts for p in files)
    assert any(p.suffix == ".py" and "tests" in p.parts for p in files)


def test_the_pattern_finds_each_kind_of_history():
    told = [
        "(issue 12 point 4)",
        "Issue 12.1: sub-facets",
        "def test_issue_12_gap():",
        "session 3",
        "hills encounter 96",
        "fixed in commit 1a2b3c4",
        "a1b2c3d (the revert)",
        "seed-brief.md",
        "the seed brief's form",
        "see #41",
    ]
    assert [line for line in told if not HISTORY.search(line)] == []
    plain = ['scope="session"', "encounter_score", "&#39;", "page.html#2", "# 3 frames", "issued warning"]
    assert [line for line in plain if HISTORY.search(line)] == []


def test_no_comment_docstring_or_document_tells_history():
    told = [f"{where}:{n}: {line}" for path in _searched() for where, n, line in _hits(path)]
    assert not told, "history in comments, docstrings, test names or documents:\n" + "\n".join(told)


def test_the_records_of_runs_name_their_code_only_as_provenance():
    # docs/results/ records which commit measured each result ("code at commit abc1234"): that is
    # provenance a reader can check out, not history. Sessions, issues, encounter ids, a hash
    # followed by a remark in parentheses and the brief are forbidden there as everywhere.
    told_here = re.compile(
        r"session [0-9]|issue [0-9]|encounter [0-9]+|\b[0-9a-f]{7}\b \(|seed-brief", flags=re.IGNORECASE
    )
    assert told_here.search("code at commit 0983e4b (load average 4)")
    records = sorted(p for p in (ROOT / "docs" / "results").rglob("*.md"))
    assert records
    told = [
        f"{path.name}:{n}: {line}"
        for path in records
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
        if told_here.search(line)
    ]
    assert not told, "history in the records of runs:\n" + "\n".join(told)
