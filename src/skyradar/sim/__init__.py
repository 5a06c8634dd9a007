"""Radar simulators: image domain (fast) and chirp-level raw ADC, plus hardware impairments."""
