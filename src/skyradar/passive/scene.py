"""The scene of a passive receiver: receiver and illuminator sites, static reflectors, aircraft, and truth.

Everything is in the local NED frame of the receiving antenna (its geodetic position is the recording's
``core:geolocation``). Static reflectors are point scatterers with an RCS: building clusters (groups of
points) and ground clutter. Aircraft follow any :class:`~skyradar.scene.trajectories.Trajectory`
(synthetic, or an ADS-B file read by :mod:`skyradar.scene.adsb`), re-expressed in the receiver's frame.

:func:`bistatic_geometry` is the forward model the simulator and the truth share: for a reflector at
``p`` with velocity ``v``, transmitter at ``T`` and receiver at ``R``,
``r_tx = |p - T|``, ``r_rx = |p - R|``, the bistatic range ``r_tx + r_rx - L`` (``L = |T - R|``, the
excess path over the direct signal, i.e. ``c`` times the delay after the direct pulse) and the bistatic
Doppler ``-(v . u_tx + v . u_rx) / lambda`` (``u`` the unit vectors from each site to the reflector).

:func:`thesis_scene` is the geometry of Maas 2022, ch. 7: a receiver on a 40 m tower 12 km from the
radar, five urban clusters at 14-20 km from the receiver, ground clutter, and a small aircraft (RCS
1 m^2) flying 1.5-2.8 km from the receiver during a 40 s (9-sweep) recording.
"""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from skyradar.errors import InputError
from skyradar.geo import EARTH_RADIUS_M, geodetic_to_ned, ned_to_geodetic
from skyradar.passive.budget import BOLTZMANN_J_K, T0_K
from skyradar.passive.illuminator import C_MPS, Illuminator
from skyradar.scene.trajectories import Trajectory

__all__ = [
    "Receiver",
    "Reflectors",
    "Aircraft",
    "PassiveScene",
    "bistatic_geometry",
    "building_cluster",
    "ground_clutter",
    "aircraft_from_adsb",
    "thesis_scene",
]


@dataclass(frozen=True)
class Receiver:
    """The receiving antenna's site (WGS84: deg, deg, m above the ellipsoid) and front end.

    Attributes
    ----------
    latitude, longitude : float
        Geodetic position, deg.
    altitude : float
        Height of the antenna above the WGS84 ellipsoid, m.
    noise_figure_db : float
        Front-end noise figure, dB.
    antenna_gain_dbi : float
        Antenna gain, dBi.
    height_above_ground_m : float
        Height of the antenna above the ground, m.

    Examples
    --------
    Thermal noise in 1 MHz: -174 dBm/Hz + 60 dB + 5 dB noise figure.

    >>> rx = Receiver(52.0, 5.0, 40.0)
    >>> round(float(10 * np.log10(rx.noise_power_w(1e6) / 1e-3)), 1), rx.geodetic
    (-109.0, (52.0, 5.0, 40.0))
    """

    latitude: float
    longitude: float
    altitude: float
    noise_figure_db: float = 5.0
    antenna_gain_dbi: float = 2.0
    height_above_ground_m: float = 40.0

    @property
    def geodetic(self) -> tuple[float, float, float]:
        return (self.latitude, self.longitude, self.altitude)

    def noise_power_w(self, bandwidth_hz: float) -> float:
        """Thermal noise referred to the input, ``k T0 F B`` (complex baseband: B = sample rate)."""
        return BOLTZMANN_J_K * T0_K * 10.0 ** (self.noise_figure_db / 10.0) * bandwidth_hz

    def position_dict(self) -> dict:
        return {"latitude": self.latitude, "longitude": self.longitude, "altitude": self.altitude}

    def info(self) -> dict:
        return {
            "noise_figure_db": self.noise_figure_db,
            "antenna_gain_dbi": self.antenna_gain_dbi,
            "height_above_ground_m": self.height_above_ground_m,
        }


