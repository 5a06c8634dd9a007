"""Run every experiment at its defaults on two code versions and compare their JSON.

A refactor or a speed-up must leave what the experiments measure unchanged. This script checks
out each version into its own git worktree under ``--work`` (created here, never a user's
folder), runs ``skyradar experiment NAME --json`` on it with that worktree's sources first on the
path, and compares the last JSON line of the two runs value by value. Keys that time the run or
name where and when it ran (``--ignore``, a regular expression on the key's path) are left out;
``--rtol`` lets measured floats differ by a stated relative amount (a compiled kernel whose
rounding changed), never counts, flags or strings.

Usage (from the repository root, with the project's ``.venv``)::

    .venv/bin/python scripts/compare_experiments.py BASE [HEAD] [--only ch2,ch5] [--work out/compare]

It prints one line per experiment, then a JSON summary as its last line; the exit status is 0
when every experiment's values are equal, 1 when any differ, 2 on bad input. Each run's stdout and
stderr stay in ``WORK/<version>/<experiment>.log`` and its outputs in ``WORK/<version>/<experiment>/``;
a run whose JSON is already there (same commit) is not run again.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

EXPERIMENTS = (
    "ch2",
    "ch3",
    "ch4",
    "ch5",
    "ch6",
    "ch7",
    "clutter",
    "encounters",
    "closed-loop",
    "bluesky",
    "arrays",
)

# Keys that time a run or say where, when and by what it ran: never part of what it measured
# (stage timings such as ``detect_s``, ``track_s_radar`` or ``process_s_per_frame_none`` included).
DEFAULT_IGNORE = (
    r"(^|\.)(version|date_utc|command|load_average\w*|workers|scheduler|output|out_dir|files|figures"
    r"|resumed_encounters|seconds)($|\.)"
    r"|(^|\.)\w*(runtime|wall|cpu|timing|elapsed|speedup|cost_ms|ms_per_frame|per_s)\w*($|\.)"
    r"|(^|\.)(detect|track|process|simulate|alert|total)_s(_\w+)?($|\.)"
)


def _flatten(value, prefix: str = "") -> dict[str, object]:
    """``{"a.b.0": leaf}`` of a JSON value."""
    if isinstance(value, dict):
        out: dict[str, object] = {}
        for key, item in value.items():
            out.update(_flatten(item, f"{prefix}.{key}" if prefix else str(key)))
        return out
    if isinstance(value, list):
        out = {}
        for i, item in enumerate(value):
            out.update(_flatten(item, f"{prefix}.{i}" if prefix else str(i)))
        return out
    return {prefix: value}


def _relative_difference(a: object, b: object) -> float:
    """|a - b| / max(|a|, |b|) of two numbers, one a float (0 when equal, both NaN included); inf
    for any other difference."""
    if a == b:
        return 0.0
    # Only measurements (floats) have a tolerance: counts, flags and strings are equal or not.
    if not (isinstance(a, float) or isinstance(b, float)):
        return math.inf
    if not all(isinstance(x, int | float) and not isinstance(x, bool) for x in (a, b)):
        return math.inf
    if math.isnan(a) and math.isnan(b):
        return 0.0
    if not (math.isfinite(a) and math.isfinite(b)):
        return math.inf
    return abs(a - b) / max(abs(a), abs(b))


def compare(before: dict, after: dict, ignore: str, rtol: float = 0.0) -> list[str]:
    """Paths whose values differ between two JSON results by more than ``rtol`` (relative; 0: any
    difference), ignored paths left out. Counts, flags and strings must be equal whatever ``rtol``."""
    pattern = re.compile(ignore)
    a, b = _flatten(before), _flatten(after)
    keys = sorted((set(a) | set(b)) - {k for k in set(a) | set(b) if pattern.search(k)})
    return [k for k in keys if k not in a or k not in b or _relative_difference(a[k], b[k]) > rtol]


def largest_relative_difference(before: dict, after: dict, ignore: str) -> float:
    """The largest relative difference of the values both results hold (ignored paths left out)."""
    pattern = re.compile(ignore)
    a, b = _flatten(before), _flatten(after)
    common = [k for k in set(a) & set(b) if not pattern.search(k)]
    return max((_relative_difference(a[k], b[k]) for k in common), default=0.0)


def _commit(rev: str) -> str:
    done = subprocess.run(
        ["git", "rev-parse", "--verify", f"{rev}^{{commit}}"], capture_output=True, text=True
    )
    if done.returncode != 0:
        print(f"compare_experiments: revision {rev!r} is not a commit of this repository", file=sys.stderr)
        sys.exit(2)
    return done.stdout.strip()


def _worktree(work: Path, commit: str) -> Path:
    tree = work / commit[:12]
    if not (tree / "src" / "skyradar").is_dir():
        subprocess.run(
            ["git", "worktree", "add", "--detach", str(tree), commit], check=True, capture_output=True
        )
    return tree


def _run(tree: Path, name: str) -> dict | None:
    """The experiment's JSON result on the sources of ``tree`` (kept beside its log)."""
    result = tree / "compare" / f"{name}.json"
    if result.is_file():
        return json.loads(result.read_text())
    result.parent.mkdir(parents=True, exist_ok=True)
    out_dir = tree / "compare" / name
    env = {**os.environ, "PYTHONPATH": str(tree / "src"), "MPLBACKEND": "Agg"}
    cmd = [sys.executable, "-m", "skyradar", "experiment", name, "--json", "-o", str(out_dir)]
    with open(tree / "compare" / f"{name}.log", "w") as log:
        done = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=log, text=True, env=env, cwd=tree)
        log.write(done.stdout)
    lines = [line for line in done.stdout.splitlines() if line.strip()]
    if done.returncode != 0 or not lines:
        return None
    data = json.loads(lines[-1])
    partial = result.with_suffix(".json.partial")
    partial.write_text(json.dumps(data))
    partial.replace(result)
    return data


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("base", help="the version before (a commit, branch or tag)")
    parser.add_argument("head", nargs="?", default="HEAD", help="the version after (default HEAD)")
    parser.add_argument("--only", default=",".join(EXPERIMENTS), help="comma-separated experiments")
    parser.add_argument("--work", default="out/compare", help="folder for the worktrees and runs")
    parser.add_argument("--ignore", default=DEFAULT_IGNORE, help="regex of key paths not compared")
    parser.add_argument(
        "--rtol",
        type=float,
        default=0.0,
        help="relative difference below which two numbers count as equal (default 0: exact)",
    )
    args = parser.parse_args(argv)
    names = [n for n in args.only.split(",") if n]
    unknown = sorted(set(names) - set(EXPERIMENTS))
    if unknown:
        print(f"compare_experiments: --only: unknown experiment {unknown[0]!r}", file=sys.stderr)
        return 2
    work = Path(args.work).resolve()
    work.mkdir(parents=True, exist_ok=True)
    trees = [_worktree(work, _commit(rev)) for rev in (args.base, args.head)]
    report: dict[str, object] = {
        "base": _commit(args.base),
        "head": _commit(args.head),
        "rtol": args.rtol,
        "experiments": {},
    }
    equal = True
    for name in names:
        before, after = (_run(tree, name) for tree in trees)
        if before is None or after is None:
            entry: dict[str, object] = {
                "equal": False,
                "failed": [t.name for t, r in zip(trees, (before, after), strict=True) if r is None],
            }
        else:
            differing = compare(before, after, args.ignore, args.rtol)
            entry = {
                "equal": not differing,
                "differing": differing[:50],
                "n_differing": len(differing),
                "largest_relative_difference": largest_relative_difference(before, after, args.ignore),
            }
        equal &= bool(entry["equal"])
        report["experiments"][name] = entry  # type: ignore[index]
        detail = entry.get("differing", entry.get("failed"))
        print(f"{name}: {'equal' if entry['equal'] else 'DIFFERENT'} {detail}")
    report["equal"] = equal
    print(json.dumps(report))
    return 0 if equal else 1


if __name__ == "__main__":
    sys.exit(main())
