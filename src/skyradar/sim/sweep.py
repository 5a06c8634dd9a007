"""Run one scenario over a list of values of one parameter and collect each run's table.

The parameter is a dotted path into the scenario file (``terrain.local_sd_m``,
``intruders.0.rcs_m2``, ``radar.noise_figure_db``...). Each run is simulated frame by frame
(memory bounded, nothing kept unless asked) and summarised by :func:`run_table`: per intruder,
the SNR measured in the simulated frames at the pixel where its truth puts it, and the share of
frames where that pixel stands out of the noise and clutter. Runs go to Dask when a scheduler
or workers are given.
"""

from __future__ import annotations

import copy
import re
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import yaml

from skyradar.errors import InputError
from skyradar.io.safe_yaml import load_yaml
from skyradar.scene.scenario import Scenario
from skyradar.sim.scenario_frames import make_simulator, scenario_truth, simulate_frames

__all__ = ["set_by_path", "parse_values", "run_table", "sweep"]

DETECTABLE_DB = 13.0  # SNR at which the ch3 detector is asked to find 95% of aircraft


def set_by_path(data: dict[str, Any], dotted: str, value: Any, source: str = "scenario") -> dict[str, Any]:
    """A deep copy of ``data`` with the item at ``dotted`` (``a.b.0.c``) set to ``value``.

    Parameters
    ----------
    data : dict
        A parsed scenario file.
    dotted : str
        Keys and list indices joined by dots; missing sections on the way are created.
    value : any
        The new value.
    source : str
        The scenario's name in error messages.

    Returns
    -------
    dict
        The copy; ``data`` is left as it is.

    Examples
    --------
    >>> data = {"intruders": [{"rcs_m2": 1.0}]}
    >>> set_by_path(data, "intruders.0.rcs_m2", 4.0), data
    ({'intruders': [{'rcs_m2': 4.0}]}, {'intruders': [{'rcs_m2': 1.0}]})
    >>> set_by_path(data, "terrain.local_sd_m", 2.0)["terrain"]
    {'local_sd_m': 2.0}
    """
    out = copy.deepcopy(data)
    keys = dotted.split(".")
    node: Any = out
    for i, part in enumerate(keys):
        last = i == len(keys) - 1
        key: str | int = part
        if isinstance(node, list):
            if not part.isdigit() or int(part) >= len(node):
                raise InputError(
                    f"{source}: --param {dotted}: '{part}' is not an index of a list of {len(node)}"
                )
            key = int(part)
        elif not isinstance(node, dict):
            raise InputError(f"{source}: --param {dotted}: '{keys[i - 1]}' is not a section")
        elif not last and key not in node:
            node[key] = {}
        if last:
            node[key] = value
        else:
            node = node[key]
    return out


_EXPONENT_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)[eE][+-]?\d+")


def parse_values(text: str) -> list[Any]:
    """Comma-separated values: numbers where they parse, strings otherwise.

    Each value is read as YAML, except that a number in exponent notation without a decimal point
    (``1e3``, which YAML 1.1 reads as a string) is a number, as it is everywhere else on the command
    line.

    Parameters
    ----------
    text : str
        The values, comma-separated; each is read as YAML.

    Returns
    -------
    list

    Examples
    --------
    >>> parse_values("1, 2.5, flat, true, 1e3, -2E-4")
    [1, 2.5, 'flat', True, 1000.0, -0.0002]
    """
    values = [
        float(v.strip()) if _EXPONENT_NUMBER.fullmatch(v.strip()) else yaml.safe_load(v.strip())
        for v in text.split(",")
        if v.strip()
    ]
    if not values:
        raise InputError(f"--values '{text}': no values")
    return values


