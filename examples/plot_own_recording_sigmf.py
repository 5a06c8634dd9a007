"""
Your own recording as SigMF: detections from a ``.sigmf-meta`` / ``.sigmf-data`` pair
======================================================================================

`SigMF <https://sigmf.org>`_ is the open format of software-defined radio recordings: the samples
in ``NAME.sigmf-data`` and a JSON description in ``NAME.sigmf-meta``. An FMCW radar's ADC stream
fits it as it is: every receive channel's samples side by side (SigMF's multichannel layout),
chirp after chirp and frame after frame. SigMF's ``core`` keys give the sample type, the ADC rate,
the channel count and the carrier; the sweep, which SigMF has no words for, goes in skyradar's
namespaced keys (``skyradar:prf_hz``, ``skyradar:bandwidth_hz``, ``skyradar:chirps_per_frame``, all
listed in :mod:`skyradar.io.recording_sigmf`).

``skyradar rd NAME.sigmf-meta -o run.zarr`` reads such a recording as it reads a raw file with a
sidecar (see the example on raw ADC frames), and every later stage works on the frames store it
writes. Here the recording is made by the simulator: three frames of the thesis prototype's sweep
with two aircraft in front of the radar, written by
:func:`~skyradar.io.recording_writer.write_sigmf_recording` as 16-bit I/Q (``ci16_le``).
"""

import json
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from skyradar.config import RadarConfig
from skyradar.io.frames import open_frames
from skyradar.io.recording_writer import write_sigmf_recording
from skyradar.io.recordings import read_recording
from skyradar.process.pipeline import process_frames
from skyradar.process.rd_store import recording_to_frames
from skyradar.sim.raw import simulate_adc
from skyradar.viz.rangedoppler import plot_strength

# %%
# The radar and its scene, in the antenna frame (x forward, y right, z down): an aircraft 1.2 km
# ahead closing at 30 m/s and one 1.8 km away 20 deg right, moving away at 15 m/s. Frames are
# 0.1 s apart; each holds 128 chirps of 2032 samples on four receive channels, in sqrt(W) at
# the ADC.
radar = RadarConfig.prototype_2022(n_doppler=128)
positions_m = np.array([[1200.0, 0.0, -20.0], [1691.0, 616.0, 0.0]])
line_of_sight = positions_m / np.linalg.norm(positions_m, axis=1, keepdims=True)
radial_mps = np.array([-30.0, 15.0])
velocities_mps = line_of_sight * radial_mps[:, None]
frame_period_s = 0.1
frames = np.stack(
    [
        simulate_adc(
            radar,
            positions_m + k * frame_period_s * velocities_mps,
            velocities_mps,
            rcs_m2=[2.0, 1.0],
            seed=k,
        )
        for k in range(3)
    ]
)
print(frames.shape, frames.dtype)

# %%
# Written as SigMF. The writer quantises to 16-bit codes (the largest magnitude at 30000 counts)
# and records the value of one count as ``skyradar:scale``, the samples' SHA-512, and the radar's
# further parameters (antenna pattern, receiver positions, noise figure) in ``skyradar:radar``.
folder = Path(tempfile.mkdtemp())
meta_path = write_sigmf_recording(
    folder / "my_radar",
    frames,
    radar,
    datatype="ci16_le",
    times_s=np.arange(3) * frame_period_s,
    start_time="2026-05-01T10:00:00Z",
)
print(sorted(p.name for p in folder.iterdir()))

# %%
# The description, without the long ``skyradar:radar`` object and the hash. A recording made by
# another program needs only ``core:datatype``, ``core:sample_rate``, ``core:num_channels``, the
# first capture's ``core:frequency``, and ``skyradar:prf_hz``, ``skyradar:bandwidth_hz`` and
# ``skyradar:chirps_per_frame``; the number of frames is what the data file holds.
meta = json.loads(meta_path.read_text())
shown = {k: v for k, v in meta["global"].items() if k not in ("skyradar:radar", "core:sha512")}
print(json.dumps({"global": shown, "captures": meta["captures"]}, indent=1))

# %%
# :func:`~skyradar.io.recordings.read_recording` opens a SigMF recording by either file name or
# the bare stem. Each field is checked against the data file before anything is read: a datatype
# it cannot read, a missing key, or a sample count that is not a whole number of frames is one
# error naming the file, the key and the value.
recording, config = read_recording(meta_path)
print(recording.shape, recording.times_s, f"{config.n_doppler} chirps per frame")

# %%
# ``skyradar rd my_radar.sigmf-meta -o run.zarr`` is
# :func:`~skyradar.process.rd_store.recording_to_frames`; ``skyradar process run.zarr -o
# detections.parquet`` is :func:`~skyradar.process.pipeline.process_frames`. Without own-ship
# navigation in the recording, the detections have range, radial velocity and direction of
# arrival, and no world position.
recording_to_frames(meta_path, folder / "run.zarr")
run = open_frames(folder / "run.zarr")
detections = process_frames(run)
table = detections[["frame", "range_m", "radial_velocity_mps", "snr_db", "azimuth_rad"]].copy()
table["azimuth_deg"] = np.degrees(table.pop("azimuth_rad").astype(float))
print(table.astype({"snr_db": float}).round(1).to_string())

# %%
# The first frame as the chain sees it: strength over the noise floor in range and radial
# velocity (:func:`~skyradar.viz.rangedoppler.plot_strength`), with the frame's detections and the
# two aircraft's true range and radial velocity.
fig, ax = plt.subplots(figsize=(7, 4))
plot_strength(run["iq"].isel(time=0).values, config, ax=ax, vmax=25.0)
first = detections.query("frame == 0")
ax.scatter(
    first["radial_velocity_mps"],
    first["range_m"],
    s=120,
    facecolors="none",
    edgecolors="red",
    linewidths=1.5,
    label="detections",
)
ax.scatter(
    radial_mps,
    np.linalg.norm(positions_m, axis=1),
    marker="s",
    s=400,
    facecolors="none",
    edgecolors="white",
    label="aircraft (truth)",
)
ax.set(title="frame 0 of my_radar.sigmf-data", ylim=(0.0, 2500.0))
ax.legend(loc="upper right")
plt.show()
