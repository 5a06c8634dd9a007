"""Radar simulators: image domain (fast) and chirp-level raw ADC, plus hardware impairments."""

import os

# numba's OpenMP threads (libgomp) spin 300,000 times at every barrier before they sleep. A frame
# crosses about six parallel regions; on a machine shared with other jobs (load 4 on 2 cores) a
# spinning thread keeps the core from the thread it waits for: two threads then took 70 CPU-ms and
# 104 ms a frame of the bench's fine_psf scene against 37 CPU-ms and 57 ms with a short spin. Read
# once, when the first parallel kernel loads libgomp; a value the user set is kept.
os.environ.setdefault("GOMP_SPINCOUNT", "10000")
