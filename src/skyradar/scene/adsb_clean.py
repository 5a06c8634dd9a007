"""Repairs that real ADS-B downloads need before they become a trajectory, and a note of what was done.

Real files (OpenSky, the ``traffic`` package, ADS-B Exchange exports, pandas' ``to_json``) come with
timestamps in epoch milliseconds, rows out of order, several rows per second (one with the position,
one with the velocity), rows without a position, and barometric beside geometric altitude. What is
safe to repair is repaired here, and each file gets ONE line saying what was done
(:func:`clean_rows` returns the notes; :mod:`skyradar.scene.adsb` logs them on the
``skyradar.scene.adsb`` logger at WARNING, so the command line shows them on stderr). What cannot be
repaired is refused with the reason (:class:`~skyradar.errors.InputError`):

* a numeric ``timestamp`` is unix seconds, milliseconds, microseconds or nanoseconds when *all* of
  its values fall in that unit's 1990-2100 band (or all are below 4.1e9: seconds, which also covers
  relative times); values between the bands, or spanning two, are refused as ambiguous;
* rows without a time are dropped; rows are sorted by time (a step back in time is a late message);
* rows sharing a timestamp are merged, each field taking its first non-missing value (the way an
  ADS-B decoder's position and velocity messages of one second belong together); positions more
  than 1 km apart at one time are refused (two aircraft in a file without ``icao24``);
* rows without a latitude, longitude or altitude are dropped;
* ``geoaltitude`` (geometric, height above the WGS84 ellipsoid) is used when present, its gaps
  filled from the barometric altitude plus the median geometric-minus-barometric offset of the
  rows that have both; without it the barometric altitude is *assumed* to be height above the
  ellipsoid, which is off by the pressure-altitude error (QNH, temperature) and the geoid
  undulation, often tens of metres;
* isolated fixes out of reach of the flight around them (faster than Mach 3 plus 50 m of position
  noise: bad decodes, spoofing) or outside the plausible latitude, longitude and altitude ranges
  are dropped, up to 5 % of a track (:data:`GLITCH_BUDGET`); more is refused.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from skyradar.errors import InputError

__all__ = [
    "EPOCH_UNITS",
    "GLITCH_BUDGET",
    "POSITION_NOISE_M",
    "time_seconds",
    "altitude_m",
    "clean_rows",
    "glitch_rows",
]

# Unix time of 1990-01-01 and 2100-01-01 in seconds: an epoch timestamp of real traffic lies between.
_EPOCH_BAND_S = (631_152_000.0, 4_102_444_800.0)
EPOCH_UNITS = (("s", 1.0), ("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9))
_SAME_TIME_MAX_SPREAD_M = 1000.0  # two fixes of one aircraft at one (1 s rounded) time are closer
_M_PER_DEG = 111_320.0  # metres per degree of latitude (rounded; used only for the 1 km check above)
# A fix may sit this far from where the previous one allows (ADS-B position quantisation, GNSS noise, m).
POSITION_NOISE_M = 50.0
# At most this share of a track's fixes may be dropped as glitches (implausible position or altitude);
# a track with more is refused: something other than an occasional bad message is wrong with it.
GLITCH_BUDGET = 0.05


def _numeric_unit(path: Path, col: str, values: np.ndarray) -> tuple[str, float]:
    """(unit, seconds per unit) of a numeric epoch column; InputError if no unit fits every value."""
    finite = np.abs(values[np.isfinite(values)])
    if finite.size == 0 or col == "time_s" or finite.max() < _EPOCH_BAND_S[1]:
        return "s", 1.0
    for unit, scale in EPOCH_UNITS[1:]:
        low, high = (b / scale for b in _EPOCH_BAND_S)
        if finite.min() >= low and finite.max() <= high:
            return unit, scale
    raise InputError(
        f"{path}: field '{col}' runs from {finite.min():.6g} to {finite.max():.6g}, which fits no one unit "
        "of unix time (s up to 4.1e9, ms 6.3e11..4.1e12, us, ns for 1990-2100): cannot tell the unit"
    )


def time_seconds(path: Path, df: pd.DataFrame) -> tuple[str, np.ndarray, str]:
    """(column, unix or relative seconds with NaN where missing, unit note) of ``time_s``/``timestamp``.

    Examples
    --------
    >>> col, t, note = time_seconds(Path("f.json"), pd.DataFrame({"timestamp": [1515748470000, None]}))
    >>> col, t.tolist(), note
    ('timestamp', [1515748470.0, nan], 'timestamp in epoch ms')
    """
    col = "time_s" if "time_s" in df.columns else "timestamp"
    if col not in df.columns:
        raise InputError(
            f"{path}: missing required field 'timestamp' (or 'time_s'); columns are {list(df.columns)}"
        )
    raw = df[col]
    if pd.api.types.is_datetime64_any_dtype(raw):
        parsed = raw
    else:
        numeric = pd.to_numeric(raw, errors="coerce")
        if pd.api.types.is_numeric_dtype(raw) or numeric.notna().sum() == raw.notna().sum():
            unit, scale = _numeric_unit(path, col, numeric.to_numpy(dtype=float))
            note = "" if unit == "s" else f"{col} in epoch {unit}"
            return col, numeric.to_numpy(dtype=float) * scale, note
        parsed = pd.to_datetime(raw, errors="coerce", utc=True, format="ISO8601")
        bad = parsed.isna() & raw.notna()
        if bad.any():
            row = int(np.nonzero(bad.to_numpy())[0][0])
            raise InputError(f"{path}: field '{col}' is not a time at row {row} ({raw.iloc[row]!r})")
    if parsed.dt.tz is None:
        parsed = parsed.dt.tz_localize("UTC")  # a time without a zone: UTC, as ADS-B services write
    seconds = (parsed - pd.Timestamp(0, tz="UTC")).dt.total_seconds().to_numpy(dtype=float)
    return col, np.where(parsed.isna().to_numpy(), np.nan, seconds), ""


def _number(df: pd.DataFrame, name: str) -> np.ndarray:
    return pd.to_numeric(df[name], errors="coerce").to_numpy(dtype=float)


def altitude_m(df: pd.DataFrame, impala: bool = False) -> tuple[np.ndarray, str, str]:
    """(altitude m with NaN where missing, field name for messages, note) from the altitude columns.

    ``alt_m`` (SI) is taken as is. Otherwise ``geoaltitude`` is preferred to the barometric
    ``altitude`` (``traffic``/OpenSky, ft) or ``baroaltitude`` (OpenSky Impala, m, ``impala=True``).

    Examples
    --------
    >>> alt, field, note = altitude_m(pd.DataFrame({"altitude": [1000.0], "geoaltitude": [1100.0]}))
    >>> round(float(alt[0]), 2), field, note
    (335.28, 'geoaltitude', '')
    """
    if "alt_m" in df.columns:
        return _number(df, "alt_m"), "alt_m", ""
    unit_m = 1.0 if impala else 0.3048  # Impala state vectors are in metres, traffic/OpenSky in feet
    baro_name = "baroaltitude" if impala else "altitude"
    baro = _number(df, baro_name) * unit_m if baro_name in df.columns else None
    if "geoaltitude" not in df.columns:
        if baro is None:
            raise InputError(f"missing required field '{baro_name}' (or 'geoaltitude', 'alt_m')")
        note = f"no geoaltitude: barometric '{baro_name}' taken as height above ellipsoid (QNH, geoid error)"
        return baro, baro_name, note
    geo = _number(df, "geoaltitude") * unit_m
    gaps = ~np.isfinite(geo)
    if baro is None or not gaps.any():
        return geo, "geoaltitude", ""
    both = np.isfinite(geo) & np.isfinite(baro)
    offset = float(np.median(geo[both] - baro[both])) if both.any() else 0.0
    fill = gaps & np.isfinite(baro)
    geo = np.where(fill, baro + offset, geo)
    how = f"+ median offset {offset:.0f} m" if both.any() else "(no row has both: offset 0)"
    return geo, "geoaltitude", f"{int(fill.sum())} geoaltitude gap(s) filled from '{baro_name}' {how}"


def _merge_same_times(path: Path, df: pd.DataFrame, t: np.ndarray, label: str) -> pd.DataFrame:
    """One row per time: each field's first non-missing value; refuse fixes more than 1 km apart."""
    work = df.assign(_t=t, _row=df.index.to_numpy())
    groups = work.groupby("_t", sort=True)
    if {"latitude", "longitude"} <= set(df.columns) and groups.ngroups < len(work):
        lat = pd.Series(_number(work, "latitude"), index=work.index).groupby(work["_t"])
        lon = pd.Series(_number(work, "longitude"), index=work.index).groupby(work["_t"])
        coslat = np.cos(np.radians(lat.mean().fillna(0.0).to_numpy()))
        spread = _M_PER_DEG * np.hypot(
            (lat.max() - lat.min()).fillna(0.0).to_numpy(),
            (lon.max() - lon.min()).fillna(0.0).to_numpy() * coslat,
        )
        far = np.flatnonzero(spread > _SAME_TIME_MAX_SPREAD_M)
        if far.size:
            rows = work.loc[work["_t"] == lat.max().index[far[0]], "_row"].tolist()
            raise InputError(
                f"{path}: field 'timestamp' repeats at rows {rows[:3]} with positions {spread[far[0]]:.0f} m "
                f"apart{label}: two aircraft in one track? (give each an 'icao24')"
            )
    merged = groups.first()  # first non-missing value per column and time
    return merged.reset_index().set_index("_row").rename_axis(None)


