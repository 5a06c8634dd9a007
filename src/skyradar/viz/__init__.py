"""Matplotlib figures (headless Agg backend)."""
