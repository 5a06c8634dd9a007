"""
The demo: a circuit over hills with three intruders, and its report
====================================================================

``skyradar demo`` (or ``make demo``) flies the embedded scenario
``skyradar/data/scenarios/demo_circuit.yaml`` through the whole chain: own-ship on a left-hand
airfield circuit over seeded fractal hills, an intruder on a collision course from the left, a
jet head-on 1.1 km aside whose closing speed aliases in Doppler, and a glider circling well
clear. It simulates the radar frames, detects and locates, tracks, alerts, and writes a report
folder: ``index.html`` (a summary in words, the figures, the alert timeline and the advice) beside
the tables it rests on (``detections.parquet``, ``tracks.parquet``, ``alerts.parquet``,
``alert_timeline.csv``, ``summary.json``).

The command is :func:`skyradar.demo.run_demo`, which also takes a scenario of your own. Here it
runs the demo scenario cut to its first 22 s (the command flies 60 s), long enough for the
collision intruder's warning and short enough for a documentation build.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import pandas as pd
import yaml

from skyradar.demo import demo_scenario_path, run_demo
from skyradar.viz.report import intruder_outcomes, summary_sentences

# %%
# The scenario is a YAML file: every key is in the scenario reference. A copy with a shorter
# ``duration_s`` is the demo's first 22 s.
scenario = yaml.safe_load(demo_scenario_path().read_text())
print(yaml.safe_dump({k: scenario[k] for k in ("origin", "terrain", "ownship")}, sort_keys=False))
print("intruders:", [intruder["name"] for intruder in scenario["intruders"]])
folder = Path(tempfile.mkdtemp())
scenario["duration_s"] = 22.0
short = folder / "demo_22s.yaml"
short.write_text(yaml.safe_dump(scenario, sort_keys=False))

# %%
# ``run_demo`` writes the report folder and returns the summary the report opens with: the same
# sentences as the top of ``index.html``.
report = folder / "report"
summary = run_demo(report, scenario=short)
timeline = pd.read_csv(report / "alert_timeline.csv")
for line in summary_sentences(summary, intruder_outcomes(summary, timeline), scenario["duration_s"]):
    print(line)
print(sorted(p.name for p in report.iterdir()))

# %%
# The alert timeline lists every change of a track's issued level (0 none, 1 preventive,
# 2 corrective, 3 warning) with the geometry at that moment and the advice: the preferred
# heading (deg) and vertical speed (m/s, positive up). A direction that rests on a 2 x 2 array
# over hills has an elevation that is not trusted (``altitude_measured`` false); the alert then
# assumes the intruder may be at the own-ship's height.
print(timeline.round(1).to_string(index=False))

# %%
# The report's figures: the plan view (each confirmed track against the truth, warnings marked)
# and each track's alert level over time.
fig, axes = plt.subplots(1, 2, figsize=(11, 4.6))
for ax, name in zip(axes, ("plan_view.png", "alert_timeline.png"), strict=True):
    ax.imshow(plt.imread(report / name))
    ax.set_axis_off()
    ax.set_title(name)
fig.tight_layout()
plt.show()
