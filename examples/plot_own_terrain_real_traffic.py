"""
Your own scenario: your DEM, with real ADS-B traffic
====================================================

A scenario of your own puts three things together: the ground (a DEM file you bring), the
own-ship, and the traffic. Here the DEM is matplotlib's sample of the Jacksboro fault in
Tennessee, copied to a file of our own as a user's download would be, and the traffic is a real
glider: an OpenSky ADS-B recording of a flight over the Luberon (France) that ships with the
``traffic`` package (the ``flights`` extra: ``pip install 'skyradar[flights]'``). Its fixes are
what real ADS-B is: seconds apart, quantised, with barometric altitudes.

A recording made elsewhere is brought to your ground by
:func:`~skyradar.scene.encounter_from_tracks.encounter_from_tracks`: the glider keeps the motion
it flew (its course, speed and climb, fix by fix), moved rigidly in time and space so that it passes the
own-ship at the miss you ask for. Both flights are then written as track files and flown by the
scenario (``type: file``), as it flies your own ADS-B download or GPS log, over the DEM
(``terrain: {type: file}``); the radar runs through the whole chain.
"""

import shutil
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib import cbook

from skyradar.chain import label_tracks, run_chain
from skyradar.daa.alerting import RADAR_ALERT_CONFIG
from skyradar.scene.adsb import fit_flight
from skyradar.scene.encounter_from_tracks import (
    encounter_from_tracks,
    encounter_scenario,
    horizontal_cpa,
    trajectory_table,
)
from skyradar.scene.flights import straight
from skyradar.scene.sample_flights import sample_flight
from skyradar.scene.scenario import Scenario

