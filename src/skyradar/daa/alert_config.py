"""Alerting settings by name or from a YAML file (``skyradar alert --config radar|default|FILE.yaml``).

``radar`` is :data:`~skyradar.daa.alerting.RADAR_ALERT_CONFIG`, the settings every DAA result of
this project uses (``experiment encounters``, ``demo``) and ``alert``'s default; ``do365b`` is
:data:`~skyradar.daa.alerting.DO365B_ALERT_CONFIG`, DAIDALUS' DO-365B non-cooperative alerter
(its ``DO_365B_no_SUM`` configuration: 2200 ft / 450 ft on every level, alerting times 55, 55,
25 s and early alerting times 110, 110, 90 s, 2 of 4, persistence 4 s, reset after a 5 s data gap);
``default`` is :class:`~skyradar.daa.alerting.AlertConfig` with its own defaults. What ``radar``
changes from ``do365b``, and why:

- its first level is preventive on a 700 ft vertical threshold (DO-365's cooperative Phase I
  preventive alert), to warn vertical encounters earlier; DO-365B's non-cooperative first level has
  the corrective volume;
- an issued level holds while lost within 1.5 times its alerting time (37.5 s for the warning),
  not within DAIDALUS' early alerting time (90 s): a radar track's prediction after a manoeuvre is
  trusted less far ahead; it holds too while its volume enlarged 1.5 times is lost (a track's
  predicted miss scatters, and near the volume's edge it would cross the edge back and forth); and
  it is lowered only after its M-of-N stayed below for 5 s;
- tracks wait before alerting (a share of the time left, at most 2 s) and a track whose horizontal
  velocity is known worse than 6 m/s (scaled by the time to CPA) raises nothing: a fresh radar
  track's velocity is noise, which DAIDALUS, fed by ADS-B-quality tracks, does not expect;
- the volumes are not widened by the vertical speed's sigma (``z_v_vel`` 0): at the ranges where a
  warning is decided the radar does not measure a vertical speed, and that sigma is the tracker's
  level-flight prior; widened by it, every level intruder up to 212 m above or below would be
  inside the warning volume whatever the radar measures (the measured height's sigma still widens);
- a lost track's prediction holds its level for 8 s (radar tracks drop out in clutter and nulls).

A file holds :class:`AlertConfig` fields, starting from ``base`` (``radar`` unless given)::

    base: radar                  # or default, do365b
    m: 3
    n: 5
    period_s: 1.0                # null: M of N frames
    persistence_s: 4.0
    hysteresis_s: 5.0
    gap_reset_s: null            # DAIDALUS' hysteresis_time: reset after a data gap this long
    z_h_pos: 1.5                 # also z_h_vel, z_v_pos, z_v_vel
    min_track_age_s: 2.0
    age_fraction_of_time_left: 0.1   # a fresh track waits at most this share of the time left
    min_track_age_floor_s: 0.5
    hold_time_factor: 1.5            # an issued level holds while lost within 1.5x its alerting time
    hold_volume_factor: 1.5          # ... or while its volume enlarged 1.5x is
    lost_track_hold_s: 8.0           # a lost track's prediction holds its alert this long
    closing_track_hold_s: 25.0       # ... a closing one's up to its closest approach, at most this
    max_velocity_sigma_mps: 6.0  # null: no gate
    flarm_thresholds_s: [18, 13, 8]
    levels:                      # preventive, corrective, warning
      - {name: preventive, dthr_m: 670.56, zthr_m: 213.36, alerting_time_s: 55}
      - {name: corrective, dthr_m: 670.56, zthr_m: 137.16, alerting_time_s: 55}
      - {name: warning, dthr_m: 670.56, zthr_m: 137.16, alerting_time_s: 25, early_alerting_time_s: 90}
    collision_volume: {dthr_m: 152.4, zthr_m: 30.48}

Every field is checked; a wrong one is refused in one line naming the file, the field and the value.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

from skyradar.daa.alerting import DO365B_ALERT_CONFIG, RADAR_ALERT_CONFIG, AlertConfig, AlertLevel
from skyradar.daa.conflict import WellClearVolume
from skyradar.errors import InputError

__all__ = ["ALERT_CONFIGS", "WARNING_LEVEL", "alert_config", "check_warns_head_on", "config_digest"]

ALERT_CONFIGS = {"radar": RADAR_ALERT_CONFIG, "default": AlertConfig(), "do365b": DO365B_ALERT_CONFIG}
WARNING_LEVEL = 3  # preventive 1, corrective 2, warning 3: the level every DAA score counts
_INTS = ("m", "n")
_FLOATS = (
    "persistence_s",
    "hysteresis_s",
    "z_h_pos",
    "z_h_vel",
    "z_v_pos",
    "z_v_vel",
    "min_track_age_s",
    "age_fraction_of_time_left",
    "min_track_age_floor_s",
    "hold_time_factor",
    "hold_volume_factor",
    "lost_track_hold_s",
    "closing_track_hold_s",
)
_OPTIONAL = ("period_s", "max_velocity_sigma_mps", "gap_reset_s")
_VOLUME_KEYS = ("dthr_m", "zthr_m", "tthr_s", "tcoa_s")


# Every setting (s, m, frames, z-scores) is far below this; beyond, the conflict geometry overflows to
# inf and NaN (a volume of 1e308 m alerted on everything, with numpy's warnings on the way).
_LARGEST = 1e6


def _number(label: str, value: Any, integer: bool = False, low: float = 0.0) -> float:
    ok = isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
    ok = ok and (float(value).is_integer() if integer else True) and low <= value <= _LARGEST
    if not ok:
        kind = "an integer" if integer else "a finite number"
        raise InputError(f"{label}: must be {kind} from {low:g} to {_LARGEST:g}, got {value!r}")
    return int(value) if integer else float(value)


def _volume(label: str, value: Any) -> WellClearVolume:
    if (
        not isinstance(value, dict)
        or not {"dthr_m", "zthr_m"} <= set(value)
        or set(value) - set(_VOLUME_KEYS)
    ):
        raise InputError(f"{label}: must be a mapping of dthr_m, zthr_m (and tthr_s, tcoa_s), got {value!r}")
    return WellClearVolume(**{k: _number(f"{label}.{k}", v) for k, v in value.items()})


def _levels(label: str, value: Any) -> tuple[AlertLevel, ...]:
    if not isinstance(value, list) or not value:
        raise InputError(
            f"{label}: must be a list of levels (preventive, corrective, warning), got {value!r}"
        )
    levels = []
    for i, item in enumerate(value):
        where = f"{label}.{i}"
        if not isinstance(item, dict) or not {"name", "alerting_time_s"} <= set(item):
            raise InputError(f"{where}: must have name, dthr_m, zthr_m and alerting_time_s, got {item!r}")
        volume = {
            k: v for k, v in item.items() if k not in ("name", "alerting_time_s", "early_alerting_time_s")
        }
        time_s = _number(f"{where}.alerting_time_s", item["alerting_time_s"])
        early = item.get("early_alerting_time_s")
        if early is not None:
            early = _number(f"{where}.early_alerting_time_s", early, low=time_s)
        levels.append(AlertLevel(str(item["name"]), _volume(where, volume), time_s, early))
    return tuple(levels)


def _fields(label: str, data: dict) -> dict:
    known = {f.name for f in dataclasses.fields(AlertConfig)}
    changes: dict[str, Any] = {}
    for key, value in data.items():
        where = f"{label}: field '{key}'"
        if key not in known:
            raise InputError(f"{where} is not an alert setting (known: base, {', '.join(sorted(known))})")
        if key in _INTS:
            changes[key] = _number(where, value, integer=True, low=1)
        elif key in _FLOATS:
            changes[key] = _number(where, value)
        elif key in _OPTIONAL:
            changes[key] = None if value is None else _number(where, value)
        elif key == "flarm_thresholds_s":
            if not isinstance(value, list) or len(value) != 3:
                raise InputError(f"{where}: must be 3 times to impact in s, got {value!r}")
            changes[key] = tuple(_number(f"{where}.{i}", v) for i, v in enumerate(value))
        elif key == "levels":
            changes[key] = _levels(where, value)
        else:  # collision_volume
            changes[key] = _volume(where, value)
    return changes


def alert_config(value: str | Path, option: str = "--config") -> AlertConfig:
    """The alerting settings ``value`` names: ``radar``, ``default``, ``do365b``, or a YAML file of fields.

    ``option`` names the command-line option in the message that refuses a value.

    Examples
    --------
    >>> alert_config("radar") is RADAR_ALERT_CONFIG, alert_config("default") == AlertConfig()
    (True, True)
    >>> alert_config("fast")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: --config fast: not radar, default, do365b or an existing .yaml file
    """
    if str(value) in ALERT_CONFIGS:
        return ALERT_CONFIGS[str(value)]
    path = Path(value)
    if path.suffix.lower() not in (".yaml", ".yml") or not path.is_file():
        raise InputError(f"{option} {value}: not radar, default, do365b or an existing .yaml file")
    from skyradar.io.safe_yaml import load_yaml

    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read as UTF-8 text ({type(exc).__name__})") from None
    data = load_yaml(text, path) or {}  # aliases bounded, duplicate keys refused, like scenarios
    if not isinstance(data, dict):
        raise InputError(f"{path}: must be a mapping of alert settings, got {type(data).__name__}")
    base = data.pop("base", "radar")
    if base not in ALERT_CONFIGS:
        raise InputError(f"{path}: field 'base' must be radar, default or do365b, got {base!r}")
    changes = _fields(str(path), data)  # its InputError (a ValueError) names the file once
    try:
        config = dataclasses.replace(ALERT_CONFIGS[base], **changes)
    except ValueError as exc:  # AlertConfig's own checks (1 <= m <= n, period_s > 0)
        raise InputError(f"{path}: {exc}") from None
    check_warns_head_on(config, str(path))
    return config


def config_digest(config: AlertConfig) -> str:
    """A short digest of every field of ``config``: two runs alerted with the same settings have the
    same digest, whatever name or file gave them (a resumed run must use the same settings).

    Examples
    --------
    >>> config_digest(alert_config("radar")) == config_digest(dataclasses.replace(RADAR_ALERT_CONFIG))
    True
    >>> config_digest(RADAR_ALERT_CONFIG) == config_digest(DO365B_ALERT_CONFIG)
    False
    """
    import hashlib
    import json

    fields = json.dumps(dataclasses.asdict(config), sort_keys=True, default=repr)
    return hashlib.sha256(fields.encode()).hexdigest()[:16]


def check_warns_head_on(config: AlertConfig, label: str) -> None:
    """Refuse settings that cannot warn on a plain collision course: a converged track of a head-on
    intruder, both aircraft at 50 m/s, 3 km apart and passing 100 m apart (inside the collision
    volume), must reach the warning level (the third, :data:`WARNING_LEVEL`) before they meet. One
    level, zero volumes, a minimum track age or a persistence longer than the approach, or a
    velocity gate no track passes would silently switch the warnings off. Nor may they alert on an
    aircraft 10 km abeam flying alongside: volumes, alerting times or z-scores of 1e308 alert on
    everything.

    Examples
    --------
    >>> check_warns_head_on(RADAR_ALERT_CONFIG, "radar")
    >>> slow = dataclasses.replace(RADAR_ALERT_CONFIG, min_track_age_s=1e9, min_track_age_floor_s=1e9)
    >>> check_warns_head_on(slow, "slow.yaml")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: slow.yaml: these settings never warn ...
    """
    import numpy as np
    import pandas as pd

    from skyradar.daa.pipeline import alerts_from_tracks

    t = np.arange(0.0, 30.0, 1.0 / 9.4)  # 3 km apart at 100 m/s closing: they meet at 30 s, 100 m apart
    own = pd.DataFrame(
        {
            "time_s": t,
            "own_north_m": 50.0 * t,
            "own_east_m": 0.0,
            "own_down_m": -1000.0,
            "own_vn_mps": 50.0,
            "own_ve_mps": 0.0,
            "own_vd_mps": 0.0,
        }
    )
    tracks = pd.DataFrame(
        {
            "time_s": t,
            "track_id": 1,
            "north_m": 3000.0 - 50.0 * t,
            "east_m": 100.0,
            "down_m": -1000.0,
            "vn_mps": -50.0,
            "ve_mps": 0.0,
            "vd_mps": 0.0,
            "confirmed": True,
        }
    )
    # And an aircraft 10 km abeam flying alongside, which no alerting may flag.
    alongside = tracks.assign(track_id=2, north_m=50.0 * t, east_m=10_000.0, vn_mps=50.0)
    tracks = pd.concat([tracks, alongside], ignore_index=True).sort_values(["time_s", "track_id"])
    # A converged radar track: 20 m of position and 2 m/s of velocity error per axis.
    for name, variance in (("pp", 400.0), ("vv", 4.0), ("pv", 0.0)):
        for i in range(3):
            for j in range(3):
                tracks[f"cov_{name}_{i}{j}"] = variance if i == j else 0.0
    every = alerts_from_tracks(tracks, own, config, with_advice=False, source=label)
    clear = every[every["track_id"] == 2]
    if len(clear) and int(clear["level"].max()) > 0:
        raise InputError(
            f"{label}: these settings alert on an aircraft 10 km abeam flying alongside (level "
            f"{int(clear['level'].max())} of {WARNING_LEVEL}): check levels, their volumes (dthr_m, zthr_m) "
            "and alerting times, and the z-scores z_h_pos, z_h_vel, z_v_pos, z_v_vel"
        )
    alerts = every[every["track_id"] == 1]
    if len(alerts) == 0 or int(alerts["level"].max()) < WARNING_LEVEL:
        reached = int(alerts["level"].max()) if len(alerts) else 0
        raise InputError(
            f"{label}: these settings never warn on a head-on collision course (a converged track, "
            f"50 m/s each, 3 km apart, 100 m miss; highest level reached {reached} of {WARNING_LEVEL}): "
            "check levels, their volumes and alerting times, min_track_age_s, persistence_s and "
            "max_velocity_sigma_mps"
        )
