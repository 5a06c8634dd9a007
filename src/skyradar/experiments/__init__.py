"""Experiments that reproduce seed-brief.md ch2..ch7: each ``run(out_dir) -> dict`` writes figures and a table."""
