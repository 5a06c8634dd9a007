"""Surveillance figures of an encounter set: declaration range, time to confirm, errors by range."""

from __future__ import annotations

import numpy as np
import pandas as pd

from skyradar.experiments.sensor_figures import sensor_summary


def test_figures_band_the_samples_by_range_and_closing_speed():
    res = pd.DataFrame(
        {
            "declaration_range_m": [4000.0, 3000.0, np.nan],
            "declaration_closing_mps": [120.0, 220.0, np.nan],
            "time_to_confirm_s": [1.0, 3.0, np.nan],
            # range, horizontal, vertical, velocity error: 3 and 4 m horizontal below 1 km, 30 m at 2.5 km
            "track_errors": [
                [[500.0, 3.0, 1.0, 0.5], [900.0, 4.0, 1.0, 0.5]],
                [[2500.0, 30.0, 10.0, 2.0]],
                [],
            ],
            "flight_s": [1800.0, 1800.0, 3600.0],
            "clutter_tracks": [1, 0, 0],
            "ground_tracks": [0, 1, 2],
        }
    )
    s = sensor_summary(res)
    assert s["intruder_confirmed_encounters"] == 2
    assert s["declaration_range_m"]["p50"] == 3500.0
    assert s["declaration_range_by_closing_mps"]["100-150"] == {"encounters": 1, "p50": 4000.0}
    assert s["declaration_range_by_closing_mps"][">=200"] == {"encounters": 1, "p50": 3000.0}
    near = s["track_error_by_range"]["0-1 km"]
    assert near["samples"] == 2 and np.isclose(near["horizontal_m_rms"], np.sqrt((9 + 16) / 2))
    assert s["track_error_by_range"]["2-3 km"]["horizontal_m_p95"] == 30.0
    assert s["track_error_by_range"]["3-5 km"] == {"samples": 0}
    assert s["time_to_confirm_s"]["p50"] == 2.0
    assert s["false_tracks_per_hour"] == 4 / 2.0  # 4 false tracks in 2 flight hours


def test_a_set_without_a_confirmed_intruder_has_empty_figures():
    res = pd.DataFrame(
        {
            "declaration_range_m": [np.nan],
            "declaration_closing_mps": [np.nan],
            "time_to_confirm_s": [np.nan],
            "track_errors": [[]],
            "flight_s": [60.0],
        }
    )
    s = sensor_summary(res)
    assert s["intruder_confirmed_encounters"] == 0 and s["declaration_range_m"] == {}
    assert s["false_tracks_per_hour"] == 0.0
