"""The frames data model: absolute UTC time, CF attributes, the radar configuration as attributes.

In the spirit of xradar / CfRadial2, a frames Dataset carries

- ``time`` (dimension coordinate): the UTC start of each frame, ``datetime64[ns]``, CF ``standard_name``
  "time". Its epoch is the dataset attribute ``start_time`` (ISO 8601 UTC), the instant of elapsed time
  0 s: a scenario's ``start_time`` or a recording's. Without one it is :data:`DEFAULT_START_TIME`
  (1970-01-01T00:00:00Z), so ``time`` then reads as elapsed time since the Unix epoch.
- ``time_s`` (coordinate on ``time``): elapsed seconds since ``start_time``, float64, units "s": the
  exact values the simulator and the processing chain compute with. Read it with :func:`frame_times_s`,
  the one accessor, which also reads stores written before the absolute time existed (their float
  ``time`` coordinate is elapsed seconds; they have no ``start_time``).
- ``units`` and ``long_name`` on every variable and coordinate, and the CF ``standard_name`` where the
  CF table has one (:data:`STANDARD_NAMES`); the global attribute ``Conventions = "CF-1.10"``.
- the RadarConfig twice: the JSON string ``radar_config`` that :func:`skyradar.io.frames.radar_config_of`
  reads back exactly, and flat ``radar_*`` attributes (:func:`radar_attrs`) a person or another tool reads.

Examples
--------
>>> t = time_coordinate([0.0, 0.5], "2026-05-01T10:00:00Z")
>>> str(t["time"][1][1]), float(t["time_s"][1][1])
('2026-05-01T10:00:00.500000000', 0.5)
"""

from __future__ import annotations

import datetime as dt
from typing import Any

import numpy as np
import xarray as xr

from skyradar.config import RadarConfig
from skyradar.errors import InputError

__all__ = [
    "DEFAULT_START_TIME",
    "OWNSHIP_VARS",
    "TARGET_VARS",
    "STANDARD_NAMES",
    "axis_coordinates",
    "parse_start_time",
    "format_start_time",
    "time_coordinate",
    "frame_times_s",
    "start_time_of",
    "radar_attrs",
    "variable_attrs",
]

DEFAULT_START_TIME = "1970-01-01T00:00:00Z"
IQ_LONG_NAME = "complex pixel, |iq|^2 in W"

# Truth variables written by the simulator: name -> (units, description).
OWNSHIP_VARS: dict[str, tuple[str, str]] = {
    "own_north_m": ("m", "own-ship (radar reference point) north in the scenario NED frame"),
    "own_east_m": ("m", "own-ship east in the scenario NED frame"),
    "own_down_m": ("m", "own-ship down in the scenario NED frame"),
    "own_vn_mps": ("m/s", "own-ship velocity north"),
    "own_ve_mps": ("m/s", "own-ship velocity east"),
    "own_vd_mps": ("m/s", "own-ship velocity down"),
    "own_lat_deg": ("degree", "own-ship WGS84 latitude"),
    "own_lon_deg": ("degree", "own-ship WGS84 longitude"),
    "own_alt_m": ("m", "own-ship altitude above the WGS84 ellipsoid"),
    "own_yaw_rad": ("rad", "own-ship heading (yaw) from north"),
    "own_pitch_rad": ("rad", "own-ship pitch, positive nose-up"),
    "own_roll_rad": ("rad", "own-ship roll (bank), positive right wing down"),
    "own_height_agl_m": ("m", "own-ship height above the terrain directly below"),
}
# The navigation solution (GNSS/AHRS with errors, skyradar.sim.navigation) beside the truth:
# what process, track and alert read (skyradar.io.navigation).
OWNSHIP_VARS |= {
    f"nav_{name[4:]}": (units, f"navigation (GNSS/AHRS with errors): {desc.replace('own-ship ', '')}")
    for name, (units, desc) in list(OWNSHIP_VARS.items())
}
TARGET_VARS: dict[str, tuple[str, str]] = {
    "tgt_north_m": ("m", "intruder north in the scenario NED frame"),
    "tgt_east_m": ("m", "intruder east"),
    "tgt_down_m": ("m", "intruder down"),
    "tgt_vn_mps": ("m/s", "intruder velocity north"),
    "tgt_ve_mps": ("m/s", "intruder velocity east"),
    "tgt_vd_mps": ("m/s", "intruder velocity down"),
    "tgt_lat_deg": ("degree", "intruder WGS84 latitude"),
    "tgt_lon_deg": ("degree", "intruder WGS84 longitude"),
    "tgt_alt_m": ("m", "intruder altitude above the WGS84 ellipsoid"),
    "tgt_range_m": ("m", "range from the radar"),
    "tgt_radial_velocity_mps": ("m/s", "true radial velocity (not aliased), positive receding"),
    "tgt_azimuth_rad": ("rad", "azimuth in the antenna frame, positive right"),
    "tgt_elevation_rad": ("rad", "elevation in the antenna frame, positive up"),
    "tgt_rcs_m2": ("m^2", "radar cross-section"),
    "tgt_snr_db": ("dB", "expected single-pixel SNR from the radar equation"),
    "tgt_visible": ("1", "inside range, field of view and line of sight"),
}


