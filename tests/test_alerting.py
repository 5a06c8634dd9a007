"""Alert levels switch at the configured times, with M-of-N persistence and hysteresis."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyradar.daa.alerting import (
    RADAR_ALERT_CONFIG,
    AlertConfig,
    AlertFilter,
    filter_alert_levels,
    raw_alert_levels,
    required_track_age,
)
from skyradar.daa.conflict import FT
from skyradar.daa.pipeline import alerts_from_tracks
from skyradar.errors import InputError

DT = 0.5
D_NC = 2200 * FT


def _head_on(start_m=8000.0, closure_mps=100.0, duration_s=90.0, dt=DT):
    """Own-ship north at 50 m/s from the origin; intruder on the same line coming south at 50 m/s."""
    t = np.arange(0.0, duration_s, dt)
    own = pd.DataFrame(
        {
            "time_s": t,
            "own_north_m": 50.0 * t,
            "own_east_m": 0.0,
            "own_down_m": -1000.0,
            "own_vn_mps": 50.0,
            "own_ve_mps": 0.0,
            "own_vd_mps": 0.0,
            "own_yaw_rad": 0.0,
        }
    )
    v_int = closure_mps - 50.0
    tracks = pd.DataFrame(
        {
            "time_s": t,
            "track_id": 1,
            "north_m": start_m - v_int * t,
            "east_m": 0.0,
            "down_m": -1000.0,
            "vn_mps": -v_int,
            "ve_mps": 0.0,
            "vd_mps": 0.0,
        }
    )
    return own, tracks


def test_raw_levels_switch_at_alerting_times():
    own, tracks = _head_on()
    out = alerts_from_tracks(tracks, own, with_advice=False)
    t = out["time_s"].to_numpy()
    # Loss of well clear (2200 ft disc) at (8000 - 670.56) / 100 = 73.29 s after start.
    t_lowc = (8000.0 - D_NC) / 100.0
    raw = out["raw_level"].to_numpy()
    assert t[np.argmax(raw >= 2)] == pytest.approx(np.ceil((t_lowc - 55.0) / DT) * DT)
    assert t[np.argmax(raw >= 3)] == pytest.approx(np.ceil((t_lowc - 25.0) / DT) * DT)
    # M = 2 of N = 4: the issued level follows one frame after the raw level.
    lvl = out["level"].to_numpy()
    assert t[np.argmax(lvl >= 2)] == pytest.approx(t[np.argmax(raw >= 2)] + DT)
    assert t[np.argmax(lvl >= 3)] == pytest.approx(t[np.argmax(raw >= 3)] + DT)
    np.testing.assert_allclose(
        out["t_in_s"].to_numpy()[raw >= 2], np.maximum(t_lowc - t[raw >= 2], 0.0), atol=1e-9
    )


def test_alerts_keep_integer_track_ids():
    # The demo's timeline formats ids as integers; a float id (7.0) broke it.
    own, tracks = _head_on(duration_s=10.0)
    out = alerts_from_tracks(tracks.assign(track_id=7), own, with_advice=False)
    assert np.issubdtype(out["track_id"].dtype, np.integer) and set(out["track_id"]) == {7}
    with pytest.raises(InputError, match="'track_id' is not a whole number at row 0"):
        alerts_from_tracks(tracks.assign(track_id=7.5), own, source="t.parquet")


def test_flarm_level_and_sector_in_pipeline():
    own, tracks = _head_on(start_m=3000.0, duration_s=30.0)
    out = alerts_from_tracks(tracks, own, with_advice=False)
    t = out["time_s"].to_numpy()
    t_imp = (3000.0 - 500 * FT) / 100.0
    fl = out["flarm_level"].to_numpy()
    assert t[np.argmax(fl >= 1)] == pytest.approx(np.ceil((t_imp - 18) / DT) * DT)
    assert t[np.argmax(fl >= 3)] == pytest.approx(np.ceil((t_imp - 8) / DT) * DT)
    assert (out["sector"] == 0).all()
    assert out["rel_alt_m"].abs().max() == 0.0


def test_hysteresis_lowers_only_after_hysteresis_time():
    cfg = AlertConfig(m=1, n=1, persistence_s=0.0, hysteresis_s=3.0)
    t = np.arange(0.0, 10.0, 0.5)
    raw = np.where(t < 4.0, 3, 0)
    lvl = filter_alert_levels(t, raw, cfg)
    assert lvl[t < 4.0].tolist() == [3] * 8
    # Below from 4.0 s, so held until 4.0 + 3.0 s.
    assert t[np.argmax(lvl == 0)] == pytest.approx(7.0)
    # A raw level that comes back before the hysteresis ran out resets the clock.
    raw2 = np.where((t < 4.0) | (t == 6.0), 3, 0)
    lvl2 = filter_alert_levels(t, raw2, cfg)
    assert t[np.argmax(lvl2 == 0)] == pytest.approx(9.5)


def test_persistence_holds_a_fresh_alert():
    cfg = AlertConfig(m=1, n=1, persistence_s=4.0, hysteresis_s=0.0)
    t = np.arange(0.0, 8.0, 1.0)
    lvl = filter_alert_levels(t, np.array([0, 2, 0, 0, 0, 0, 0, 0]), cfg)
    assert lvl.tolist() == [0, 2, 2, 2, 2, 0, 0, 0]


def test_m_of_n_ignores_isolated_blips():
    cfg = AlertConfig(m=2, n=4, persistence_s=0.0, hysteresis_s=0.0)
    t = np.arange(12.0)
    blips = np.array([3, 0, 0, 0, 3, 0, 0, 0, 3, 0, 0, 0])
    assert filter_alert_levels(t, blips, cfg).max() == 0
    pair = np.array([0, 3, 0, 0, 3, 0, 0, 0, 0, 0, 0, 0])
    assert filter_alert_levels(t, pair, cfg).tolist() == [0, 0, 0, 0, 3, 0, 0, 0, 0, 0, 0, 0]


def _m_of_n_levels(raw, m, n):
    out = []
    for k in range(len(raw)):
        window = raw[max(0, k - n + 1) : k + 1]
        out.append(max([lv for lv in range(1, 4) if sum(r >= lv for r in window) >= m], default=0))
    return out


@given(st.lists(st.integers(0, 3), min_size=1, max_size=40), st.integers(1, 4), st.integers(0, 3))
@settings(max_examples=200, deadline=None)
def test_filter_invariants(raw, n, m_minus):
    m = max(1, n - m_minus)
    cfg = AlertConfig(m=m, n=n, persistence_s=2.0, hysteresis_s=3.0)
    lvl = filter_alert_levels(np.arange(len(raw), dtype=float), np.array(raw), cfg)
    mofn = _m_of_n_levels(raw, m, n)
    for k in range(len(raw)):
        assert lvl[k] >= mofn[k]  # never below what M of N support
        if k and lvl[k] > lvl[k - 1]:
            assert lvl[k] == mofn[k]  # rises only to the M-of-N level
        if k and lvl[k] < lvl[k - 1]:
            # lowered only after the M-of-N level stayed below for hysteresis_s (4 frames of 1 s)
            assert k >= 3 and all(mofn[j] < lvl[k - 1] for j in range(k - 3, k + 1))


def test_uncertainty_raises_level():
    s = np.array([[6000.0, 800.0, 0.0]])
    v = np.array([[-100.0, 0.0, 0.0]])
    base = raw_alert_levels(s, v)
    wide = raw_alert_levels(s, v, cov_pos_m2=np.diag([200.0**2, 200.0**2, 50.0**2])[None])
    assert base["level"][0] == 0
    assert wide["level"][0] >= 2
    assert wide["dthr_m"][0] == pytest.approx(D_NC + 1.5 * 200.0)


def test_filter_state_is_per_track_and_confirmed_only():
    own, tracks = _head_on()
    other = tracks.copy()
    other["track_id"] = 2
    other["east_m"] = 5000.0  # far to the side: never alerts
    both = pd.concat([tracks, other]).sort_values("time_s", kind="stable")
    both["confirmed"] = both["track_id"] == 1
    out = alerts_from_tracks(both, own, with_advice=False)
    assert set(out["track_id"]) == {1}
    both["confirmed"] = True
    out = alerts_from_tracks(both, own, with_advice=False)
    assert out.loc[out.track_id == 2, "level"].max() == 0
    assert out.loc[out.track_id == 1, "level"].max() == 3


def test_pipeline_rejects_bad_input():
    own, tracks = _head_on()
    with pytest.raises(InputError, match="missing column"):
        alerts_from_tracks(tracks.drop(columns="vn_mps"), own, source="t.parquet")
    late = tracks.copy()
    late["time_s"] += 500.0
    with pytest.raises(InputError, match="t.parquet: field 'time_s'"):
        alerts_from_tracks(late, own, source="t.parquet")


def test_filter_rejects_bad_m_of_n():
    with pytest.raises(ValueError):
        AlertFilter(AlertConfig(m=5, n=4))


def test_cli_alert_writes_table(tmp_path):
    import json
    import subprocess
    import sys

    from typer.testing import CliRunner

    from skyradar.cli import app
    from skyradar.daa.pipeline import truth_tracks
    from skyradar.io.tables import read_table, write_table
    from skyradar.web.sample import sample_run_dataset, write_sample_run

    run = write_sample_run(tmp_path / "run.zarr", n_frames=40)
    tracks = truth_tracks(sample_run_dataset(n_frames=40))
    write_table(tracks, tmp_path / "tracks.parquet")
    out = tmp_path / "alerts.parquet"
    res = CliRunner().invoke(
        app, ["alert", str(tmp_path / "tracks.parquet"), "--ownship", str(run), "-o", str(out), "--json"]
    )
    assert res.exit_code == 0, res.output
    summary = json.loads(res.stdout.strip().splitlines()[-1])
    alerts = read_table(out, required=["time_s", "track_id", "level", "heading_bands_deg"])
    assert summary["tracks_with_warning"] == 1 and summary["first_warning_s"] == 35.0
    assert alerts.loc[alerts.track_id == 1, "level"].max() == 0
    # Bad input: one line naming the file and field, exit code 2 (through the real entry point).
    bad = tmp_path / "bad.parquet"
    write_table(tracks.drop(columns="vd_mps"), bad)
    cmd = [sys.executable, "-c", "from skyradar.cli import main; main()", "alert", str(bad)]
    proc = subprocess.run(
        cmd + ["--ownship", str(run), "-o", str(out)], capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 2
    assert (
        proc.stderr.strip().startswith("error:")
        and "vd_mps" in proc.stderr
        and "Traceback" not in proc.stderr
    )


def test_young_tracks_do_not_alert():
    own, tracks = _head_on(start_m=3000.0, duration_s=10.0)  # warning geometry from the first frame
    out = alerts_from_tracks(tracks, own, AlertConfig(min_track_age_s=2.0), with_advice=False)
    t, raw = out["time_s"].to_numpy(), out["raw_level"].to_numpy()
    assert (raw[t < 2.0] == 0).all() and (raw[t >= 2.0] == 3).all()
    assert t[np.argmax(out["level"].to_numpy() == 3)] == pytest.approx(2.0 + DT)


def test_m_of_n_over_periods_counts_seconds_not_frames():
    # 5 frames/s. DAIDALUS' 2 of 4 at 1 Hz: half of the last 4 s of frames must reach the level.
    t = np.round(np.arange(0.0, 10.0, 0.2), 6)
    raw = np.where(t >= 3.0, 3, 0)
    kw = {"m": 2, "n": 4, "persistence_s": 0.0, "hysteresis_s": 0.0}
    by_period = filter_alert_levels(t, raw, AlertConfig(period_s=1.0, **kw))
    by_frame = filter_alert_levels(t, raw, AlertConfig(**kw))
    assert t[np.argmax(by_frame == 3)] == pytest.approx(3.2)  # 2 of the last 4 frames
    assert t[np.argmax(by_period == 3)] == pytest.approx(4.8)  # 10 of the 20 frames in (0.8, 4.8]
    # A 0.4 s flicker raises a frame-based alert but not a period-based one.
    flicker = np.where((t >= 3.0) & (t < 3.4), 3, 0)
    assert filter_alert_levels(t, flicker, AlertConfig(**kw)).max() == 3
    assert filter_alert_levels(t, flicker, AlertConfig(period_s=1.0, **kw)).max() == 0
    with pytest.raises(ValueError, match="period_s"):
        AlertConfig(period_s=0.0)


def test_velocity_gate_bounds_the_miss_error_not_the_velocity_error():
    # Over hills, a head-on intruder first detected over clutter 1.7 km away (114 m/s closing), its
    # cross-range velocity known to 10-20 m/s for seconds after suppression's scattered directions. A
    # plain 6 m/s gate keeps it silent through its loss of well clear. At 8 s to CPA a 12 m/s error
    # moves the predicted miss by ~100 m, less than 6 m/s does at the warning's 25 s: the gate is on
    # that product. A far track with the same error stays silent.
    cfg = AlertConfig(max_velocity_sigma_mps=6.0, min_track_age_s=0.0)
    ungated = AlertConfig(min_track_age_s=0.0)
    cov = {f"cov_vv_{i}{j}": (12.0**2 / 2 if i == j and i < 2 else 0.0) for i in range(3) for j in range(3)}
    near = _head_on(start_m=1200.0, closure_mps=114.0, duration_s=4.0)  # 10 s to CPA: warning
    far = _head_on(start_m=4000.0, closure_mps=114.0, duration_s=4.0)  # 35 s to CPA
    levels = {
        (name, gate): alerts_from_tracks(tracks.assign(**cov), own, c, with_advice=False)["raw_level"].max()
        for name, (own, tracks) in (("near", near), ("far", far))
        for gate, c in ((True, cfg), (False, ungated))
    }
    assert levels == {("near", True): 3, ("near", False): 3, ("far", True): 0, ("far", False): 3}


def _crossing_ahead(true_offset_m: float, with_range: bool = True) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Own-ship north at 50 m/s; an intruder 2.8 km ahead coming south at 65 m/s (115 m/s closing),
    passing ``true_offset_m`` east. Its 3-D rows put it 300 m east (a track's estimate from scattered
    directions, horizontal velocity sigma 10 m/s); its range and range rate are the true ones with a
    pixel's noise (4 m, 0.1 m/s)."""
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 10.0, 1.0 / 9.4)
    own = pd.DataFrame(
        {
            "time_s": t,
            "own_north_m": 50.0 * t,
            "own_east_m": 0.0,
            "own_down_m": -1000.0,
            "own_vn_mps": 50.0,
            "own_ve_mps": 0.0,
            "own_vd_mps": 0.0,
            "own_yaw_rad": 0.0,
        }
    )
    north = 2800.0 - 65.0 * t
    tracks = pd.DataFrame(
        {
            "time_s": t,
            "track_id": 1,
            "north_m": north,
            "east_m": 300.0,
            "down_m": -1000.0,
            "vn_mps": -65.0,
            "ve_mps": 0.0,
            "vd_mps": 0.0,
        }
    )
    tracks = tracks.assign(
        **{f"cov_vv_{i}{j}": (50.0 if i == j and i < 2 else 0.0) for i in range(3) for j in range(3)}
    )
    if with_range:
        rel_north = north - 50.0 * t
        r = np.hypot(rel_north, true_offset_m)
        rdot = rel_north * -115.0 / r
        tracks = tracks.assign(
            range_m=r + rng.normal(0, 4.0, t.size), range_rate_mps=rdot + rng.normal(0, 0.1, t.size)
        )
    return own, tracks


