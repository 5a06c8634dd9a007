"""
Your own recording: raw ADC frames in, detections out
=====================================================

A radar you built or bought writes its ADC samples to a file of its own. To bring them to
skyradar, put a small sidecar (JSON or YAML, the ``skyradar-adc/1`` format of
:mod:`skyradar.io.recordings`) beside the samples: how they lie on disk (``dtype``, ``shape``, the
order of the ``axes``) and what the radar is (sample rate, carrier, sweep, chirp rate).
``skyradar rd`` turns the recording into the same range-Doppler frames store the simulator
writes, so every later stage (``skyradar process``, ``track``, ``serve``) reads it as it reads a
simulated run. A recording already in SigMF (``NAME.sigmf-meta`` and ``NAME.sigmf-data``) needs
no sidecar: see the SigMF example; a passive receiver's SigMF recording goes to ``skyradar
passive`` instead (the passive radar guide).

Here "your radar" is simulated at chirp level (:func:`skyradar.sim.raw.simulate_adc`): three
frames with two aircraft in front of it, quantised to 16-bit I/Q as an ADC would, and written in
the radar's own axis order, chirp before channel.
"""

import json
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from skyradar.config import RadarConfig
from skyradar.io.frames import open_frames
from skyradar.io.recordings import read_recording
from skyradar.process.pipeline import process_frames
from skyradar.process.rd_store import recording_to_frames
from skyradar.sim.raw import simulate_adc

# %%
# The radar: the thesis prototype's sweep (10 MHz ADC, 9.425 GHz carrier, 10 MHz per chirp, 4921
# chirps per second, four receive channels) with 128 chirps per frame. Two aircraft in the antenna
# frame (x forward, y right, z down): one 1.5 km ahead closing at 30 m/s, one 2 km away 15 deg
# left, moving away at 12 m/s.
radar = RadarConfig.prototype_2022(n_doppler=128)
positions_m = np.array([[1500.0, 100.0, 0.0], [1932.0, -518.0, -50.0]])
line_of_sight = positions_m / np.linalg.norm(positions_m, axis=1, keepdims=True)
radial_mps = np.array([-30.0, 12.0])
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
)  # (frame, rx, chirp, sample), sqrt(W) at the ADC

# %%
# On disk as the radar writes it: 16-bit I/Q pairs, axes in the order (frame, chirp, rx, sample),
# one count worth ``scale`` sqrt(W). The sidecar is all skyradar needs to read the file.
folder = Path(tempfile.mkdtemp())
scale = float(np.abs(frames).std()) / 300.0  # the noise at about 300 counts
counts = np.moveaxis(frames, 2, 1) / scale  # (frame, chirp, rx, sample)
pairs = np.stack([counts.real, counts.imag], axis=-1)
np.round(pairs).clip(-32768, 32767).astype("<i2").tofile(folder / "my_radar.bin")
sidecar = {
    "format": "skyradar-adc/1",
    "data_file": "my_radar.bin",
    "dtype": "complex_int16",
    "shape": list(counts.shape),
    "axes": ["frame", "chirp", "rx", "sample"],
    "sample_rate_hz": radar.fs_hz,
    "fc_hz": radar.fc_hz,
    "bandwidth_hz": radar.bandwidth_hz,
    "prf_hz": radar.prf_hz,
    "scale": scale,
    "frame_period_s": frame_period_s,
}
lines = [f"  {json.dumps(key)}: {json.dumps(value)}" for key, value in sidecar.items()]
(folder / "my_radar.json").write_text("{\n" + ",\n".join(lines) + "\n}\n")
print((folder / "my_radar.json").read_text())

# %%
# :func:`~skyradar.io.recordings.read_recording` checks every field against the data file (a
# wrong shape, dtype or missing field is refused, naming it) and serves the frames lazily in
# skyradar's order (frame, rx, chirp, sample), scaled back to sqrt(W).
recording, config = read_recording(folder / "my_radar.json")
print(recording.shape, recording.times_s, f"range bins of {config.range_resolution_m:.1f} m")

# %%
# ``skyradar rd my_radar.json -o run.zarr`` is :func:`~skyradar.process.rd_store.recording_to_frames`;
# ``skyradar process run.zarr -o detections.parquet`` is
# :func:`~skyradar.process.pipeline.process_frames` on the opened store. The recording carries no
# own-ship navigation, so the detections have range, radial velocity and direction of arrival, and
# no world position.
summary = recording_to_frames(folder / "my_radar.json", folder / "run.zarr")
run = open_frames(folder / "run.zarr")
detections = process_frames(run)
print({key: summary[key] for key in ("frames", "n_range", "n_doppler", "n_rx")})
shown = detections[["frame", "range_m", "radial_velocity_mps", "snr_db", "azimuth_rad"]].copy()
shown["azimuth_rad"] = np.degrees(shown["azimuth_rad"])
shown = shown.rename(columns={"azimuth_rad": "azimuth_deg"}).astype({"snr_db": float, "azimuth_deg": float})
print(shown.round(1).to_string())

# %%
# The first frame's channel-mean power over range and radial velocity, relative to its median
# (the noise floor), with the frame's detections and the two aircraft's true range and radial
# velocity.
cube = run["iq"].isel(time=0).values
power_db = 10.0 * np.log10(np.mean(np.abs(cube) ** 2, axis=2))
power_db -= np.median(power_db)
velocity, range_km = config.doppler_axis_mps, config.range_axis_m / 1000.0
fig, ax = plt.subplots(figsize=(7, 4))
extent = [velocity[0], velocity[-1], range_km[-1], range_km[0]]
image = ax.imshow(power_db, aspect="auto", extent=extent, cmap="viridis", vmin=0.0, vmax=20.0)
first = detections.query("frame == 0")
ax.scatter(
    first["radial_velocity_mps"],
    first["range_m"] / 1000.0,
    s=120,
    facecolors="none",
    edgecolors="red",
    linewidths=1.5,
    label="detections",
)
true_range_km = np.linalg.norm(positions_m, axis=1) / 1000.0
ax.scatter(
    radial_mps,
    true_range_km,
    marker="s",
    s=400,
    facecolors="none",
    edgecolors="white",
    label="aircraft (truth)",
)
ax.set(xlabel="radial velocity [m/s]", ylabel="range [km]", title="frame 0 of my_radar.bin", ylim=(3.0, 0.0))
ax.legend(loc="lower right")
fig.colorbar(image, label="power over the noise floor [dB]")
plt.show()
