"""Several heads' detections as one stream: which same-frame detections are one object (track.fusion)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from skyradar.config import RadarConfig
from skyradar.process.doa import FIELD_OF_VIEW_LOSS_DB, direction_from_angles
from skyradar.track.fusion import OUTSIDE_FIELD_GAP_DB, fuse_heads


def _pair(snr_db: tuple[float, float], azimuth_deg: tuple[float, float]) -> pd.DataFrame:
    """One frame: a nose and a left-head detection at one range and radial velocity, at the given
    SNRs and world azimuths (level, 820 m away)."""
    u = direction_from_angles(np.radians(azimuth_deg), np.zeros(2))
    p = 820.0 * u
    return pd.DataFrame(
        {
            "time_s": [0.0, 0.0],
            "range_m": [820.0, 821.0],
            "radial_velocity_mps": [-15.0, -15.1],
            "snr_db": list(snr_db),
            "radar": ["nose", "left"],
            "north_m": p[:, 0],
            "east_m": p[:, 1],
            "down_m": p[:, 2],
        }
    )


def test_the_gap_is_two_way_the_field_of_views_edge_loss():
    assert OUTSIDE_FIELD_GAP_DB == 2.0 * FIELD_OF_VIEW_LOSS_DB


def test_a_head_that_sees_a_target_from_outside_its_field_adds_no_second_object():
    # An aircraft 5 deg right of the nose: the nose head at 41 dB; the left head (boresight 75 deg
    # left) sees it through its pattern's skirts at 10 dB and points 65 deg left: 960 m apart.
    fused, rows = fuse_heads(_pair((41.0, 10.0), (5.0, -65.0)), RadarConfig.prototype_2022())
    assert rows.tolist() == [0] and fused["radar"].tolist() == ["nose"]


def test_two_aircraft_at_one_range_and_doppler_within_both_fields_stay_two():
    # As strong as two heads can see one aircraft apart inside both their fields (8 dB): their
    # directions are measured, and 960 m apart they are two aircraft.
    fused, rows = fuse_heads(_pair((30.0, 22.0), (5.0, -65.0)), RadarConfig.prototype_2022())
    assert rows.tolist() == [0, 1]
    # The same pair where the directions agree is one aircraft seen by both heads.
    fused, rows = fuse_heads(_pair((30.0, 22.0), (-30.0, -31.0)), RadarConfig.prototype_2022())
    assert rows.tolist() == [0]