def test_a_range_path_inside_the_volume_lifts_the_velocity_gate():
    # A fast closure at 2-3 km over clutter: its directions scatter, so its horizontal velocity sigma
    # stays near 10 m/s and the gate silences it while the CPA is more than 15 s away. Its range and
    # Doppler are measured to a pixel: their path gives the 3-D miss to ~10 m, and the horizontal miss
    # is at most that. Inside the volume's radius by 3 sigmas, the conflict holds whatever the
    # velocity error; a path passing 1 km away (the directions alone made the conflict) stays silent.
    cfg = AlertConfig(max_velocity_sigma_mps=6.0, min_track_age_s=0.0)
    early = {}
    for name, offset, with_range in (
        ("inside", 320.0, True),
        ("outside", 1000.0, True),
        ("no range", 320.0, False),
    ):
        own, tracks = _crossing_ahead(offset, with_range)
        out = alerts_from_tracks(tracks, own, cfg, with_advice=False)
        gated = out["tcpa_s"].to_numpy() > 16.0  # the plain gate silences these rows (10 m/s x 16 s > 150 m)
        early[name] = int(out["raw_level"].to_numpy()[gated].max())
    assert early == {"inside": 3, "outside": 0, "no range": 0}


def test_the_rows_before_confirmation_extend_the_range_path_that_lifts_the_gate():
    # The same closure first held by the ground test for 3 s (over clutter its first detections
    # are judged young, rough or on the ground), then confirmed. Its range and range rate were
    # measured all along, so its path spans the fit's 4 s one second after confirmation, not four.
    # Held rows can only lift the gate: a path passing 1 km away stays silent with them.
    cfg = AlertConfig(max_velocity_sigma_mps=6.0, min_track_age_s=0.0)
    first_inside = {}
    for name, offset, keep_held in (
        ("with held rows", 320.0, True),
        ("confirmed rows only", 320.0, False),
        ("outside, with held rows", 1000.0, True),
    ):
        own, tracks = _crossing_ahead(offset)
        tracks = tracks.assign(confirmed=tracks["time_s"] >= 3.0)
        if not keep_held:
            tracks = tracks[tracks["confirmed"]]
        out = alerts_from_tracks(tracks, own, cfg, with_advice=False)
        gated = out["tcpa_s"].to_numpy() > 16.0  # the plain gate silences these rows (10 m/s x 16 s > 150 m)
        raised = (out["raw_level"].to_numpy() == 3) & gated
        first_inside[name] = (
            round(float(out["time_s"].to_numpy()[np.argmax(raised)]), 1) if raised.any() else None
        )
    assert first_inside["with held rows"] <= 4.1
    assert first_inside["confirmed rows only"] >= 6.9
    assert first_inside["outside, with held rows"] is None


