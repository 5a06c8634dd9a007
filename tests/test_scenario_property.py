"""Scenarios drawn across and beyond every stated range: each is built or refused in one line.

Values are drawn inside the plausible ranges, at their edges and far beyond them (kilometres for
metres, NaN, infinities, negative rates). A scenario either builds, and then holds only plausible
values, or is refused with an :class:`~skyradar.errors.InputError` of one line naming the field; no
other exception reaches the user.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from skyradar.errors import InputError
from skyradar.scene.adsb import ALT_LIMITS_M
from skyradar.scene.flyable import AIRCRAFT_CLASSES
from skyradar.scene.scenario import Scenario

WILD = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -1.0, 1e9, -1e9, 1e308, 30.0, 30.000001, -30.0, 100.0, 100.5]),
)


PLAUSIBLE = {
    "lever_arm_m": st.tuples(*[st.floats(-30, 30) for _ in range(3)]),
    "heading_bias_deg": st.floats(0, 30),
    "gnss_horizontal_bias_m": st.floats(0, 100),
    "speed_mps": st.floats(20, 150),
    "down_m": st.floats(-3000, -100),
    "duration_s": st.floats(0.2, 3),
    "frame_rate_hz": st.floats(1, 19),  # the prototype frames at most 1/50.8 ms
    "intruder_speed_mps": st.floats(10, 120),
    "horizontal_miss_m": st.floats(0, 2000),
    "aircraft_class": st.sampled_from(["ga", "transport", "any"]),
}
plausible = st.fixed_dictionaries(PLAUSIBLE)
# One field at a time taken far out (or to a bad name): the rest plausible.
wild = st.tuples(plausible, st.sampled_from(sorted(PLAUSIBLE)), WILD).map(
    lambda drawn: {
        **drawn[0],
        drawn[1]: (
            "jet"
            if drawn[1] == "aircraft_class"
            else (drawn[2],) * 3
            if drawn[1] == "lever_arm_m"
            else drawn[2]
        ),
    }
)


def _scenario(v: dict) -> dict:
    return {
        "name": "drawn",
        "origin": {"lat_deg": 52.5, "lon_deg": 4.36, "alt_m": 0.0},
        "duration_s": v["duration_s"],
        "frame_rate_hz": v["frame_rate_hz"],
        "mount": {"preset": "forward", "lever_arm_m": list(v["lever_arm_m"])},
        "navigation": {
            "model": "ga-typical",
            "heading_bias_deg": v["heading_bias_deg"],
            "gnss_horizontal_bias_m": v["gnss_horizontal_bias_m"],
        },
        "ownship": {
            "type": "straight",
            "start_ned_m": [0.0, 0.0, v["down_m"]],
            "heading_deg": 10.0,
            "speed_mps": v["speed_mps"],
            "aircraft_class": v["aircraft_class"],
        },
        "intruders": [
            {
                "type": "encounter",
                "kind": "head-on",
                "t_cpa_s": 30.0,
                "horizontal_miss_m": v["horizontal_miss_m"],
                "intruder_speed_mps": v["intruder_speed_mps"],
            }
        ],
    }


def _built_or_refused(values) -> bool:
    """True when built (its values then checked plausible), False when refused in one line."""
    try:
        built = Scenario.from_dict(_scenario(values)).build()
    except InputError as exc:
        assert "\n" not in str(exc).strip() and "field" in str(exc), str(exc)
        return False
    assert all(abs(x) <= 30.0 for x in built.heads[0].config.mount.position_m)
    nav = built.navigation
    assert 0 <= nav.heading_bias_deg <= 30.0 and 0 <= nav.gnss_horizontal_bias_m <= 100.0
    own = built.ownship.sample(built.times_s)
    limits = AIRCRAFT_CLASSES[values["aircraft_class"]]
    assert np.linalg.norm(own.velocity_ned_mps, axis=1).max() <= limits.speed_mps
    assert ALT_LIMITS_M[0] <= own.alt_m.min() and own.alt_m.max() <= ALT_LIMITS_M[1]
    assert math.isfinite(built.times_s.sum()) and built.times_s.size >= 1
    return True


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(plausible)
def test_a_scenario_of_plausible_values_is_built(values):
    values = {
        **values,
        "speed_mps": min(values["speed_mps"], AIRCRAFT_CLASSES[values["aircraft_class"]].speed_mps),
    }
    assert _built_or_refused(values)


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(wild)
def test_a_scenario_with_a_value_far_out_is_built_plausible_or_refused_in_one_line(values):
    event("built" if _built_or_refused(values) else "refused")
