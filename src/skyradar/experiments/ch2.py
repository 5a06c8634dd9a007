"""ch2: the simulator's published behaviour, measured on simulated frames against closed form.

Own aircraft 1000 m over flat ground at 30 m/s with a forward antenna (the shipped scenario
``ch2_flat_forward.yaml``): ground returns are bounded by the asymptotes R = H and V = -speed;
a head-on intruder 2000 m ahead closing at 60 m/s appears aliased near +18 m/s. At 60 m/s the
ground return wraps to the right edge of the image.

Measurements come from the noisy image: ground pixels are those 12 dB over the noise floor;
per range bin the most negative ground velocity traces v(r) = -V sqrt(1 - (H/r)^2), and a least
squares fit of v^2 = V^2 - V^2 H^2 / r^2 gives both asymptotes.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import yaml

from skyradar.config import RadarConfig
from skyradar.errors import InputError
from skyradar.experiments.summary_md import number, page, write_summary
from skyradar.io.atomic import write_csv_atomic
from skyradar.io.json_results import write_json_atomic
from skyradar.scene.scenario import Scenario, example_scenario
from skyradar.sim.scenario_frames import make_simulator, scenario_truth, simulate_frames
from skyradar.viz.rangedoppler import save_frame_figure, strength_db

__all__ = ["run", "fit_asymptotes", "summary_markdown"]

GROUND_DB = 12.0
SLOW_MPS, FAST_MPS = 30.0, 60.0  # own-ship speeds: the ground inside the image, and wrapped past -VLim


def _built(speed_mps: float, n_frames: int):
    path = example_scenario("ch2_flat_forward")
    data = yaml.safe_load(path.read_text())
    data["ownship"]["speed_mps"] = speed_mps
    data["duration_s"] = n_frames / data["frame_rate_hz"]
    if speed_mps != 30.0:  # keep the intruder 2000 m ahead at t = 0, closing at speed + 30
        data["intruders"][0]["t_cpa_s"] = 2000.0 / (speed_mps + data["intruders"][0]["intruder_speed_mps"])
    return Scenario.from_dict(data, source=path).build()


def fit_asymptotes(ground: np.ndarray, config: RadarConfig) -> tuple[float, float]:
    """Fit (H, V) of v(r) = -V sqrt(1 - (H/r)^2) to the fastest-closing ground per range bin."""
    rows = np.nonzero(ground.any(axis=1))[0]
    r = config.range_axis_m[rows]
    v = config.doppler_axis_mps[np.argmax(ground[rows], axis=1)]  # first True column = most negative
    use = r > r.min() + 10 * config.range_resolution_m  # skip the steep corner next to R = H
    design = np.column_stack([np.ones(use.sum()), 1.0 / r[use] ** 2])
    (a, b), *_ = np.linalg.lstsq(design, v[use] ** 2, rcond=None)
    return float(np.sqrt(-b / a)), float(np.sqrt(a))


def _intruder_pixel(
    frame: np.ndarray, config: RadarConfig, min_velocity: float
) -> tuple[float, float, float]:
    db = strength_db(frame, config)
    db[:, config.doppler_axis_mps < min_velocity] = -np.inf
    k, j = np.unravel_index(np.argmax(db), db.shape)
    return float(config.range_axis_m[k]), float(config.doppler_axis_mps[j]), float(db[k, j])


def _case(speed: float, n_frames: int) -> dict[str, Any]:
    built = _built(speed, n_frames)
    simulator = make_simulator(built)
    simulate_frames(built, np.array([0]), simulator)  # compile and warm up
    start = time.perf_counter()
    frames = simulate_frames(built, np.arange(n_frames), simulator)
    fps = n_frames / (time.perf_counter() - start)
    _, targets, _ = scenario_truth(built, simulator)
    return {"built": built, "frames": frames, "fps": fps, "truth": targets}


# Both cases hold their frames in memory (2.7 MB each for the prototype): 200 per case is about 1 GB.
MAX_FRAMES_PER_CASE = 200


def _slow_case_measures(slow: dict) -> dict[str, Any]:
    """30 m/s case: the ground's near-range and velocity asymptotes, and the intruder's pixel."""
    cfg = slow["built"].radar
    frame = slow["frames"][0]
    ground = strength_db(frame, cfg) > GROUND_DB
    ground[:, cfg.doppler_axis_mps > cfg.doppler_resolution_mps] = False  # ground never recedes at 30 m/s
    first_ground = float(cfg.range_axis_m[np.nonzero(ground.any(axis=1))[0].min()])
    h_fit, v_fit = fit_asymptotes(ground, cfg)
    tgt_r, tgt_v, tgt_db = _intruder_pixel(frame, cfg, 5.0)
    true_r = float(slow["truth"]["tgt_range_m"][0, 0])
    true_v = float(slow["truth"]["tgt_radial_velocity_mps"][0, 0])
    k_exp, j_exp = int(cfg.range_bin(true_r, true_v)), int(cfg.doppler_bin(true_v))
    return {
        "asymptote_range_m": h_fit,
        "asymptote_range_expected_m": 1000.0,
        "first_ground_range_m": first_ground,
        "asymptote_velocity_mps": -v_fit,
        "asymptote_velocity_expected_mps": -30.0,
        "intruder_range_m": tgt_r,
        "intruder_velocity_mps": tgt_v,
        "intruder_snr_db": tgt_db,
        "intruder_expected_range_m": float(cfg.range_axis_m[k_exp]),
        "intruder_expected_velocity_mps": float(cfg.doppler_axis_mps[j_exp]),
        "intruder_true_radial_velocity_mps": true_v,
    }


def _wrap_measures(fast: dict, cfg) -> dict[str, Any]:
    """60 m/s case: the ground wraps past -VLim and reappears at the right edge of the image."""
    fast_ground = strength_db(fast["frames"][0], cfg) > GROUND_DB
    fast_ground[:, cfg.doppler_axis_mps <= cfg.doppler_resolution_mps] = False  # wrapped: right of zero
    wrapped = np.nonzero(fast_ground.any(axis=0))[0]
    wrap_min = float(cfg.doppler_axis_mps[wrapped.min()]) if wrapped.size else float("nan")
    wrap_expected = -60.0 * np.sqrt(1 - (1000.0 / cfg.range_axis_m[-1]) ** 2) + 2 * cfg.v_lim_mps
    return {
        "wrap60_right_edge": bool(wrapped.size and wrapped.max() == cfg.n_doppler - 1),
        "wrap60_min_velocity_mps": wrap_min,
        "wrap60_expected_min_velocity_mps": float(wrap_expected),
    }


def run(out_dir: str | Path = "out/ch2", n_frames: int = 3) -> dict[str, Any]:
    """Simulate the ch2 cases, write figures and the table, return the measured values.

    ``n_frames`` (1 to :data:`MAX_FRAMES_PER_CASE`) frames per case; more is refused before any
    work (``--frames 10**20`` was reported as the scenario's ``duration_s``).
    """
    if not 1 <= n_frames <= MAX_FRAMES_PER_CASE:
        raise InputError(f"--frames: must be an integer >= 1 and <= {MAX_FRAMES_PER_CASE}, got {n_frames!r}")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    slow, fast = _case(SLOW_MPS, n_frames), _case(FAST_MPS, n_frames)
    cfg = slow["built"].radar
    result = _slow_case_measures(slow) | _wrap_measures(fast, cfg)
    result |= {"range_bin_m": cfg.range_resolution_m, "doppler_bin_mps": cfg.doppler_resolution_mps}
    result |= {"frames_per_s": slow["fps"], "thesis_frames_per_s": 3.3}
    _figures(out, slow, fast, result)
    r = result
    table = pd.DataFrame(
        [
            ("near-range asymptote R [m]", r["asymptote_range_m"], 1000.0),
            ("velocity asymptote V [m/s]", r["asymptote_velocity_mps"], -30.0),
            ("intruder range [m]", r["intruder_range_m"], r["intruder_expected_range_m"]),
            (
                "intruder radial velocity (aliased) [m/s]",
                r["intruder_velocity_mps"],
                r["intruder_expected_velocity_mps"],
            ),
            (
                "60 m/s: wrapped ground starts at [m/s]",
                r["wrap60_min_velocity_mps"],
                r["wrap60_expected_min_velocity_mps"],
            ),
        ],
        columns=["quantity", "measured", "closed_form"],
    )
    write_csv_atomic(table, out / "ch2_table.csv", index=False)
    write_json_atomic(out / "ch2.json", result)
    write_summary(out, summary_markdown(result, out))
    return result


_FILES = {
    "ch2_flat_30mps.png": "the range-Doppler image at 30 m/s with both asymptotes and the intruder marked",
    "ch2_flat_60mps.png": "the range-Doppler image at 60 m/s, the ground wrapped to the right edge",
    "ch2_table.csv": "measured against closed form, one row per quantity",
    "ch2.json": "every measured value",
}


def summary_markdown(result: dict[str, Any], out_dir: Path | None = None) -> str:
    """``summary.md`` of a ch2 run: the asymptotes, the aliased intruder and the wrap against closed form.

    Parameters
    ----------
    result : dict
        The summary :func:`run` returns (also in ``ch2.json``).
    out_dir : Path, optional
        The run's folder: only the files present there are listed (None: all of them).

    Returns
    -------
    str
        Markdown: title, sentences, a table of measured against closed form, the files.

    Examples
    --------
    >>> r = {"asymptote_range_m": 1001.2, "asymptote_range_expected_m": 1000.0,
    ...      "first_ground_range_m": 996.1, "asymptote_velocity_mps": -30.1,
    ...      "asymptote_velocity_expected_mps": -30.0, "intruder_range_m": 1995.0,
    ...      "intruder_velocity_mps": 18.3, "intruder_snr_db": 31.0, "intruder_expected_range_m": 1995.0,
    ...      "intruder_expected_velocity_mps": 18.3, "intruder_true_radial_velocity_mps": -60.0,
    ...      "wrap60_right_edge": True, "wrap60_min_velocity_mps": 15.2,
    ...      "wrap60_expected_min_velocity_mps": 15.0, "range_bin_m": 3.75, "doppler_bin_mps": 0.61,
    ...      "frames_per_s": 41.0, "thesis_frames_per_s": 3.3}
    >>> text = summary_markdown(r)
    >>> print(text.splitlines()[0])
    # ch2: the simulator against closed form
    >>> "| near-range asymptote R [m] | 1001.2 | 1000.0 |" in text, "`ch2_flat_60mps.png`" in text
    (True, True)
    """
    r = result
    paragraphs = [
        f"Own aircraft {number(r['asymptote_range_expected_m'], 0)} m over flat ground with a forward "
        f"antenna, flying at {number(SLOW_MPS, 0)} m/s and at {number(FAST_MPS, 0)} m/s; the first simulated "
        "frame of each, measured on the noisy image against closed form. "
        f"At {number(SLOW_MPS, 0)} m/s the ground's near-range asymptote fits at "
        f"{number(r['asymptote_range_m'])} m "
        f"(closed form {number(r['asymptote_range_expected_m'])} m, one range bin "
        f"{number(r['range_bin_m'], 2)} m) and its velocity asymptote at "
        f"{number(r['asymptote_velocity_mps'])} m/s (closed form "
        f"{number(r['asymptote_velocity_expected_mps'])} m/s). The head-on intruder, at a true radial "
        f"velocity of {number(r['intruder_true_radial_velocity_mps'])} m/s, shows aliased at "
        f"{number(r['intruder_velocity_mps'])} m/s and {number(r['intruder_range_m'])} m, "
        f"{number(r['intruder_snr_db'])} dB over the noise (closed-form pixel: "
        f"{number(r['intruder_expected_velocity_mps'])} m/s, {number(r['intruder_expected_range_m'])} m).",
        f"At {number(FAST_MPS, 0)} m/s the ground "
        f"{'wraps' if r['wrap60_right_edge'] else 'does not wrap'} to the right edge of the image, "
        "the wrapped part starting at "
        f"{number(r['wrap60_min_velocity_mps'])} m/s (closed form "
        f"{number(r['wrap60_expected_min_velocity_mps'])} m/s). The simulator ran "
        f"{number(r['frames_per_s'])} frames per second (the thesis' simulator: "
        f"{number(r['thesis_frames_per_s'])}). Look at the two images for the asymptotes and the wrap.",
    ]
    rows = [
        ["near-range asymptote R [m]", r["asymptote_range_m"], r["asymptote_range_expected_m"]],
        ["velocity asymptote V [m/s]", r["asymptote_velocity_mps"], r["asymptote_velocity_expected_mps"]],
        ["intruder range [m]", r["intruder_range_m"], r["intruder_expected_range_m"]],
        [
            "intruder radial velocity, aliased [m/s]",
            r["intruder_velocity_mps"],
            r["intruder_expected_velocity_mps"],
        ],
        [
            "60 m/s: wrapped ground starts at [m/s]",
            r["wrap60_min_velocity_mps"],
            r["wrap60_expected_min_velocity_mps"],
        ],
        ["simulated frames per second", r["frames_per_s"], f"{number(r['thesis_frames_per_s'])} (thesis)"],
    ]
    header = ["quantity", "measured", "closed form or thesis"]
    return page("ch2: the simulator against closed form", paragraphs, header, rows, _FILES, out_dir)


def _figures(out: Path, slow: dict, fast: dict, result: dict[str, Any]) -> None:
    cfg = slow["built"].radar
    save_frame_figure(
        slow["frames"][0],
        cfg,
        out / "ch2_flat_30mps.png",
        title="1000 m, 30 m/s:",
        markers=[(result["intruder_velocity_mps"], result["intruder_range_m"], "head-on intruder (aliased)")],
        hlines=[(1000.0, "R = H = 1000 m")],
        vlines=[(-30.0, "V = -30 m/s")],
    )
    save_frame_figure(
        fast["frames"][0],
        cfg,
        out / "ch2_flat_60mps.png",
        title="1000 m, 60 m/s:",
        hlines=[(1000.0, "R = H")],
        vlines=[(-60.0 + 2 * cfg.v_lim_mps, "V = -60 m/s, wrapped")],
    )