# CF standard names (CF table v84) of the frames variables that have one; the others carry units and
# long_name only (no CF name exists for, e.g., a complex radar pixel or an intruder's cross-section).
STANDARD_NAMES: dict[str, str] = {
    "time": "time",
    "range": "projection_range_coordinate",
    "doppler": "radial_velocity_of_scatterers_away_from_instrument",
    "own_lat_deg": "latitude",
    "own_lon_deg": "longitude",
    "own_alt_m": "height_above_reference_ellipsoid",
    "own_yaw_rad": "platform_yaw",
    "own_pitch_rad": "platform_pitch",
    "own_roll_rad": "platform_roll",
    "own_height_agl_m": "height",
    "tgt_lat_deg": "latitude",
    "tgt_lon_deg": "longitude",
    "tgt_alt_m": "height_above_reference_ellipsoid",
    "tgt_radial_velocity_mps": "radial_velocity_of_scatterers_away_from_instrument",
}

# RadarConfig fields and derived quantities written as flat ``radar_<name>`` attributes.
_RADAR_SCALARS = (
    "fc_hz",
    "fs_hz",
    "prf_hz",
    "pe_dbm",
    "bandwidth_hz",
    "n_doppler",
    "range_limit_m",
    "noise_figure_db",
    "temperature_k",
    "wavelength_m",
    "n_range",
    "n_rx",
    "range_resolution_m",
    "doppler_resolution_mps",
    "v_lim_mps",
    "frame_duration_s",
    "range_doppler_coupling_s",
    "noise_power_w",
)


def parse_start_time(value: Any, source: str = "scenario", field: str = "start_time") -> np.datetime64:
    """An ISO 8601 instant (``Z`` or an offset; no offset means UTC) as UTC ``datetime64[ns]``.

    Examples
    --------
    >>> str(parse_start_time("2026-05-01T12:00:00+02:00"))
    '2026-05-01T10:00:00.000000000'
    >>> parse_start_time("May 1st")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: scenario: field 'start_time' is not an ISO 8601 time (got 'May 1st')
    """
    if isinstance(value, np.datetime64):
        return value.astype("datetime64[ns]")
    try:
        when = value if isinstance(value, dt.datetime) else dt.datetime.fromisoformat(str(value))
    except ValueError:
        raise InputError(f"{source}: field '{field}' is not an ISO 8601 time (got {value!r})") from None
    if when.tzinfo is not None:
        when = when.astimezone(dt.UTC).replace(tzinfo=None)
    return np.datetime64(when, "ns")


def format_start_time(when: np.datetime64) -> str:
    """``datetime64`` as ISO 8601 UTC with a ``Z`` (whole seconds shown without a fraction).

    Parameters
    ----------
    when : numpy.datetime64
        A UTC instant.

    Returns
    -------
    str
        The instant with trailing zeros of the fraction dropped; :func:`parse_start_time` reads it back.

    Examples
    --------
    >>> when = np.datetime64("2026-05-01T10:00:00.250")
    >>> format_start_time(when), format_start_time(np.datetime64("2026-05-01"))
    ('2026-05-01T10:00:00.25Z', '2026-05-01T00:00:00Z')
    >>> parse_start_time(format_start_time(when)) == when
    np.True_
    """
    text = str(np.datetime64(when, "ns"))  # type: ignore[call-overload]  # numpy's stub: no (datetime64, unit)
    head, _, frac = text.partition(".")
    frac = frac.rstrip("0")
    return f"{head}.{frac}Z" if frac else f"{head}Z"


