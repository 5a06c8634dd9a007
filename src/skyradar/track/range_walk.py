"""Track initiation from a range walk: a fast closure confirmed by its range history, not its hit rate.

A closure faster than the Doppler image is wide aliases into it; at the prototype's 78.3 m/s image
a head-on closure at 113 m/s sits in the cell of -34.7 m/s. Over relief that cell is often the one
the ground ahead fills, and the target is then detected in only a fraction of the frames, its
detections at the threshold of a secondary test or beside a clutter ridge. An M-of-N rule (4 of 5
frames) confirms nothing at a 30 % detection rate, and the aircraft is tracked only when it is
near, seconds from the loss of well clear.

Its range history says what its hit rate cannot. Between two detections of one object the range
moves at its true radial velocity, which is the cell's Doppler plus a whole number of image
widths: ``r(t) = r_0 + (v + k W) (t - t_0)``. For a given detection and ambiguity ``k`` the line is
fixed; no slope is fitted. Detections of the same Doppler that lie on that line within a range
bin, in enough frames spread over a few seconds, are one object moving at ``v + k W``. A static
point cannot do it when ``|v + k W|`` exceeds the own-ship's speed: a static point's range changes
at most at that speed, so the ground can only support such a line by chance coincidences, never
by its geometry. Three tests keep that chance low where the ground's detections are dense (a
clutter patch at one Doppler that the line crosses): the line must be supported in at least
``least_frames`` frames spanning ``min_span_s`` (a patch a fast line crosses in a second does not
span it); better than any line a static point could follow through the same detection
(``static_ratio`` times the support of the best ground-compatible ambiguity, ``|v + k W|`` at most
the own-ship's speed plus the margin); and by more detections than chance puts on it. The
detections of that Doppler in the window that are not on the line, spread over their ranges, fall
in the line's range gate at a Poisson rate ``lambda = n * 2 gate / extent``; the line's support
must be one that rate reaches with a probability of at most ``false_walk_probability`` (about one
false walk an hour over the whole image at 9.4 frames/s, ten candidates a frame and two
ambiguities each).

Only closing walks start tracks (``v + k W`` below minus the own-ship's speed less the margin):
the alerting stage needs the aircraft that come nearer, and an opening line at the same speed would
be an object moving away from a nose radar faster than the own-ship flies.

Examples
--------
A closure at -113 m/s, aliased to -34.7 m/s, detected in every third frame at 9.4 frames/s; the
own-ship flies at 50 m/s:

>>> walks = RangeWalks(doppler_width_mps=78.3)
>>> t = np.arange(40) / 9.4
>>> started = []
>>> for k, time_s in enumerate(t):
...     z = np.array([[3000.0 - 113.0 * time_s, -113.0 + 78.3]]) if k % 3 == 0 else np.zeros((0, 2))
...     rows, velocity = walks.step(time_s, z, np.ones(len(z), bool), static_speed_mps=50.0)
...     started += [(round(float(time_s), 2), round(float(v), 1)) for v in velocity]
>>> started[0]
(2.23, -113.0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

__all__ = ["RangeWalkRule", "RangeWalks"]

_MIN_EXTENT_M = 300.0  # least range extent the chance rate spreads a Doppler's detections over


@dataclass(frozen=True)
class RangeWalkRule:
    """The settings of :class:`RangeWalks`.

    Attributes
    ----------
    window_s : float
        How far back a line looks for its support, s.
    least_frames : int
        Frames (the new detection's included) that must hold a detection on the line.
    min_span_s : float
        Least time between the line's oldest supporting detection and the new one, s.
    range_gate_m : float
        Largest range residual of a supporting detection from the line, m (a range bin: the line's
        slope comes from the Doppler, known to a fraction of a m/s, so over a few seconds the line
        is known to about the range measurement's own error).
    doppler_gate_mps : float
        Largest Doppler difference of a supporting detection from the new one, m/s (the closing
        speed of a straight flight changes slowly far from the closest approach).
    margin_mps : float
        Speed over the own-ship's that a walk must exceed to be no static point's, m/s (the
        navigated speed's error and the ground's own motion: trees, water, vehicles at walking pace).
    max_closing_mps : float
        Fastest closing speed considered, m/s (two light aircraft head-on: well under 200 m/s).
    static_ratio : float
        The walk's support must be this many times the best ground-compatible line's.
    false_walk_probability : float
        Largest chance that the detections of the walk's Doppler in the window put its support on
        one line by coincidence (Poisson, see the module docstring).

    Examples
    --------
    A closure at -113 m/s (aliased into a 78.3 m/s image) detected every 0.2 s: the default rule
    starts the walk after ``min_span_s = 2`` s, a rule of 4 frames over 1 s after 1 s.

    >>> def first_walk(rule):
    ...     walks = RangeWalks(78.3, rule)
    ...     for k in range(30):
    ...         z = np.array([[3000.0 - 113.0 * 0.2 * k, -113.0 + 78.3]])
    ...         rows, velocity = walks.step(0.2 * k, z, np.ones(1, bool), static_speed_mps=50.0)
    ...         if rows.size:
    ...             return round(0.2 * k, 1), round(float(velocity[0]), 1)
    >>> first_walk(RangeWalkRule()), first_walk(RangeWalkRule(window_s=2.0, least_frames=4, min_span_s=1.0))
    ((2.0, -113.0), (1.0, -113.0))
    >>> RangeWalkRule(least_frames=2)
    Traceback (most recent call last):
    ...
    ValueError: least_frames must be at least 3, got 2
    """

    window_s: float = 4.0
    least_frames: int = 6
    min_span_s: float = 2.0
    range_gate_m: float = 15.0
    doppler_gate_mps: float = 0.8
    margin_mps: float = 10.0
    max_closing_mps: float = 200.0
    static_ratio: float = 2.0
    false_walk_probability: float = 1e-6

    def __post_init__(self) -> None:
        if self.least_frames < 3:
            raise ValueError(f"least_frames must be at least 3, got {self.least_frames}")
        if not (0.0 < self.min_span_s <= self.window_s):
            raise ValueError(f"need 0 < min_span_s <= window_s, got {self.min_span_s}, {self.window_s}")


class RangeWalks:
    """Finds detections that complete a fast closing range walk (see the module docstring).

    Keeps the recent detections not taken by a confirmed track (times, frames, range, Doppler);
    :meth:`step` searches each new candidate's lines against them, then adds the frame's candidates.
    The search is compiled (numba): a candidate's Doppler neighbours come from binary searches on the
    kept detections sorted by Doppler, and every ambiguity's line is judged in one pass over them, so
    a candidate costs in proportion to its Doppler neighbours, not to every kept detection
    (``skyradar bench track`` measures it).

    Parameters
    ----------
    doppler_width_mps : float
        Width ``W`` of the Doppler image (``2 V_lim``), m/s.
    rule : RangeWalkRule, optional
        Thresholds (default :class:`RangeWalkRule`).

    Examples
    --------
    A closure at -113 m/s seen in the cell of -34.7 m/s every 0.2 s, the own-ship at 50 m/s: the
    frame that completes 2 s of support gives the detection and its true radial velocity.

    >>> walks = RangeWalks(doppler_width_mps=78.3)
    >>> for k in range(11):
    ...     z = np.array([[3000.0 - 113.0 * 0.2 * k, -113.0 + 78.3]])
    ...     rows, velocity = walks.step(0.2 * k, z, np.ones(1, bool), static_speed_mps=50.0)
    ...     if rows.size:
    ...         print(k, rows.tolist(), velocity.round(1).tolist())
    10 [0] [-113.0]
    """

    def __init__(self, doppler_width_mps: float, rule: RangeWalkRule | None = None) -> None:
        self.width = float(doppler_width_mps)
        self.rule = rule or RangeWalkRule()
        self._frame = 0
        self._t = np.zeros(0)
        self._f = np.zeros(0, np.int64)
        self._r = np.zeros(0)
        self._v = np.zeros(0)

    def step(
        self, time_s: float, z: np.ndarray, candidate: np.ndarray, static_speed_mps: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """One frame: which of its detections complete a closing walk, and at which true radial velocity.

        Parameters
        ----------
        time_s : float
            The frame's time, s (not decreasing between calls).
        z : ndarray, shape (n, 2)
            The frame's detections: range (m) and the cell's radial velocity (m/s, aliased).
        candidate : ndarray of bool, shape (n,)
            Detections free to start or support a walk (not taken by a confirmed track).
        static_speed_mps : float
            The fastest a static point's range can change this frame (the own-ship's speed), m/s.
            NaN: unknown, and no walk starts (the detections are still kept as support).

        Returns
        -------
        rows : ndarray of int
            Rows of ``z`` that complete a walk, at most one per walk.
        velocity_mps : ndarray
            Their true radial velocity (``v + k W``), m/s.
        """
        rule = self.rule
        z = np.asarray(z, float).reshape(-1, 2)
        keep = self._t >= time_s - rule.window_s
        self._t, self._f, self._r, self._v = self._t[keep], self._f[keep], self._r[keep], self._v[keep]
        rows = np.zeros(0, int)
        velocity = np.zeros(0)
        cand = np.flatnonzero(np.asarray(candidate, bool))
        if np.isfinite(static_speed_mps) and self._t.size and cand.size:
            found, taken = self._search(float(time_s), z[cand], float(static_speed_mps) + rule.margin_mps)
            walked = np.isfinite(found)
            rows, velocity = cand[walked], found[walked]
            if taken.any():  # a walk's support belongs to its track now
                left = ~taken
                self._t, self._f, self._r, self._v = (
                    self._t[left],
                    self._f[left],
                    self._r[left],
                    self._v[left],
                )
        new = np.setdiff1d(cand, rows)
        self._t = np.concatenate([self._t, np.full(new.size, float(time_s))])
        self._f = np.concatenate([self._f, np.full(new.size, self._frame, np.int64)])
        self._r = np.concatenate([self._r, z[new, 0]])
        self._v = np.concatenate([self._v, z[new, 1]])
        self._frame += 1
        return rows.astype(int), velocity.astype(float)

    def _search(self, time_s: float, z: np.ndarray, limit_mps: float) -> tuple[np.ndarray, np.ndarray]:
        """The closing walk of each candidate detection ``z`` (rows: range, aliased Doppler), in
        order, against the kept detections: its true radial velocity (NaN: none), and which kept
        detections the walks took. ``limit_mps``: the fastest a static point's range changes, plus
        the rule's margin."""
        rule = self.rule
        by_doppler = np.argsort(self._v, kind="stable")
        settings = np.array(
            [
                self.width,
                limit_mps,
                rule.doppler_gate_mps,
                rule.range_gate_m,
                rule.least_frames,
                rule.min_span_s,
                rule.static_ratio,
                rule.max_closing_mps,
                rule.false_walk_probability,
                _MIN_EXTENT_M,
            ]
        )
        return _search_walks(
            time_s,
            np.ascontiguousarray(z[:, 0]),
            np.ascontiguousarray(z[:, 1]),
            self._t,
            self._f,
            self._r,
            self._v,
            by_doppler,
            self._v[by_doppler],
            self._frame,
            settings,
        )


@numba.njit(cache=True)
def _off_line(r_kept, t_kept, ri, v_line, time_s):  # pragma: no cover - numba
    """Range of a kept detection (``r_kept`` m at ``t_kept`` s) off the line through the new
    detection (``ri`` m at ``time_s`` s) at ``v_line`` m/s."""
    return r_kept - (ri + v_line * (t_kept - time_s))


@numba.njit(cache=True)
def _poisson_tail(n: int, mean: float) -> float:  # pragma: no cover - numba
    """P(X >= n) for X ~ Poisson(mean): the sum of the tail's terms from n up."""
    if n <= 0:
        return 1.0
    if mean <= 0.0:
        return 0.0
    term = math.exp(-mean + n * math.log(mean) - math.lgamma(n + 1.0))
    total = 0.0
    j = n
    while term > 1e-300 and (term > 1e-17 * total or j < mean):
        total += term
        j += 1
        term *= mean / j
    return min(total, 1.0)


@numba.njit(cache=True)
def _search_walks(
    time_s, cand_r, cand_v, t, f, r, v, by_doppler, sorted_v, frame_now, settings
):  # pragma: no cover
    """Each candidate's closing walk (its true radial velocity, NaN: none) through the kept
    detections (times ``t``, frames ``f``, ranges ``r``, Doppler ``v``; ``by_doppler`` sorts them by
    Doppler into ``sorted_v``), in the candidates' order; a walk's support is taken from the later
    candidates. Returns the velocities and the taken mask. ``settings``: image width, the static
    limit, then :class:`RangeWalkRule`'s gates and tests (see :meth:`RangeWalks.step`)."""
    width, limit, gate_v, gate_r = settings[0], settings[1], settings[2], settings[3]
    least, min_span, static_ratio = int(settings[4]), settings[5], settings[6]
    max_closing, p_false, min_extent = settings[7], settings[8], settings[9]
    n_kept = t.size
    taken = np.zeros(n_kept, np.bool_)
    found = np.full(cand_r.size, np.nan)
    near = np.empty(n_kept, np.int64)
    dv = np.empty(n_kept)
    oldest = frame_now
    for q in range(n_kept):
        oldest = min(oldest, f[q])
    n_ages = frame_now - oldest + 1
    for c in range(cand_r.size):
        ri, vi = cand_r[c], cand_v[c]
        # The kept detections within the Doppler gate, modulo the image width (binary searches on
        # the gate and its images one width either side).
        m = 0
        for shift in (-width, 0.0, width):
            lo = np.searchsorted(sorted_v, vi + shift - gate_v - 1e-9)
            hi = np.searchsorted(sorted_v, vi + shift + gate_v + 1e-9, side="right")
            for q in range(lo, hi):
                idx = by_doppler[q]
                if taken[idx]:
                    continue
                d = (v[idx] - vi + width / 2.0) % width - width / 2.0
                if abs(d) <= gate_v:
                    near[m] = idx
                    dv[m] = d
                    m += 1
        if m < least - 1:
            continue
        k_max = int(math.ceil((max_closing + abs(vi)) / width)) + 1
        # Frames holding support of each ambiguity's line r0 + (mean Doppler + k W)(t - t0).
        n_frames = np.ones(2 * k_max + 1, np.int64)  # the new detection's frame
        seen = np.zeros(n_ages, np.bool_)
        for kk in range(2 * k_max + 1):
            k = kk - k_max
            if not -max_closing <= vi + k * width <= limit:
                continue  # neither a static point's line nor a closing one: never judged
            seen[:] = False
            for a in range(m):
                idx = near[a]
                residual = _off_line(r[idx], t[idx], ri, vi + 0.5 * dv[a] + k * width, time_s)
                if abs(residual) <= gate_r and not seen[frame_now - f[idx]]:
                    seen[frame_now - f[idx]] = True
                    n_frames[kk] += 1
        static = 1
        for kk in range(2 * k_max + 1):
            if abs(vi + (kk - k_max) * width) <= limit:
                static = max(static, n_frames[kk])
        # Chance support: the Doppler's other detections in the window, spread over the ranges they cover.
        r_low, r_high = np.inf, -np.inf
        for a in range(m):
            r_low, r_high = min(r_low, r[near[a]]), max(r_high, r[near[a]])
        per_detection = 2.0 * gate_r / (max(r_high - r_low, min_extent) + 2.0 * gate_r)
        best_k, best_n = -1, 0
        for kk in range(2 * k_max + 1):
            speed = vi + (kk - k_max) * width
            n = n_frames[kk]
            if not (speed < -limit and speed >= -max_closing):
                continue
            if n < least or n < static_ratio * static or n <= best_n:
                continue
            support, first_t = 0, time_s
            for a in range(m):
                idx = near[a]
                residual = _off_line(r[idx], t[idx], ri, vi + 0.5 * dv[a] + (kk - k_max) * width, time_s)
                if abs(residual) <= gate_r:
                    support += 1
                    first_t = min(first_t, t[idx])
            if time_s - first_t < min_span:
                continue
            if _poisson_tail(n - 1, (m - support) * per_detection) > p_false:  # at least n - 1 supports
                continue
            best_k, best_n = kk, n
        if best_k < 0:
            continue
        found[c] = vi + (best_k - k_max) * width
        for a in range(m):
            idx = near[a]
            residual = _off_line(r[idx], t[idx], ri, vi + 0.5 * dv[a] + (best_k - k_max) * width, time_s)
            if abs(residual) <= gate_r:
                taken[idx] = True
    return found, taken
