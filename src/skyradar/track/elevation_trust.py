"""Which measured elevations a track's height may rest on, and where the others put a detection.

Clutter suppression (``process.clutter_frames``) measures a detection's elevation, or leaves it
unmeasured where the nulls take the elevation dimension of the 2x2 array (``elevation_measured``
False; the direction then holds the co-altitude prior). A *measured* elevation in a cell the
ground also fills is not always the target's: where the ground is 15 dB over the target, the
plain DoA of the cell is the ground's (over flat ground 300 m below, a co-altitude intruder's
"measured" elevations are -16 to -20 deg, the ground's depression at those ranges), and after
whitening a mixture lands between the target and the ground (-13 to -28 deg for the same
intruder over Jacksboro). Both errors pull *towards the ground*, so they are below the target's
true elevation; none can put a reading above the own-ship's horizontal when the ground is below
it. Hence the asymmetric rule (:func:`elevation_trusted`): inside the ground's range-Doppler band
(:func:`in_ground_band`) an elevation counts only when it is measured and more than ``k``
standard deviations above the own-ship's horizontal (the deviation at least a floor that scales
with the array's beamwidth in elevation, :func:`band_elevation_sigma_rad`); outside the band every
measured elevation counts. The rest are *free*: the tracker places them at the co-altitude prior
(elevation 0 above the own-ship's horizontal, :func:`at_elevation`) with a vertical-angle sigma of
:data:`FREE_ELEVATION_SIGMA_RAD`, while range and azimuth count in full. A track with no trusted
elevation then stays co-altitude; one with trusted elevations follows them (a free reading weighs
1/300 of a trusted one at 0.02 rad). Free readings are not placed at the track's *predicted*
elevation: there they hold nothing, and the radial-velocity update moves the height unopposed (a
track 110 m below with no trusted reading can climb to 500 m up and miss a conflict).

An aircraft overtaken 339 m above has its elevations measured on 30-70 % of its detections, at
27-45 deg, within a few degrees of the truth; the co-altitude prior of the others holds its track
74 m above the own-ship, and it is warned. Below the horizontal one reading cannot be told from
the ground's pull, but a track's readings can (:class:`BelowConsensus`): the ground's pull
scatters from frame to frame or lies on the surface, an aircraft's readings agree, clear of it.
Those that agree are trusted, so an aircraft passing 281 m below is not warned as co-altitude.
Once a track's readings agree on a height above, its free readings sit at that height instead of
the co-altitude prior, its trusted readings above at that height too (with the readings' spread
as sigma), and the 3-D filter restarts its height there (``doa_feed``): read one at a time, the
scattered readings of an aircraft above let the first one accepted set the height. What it still
costs: an intruder below whose readings are mostly unmeasured or scattered keeps the co-altitude
prior and is warned as if co-altitude: a false warning where it passes well below, never a
missed one.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "FREE_ELEVATION_SIGMA_RAD",
    "BAND_ELEVATION_SIGMA_RAD",
    "band_elevation_sigma_rad",
    "in_ground_band",
    "elevation_trusted",
    "at_elevation",
    "place_elevations",
    "AboveVotes",
    "median_above",
    "MEDIAN_ABOVE_FLOOR_RAD",
    "MEDIAN_ABOVE_K",
    "BelowConsensus",
]

FREE_ELEVATION_SIGMA_RAD = 0.35  # vertical-angle sigma of a free detection, at the co-altitude prior
# Least elevation scatter assumed inside the ground's band when a reading is judged above the horizontal
# (3 of it: 8.6 deg), for the prototype's square: readings through the nulls scatter by degrees past their
# bound, with a heavy upper tail (over hills, an aircraft 39 m below has 1.7 % of its measured elevations
# above 8.6 deg). Other arrays scale it by their vertical aperture (band_elevation_sigma_rad).
BAND_ELEVATION_SIGMA_RAD = 0.05
# Elevation bias a track's readings share, rad (3 deg): three times the 1-deg dynamic pitch and roll
# error of a GA MEMS AHRS (the ``ga-typical`` navigation's datasheet class) with the mount's alignment.
MEDIAN_ABOVE_FLOOR_RAD = 0.052
MEDIAN_ABOVE_K = 3.7  # standard errors of the median (one-sided 1e-4)
_GROUND_RANGE_FRACTION = 0.5  # ground may be in range from half the own-ship's height above it (relief)


def in_ground_band(
    range_m: np.ndarray,
    radial_velocity_mps: np.ndarray,
    own_speed_mps: float,
    height_agl_m: float,
    margin_mps: float = 5.0,
) -> np.ndarray:
    """Whether the ground can fill each detection's range-Doppler cell (bool per detection).

    A static point's radial velocity is at most the own-ship's speed, and no ground lies closer
    than the own-ship's height above it (half of it here: relief ahead rises above the ground
    below). NaN ``height_agl_m`` (clear sky, no terrain): False everywhere.
    ``radial_velocity_mps`` is the cell's: the alias within ``+-V_lim`` (``units.wrap``), not the
    de-aliased velocity. A head-on closure of -115 m/s sits in the cell of -36.7 m/s, which the
    ground fills at 50 m/s: judged on -115 m/s, the readings of an intruder 47 m below that the
    ground pulls down would be trusted, its track held 245-335 m below the aircraft, and it would
    never be warned. When the own-ship is faster than ``V_lim`` less the
    margin, every cell beyond half its height above the ground is in the band.

    Examples
    --------
    >>> rng, v = np.array([2000.0, 2000.0, 200.0]), np.array([-30.0, -90.0, -30.0])
    >>> in_ground_band(rng, v, 50.0, 500.0).tolist()
    [True, False, False]
    >>> cell = np.array([-30.0, -90.0 + 78.3, -30.0])  # -90 m/s aliases to -11.7 with V_lim 39.15 m/s
    >>> in_ground_band(rng, cell, 50.0, 500.0).tolist()
    [True, True, False]
    """
    if not np.isfinite(height_agl_m):
        return np.zeros(np.shape(range_m), bool)
    near = np.asarray(range_m, float) >= _GROUND_RANGE_FRACTION * height_agl_m
    return near & (np.abs(np.asarray(radial_velocity_mps, float)) <= own_speed_mps + margin_mps)


def band_elevation_sigma_rad(channel_positions_m: np.ndarray, wavelength_m: float) -> float:
    """Least elevation scatter assumed in the ground's band for an array, rad.

    :data:`BAND_ELEVATION_SIGMA_RAD` was measured on the prototype's square, whose rows sit a
    quarter wavelength above and below its centre. The scatter past the bound comes from the
    ground the nulls leave in the cell (relief puts it at more than the two nulled directions),
    and the angle a residual interferer pulls an estimate by scales with the beamwidth, which
    scales inversely with the array's vertical extent. So the floor is the square's times the
    ratio of the RMS vertical offsets of the channels (``down`` about their mean), the square's
    (``wavelength_m / 4``) over the array's (``channel_positions_m``, m: the receivers, or a MIMO
    radar's virtual channels). An array no taller than the square keeps the square's floor, and
    ``ura-4x2`` (rows at a quarter and three quarters of a wavelength from its centre) has 0.45 of
    it; an array with no vertical extent has no elevation to trust (infinity).

    Examples
    --------
    >>> from skyradar.rx_layouts import rx_layout_m
    >>> lam = 0.0123
    >>> [round(band_elevation_sigma_rad(rx_layout_m(n, lam), lam), 4) for n in ("square", "ura-2x4", "kite")]
    [0.05, 0.05, 0.0302]
    >>> round(band_elevation_sigma_rad(rx_layout_m("ura-4x2", lam), lam), 4)
    0.0224
    """
    down = np.asarray(channel_positions_m, float)[:, 2]
    rms_m = float(np.sqrt(np.mean((down - down.mean()) ** 2)))
    if rms_m <= 0.0:
        return float("inf")
    return BAND_ELEVATION_SIGMA_RAD * round(float(wavelength_m) / 4.0 / rms_m, 6)


def elevation_trusted(
    elevation_rad: np.ndarray,
    sigma_rad: np.ndarray,
    measured: np.ndarray,
    band: np.ndarray,
    k: float = 3.0,
    band_sigma_rad: float = BAND_ELEVATION_SIGMA_RAD,
) -> np.ndarray:
    """Whether each detection's elevation may move its track's height (bool per detection).

    ``elevation_rad`` is the DoA point's elevation above the own-ship's horizontal (NED), rad;
    ``sigma_rad`` its standard deviation (taken at least ``band_sigma_rad`` in the band: the
    array's :func:`band_elevation_sigma_rad`, by default the square's
    :data:`BAND_ELEVATION_SIGMA_RAD`); ``measured`` the detection's ``elevation_measured``;
    ``band`` :func:`in_ground_band`.
    The track's vote (:class:`AboveVotes`) is applied by :func:`place_elevations`. See the module
    docstring for the rule.

    Examples
    --------
    >>> el = np.radians([-20.0, 20.0, 2.0, -20.0])
    >>> elevation_trusted(el, np.full(4, 0.02), np.array([True, True, True, False]),
    ...                   np.array([True, True, True, False])).tolist()
    [False, True, False, False]
    """
    floor = np.where(band, band_sigma_rad, 0.0)
    above = np.asarray(elevation_rad, float) > k * np.maximum(np.asarray(sigma_rad, float), floor)
    return np.asarray(measured, bool) & (~np.asarray(band, bool) | above)


class AboveVotes:
    """Per track, whether most of its recent in-band elevations say it flies above the own-ship.

    A co-altitude aircraft's readings through the nulls scatter with heavy tails (over hills, an
    aircraft 39 m below has 1.7 % of 303 measured elevations more than 8.6 deg above the
    horizontal, 0.7 % more than 12 deg). Trusted one by one, each such reading lifts the track and
    the free readings then hold it there: it can climb to 620 m above, and a near collision goes
    unwarned. An aircraft that is above has nearly all its readings above (93-99 % over hills and
    Jacksboro). So a track's in-band elevations count only while at least ``least`` of its last
    ``window`` measured in-band readings were above the threshold, and stay voted while ``keep``
    are (readings pulled to the ground come in runs: a vote lost on each lets the co-altitude prior
    of the free readings drag the track back down). 7 of 10: a co-altitude track
    with 5 % of its readings 10-30 deg up in bursts of three stays within 60 m of its height (5 of
    10 let one of three draws climb 420 m); 14 of 20 resists more but an aircraft 340 m above
    then takes seconds longer to reach its height (``tests/test_elevation_trust.py``).

    While voted, the track's height is the median height ``r sin(el)`` of those readings above, and
    their spread (1.4826 median absolute deviation) its uncertainty: one reading at a time, the
    scattered readings of an aircraft above (over flat ground 300 m below, one overtaken 339 m
    above reads 14-43 deg for a true 27-32 deg, on 30 % of its detections) set the track's height
    from the first one accepted and the gate keeps out the rest; the track stays 170 m up.

    A track whose readings stay mostly under the threshold is voted above too when the median of
    its last ``median_window`` readings is (:func:`median_above`), tested from its
    ``median_least``-th reading on: a track born close to the own-ship (reacquired, or first seen
    late) with 40 % of its frames measured gathers twenty readings in about five seconds, during
    which it sits at the co-altitude prior, and an aircraft 300 m above may be warned as if level.
    Ten readings let the median vote in half that time, at the same chance per window that a level
    aircraft's readings pass (their scatter held at least ``spread_floor_rad``).

    Examples
    --------
    >>> votes = AboveVotes(window=4, least=2)
    >>> ids, up, on = np.array([1, 2]), np.array([300.0, 280.0]), np.array([True, True])
    >>> votes.update(ids, np.array([True, False]), on, up)[0].tolist()
    [nan, nan]
    >>> votes.update(ids, np.array([True, True]), on, up + 20.0)[0].tolist()
    [310.0, nan]
    """

    def __init__(
        self,
        window: int = 10,
        least: int = 7,
        keep: int = 4,
        median_window: int = 20,
        median_least: int = 10,
        spread_floor_rad: float = BAND_ELEVATION_SIGMA_RAD,
    ) -> None:
        self.window, self.least, self.keep = int(window), int(least), int(keep)
        self.median_window, self.median_least = int(median_window), int(median_least)
        self.spread_floor_rad = float(spread_floor_rad)
        self._recent = _RecentReadings(max(self.window, self.median_window))
        self._voted: set[int] = set()

    def update(
        self,
        ids: np.ndarray,
        above: np.ndarray,
        counts: np.ndarray,
        up_m: np.ndarray,
        elevation_rad: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Add this frame's vote ``above`` and height ``up_m`` (m above the own-ship) of each track
        ``ids`` where ``counts``; returns each track's height and its spread while voted above, m
        (NaN: not voted). Tracks not listed are forgotten. With the readings' ``elevation_rad``
        (above the own-ship's horizontal), the last ``median_window`` readings (from
        ``median_least`` on) whose median elevation is above the horizontal (:func:`median_above`,
        their scatter taken as at least ``spread_floor_rad``) vote the track above too, at the
        median of those readings' heights."""
        el = np.full(len(np.atleast_1d(up_m)), np.nan) if elevation_rad is None else elevation_rad
        columns = (np.asarray(above, float), np.asarray(up_m, float), np.asarray(el, float))
        readings = np.column_stack(columns).tolist()
        out = np.full((len(readings), 2), np.nan)
        voted = set()
        recents = self._recent.push(ids, readings, counts)
        for n, (i, recent) in enumerate(zip(np.asarray(ids).tolist(), recents, strict=True)):
            votes, up, elevation = np.array(recent, float).reshape(-1, 3).T
            last_votes, last_up = votes[-self.window :], up[-self.window :]
            if last_votes.sum() >= (self.keep if i in self._voted else self.least):
                out[n] = _median_and_spread(last_up[last_votes > 0])
                voted.add(int(i))
            elif median_above(
                elevation[-self.median_window :],
                least=self.median_least,
                spread_floor_rad=self.spread_floor_rad,
            ):
                out[n] = _median_and_spread(up[-self.median_window :])
                voted.add(int(i))
        self._voted = voted
        return out[:, 0], out[:, 1]

    def recent(self, track_id: int) -> tuple[list, bool]:
        """Track ``track_id``'s last readings (rows of vote, height m, elevation rad; oldest
        first) and whether it was voted above at its last update."""
        return self._recent.of(track_id), int(track_id) in self._voted

    def resume(self, track_id: int, readings: list, voted: bool) -> None:
        """Hold ``readings`` (as :meth:`recent` gives them) and the vote ``voted`` as track
        ``track_id``'s, e.g. a lost track's before its gap followed by those of the track that
        reacquired its id after it."""
        self._recent.set(track_id, readings)
        self._voted.discard(int(track_id))
        if voted:
            self._voted.add(int(track_id))


