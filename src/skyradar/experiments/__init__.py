"""Experiments that reproduce the thesis' chapters 2 to 7 (Maas 2022), and the DAA evaluation.

``encounters`` scores the whole chain on an encounter set and ``demo`` (in :mod:`skyradar.demo`)
flies one scenario end to end. ch6 is the GPS check against a map, ch7 the passive radar.

Each module's ``run(out_dir, ...) -> dict`` writes its figures (PNG) and its table, and returns
the measured values that ``skyradar experiment NAME --json`` prints.
"""