def test_a_range_path_inside_the_volume_raises_a_co_altitude_track_its_velocity_would_clear():
    # A fast closure whose elevation the clutter nulls took (its height is the co-altitude prior)
    # and whose horizontal velocity drifted 25 m/s east on scattered directions: the track predicts
    # a horizontal miss near 900 m, outside the 670 m warning radius. Its range and range rate put
    # the 3-D miss at 320 m, and the horizontal miss is at most that: the warning is raised on the
    # path once it enters within the alerting time. A measured height is the 3-D track's to judge,
    # and a track whose height is outside the volume when the path enters is not raised by it.
    cfg = AlertConfig(min_track_age_s=0.0)
    entering = {}
    for name, offset_m, measured, above_m in (
        ("prior, path inside", 320.0, False, 0.0),
        ("prior, path outside", 1000.0, False, 0.0),
        ("measured height", 320.0, True, 0.0),
        ("prior, 300 m above", 320.0, False, 300.0),
    ):
        own, tracks = _crossing_ahead(offset_m)
        drifted = {"east_m": 300.0 + 25.0 * tracks["time_s"], "ve_mps": 25.0, "down_m": -1000.0 - above_m}
        tracks = _converged(tracks).assign(**drifted, altitude_measured=measured)
        out = alerts_from_tracks(tracks, own, cfg, with_advice=False)
        assert (out["hmd_m"] > 800.0).all()  # the velocity alone clears every row
        warned = out["time_s"].to_numpy()[out["raw_level"].to_numpy() == 3]
        entering[name] = round(float(warned[0]), 1) if warned.size else None
    # Own-ship and intruder close at 115 m/s from 2.8 km: the path is within 670 m of the own-ship
    # from 24.3 - 5.0 = 19.3 s with its miss 3 sigmas high, inside the 25 s alerting time as soon
    # as the fit spans its 4 s.
    assert entering["prior, path inside"] == pytest.approx(4.0, abs=0.2)
    assert entering == {"prior, path inside": entering["prior, path inside"]} | {
        "prior, path outside": None,
        "measured height": None,
        "prior, 300 m above": None,
    }


