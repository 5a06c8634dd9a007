"""Encounters from two recorded flights (skyradar.scene.encounter_from_tracks, `skyradar make-encounter`).

Straight flights make the closest point of approach a closed form: with the horizontal relative
position r and velocity v at any time t0, it is at t0 - r.v / |v|^2 at distance |r x v| / |v|.
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from cli_helpers import assert_one_line_error, skyradar, skyradar_in_process
from skyradar.errors import InputError
from skyradar.scene.adsb import read_trajectory
from skyradar.scene.encounter_from_tracks import encounter_from_tracks, trajectory_table
from skyradar.scene.flights import straight
from skyradar.scene.scenario import load_scenario

MUNICH, LISBON = (48.2, 11.6, 500.0), (38.7, -9.1, 0.0)


def _closed_form_cpa(own, intr, t0: float) -> tuple[float, float, float]:
    """(t, horizontal miss, vertical miss) of two constant-velocity flights, from two samples each."""
    t1 = t0 + 1.0
    r0 = intr.sample(t0).position_ned_m[0] - own.sample(t0).position_ned_m[0]
    r1 = intr.sample(t1).position_ned_m[0] - own.sample(t1).position_ned_m[0]
    v = r1 - r0
    t_star = t0 - float(np.dot(r0[:2], v[:2]) / np.dot(v[:2], v[:2]))
    r = r0 + v * (t_star - t0)
    return t_star, float(np.hypot(r[0], r[1])), float(-r[2])


@pytest.mark.parametrize(
    ("own_heading", "intr_heading", "miss_m", "vertical_m", "rotate_deg", "side"),
    [
        (30.0, 100.0, 200.0, 50.0, 0.0, "right"),
        (0.0, 180.0, 0.0, -100.0, 0.0, "left"),
        (250.0, 250.0, 500.0, 0.0, 90.0, "left"),
        (90.0, 10.0, 1000.0, 150.0, -45.0, "right"),
    ],
)
def test_closest_approach_is_the_requested_one(
    own_heading, intr_heading, miss_m, vertical_m, rotate_deg, side
):
    a = straight([0, 0, -1000], own_heading, 50.0, 200.0, origin=MUNICH, rate_hz=1.0, name="A")
    b = straight([0, 0, -800], intr_heading, 40.0, 300.0, origin=LISBON, rate_hz=1.0, name="B")
    own, intr = encounter_from_tracks(a, b, 120.0, miss_m, vertical_m, 150.0, rotate_deg, side)
    t_star, h_m, v_m = _closed_form_cpa(own, intr, 100.0)
    assert t_star == pytest.approx(120.0, abs=1e-6)
    assert h_m == pytest.approx(miss_m, abs=1e-3) and v_m == pytest.approx(vertical_m, abs=0.05)
    np.testing.assert_allclose(own.sample(120.0).position_ned_m[0], 0.0, atol=1e-6)  # origin at CPA
    heading = np.degrees(np.arctan2(*intr.velocity_ned_mps[0, [1, 0]]))
    # Turned by rotate_deg; 0.1 deg: B's straight line in its own origin's frame meets meridians 6 km
    # from that origin at another angle (convergence 6 km / 87 km per deg * sin 38.7 deg = 0.04 deg).
    assert (heading - intr_heading - rotate_deg + 180.0) % 360.0 - 180.0 == pytest.approx(0.0, abs=0.1)
    assert intr.time_s[0] == pytest.approx(-30.0)  # intruder time 150 s moved to 120 s
    if miss_m:  # the intruder passes on the requested side of the own ship's track
        r = intr.sample(120.0).position_ned_m[0]
        right = np.array([-np.sin(np.radians(own_heading)), np.cos(np.radians(own_heading))])
        assert np.sign(np.dot(r[:2], right)) == (1 if side == "right" else -1)


def test_scenario_round_trip_through_files_keeps_the_encounter(tmp_path):
    """The written tracks, read back by the scenario loader, still meet as requested."""
    import yaml

    from skyradar.scene.encounter_from_tracks import encounter_scenario

    a = straight([0, 0, -1000], 30.0, 50.0, 200.0, origin=MUNICH, rate_hz=1.0, name="A")
    b = straight([0, 0, -800], 100.0, 40.0, 300.0, origin=LISBON, rate_hz=1.0, name="B")
    own, intr = encounter_from_tracks(a, b, 120.0, 200.0, 50.0)
    trajectory_table(own).to_csv(tmp_path / "own.csv", index=False)
    trajectory_table(intr).to_csv(tmp_path / "intr.csv", index=False)
    scenario = encounter_scenario(own, intr, "own.csv", "intr.csv", 120.0, before_s=60.0, after_s=20.0)
    (tmp_path / "enc.yaml").write_text(yaml.safe_dump(scenario))
    built = load_scenario(tmp_path / "enc.yaml").build()
    assert built.times_s[0] == pytest.approx(60.0) and built.times_s[-1] == pytest.approx(140.0, abs=0.2)
    t_star, h_m, v_m = _closed_form_cpa(built.ownship, built.intruders[0].trajectory, 100.0)
    assert (t_star, h_m, v_m) == pytest.approx((120.0, 200.0, 50.0), abs=0.05)
    back = read_trajectory(tmp_path / "intr.csv", origin=own.origin, time_zero_s=0.0)
    times = np.linspace(max(back.start_s, intr.start_s), min(back.end_s, intr.end_s), 200)
    np.testing.assert_allclose(
        back.sample(times).velocity_ned_mps, intr.sample(times).velocity_ned_mps, atol=0.05
    )


def test_bad_requests_name_the_field():
    a = straight([0, 0, -1000], 30.0, 50.0, 100.0, rate_hz=1.0, name="A")
    with pytest.raises(InputError, match="closest-approach time: 500 s is outside 'A'"):
        encounter_from_tracks(a, a, 500.0, 100.0)
    with pytest.raises(InputError, match="horizontal miss: must be a finite distance >= 0 m, got -1"):
        encounter_from_tracks(a, a, 50.0, -1.0)


def test_make_encounter_command(tmp_path, monkeypatch, capsys, caplog):
    rows = []
    for heading, origin in ((30.0, MUNICH), (100.0, LISBON)):
        traj = straight([0, 0, -1000], heading, 50.0, 200.0, origin=origin, rate_hz=1.0)
        s = traj.sample(traj.time_s)
        df = pd.DataFrame(
            {
                "timestamp": (1.7e9 + s.time_s) * 1000,
                "latitude": s.lat_deg,
                "longitude": s.lon_deg,
                "altitude": s.alt_m / 0.3048,
            }
        )
        rows.append(df)
    rows[0].iloc[::-1].to_csv(tmp_path / "a.csv.gz", index=False)  # reversed, epoch ms: cleaned
    rows[1].to_json(tmp_path / "b.json", orient="records")
    monkeypatch.chdir(tmp_path)
    args = ("make-encounter", "a.csv.gz", "b.json", "-o", "enc.yaml", "--miss-m", "300", "--t-cpa-s", "100")
    code, stdout, stderr = skyradar_in_process(
        monkeypatch, capsys, *args, "--vertical-miss-m", "-60", "--json"
    )
    assert code == 0, stderr
    out = json.loads(stdout.strip().splitlines()[-1])
    assert out["t_cpa_s"] == pytest.approx(100.0, abs=1e-3) and out["horizontal_miss_m"] == pytest.approx(
        300.0
    )
    assert out["vertical_miss_m"] == pytest.approx(-60.0, abs=0.05)
    notes = [r.getMessage() for r in caplog.records if r.name == "skyradar.scene.adsb"]  # stderr in a shell
    assert "a.csv.gz: cleaned: timestamp in epoch ms, sorted by time (200 step(s) back)" in notes[0]
    built = load_scenario(tmp_path / "enc.yaml").build()
    assert (built.times_s[0], len(built.intruders)) == (pytest.approx(40.0), 1)
    # A file that cannot be repaired (timestamps between seconds and milliseconds) is refused in one
    # line with the reason, and the scenario written before is left as it was.
    rows[1].assign(timestamp=lambda d: d["timestamp"] / 100).to_json(tmp_path / "bad.json", orient="records")
    before = (tmp_path / "enc.yaml").read_text()
    again = skyradar("make-encounter", "bad.json", "b.json", "-o", "enc.yaml", "--overwrite", cwd=tmp_path)
    assert_one_line_error(again, "bad.json: field 'timestamp' runs from", "cannot tell the unit")
    assert (tmp_path / "enc.yaml").read_text() == before
