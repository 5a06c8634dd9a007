"""Speed benchmarks: each ``run() -> dict`` measures our code and a baseline in the same run."""