def test_a_range_path_holds_a_warning_whose_track_height_the_ground_pulled_down():
    # A closure 79 m below passing 343 m aside, over hills: inside the ground's band its elevations
    # are mixtures pulled towards the ground that agree on 300 m below, so the track predicts a
    # vertical miss of 300 m and no loss of well clear. Its range and range rate measure a 3-D miss
    # of 352 m, which leaves sqrt(352^2 - 340^2) = 91 m of vertical miss beside the predicted
    # horizontal 340 m: the issued warning holds. It is not raised on that (a predicted horizontal
    # miss that is off leaves a vertical that is off too), and a path whose 3-D miss agrees with
    # the track's (450 m) holds nothing.
    s = np.array([[1500.0, 340.0, 300.0]])  # NED: 1.5 km ahead, 340 m right, 300 m below
    v = np.array([[-110.0, 0.0, 0.0]])
    speed2, tcpa = np.array([110.0**2]), np.array([1500.0 / 110.0])
    for miss_m, held in ((352.0, 3), (450.0, 0)):
        path = (np.array([miss_m]), np.array([3.0]), speed2, tcpa)
        out = raw_alert_levels(s, v, AlertConfig(), miss=path)
        assert (int(out["level"][0]), int(out["hold_level"][0])) == (0, held), miss_m


