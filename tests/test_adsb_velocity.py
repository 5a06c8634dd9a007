"""Recorded velocities that are not those of the recorded positions are not used.

The ``traffic`` package's calibration samples carry a ground track about 100 deg off their
positions' course. A path fitted to both would swing the aircraft at some 10 g between 5 s fixes,
and the radar would see a radial velocity jumping by 100 m/s within a second. A few degrees off is
reporting error, which the smoother weighs against the positions.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from skyradar.scene.adsb import read_trajectory

KT = 1852.0 / 3600.0


def _write(tmp_path, track_deg: float) -> str:
    t = np.arange(0.0, 60.0, 5.0)
    north_m = 60.0 * t  # due north at 60 m/s
    df = pd.DataFrame(
        {
            "timestamp": 1_700_000_000 + t,
            "latitude": 48.0 + north_m / 111_200.0,
            "longitude": np.full(t.size, 16.0),
            "altitude": np.full(t.size, 3000.0),
            "groundspeed": np.full(t.size, 60.0 / KT),
            "track": np.full(t.size, track_deg),
            "vertical_rate": np.zeros(t.size),
        }
    )
    path = tmp_path / f"track_{track_deg:g}.csv"
    df.to_csv(path, index=False)
    return str(path)


@pytest.mark.parametrize(("track_deg", "replaced"), [(103.0, True), (4.0, False)])
def test_velocity_columns_off_the_positions_course_are_replaced(tmp_path, caplog, track_deg, replaced):
    traj = read_trajectory(_write(tmp_path, track_deg))
    mid = traj.sample(np.array([20.0]))
    east = float(mid.velocity_ned_mps[0, 1])
    # Not used: the course of the positions (due north). Used: between the positions' course and the
    # recorded 4 deg (4.2 m/s east), weighed by their spreads.
    if replaced:
        assert east == pytest.approx(0.0, abs=0.3)
    else:
        assert -0.3 <= east <= 60.0 * np.sin(np.radians(4.0)) + 0.3
    assert float(mid.velocity_ned_mps[0, 0]) == pytest.approx(60.0, abs=1.0)
    assert ("off the positions' course" in caplog.text) == replaced