def median_above(
    elevation_rad: np.ndarray,
    k: float = MEDIAN_ABOVE_K,
    floor_rad: float = MEDIAN_ABOVE_FLOOR_RAD,
    least: int = 3,
    spread_floor_rad: float = 0.0,
) -> bool:
    """Whether a track's measured elevations (rad, above the own-ship's horizontal) put it above.

    One reading in the ground's band counts only far above the horizontal (:func:`elevation_trusted`:
    8.6 deg): readings through the nulls scatter by degrees and their tail reaches that high. Their
    median does not: it moves by ``1.2533 * spread / sqrt(n)`` (``spread`` 1.4826 median absolute
    deviation), and the ground pulls it down, never up. So an aircraft 300 m above at 3 km (5.7 deg,
    readings scattered by 3.5 deg) is above when the median of its ``n`` readings (at least
    ``least``) is ``k`` of those errors above the horizontal and above ``floor_rad``, the bias the
    readings share (the AHRS pitch and roll errors and the antenna's mounting), long before a single
    reading passes 8.6 deg. ``spread`` is taken as at least ``spread_floor_rad``, the least scatter
    the array gives readings in the ground's band (:func:`band_elevation_sigma_rad`): a few readings
    can agree by chance, but not more closely than the array resolves. Estimated from ten readings,
    the spread alone falls far enough below the truth often enough that a level aircraft's median
    would pass in about one window in 350; with the floor it passes in about one in three
    thousand, as twenty readings do (3.7: one-sided 1e-4 for a known spread).

    Parameters
    ----------
    elevation_rad : ndarray
        The track's measured in-band elevations above the own-ship's horizontal, rad (NaN ignored).
    k : float
        Standard errors of the median it must lie above the horizontal.
    floor_rad : float
        Least median elevation, rad: the bias the readings may share.
    least : int
        Fewest finite readings the test is made on (never under three).
    spread_floor_rad : float
        Least spread of the readings, rad.

    Returns
    -------
    bool
        Whether the median elevation is above both bounds.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> median_above(np.radians(5.7 + 3.5 * rng.standard_normal(20)))
    True
    >>> co_altitude = np.radians(np.r_[3.5 * rng.standard_normal(17), 20.0, 25.0, 30.0])  # a burst up
    >>> median_above(co_altitude)
    False
    >>> median_above(np.radians([6.0, 6.2, 5.9]), least=10)  # too few readings
    False
    """
    el = np.asarray(elevation_rad, float)
    el = el[np.isfinite(el)]
    if el.size < max(int(least), 3):
        return False
    median, spread = _median_and_spread(el)
    spread = max(spread, float(spread_floor_rad))
    return bool(median > max(k * 1.2533 * spread / np.sqrt(el.size), floor_rad))