def test_a_tracks_table_with_repeated_rows_is_alerted_as_without_them():
    # A table that lists some of a track's rows twice (concatenated exports) describes the same
    # track: its alerts are those of the table without the repeats.
    cfg = AlertConfig(max_velocity_sigma_mps=6.0, min_track_age_s=0.0)
    own, tracks = _crossing_ahead(320.0)
    repeated = pd.concat([tracks, tracks.iloc[:5]]).sort_values("time_s", kind="stable")
    once = alerts_from_tracks(tracks, own, cfg, with_advice=False)
    twice = alerts_from_tracks(repeated, own, cfg, with_advice=False).drop_duplicates(["time_s", "track_id"])
    assert twice["level"].tolist() == once["level"].tolist()


def test_a_tracks_table_without_times_is_one_error_naming_the_columns():
    own, tracks = _crossing_ahead(320.0)
    with pytest.raises(InputError, match=r"t.parquet: missing column\(s\) \['time_s'\]"):
        alerts_from_tracks(tracks.drop(columns="time_s"), own, with_advice=False, source="t.parquet")


def _converged(tracks: pd.DataFrame, sigma_mps: float = 2.0) -> pd.DataFrame:
    """A track with a converged velocity (``sigma_mps`` per horizontal axis, 20 m of position)."""
    cov = {f"cov_vv_{i}{j}": (sigma_mps**2 if i == j else 0.0) for i in range(3) for j in range(3)}
    cov |= {f"cov_pp_{i}{j}": (400.0 if i == j else 0.0) for i in range(3) for j in range(3)}
    return tracks.assign(**cov)


