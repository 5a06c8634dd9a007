"""The world the radar looks at: terrain, own-ship and intruder trajectories, scenario files."""