@dataclass(frozen=True)
class Reflectors:
    """Static point scatterers: NED positions (n, 3) m, RCS (n,) m^2, kind and group name per point.

    Attributes
    ----------
    position_ned_m : ndarray
        Positions in the receiver's NED frame, (n, 3), m.
    rcs_m2 : ndarray
        Radar cross-section of each point, (n,), m^2 (finite, >= 0).
    kind : ndarray
        Kind of each point (``"building"``, ``"clutter"``), (n,); one value is broadcast to all.
    group : ndarray
        Group name of each point (the cluster's), (n,); one value is broadcast to all.

    Examples
    --------
    >>> town = Reflectors([[100.0, 0.0, 20.0], [120.0, 5.0, 20.0]], [10.0, 30.0], "building", "town")
    >>> both = Reflectors.concat([town, Reflectors([0.0, 900.0, 40.0], 0.5, "clutter", "ground")])
    >>> len(both), both.position_ned_m.shape, both.kind.tolist()
    (3, (3, 3), ['building', 'building', 'clutter'])
    >>> Reflectors([[0.0, 0.0, 0.0]], [-1.0], "building", "x")
    Traceback (most recent call last):
    ...
    skyradar.errors.InputError: reflectors: need finite positions (n, 3) and rcs_m2 >= 0 (n,), got 1, (1,)
    """

    position_ned_m: np.ndarray
    rcs_m2: np.ndarray
    kind: np.ndarray
    group: np.ndarray

    if TYPE_CHECKING:
        # The constructor takes anything array-like (a single kind or group name for all the points);
        # __post_init__ turns each into its array. The dataclass writes the real __init__.
        def __init__(
            self, position_ned_m: ArrayLike, rcs_m2: ArrayLike, kind: ArrayLike, group: ArrayLike
        ) -> None: ...

    def __post_init__(self) -> None:
        pos = np.asarray(self.position_ned_m, dtype=float).reshape(-1, 3)
        n = pos.shape[0]
        rcs = np.asarray(self.rcs_m2, dtype=float).reshape(-1)
        if rcs.shape != (n,) or np.any(~np.isfinite(rcs)) or np.any(rcs < 0) or np.any(~np.isfinite(pos)):
            raise InputError(
                f"reflectors: need finite positions (n, 3) and rcs_m2 >= 0 (n,), got {n}, {rcs.shape}"
            )
        object.__setattr__(self, "position_ned_m", pos)
        object.__setattr__(self, "rcs_m2", rcs)
        object.__setattr__(self, "kind", np.broadcast_to(np.asarray(self.kind, dtype=object), (n,)).copy())
        object.__setattr__(self, "group", np.broadcast_to(np.asarray(self.group, dtype=object), (n,)).copy())

    def __len__(self) -> int:
        return self.rcs_m2.size

    @staticmethod
    def concat(parts: list[Reflectors]) -> Reflectors:
        if not parts:
            return Reflectors(np.zeros((0, 3)), np.zeros(0), np.zeros(0, object), np.zeros(0, object))
        return Reflectors(
            np.concatenate([p.position_ned_m for p in parts]),
            np.concatenate([p.rcs_m2 for p in parts]),
            np.concatenate([p.kind for p in parts]),
            np.concatenate([p.group for p in parts]),
        )