# %%
# Your DEM: any path (SRTM ``.hgt``, GeoTIFF or ``.npz``). This ``.npz`` holds the heights (m) on
# a 3 arc-second grid and the grid's corners.
folder = Path(tempfile.mkdtemp())
dem_file = folder / "my_dem.npz"
shutil.copy(cbook.get_sample_data("jacksboro_fault_dem.npz", asfileobj=False), dem_file)
dem = np.load(dem_file)
heights_m = np.asarray(dem["elevation"], float)
lat_deg = 0.5 * (float(dem["ymin"]) + float(dem["ymax"]))
lon_deg = 0.5 * (float(dem["xmin"]) + float(dem["xmax"]))
ground_m = float(heights_m[heights_m.shape[0] // 2, heights_m.shape[1] // 2])
print(f"DEM {heights_m.shape}, heights {heights_m.min():.0f} to {heights_m.max():.0f} m")
print(f"centre {lat_deg:.4f} N {lon_deg:.4f} E, ground {ground_m:.0f} m")

# %%
# The traffic: two and a half minutes of the glider's recording, in the units OpenSky stores
# (feet, knots, feet per minute), written to a CSV file of our own.
raw = pd.read_json(sample_flight("gliders/luberon"))
stamp = pd.to_datetime(raw["timestamp"], utc=True)
elapsed_s = (stamp - stamp.min()).dt.total_seconds()
fixes_file = folder / "glider_fixes.csv"
raw[(elapsed_s >= 15540) & (elapsed_s < 15690)].to_csv(fixes_file, index=False)
glider = fit_flight(fixes_file, "glider")
print(f"{glider.fix_time_s.size} fixes over {glider.fix_time_s[-1] - glider.fix_time_s[0]:.0f} s")

# %%
# The own-ship flies north at 50 m/s, 1000 m above the ground at the DEM's centre. The glider's
# state 90 s into its stretch is moved to meet the own-ship 30 s into the flight, 150 m to the
# right and 60 m above; :func:`~skyradar.scene.encounter_from_tracks.horizontal_cpa` measures what
# the moved flights do.
own = straight([-1500.0, 0.0, -1000.0], 0.0, 50.0, 60.0, origin=(lat_deg, lon_deg, ground_m), name="own-ship")
own, intruder = encounter_from_tracks(own, glider.trajectory, 30.0, 150.0, 60.0, intruder_time_s=90.0)
t_cpa_s, miss_h_m, miss_v_m = horizontal_cpa(own, intruder)
print(f"closest approach at {t_cpa_s:.1f} s: {miss_h_m:.0f} m aside, {miss_v_m:.0f} m above")

# %%
# The scenario: both flights as track files, the 14 s before the closest approach at 4.7 frames
# per second, over the DEM file, the antenna tilted down (``forward-down``).
trajectory_table(own).to_csv(folder / "own.csv", index=False)
trajectory_table(intruder).to_csv(folder / "glider.csv", index=False)
scenario = encounter_scenario(
    own, intruder, str(folder / "own.csv"), str(folder / "glider.csv"), t_cpa_s, before_s=14.0, after_s=0.0
)
scenario["name"] = "a real glider over my DEM"
scenario["intruders"][0] |= {"name": "glider", "aircraft_class": "glider", "rcs_m2": 1.0}
scenario |= {
    "mount": "forward-down",
    "terrain": {"type": "file", "path": str(dem_file)},
    "frame_rate_hz": 4.7,
    "simulation": {"occlusion": True, "noise": True, "seed": 1},
}
built = Scenario.from_dict(scenario).build()
out = run_chain(built, RADAR_ALERT_CONFIG)
labels = label_tracks(out["tracks"], out["truth"])
detections = out["detections"]
print(f"{len(detections)} detections, {int(detections['is_ground'].sum())} on the ground")
print(f"tracks and what they follow: {labels}")
alerts = out["alerts"]
for level, name in ((1, "preventive"), (2, "corrective"), (3, "warning")):
    rows = alerts[alerts["level"] >= level].sort_values("time_s")
    if len(rows):
        first = rows.iloc[0]
        print(f"first {name} or higher at {first['time_s']:.1f} s, {first['range_m']:.0f} m away")

# %%
# Left: the DEM with the own-ship's and the glider's paths over the run, and the glider's ADS-B
# fixes moved with it. Right: the glider's range from the own-ship, its truth against its confirmed
# track, and where the alert level rose.
truth = out["truth"]
fig, (ax_map, ax_range) = plt.subplots(1, 2, figsize=(11, 4.6))
extent = [float(dem["xmin"]), float(dem["xmax"]), float(dem["ymax"]), float(dem["ymin"])]
image = ax_map.imshow(heights_m, extent=extent, cmap="terrain", origin="upper")
fig.colorbar(image, ax=ax_map, label="ground height [m]")
window = np.linspace(max(own.start_s, intruder.start_s), built.times_s[-1], 200)
for path, style, label in ((own, "k-", "own-ship"), (intruder, "r-", "glider")):
    s = path.sample(window)
    ax_map.plot(s.lon_deg, s.lat_deg, style, label=label)
fixes = intruder.sample(glider.fix_time_s + (t_cpa_s - 90.0))  # the fixes' times, moved with the flight
seen = (fixes.time_s >= window[0]) & (fixes.time_s <= window[-1])
ax_map.plot(fixes.lon_deg[seen], fixes.lat_deg[seen], "wo", ms=4, mec="r", label="ADS-B fixes (moved)")
pad = 0.02
ax_map.set(xlim=(lon_deg - pad, lon_deg + pad), ylim=(lat_deg - pad, lat_deg + pad), xlabel="longitude [deg]")
ax_map.set(ylabel="latitude [deg]", title="over the DEM", aspect=1.0 / np.cos(np.radians(lat_deg)))
ax_map.legend(fontsize=8, loc="lower right")
target = truth.sel(target="glider")
ax_range.plot(built.times_s, target["tgt_range_m"], "k--", label="glider: truth")
for track_id, rows in out["tracks"].query("confirmed").groupby("track_id"):
    name = labels.get(track_id, "clutter")
    ax_range.plot(rows["time_s"], rows["range_m"], ".", ms=4, label=f"track {track_id} ({name})")
for _, rows in alerts.groupby("track_id"):
    rises = rows[rows["level"].diff().fillna(rows["level"]) > 0]
    for r in rises.itertuples():
        ax_range.annotate(
            f"level {r.level}", (r.time_s, r.range_m), xytext=(5, 10), textcoords="offset points"
        )
ax_range.set(xlabel="time [s]", ylabel="range [m]", title="the glider's range")
ax_range.legend(fontsize=8)
fig.tight_layout()
plt.show()
