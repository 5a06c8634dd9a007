"""
Reading alerts and advice, and opening the live display
=======================================================

``skyradar alert`` writes one row per track per frame: the alert level the pilot is shown, the
conflict geometry it comes from, and on every frame with an alert the advice of that frame (the
headings and vertical speeds to avoid, and one preferred manoeuvre). This example runs an
encounter with two intruders through the chain, reads that table column by column, draws the
advice over time, and starts the live display (``skyradar serve``) on the run to fetch what its
page shows.
Every column is listed with its unit in :ref:`tables-alerts`; the rules behind the levels are in
:doc:`/how-it-works/alerting`.
"""

import importlib.util
import json
import tempfile
import urllib.request
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from skyradar.chain import label_tracks, track_and_alert
from skyradar.daa.alerting import RADAR_ALERT_CONFIG
from skyradar.io.frames import open_frames
from skyradar.io.tables import write_table
from skyradar.process.pipeline import process_frames
from skyradar.scene.scenario import Scenario
from skyradar.sim.simulate_store import simulate_to_zarr

# %%
# The encounter: own-ship flies north at 50 m/s, 1000 m above the sea-level origin. ``head-on``
# comes the other way at 50 m/s and would pass 100 m aside 30 s into the run; ``crossing`` comes
# from the right 150 m higher and passes 1.5 km ahead. No terrain: clear sky.
scenario = {
    "name": "alerts example",
    "origin": {"lat_deg": 52.0, "lon_deg": 5.0, "alt_m": 0.0},
    "duration_s": 30.0,
    "frame_rate_hz": 4.7,
    "ownship": {"type": "straight", "start_ned_m": [0, 0, -1000], "heading_deg": 0, "speed_mps": 50},
    "intruders": [
        {
            "name": "head-on",
            "type": "encounter",
            "kind": "head-on",
            "t_cpa_s": 30,
            "intruder_speed_mps": 50,
            "horizontal_miss_m": 100,
            "rcs_m2": 2.0,
        },
        {
            "name": "crossing",
            "type": "encounter",
            "kind": "crossing",
            "t_cpa_s": 30,
            "intruder_speed_mps": 40,
            "horizontal_miss_m": 1500,
            "vertical_miss_m": 150,
            "rcs_m2": 2.0,
        },
    ],
}
built = Scenario.from_dict(scenario).build()

# %%
# The chain as the command line runs it: ``skyradar simulate`` writes the frames store the
# display replays, ``skyradar process`` finds the detections, ``skyradar track`` and ``skyradar
# alert`` (here one call, :func:`~skyradar.chain.track_and_alert`, with the settings
# ``--config radar`` names) make the tracks and the alerts.
folder = Path(tempfile.mkdtemp())
run_path = simulate_to_zarr(built, folder / "run.zarr")
run = open_frames(run_path)
detections = process_frames(run, source=str(run_path))
out = track_and_alert(detections, built, alert_config=RADAR_ALERT_CONFIG, truth=run)
alerts, tracks = out["alerts"], out["tracks"]
names = label_tracks(tracks, run)  # the intruder each track follows, from the run's truth
write_table(alerts, folder / "alerts.parquet")
print(f"{len(detections)} detections, {tracks['track_id'].nunique()} tracks: {names}")

# %%
# Levels and geometry
# -------------------
# ``level`` is what the pilot is shown: 0 none, 1 preventive, 2 corrective, 3 warning, after
# the persistence filter and the hold; ``raw_level`` is what this frame's geometry alone gives.
# The geometry columns say why: ``t_in_s`` is the predicted time to the loss of well clear,
# ``tcpa_s`` the time to the horizontal closest approach, ``hmd_m`` and ``vmd_m`` the horizontal
# and vertical miss there. ``bearing_deg`` (positive right), ``sector`` (clock position, 0 ahead)
# and ``rel_alt_m`` place the intruder as a traffic display would. Below: each track's first row
# at each level it reached.
geometry = ["time_s", "track_id", "level", "raw_level", "t_in_s", "tcpa_s", "hmd_m", "vmd_m"]
geometry += ["range_m", "bearing_deg", "sector", "rel_alt_m"]
firsts = alerts.sort_values("time_s").drop_duplicates(["track_id", "level"])
firsts = firsts.sort_values(["track_id", "time_s"])[geometry]
firsts.insert(2, "intruder", firsts["track_id"].map(lambda t: names.get(t, "clutter")))
print(firsts.round(1).to_string(index=False))

# %%
# Advice
# ------
# On a frame where some track alerts, every row of that frame carries the frame's advice:
# ``heading_bands_deg`` and ``vs_bands_mps`` are the headings (same speed) and vertical speeds
# (same horizontal velocity) that would lose well clear with some intruder within the lookahead,
# flattened as ``[lo0, hi0, lo1, hi1, ...]``; ``terrain_vs_bands_mps`` are those that come too
# close to the ground (none here: over clear sky there is no height above ground);
# ``preferred_heading_deg`` and ``preferred_vs_mps`` are the one manoeuvre advised, the Modified
# Voltage Potential resolution moved to the nearest candidate outside every band. A heading band
# that crosses north ends above 360 deg: ``[330, 420]`` is 330 deg through north to 60 deg. When
# every candidate conflicts, the band spans the whole scale and the preferred value is the
# candidate that loses well clear last: no manoeuvre of that kind keeps well clear any more, and
# that one buys the most time. Here is the advice of the first warning frame.
advice_columns = ["heading_bands_deg", "vs_bands_mps", "preferred_heading_deg", "preferred_vs_mps"]
per_frame = alerts[alerts["level"] > 0].drop_duplicates("time_s").set_index("time_s")[advice_columns]
first_warning_s = float(alerts.loc[alerts["level"] == 3, "time_s"].min())
advice = per_frame.loc[first_warning_s]