@dataclass(frozen=True)
class Aircraft:
    """An aircraft of constant RCS on a trajectory in the receiver's NED frame.

    Recording time ``t`` is trajectory time ``t + time_offset_s``; outside the trajectory's span the
    aircraft is absent.

    Attributes
    ----------
    trajectory : Trajectory
        The flight, positions in the receiver's NED frame (m).
    rcs_m2 : float
        Radar cross-section, m^2.
    time_offset_s : float
        Trajectory time at recording time 0, s.

    Examples
    --------
    North at 50 m/s over trajectory times 0-10 s, seen from recording time 0 at trajectory time 4 s:

    >>> from skyradar.scene.trajectories import Trajectory
    >>> traj = Trajectory.from_states([0.0, 10.0], [[0, 0, -500], [500, 0, -500]], [[50, 0, 0]] * 2,
    ...                               origin=(52.0, 5.0, 40.0), name="GA1")
    >>> present, pos, vel = Aircraft(traj, rcs_m2=2.0, time_offset_s=4.0).states(np.array([0.0, 2.0, 8.0]))
    >>> present.tolist(), pos[:, 0].round(3).tolist()
    ([True, True, False], [200.0, 300.0, nan])
    """

    trajectory: Trajectory
    rcs_m2: float = 1.0
    time_offset_s: float = 0.0

    @property
    def name(self) -> str:
        return self.trajectory.name

    def states(self, t_s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(present mask, positions (n, 3), velocities (n, 3)) at recording times ``t_s``."""
        t = np.asarray(t_s, dtype=float) + self.time_offset_s
        present = self.trajectory.covers(t)
        pos = np.full((t.size, 3), np.nan)
        vel = np.zeros((t.size, 3))
        if present.any():
            s = self.trajectory.sample(t[present])
            pos[present], vel[present] = s.position_ned_m, s.velocity_ned_mps
        return present, pos, vel


def bistatic_geometry(
    position_ned_m: np.ndarray,
    velocity_ned_mps: np.ndarray,
    tx_ned_m: np.ndarray,
    wavelength_m: float,
    rx_ned_m: np.ndarray | None = None,
) -> dict[str, np.ndarray]:
    """Ranges, bistatic range (excess path over the direct one) and bistatic Doppler of reflectors.

    Returns a dict of arrays: ``r_tx_m``, ``r_rx_m``, ``bistatic_range_m`` (``r_tx + r_rx - L``),
    ``delay_s`` (after the direct pulse), ``bistatic_doppler_hz`` and ``range_sum_rate_mps``.

    Examples
    --------
    A reflector on the far extension of the baseline, moving away from both: range rate 2 v.

    >>> g = bistatic_geometry([[0.0, 3000.0, 0.0]], [[0.0, 10.0, 0.0]], [0.0, -1000.0, 0.0], 0.1)
    >>> float(g["bistatic_range_m"][0]), float(g["bistatic_doppler_hz"][0])
    (6000.0, -200.0)
    """
    p = np.asarray(position_ned_m, dtype=float).reshape(-1, 3)
    v = np.asarray(velocity_ned_mps, dtype=float).reshape(-1, 3)
    tx = np.asarray(tx_ned_m, dtype=float)
    rx = np.zeros(3) if rx_ned_m is None else np.asarray(rx_ned_m, dtype=float)
    d_tx, d_rx = p - tx, p - rx
    r_tx, r_rx = np.linalg.norm(d_tx, axis=1), np.linalg.norm(d_rx, axis=1)
    rate = np.einsum("ij,ij->i", v, d_tx) / r_tx + np.einsum("ij,ij->i", v, d_rx) / r_rx
    bistatic = r_tx + r_rx - float(np.linalg.norm(tx - rx))
    return {
        "r_tx_m": r_tx,
        "r_rx_m": r_rx,
        "bistatic_range_m": bistatic,
        "delay_s": bistatic / C_MPS,
        "range_sum_rate_mps": rate,
        "bistatic_doppler_hz": -rate / wavelength_m,
    }


def _ground_down(north: np.ndarray, east: np.ndarray, drop_m: float) -> np.ndarray:
    # Ground ``drop_m`` below the antenna, plus the Earth's curvature (NED is a tangent plane).
    return drop_m + (north**2 + east**2) / (2.0 * EARTH_RADIUS_M)


def building_cluster(
    name: str,
    bearing_deg: float,
    distance_m: float,
    rng: np.random.Generator,
    n_points: int = 40,
    radius_m: float = 400.0,
    rcs_median_m2: float = 1000.0,
    height_below_antenna_m: float = 25.0,
) -> Reflectors:
    """A town as a Gaussian cloud of point scatterers with log-normal RCS (sigma 1 neper), at a bearing and
    distance from the receiver.

    A median of 1000 m^2 per point (walls and roofs facing both sites, corner reflections) puts a town
    15-20 dB above the rural clutter points around it, as the towns stood out in the thesis' recording.

    Parameters
    ----------
    name : str
        The cluster's group name.
    bearing_deg : float
        Bearing of the cluster's centre from the receiver, clockwise from north, deg.
    distance_m : float
        Horizontal distance of the centre from the receiver, m.
    rng : numpy.random.Generator
        Source of the point positions and RCS.
    n_points : int
        Number of points.
    radius_m : float
        Twice the standard deviation of the points' horizontal scatter around the centre, m.
    rcs_median_m2 : float
        Median RCS per point, m^2.
    height_below_antenna_m : float
        Height of the ground below the antenna at the receiver, m (the Earth's curvature is added).

    Returns
    -------
    Reflectors
        ``n_points`` points of kind ``"building"`` and group ``name``.

    Examples
    --------
    A town 10 km due east: the points' down coordinate is 25 m plus the curvature drop
    ``(10 km)^2 / (2 R)``, about 7.8 m.

    >>> c = building_cluster("town", 90.0, 10_000.0, np.random.default_rng(0), n_points=200, radius_m=100.0)
    >>> east, down = c.position_ned_m[:, 1].mean(), c.position_ned_m[:, 2].mean()
    >>> len(c), set(c.group), round(float(east), -2), round(float(down))
    (200, {'town'}, 10000.0, 33)
    """
    centre = distance_m * np.array([np.cos(np.radians(bearing_deg)), np.sin(np.radians(bearing_deg))])
    ne = centre + rng.normal(0.0, radius_m / 2.0, size=(n_points, 2))
    down = _ground_down(ne[:, 0], ne[:, 1], height_below_antenna_m)
    rcs = rcs_median_m2 * np.exp(rng.normal(0.0, 1.0, n_points))
    return Reflectors(np.column_stack([ne, down]), rcs, "building", name)


def ground_clutter(
    rng: np.random.Generator,
    tx_ned_m: np.ndarray,
    n_points: int = 800,
    max_distance_m: float = 22_000.0,
    sigma0_db: float = -50.0,
    exclusion_m: float = 1500.0,
    height_below_antenna_m: float = 40.0,
) -> Reflectors:
    """Ground clutter: points uniform over a disc around the receiver, each with RCS ``sigma0 * area / n``.

    Points nearer the transmitter than ``exclusion_m`` are dropped: a PSR's elevation pattern and site
    screening keep its own surroundings out of the beam. ``sigma0_db`` about -50 dB: low-grazing rural
    land at S band, most of it shadowed.

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of the point positions.
    tx_ned_m : ndarray
        The transmitter's position in the receiver's NED frame, m.
    n_points : int
        Number of points drawn over the disc (before the exclusion).
    max_distance_m : float
        Radius of the disc, m.
    sigma0_db : float
        Clutter reflectivity (RCS per unit ground area), dB m^2/m^2.
    exclusion_m : float
        Points within this horizontal distance of the transmitter are dropped, m.
    height_below_antenna_m : float
        Height of the ground below the antenna at the receiver, m (the Earth's curvature is added).

    Returns
    -------
    Reflectors
        The kept points, kind ``"clutter"``, group ``"ground"``.

    Examples
    --------
    Each point carries 1e-5 * pi * (22 km)^2 / 800 = 19.0 m^2:

    >>> tx = np.array([0.0, -12000.0, 0.0])
    >>> g = ground_clutter(np.random.default_rng(0), tx)
    >>> from_tx = np.hypot(*(g.position_ned_m[:, :2] - tx[:2]).T)
    >>> round(float(g.rcs_m2[0]), 1), len(g) < 800, bool(from_tx.min() > 1500)
    (19.0, True, True)
    """
    r = max_distance_m * np.sqrt(rng.uniform(0.0, 1.0, n_points))
    phi = rng.uniform(0.0, 2 * np.pi, n_points)
    ne = np.column_stack([r * np.cos(phi), r * np.sin(phi)])
    keep = np.hypot(ne[:, 0] - tx_ned_m[0], ne[:, 1] - tx_ned_m[1]) > exclusion_m
    ne = ne[keep]
    rcs = np.full(ne.shape[0], 10.0 ** (sigma0_db / 10.0) * np.pi * max_distance_m**2 / n_points)
    down = _ground_down(ne[:, 0], ne[:, 1], height_below_antenna_m)
    return Reflectors(np.column_stack([ne, down]), rcs, "clutter", "ground")


@dataclass(frozen=True)
class PassiveScene:
    """Everything the recording simulator needs; positions in the receiver's NED frame.

    ``azimuth_at_t0_rad`` is the beam azimuth at the first sample and ``first_pulse_s`` the emission
    time of PRI 0 on the recording's clock: the processor must find both from the direct path.

    Attributes
    ----------
    receiver : Receiver
        The receiving site; the scene's NED frame is centred on it.
    illuminator : Illuminator
        The transmitting radar.
    reflectors : Reflectors
        Static point scatterers.
    aircraft : tuple of Aircraft
        Moving reflectors.
    duration_s : float
        Length of the recording, s.
    azimuth_at_t0_rad : float
        Beam azimuth at the first sample, clockwise from north, rad.
    first_pulse_s : float
        Emission time of PRI 0, s from the first sample.
    start_time : datetime
        Wall-clock time of the first sample.
    seed : int
        Seed of the receiver noise.
    description : str
        The recording's description.

    Examples
    --------
    The illuminator 12 km due west: the beam, starting north and turning at 13.5 rpm (4.44 s a turn),
    points east at the receiver after a quarter turn and then once per turn.

    >>> from skyradar.geo import ned_to_geodetic
    >>> from skyradar.passive.illuminator import Illuminator
    >>> rx = Receiver(52.0, 5.0, 40.0)
    >>> ill = Illuminator(*map(float, ned_to_geodetic(np.array([0.0, -12000.0, 0.0]), *rx.geodetic)))
    >>> mast = Reflectors([[0.0, 4000.0, 0.0]], [10.0], "building", "mast")
    >>> scene = PassiveScene(rx, ill, mast, duration_s=8.0)
    >>> round(scene.baseline_m, 3), np.degrees(scene.azimuth_from_tx_rad([[0.0, 0.0, 0.0]])).round(6).tolist()
    (12000.0, [90.0])
    >>> scene.receiver_crossing_times_s.round(3).tolist()
    [1.111, 5.556]

    A crossing due exactly at the end of a 10 s recording is after its last sample:

    >>> from dataclasses import replace
    >>> replace(scene, duration_s=10.0).receiver_crossing_times_s.round(3).tolist()
    [1.111, 5.556]
    """

    receiver: Receiver
    illuminator: Illuminator
    reflectors: Reflectors
    aircraft: tuple[Aircraft, ...] = ()
    duration_s: float = 40.0
    azimuth_at_t0_rad: float = 0.0
    first_pulse_s: float = 0.0
    start_time: dt.datetime = field(default_factory=lambda: dt.datetime(2026, 6, 1, 10, 0, tzinfo=dt.UTC))
    seed: int = 0
    description: str = "simulated passive radar recording"

    def __post_init__(self) -> None:
        if not np.isfinite(self.duration_s) or self.duration_s <= 0:
            raise InputError(f"passive scene: field 'duration_s' must be > 0, got {self.duration_s!r}")

    @cached_property
    def illuminator_ned_m(self) -> np.ndarray:
        ill = self.illuminator
        return geodetic_to_ned(ill.latitude, ill.longitude, ill.altitude, *self.receiver.geodetic)

    @property
    def baseline_m(self) -> float:
        return float(np.linalg.norm(self.illuminator_ned_m))

    def azimuth_from_tx_rad(self, position_ned_m: np.ndarray) -> np.ndarray:
        """Azimuth (clockwise from north) of points seen from the transmitter, radians.

        A flat-plane azimuth in the receiver's frame: at 20 km the transmitter's own north differs from
        the receiver's by well under the beam's 0.1 deg pointing scale.
        """
        d = np.asarray(position_ned_m, dtype=float).reshape(-1, 3) - self.illuminator_ned_m
        return np.mod(np.arctan2(d[:, 1], d[:, 0]), 2 * np.pi)

    @property
    def receiver_crossing_times_s(self) -> np.ndarray:
        """Times the main beam points at the receiver (the direct path's scan peaks) within the recording."""
        return self._crossings(float(self.azimuth_from_tx_rad(np.zeros((1, 3)))[0]))

    def _crossings(self, azimuth_rad: float) -> np.ndarray:
        w = self.illuminator.rotation_rate_rad_s
        t0 = np.mod(azimuth_rad - self.azimuth_at_t0_rad, 2 * np.pi) / w
        period = 2 * np.pi / w
        # Crossings strictly before the end: one due at the end (to rounding) falls after the last
        # sample, and np.arange's float steps can land it a hair inside.
        count = max(int(np.ceil((self.duration_s - t0) / period - 1e-9)), 0)
        return t0 + period * np.arange(count)


def aircraft_from_adsb(
    path: str | Path, receiver: Receiver, start_time: dt.datetime | None = None, rcs_m2: float = 1.0
) -> list[Aircraft]:
    """Aircraft from an ADS-B/track file (CSV, Parquet, JSON; see :mod:`skyradar.scene.adsb`).

    With ``start_time`` and absolute timestamps in the file, recording time 0 is ``start_time``;
    otherwise it is the file's first timestamp. An ATC radar's traffic is of every type: each
    aircraft's path is built within the ``any`` class's limits (:mod:`skyradar.scene.flyable`).

    Parameters
    ----------
    path : str or Path
        The track file (one aircraft per ``icao24``).
    receiver : Receiver
        The receiver, whose NED frame the trajectories are expressed in.
    start_time : datetime, optional
        Wall-clock time of recording time 0.
    rcs_m2 : float
        Radar cross-section given to every aircraft, m^2.

    Returns
    -------
    list of Aircraft
        One per aircraft of the file, named by its ``icao24``.

    Examples
    --------
    An aircraft 500 m above the receiver flying north, 0.001 deg (111 m) every 10 s:

    >>> import tempfile, pathlib
    >>> rows = "0,abc123,52.0,5.0,540\\n10,abc123,52.001,5.0,540\\n20,abc123,52.002,5.0,540\\n"
    >>> with tempfile.TemporaryDirectory() as d:
    ...     f = pathlib.Path(d) / "traffic.csv"
    ...     _ = f.write_text("time_s,icao24,latitude,longitude,alt_m\\n" + rows)
    ...     planes = aircraft_from_adsb(f, Receiver(52.0, 5.0, 40.0), rcs_m2=3.0)
    >>> [(p.name, p.rcs_m2) for p in planes]
    [('abc123', 3.0)]
    >>> _, pos, _ = planes[0].states(np.array([0.0, 10.0]))
    >>> pos[:, [0, 2]].round(1).tolist()
    [[0.0, -500.0], [111.3, -500.0]]
    """
    from skyradar.scene.adsb import read_trajectories

    trajectories = read_trajectories(path, origin=receiver.geodetic, aircraft_class="any")
    out = []
    for traj in trajectories.values():
        offset = 0.0
        if start_time is not None and np.isfinite(traj.epoch_s):
            offset = start_time.timestamp() - traj.epoch_s
        out.append(Aircraft(traj, rcs_m2, offset))
    return out


def thesis_scene(duration_s: float = 40.0, seed: int = 0, aircraft: bool = True) -> PassiveScene:
    """The geometry of Maas 2022, ch. 7 (synthetic sites near Utrecht, NL; no real town is modelled).

    Receiver antenna on a 40 m tower; the PSR 12 km to the west-south-west (bearing 250 deg) on a 20 m
    mast; five building clusters 14.5-19.5 km from the receiver; 800 ground-clutter points; a small
    aircraft (RCS 1 m^2) at 450 m, 50 m/s on heading 300 deg, 1.6-2.8 km from the receiver. The beam
    starts 30 deg before the receiver's direction.

    Examples
    --------
    >>> s = thesis_scene()
    >>> round(s.baseline_m / 1e3, 2), round(s.illuminator.rotation_period_s * 9, 1), len(s.aircraft)
    (12.0, 40.0, 1)
    """
    rng = np.random.default_rng(seed)
    rx_lat, rx_lon, ground_m, tower_m = 52.10, 5.30, 5.0, 40.0
    receiver = Receiver(rx_lat, rx_lon, ground_m + tower_m, height_above_ground_m=tower_m)
    b = np.radians(250.0)
    tx_ned = np.array([12_000.0 * np.cos(b), 12_000.0 * np.sin(b), 0.0])
    tx_ned[2] = _ground_down(tx_ned[0], tx_ned[1], tower_m - 20.0)
    lat, lon, alt = ned_to_geodetic(tx_ned, *receiver.geodetic)
    illuminator = Illuminator(float(lat), float(lon), float(alt))
    clusters = [
        building_cluster(name, bearing, dist, rng)
        for name, bearing, dist in [
            ("cluster N 14.5 km", 20.0, 14_500.0),
            ("cluster E 15.5 km", 100.0, 15_500.0),  # 17 deg off the radar-to-receiver look
            ("cluster SE 17 km", 130.0, 17_000.0),
            ("cluster S 18.5 km", 170.0, 18_500.0),
            ("cluster NW 19.5 km", 320.0, 19_500.0),
        ]
    ]
    reflectors = Reflectors.concat([*clusters, ground_clutter(rng, tx_ned)])
    planes: tuple[Aircraft, ...] = ()
    if aircraft:
        heading = np.radians(300.0)
        vel = 50.0 * np.array([np.cos(heading), np.sin(heading), 0.0])
        start = np.array([1500.0, 500.0, -(450.0 - ground_m - tower_m)])
        t = np.linspace(-5.0, duration_s + 5.0, 9)
        traj = Trajectory.from_states(
            t, start + t[:, None] * vel, np.tile(vel, (t.size, 1)), origin=receiver.geodetic, name="aircraft"
        )
        planes = (Aircraft(traj, 1.0),)
    az_rx = np.mod(np.arctan2(-tx_ned[1], -tx_ned[0]), 2 * np.pi)
    return PassiveScene(
        receiver,
        illuminator,
        reflectors,
        planes,
        duration_s=duration_s,
        azimuth_at_t0_rad=float(az_rx - np.radians(30.0)),
        first_pulse_s=2.0e-4,
        seed=seed,
        description="Maas 2022 ch. 7 geometry: PSR 12 km from a tower receiver, 5 clusters, 1 aircraft",
    )
