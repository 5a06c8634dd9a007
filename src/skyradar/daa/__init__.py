"""Detect and avoid: conflict detection, alert levels and resolution advice."""