@pytest.mark.parametrize("closure_mps", [80.0, 100.0, 120.0])
def test_a_track_confirmed_8_s_before_the_loss_warns_within_a_second(closure_mps):
    # DO-365 judges an alert by the time it leaves the pilot: a track first confirmed 8 s before the
    # loss of well clear cannot spend the fixed 2 s minimum age and then 2 s of M-of-N window on
    # proving itself. At 9.4 frames/s its wait is a tenth of the time left, and the silenced rows are
    # no evidence against the conflict in the 2-of-4-seconds filter.
    dt = 1.0 / 9.4
    own, tracks = _head_on(start_m=D_NC + 8.0 * closure_mps, closure_mps=closure_mps, duration_s=9.0, dt=dt)
    out = alerts_from_tracks(_converged(tracks), own, RADAR_ALERT_CONFIG, with_advice=False)
    first_warning = out["time_s"].to_numpy()[np.argmax(out["level"].to_numpy() == 3)]
    assert out["level"].max() == 3
    assert first_warning <= 1.0


def test_rows_the_velocity_gate_silences_are_no_evidence_against_the_conflict():
    # A fast closure confirmed over clutter 1.5 km away: its directions scatter, so its horizontal
    # velocity sigma starts near 30 m/s and converges below the gate's bound over about 2.5 s. The
    # gated rows say nothing about the conflict; counted as "no conflict" they would fill the
    # 2-of-4-seconds window with zeros and the warning would wait until its converged rows were half
    # of it (1.3-1.7 s at this closure). Taken as no evidence, it is issued on the second converged row.
    dt = 1.0 / 9.4
    own, tracks = _head_on(start_m=D_NC + 10.0 * 115.0, closure_mps=115.0, duration_s=8.0, dt=dt)
    t = tracks["time_s"].to_numpy()
    sigma = np.where(t < 2.5, 30.0, 2.0)  # per horizontal axis: gated (x ~12 s to CPA > 150 m), then not
    cov = {f"cov_vv_{i}{j}": (sigma**2 if i == j else np.zeros_like(t)) for i in range(3) for j in range(3)}
    cfg = AlertConfig(
        period_s=1.0, max_velocity_sigma_mps=6.0, min_track_age_s=0.0, min_track_age_floor_s=0.0
    )
    out = alerts_from_tracks(tracks.assign(**cov), own, cfg, with_advice=False)
    first_converged = t[np.argmax(t >= 2.5)]
    gated_rows = out["time_s"].to_numpy() < 2.5
    assert (out["raw_level"].to_numpy()[gated_rows] == 0).all()
    first_warning = out["time_s"].to_numpy()[np.argmax(out["level"].to_numpy() == 3)]
    assert first_warning == pytest.approx(first_converged + dt)
    # The same converged rows after a window of frames that measured no conflict wait for their half.
    clear = tracks.assign(**cov, east_m=np.where(t < 2.5, 3000.0, 0.0), ve_mps=0.0)
    measured = alerts_from_tracks(
        clear.assign(**{"cov_vv_00": 4.0, "cov_vv_11": 4.0}), own, cfg, with_advice=False
    )
    later = measured["time_s"].to_numpy()[np.argmax(measured["level"].to_numpy() == 3)]
    assert later > first_converged + 0.5