def _refuse_text(path: Path, df: pd.DataFrame, name: str, label: str) -> None:
    """Refuse a text that is not a number in a numeric field (``FL350``, ``1000ft``): an empty field is a
    missing value (the row is dropped and the drop reported), a word is a format this reader does not
    know, and dropping it would build the flight from the other rows without a word about why."""
    if name not in df.columns or pd.api.types.is_numeric_dtype(df[name]):
        return
    raw = df[name].astype(object)
    text = raw.map(lambda v: v.strip().lower() if isinstance(v, str) else None)
    words = text.notna() & ~text.isin(["", "nan", "ground"])  # readsb's "ground": no altitude
    bad = words & pd.to_numeric(raw.where(words), errors="coerce").isna()
    if bad.any():
        row = raw.index[int(np.flatnonzero(bad.to_numpy())[0])]
        raise InputError(
            f"{path}: field '{name}' is not a number at row {row} ({raw.loc[row]!r}){label}; "
            "give a number (or leave the field empty)"
        )


def clean_rows(
    path: Path, df: pd.DataFrame, impala: bool = False, label: str = ""
) -> tuple[pd.DataFrame, str, np.ndarray, np.ndarray, str, list[str]]:
    """Repair one aircraft's rows: ``(rows, time column, seconds, altitude m, altitude field, notes)``.

    Parameters
    ----------
    path : Path
        The file the rows come from, named in errors.
    df : pandas.DataFrame
        One aircraft's rows as read (:func:`skyradar.scene.adsb.read_track_table`).
    impala : bool
        OpenSky Impala state vectors: the barometric altitude is ``baroaltitude`` in m, not
        ``altitude`` in ft.
    label : str
        Appended to error messages (the aircraft, for a file of several).

    Returns
    -------
    rows : pandas.DataFrame
        The rows sorted by time, one per time, each with a finite latitude, longitude and
        altitude; the index keeps the file's row numbers for later messages.
    time_column : str
        ``time_s`` or ``timestamp``.
    time_s : ndarray
        The rows' times, unix or relative s.
    alt_m : ndarray
        The rows' altitudes, m.
    alt_field : str
        The column the altitudes come from, for messages.
    notes : list of str
        One phrase per repair.

    Examples
    --------
    A row out of order, a velocity-only row sharing a timestamp, and a row without a position:

    >>> df = pd.DataFrame({"timestamp": [20.0, 0.0, 10.0, 10.0, 30.0],
    ...                    "latitude": [52.002, 52.0, 52.001, None, None],
    ...                    "longitude": [4.0, 4.0, 4.0, None, 4.0], "alt_m": [300.0] * 5})
    >>> rows, col, t, alt, field, notes = clean_rows(Path("f.csv"), df)
    >>> rows.index.tolist(), col, t.tolist(), alt.tolist(), field
    ([1, 2, 0], 'timestamp', [0.0, 10.0, 20.0], [300.0, 300.0, 300.0], 'alt_m')
    >>> for note in notes:
    ...     print(note)
    sorted by time (1 step(s) back)
    merged 1 row(s) sharing a timestamp
    dropped 1 row(s) without a position
    """
    col, t, unit_note = time_seconds(path, df)
    notes = [unit_note] if unit_note else []
    no_time = ~np.isfinite(t)
    if no_time.any():
        notes.append(f"dropped {int(no_time.sum())} row(s) without a time")
        df, t = df[~no_time], t[~no_time]
    steps_back = int(np.sum(np.diff(t) < 0))
    if steps_back:
        notes.append(f"sorted by time ({steps_back} step(s) back)")
    n_before = len(df)
    df = _merge_same_times(path, df, t, label)
    t = df.pop("_t").to_numpy(dtype=float)
    if len(df) < n_before:
        notes.append(f"merged {n_before - len(df)} row(s) sharing a timestamp")
    for name in ("latitude", "longitude", "alt_m", "geoaltitude", "baroaltitude" if impala else "altitude"):
        _refuse_text(path, df, name, label)
    try:
        alt, alt_field, alt_note = altitude_m(df, impala)
    except InputError as exc:
        raise InputError(f"{path}: {exc}{label}; columns are {list(df.columns)}") from None
    notes += [alt_note] if alt_note else []
    lat_lon = [_number(df, c) if c in df.columns else None for c in ("latitude", "longitude")]
    for name, values in zip(("latitude", "longitude"), lat_lon, strict=True):
        if values is None:
            raise InputError(f"{path}: missing required field '{name}'; columns are {list(df.columns)}")
    lat, lon = lat_lon
    assert lat is not None and lon is not None  # both present: checked above
    no_position = ~(np.isfinite(lat) & np.isfinite(lon))
    no_altitude = ~np.isfinite(alt) & ~no_position
    no_fix = no_position | no_altitude
    if no_position.any():
        notes.append(f"dropped {int(no_position.sum())} row(s) without a position")
    if no_altitude.any():
        first = df.index[int(np.flatnonzero(no_altitude)[0])]
        notes.append(
            f"dropped {int(no_altitude.sum())} row(s) without an altitude ('{alt_field}' empty or not "
            f"a number; first: row {first})"
        )
    if no_fix.any():
        df, t, alt = df[~no_fix], t[~no_fix], alt[~no_fix]
    return df, col, t, alt, alt_field, notes