def intervals(flat):
    """Bands ``[lo0, hi0, lo1, hi1, ...]`` as a list of (lo, hi) pairs."""
    flat = [float(x) for x in flat]
    return list(zip(flat[0::2], flat[1::2], strict=True))


print(f"first warning at t = {first_warning_s:.1f} s")
print("heading bands [deg]:", [(round(lo), round(hi)) for lo, hi in intervals(advice["heading_bands_deg"])])
print(
    "vertical-speed bands [m/s]:",
    [(round(lo, 1), round(hi, 1)) for lo, hi in intervals(advice["vs_bands_mps"])],
)
print(f"preferred heading {advice['preferred_heading_deg']:.0f} deg")
print(f"preferred vertical speed {advice['preferred_vs_mps']:.1f} m/s")

# %%
# The whole encounter: each track's issued level over time, and the advice of every frame with an
# alert, the bands in red and the preferred manoeuvre in black. The heading band holds the
# headings that keep closing on the head-on intruder and widens as it comes nearer, until no
# turn at this speed keeps well clear. Every vertical speed the advice considers (up to 10 m/s
# either way) loses the 450 ft vertical separation before the closest approach, so the vertical
# band is full from the first warning, and the preferred vertical speed is the one that loses
# well clear last.
fig, (ax_level, ax_heading, ax_vs) = plt.subplots(3, 1, figsize=(7, 8), sharex=True)
for track_id, rows in alerts.groupby("track_id"):
    ax_level.step(
        rows["time_s"],
        rows["level"],
        where="post",
        label=f"track {track_id} ({names.get(track_id, 'clutter')})",
    )
ax_level.set(ylabel="issued level", yticks=[0, 1, 2, 3], ylim=(-0.2, 3.2))
ax_level.set_yticklabels(["none", "preventive", "corrective", "warning"])
ax_level.legend(loc="upper left", fontsize=8)
frame_dt = 1.0 / scenario["frame_rate_hz"]
for time_s, row in per_frame.iterrows():
    for lo, hi in intervals(row["heading_bands_deg"]):
        # A band across north, [lo, hi > 360], is drawn as [lo, 360] and [0, hi - 360].
        for bottom, top in ((lo, min(hi, 360.0)), (0.0, hi - 360.0)):
            if top > bottom:
                ax_heading.bar(
                    time_s, top - bottom, bottom=bottom, width=frame_dt, color="tab:red", alpha=0.5
                )
    for lo, hi in intervals(row["vs_bands_mps"]):
        ax_vs.bar(time_s, hi - lo, bottom=lo, width=frame_dt, color="tab:red", alpha=0.5, linewidth=0)
ax_heading.plot(per_frame.index, per_frame["preferred_heading_deg"], "k.", ms=3, label="preferred")
ax_vs.plot(per_frame.index, per_frame["preferred_vs_mps"], "k.", ms=3)
ax_heading.set(ylabel="heading [deg]", ylim=(0, 360), yticks=[0, 90, 180, 270, 360])
ax_heading.legend(loc="upper left", fontsize=8)
ax_vs.set(ylabel="vertical speed [m/s]", xlabel="time [s]")
fig.suptitle("issued levels, and the bands to avoid on each alerting frame")
fig.tight_layout()
plt.show()

# %%
# The live display
# ----------------
# ``skyradar serve run.zarr --alerts alerts.parquet`` opens the display on this run: a plan view of
# the traffic coloured by level, the advice as bands on a heading and a vertical-speed scale, and
# each frame's range-Doppler image, replayed at the run's pace (``--speed`` faster). It binds to
# 127.0.0.1 and prints the address to open in a browser; Ctrl-C stops it. Without ``--alerts`` it
# alerts the tracks given with ``--tracks``, or the run's intruder truth.
#
# :func:`~skyradar.web.server.create_app` builds the same app in Python, and
# :func:`~skyradar.web.server.serve_in_thread` runs it in the background until the ``with`` block
# ends, so a script (or this page's build) can read what the page reads: ``/api/info`` for the
# run and ``/api/frame/N`` for a frame (``?image=false`` leaves out its image). The display needs
# the ``web`` extra (``pip install skyradar[web]``).
print(f"in {folder}: skyradar serve run.zarr --alerts alerts.parquet")


def rounded(value):
    """``value`` with every float rounded to 0.1, for reading."""
    if isinstance(value, dict):
        return {key: rounded(item) for key, item in value.items()}
    if isinstance(value, list):
        return [rounded(item) for item in value]
    return round(value, 1) if isinstance(value, float) else value


if importlib.util.find_spec("fastapi") and importlib.util.find_spec("uvicorn"):
    from skyradar.web.server import create_app, serve_in_thread

    app = create_app(run_path, alerts_path=folder / "alerts.parquet", autoplay=False)
    with serve_in_thread(app) as url:
        with urllib.request.urlopen(f"{url}/api/info", timeout=10) as response:
            info = json.load(response)
        index = int(np.argmin(np.abs(np.asarray(info["times_s"]) - first_warning_s)))
        with urllib.request.urlopen(f"{url}/api/frame/{index}?image=false", timeout=10) as response:
            shown = json.load(response)
    print(f"{info['run']}: {info['n_total']} frames, traffic from the {info['traffic_source']} table")
    payload = {k: shown[k] for k in ("time_s", "max_level", "ownship", "traffic", "advice")}
    print(json.dumps(rounded(payload), indent=1))
else:
    print("the live display needs the web extra: pip install skyradar[web]")