def _median_and_spread(up_m: np.ndarray) -> tuple[float, float]:
    """Median of ``up_m`` and its spread (1.4826 median absolute deviation), m."""
    median = float(np.median(up_m))
    return median, 1.4826 * float(np.median(np.abs(up_m - median)))


class _RecentReadings:
    """Each track's last ``window`` readings, kept from frame to frame; tracks not listed are forgotten."""

    def __init__(self, window: int) -> None:
        self.window = int(window)
        self._by_track: dict[int, list] = {}

    def push(self, ids: np.ndarray, readings: list, counts: np.ndarray) -> list[list]:
        """Add ``readings[n]`` to track ``ids[n]`` where ``counts[n]``; each listed track's readings."""
        track_ids = [int(i) for i in np.asarray(ids).tolist()]
        listed = set(track_ids)
        self._by_track = {i: v for i, v in self._by_track.items() if i in listed}
        out = []
        for i, reading, c in zip(track_ids, readings, np.asarray(counts).tolist(), strict=True):
            recent = self._by_track.setdefault(i, [])
            if c:
                recent.append(reading)
                del recent[: -self.window]
            out.append(recent)
        return out

    def of(self, track_id: int) -> list:
        """A copy of track ``track_id``'s readings, oldest first (empty if none)."""
        return list(self._by_track.get(int(track_id), []))

    def set(self, track_id: int, readings: list) -> None:
        """Hold ``readings`` (oldest first, the last ``window`` kept) as track ``track_id``'s."""
        self._by_track[int(track_id)] = list(readings)[-self.window :]