def _consistent(pos: np.ndarray, t: np.ndarray, i: int, j: int, max_speed_mps: float) -> bool:
    """Whether fixes i and j are within reach of each other (plus the position noise allowance)."""
    return bool(np.linalg.norm(pos[j] - pos[i]) <= max_speed_mps * abs(t[j] - t[i]) + POSITION_NOISE_M)


def glitch_rows(pos: np.ndarray, t: np.ndarray, max_speed_mps: float) -> np.ndarray:
    """Mask of fixes out of reach of the flight around them (bad decodes, spoofed or stale positions).

    From an anchor (the first fix consistent with its next two, else with its next one), a fix is
    kept when it is within ``max_speed_mps * dt + POSITION_NOISE_M`` of the last kept fix, walking
    forward and then back from the anchor; every other fix is a glitch (all of them without anchor).

    Examples
    --------
    >>> t = np.arange(5.0)
    >>> pos = np.array([[0, 0, 0], [50, 0, 0], [9e4, 0, 0], [150, 0, 0], [200, 0, 0]], float)
    >>> glitch_rows(pos, t, 1029.0).tolist()
    [False, False, True, False, False]
    """
    n = len(t)
    bad = np.ones(n, bool)
    step = np.linalg.norm(np.diff(pos, axis=0), axis=1) <= max_speed_mps * np.diff(t) + POSITION_NOISE_M
    runs = np.flatnonzero(step[:-1] & step[1:])  # fixes i, i+1, i+2 agree: a safer anchor than a pair
    pairs = np.flatnonzero(step)
    anchor = int(runs[0]) if runs.size else (int(pairs[0]) if pairs.size else None)
    if anchor is None:
        return bad
    for order in (range(anchor, n), range(anchor, -1, -1)):
        last = anchor
        for i in order:
            if i == anchor or _consistent(pos, t, last, i, max_speed_mps):
                bad[i], last = False, i
    return bad


