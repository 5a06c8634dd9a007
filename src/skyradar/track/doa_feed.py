"""The 3-D tracker's measurements: a detection's DoA position, its covariance and radial velocity.

:class:`Measure3D` turns the detections assigned in one frame of the range-Doppler tracker into
the 3-D tracker's (:class:`~skyradar.track.tracker3d.Tracker3D`) update: the DoA point moved
from the apparent range ``R + c V_R`` to the true one, its covariance
(:func:`~skyradar.track.measure3d.position_covariance`), the elevations it may trust
(:mod:`skyradar.track.elevation_trust`) and the de-aliased radial velocity.

A time-division MIMO radar's frame chooses each detection's residue of the velocity ambiguity by
the antenna's field of view (:func:`skyradar.process.mimo.virtual_pixels`); far above or below the
horizontal both residues fit and the frame may read the mirror direction. Once a track's range
rate has resolved its radial velocity ``v``, the residue is ``round((v - v_hat) / 2 VLim) mod
n_tx`` for the detection's aliased ``v_hat``: where that is the runner-up's, the detection's
position is the runner-up's (``other_north_m``, ...) with its own direction's angle error
(``other_azimuth_rad``, ``other_elevation_rad``), so a track's height follows the aircraft, not
a mirror that flips with the frames. The positions a track was fed before its radial velocity
resolved came from each frame's own choice, some of them the mirror hundreds of metres away, and
the filter built on them has learnt a noise scale that large (:class:`~skyradar.track.tracker3d.Tracker3D`).
At the frame it resolves, a position of the residue its range rate says that misses the filter's
gate at its stated noise restarts the filter (``restart_ids``) instead of pulling it over in small
steps: left to the gate, the aircraft's positions straddle it with that noise scale, the five
rejections in a row a restart waits for do not come, and the track of an aircraft overtaken a few
hundred metres above slides towards it at tens of m/s for seconds, a vertical speed that warns.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skyradar.io.ownship_states import REQUIRED_COLUMNS
from skyradar.process.doa import channel_positions_m
from skyradar.track.elevation_trust import (
    BAND_ELEVATION_SIGMA_RAD,
    AboveVotes,
    BelowConsensus,
    band_elevation_sigma_rad,
    place_elevations,
)
from skyradar.track.ground_doa import elevation_measured_flags
from skyradar.track.io import validate_ownship
from skyradar.track.measure3d import angle_covariance_rad2, angle_sigma_rad, position_covariance
from skyradar.track.tracker3d import RadialObservation, Tracker3D
from skyradar.units import wrap

__all__ = ["Measure3D", "OWNSHIP_COLUMNS"]

_NED = ("north_m", "east_m", "down_m")
_OTHER = ("other_residue", "other_north_m", "other_east_m", "other_down_m")
_OTHER_ANGLES = ("other_azimuth_rad", "other_elevation_rad")
_RIGHT = ("right_axis_north", "right_axis_east", "right_axis_down")
OWNSHIP_COLUMNS = REQUIRED_COLUMNS  # the own-ship rows the 3-D feed reads: time, NED position, velocity


@dataclass(frozen=True)
class _LostEvidence:
    """What a lost track's elevations said when it was lost at ``time_s`` (s): its in-band readings
    (:meth:`AboveVotes.recent`, :meth:`BelowConsensus.recent`), its vote above, the height its
    readings last agreed on (m above the own-ship, NaN: none) and whether they agreed on a height
    (voted above, or a consensus below) when it was lost."""

    time_s: float
    above: list
    voted: bool
    below: list
    agreed_up: float
    agreed: bool


class Measure3D:
    """Feeds the 3-D tracker: DoA position, its covariance and the de-aliased radial velocity."""

    def __init__(
        self, det, config, motion, sigma_rad, ownship, grid, surface_down=None, lost_memory_s: float = 8.0
    ) -> None:
        self.active = all(c in det.columns for c in _NED)
        if not self.active:
            return
        # A lost filter is kept as long as the range-Doppler tracker may give its id back.
        self.t3 = Tracker3D(lost_memory_s=lost_memory_s)
        self.config, self.sigma_rad = config, sigma_rad
        # The array's least elevation scatter in the ground's band (a taller array's is smaller).
        self.band_sigma_rad = (
            BAND_ELEVATION_SIGMA_RAD
            if config is None
            else band_elevation_sigma_rad(channel_positions_m(config), config.wavelength_m)
        )
        self.motion, self.width = motion, motion.doppler_width_mps
        self.ned, self.z, self.sigma = np.empty((0, 3)), np.empty((0, 2)), np.empty(0)
        # Each detection's angle error on the array's axes and the array's right axis in NED.
        self.angle_cov, self.right = np.empty((0, 2, 2)), np.empty((0, 3))
        # A time-division MIMO radar's detections carry the runner-up residue's position too.
        self.n_tx = 1 if config is None else config.n_tx
        self.other_residue, self.other_ned = np.empty(0, np.int64), np.empty((0, 3))
        self.other_sigma, self.other_angle_cov = np.empty(0), np.empty((0, 2, 2))
        self.measured, self.trusted = np.empty(0, bool), np.empty(0, bool)
        self.own, self.agl = None, np.full(len(grid), np.nan)
        self.votes = AboveVotes(spread_floor_rad=self.band_sigma_rad)
        self.below, self.surface_down = BelowConsensus(), surface_down
        self.agreed_up: dict[int, float] = {}  # the height each track's in-band readings last agreed on
        self.agreed_ids: set[int] = set()  # tracks whose in-band readings agreed on a height last frame
        self.resolved_ids: set[int] = set()  # MIMO tracks whose range rate chose their residue last frame
        # The elevation evidence of tracks the range-Doppler tracker may still give back (reacquire).
        self.lost_memory_s = float(lost_memory_s)
        self._alive_ids = np.empty(0, np.int64)
        self._lost: dict[int, _LostEvidence] = {}
        self.add_detections(det)
        if ownship is not None:
            self.own, self.agl = np.empty((0, len(OWNSHIP_COLUMNS) - 1)), np.empty(0)
            self.add_frames(grid, ownship)

    def add_detections(self, det) -> None:
        """Append detections after the rows held (a stream adds each frame's; rows index them all)."""
        ned = det[list(_NED)].to_numpy(float)
        z = det[["range_m", "radial_velocity_mps"]].to_numpy(float)
        if self.sigma_rad is None and "snr_db" in det.columns:
            azimuth, elevation = (
                det[c].to_numpy(float) if c in det.columns else np.zeros(len(det))
                for c in ("azimuth_rad", "elevation_rad")
            )
            snr_db = det["snr_db"].to_numpy(float)
            sigma = angle_sigma_rad(snr_db, self.config, azimuth, elevation)
            angle_cov = angle_covariance_rad2(snr_db, self.config, azimuth, elevation)
        else:
            sigma = np.full(len(det), 0.04 if self.sigma_rad is None else float(self.sigma_rad))
            angle_cov = sigma[:, None, None] ** 2 * np.eye(2)
        right = np.full((len(det), 3), np.nan)
        if all(c in det.columns for c in _RIGHT):
            right = det[list(_RIGHT)].to_numpy(float)
        self.angle_cov = np.concatenate([self.angle_cov, angle_cov])
        self.right = np.concatenate([self.right, right])
        self.ned, self.z = np.concatenate([self.ned, ned]), np.concatenate([self.z, z])
        other_residue, other_ned = np.full(len(det), -1, np.int64), np.full((len(det), 3), np.nan)
        if all(c in det.columns for c in _OTHER):
            other_residue = det["other_residue"].to_numpy(np.int64)
            other_ned = det[list(_OTHER[1:])].to_numpy(float)
        self.other_residue = np.concatenate([self.other_residue, other_residue])
        self.other_ned = np.concatenate([self.other_ned, other_ned])
        # The runner-up's angle error is its own direction's (a mirror direction has its own bound
        # and its own turn onto the array's axes); a table without its angles lends the chosen one's.
        other_sigma, other_cov = sigma.copy(), angle_cov.copy()
        if (
            self.sigma_rad is None
            and "snr_db" in det.columns
            and all(c in det.columns for c in _OTHER_ANGLES)
        ):
            other_az, other_el = (det[c].to_numpy(float) for c in _OTHER_ANGLES)
            known = np.isfinite(other_az) & np.isfinite(other_el)
            snr_db = det["snr_db"].to_numpy(float)[known]
            other_sigma[known] = angle_sigma_rad(snr_db, self.config, other_az[known], other_el[known])
            other_cov[known] = angle_covariance_rad2(snr_db, self.config, other_az[known], other_el[known])
        self.other_sigma = np.concatenate([self.other_sigma, other_sigma])
        self.other_angle_cov = np.concatenate([self.other_angle_cov, other_cov])
        self.sigma = np.concatenate([self.sigma, sigma])
        self.measured = np.concatenate([self.measured, elevation_measured_flags(det)])
        self.trusted = np.concatenate([self.trusted, np.zeros(len(det), bool)])

    def add_frames(self, grid, ownship) -> None:
        """Append the own-ship state (:data:`OWNSHIP_COLUMNS`, optionally ``own_height_agl_m``) of the
        frames at times ``grid``, interpolated from the table ``ownship``; frame ``k`` of
        :meth:`step` indexes them all."""
        validate_ownship(ownship, OWNSHIP_COLUMNS)
        t = ownship["time_s"].to_numpy(float)
        own = np.column_stack([np.interp(grid, t, ownship[c].to_numpy(float)) for c in OWNSHIP_COLUMNS[1:]])
        agl = np.full(len(grid), np.nan)
        if "own_height_agl_m" in ownship:  # the ground's range-Doppler band (elevation_trust)
            agl = np.interp(grid, t, ownship["own_height_agl_m"].to_numpy(float))
        self.own = own if self.own is None else np.concatenate([self.own, own])
        self.agl = np.concatenate([self.agl, agl])

    def reacquire(self, new_ids: np.ndarray, lost_ids: np.ndarray, k: int) -> None:
        """Give the tracks ``new_ids`` the ids ``lost_ids`` they reacquired (before :meth:`step`
        of frame ``k``): their 3-D filters (:meth:`Tracker3D.rename`) and their elevation evidence.

        In the ground's band a track's height rests on its readings agreeing over the last ten
        frames (:mod:`skyradar.track.elevation_trust`); a track that reacquires a lost id has only
        its few readings since it started, too few to agree, so they sit at the co-altitude prior.
        For an aircraft 250 m below at 600 m, the prior puts its position 26 deg off its measured
        direction, tens of metres off horizontally as well, and the new filter misses the lost
        one's fusion gate: the track is warned at once, at the own-ship's altitude. So when the
        lost track's readings agreed on a height (voted above, or a consensus below) and the new
        track's in-band readings do not contradict it (their median within three bounds of the
        lost filter's height, predicted across the gap), the track resumes: its readings follow
        the lost track's in the votes and the consensus below, and its filter is moved on its
        range sphere to the lost filter's height (with its own vertical sigma, so the height is
        not counted twice) before the two are fused. Otherwise it starts with its own readings only.
        A ground track handed an intruder's id reads the surface, which contradicts a height
        above; inheriting one below only takes it further from a warning.
        """
        new_ids, lost_ids = np.asarray(new_ids, np.int64), np.asarray(lost_ids, np.int64)
        if not self.active or new_ids.size == 0:
            return
        resumed: dict[int, float] = {}
        for new, lost in zip(new_ids.tolist(), lost_ids.tolist(), strict=True):
            evidence = self._lost.pop(lost, None)
            above, voted = self.votes.recent(new)
            below = self.below.recent(new)
            height = self._lost_height(evidence, lost, above, k)
            if evidence is not None and height is not None:
                above, voted = evidence.above + above, evidence.voted
                below = evidence.below + below
                if np.isfinite(evidence.agreed_up):
                    self.agreed_up[lost] = evidence.agreed_up
                resumed[new] = height
            self.votes.resume(lost, above, voted)
            self.below.resume(lost, below)
            for held in (self.agreed_ids, self.resolved_ids):
                if new in held:
                    held.discard(new)
                    held.add(lost)
        if resumed and self.own is not None:
            ids, heights = np.array(list(resumed), np.int64), np.array(list(resumed.values()), float)
            self.t3.reset_height(ids, self.own[k - 1], heights, np.full(ids.size, np.nan))
        self._alive_ids = np.where(np.isin(self._alive_ids, new_ids), -1, self._alive_ids)
        self.t3.rename(new_ids, lost_ids)

    def _lost_height(self, evidence, lost_id: int, above: list, k: int) -> float | None:
        """The height above the own-ship (m) a reacquired track resumes at, or None: the lost
        filter's, predicted to the last frame, where the lost track's readings agreed on a height
        and the new track's in-band readings ``above`` (:meth:`AboveVotes.recent`) do not
        contradict it."""
        if evidence is None or not evidence.agreed or self.own is None or k < 1:
            return None
        lost = self.t3.lost_prediction(lost_id)
        if lost is None or not np.all(np.isfinite(lost[0])):
            return None
        x, P = lost
        own = self.own[k - 1]
        up = float(own[2] - x[2])
        readings = np.array(above, float).reshape(-1, 3)
        if len(readings) >= 3:
            range_m = float(np.linalg.norm(x[:3] - own[:3]))
            bound = 3.0 * max(float(np.sqrt(P[2, 2])), self.band_sigma_rad * range_m)
            if abs(float(np.median(readings[:, 1])) - up) > bound:
                return None
        return up

    def _remember_lost(self, alive_ids: np.ndarray, time_s: float) -> None:
        """Keep the elevation evidence of the tracks gone since the last frame for a reacquisition;
        forget what is older than the memory."""
        gone = self._alive_ids[(self._alive_ids >= 0) & ~np.isin(self._alive_ids, alive_ids)]
        for i in gone.tolist():
            above, voted = self.votes.recent(i)
            below = self.below.recent(i)
            self._lost[i] = _LostEvidence(
                time_s=time_s,
                above=above,
                voted=voted,
                below=below,
                agreed_up=self.agreed_up.get(i, np.nan),
                agreed=voted or bool(np.isfinite(self.below.consensus(below)[0])),
            )
        self._lost = {i: e for i, e in self._lost.items() if time_s - e.time_s <= self.lost_memory_s}
        self._alive_ids = np.asarray(alive_ids, np.int64).copy()

    def step(self, tracker, out, k: int, a: int, b: int) -> tuple[np.ndarray, np.ndarray]:
        det = out.alive_detection
        self._remember_lost(np.asarray(out.alive_ids, np.int64), float(out.time_s))
        has = det >= 0
        idx = det[has] + a
        pos = np.full((det.size, 3), np.nan)
        pos[has] = self.ned[idx]
        state, resolved = tracker.tracks.x, tracker.tracks.resolved
        v_meas = np.full(det.size, np.nan)
        v_meas[has] = self.z[idx, 1]
        # The detection's radial velocity moved to the track's (de-aliased) alias.
        alias = np.round((state[:, 1] - v_meas) / self.width)
        v_track = v_meas + self.width * alias
        v_unaliased = np.where(resolved, v_track, np.nan)
        sigma = np.full(det.size, 0.04)
        sigma[has] = self.sigma[idx]
        angle_cov = np.full((det.size, 2, 2), np.nan)
        angle_cov[has] = self.angle_cov[idx]
        restart = None
        if self.n_tx > 1:  # the residue the track's range rate says, where the frame chose the other
            ids = np.asarray(out.alive_ids, np.int64)
            restart = ids[resolved & ~np.isin(ids, list(self.resolved_ids))]
            self.resolved_ids = {int(i) for i in ids[resolved]}
            take = np.zeros(det.size, bool)
            take[has] = resolved[has] & (np.mod(alias[has], self.n_tx) == self.other_residue[idx])
            rows = det[take] + a
            pos[take], sigma[take], angle_cov[take] = (
                self.other_ned[rows],
                self.other_sigma[rows],
                self.other_angle_cov[rows],
            )
        c, sr = self.motion.coupling_s, self.motion.sigma_range_m
        if self.own is None:
            r = np.full(det.size, 1.0)
            r[has] = self.z[idx, 0]
            variances = np.maximum(r * sigma, 5.0) ** 2
            return self.t3.step(float(out.time_s), out.alive_ids, pos, variances, restart_ids=restart)
        own_p, own_v = self.own[k, :3], self.own[k, 3:]
        d = pos - own_p
        rng = np.linalg.norm(d, axis=1, keepdims=True)
        # The DoA point sits at the apparent range R + c V_R; move it to the true range.
        v_best = np.where(resolved, v_track, v_meas)
        pos = own_p + d * (1.0 - c * v_best[:, None] / rng)
        range_sigma = np.where(resolved, sr, np.hypot(sr, 0.5 * c * self.width))
        # Measured on the full chain (ch4 Free), DoA positions are off along the line of sight by
        # 17-25 m RMS at high SNR and far more at low SNR (angle outliers), not by the range noise;
        # trusting the range there slowed the 3-D velocity's convergence (median error 10 vs 6 m/s),
        # so the along-sight error is never taken below the across-sight one.
        across = np.linalg.norm(pos - own_p, axis=1) * sigma
        # Elevations the ground may have pulled, or the nulls left unmeasured, sit at the height the
        # track's readings last agreed on, else at the co-altitude prior, with a loose vertical sigma
        # (skyradar.track.elevation_trust).
        measured = np.zeros(det.size, bool)
        measured[has] = self.measured[idx]
        speed = float(np.linalg.norm(own_v))
        pos, el_sigma, trusted, track_up, spread = place_elevations(
            pos,
            own_p,
            speed,
            sigma,
            measured,
            wrap(v_meas, self.width),  # the cell's velocity: the ground's band is judged on it
            self.agl[k],
            self.votes,
            out.alive_ids,
            self.below,
            self._clearance(pos, own_p[2] + self.agl[k]),
            np.array([self.agreed_up.get(int(i), np.nan) for i in out.alive_ids], float),
            self.band_sigma_rad,
        )
        self.trusted[idx] = trusted[has]
        self._restart_heights(out.alive_ids, self.own[k], track_up, spread)
        cov = np.full((det.size, 3, 3), np.nan)
        use = has & np.isfinite(sigma)
        # The angle error on the array's axes (a wide array's elevation is its worse axis), the
        # elevation loosened where the placement rules loosened it.
        loosened = np.where(el_sigma != sigma, el_sigma, np.nan)
        cov[use] = position_covariance(
            pos[use],
            own_p,
            angle_cov[use],
            np.maximum(range_sigma, across)[use],
            loosened[use],
            self.right[det[use] + a],
        )
        radial = RadialObservation(own_p, own_v, v_unaliased, self.motion.sigma_velocity_mps)
        return self.t3.step(float(out.time_s), out.alive_ids, pos, cov, radial, restart_ids=restart)

    def _restart_heights(self, ids, own_state, track_up, spread) -> None:
        """Restart the 3-D height of each track whose readings now agree on one and did not last frame.

        Its height so far is the co-altitude prior (or a first scattered reading): a gradual pull
        from there takes seconds the alert does not have (over flat ground 300 m below, an aircraft
        overtaken 339 m above is first seen 780 m away, already inside the horizontal volume)."""
        agreed = np.isfinite(track_up)
        new = agreed & ~np.isin(ids, list(self.agreed_ids))
        self.agreed_ids = {int(i) for i in np.asarray(ids)[agreed]}
        alive = {int(i) for i in np.asarray(ids)}
        self.agreed_up = {i: u for i, u in self.agreed_up.items() if i in alive}
        self.agreed_up.update(zip(np.asarray(ids)[agreed].tolist(), track_up[agreed].tolist(), strict=True))
        if np.any(new):
            self.t3.reset_height(np.asarray(ids)[new], own_state, track_up[new], spread[new])

    def _clearance(self, pos: np.ndarray, flat_down_m: float) -> np.ndarray:
        """Height of each point above the terrain (``surface_down``), else above a level ground at
        ``flat_down_m``, m; NaN where the point is unknown."""
        if self.surface_down is None:
            return flat_down_m - pos[:, 2]
        out = np.full(len(pos), np.nan)
        ok = np.isfinite(pos).all(axis=1)
        out[ok] = np.asarray(self.surface_down(pos[ok, :2]), float) - pos[ok, 2]
        return out