class BelowConsensus:
    """Per track, the height below the own-ship its recent in-band elevations agree on, if any.

    Readings the ground pulls scatter: the target-to-clutter ratio of a cell changes from frame to
    frame (target fluctuation, speckle), and so does where a mixture points (over hills, for
    aircraft 39 and 110 m below, the heights implied by ten successive readings spread by 35-190 m,
    median absolute deviation, 4-20 times their bound). An aircraft below has its readings where it
    is (281 m below: spread 2-31 m, within its bound). Readings the ground dominates agree too, on
    the surface (a co-altitude intruder over Jacksboro reads 340-350 m below, 3-21 m above the
    terrain there). So a track's below readings count once at
    least ``least`` of its last ``window`` measured in-band readings are below the threshold, the
    heights ``r sin(el)`` they imply spread by at most ``spread`` times their median bound
    ``r sigma``, and the median reading is clear of the surface by its margin (``clear_m`` > 0 per
    reading: height above the terrain less three bounds). The consensus is the median height, m
    (negative: below), with its spread; NaN where there is none.

    Examples
    --------
    >>> below = BelowConsensus(window=4, least=3)
    >>> ids, up, sd = np.array([1, 2, 3]), np.array([-300.0, -100.0, -300.0]), np.full(3, 20.0)
    >>> is_below, clear = np.array([True, False, True]), np.array([150.0, 350.0, -20.0])
    >>> for _ in range(3):
    ...     h, spread = below.update(ids, up, sd, is_below, np.ones(3, bool), clear)
    >>> h.tolist()
    [nan, nan, nan]
    >>> below.update(ids, up, sd, is_below, np.ones(3, bool), clear)[0].tolist()
    [-300.0, nan, nan]
    """

    def __init__(self, window: int = 10, least: int = 7, spread: float = 1.5) -> None:
        self.window, self.least, self.spread = int(window), int(least), float(spread)
        self._recent = _RecentReadings(window)

    def update(
        self,
        ids: np.ndarray,
        up_m: np.ndarray,
        bound_m: np.ndarray,
        below: np.ndarray,
        counts: np.ndarray,
        clear_m: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Add this frame's readings (height ``up_m`` above the own-ship, its bound ``bound_m``,
        whether ``below`` the threshold, clearance ``clear_m`` of the surface) of each track ``ids``
        where ``counts``; returns each track's consensus height and its spread, m (NaN: none).
        Tracks not listed are forgotten."""
        columns = (
            np.asarray(up_m, float),
            np.asarray(bound_m, float),
            np.asarray(below, float),
            np.asarray(clear_m, float),
        )
        recent = self._recent.push(ids, np.column_stack(columns).tolist(), counts)
        out = np.array([self.consensus(r) for r in recent], float)
        out = out.reshape(-1, 2)
        return out[:, 0], out[:, 1]

    def recent(self, track_id: int) -> list:
        """Track ``track_id``'s last readings (rows of height m, bound m, below, clearance m;
        oldest first)."""
        return self._recent.of(track_id)

    def resume(self, track_id: int, readings: list) -> None:
        """Hold ``readings`` (as :meth:`recent` gives them) as track ``track_id``'s."""
        self._recent.set(track_id, readings)

    def consensus(self, readings: list) -> tuple[float, float]:
        """The height (m) and spread (m) the ``readings`` (as :meth:`recent` gives them) agree on
        below the own-ship; NaN, NaN where they do not."""
        up, bound, below, clear = np.array(readings, float).reshape(-1, 4).T
        if len(up) < self.window or below.sum() < self.least:
            return np.nan, np.nan
        median, spread = _median_and_spread(up)
        agree = spread <= self.spread * float(np.median(bound)) and float(np.median(clear)) > 0.0
        return (median, spread) if agree else (np.nan, np.nan)