def readsb_trace(data: dict) -> pd.DataFrame:
    """A readsb / ADS-B Exchange ``trace_full_*.json`` file as rows in the ``traffic`` convention.

    The file is ``{"icao": ..., "timestamp": unix s, "trace": [[dt_s, lat, lon, alt_baro_ft or
    "ground", gs_kt, track_deg, flags, vrate_fpm, details or null, source, alt_geom_ft, ...], ...]}``
    (readsb's README-json). ``"ground"`` altitudes become missing (filled from ``alt_geom`` or
    dropped by :func:`clean_rows`).

    Examples
    --------
    >>> point = [0.0, 16.7, -88.0, 32000, 478.6, 327.8, 1, 0, None, "adsb_icao", 33825]
    >>> rows = readsb_trace({"icao": "ac671b", "timestamp": 100.0, "trace": [point]})
    >>> rows[["timestamp", "altitude", "geoaltitude", "icao24"]].values.tolist()
    [[100.0, 32000.0, 33825.0, 'ac671b']]
    """
    points = [p for p in data["trace"] if isinstance(p, list) and len(p) >= 8]
    if not points:
        raise InputError(
            "readsb trace: field 'trace' has no points [dt, lat, lon, alt, gs, track, flags, vrate...]"
        )

    def column(k: int) -> list:
        def number(v) -> bool:
            return isinstance(v, int | float) and not isinstance(v, bool)

        return [p[k] if len(p) > k and number(p[k]) else np.nan for p in points]

    rows = pd.DataFrame(
        {
            "timestamp": float(data["timestamp"]) + np.asarray(column(0), float),
            "latitude": column(1),
            "longitude": column(2),
            "altitude": column(3),
            "groundspeed": column(4),
            "track": column(5),
            "vertical_rate": column(7),
            "geoaltitude": column(10),
        },
        dtype=float,
    )
    rows["icao24"] = str(data.get("icao", "trace"))
    flights = [p[8].get("flight") for p in points if isinstance(p[8], dict) and p[8].get("flight")]
    if flights:
        rows["callsign"] = str(flights[0]).strip()
    return rows