def run_table(built, frames: np.ndarray | None = None, chunk: int = 8) -> pd.DataFrame:
    """Per-intruder detectability measured in the simulated frames (one row per intruder).

    Parameters
    ----------
    built : BuiltScenario
    frames : ndarray, shape (time, n_range, n_doppler, n_rx), optional
        The run's frames; default: simulated ``chunk`` frames at a time.
    chunk : int
        Frames simulated at a time.

    Returns
    -------
    pandas.DataFrame
        Per intruder: ``frames``, ``frames_visible``, the median expected and measured SNR (dB)
        over its visible frames, ``detectable_share`` (measured SNR at least ``DETECTABLE_DB``)
        and ``min_range_m``. The measured SNR is the power at the intruder's truth pixel over the
        thermal noise per pixel, summed over antennas (so clutter and spurs in that pixel count
        against it). A scenario without intruders gives one row with ``frames`` only.

    Examples
    --------
    Without noise or clutter, the measured SNR is the expected one:

    >>> from skyradar.scene.scenario import Scenario
    >>> spec = {"name": "pair", "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    ...     "radar": {"range_limit_m": 1500}, "simulation": {"noise": False},
    ...     "ownship": {"type": "straight", "start_ned_m": [0, 0, -2000], "speed_mps": 30},
    ...     "intruders": [{"name": "A", "type": "straight", "start_ned_m": [900, 0, -2000], "speed_mps": 30}],
    ...     "frame_rate_hz": 10, "duration_s": 0.2}
    >>> row = run_table(Scenario.from_dict(spec).build()).iloc[0]
    >>> row["intruder"], int(row["frames_visible"]), round(float(row["expected_snr_db_median"]), 2)
    ('A', 2, 32.44)
    >>> round(float(row["measured_snr_db_median"]), 2), float(row["detectable_share"])
    (32.44, 1.0)
    """
    cfg = built.radar
    simulator = make_simulator(built)
    _, truth, names = scenario_truth(built, simulator)
    n = built.times_s.size
    if not names:
        return pd.DataFrame({"frames": [n]})
    visible = truth["tgt_visible"].astype(bool)
    v_r = np.where(visible, truth["tgt_radial_velocity_mps"], 0.0)  # NaN where absent: no bin
    k, j = cfg.range_bin(np.where(visible, truth["tgt_range_m"], 0.0), v_r), cfg.doppler_bin(v_r)
    snr = np.full(visible.shape, np.nan)
    for start in range(0, n, chunk):
        idx = np.arange(start, min(start + chunk, n))
        block = frames[idx] if frames is not None else simulate_frames(built, idx, simulator)
        for row, i in enumerate(idx):
            for seen_t in np.nonzero(visible[i])[0]:
                power = np.mean(np.abs(block[row, int(k[i, seen_t]), int(j[i, seen_t])]) ** 2)
                snr[i, seen_t] = 10 * np.log10(power / cfg.noise_power_w)
    rows = []
    for t, name in enumerate(names):
        seen = visible[:, t]
        rows.append(
            {
                "intruder": name,
                "frames": n,
                "frames_visible": int(seen.sum()),
                "expected_snr_db_median": float(np.nanmedian(truth["tgt_snr_db"][seen, t]))
                if seen.any()
                else np.nan,
                "measured_snr_db_median": float(np.nanmedian(snr[seen, t])) if seen.any() else np.nan,
                "detectable_share": float(np.mean(snr[seen, t] >= DETECTABLE_DB)) if seen.any() else 0.0,
                "min_range_m": float(np.nanmin(truth["tgt_range_m"][:, t])) if seen.any() else np.nan,
            }
        )
    return pd.DataFrame(rows)


def _one_run(data: dict[str, Any], source: str, param: str, value: Any) -> pd.DataFrame:
    built = Scenario.from_dict(set_by_path(data, param, value, source), source=source).build()
    table = run_table(built)
    table.insert(0, param, value)
    return table


def sweep(
    scenario: str | Path,
    param: str,
    values: Sequence[Any],
    scheduler: str | None = None,
    workers: int | None = None,
    progress: Callable[[int], None] | None = None,
) -> pd.DataFrame:
    """One table: every run's :func:`run_table` with a leading column holding the parameter value.

    Parameters
    ----------
    scenario : str or Path
        The scenario file.
    param : str
        Dotted path of the parameter (:func:`set_by_path`).
    values : sequence
        Its values, one run each; all are checked before any run.
    scheduler : str, optional
        Address of an existing Dask scheduler.
    workers : int, optional
        Start a local Dask cluster with this many workers. Without ``scheduler`` and ``workers``
        the runs go one after the other in this process.
    progress : callable, optional
        Called with 1 after each run.

    Returns
    -------
    pandas.DataFrame

    Examples
    --------
    Ten times the RCS, 10 dB more SNR:

    >>> import tempfile
    >>> tmp = tempfile.TemporaryDirectory()
    >>> spec = {"name": "pair", "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    ...     "radar": {"range_limit_m": 1500}, "simulation": {"noise": False},
    ...     "ownship": {"type": "straight", "start_ned_m": [0, 0, -2000], "speed_mps": 30},
    ...     "intruders": [{"name": "A", "type": "straight", "start_ned_m": [900, 0, -2000], "speed_mps": 30}],
    ...     "frame_rate_hz": 10, "duration_s": 0.2}
    >>> path = Path(tmp.name) / "pair.yaml"
    >>> _ = path.write_text(yaml.safe_dump(spec))
    >>> table = sweep(path, "intruders.0.rcs_m2", [1.0, 10.0])
    >>> table.columns[0], table["intruders.0.rcs_m2"].tolist()  # the leading column: the parameter
    ('intruders.0.rcs_m2', [1.0, 10.0])
    >>> round(float(table["measured_snr_db_median"].diff().iloc[1]), 2)
    10.0
    >>> tmp.cleanup()
    """
    path = Path(scenario)
    try:
        text = path.read_text()
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read scenario ({type(exc).__name__}: {exc})") from None
    data = load_yaml(text, path)
    for value in values:  # fail fast on a bad path or value, before any work
        Scenario.from_dict(set_by_path(data, param, value, str(path)), source=path)
    if scheduler is None and not workers:
        tables = []
        for value in values:
            tables.append(_one_run(data, str(path), param, value))
            if progress:
                progress(1)
    else:
        from skyradar.parallel import close, connect

        client = connect(scheduler, workers)
        try:
            futures = [client.submit(_one_run, data, str(path), param, v, pure=False) for v in values]
            tables = []
            for future in futures:
                tables.append(future.result())
                if progress:
                    progress(1)
        finally:
            close(client, owns_cluster=scheduler is None)
    return pd.concat(tables, ignore_index=True)