def at_elevation(
    positions_m: np.ndarray, own_position_m: np.ndarray, elevation_rad: np.ndarray
) -> np.ndarray:
    """Positions moved to ``elevation_rad`` above the radar's horizontal (NED), same range and bearing.

    Examples
    --------
    >>> at_elevation(np.array([[1000.0, 0.0, 0.0]]), np.zeros(3), np.array([np.pi / 6])).round(1).tolist()
    [[866.0, 0.0, -500.0]]
    """
    own = np.asarray(own_position_m, float)
    d = np.asarray(positions_m, float) - own
    r = np.linalg.norm(d, axis=1)
    bearing = np.arctan2(d[:, 1], d[:, 0])
    el = np.asarray(elevation_rad, float)
    return own + r[:, None] * np.column_stack(
        [np.cos(el) * np.cos(bearing), np.cos(el) * np.sin(bearing), -np.sin(el)]
    )


def place_elevations(
    positions_m: np.ndarray,
    own_position_m: np.ndarray,
    own_speed_mps: float,
    sigma_rad: np.ndarray,
    measured: np.ndarray,
    radial_velocity_mps: np.ndarray,
    height_agl_m: float,
    votes: AboveVotes | None = None,
    ids: np.ndarray | None = None,
    below: BelowConsensus | None = None,
    clearance_m: np.ndarray | None = None,
    last_up_m: np.ndarray | None = None,
    band_sigma_rad: float = BAND_ELEVATION_SIGMA_RAD,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """DoA positions with free elevations at their track's height, elevation sigma, trust, and height.

    Parameters
    ----------
    positions_m, own_position_m, own_speed_mps : ndarray (k, 3), ndarray (3,), float
        NED DoA positions and the own-ship's, m; its speed, m/s.
    sigma_rad, measured, radial_velocity_mps : ndarray, shape (k,)
        Angle sigma (rad), ``elevation_measured`` and the cell's radial velocity (m/s, an alias).
    height_agl_m : float
        Own-ship's height above the ground, m (NaN: no ground known).
    votes, ids : AboveVotes and ndarray of int, shape (k,), optional
        The tracks' votes (updated here) and track ids; without: all voted, each reading on its own.
    below, clearance_m : BelowConsensus and ndarray, shape (k,), optional
        The tracks' consensus below (updated here) and each point's height above the terrain, m; in
        the band, readings below count only within 3 bounds of it (sigma at least ``band_sigma_rad``).
    last_up_m : ndarray, shape (k,), optional
        Height above the own-ship each row's track last agreed on, m (NaN: never).
    band_sigma_rad : float
        Least elevation scatter in the ground's band, rad (:func:`band_elevation_sigma_rad` of the
        array; default the square's).

    Returns
    -------
    positions_m, elevation_sigma_rad, trusted, track_up_m, track_spread_m : ndarray
        See :func:`_placed`; the height above the own-ship each row's track agrees on
        (:class:`AboveVotes`) and its spread (at least ``band_sigma_rad`` at its range), m.

    Examples
    --------
    >>> pos = np.array([[2000.0, 0.0, 700.0], [2000.0, 0.0, -700.0]])  # 19 deg below, 19 deg above
    >>> p, s, ok, up, _ = place_elevations(pos, np.zeros(3), 50, np.full(2, 0.02), np.ones(2, bool), -30, 500)
    >>> ok.tolist(), p[:, 2].round(1).tolist(), s.tolist(), up.tolist()
    ([False, True], [0.0, -700.0], [0.35, 0.02], [nan, nan])
    """
    own = np.asarray(own_position_m, float)
    d = np.asarray(positions_m, float) - own
    elevation, range_m = np.arctan2(-d[:, 2], np.hypot(d[:, 0], d[:, 1])), np.linalg.norm(d, axis=1)
    band = in_ground_band(range_m, radial_velocity_mps, own_speed_mps, height_agl_m)
    trusted = elevation_trusted(elevation, sigma_rad, measured, band, band_sigma_rad=band_sigma_rad)
    in_band = np.asarray(measured, bool) & band
    sigma, held = np.asarray(sigma_rad, float), np.zeros(len(d), bool)
    trusted, track_up, spread = _voted(
        votes, ids, trusted, band, in_band, range_m * np.sin(elevation), elevation
    )
    spread = np.where(np.isfinite(track_up), np.fmax(spread, band_sigma_rad * range_m), np.nan)
    if below is not None and clearance_m is not None:
        held = _held_below(elevation, range_m, sigma, in_band, clearance_m, below, ids, band_sigma_rad)
    trusted, sigma = trusted | held, np.where(held, np.maximum(sigma, band_sigma_rad), sigma)
    agreed, window = trusted & band & ~held & np.isfinite(track_up), votes.window if votes is not None else 1
    placed = (positions_m, own, range_m, sigma, trusted, agreed, track_up, spread, last_up_m, window)
    return *_placed(*placed), trusted, track_up, spread


def _voted(votes, ids, trusted, band, in_band, up_m, elevation) -> tuple:
    """Trust in the band only while the track is voted above; the tracks' agreed heights and spreads."""
    if votes is None:
        return trusted, *np.full((2, len(trusted)), np.nan)
    track_up, spread = votes.update(ids, trusted & band, in_band, up_m, elevation)
    return trusted & (~band | np.isfinite(track_up)), track_up, spread


def _placed(positions_m, own, range_m, sigma, trusted, agreed, track_up, spread, last_up_m, window) -> tuple:
    """Positions and elevation sigmas: ``agreed`` readings (trusted, in the band, the track voted
    above) at their track's height ``track_up`` with a sigma of at least ``sqrt(window)`` times its
    ``spread`` (m): the height is the median of the last ``window`` readings, fed every frame, and
    their spread measures their scatter within that second, not the slow clutter pull they share;
    fed at the spread, the filter takes the median's drift for a vertical speed (over hills, an
    aircraft level 232 m above drifts from 253 to 210 m over 12 s: -2.5 to -3 m/s at a sigma of
    0.8-1.1, and a false warning after the closest approach), so ``window`` successive feeds weigh as one
    (in the band a track's height rests on what its readings agree on, not on each scattered one);
    free ones at the track's current height, else at ``last_up_m`` (a vote lost on a run of
    readings the ground pulls would let the co-altitude prior drag the track down: over flat ground
    300 m below, an aircraft 280 m above would sink to 103 m in 20 s, and be warned), else at elevation 0 (the
    co-altitude prior), with :data:`FREE_ELEVATION_SIGMA_RAD`."""
    sigma = np.where(agreed, np.fmax(sigma, np.sqrt(window) * spread / range_m), sigma)
    moved = (~trusted | agreed) & np.isfinite(positions_m).all(axis=1)
    out = np.array(positions_m, float)
    prior = track_up if last_up_m is None else np.where(np.isfinite(track_up), track_up, last_up_m)
    height = np.nan_to_num(prior[moved], nan=0.0)
    out[moved] = at_elevation(out[moved], own, np.arcsin(np.clip(height / range_m[moved], -1.0, 1.0)))
    return out, np.where(trusted, sigma, FREE_ELEVATION_SIGMA_RAD)


def _held_below(
    elevation, range_m, sigma, in_band, clearance_m, below, ids, band_sigma_rad: float, k: float = 3.0
) -> np.ndarray:
    """In-band readings below the horizontal that agree with their track's :class:`BelowConsensus`.

    A consensus below only trusts its readings; it neither places free ones nor restarts the
    track's height: readings a mixture pulls can agree too (over flat ground 1000 m below, an
    aircraft 103 m below has readings agreeing 700 m below; held there, its track would never be
    warned). Above the horizontal the ground pulls none."""
    wide = k * np.maximum(sigma, band_sigma_rad)
    up, loose, is_below = range_m * np.sin(elevation), range_m * wide, elevation < -wide
    clear = np.asarray(clearance_m) - loose
    consensus, _ = below.update(ids, up, range_m * sigma, is_below, in_band, clear)
    return in_band & is_below & (np.abs(up - consensus) <= loose)
