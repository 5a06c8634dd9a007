"""Experiments that reproduce seed-brief.md ch2..ch7.

Each module's ``run(out_dir, ...) -> dict`` writes its figures (PNG) and its table, and returns
the measured values that ``skyradar experiment NAME --json`` prints.
"""
