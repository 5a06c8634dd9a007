"""Multi-target tracking in range-Doppler and 3-D, with swappable parts, and track metrics."""
