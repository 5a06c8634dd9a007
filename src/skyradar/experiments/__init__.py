"""Experiments that reproduce seed-brief.md ch2, ch3, ch4 and ch5, and the DAA evaluation.

``encounters`` scores the whole chain on an encounter set and ``demo`` (in :mod:`skyradar.demo`)
flies one scenario end to end. ch6 (GPS check) and ch7 (passive radar) are not built.

Each module's ``run(out_dir, ...) -> dict`` writes its figures (PNG) and its table, and returns
the measured values that ``skyradar experiment NAME --json`` prints.
"""
