"""
A thesis result: direction-of-arrival errors of the field test (ch. 3)
======================================================================

``skyradar experiment ch3`` reproduces chapter 3 of the thesis whose methods the package
implements (J. B. Maas, *Radar Sensing in General Aviation for Purposes of Detect and Avoid*, PhD
thesis, Delft University of Technology, 2022, DOI `10.4233/uuid:b7fae981-33a4-4cdb-993c-4ec06b6534ba
<https://doi.org/10.4233/uuid:b7fae981-33a4-4cdb-993c-4ec06b6534ba>`_). The prototype stands on
the ground aimed just above the horizon, its four receive channels are calibrated on a building,
and an aircraft flies towards it. Every frame is detected, located in 3-D from the phases of the
2x2 receive array and compared with the aircraft's truth, raw and after a 9-frame Hann filter
along the track. The thesis measured the same errors on its field-test flight;
``skyradar.experiments.ch3.THESIS_TABLE`` holds its values, and the experiment's table puts
them beside the simulated ones.

Here the experiment runs from Python at a reduced size: the approach path at the 9.4 Hz field rate
(300 frames, 32 s, from 3 km in to about 900 m), 20 frames of the static scene for the spur map and
the calibration, and no comparison of other array spacings (the command flies two more).
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from skyradar.experiments import ch3

# %%
# ``skyradar.experiments.ch3.run`` writes the figures, the table and a JSON summary into a
# folder and returns the summary.
folder = Path(tempfile.mkdtemp())
summary = ch3.run(folder, n_frames=300, n_static=20, path="approach", compare_spacings=())
print(
    f"{summary['detected_frames']} of {summary['frames']} frames detected, "
    f"{summary['false_alarms_per_frame']:.2f} false alarms per frame, "
    f"calibration phase error {summary['calib_phase_err_deg']:.2f} deg"
)
print(
    f"Cramer-Rao bound at the measured SNR (RMS over the detections): azimuth "
    f"{summary['az_crlb_deg']:.2f} deg, elevation {summary['el_crlb_deg']:.2f} deg"
)

# %%
# The experiment's table (``ch3_table.csv``): mean and standard deviation of each error over the
# detected frames, raw and Hann-filtered, beside the thesis' values; the 3-D distance in m, the
# antenna-frame angles in deg.
table = pd.read_csv(folder / "ch3_table.csv", index_col="quantity")
print(table.round(2).to_string())

# %%
# The spreads side by side. The thesis' values come from one recorded field flight, not from this
# simulated approach: compare their magnitudes, not their digits.
fig, axes = plt.subplots(1, 3, figsize=(10, 3.6))
labels = {
    "dist_m": "3-D distance error SD [m]",
    "az_deg": "azimuth error SD [deg]",
    "el_deg": "elevation error SD [deg]",
}
x = np.arange(2)
for ax, (quantity, label) in zip(axes, labels.items(), strict=True):
    row = table.loc[quantity]
    ax.bar(x - 0.2, [row["raw_sd"], row["hann_sd"]], 0.4, label="skyradar (simulated)")
    ax.bar(x + 0.2, [row["thesis_raw_sd"], row["thesis_hann_sd"]], 0.4, label="thesis (field test)")
    ax.set(xticks=x, xticklabels=["raw", "Hann"], ylabel=label)
axes[0].legend(fontsize=8)
fig.tight_layout()
plt.show()

# %%
# Along the approach (``ch3_track.parquet``, one row per frame): the position error shrinks as the
# aircraft comes in (higher SNR, a shorter lever arm for the same angle error), and the Hann filter
# takes out most of the frame-to-frame scatter.
track = pd.read_parquet(folder / "ch3_track.parquet")
fig, ax = plt.subplots(figsize=(7, 3.5))
ax.plot(track["true_range_m"] / 1e3, track["dist_raw_m"], ".", ms=3, label="raw")
ax.plot(track["true_range_m"] / 1e3, track["dist_hann_m"], label="Hann, 9 frames")
ax.set(xlabel="range [km]", ylabel="3-D position error [m]", title="position error along the approach")
ax.invert_xaxis()
ax.legend()
fig.tight_layout()
plt.show()
