"""Do these tracks come from this run? The own-ship signature carried from frames to alerts.

Tracks are positions in the NED frame of the run they were detected in, relative to that run's
own-ship. Alerting them against the own-ship of another run gives geometry that is silently
wrong (typically no warning at all). ``skyradar process`` therefore stores an own-ship
signature of its run in the detections table's metadata, ``skyradar track`` carries it into the
tracks table, and ``skyradar alert`` compares it with the ``--ownship`` run: the origin of the
NED frame and the own-ship position at a few times must agree. Tables written before the
signature existed are traced back through their ``source`` metadata (tracks -> detections ->
run) when those files still exist.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from skyradar.errors import InputError
from skyradar.io.frames_model import frame_times_s

__all__ = ["ownship_signature", "check_tracks_match_run"]

_POS = ("own_north_m", "own_east_m", "own_down_m")
_N_SAMPLES = 5
_POSITION_TOLERANCE_M = 1.0  # re-simulating a scenario gives the same own-ship to well below this
_ORIGIN_TOLERANCE_DEG = 1e-7  # about 1 cm


def ownship_signature(ds: xr.Dataset, source: str) -> str | None:
    """JSON signature of a run's own-ship: origin, time span and the position at a few times.

    ``None`` for a run without own-ship state (a recording).

    Examples
    --------
    >>> t = np.arange(4.0)
    >>> ds = xr.Dataset({n: ("time", v) for n, v in zip(_POS, (10 * t, 0 * t, -500 + 0 * t))},
    ...                 coords={"time": t}, attrs={"origin_lat_deg": 52.0, "origin_lon_deg": 4.0})
    >>> sig = json.loads(ownship_signature(ds, "run.zarr"))
    >>> sig["time_span_s"], sig["samples"][-1]
    ([0.0, 3.0], [3.0, 30.0, 0.0, -500.0])
    """
    from skyradar.io.run_origin import scenario_origin

    if not all(name in ds for name in _POS) or ds.sizes.get("time", 0) == 0:
        return None
    t = frame_times_s(ds)
    pos = np.stack([np.asarray(ds[name].values, float) for name in _POS], axis=-1)
    picks = np.unique(np.linspace(0, t.size - 1, _N_SAMPLES).round().astype(int))
    origin = scenario_origin(ds)
    return json.dumps(
        {
            "run": str(source),
            "origin": None if origin is None else [float(v) for v in origin],
            "time_span_s": [float(t[0]), float(t[-1])],
            "samples": [[float(t[i]), *(float(v) for v in pos[i])] for i in picks],
        }
    )


def _table_attrs(path: Path) -> dict[str, Any]:
    """Metadata of a Parquet table without reading its rows ({} when it cannot be read)."""
    import pyarrow.parquet as pq

    try:
        raw = pq.read_schema(path).metadata or {}
        return json.loads(raw.get(b"PANDAS_ATTRS", b"{}"))
    except (OSError, ValueError):  # pyarrow's errors derive from these
        return {}


def _signature_of(attrs: dict[str, Any], depth: int = 0) -> str | None:
    """The own-ship signature in a table's metadata, else the one found by following ``source``."""
    if attrs.get("ownship_signature"):
        return str(attrs["ownship_signature"])
    source = attrs.get("source")
    if not source or depth > 2 or not Path(source).exists():
        return None
    path = Path(source)
    if path.is_file() and path.suffix.lower() == ".parquet":
        return _signature_of(_table_attrs(path), depth + 1)
    try:
        from skyradar.io.frames import open_frames

        return ownship_signature(open_frames(path), str(path))
    except (InputError, OSError, ValueError, KeyError):
        return None


def _describe(t0: float, t1: float, origin: Any) -> str:
    where = "" if origin is None else f", origin lat {origin[0]:.6g}, lon {origin[1]:.6g}"
    return f"{t0:.6g}..{t1:.6g} s{where}"