def time_coordinate(times_s: Any, start_time: Any = None) -> dict[str, Any]:
    """The ``time`` (UTC datetime64[ns]) and ``time_s`` (elapsed s) coordinates of frames at ``times_s``.

    Parameters
    ----------
    times_s : array_like
        Frame times, s since ``start_time``.
    start_time : str or datetime64, optional
        ISO 8601 instant of elapsed time 0 s; default :data:`DEFAULT_START_TIME`.

    Returns
    -------
    dict
        ``{"time": (dim, values, attrs), "time_s": (dim, values, attrs)}`` for an xarray constructor:
        ``time = start_time + round(time_s * 1e9) ns``; ``time_s`` keeps the float seconds exactly.

    Examples
    --------
    >>> c = time_coordinate([0.0, 1.5, 2e-9], "2026-05-01T12:00:00+02:00")
    >>> [str(t) for t in c["time"][1]]
    ['2026-05-01T10:00:00.000000000', '2026-05-01T10:00:01.500000000', '2026-05-01T10:00:00.000000002']
    >>> c["time_s"][1].tolist(), c["time_s"][2]["units"]
    ([0.0, 1.5, 2e-09], 's')
    """
    t = np.asarray(times_s, float)
    epoch = parse_start_time(DEFAULT_START_TIME if start_time is None else start_time)
    # Non-finite times (refused by open_frames, which names the frame) map to the epoch here.
    ns = np.round(np.nan_to_num(t * 1e9, nan=0.0, posinf=0.0, neginf=0.0))
    absolute = epoch + ns.astype(np.int64).astype("timedelta64[ns]")
    return {
        "time": ("time", absolute, {"standard_name": "time", "long_name": "frame start time (UTC)"}),
        "time_s": ("time", t, {"units": "s", "long_name": "elapsed time since start_time"}),
    }


def axis_coordinates(config: RadarConfig, times_s: Any, start_time: Any = None) -> dict[str, Any]:
    """Coordinates of a (time, range, doppler, rx) frames Dataset, with CF attributes.

    Parameters
    ----------
    config : RadarConfig
        Gives the range axis (m), Doppler axis (m/s) and antenna count.
    times_s : array_like
        Frame times, s since ``start_time``.
    start_time : str or datetime64, optional
        ISO 8601 instant of elapsed time 0 s (see :func:`time_coordinate`).

    Returns
    -------
    dict
        ``time``, ``time_s``, ``range``, ``doppler`` and ``rx``, each ``(dim, values, attrs)``.

    Examples
    --------
    Range bins are c / (2 B) = 14.99 m apart for a 10 MHz sweep; four Doppler bins span
    [-v_lim, v_lim) in steps of v_lim / 2.

    >>> cfg = RadarConfig.prototype_2022(n_doppler=4, range_limit_m=100.0)
    >>> c = axis_coordinates(cfg, [0.0, 0.1])
    >>> sorted(c), np.round(c["range"][1][:3], 2).tolist(), c["range"][2]["units"]
    (['doppler', 'range', 'rx', 'time', 'time_s'], [0.0, 14.99, 29.98], 'm')
    >>> np.round(c["doppler"][1] / cfg.v_lim_mps, 6).tolist(), c["rx"][1].tolist()
    ([-1.0, -0.5, 0.0, 0.5], [0, 1, 2, 3])
    """
    coords = time_coordinate(times_s, start_time)
    coords["range"] = ("range", config.range_axis_m, _cf("range", "m", "range bin centre"))
    coords["doppler"] = (
        "doppler",
        config.doppler_axis_mps,
        _cf("doppler", "m/s", "radial velocity bin centre, positive receding"),
    )
    long_name = "receive antenna index"
    if config.n_tx > 1:
        long_name = "virtual channel index, transmitter * n_rx + receiver (time-division MIMO)"
    coords["rx"] = ("rx", np.arange(config.n_virtual), {"units": "1", "long_name": long_name})
    return coords


