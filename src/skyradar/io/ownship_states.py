"""The own-ship's navigated state per frame, one typed object where process, clutter and alerting meet.

:class:`OwnShipStates` holds one array per quantity (SI units in the names) and the run's flags
(``has_geo``, ``navigation_source``). It is built from a frames run
(:meth:`OwnShipStates.from_frames`, the navigation solution of
:func:`skyradar.io.navigation.navigation_state`, never the truth) or from columns named as in the
own-ship table (:meth:`OwnShipStates.from_columns`, e.g. an own-ship table interpolated to the
tracks' times). Inside, consumers work on the plain arrays.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields
from typing import Any, Literal

import numpy as np
import xarray as xr

from skyradar.io.navigation import NAVIGATION_SOURCES, STATE_COLUMNS, navigation_state

__all__ = ["OwnShipStates", "NavigationSource", "REQUIRED_COLUMNS"]

NavigationSource = Literal["navigation", "truth"]  # skyradar.io.navigation.NAVIGATION_SOURCES

# The own-ship table's columns every state needs: time, NED position and velocity.
REQUIRED_COLUMNS = ("time_s", *STATE_COLUMNS[:6])  # north, east, down; vn, ve, vd
_ATTITUDE = ("own_yaw_rad", "own_pitch_rad", "own_roll_rad")
_GEO = ("own_lat_deg", "own_lon_deg", "own_alt_m")
# An unknown height above the ground stays unknown (NaN); an unknown attitude or geodetic fix reads
# as 0 (level flight, and ``has_geo`` False so that no consumer uses the fix).
_FILL = dict.fromkeys(_ATTITUDE + _GEO, 0.0) | {"own_height_agl_m": np.nan}


@dataclass(frozen=True, eq=False)
class OwnShipStates:
    """The own-ship's navigated state at ``n`` times: one read-only float64 array per quantity.

    Positions and velocities are in the scenario's NED frame (north, east, down). Every array is
    copied on construction and made read-only, so a state never changes under its consumers.

    Parameters
    ----------
    time_s : ndarray
        Times of the states, s.
    north_m, east_m, down_m : ndarray
        Position in the scenario NED frame, m.
    vn_mps, ve_mps, vd_mps : ndarray
        Velocity north, east and down, m/s.
    yaw_rad, pitch_rad, roll_rad : ndarray
        Attitude (heading, pitch, roll; 0 where the source has none), rad.
    lat_deg, lon_deg : ndarray
        WGS84 geodetic latitude and longitude, deg (meaningful only when ``has_geo``).
    alt_m : ndarray
        Height above the WGS84 ellipsoid, m (meaningful only when ``has_geo``).
    height_agl_m : ndarray
        Navigated height above the ground below, m (NaN where unknown).
    has_geo : bool
        Whether the source holds a geodetic fix (``lat_deg``, ``lon_deg``, ``alt_m``).
    navigation_source : {"navigation", "truth"} or None
        Where the state comes from: the navigation solution (``nav_*``), the own-ship truth of a
        store written without one (``own_*``), or None when unknown (a hand-made table).

    Raises
    ------
    ValueError
        When an array is not one-dimensional, the lengths differ, or ``navigation_source`` is not
        one of :data:`skyradar.io.navigation.NAVIGATION_SOURCES` or None.

    Examples
    --------
    >>> import numpy as np
    >>> own = OwnShipStates.from_columns(
    ...     {"time_s": [0.0, 1.0, 2.0], "own_north_m": [0.0, 50.0, 100.0], "own_east_m": np.zeros(3),
    ...      "own_down_m": np.full(3, -500.0), "own_vn_mps": np.full(3, 50.0), "own_ve_mps": np.zeros(3),
    ...      "own_vd_mps": np.zeros(3)})
    >>> len(own), own.has_geo, float(own.height_agl_m[0])
    (3, False, nan)
    >>> own.select(slice(1, None)).north_m.tolist()
    [50.0, 100.0]
    >>> own.position_ned_m[-1].tolist()
    [100.0, 0.0, -500.0]
    """

    time_s: np.ndarray
    north_m: np.ndarray
    east_m: np.ndarray
    down_m: np.ndarray
    vn_mps: np.ndarray
    ve_mps: np.ndarray
    vd_mps: np.ndarray
    yaw_rad: np.ndarray
    pitch_rad: np.ndarray
    roll_rad: np.ndarray
    lat_deg: np.ndarray
    lon_deg: np.ndarray
    alt_m: np.ndarray
    height_agl_m: np.ndarray
    has_geo: bool = False
    navigation_source: NavigationSource | None = None

    def __post_init__(self) -> None:
        n = None
        for name in _ARRAY_FIELDS:
            values = np.array(getattr(self, name), dtype=float)
            if values.ndim != 1:
                raise ValueError(f"OwnShipStates: field '{name}' must be one-dimensional, got {values.shape}")
            if n is None:
                n = values.size
            elif values.size != n:
                raise ValueError(f"OwnShipStates: field '{name}' has {values.size} values, 'time_s' has {n}")
            values.setflags(write=False)
            object.__setattr__(self, name, values)
        object.__setattr__(self, "has_geo", bool(self.has_geo))
        if self.navigation_source is not None and self.navigation_source not in NAVIGATION_SOURCES:
            raise ValueError(
                f"OwnShipStates: field 'navigation_source' must be one of {', '.join(NAVIGATION_SOURCES)} "
                f"or None, got {self.navigation_source!r}"
            )

    def __len__(self) -> int:
        return int(self.time_s.size)

    def select(self, index: Any) -> OwnShipStates:
        """The states at ``index``: a slice, integer indices or a boolean mask (an integer keeps one state).

        Parameters
        ----------
        index : slice, int, array of int or array of bool
            Which states to keep, as numpy indexes a one-dimensional array.

        Returns
        -------
        OwnShipStates
            The kept states, with the same flags.
        """
        if isinstance(index, (int, np.integer)):
            index = [index]
        return OwnShipStates(
            **{name: getattr(self, name)[index] for name in _ARRAY_FIELDS},
            has_geo=self.has_geo,
            navigation_source=self.navigation_source,
        )

    def __getitem__(self, index: Any) -> OwnShipStates:
        """``states[index]`` is :meth:`select`."""
        return self.select(index)

    @property
    def position_ned_m(self) -> np.ndarray:
        """Positions (n, 3): north, east, down, m."""
        return np.stack([self.north_m, self.east_m, self.down_m], -1)

    @property
    def velocity_ned_mps(self) -> np.ndarray:
        """Velocities (n, 3): north, east, down, m/s."""
        return np.stack([self.vn_mps, self.ve_mps, self.vd_mps], -1)

    @classmethod
    def from_columns(
        cls, columns: Mapping[str, Any], navigation_source: NavigationSource | None = None
    ) -> OwnShipStates:
        """States from columns named as in the own-ship table (``time_s``, ``own_*``).

        Parameters
        ----------
        columns : mapping of str to array_like
            Must hold :data:`REQUIRED_COLUMNS`; may hold ``own_yaw_rad``, ``own_pitch_rad``,
            ``own_roll_rad`` (absent: 0 rad), ``own_lat_deg``, ``own_lon_deg``, ``own_alt_m``
            (``has_geo`` when all three are present; absent: 0) and ``own_height_agl_m`` (absent:
            NaN, unknown). Other keys are ignored. A pandas DataFrame serves as well as a dict.
        navigation_source : {"navigation", "truth"} or None
            Where the columns come from.

        Returns
        -------
        OwnShipStates

        Raises
        ------
        KeyError
            When a required column is missing.
        """
        missing = [name for name in REQUIRED_COLUMNS if name not in columns]
        if missing:
            raise KeyError(f"OwnShipStates: missing column(s) {', '.join(missing)}")
        n = np.size(columns["time_s"])
        values = {name[4:] if name.startswith("own_") else name: columns[name] for name in REQUIRED_COLUMNS}
        for name, fill in _FILL.items():
            values[name[4:]] = columns[name] if name in columns else np.full(n, fill)
        return cls(
            **values,
            has_geo=all(name in columns for name in _GEO),
            navigation_source=navigation_source,
        )

    @classmethod
    def from_frames(cls, ds: xr.Dataset, source: str = "frames") -> OwnShipStates | None:
        """The navigated state at every frame of a frames run, or None without position and velocity.

        Parameters
        ----------
        ds : xr.Dataset
            A frames Dataset (its ``nav_*`` variables; ``own_*`` only in stores written without
            navigation, :func:`skyradar.io.navigation.navigation_state`).
        source : str
            Name of the run, for the note logged when the state falls back to the truth.

        Returns
        -------
        OwnShipStates or None
            None when the run lacks any of the position and velocity variables.

        Examples
        --------
        >>> ds = xr.Dataset({f"nav_{k}": ("time", [1.0, 2.0]) for k in
        ...                  ("north_m", "east_m", "down_m", "vn_mps", "ve_mps", "vd_mps")},
        ...                 coords={"time": [0.0, 0.1]})
        >>> own = OwnShipStates.from_frames(ds)
        >>> own.north_m.tolist(), own.navigation_source, own.has_geo
        ([1.0, 2.0], 'navigation', False)
        """
        nav = navigation_state(ds, source)
        if nav is None or not all(name in nav for name in REQUIRED_COLUMNS):
            return None
        columns = {name: nav[name].to_numpy(float) for name in nav.columns}
        return cls.from_columns(columns, nav.attrs["navigation_source"])

    @classmethod
    def concatenate(cls, states: Sequence[OwnShipStates]) -> OwnShipStates:
        """The states of ``states`` one after the other, with the flags of the last (the newest).

        Parameters
        ----------
        states : sequence of OwnShipStates
            At least one.

        Returns
        -------
        OwnShipStates
        """
        if not states:
            raise ValueError("OwnShipStates.concatenate: no states")
        last = states[-1]
        return cls(
            **{name: np.concatenate([getattr(s, name) for s in states]) for name in _ARRAY_FIELDS},
            has_geo=last.has_geo,
            navigation_source=last.navigation_source,
        )


_ARRAY_FIELDS = tuple(f.name for f in fields(OwnShipStates) if f.name not in ("has_geo", "navigation_source"))
