"""Track metrics: GOSPA against Stone Soup, innovation statistics, counts, switches, fragmentation."""

import datetime

import numpy as np
import pandas as pd
import pytest
from stonesoup.measures import Euclidean  # stonesoup is a dev extra: a missing one is an error, not a skip
from stonesoup.metricgenerator.ospametric import GOSPAMetric
from stonesoup.types.state import State

from skyradar.track.io import Truth
from skyradar.track.metrics import gospa, innovation_stats, pixel_distance, track_metrics, truth_segments


def _stonesoup_gospa(est, tru, c, p):
    now = datetime.datetime(2024, 1, 1)
    metric = GOSPAMetric(c=c, p=p, measure=Euclidean(mapping=(0, 1)))
    es = [State(np.array(e, float).reshape(-1, 1), timestamp=now) for e in est]
    ts = [State(np.array(t, float).reshape(-1, 1), timestamp=now) for t in tru]
    return metric.compute_gospa_metric(es, ts)[0].value


@pytest.mark.parametrize("seed", range(12))
def test_gospa_equals_stone_soup(seed):
    rng = np.random.default_rng(seed)
    m, n = rng.integers(0, 7), rng.integers(0, 7)
    est = rng.uniform(0, 30, (m, 2))
    tru = rng.uniform(0, 30, (n, 2))
    c, p = float(rng.uniform(2, 15)), float(rng.choice([1.0, 2.0, 3.0]))
    if m == 0 and n == 0:
        assert gospa(np.zeros((0, 0)), c, p)["distance"] == 0.0
        return
    d = np.linalg.norm(est[:, None, :] - tru[None, :, :], axis=-1)
    ours = gospa(d, c, p)
    ref = _stonesoup_gospa(est, tru, c, p)
    for key in ("distance", "localisation", "missed", "false"):
        assert ours[key] == pytest.approx(float(ref[key]), abs=1e-6), key


def test_gospa_known_values():
    # One estimate 1 away from one truth, one truth missed: d^2 = 1 + c^2/2.
    d = np.array([[1.0, 50.0]])
    assert gospa(d, c=4.0, p=2)["distance"] == pytest.approx(np.sqrt(1 + 8))
    assert gospa(np.zeros((3, 0)), c=2.0, p=1)["distance"] == pytest.approx(3.0)


def test_innovation_stats_pixels_and_si():
    y = np.array([[15.0, 0.0], [0.0, 0.6], [np.nan, 1.0]] + [[0.0, 0.0]] * 17)
    s = innovation_stats(y, (15.0, 0.3))
    assert s["n_innov"] == 19
    assert s["innov_mean_px"] == pytest.approx(3.0 / 19)
    assert s["innov_range_mean_m"] == pytest.approx(15.0 / 19)
    px = np.array([1.0, 2.0] + [0.0] * 17)
    assert s["innov_p95_px"] == pytest.approx(np.percentile(px, 95))


def test_pixel_distance_wraps_doppler():
    d = pixel_distance(
        np.array([[100.0, 38.0]]), np.array([[115.0, -38.0], [100.0, 30.0]]), (15.0, 0.5), 78.0
    )
    assert d[0, 0] == pytest.approx(np.hypot(1.0, 4.0))
    assert d[0, 1] == pytest.approx(16.0)


def _tracks(rows):
    df = pd.DataFrame(rows, columns=["time_s", "track_id", "range_m", "radial_velocity_mps"])
    df["innovation_range_m"] = 0.0
    df["innovation_radial_velocity_mps"] = 0.0
    return df


def test_counts_switches_fragmentation_on_constructed_case():
    t = np.arange(10.0)
    R = np.column_stack([np.full(10, 1000.0), np.full(10, 2000.0)])
    V = np.zeros((10, 2))
    vis = np.ones((10, 2), bool)
    vis[4:6, 1] = False  # target 1 invisible for two frames -> two segments with gap_s < 2
    truth = Truth(t, R, V, vis)
    assert truth_segments(truth, gap_s=1.5).max() == 2
    rows = []
    for k in range(10):
        rows.append((t[k], 1 if k < 5 else 2, 1000.0, 0.0))  # target 0: track 1 then track 2
        if vis[k, 1]:
            rows.append((t[k], 7, 2000.0, 0.0))  # target 1: one track over both segments
    rows.append((3.0, 99, 4000.0, 10.0))  # a false track
    m = track_metrics(_tracks(rows), truth, (15.0, 0.3), 78.0, gap_s=1.5)
    assert m["truth_tracks"] == 3
    assert m["tracks"] == 4 and m["false_tracks"] == 1
    assert m["fragmentation"] == 1 and m["id_switches"] == 1
    assert m["completeness"] == pytest.approx(1.0)
    # Same truth, perfect tracks: one per segment.
    good = [(t[k], 1, 1000.0, 0.0) for k in range(10)]
    good += [(t[k], 7 if k < 4 else 8, 2000.0, 0.0) for k in range(10) if vis[k, 1]]
    g = track_metrics(_tracks(good), truth, (15.0, 0.3), 78.0, gap_s=1.5)
    assert (g["tracks"], g["fragmentation"], g["id_switches"], g["gospa_mean"]) == (3, 0, 0, 0.0)