def _mismatch(made: dict[str, Any], origin: Any, t: np.ndarray, pos: np.ndarray) -> str | None:
    """Why the signature ``made`` is not the run (origin, times ``t``, own-ship ``pos``), or None."""
    a = made.get("origin")
    if (
        a is not None
        and origin is not None
        and max(abs(a[0] - origin[0]), abs(a[1] - origin[1])) > _ORIGIN_TOLERANCE_DEG
    ):
        return "the NED origins differ"
    inside = [s for s in made["samples"] if t[0] - 1e-6 <= s[0] <= t[-1] + 1e-6]
    if not inside:
        return "their time spans do not overlap"
    for time_s, *made_pos in inside:
        here = np.array([np.interp(time_s, t, pos[:, k]) for k in range(3)])
        gap = float(np.linalg.norm(here - np.array(made_pos)))
        if gap > _POSITION_TOLERANCE_M:
            return f"the own-ship positions differ by {gap:.0f} m at t = {time_s:.6g} s"
    return None


def check_tracks_match_run(
    tracks_attrs: dict[str, Any], tracks_path: str, ds: xr.Dataset, run: str, option: str = "--ownship"
) -> None:
    """Raise :class:`InputError` when the tracks were not made from the frames run ``run``.

    ``tracks_attrs`` is the tracks table's metadata (``DataFrame.attrs``); ``option`` is how the
    command was given ``run`` (``""`` for an argument), named in the message. Without a signature
    anywhere along its ``source`` chain, or without own-ship state in ``ds``, nothing can be
    compared and nothing is raised (the time-span check of the alerting still applies).

    Parameters
    ----------
    tracks_attrs : dict
        The tracks table's metadata (``ownship_signature``, or a ``source`` to follow).
    tracks_path : str
        Name of the tracks table in the message.
    ds : xr.Dataset
        The frames run, with the own-ship NED position ``own_north_m, own_east_m, own_down_m`` (m).
    run : str
        Name of the run in the message.
    option : str
        How the command was given ``run`` (``""`` for an argument).

    Returns
    -------
    None
        Raises :class:`InputError` on a mismatch (origin, time span, or own-ship positions more than
        1 m apart).

    Examples
    --------
    >>> t = np.arange(4.0)
    >>> pos = {n: ("time", v) for n, v in zip(_POS, (10 * t, 0 * t, -500 + 0 * t))}
    >>> ds = xr.Dataset(pos, coords={"time": t})
    >>> attrs = {"ownship_signature": ownship_signature(ds, "a.zarr")}
    >>> check_tracks_match_run(attrs, "tracks.parquet", ds, "a.zarr") is None
    True
    >>> check_tracks_match_run(attrs, "tracks.parquet", ds.assign(own_east_m=ds.own_east_m + 50.0), "b.zarr")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: tracks.parquet: tracks come from run a.zarr (0..3 s) but --ownship b.zarr is \
another run (0..3 s): the own-ship positions differ by 50 m at t = 0 s; give the run the tracks were made from
    """
    from skyradar.io.run_origin import scenario_origin

    made_text = _signature_of(tracks_attrs)
    if made_text is None or not all(name in ds for name in _POS) or ds.sizes.get("time", 0) == 0:
        return
    made = json.loads(made_text)
    t = frame_times_s(ds)
    pos = np.stack([np.asarray(ds[name].values, float) for name in _POS], axis=-1)
    origin = scenario_origin(ds)
    why = _mismatch(made, origin, t, pos)
    if why is not None:
        t0, t1 = made["time_span_s"]
        was = _describe(t0, t1, made.get("origin"))
        raise InputError(
            f"{tracks_path}: tracks come from run {made['run']} ({was}) but {option + ' ' if option else ''}"
            f"{run} is another "
            f"run ({_describe(t[0], t[-1], origin)}): {why}; "
            "give the run the tracks were made from"
        )