def test_an_issued_warning_is_held_while_the_velocity_gate_silences_the_rows():
    # A head-on warned on converged rows, whose velocity then scatters for 9 s (an own-ship turn,
    # directions over clutter): the gate keeps those rows from raising, and they say nothing that
    # the conflict is gone. Counted as frames without a conflict they would drop the warning after
    # the 5-s hysteresis and raise it again when the velocity converges; held by their geometry
    # (the volume widened by the velocity's sigma still lost), the warning stays on.
    dt = 1.0 / 9.4
    own, tracks = _head_on(start_m=D_NC + 20.0 * 100.0, closure_mps=100.0, duration_s=15.0, dt=dt)
    t = tracks["time_s"].to_numpy()
    gated = (t >= 3.0) & (t < 12.0)
    sigma = np.where(gated, 9.0, 2.0)  # per horizontal axis: 12.7 m/s x 15-24 s to CPA > 150 m
    cov = {f"cov_vv_{i}{j}": (sigma**2 if i == j else np.zeros_like(t)) for i in range(3) for j in range(3)}
    cfg = replace(RADAR_ALERT_CONFIG, min_track_age_s=0.0, min_track_age_floor_s=0.0)
    out = alerts_from_tracks(tracks.assign(**cov), own, cfg, with_advice=False)
    level, raw = out["level"].to_numpy(), out["raw_level"].to_numpy()
    assert (raw[gated] == 0).all()  # the gate silences them
    first = int(np.argmax(level == 3))
    assert t[first] < 3.0 and (level[first:] == 3).all()


def test_a_track_far_from_its_loss_of_well_clear_waits_the_full_age():
    # 20 s and more from the loss, a fresh track keeps the full minimum age: there is time to converge.
    dt = 1.0 / 9.4
    own, tracks = _head_on(start_m=D_NC + 24.0 * 100.0, closure_mps=100.0, duration_s=6.0, dt=dt)
    out = alerts_from_tracks(_converged(tracks), own, RADAR_ALERT_CONFIG, with_advice=False)
    t, level = out["time_s"].to_numpy(), out["level"].to_numpy()
    assert (level[t < RADAR_ALERT_CONFIG.min_track_age_s] == 0).all()
    assert level.max() == 3


def test_required_track_age_scales_with_the_time_left_and_is_bounded():
    s = np.array([[D_NC + 100.0 * t_left, 0.0, 0.0] for t_left in (0.0, 3.0, 8.0, 15.0, 30.0)])
    v = np.tile([-100.0, 0.0, 0.0], (5, 1))
    age = required_track_age(s, v, AlertConfig())
    assert age.tolist() == pytest.approx([0.5, 0.5, 0.8, 1.5, 2.0])
    # A track predicted to pass well clear waits the full age; so does every track when the floor is off.
    diverging = required_track_age(
        np.array([[3000.0, 5000.0, 0.0]]), np.array([[100.0, 0.0, 0.0]]), AlertConfig()
    )
    assert diverging.tolist() == [2.0]
    cfg = AlertConfig(age_fraction_of_time_left=1.0, min_track_age_s=2.0, min_track_age_floor_s=2.0)
    assert required_track_age(s, v, cfg).tolist() == [2.0] * 5
    with pytest.raises(ValueError, match="age_fraction_of_time_left"):
        AlertConfig(age_fraction_of_time_left=1.5)


def test_an_issued_warning_is_held_while_its_loss_is_predicted_within_the_hold_time():
    # Threshold hysteresis: a head-on intruder whose predicted entry hovers around the warning's 25 s
    # alerting time (22-28 s, a track's prediction wobbling with its velocity) is warned once and not
    # dropped: the warning holds while the entry stays within its early alerting time (90 s).
    s = np.array([[D_NC + 100.0 * t_left, 0.0, 0.0] for t_left in (20.0, 80.0, 100.0)])
    out = raw_alert_levels(s, np.tile([-100.0, 0.0, 0.0], (3, 1)), AlertConfig())
    assert out["level"].tolist() == [3, 0, 0]  # beyond the corrective's 55 s too
    assert out["hold_level"].tolist() == [3, 3, 2]  # within 90 s (warning) and 110 s (corrective)
    t = np.arange(0.0, 30.0, 0.5)
    t_left = 25.0 + 3.0 * np.sin(t)  # the predicted entry wobbles about the alerting time
    raw = np.where(t_left <= 25.0, 3, 2)
    hold = np.where(t_left <= 37.5, 3, 2)
    cfg = AlertConfig(persistence_s=0.0, hysteresis_s=1.0)
    chattering = filter_alert_levels(t, raw, cfg)
    steady = filter_alert_levels(t, raw, cfg, hold)
    first = int(np.argmax(steady == 3))
    assert (steady[first:] == 3).all()
    assert (np.diff(chattering[first:]) != 0).sum() >= 4
    with pytest.raises(ValueError, match="hold_time_factor"):
        AlertConfig(hold_time_factor=0.5)


