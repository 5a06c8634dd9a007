"""The closed loop: a pilot flies the advice of the chain, and the chain sees the aircraft the pilot flies.

An encounter flown open-loop keeps its scripted own-ship whatever the alerts say; flown closed-loop,
the own-ship is a :class:`~skyradar.pilot.Pilot` that reacts to the alerts and advice of each frame,
and every later frame is simulated from where the pilot took the aircraft. Three ways to fly one
encounter, scored alike by :func:`separation`:

- **unequipped** (:func:`fly_unequipped`): the plan, no DAA;
- **perfect surveillance** (:func:`fly_perfect_surveillance`): the true states of every intruder,
  every frame, through the same alerting and advice (:class:`skyradar.daa.pipeline.AlertStream`)
  and the same pilot: what the alerting logic and the pilot can achieve with a perfect sensor;
- **radar** (:class:`ClosedLoopChain`, :func:`fly_radar`): the whole chain, frame by frame
  (:class:`skyradar.stream.StreamingChain`), flying the pilot's own-ship.

The risk ratio of a set of encounters is the rate of an event (loss of well clear, near mid-air
collision) flown with the system divided by its rate flown unequipped; its induced losses are the
encounters that lose well clear equipped but not unequipped.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from skyradar.daa.alerting import AlertConfig
from skyradar.daa.conflict import FT, WellClearVolume
from skyradar.daa.pipeline import AlertStream
from skyradar.pilot import Pilot, PilotConfig
from skyradar.scene.trajectories import Trajectory, TrajectorySample
from skyradar.stream import StreamingChain, frame_advice

__all__ = [
    "CONDITIONS",
    "NMAC_HORIZONTAL_M",
    "NMAC_VERTICAL_M",
    "ClosedLoopChain",
    "ClosedLoopRun",
    "fly_unequipped",
    "fly_perfect_surveillance",
    "fly_radar",
    "separation",
]

CONDITIONS = ("unequipped", "perfect", "radar")
NMAC_HORIZONTAL_M = 500.0 * FT  # a near mid-air collision: within 500 ft horizontally ...
NMAC_VERTICAL_M = 100.0 * FT  # ... and 100 ft vertically at once
_SEPARATION_STEP_S = 0.05


@dataclass(frozen=True)
class ClosedLoopRun:
    """One encounter flown one way.

    Attributes
    ----------
    condition : str
        ``unequipped``, ``perfect`` or ``radar``.
    flown : DataFrame
        The own-ship flown (:meth:`skyradar.pilot.Pilot.flown`): ``time_s``, NED position (m),
        velocity (m/s) and the pilot's ``mode``.
    alerts : DataFrame
        The alerts table the pilot saw (empty unequipped).
    first_action_s : float
        When the pilot first manoeuvred, s (NaN: never).
    manoeuvre_s : float
        Time the pilot spent off the plan (avoiding and returning), s.

    Examples
    --------
    Unequipped, the own-ship flies its plan (north at 50 m/s) and never manoeuvres:

    >>> from skyradar.scene.scenario import Scenario
    >>> spec = {"name": "head-on", "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    ...     "radar": {"range_limit_m": 1500},
    ...     "ownship": {"type": "straight", "start_ned_m": [0, 0, -2000], "speed_mps": 50},
    ...     "intruders": [{"name": "A", "type": "straight", "start_ned_m": [900, -40, -2000],
    ...                    "heading_deg": 180, "speed_mps": 40}],
    ...     "frame_rate_hz": 2.0, "duration_s": 5.0}
    >>> run = fly_unequipped(Scenario.from_dict(spec).build())
    >>> run.condition, len(run.alerts), run.manoeuvre_s, bool(np.isnan(run.first_action_s))
    ('unequipped', 0, 0.0, True)
    """

    condition: str
    flown: pd.DataFrame
    alerts: pd.DataFrame
    first_action_s: float
    manoeuvre_s: float


class ClosedLoopChain(StreamingChain):
    """The streaming chain flying a pilot's own-ship: each frame's alerts and advice steer the next.

    Parameters
    ----------
    built : BuiltScenario
        The scenario; its own-ship trajectory is the pilot's plan.
    pilot_config : PilotConfig, optional
        The pilot's reactions and the aircraft's kinematics.
    alert_config, process_options, heads
        As in :class:`~skyradar.stream.StreamingChain` (advice is always on: the pilot flies it).

    Examples
    --------
    >>> from skyradar.scene.scenario import Scenario
    >>> spec = {"name": "head-on", "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    ...     "radar": {"range_limit_m": 1500},
    ...     "ownship": {"type": "straight", "start_ned_m": [0, 0, -2000], "speed_mps": 50},
    ...     "intruders": [{"name": "A", "type": "straight", "start_ned_m": [900, -40, -2000],
    ...                    "heading_deg": 180, "speed_mps": 40}],
    ...     "frame_rate_hz": 9.4, "duration_s": 1.0}
    >>> chain = ClosedLoopChain(Scenario.from_dict(spec).build())
    >>> results = chain.run()
    >>> len(results), chain.pilot.mode  # one second: no alert reached the pilot's action yet
    (9, 'plan')
    """

    def __init__(
        self,
        built,
        pilot_config: PilotConfig | None = None,
        alert_config: AlertConfig | None = None,
        process_options: dict[str, Any] | None = None,
        heads: list[str] | None = None,
    ) -> None:
        super().__init__(built, alert_config, True, process_options, heads)
        self.pilot = Pilot(built.ownship, pilot_config, start_s=float(built.times_s[0]))

    def ownship_state(self, frame: int) -> TrajectorySample:
        """The pilot's aircraft at the frame's time (flown from the frames before)."""
        return self.pilot.advance(float(self.built.times_s[frame]))

    def step(self):
        """Step the chain one frame, then show its alerts and advice to the pilot."""
        result = super().step()
        _show_pilot(self.pilot, result.time_s, result.alerts)
        return result


def _show_pilot(pilot: Pilot, time_s: float, alerts: pd.DataFrame) -> None:
    """The frame's highest level, its advice and when the traffic alerting at the pilot's level
    passes its closest approach (the latest of the frame's tracks), shown to the pilot."""
    level = int(alerts["level"].max()) if len(alerts) else 0
    advice = frame_advice(alerts)
    heading = advice.preferred_heading_deg if advice is not None else np.nan
    vs = advice.preferred_vs_mps if advice is not None else np.nan
    passes = np.nan
    if len(alerts) and "tcpa_s" in alerts:
        alerting = alerts["level"].to_numpy() >= pilot.config.respond_level
        tcpa = alerts["tcpa_s"].to_numpy(float)[alerting]
        if np.isfinite(tcpa).any():
            passes = float(time_s) + float(np.nanmax(tcpa))
    pilot.observe(time_s, level, heading, vs, passes)


def _plan_flown(plan: Trajectory, times_s: np.ndarray) -> pd.DataFrame:
    state = plan.sample(times_s)
    table = pd.DataFrame(
        np.column_stack([times_s, state.position_ned_m, state.velocity_ned_mps]),
        columns=["time_s", "north_m", "east_m", "down_m", "vn_mps", "ve_mps", "vd_mps"],
    )
    table["mode"] = "plan"
    return table


def fly_unequipped(built) -> ClosedLoopRun:
    """The encounter without DAA: the own-ship's plan at the frames' times.

    Parameters
    ----------
    built : BuiltScenario
        The scenario (:meth:`skyradar.scene.scenario.Scenario.build`).

    Returns
    -------
    ClosedLoopRun
        Condition ``unequipped``: the plan sampled at every frame (``mode`` ``plan``), no alerts,
        no manoeuvre.

    Examples
    --------
    Ten frames at 2 Hz; the last at 4.5 s, 225 m north at 50 m/s:

    >>> from skyradar.scene.scenario import Scenario
    >>> spec = {"name": "head-on", "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    ...     "radar": {"range_limit_m": 1500},
    ...     "ownship": {"type": "straight", "start_ned_m": [0, 0, -2000], "speed_mps": 50},
    ...     "intruders": [{"name": "A", "type": "straight", "start_ned_m": [900, -40, -2000],
    ...                    "heading_deg": 180, "speed_mps": 40}],
    ...     "frame_rate_hz": 2.0, "duration_s": 5.0}
    >>> flown = fly_unequipped(Scenario.from_dict(spec).build()).flown
    >>> last = flown.iloc[-1]
    >>> len(flown), float(last["time_s"]), round(float(last["north_m"]), 6), set(flown["mode"])
    (10, 4.5, 225.0, {'plan'})
    """
    flown = _plan_flown(built.ownship, np.asarray(built.times_s, float))
    return ClosedLoopRun("unequipped", flown, pd.DataFrame(), np.nan, 0.0)


def _ownship_row(built, state: TrajectorySample) -> pd.DataFrame:
    """The own-ship table's row of a true state (perfect surveillance knows its own state, too)."""
    pos, vel = state.position_ned_m[0], state.velocity_ned_mps[0]
    row = {
        "time_s": float(state.time_s[0]),
        "own_north_m": pos[0],
        "own_east_m": pos[1],
        "own_down_m": pos[2],
        "own_vn_mps": vel[0],
        "own_ve_mps": vel[1],
        "own_vd_mps": vel[2],
        "own_yaw_rad": float(state.attitude_rad[0, 0]),
    }
    if built.terrain is not None:
        ground = float(np.asarray(built.terrain.height_at(state.lat_deg, state.lon_deg))[0])
        row["own_height_agl_m"] = float(state.alt_m[0]) - ground
    return pd.DataFrame([row])


def _truth_rows(built, time_s: float) -> pd.DataFrame:
    """Every intruder's true state at ``time_s`` as confirmed tracks rows (track id: index + 1)."""
    rows = []
    for k, intruder in enumerate(built.intruders):
        if not intruder.trajectory.covers(np.array([time_s]))[0]:
            continue
        s = intruder.trajectory.sample(time_s)
        pos, vel = s.position_ned_m[0], s.velocity_ned_mps[0]
        rows.append(
            {
                "time_s": time_s,
                "track_id": k + 1,
                "north_m": pos[0],
                "east_m": pos[1],
                "down_m": pos[2],
                "vn_mps": vel[0],
                "ve_mps": vel[1],
                "vd_mps": vel[2],
                "confirmed": True,
            }
        )
    columns = ["time_s", "track_id", "north_m", "east_m", "down_m", "vn_mps", "ve_mps", "vd_mps", "confirmed"]
    return pd.DataFrame(rows, columns=columns)


def fly_perfect_surveillance(
    built, pilot_config: PilotConfig | None = None, alert_config: AlertConfig | None = None
) -> ClosedLoopRun:
    """The encounter with a perfect sensor: true intruder and own-ship states, every frame, alerted
    and advised as the radar's tracks are, flown by the same pilot.

    Parameters
    ----------
    built : BuiltScenario
        The scenario; its own-ship trajectory is the pilot's plan.
    pilot_config : PilotConfig, optional
        The pilot's reactions and the aircraft's kinematics.
    alert_config : AlertConfig, optional
        Volumes, times and gates of the alerting (default :class:`AlertConfig`).

    Returns
    -------
    ClosedLoopRun
        Condition ``perfect``: the own-ship the pilot flew, the alerts of every frame, when the pilot
        first manoeuvred (s) and for how long (s).

    Examples
    --------
    Head-on, 900 m apart and closing at 90 m/s: the truth alerts at warning level at once, and the
    pilot turns away within the first seconds.

    >>> from skyradar.scene.scenario import Scenario
    >>> spec = {"name": "head-on", "origin": {"lat_deg": 52.0, "lon_deg": 4.36, "alt_m": 0.0},
    ...     "radar": {"range_limit_m": 1500},
    ...     "ownship": {"type": "straight", "start_ned_m": [0, 0, -2000], "speed_mps": 50},
    ...     "intruders": [{"name": "A", "type": "straight", "start_ned_m": [900, -40, -2000],
    ...                    "heading_deg": 180, "speed_mps": 40}],
    ...     "frame_rate_hz": 2.0, "duration_s": 5.0}
    >>> run = fly_perfect_surveillance(Scenario.from_dict(spec).build())
    >>> run.condition, len(run.alerts), int(run.alerts["level"].max()), run.first_action_s
    ('perfect', 10, 3, 4.0)
    >>> sorted(set(run.flown["mode"]))
    ['avoid', 'plan']
    """
    pilot = Pilot(built.ownship, pilot_config, start_s=float(built.times_s[0]))
    stream = AlertStream(alert_config, with_advice=True, source=f"{built.name} (truth)")
    alerts = []
    for time_s in np.asarray(built.times_s, float):
        state = pilot.advance(time_s)
        frame = stream.step(time_s, _truth_rows(built, time_s), _ownship_row(built, state))
        alerts.append(frame)
        _show_pilot(pilot, time_s, frame)
    table = pd.concat(alerts, ignore_index=True) if alerts else pd.DataFrame()
    return ClosedLoopRun("perfect", pilot.flown(), table, pilot.first_action_s, pilot.manoeuvre_s)


def fly_radar(
    built,
    pilot_config: PilotConfig | None = None,
    alert_config: AlertConfig | None = None,
    process_options: dict[str, Any] | None = None,
    heads: list[str] | None = None,
) -> ClosedLoopRun:
    """The encounter with the radar chain in the loop (:class:`ClosedLoopChain`), to the last frame.

    Parameters
    ----------
    built : BuiltScenario
        The scenario; its own-ship trajectory is the pilot's plan.
    pilot_config : PilotConfig, optional
        The pilot's reactions and the aircraft's kinematics.
    alert_config, process_options, heads
        As in :class:`~skyradar.stream.StreamingChain`.

    Returns
    -------
    ClosedLoopRun
        Condition ``radar``: the own-ship the pilot flew, the alerts of every frame, when the pilot
        first manoeuvred (s) and for how long (s).
    """
    chain = ClosedLoopChain(built, pilot_config, alert_config, process_options, heads)
    alerts = pd.concat([result.alerts for result in chain.run()], ignore_index=True)
    pilot = chain.pilot
    return ClosedLoopRun("radar", pilot.flown(), alerts, pilot.first_action_s, pilot.manoeuvre_s)


def separation(
    flown: pd.DataFrame, intruder: Trajectory, volume: WellClearVolume | None = None
) -> dict[str, float]:
    """Separation of a flown own-ship from an intruder over the flown span, on a 0.05-s grid.

    Parameters
    ----------
    flown : DataFrame
        ``time_s`` (s) and NED ``north_m``, ``east_m``, ``down_m`` (m) of the own-ship, increasing in time.
    intruder : Trajectory
        The intruder's true flight (covering the flown span).
    volume : WellClearVolume, optional
        The well-clear volume (default DO-365's non-cooperative 2200 ft / 450 ft).

    Returns
    -------
    dict
        ``lowc`` (1.0 when well clear is lost, else 0.0), ``t_lowc_s`` (first loss, s; NaN),
        ``nmac`` (1.0 within 500 ft horizontally and 100 ft vertically at once, else 0.0), the
        smallest horizontal and vertical separations ``min_horizontal_m``, ``min_vertical_m``
        and distance ``min_distance_m`` (m), and ``t_cpa_s`` (s), over the span both fly.

    Examples
    --------
    Head-on at the same altitude, 100 m/s closing, 60 m apart horizontally at the CPA:

    >>> t = np.array([0.0, 20.0])
    >>> own = pd.DataFrame({"time_s": t, "north_m": [0.0, 1000.0], "east_m": 0.0, "down_m": -500.0})
    >>> other = Trajectory.from_states(t, [[2000, 60, -500], [1000, 60, -500]], origin=(52.0, 4.0, 0.0))
    >>> s = separation(own, other)
    >>> s["lowc"], s["nmac"], round(s["min_horizontal_m"], 1), s["t_cpa_s"]
    (1.0, 1.0, 60.0, 20.0)
    """
    volume = volume or WellClearVolume.do365_noncoop()
    t_flown = flown["time_s"].to_numpy(float)
    start, end = max(t_flown[0], intruder.time_s[0]), min(t_flown[-1], intruder.time_s[-1])
    if end < start:
        raise ValueError(f"separation: the intruder '{intruder.name}' does not fly during the flown span")
    t = np.arange(start, end + 1e-9, _SEPARATION_STEP_S)
    own = np.stack(
        [np.interp(t, t_flown, flown[c].to_numpy(float)) for c in ("north_m", "east_m", "down_m")], -1
    )
    rel = intruder.sample(t).position_ned_m - own
    horizontal, vertical = np.hypot(rel[:, 0], rel[:, 1]), np.abs(rel[:, 2])
    lost = (horizontal <= volume.dthr_m) & (vertical <= volume.zthr_m)
    nmac = (horizontal <= NMAC_HORIZONTAL_M) & (vertical <= NMAC_VERTICAL_M)
    distance = np.linalg.norm(rel, axis=1)
    return {
        "lowc": float(lost.any()),
        "t_lowc_s": float(t[np.argmax(lost)]) if lost.any() else float("nan"),
        "nmac": float(nmac.any()),
        "min_horizontal_m": float(horizontal.min()),
        "min_vertical_m": float(vertical.min()),
        "min_distance_m": float(distance.min()),
        "t_cpa_s": float(t[int(np.argmin(distance))]),
    }