def variable_attrs(name: str, units: str, long_name: str) -> dict[str, str]:
    """``units``, ``long_name`` and, when CF has one, ``standard_name`` of variable ``name``.

    Parameters
    ----------
    name : str
        The variable name, looked up in :data:`STANDARD_NAMES`.
    units : str
        Its units, e.g. "m", "m/s", "rad".
    long_name : str
        A description.

    Returns
    -------
    dict of str to str

    Examples
    --------
    >>> variable_attrs("own_lat_deg", "degree", "own-ship WGS84 latitude")["standard_name"]
    'latitude'
    >>> variable_attrs("tgt_rcs_m2", "m^2", "radar cross-section")
    {'units': 'm^2', 'long_name': 'radar cross-section'}
    """
    return _cf(name, units, long_name)


def _cf(name: str, units: str, long_name: str) -> dict[str, str]:
    out = {"units": units, "long_name": long_name}
    if name in STANDARD_NAMES:
        out["standard_name"] = STANDARD_NAMES[name]
    return out


def frame_times_s(ds: xr.Dataset) -> np.ndarray:
    """Frame times in seconds since the run's ``start_time`` (float64): THE way to read frame times.

    Reads ``time_s`` when present; a float ``time`` coordinate (stores written before absolute time,
    or hand-built Datasets) is taken as elapsed seconds already; a datetime ``time`` without
    ``time_s`` is measured from the ``start_time`` attribute (default :data:`DEFAULT_START_TIME`).

    Examples
    --------
    >>> old = xr.Dataset(coords={"time": [0.0, 0.1]})
    >>> frame_times_s(old).tolist()
    [0.0, 0.1]
    >>> new = xr.Dataset(coords=time_coordinate([0.0, 0.1], "2026-05-01T10:00:00Z"))
    >>> frame_times_s(new).tolist()
    [0.0, 0.1]
    """
    if "time_s" in ds.coords or "time_s" in ds.data_vars:
        return np.asarray(ds["time_s"].values, float)
    values = np.asarray(ds["time"].values)
    if np.issubdtype(values.dtype, np.datetime64):
        return (values - start_time_of(ds)).astype("timedelta64[ns]").astype(np.int64) / 1e9
    return values.astype(float)


def start_time_of(ds: xr.Dataset) -> np.datetime64:
    """UTC instant of elapsed time 0 s (the ``start_time`` attribute, or :data:`DEFAULT_START_TIME`).

    Parameters
    ----------
    ds : xarray.Dataset
        A frames Dataset.

    Returns
    -------
    numpy.datetime64
        In ns, UTC (an offset in the attribute is applied).

    Examples
    --------
    >>> str(start_time_of(xr.Dataset(attrs={"start_time": "2026-05-01T12:00:00+02:00"})))
    '2026-05-01T10:00:00.000000000'
    >>> str(start_time_of(xr.Dataset()))
    '1970-01-01T00:00:00.000000000'
    """
    return parse_start_time(ds.attrs.get("start_time", DEFAULT_START_TIME), "frames", "start_time")


def radar_attrs(config: RadarConfig) -> dict[str, Any]:
    """Flat, human-readable ``radar_*`` attributes (SI units in the names); positions row-major (n_rx, 3).

    Examples
    --------
    >>> a = radar_attrs(RadarConfig.prototype_2022())
    >>> a["radar_fc_hz"], a["radar_n_rx"], len(a["radar_rx_positions_m"])
    (9425000000.0, 4, 12)
    """
    out: dict[str, Any] = {f"radar_{k}": _plain(getattr(config, k)) for k in _RADAR_SCALARS}
    out["radar_rx_positions_m"] = [float(v) for v in np.ravel(config.rx_positions_m)]
    out["radar_tx_position_m"] = [float(v) for v in np.ravel(config.tx_position_m)]
    out["radar_antenna_combine"] = str(config.antenna.combine)
    mount = config.mount
    out["radar_mount_position_m"] = [float(v) for v in mount.position_m]
    for angle in ("yaw_deg", "pitch_deg", "roll_deg"):
        out[f"radar_mount_{angle}"] = float(getattr(mount, angle))
    return out


def _plain(value: Any) -> Any:
    return int(value) if isinstance(value, int | np.integer) else float(value)
