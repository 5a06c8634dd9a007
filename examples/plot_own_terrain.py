"""
Your own terrain: a DEM file under the flight
=============================================

A scenario over a digital elevation model you bring (SRTM ``.hgt``, GeoTIFF or ``.npz``). Here the
DEM is matplotlib's sample of the Jacksboro fault in Tennessee, copied to a file of our own as a
user's download would be. Without an ``origin`` the scenario starts at the DEM's centre, on the
ground; the own-ship flies 1000 m above it with the antenna tilted down, and an intruder crosses
150 m below, against the ground clutter.

The first frame's range-Doppler image shows the ground return (the bright band that follows the
terrain's Doppler) and the frame's detections after clutter suppression, those the ground filter
puts on the DEM's surface apart from the rest (the tracker leaves them out).
"""

import shutil
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib import cbook

from skyradar.chain import run_chain
from skyradar.daa.alerting import RADAR_ALERT_CONFIG
from skyradar.scene.scenario import Scenario

# %%
# "Your" DEM: a file on disk (any path; relative paths are read from the scenario file's folder).
folder = Path(tempfile.mkdtemp())
dem = folder / "my_dem.npz"
shutil.copy(cbook.get_sample_data("jacksboro_fault_dem.npz", asfileobj=False), dem)

scenario = {
    "name": "own DEM example",
    "mount": "forward-down",
    "terrain": {"type": "file", "path": str(dem)},
    "ownship": {"type": "straight", "start_ned_m": [-3000, 0, -1000], "heading_deg": 0, "speed_mps": 40},
    "intruders": [
        {
            "name": "crossing",
            "type": "encounter",
            "kind": "crossing",
            "t_cpa_s": 25,
            "horizontal_miss_m": 300,
            "vertical_miss_m": -150,
            "rcs_m2": 1.0,
        },
    ],
    "frame_rate_hz": 4.7,
    "duration_s": 4.0,
    "simulation": {"occlusion": True, "noise": True, "seed": 1},
}
built = Scenario.from_dict(scenario).build()
print("origin (lat, lon, ground height m):", tuple(round(x, 4) for x in built.origin))
out = run_chain(built, RADAR_ALERT_CONFIG, keep_frames=(0,))

# %%
# The first frame's channel-mean power (dB) over range and radial velocity, and its detections.
cube = out["rd_frames"][0]
power_db = 10.0 * np.log10(np.mean(np.abs(cube) ** 2, axis=2) + 1e-30)
config = built.radar
detections = out["detections"].query("frame == 0")
fig, ax = plt.subplots(figsize=(7, 4))
velocity, range_km = config.doppler_axis_mps, config.range_axis_m / 1000.0  # bin centres, FFT-shifted order
extent = [velocity[0], velocity[-1], range_km[-1], range_km[0]]
image = ax.imshow(power_db, aspect="auto", extent=extent, cmap="viridis")
for on_ground, colour, label in ((True, "white", "on the ground"), (False, "red", "not ground")):
    rows = detections[detections["is_ground"] == on_ground]
    ax.scatter(
        rows["radial_velocity_mps"],
        rows["range_m"] / 1000.0,
        s=25,
        facecolors="none",
        edgecolors=colour,
        label=f"detections {label}",
    )
ax.set(xlabel="radial velocity [m/s]", ylabel="range [km]", title="frame 0 over the DEM")
ax.legend(loc="lower right")
fig.colorbar(image, label="power [dB]")
plt.show()
