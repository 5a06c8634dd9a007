"""
Real traffic: a recorded GA flight as the own-ship
==================================================

The ``traffic`` package (the ``flights`` extra: ``pip install 'skyradar[flights]'``) ships OpenSky
ADS-B recordings of whole flights, which :mod:`skyradar.scene.sample_flights` finds on disk. Here a
calibration aircraft's flight near Cardiff is the own-ship. Its fixes are what real ADS-B is: 5 s
apart, quantised, positions that lag and repeat, and a track column far off the positions' course.

A scenario flies the fixes file itself (``ownship: {type: file}``), as it flies your own ADS-B
download or GPS log: the fixes become a flyable path within the GA class's kinematic limits (the
path ``skyradar flight`` writes and draws). An intruder is then put on a crossing course and the
radar runs through the whole chain: simulate, detect, track, alert.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from skyradar.chain import label_tracks, run_chain
from skyradar.daa.alerting import RADAR_ALERT_CONFIG
from skyradar.scene.adsb import fit_flight
from skyradar.scene.sample_flights import sample_flight
from skyradar.scene.scenario import Scenario

# %%
# The recording: one row per ADS-B fix, in the units OpenSky stores (feet, knots, feet per
# minute). Five minutes of it, two turns of the calibration pattern, go to a CSV file of our own.
raw = pd.read_json(sample_flight("calibration/cardiff"))
stamp = pd.to_datetime(raw["timestamp"], utc=True)
elapsed_s = (stamp - stamp.min()).dt.total_seconds()
folder = Path(tempfile.mkdtemp())
fixes_file = folder / "cardiff_fixes.csv"
raw[(elapsed_s >= 1000) & (elapsed_s < 1300)].to_csv(fixes_file, index=False)
print(raw.head(3).to_string())

# %%
# :func:`~skyradar.scene.adsb.fit_flight` builds the flyable path (a Kalman smoother whose
# accelerations stay within the class's limits) and keeps the fixes beside it; the one line it
# logs names every repair (``fit.notes``). The speed between consecutive fixes swings from 45 to
# 115 m/s where the aircraft reports 60 to 85: a path through every fix would accelerate as no light
# aircraft can.
fit = fit_flight(fixes_file, "ga")
path = fit.trajectory

fig, (ax_map, ax_speed) = plt.subplots(1, 2, figsize=(10, 4.2))
ax_map.plot(path.position_ned_m[:, 1] / 1e3, path.position_ned_m[:, 0] / 1e3, label="flyable path")
fixes_km = fit.fix_position_ned_m / 1e3
ax_map.scatter(fixes_km[:, 1], fixes_km[:, 0], s=8, c="k", label="ADS-B fixes")
ax_map.set(xlabel="east [km]", ylabel="north [km]", aspect="equal", title="plan view")
ax_map.legend()
ax_speed.plot(
    path.time_s, np.hypot(path.velocity_ned_mps[:, 0], path.velocity_ned_mps[:, 1]), label="flyable path"
)
if fit.fix_velocity_ned_mps is not None:
    reported = np.hypot(fit.fix_velocity_ned_mps[:, 0], fit.fix_velocity_ned_mps[:, 1])
    ax_speed.scatter(fit.fix_time_s, reported, s=8, c="k", label="reported ground speed")
step = np.linalg.norm(np.diff(fit.fix_position_ned_m[:, :2], axis=0), axis=1) / np.diff(fit.fix_time_s)
ax_speed.scatter(fit.fix_time_s[1:], step, s=10, marker="x", c="tab:red", label="fix to fix")
ax_speed.set(xlabel="time [s]", ylabel="ground speed [m/s]", title="horizontal speed")
ax_speed.legend(fontsize=8)
fig.tight_layout()
plt.show()

# %%
# The scenario flies the fixes file (scenario time 0 at its first fix). A crossing intruder would
# pass 150 m from the own-ship 160 s in; the radar runs the 20 s before, from 130 s, at 4.7 frames
# per second. No terrain: clear sky.
scenario = {
    "name": "recorded own-ship",
    "ownship": {"type": "file", "path": str(fixes_file)},
    "intruders": [
        {
            "name": "crossing",
            "type": "encounter",
            "kind": "crossing",
            "t_cpa_s": 160.0,
            "horizontal_miss_m": 150.0,
            "rcs_m2": 2.0,
        },
    ],
    "start_s": 130.0,
    "duration_s": 20.0,
    "frame_rate_hz": 4.7,
}
built = Scenario.from_dict(scenario).build()
out = run_chain(built, RADAR_ALERT_CONFIG)
labels = label_tracks(out["tracks"], out["truth"])
print(f"{len(out['detections'])} detections; tracks and what they follow: {labels}")
warnings = out["alerts"].query("level == 3").sort_values("time_s")
if len(warnings):
    first = warnings.iloc[0]
    print(f"first warning at {first['time_s']:.1f} s, {first['range_m']:.0f} m away")

# %%
# The intruder's confirmed track against its truth: seen from above (scenario NED frame, origin at
# the first fix) and in range over time.
truth = out["truth"]
times_s = built.times_s
tracks = out["tracks"].query("confirmed")
fig, (ax_map, ax_range) = plt.subplots(1, 2, figsize=(10, 4.2))
ax_map.plot(truth["own_east_m"], truth["own_north_m"], "k", label="own-ship")
for name in truth["target"].values:
    target = truth.sel(target=name)
    ax_map.plot(target["tgt_east_m"], target["tgt_north_m"], "--", label=f"{name}: truth")
    ax_range.plot(times_s, target["tgt_range_m"] / 1e3, "--", label=f"{name}: truth")
for track_id, rows in tracks.groupby("track_id"):
    label = f"track {track_id} ({labels.get(track_id, 'unlabelled')})"
    ax_map.plot(rows["east_m"], rows["north_m"], ".", ms=4, label=label)
    ax_range.plot(rows["time_s"], rows["range_m"] / 1e3, ".", ms=4, label=label)
ax_map.set(xlabel="east [m]", ylabel="north [m]", aspect="equal", title="track and truth")
ax_range.set(xlabel="time [s]", ylabel="range [km]", title="range from the own-ship")
ax_map.legend(fontsize=8)
ax_range.legend(fontsize=8)
fig.tight_layout()
plt.show()