def test_an_issued_warning_is_held_while_the_miss_stays_inside_the_enlarged_volume():
    # Threshold hysteresis in space: a head-on intruder whose track height scatters about the 450 ft
    # threshold (130-170 m above, the 30-35 m a radar's height scatters by at 2-3 km) after it was
    # warned 110 m above. Without the spatial hold its warning drops and comes back; with the
    # volume enlarged 1.5 times (206 m) it holds.
    own, tracks = _head_on(start_m=4000.0, duration_s=34.0)
    t = tracks["time_s"].to_numpy()
    wobble = 150.0 + 20.0 * np.sign(np.sin(2.0 * np.pi * t / 14.0))  # 170 m for 7 s, then 130 m for 7 s
    up = np.where(t < 14.0, 110.0, wobble)
    tracks = tracks.assign(down_m=-1000.0 - up)
    plain = replace(RADAR_ALERT_CONFIG, z_v_pos=0.0, hold_volume_factor=1.0)  # no covariance: no widening
    held = replace(plain, hold_volume_factor=1.5)
    lvl_plain = alerts_from_tracks(tracks, own, plain, with_advice=False)["level"].to_numpy()
    lvl_held = alerts_from_tracks(tracks, own, held, with_advice=False)["level"].to_numpy()
    first = int(np.argmax(lvl_held == 3))
    assert first > 0 and t[first] < 14.0 and int(np.argmax(lvl_plain == 3)) == first  # raised alike
    assert (lvl_held[first:] == 3).all()
    assert (np.diff((lvl_plain[first:] == 3).astype(int)) != 0).sum() >= 2  # dropped and raised again
    # Beyond the enlarged volume nothing holds it: 250 m above, the warning is lowered.
    away = tracks.assign(down_m=-1000.0 - np.where(t < 14.0, 110.0, 250.0))
    lvl_away = alerts_from_tracks(away, own, held, with_advice=False)["level"].to_numpy()
    assert lvl_away[-1] < 3
    with pytest.raises(ValueError, match="hold_volume_factor"):
        AlertConfig(hold_volume_factor=0.9)


def _level_below(height_below_m: float, climb_mps: float, sigma_vz_mps: float) -> tuple:
    """A head-on intruder closing at 100 m/s from 4 km, ``height_below_m`` below own-ship at first and
    climbing at ``climb_mps``; its track's horizontal velocity converged (2 m/s), its height known to
    10 m and its vertical speed to ``sigma_vz_mps`` (at 3 m/s: the tracker's level-flight prior)."""
    dt = 1.0 / 9.4
    own, tracks = _head_on(start_m=4000.0, closure_mps=100.0, duration_s=45.0, dt=dt)
    t = tracks["time_s"].to_numpy()
    tracks = _converged(tracks).assign(
        down_m=-1000.0 + height_below_m - climb_mps * t,
        vd_mps=-climb_mps,
        cov_pp_22=100.0,
        cov_vv_22=sigma_vz_mps**2,
    )
    return own, tracks


def test_a_level_intruder_outside_the_may_alert_zone_is_not_warned_for_its_prior_vertical_speed():
    # 212 m below and level: outside 1.5 times ZTHR (206 m), where a near miss must not be warned.
    # The track's vertical-speed sigma is the level-flight prior, not a measurement; widened by it,
    # ZTHR (137 m, plus 7.5 m for the height's sigma) would grow by 3 m/s x 25 s to 220 m, and the
    # intruder would be warned however well its height is measured. The radar settings widen by the
    # measured height's sigma only.
    own, tracks = _level_below(212.0, climb_mps=0.0, sigma_vz_mps=3.0)
    radar = alerts_from_tracks(tracks, own, RADAR_ALERT_CONFIG, with_advice=False)
    assert radar["level"].max() < 3
    widened_by_prior = replace(RADAR_ALERT_CONFIG, z_v_vel=1.0)
    assert alerts_from_tracks(tracks, own, widened_by_prior, with_advice=False)["level"].max() == 3


def test_an_intruder_climbing_into_the_volume_is_warned_before_the_loss():
    # The same intruder climbing at 3 m/s, its vertical speed measured (0.5 m/s): the prediction
    # carries it into the volume (220 - 3 x 40 = 100 m below at the closest approach).
    own, tracks = _level_below(220.0, climb_mps=3.0, sigma_vz_mps=0.5)
    out = alerts_from_tracks(tracks, own, RADAR_ALERT_CONFIG, with_advice=False)
    t = out["time_s"].to_numpy()
    rel = np.abs(tracks["down_m"].to_numpy() + 1000.0)
    horizontal = np.abs(tracks["north_m"].to_numpy() - own["own_north_m"].to_numpy())
    t_lowc = t[np.argmax((rel <= 137.16) & (horizontal <= D_NC))]
    t_warn = t[np.argmax(out["level"].to_numpy() == 3)]
    assert out["level"].max() == 3 and t_warn < t_lowc - 12.5
